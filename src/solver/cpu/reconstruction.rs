//! The CPU twin of the reconstruction pass: ΔL for every patch from one shooter, with the same
//! form factors as `glsl/reconstruct.frag` (`solver::form_factor`) and exact visibility.

use crate::scene::bvh::Bvh;
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
