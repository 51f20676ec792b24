//! Polygons that fall between the pixel centres (`Tuning::cull_between_samples`). The item
//! buffer is single-sampled: the rasteriser makes a fragment only where a pixel's centre lies
//! inside a triangle. A polygon whose projected corners span no pixel centre across (or none
//! up and down) covers none, so drawing it changes no pixel; leaving it out of the view keeps
//! the item buffer as it is. In the complex room most shots draw 16² to 60² per face, where a
//! book's spine is a fraction of a pixel, and the books are most of the triangles.

use crate::scene::Scene;
use glam::{Mat4, Vec3};

use super::plates::Plates;

/// How far outside its projected corners a polygon may still make a fragment, in pixels: more
/// than llvmpipe's vertex snapping (1/256 pixel) and the float noise between our transform and
/// the GPU's.
const MARGIN: f32 = 1.0 / 32.0;

/// Projected wider than this many pixels (bounding sphere, across), a polygon is taken as drawn
/// without looking at its corners: it spans a centre nearly always.
pub const MAX_EXTENT: f32 = 2.0;

/// Each drawn polygon's outline as the visibility pass's mesh has it: its own corners, or its
/// plate's for a plate's representative.
#[derive(Clone, Debug, Default)]
pub struct Outlines {
    start: Vec<usize>,
    points: Vec<Vec3>,
}

impl Outlines {
    /// Every polygon's outline: its plate's for a representative, else its own corners.
    pub fn new(scene: &Scene, plates: &Plates) -> Outlines {
        let mut outlines = Outlines {
            start: Vec::with_capacity(scene.polygons.len() + 1),
            points: Vec::new(),
        };
        for (p, polygon) in scene.polygons.iter().enumerate() {
            outlines.start.push(outlines.points.len());
            let outline = plates.outlines.get(&p).unwrap_or(&polygon.vertices);
            outlines.points.extend_from_slice(outline);
        }
        outlines.start.push(outlines.points.len());
        outlines
    }

    /// Polygon `p`'s outline.
    pub fn of(&self, p: usize) -> &[Vec3] {
        &self.points[self.start[p]..self.start[p + 1]]
    }
}

/// Whether `outline`, taken to a hemicube face's eye space by `face` (looking down -z, a 90°
/// frustum), covers no pixel centre of that face drawn `r` pixels wide. False whenever a
/// corner lies nearer than `near` (clipping would move the corners).
pub fn misses_every_centre(outline: &[Vec3], face: &Mat4, r: f32, near: f32) -> bool {
    let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
    for &corner in outline {
        let c = face.transform_point3(corner);
        if -c.z <= near {
            return false;
        }
        // Pixel coordinates within the face: tangent -1..1 across r pixels.
        let pixel = (glam::Vec2::new(c.x, c.y) / -c.z + 1.0) * (0.5 * r);
        lo = lo.min(pixel);
        hi = hi.max(pixel);
    }
    // Centres lie at i + 0.5: none in [lo, hi] when the first centre at or after lo lies
    // beyond hi, on either axis.
    let first = (lo - 0.5 - MARGIN).ceil();
    let last = (hi - 0.5 + MARGIN).floor();
    first.x > last.x || first.y > last.y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(centre: Vec3, half: f32) -> Vec<Vec3> {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, y)| centre + Vec3::new(x * half, y * half, 0.0))
            .collect()
    }

    #[test]
    fn a_square_between_centres_is_missed_and_one_over_a_centre_is_not() {
        // At distance 1 and r = 4, a pixel spans 0.5 in tangent; pixel centres lie at tangent
        // -0.75, -0.25, 0.25, 0.75.
        let face = Mat4::IDENTITY;
        let between = square(Vec3::new(0.0, 0.0, -1.0), 0.2);
        assert!(misses_every_centre(&between, &face, 4.0, 1e-3));
        let over = square(Vec3::new(0.25, 0.25, -1.0), 0.01);
        assert!(!misses_every_centre(&over, &face, 4.0, 1e-3));
        // Spanning a centre across but not up and down: missed.
        let wide = square(Vec3::new(0.25, 0.0, -1.0), 0.1);
        assert!(misses_every_centre(&wide, &face, 4.0, 1e-3));
        // A corner within the margin of a centre counts as covering it.
        let touching = square(Vec3::new(0.25 - 0.1, 0.25, -1.0), 0.1 - 1e-3);
        assert!(!misses_every_centre(&touching, &face, 4.0, 1e-3));
    }

    #[test]
    fn corners_near_or_behind_the_eye_are_never_missed() {
        let face = Mat4::IDENTITY;
        let near = square(Vec3::new(0.0, 0.0, -1e-4), 1e-6);
        assert!(!misses_every_centre(&near, &face, 4.0, 1e-3));
        let behind = square(Vec3::new(0.0, 0.0, 1.0), 0.01);
        assert!(!misses_every_centre(&behind, &face, 4.0, 1e-3));
    }
}
