//! The viewer's camera: orbit around the target, pan, zoom, starting from the scene's camera
//! (so the first frame is exactly the picture `radiosity solve` renders).

use crate::scene::Camera;
use glam::{Quat, Vec3};

/// Closest the eye may come to the pole of the up axis, as |cos| of the angle between them.
const POLE: f32 = 0.995;

/// The viewer's camera: it orbits the target (drag), zooms (wheel) and goes home (key H).
pub struct OrbitCamera {
    home: Camera,
    /// Where it is now.
    pub camera: Camera,
}

impl OrbitCamera {
    /// A camera at `home`, which it returns to.
    pub fn new(home: Camera) -> OrbitCamera {
        OrbitCamera { home, camera: home }
    }

    /// Back to the scene's camera.
    pub fn reset(&mut self) {
        self.camera = self.home;
    }

    /// Turn the eye around the target: `yaw` about the up axis, `pitch` about the camera's right
    /// axis (radians; positive pitch raises the eye). The eye never passes over the poles.
    pub fn orbit(&mut self, yaw: f32, pitch: f32) {
        let c = &mut self.camera;
        let up = c.up.normalize();
        let mut offset = Quat::from_axis_angle(up, yaw) * (c.eye - c.target);
        let right = offset.cross(up).normalize_or_zero();
        if right != Vec3::ZERO {
            let raised = Quat::from_axis_angle(right, pitch) * offset;
            if raised.normalize().dot(up).abs() < POLE {
                offset = raised;
            }
        }
        c.eye = c.target + offset;
    }

    /// Slide eye and target in the view plane by a fraction of the view's height (`dx` right,
    /// `dy` up), so a drag moves the scene with the mouse.
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let c = &mut self.camera;
        let forward = (c.target - c.eye).normalize();
        let right = forward.cross(c.up).normalize_or_zero();
        let up = right.cross(forward);
        let height = 2.0 * (c.target - c.eye).length() * (0.5 * c.fov_y.to_radians()).tan();
        let shift = (right * dx + up * dy) * height;
        c.eye -= shift;
        c.target -= shift;
    }

    /// Move the eye towards the target (positive `steps`) or away, 10 % of the distance a step,
    /// between 1/1000 and 100 times the scene camera's distance.
    pub fn zoom(&mut self, steps: f32) {
        let c = &mut self.camera;
        let home = (self.home.eye - self.home.target).length();
        let offset = (c.eye - c.target) * 0.9f32.powf(steps.clamp(-50.0, 50.0));
        c.eye = c.target + offset.clamp_length(1e-3 * home, 1e2 * home);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cornell() -> Camera {
        Camera {
            eye: Vec3::new(278.0, 273.0, -800.0),
            target: Vec3::new(278.0, 273.0, 0.0),
            up: Vec3::Y,
            fov_y: 39.3077,
        }
    }

    #[test]
    fn starts_at_the_scene_camera_and_returns_to_it() {
        let mut c = OrbitCamera::new(cornell());
        assert_eq!(c.camera, cornell());
        c.orbit(0.3, 0.2);
        c.pan(0.1, 0.1);
        c.zoom(2.0);
        assert_ne!(c.camera, cornell());
        c.reset();
        assert_eq!(c.camera, cornell());
    }

    #[test]
    fn orbit_keeps_the_distance_and_stops_at_the_poles() {
        let mut c = OrbitCamera::new(cornell());
        c.orbit(1.0, 0.5);
        let d = (c.camera.eye - c.camera.target).length();
        assert!((d - 800.0).abs() < 1e-2, "{d}");
        for _ in 0..100 {
            c.orbit(0.0, 0.1);
        }
        let dir = (c.camera.eye - c.camera.target).normalize();
        assert!(dir.dot(Vec3::Y) < POLE && dir.dot(Vec3::Y) > 0.9, "{dir}");
        // A quarter turn of yaw moves the eye from -z to the side.
        let mut c = OrbitCamera::new(cornell());
        c.orbit(std::f32::consts::FRAC_PI_2, 0.0);
        let dir = (c.camera.eye - c.camera.target).normalize();
        assert!(dir.x.abs() > 0.999, "{dir}");
    }

    #[test]
    fn pan_moves_eye_and_target_together_and_zoom_approaches() {
        let mut c = OrbitCamera::new(cornell());
        c.pan(0.5, 0.0);
        assert!((c.camera.target - c.camera.eye - Vec3::new(0.0, 0.0, 800.0)).length() < 1e-3);
        assert!((c.camera.target.x - 278.0).abs() > 100.0);
        let mut c = OrbitCamera::new(cornell());
        c.zoom(1.0);
        assert!(((c.camera.eye - c.camera.target).length() - 720.0).abs() < 1e-2);
        c.zoom(-1000.0);
        assert!(((c.camera.eye - c.camera.target).length() - 80_000.0).abs() < 1.0);
        c.zoom(1e6);
        assert!((c.camera.eye - c.camera.target).length() >= 0.79);
    }
}
