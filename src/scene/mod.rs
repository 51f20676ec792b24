//! The scene: planar polygons (the paper's faces, each of which gets its own lightmap), their
//! Lambertian materials (`Kd` reflectance, `Ke` emitted radiance) and an optional camera.

pub mod bundled;
pub mod bvh;
mod emission;
mod error;
mod files;
mod framing;
mod gltf;
mod gltf_data;
mod header;
mod libraries;
mod load;
pub mod merge;
mod mtl;
mod obj;
mod overlap;
pub mod sky;
mod statements;
pub mod third_party;
mod triangulate;

pub use emission::{Emission, LoadOptions};
pub use error::{EmissionError, SceneError, MAX_KE, MAX_SCENE_SIZE, MIN_SCENE_SIZE};
pub use files::{allow_outside_materials, shown, shown_path, MAX_MTL_BYTES, MAX_OBJ_BYTES};
pub use gltf::{load_gltf, load_gltf_with};
pub use load::{load_obj, load_obj_with};
pub use sky::SkyStats;
pub use triangulate::triangulate;

/// The scene in `path`: a glTF file (`.glb`, `.gltf`, by its extension, see `gltf.rs`) or an
/// OBJ file with its MTL libraries from the same folder.
pub fn load_file_with(path: &std::path::Path, options: &LoadOptions) -> Result<Scene, SceneError> {
    if gltf::is_gltf(path) {
        gltf::load_gltf_with(path, options)
    } else {
        load::load_obj_with(path, options)
    }
}

/// The material of faces that name none, or one no library defines: a neutral grey that does
/// not emit.
pub const DEFAULT_MATERIAL: &str = "(default)";

/// The reflectance of [`DEFAULT_MATERIAL`], and of materials that give their colour only as a
/// texture (`mtl.rs`): a neutral grey, dark enough that a closed room of it converges.
pub const DEFAULT_GREY: f32 = 0.5;

use crate::geometry::{bounds, mean, sphere_around, Plane};
use glam::Vec3;

/// A material of the MTL file: what the solver uses of it.
#[derive(Clone, Debug)]
pub struct Material {
    /// Its name as messages show it (control characters escaped).
    pub name: String,
    /// Diffuse reflectance (albedo), linear RGB in [0, 1].
    pub kd: Vec3,
    /// Emitted radiance, one-sided, linear RGB (the units of every output value).
    pub ke: Vec3,
}

impl Material {
    /// Whether it emits (any channel of `ke` above zero).
    pub fn is_emitter(&self) -> bool {
        self.ke.max_element() > 0.0
    }
}

/// A planar polygon, vertices counter-clockwise seen from its front.
#[derive(Clone, Debug)]
pub struct Polygon {
    /// Corners, counter-clockwise seen from the front.
    pub vertices: Vec<Vec3>,
    /// Unit normal, towards the front (the side that emits and receives).
    pub normal: Vec3,
    /// Area, scene units squared.
    pub area: f32,
    /// The centroid of its area.
    pub centroid: Vec3,
    /// Index into `Scene::materials`.
    pub material: usize,
    /// The OBJ object (or group) the face came from, for messages.
    pub object: String,
}

impl Polygon {
    /// Normal (Newell's method, robust for slightly non-planar polygons), area and area centroid.
    /// `None` for a degenerate (zero-area) polygon.
    pub fn new(mut vertices: Vec<Vec3>, material: usize, object: String) -> Option<Polygon> {
        // A vertex repeated next to itself adds no corner; it only blocks triangulation.
        vertices.dedup();
        while vertices.len() > 1 && vertices.first() == vertices.last() {
            vertices.pop();
        }
        let n = vertices.len();
        if n < 3 {
            return None;
        }
        // Newell's sums relative to the first vertex: on absolute positions their rounding grows
        // with the square of the distance from the origin (a unit square 1e4 away came out with
        // twice its area and a normal 53° off).
        let o = vertices[0];
        let mut newell = Vec3::ZERO;
        for i in 0..n {
            let (a, b) = (vertices[i] - o, vertices[(i + 1) % n] - o);
            newell += a.cross(b);
        }
        let area = 0.5 * newell.length();
        let extent = bounds(&vertices)
            .map(|(lo, hi)| (hi - lo).length())
            .unwrap_or(0.0);
        if !area.is_finite() || area <= 1e-9 * extent * extent {
            return None;
        }
        let normal = newell / (2.0 * area);
        // Area-weighted centroid of the fan triangles (the point a paper-mode shooter shoots from).
        let mut centroid = Vec3::ZERO;
        let mut total = 0.0;
        for i in 1..n - 1 {
            let (a, b, c) = (vertices[0], vertices[i], vertices[i + 1]);
            let w = 0.5 * (b - a).cross(c - a).dot(normal);
            centroid += w * (a + b + c) / 3.0;
            total += w;
        }
        let centroid = if total.abs() > 0.0 {
            centroid / total
        } else {
            mean(&vertices)
        };
        Some(Polygon {
            vertices,
            normal,
            area,
            centroid,
            material,
            object,
        })
    }
}

