//! Beyond the paper, with face clusters (`face_clusters.rs`, issue 58): a face cluster's members
//! as its shot's near field.
//!
//! A face cluster shoots its members' energy from one point along their mean normal, with one
//! visibility pass and one flat outline. Far from the cluster that is what the members would
//! send, within the cone's direction error. Near it, at receivers about as close as the cluster
//! is wide (a sofa's seams, its cushions, radiator fins), it is not: the members stand at other
//! distances and angles than the flat outline. Sampled clusters of the living room, shot on the
//! CPU (`examples/fc_probe.rs`), moved 20 % of their energy between receivers that way. So a
//! receiver within [`REACH`] cluster extents of the shooting point gets the members' own
//! outlines, each with its normal and its share of the energy; visibility is still the one
//! point's item buffer. The same shots then moved 7 %.
//!
//! The shader (`glsl/reconstruct.frag`, `PartsFactor`) reads the parts from a texture, a row
//! each; its CPU twin is `cpu::reconstruction::delta`.

use super::clusters::Member;
use super::{Shooter, MAX_CORNERS};
use crate::patches::PatchLayout;
use crate::scene::Scene;
use glam::Vec3;

/// Receivers nearer a face cluster's shooting point than this many times its extent (the
/// widest side of its members' bounds) get the members' own outlines; the probe's "near".
pub const REACH: f32 = 3.0;

/// Texels of a part's row in the shader's texture: the head, the normal, `MAX_CORNERS` corners.
pub const ROW_TEXELS: usize = 2 + MAX_CORNERS;

/// A shooter's parts: rows `first..first + count` of its step's parts, used at receivers within
/// `reach` (world units) of its point. `count` 0: a shooter of one outline.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PartRows {
    /// Its first part in the step's parts.
    pub first: u32,
    /// How many.
    pub count: u32,
    /// The distance from the shooting point within which they replace the outline.
    pub reach: f32,
}

/// One member of a face cluster's shot: its outline and normal, and per colour channel its
/// share of the shooter's energy over the outline's area (so that the shooter's energy times
/// Σ weight × factor to the outline is what the members send).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Part {
    /// Share of the shooter's energy / area, RGB.
    pub weight: Vec3,
    /// The member's unit normal.
    pub normal: Vec3,
    /// Its outline, counter-clockwise from its front: `corners[..corner_count]`.
    pub corners: [Vec3; MAX_CORNERS],
    /// Corners of the outline.
    pub corner_count: usize,
}

impl Part {
    /// The outline's corners.
    pub fn outline(&self) -> &[Vec3] {
        &self.corners[..self.corner_count]
    }

    /// The row of the shader's texture: the weight and the corner count, the normal, the
    /// corners (RGBA each).
    pub fn texels(&self) -> [[f32; 4]; ROW_TEXELS] {
        let mut row = [[0.0; 4]; ROW_TEXELS];
        let w = self.weight;
        row[0] = [w.x, w.y, w.z, self.corner_count as f32];
        row[1] = self.normal.extend(0.0).to_array();
        for (texel, c) in row[2..].iter_mut().zip(self.outline()) {
            *texel = c.extend(1.0).to_array();
        }
        row
    }
}

/// The parts of the face clusters among `shooters` (whose `members` have `face`), in shooter
/// order; each such shooter's [`PartRows`] set to its own.
pub fn parts_of(
    scene: &Scene,
    layout: &PatchLayout,
    shooters: &mut [Shooter],
    members: &[Member],
) -> Vec<Part> {
    let mut parts = Vec::new();
    for (i, shooter) in shooters.iter_mut().enumerate() {
        let own = || members.iter().filter(move |m| m.face && m.shooter == i);
        if own().next().is_none() {
            continue;
        }
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        let first = parts.len() as u32;
        for m in own() {
            let polygon = &scene.polygons[m.polygon];
            for &v in &polygon.vertices {
                (lo, hi) = (lo.min(v), hi.max(v));
            }
            let lm = &layout.lightmaps[m.polygon];
            let (corners, corner_count, area) =
                lm.polygon_outline::<MAX_CORNERS>(&polygon.vertices);
            let share = |e: f32, total: f32| if total != 0.0 { e / total } else { 0.0 };
            let (e, total) = (m.energy, shooter.energy);
            let weight = Vec3::new(
                share(e.x, total.x),
                share(e.y, total.y),
                share(e.z, total.z),
            );
            parts.push(Part {
                weight: if area > 0.0 {
                    weight / area
                } else {
                    Vec3::ZERO
                },
                normal: polygon.normal,
                corners,
                corner_count,
            });
        }
        shooter.parts = PartRows {
            first,
            count: parts.len() as u32 - first,
            reach: REACH * (hi - lo).max_element(),
        };
    }
    parts
}
