//! The CPU twin of the reconstruction pass: ΔL for every patch from one shooter, with the same
//! form factors as `glsl/reconstruct.frag` (`solver::form_factor`) and exact visibility.

use crate::patches::PatchLayout;
use crate::scene::bvh::Bvh;
use crate::scene::Scene;
use crate::solver::{form_factor, FormFactorKind, Part, Shooter};
use glam::Vec3;

/// A receiving patch: its atlas texel, polygon, centre, normal and reflectance.
#[derive(Clone, Copy)]
pub struct Receiver {
    /// Its texel in the atlas (row-major index).
    pub texel: usize,
    /// Its polygon's ID.
    pub polygon: u32,
    /// The patch's centre, world space.
    pub centre: Vec3,
    /// Its polygon's unit normal.
    pub normal: Vec3,
    /// Its polygon's reflectance (Kd).
    pub rho: Vec3,
}

/// Every patch of `layout` as a receiver: its texel's centre on its polygon, the polygon's
/// normal and reflectance; in texel order.
pub fn receivers(scene: &Scene, layout: &PatchLayout) -> Vec<Receiver> {
    let width = layout.atlas_width as usize;
    let owned = layout
        .owner
        .iter()
        .enumerate()
        .filter(|&(_, &owner)| owner != 0);
    owned
        .map(|(texel, &owner)| {
            let p = owner as usize - 1;
            let polygon = &scene.polygons[p];
            let lm = &layout.lightmaps[p];
            let (x, y) = (texel % width, texel / width);
            Receiver {
                texel,
                polygon: p as u32,
                centre: lm.world(
                    (x - lm.x as usize) as f32 + 0.5,
                    (y - lm.y as usize) as f32 + 0.5,
                ),
                normal: polygon.normal,
                rho: scene.material(polygon).kd,
            }
        })
        .collect()
}

/// ΔL at `r` from `s` (zero on the shooter's own polygon: a planar shooter sends it nothing);
/// `parts`: the step's, which `s.parts` points at (beyond the paper: a face cluster's members,
/// near it); `slack`: `Scene::plane_slack`, for the polygon factor.
pub fn delta(
    r: &Receiver,
    s: &Shooter,
    parts: &[Part],
    kind: FormFactorKind,
    slack: f32,
    bvh: &Bvh,
) -> Vec3 {
    if r.polygon as usize == s.polygon {
        return Vec3::ZERO;
    }
    let near = r.centre.distance(s.position) < s.parts.reach;
    let received = match kind {
        FormFactorKind::Point => {
            s.energy * form_factor::point(r.centre, r.normal, s.position, s.normal)
        }
        FormFactorKind::Polygon if near => {
            let rows = s.parts.first as usize..(s.parts.first + s.parts.count) as usize;
            let factor =
                |p: &Part| form_factor::polygon(r.centre, r.normal, p.outline(), p.normal, slack);
            s.energy
                * parts[rows]
                    .iter()
                    .fold(Vec3::ZERO, |sum, p| sum + p.weight * factor(p))
        }
        FormFactorKind::Polygon => {
            let outline = &s.corners[..s.corner_count];
            s.energy / s.area * form_factor::polygon(r.centre, r.normal, outline, s.normal, slack)
        }
    };
    // Cast the shadow ray only where there is something to shadow.
    if received == Vec3::ZERO || bvh.occluded(r.centre, s.position, r.polygon, s.polygon as u32) {
        return Vec3::ZERO;
    }
    r.rho * received
}