impl Polygon {
    /// Do all vertices lie within `tolerance` × the polygon's size of its plane?
    pub fn is_planar(&self, tolerance: f32) -> bool {
        let size = bounds(&self.vertices)
            .map(|(lo, hi)| (hi - lo).length())
            .unwrap_or(0.0);
        let plane = self.plane();
        self.vertices
            .iter()
            .all(|v| plane.distance(*v).abs() <= tolerance * size)
    }

    /// The polygon's plane: its normal through its centroid.
    pub fn plane(&self) -> Plane {
        Plane::through(self.normal, self.centroid)
    }

    /// A sphere around the polygon: its centroid and the distance to its farthest vertex.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        sphere_around(self.centroid, &self.vertices)
    }
}

/// A pinhole camera (from a `# camera` line, the flags, or chosen by casting rays).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where it stands.
    pub eye: Vec3,
    /// The point it looks at.
    pub target: Vec3,
    /// The picture's up direction (not parallel to the view).
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y: f32,
}

/// The field of view a camera may have, degrees: 0 and 180 make the projection singular; 1 and
/// 179 keep it well conditioned (tan 89.5° ≈ 115).
pub const FOV_RANGE: std::ops::RangeInclusive<f32> = 1.0..=179.0;

/// Why a camera cannot make a picture.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum CameraError {
    /// A vector (named) with a NaN or infinite component.
    #[error("the {0} is not three finite numbers")]
    NotFinite(&'static str),
    /// The eye on the target (the point, formatted).
    #[error("the eye and the target are the same point ({0}), so there is no view direction")]
    EyeIsTarget(String),
    /// A zero up vector.
    #[error("the up vector is zero")]
    UpZero,
    /// An up vector along the view.
    #[error(
        "the up vector ({up}) is parallel to the view direction ({view}), so the picture's \
         vertical is undefined"
    )]
    UpParallel {
        /// The up vector, formatted.
        up: String,
        /// The view direction, formatted.
        view: String,
    },
    /// A field of view outside `FOV_RANGE`.
    #[error("the field of view {0}° is outside 1 to 179 degrees")]
    Fov(f32),
}

impl Camera {
    /// Refuse a camera that gives a black, flipped or speckled picture: non-finite values, no
    /// view direction, an up vector that is zero or along the view, a field of view outside
    /// [`FOV_RANGE`].
    pub fn validate(&self) -> Result<(), CameraError> {
        for (name, v) in [("eye", self.eye), ("target", self.target), ("up", self.up)] {
            if !v.is_finite() {
                return Err(CameraError::NotFinite(name));
            }
        }
        // In f64: coordinates near f32::MAX overflow the f32 length.
        let (eye, target, up) = (
            self.eye.as_dvec3(),
            self.target.as_dvec3(),
            self.up.as_dvec3(),
        );
        let view = target - eye;
        let scale = eye.abs().max(target.abs()).max_element();
        // Closer than the coordinates' float rounding: the direction would be noise.
        if view.length() <= 1e-6 * scale || view.length() == 0.0 {
            return Err(CameraError::EyeIsTarget(show(self.eye)));
        }
        if up.length() == 0.0 {
            return Err(CameraError::UpZero);
        }
        // Within about 0.06° of the view direction the picture's roll is float noise.
        if view.normalize().cross(up.normalize()).length() <= 1e-3 {
            return Err(CameraError::UpParallel {
                up: show(self.up),
                view: show(view.as_vec3()),
            });
        }
        if !FOV_RANGE.contains(&self.fov_y) {
            return Err(CameraError::Fov(self.fov_y));
        }
        Ok(())
    }
}

fn show(v: Vec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}

/// A loaded scene: planar polygons with their materials, in one list the passes share.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Its name: the OBJ file's stem.
    pub name: String,
    /// Its polygons; their index is the polygon ID of the item buffer.
    pub polygons: Vec<Polygon>,
    /// Its materials, indexed by `Polygon::material`.
    pub materials: Vec<Material>,
    /// Vertices as counted in the file (`v` lines): what Table 1 calls vertices.
    pub vertex_count: usize,
    /// The camera of a `# camera` line, if any.
    pub camera: Option<Camera>,
    /// Default patch size in scene units, from a `# patch-size S` line in the OBJ.
    pub patch_size: Option<f32>,
    /// Polygons dropped while loading because they had (near) zero area.
    pub skipped_degenerate: usize,
    /// Faces read (after zero-area ones were skipped, non-planar ones split and duplicates
    /// dropped), before connected coplanar faces were merged into `polygons`.
    pub faces: usize,
}

