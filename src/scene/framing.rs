//! The camera of a scene without a `# camera` line. Up is +Y (the OBJ convention, and what
//! Blender's exporter writes); a scene modelled with another up axis needs its own camera.
//!
//! The display draws both sides of every polygon, the back black, so a good picture is one whose
//! rays meet the fronts of polygons. Candidate views are judged by casting rays:
//!
//! - **A box open on one side is shown through its opening** (a Cornell box without its front):
//!   the eye outside, facing the opening square on, at the distance where the opening fills a
//!   square picture. A box is open on one side when the rays cast in through that side of its
//!   bounds meet fronts (the walls' insides, what stands in the box) and those cast in through
//!   each of the five others meet backs (the walls from outside). The test comes first: from
//!   inside a box whose opening is small next to its walls (the archive's boxes of 1.59 height,
//!   Sphere, Water and Glossy), fewer than a tenth of the rays get out, and such a box passed for
//!   a closed room, shown from inside facing a side wall.
//! - **A closed room is shown from inside.** Eyes at mid-height near one end of the longest
//!   horizontal axis (then farther in, then a little lower or higher, then along the other
//!   axis), looking along it with a wide field of view. An eye is inside a room when at least
//!   90 % of rays cast in all directions from it meet the front of a polygon (walls face inward;
//!   an eye inside a solid meets backs, one in an open scene meets nothing). The first such eye
//!   whose picture is at least 90 % fronts of polygons, half of them at least 15 % of the room's
//!   length away, is taken: an eye just in front of a sofa sees the sofa, not the room.
//! - **Otherwise the scene is shown whole from outside**: the eye where the bounding sphere fits
//!   the field of view, from a three-quarter view above (from -Z and +X), or, when that shows
//!   mostly backs of polygons (walls facing in, a courtyard's seen from outside), from the
//!   direction among 24 (8 around, 3 heights) whose picture shows the largest share of fronts.

use super::bvh::Bvh;
use super::{Camera, Scene};
use glam::Vec3;

/// Rays cast in all directions from a candidate eye.
const RAYS: usize = 512;
/// Share of them that must meet the front of a polygon for the eye to be inside a room: a
/// doorway or a window lets some out.
const ENCLOSED: f32 = 0.9;
/// Rays per side of the grid cast through a candidate picture.
const GRID: usize = 16;
/// Share of a picture from inside that must show fronts of polygons.
const SHOWN: f32 = 0.9;
/// Share of the surfaces in a picture from outside that may be backs before other directions
/// are tried.
const BACKS: f32 = 0.05;
/// Least median distance, as a share of the room's length, at which a picture from inside
/// meets surfaces: an eye just in front of a sofa sees the sofa, not the room.
const DEPTH: f32 = 0.15;
/// Vertical field of view inside a room, degrees: wide, as a photograph of an interior.
pub const ROOM_FOV: f32 = 70.0;
/// Vertical field of view from outside, degrees.
pub const OUTSIDE_FOV: f32 = 40.0;
/// Where the eye may stand along the room's axis (share of its length from one end).
const ALONG: [f32; 3] = [0.12, 0.25, 0.4];
/// Eye heights tried (share of the room's height from the floor).
const HEIGHTS: [f32; 3] = [0.5, 0.35, 0.65];
/// Heights of the view from outside, degrees above the horizon.
const ELEVATIONS: [f32; 3] = [30.0, 10.0, 0.0];
/// Share of the rays cast in through a side of the bounds that must meet fronts for the side to
/// be open, or backs for it to be closed: a water surface or a lamp seen edge on may show a few
/// of the wrong side.
const SIDE: f32 = 0.75;
/// Room left around an opening in the picture (a share of its half-width).
const MARGIN: f32 = 1.05;

pub(super) fn default_camera(scene: &Scene) -> Camera {
    let bvh = Bvh::new(scene);
    (open_box(scene, &bvh))
        .or_else(|| interior(scene, &bvh))
        .unwrap_or_else(|| exterior(scene, &bvh))
}

/// Square on to the opening of a box open on one side ([`open_side`]), the whole opening in a
/// square picture, looking along the open axis at the middle of the box.
fn open_box(scene: &Scene, bvh: &Bvh) -> Option<Camera> {
    let out = open_side(scene, bvh)?;
    let (lo, hi) = scene.bounds();
    let (centre, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let axis = out.abs();
    // The opening's larger half-side fits the vertical field of view (and so the horizontal one
    // of a picture at least as wide as tall).
    let across = (half - axis * half.dot(axis)).max_element();
    let distance = MARGIN * across / (0.5 * OUTSIDE_FOV.to_radians()).tan();
    Some(Camera {
        eye: centre + out * (half.dot(axis) + distance),
        target: centre,
        up: Vec3::Y,
        fov_y: OUTSIDE_FOV,
    })
}

/// The outward normal of the one side of the scene's bounds through which it is open, when the
/// rays cast in through that side meet fronts and those cast in through each of the others meet
/// backs. A closed room shows backs on every side, an open scene fronts or nothing; a box open
/// at the top (a courtyard) is left to the views from above.
fn open_side(scene: &Scene, bvh: &Bvh) -> Option<Vec3> {
    let (lo, hi) = scene.bounds();
    let sides = [
        Vec3::Z,
        Vec3::NEG_Z,
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
    ];
    let seen: Vec<Seen> = (sides.iter())
        .map(|&out| fronts(scene, bvh, side_rays(lo, hi, out)))
        .collect();
    let share = |k: usize, s: &Seen| k as f32 / s.rays.max(1) as f32;
    let open: Vec<usize> = (0..sides.len())
        .filter(|&i| share(seen[i].front, &seen[i]) >= SIDE)
        .collect();
    let [i] = open[..] else {
        return None;
    };
    let closed = (0..sides.len())
        .filter(|&j| j != i)
        .all(|j| share(seen[j].back, &seen[j]) >= SIDE);
    (closed && sides[i].y == 0.0).then_some(sides[i])
}

/// A [`GRID`] × [`GRID`] grid of parallel rays cast in through the side of the bounds `lo`–`hi`
/// whose outward normal is `out`, from just outside it, over its middle 90 % (the walls along its
/// edges lie in the bounds' planes).
fn side_rays(lo: Vec3, hi: Vec3, out: Vec3) -> impl Iterator<Item = (Vec3, Vec3)> {
    let (centre, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let axis = out.abs();
    let u = if axis.x > 0.0 { Vec3::Y } else { Vec3::X };
    let v = axis.cross(u).abs();
    let start = centre + out * (half.dot(axis) + 0.01 * half.length());
    (0..GRID * GRID).map(move |k| {
        let at = |i: usize| 0.9 * ((i as f32 + 0.5) / GRID as f32 * 2.0 - 1.0);
        let o = start + u * (at(k % GRID) * half.dot(u)) + v * (at(k / GRID) * half.dot(v));
        (o, -out)
    })
}

/// From inside, if the scene closes around a candidate eye and the view from it shows fronts.
fn interior(scene: &Scene, bvh: &Bvh) -> Option<Camera> {
    let (lo, hi) = scene.bounds();
    let extent = hi - lo;
    // A scene without height (a floor alone) encloses nothing.
    if extent.y <= 1e-3 * extent.length() {
        return None;
    }
    let axes = if extent.x >= extent.z {
        [Vec3::X, Vec3::Z]
    } else {
        [Vec3::Z, Vec3::X]
    };
    let centre = lo + 0.5 * extent;
    let directions = sphere_directions(RAYS);
    for axis in axes {
        let length = extent.dot(axis);
        for height in HEIGHTS {
            for along in ALONG {
                // Near the low end looking towards the high one, then the other way round.
                for (start, forward) in [(lo, axis), (hi, -axis)] {
                    let mut eye = centre + axis * (start - centre).dot(axis);
                    eye += forward * along * length;
                    eye.y = lo.y + height * extent.y;
                    let camera = Camera {
                        eye,
                        // Towards the centre: the viewer orbits about the target, inside.
                        target: eye + forward * (0.5 - along).max(0.05) * length,
                        up: Vec3::Y,
                        fov_y: ROOM_FOV,
                    };
                    let all = directions.iter().map(|&d| (eye, d));
                    if fronts(scene, bvh, all).share() >= ENCLOSED
                        && fronts(scene, bvh, picture_rays(&camera)).share() >= SHOWN
                        && median_depth(bvh, &camera) >= DEPTH * length
                    {
                        return Some(camera);
                    }
                }
            }
        }
    }
    None
}

/// From outside, the bounding sphere filling the field of view.
fn exterior(scene: &Scene, bvh: &Bvh) -> Camera {
    let (lo, hi) = scene.bounds();
    let centre = 0.5 * (lo + hi);
    let radius = 0.5 * (hi - lo).length();
    let distance = radius / (0.5 * OUTSIDE_FOV.to_radians()).sin();
    let mut best: Option<(f32, Camera)> = None;
    for elevation in ELEVATIONS {
        // From -Z turned 30° towards +X, then on round in steps of 45°.
        for k in 0..8 {
            let (azimuth, elevation) = (
                (30.0 + 45.0 * k as f32).to_radians(),
                elevation.to_radians(),
            );
            let direction = Vec3::new(
                azimuth.sin() * elevation.cos(),
                elevation.sin(),
                -azimuth.cos() * elevation.cos(),
            );
            let camera = Camera {
                eye: centre + direction * distance,
                target: centre,
                up: Vec3::Y,
                fov_y: OUTSIDE_FOV,
            };
            let seen = fronts(scene, bvh, picture_rays(&camera));
            let backs = seen.back as f32 / (seen.front + seen.back).max(1) as f32;
            if backs <= BACKS {
                return camera;
            }
            if best.is_none_or(|(b, _)| backs < b) {
                best = Some((backs, camera));
            }
        }
    }
    best.map(|(_, c)| c).expect("eight directions tried")
}

/// What rays meet: fronts of polygons, backs, or nothing.
#[derive(Default)]
struct Seen {
    front: usize,
    back: usize,
    rays: usize,
}

impl Seen {
    /// The share of rays that met a front.
    fn share(&self) -> f32 {
        self.front as f32 / self.rays.max(1) as f32
    }
}

fn fronts(scene: &Scene, bvh: &Bvh, rays: impl Iterator<Item = (Vec3, Vec3)>) -> Seen {
    let mut seen = Seen::default();
    for (o, d) in rays {
        seen.rays += 1;
        if let Some((_, p)) = bvh.closest(o, d, u32::MAX) {
            if scene.polygons[p as usize].normal.dot(d) < 0.0 {
                seen.front += 1;
            } else {
                seen.back += 1;
            }
        }
    }
    seen
}

/// The median distance along the picture's rays to what they meet (rays that meet nothing count
/// as infinitely far).
fn median_depth(bvh: &Bvh, camera: &Camera) -> f32 {
    let mut t: Vec<f32> = picture_rays(camera)
        .map(|(o, d)| {
            bvh.closest(o, d, u32::MAX)
                .map_or(f32::INFINITY, |(t, _)| t)
        })
        .collect();
    t.sort_unstable_by(f32::total_cmp);
    t[t.len() / 2]
}

/// Rays from the eye through a [`GRID`] × [`GRID`] grid over a square picture.
fn picture_rays(camera: &Camera) -> impl Iterator<Item = (Vec3, Vec3)> {
    let forward = (camera.target - camera.eye).normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    let half = (0.5 * camera.fov_y.to_radians()).tan();
    let eye = camera.eye;
    (0..GRID * GRID).map(move |k| {
        let at = |i: usize| ((i as f32 + 0.5) / GRID as f32 * 2.0 - 1.0) * half;
        let d = forward + at(k % GRID) * right + at(k / GRID) * up;
        (eye, d.normalize())
    })
}

/// `n` directions spread evenly over the sphere (a Fibonacci lattice).
fn sphere_directions(n: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).sqrt();
            let a = golden * i as f32;
            Vec3::new(r * a.cos(), y, r * a.sin())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::{test_scene, Polygon};
    use super::*;

    /// The six faces of a box from `lo` to `hi`, facing in (a room) or out (a solid).
    fn cuboid(lo: Vec3, hi: Vec3, inward: bool) -> Vec<Polygon> {
        let c = |x: bool, y: bool, z: bool| {
            Vec3::new(
                if x { hi.x } else { lo.x },
                if y { hi.y } else { lo.y },
                if z { hi.z } else { lo.z },
            )
        };
        // Each face counter-clockwise seen from outside.
        let faces = [
            [
                c(false, false, false),
                c(false, false, true),
                c(false, true, true),
                c(false, true, false),
            ],
            [
                c(true, false, false),
                c(true, true, false),
                c(true, true, true),
                c(true, false, true),
            ],
            [
                c(false, false, false),
                c(true, false, false),
                c(true, false, true),
                c(false, false, true),
            ],
            [
                c(false, true, false),
                c(false, true, true),
                c(true, true, true),
                c(true, true, false),
            ],
            [
                c(false, false, false),
                c(false, true, false),
                c(true, true, false),
                c(true, false, false),
            ],
            [
                c(false, false, true),
                c(true, false, true),
                c(true, true, true),
                c(false, true, true),
            ],
        ];
        faces
            .into_iter()
            .map(|f| {
                let mut v = f.to_vec();
                if inward {
                    v.reverse();
                }
                Polygon::new(v, 0, "box".into()).unwrap()
            })
            .collect()
    }

    fn inside(c: &Camera, lo: Vec3, hi: Vec3) -> bool {
        c.eye.cmpgt(lo).all() && c.eye.cmplt(hi).all()
    }

    #[test]
    fn a_closed_room_is_seen_from_inside_along_its_length() {
        let (lo, hi) = (Vec3::new(-1.0, 0.0, -4.0), Vec3::new(3.0, 3.0, 6.0));
        let scene = test_scene(cuboid(lo, hi, true));
        let c = scene.camera_or_default();
        assert!(inside(&c, lo, hi), "{c:?}");
        assert!(c.validate().is_ok());
        assert_eq!((c.target - c.eye).normalize(), Vec3::Z, "{c:?}");
        assert_eq!(c.fov_y, ROOM_FOV);
        // With furniture in the middle (a solid block, facing out), still from inside.
        let mut polygons = cuboid(lo, hi, true);
        polygons.extend(cuboid(
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(2.0, 1.0, 2.0),
            false,
        ));
        assert!(inside(&test_scene(polygons).camera_or_default(), lo, hi));
    }

    /// Every corner of the scene's bounds is in the picture.
    fn frames_the_bounds(scene: &Scene, c: &Camera) {
        let (lo, hi) = scene.bounds();
        let view = (c.target - c.eye).normalize();
        for i in 0..8 {
            let corner = Vec3::select(glam::BVec3::new(i & 1 > 0, i & 2 > 0, i & 4 > 0), hi, lo);
            let angle = view.angle_between(corner - c.eye).to_degrees();
            assert!(angle <= 0.5 * c.fov_y + 0.01, "corner {corner} at {angle}°");
        }
    }

    #[test]
    fn an_eye_just_in_front_of_furniture_is_passed_over() {
        // The first eye tried (mid-height, an eighth of the way along) stands 0.1 in front of a
        // tall cabinet: the room encloses it and its picture is all fronts, but all cabinet.
        let (lo, hi) = (Vec3::new(-1.0, 0.0, -4.0), Vec3::new(3.0, 3.0, 6.0));
        let first = Vec3::new(1.0, 1.5, -4.0 + 0.12 * 10.0);
        let cabinet = cuboid(
            Vec3::new(-0.5, 0.0, first.z + 0.1),
            Vec3::new(2.5, 2.9, first.z + 0.6),
            false,
        );
        let mut polygons = cuboid(lo, hi, true);
        polygons.extend(cabinet);
        let scene = test_scene(polygons);
        let c = scene.camera_or_default();
        assert!(inside(&c, lo, hi), "{c:?}");
        assert!(c.eye.distance(first) > 0.5, "{c:?}");
        let depth = median_depth(&Bvh::new(&scene), &c);
        assert!(depth >= DEPTH * 10.0, "median depth {depth}: {c:?}");
    }

    #[test]
    fn an_open_scene_is_seen_whole_from_a_three_quarter_view_above() {
        let (lo, hi) = (Vec3::new(-2.0, 0.0, -2.0), Vec3::new(2.0, 1.0, 2.0));
        let floor = cuboid(lo, hi, true).remove(2);
        let block = |x: f32| cuboid(Vec3::new(x, 0.0, -0.5), Vec3::new(x + 1.0, 1.0, 0.5), false);
        let mut objects = vec![floor.clone()];
        objects.extend(block(-1.5));
        objects.extend(block(0.5));
        // Two blocks on a floor, a solid block alone, a floor alone.
        for polygons in [objects, block(0.0), vec![floor]] {
            let scene = test_scene(polygons);
            let c = scene.camera_or_default();
            assert!(!inside(&c, lo, hi), "{c:?}");
            assert_eq!(c.fov_y, OUTSIDE_FOV);
            assert!(c.validate().is_ok());
            frames_the_bounds(&scene, &c);
            let view = c.eye - c.target;
            assert!(
                view.x > 0.0 && view.y > 0.0 && view.z < 0.0,
                "three-quarter: {c:?}"
            );
        }
    }

    /// Every corner of the scene's bounds is in a square picture.
    fn frames_the_bounds_in_a_square(scene: &Scene, c: &Camera) {
        let (lo, hi) = scene.bounds();
        let forward = (c.target - c.eye).normalize();
        let right = forward.cross(c.up).normalize();
        let up = right.cross(forward);
        let half = (0.5 * c.fov_y.to_radians()).tan();
        for i in 0..8 {
            let corner = Vec3::select(glam::BVec3::new(i & 1 > 0, i & 2 > 0, i & 4 > 0), hi, lo);
            let d = corner - c.eye;
            let (x, y) = (d.dot(right) / d.dot(forward), d.dot(up) / d.dot(forward));
            assert!(
                x.abs() <= half && y.abs() <= half,
                "corner {corner} at ({x}, {y})"
            );
        }
    }

    #[test]
    fn a_box_open_on_one_side_is_seen_through_its_opening() {
        // A Cornell box whose open side faces +Z (as in the archive's OBJ), then one open at
        // -X; boxes as high as wide and lower (the archive's Sphere, Water and Glossy boxes are
        // 1.59 high and 2 wide: from inside, less than a tenth of the rays got out, and they
        // were shown from inside facing a side wall).
        for height in [2.0, 1.59, 0.8] {
            for (removed, out) in [(5, Vec3::Z), (0, Vec3::NEG_X)] {
                let (lo, hi) = (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, height, 1.0));
                let mut polygons = cuboid(lo, hi, true);
                polygons.remove(removed);
                // A block in it, off the middle, facing out.
                let block = (Vec3::new(0.3, 0.1, 0.3), Vec3::new(0.7, 0.5, 0.7));
                polygons.extend(cuboid(block.0, block.1, false));
                let scene = test_scene(polygons);
                let c = scene.camera_or_default();
                let view = (c.target - c.eye).normalize();
                assert!(view.dot(-out) > 0.9999, "{height} {out}: {c:?}");
                assert!(c.eye.dot(out) > hi.dot(out.abs()), "outside: {c:?}");
                frames_the_bounds_in_a_square(&scene, &c);
                let bvh = Bvh::new(&scene);
                let seen = fronts(&scene, &bvh, picture_rays(&c));
                assert_eq!(seen.back, 0, "{height} {out}");
                // The wall facing the opening in the middle of the picture.
                let (_, p) = bvh.closest(c.eye, view, u32::MAX).unwrap();
                let p = &scene.polygons[p as usize];
                assert!(p.normal.dot(out) > 0.999, "{height} {out}: {p:?}");
            }
        }
    }

    /// A closed room, an open scene and a box open at the top have no open side: the views
    /// from inside and from above are as before.
    #[test]
    fn closed_rooms_open_scenes_and_courtyards_have_no_open_side() {
        let (lo, hi) = (Vec3::new(-1.0, 0.0, -4.0), Vec3::new(3.0, 3.0, 6.0));
        let room = cuboid(lo, hi, true);
        let mut courtyard = room.clone();
        courtyard.remove(3);
        let floor = room[2].clone();
        let mut blocks = vec![floor];
        blocks.extend(cuboid(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 1.0),
            false,
        ));
        for (name, polygons) in [("room", room), ("courtyard", courtyard), ("blocks", blocks)] {
            let scene = test_scene(polygons);
            assert_eq!(open_side(&scene, &Bvh::new(&scene)), None, "{name}");
        }
    }
}