/// A scene of `polygons` with one grey material and nothing else (unit tests of the scene
/// analyses).
#[cfg(test)]
pub(crate) fn test_scene(polygons: Vec<Polygon>) -> Scene {
    Scene {
        name: "t".into(),
        polygons,
        materials: vec![Material {
            name: "m".into(),
            kd: Vec3::splat(0.5),
            ke: Vec3::ZERO,
        }],
        vertex_count: 0,
        camera: None,
        patch_size: None,
        skipped_degenerate: 0,
        faces: 0,
    }
}

impl Scene {
    /// The material of `polygon`.
    pub fn material(&self, polygon: &Polygon) -> &Material {
        &self.materials[polygon.material]
    }

    /// The triangles of its polygons, n − 2 for each n-gon.
    pub fn triangle_count(&self) -> u64 {
        self.polygons
            .iter()
            .map(|p| p.vertices.len().saturating_sub(2) as u64)
            .sum()
    }

    /// Polygons whose material emits.
    pub fn light_count(&self) -> usize {
        self.polygons
            .iter()
            .filter(|p| self.material(p).is_emitter())
            .count()
    }

    /// The names of the materials that emit, whether or not a face uses them.
    pub fn emitting_materials(&self) -> Vec<&str> {
        self.materials
            .iter()
            .filter(|m| m.is_emitter())
            .map(|m| m.name.as_str())
            .collect()
    }

    /// Area of every polygon together.
    pub fn total_area(&self) -> f32 {
        self.polygons.iter().map(|p| p.area).sum()
    }

    /// The axis-aligned bounding box, (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let all: Vec<Vec3> = self
            .polygons
            .iter()
            .flat_map(|p| p.vertices.iter().copied())
            .collect();
        bounds(&all).unwrap_or((Vec3::ZERO, Vec3::ONE))
    }

    /// The length of the bounding box's diagonal.
    pub fn size(&self) -> f32 {
        let (lo, hi) = self.bounds();
        (hi - lo).length()
    }

    /// World units within which a point counts as on a plane (float noise: 1e-5 of the scene's
    /// size; the rooms' thinnest gap, a sheet of paper on a desk, is 1 mm in 7 m).
    pub fn plane_slack(&self) -> f32 {
        1e-5 * self.size()
    }

    /// The scene's own camera (its `# camera` line), or one that shows it: from inside a closed
    /// room, from outside an open scene (see `framing.rs`).
    pub fn camera_or_default(&self) -> Camera {
        // The sky (`--sky`) would make any scene a closed box to the framing: it frames the scene.
        self.camera
            .unwrap_or_else(|| framing::default_camera(&self.without_sky()))
    }
}

#[cfg(test)]
mod camera_tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 0.0, -5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y: 40.0,
        }
    }

    #[test]
    fn validate_refuses_what_makes_no_picture() {
        assert_eq!(camera().validate(), Ok(()));
        let with = |f: fn(&mut Camera)| {
            let mut c = camera();
            f(&mut c);
            c.validate()
        };
        assert!(matches!(
            with(|c| c.eye.x = f32::NAN),
            Err(CameraError::NotFinite("eye"))
        ));
        assert!(matches!(
            with(|c| c.target = c.eye),
            Err(CameraError::EyeIsTarget(_))
        ));
        assert_eq!(with(|c| c.up = Vec3::ZERO), Err(CameraError::UpZero));
        assert!(matches!(
            with(|c| c.up = Vec3::Z),
            Err(CameraError::UpParallel { .. })
        ));
        // A little off the view direction is a tilted picture, not an undefined one.
        assert_eq!(with(|c| c.up = Vec3::new(0.0, 0.01, 1.0)), Ok(()));
        for fov in [0.0, 0.5, 179.5, 180.0, -50.0, f32::NAN] {
            let mut c = camera();
            c.fov_y = fov;
            assert!(c.validate().is_err(), "{fov}");
        }
        // Coordinates near f32::MAX: the view direction's length overflows f32, not the check.
        assert_eq!(
            with(|c| {
                c.eye = Vec3::new(-3e38, 0.0, 0.0);
                c.target = Vec3::new(3e38, 0.0, 0.0);
            }),
            Ok(())
        );
    }
}
