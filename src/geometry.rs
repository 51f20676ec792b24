//! Small geometry shared by the scene, the patches and the passes, one copy each: planes,
//! bounding boxes and spheres, and polygons in a plane's own 2D coordinates (flattening,
//! clipping, area, point in polygon). Nothing here knows about scenes or GL.

use glam::{Vec2, Vec3};

/// A plane `normal·x = offset` (a unit normal; which side is "in front" is the caller's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// The unit normal.
    pub normal: Vec3,
    /// `normal·x` on the plane.
    pub offset: f32,
}

impl Plane {
    /// The plane with this normal through `point`.
    pub fn through(normal: Vec3, point: Vec3) -> Plane {
        Plane {
            normal,
            offset: normal.dot(point),
        }
    }

    /// Signed distance of `p` (positive in front, on the normal's side).
    pub fn distance(&self, p: Vec3) -> f32 {
        self.normal.dot(p) - self.offset
    }

    /// The same plane facing the other way.
    pub fn flipped(&self) -> Plane {
        Plane {
            normal: -self.normal,
            offset: -self.offset,
        }
    }
}

/// The axis-aligned bounding box (min, max) of `points`; `None` when there are none.
pub fn bounds(points: &[Vec3]) -> Option<(Vec3, Vec3)> {
    let first = *points.first()?;
    Some(
        points
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
    )
}

/// The mean of `points` (not empty).
pub fn mean(points: &[Vec3]) -> Vec3 {
    points.iter().fold(Vec3::ZERO, |s, &v| s + v) / points.len() as f32
}

/// A sphere around `points` centred on `centre`: (centre, distance to the farthest point).
pub fn sphere_around(centre: Vec3, points: &[Vec3]) -> (Vec3, f32) {
    let radius = points.iter().map(|v| v.distance(centre));
    (centre, radius.fold(0.0, f32::max))
}

/// `points` in the 2D coordinates of a plane spanned by `u` and `v`: (p·u, p·v).
pub fn flatten(points: &[Vec3], u: Vec3, v: Vec3) -> impl Iterator<Item = Vec2> + '_ {
    points.iter().map(move |p| Vec2::new(p.dot(u), p.dot(v)))
}

/// The rectangle [lo, hi] as a counter-clockwise outline, starting at `lo`.
pub fn rectangle(lo: Vec2, hi: Vec2) -> [Vec2; 4] {
    [lo, Vec2::new(hi.x, lo.y), hi, Vec2::new(lo.x, hi.y)]
}

/// `subject` clipped to the convex, counter-clockwise `clip` polygon (Sutherland–Hodgman), both
/// in one plane's 2D coordinates. `None` when `clip` is not convex.
pub fn clip_convex(subject: &[Vec2], clip: &[Vec2]) -> Option<Vec<Vec2>> {
    let n = clip.len();
    let turn =
        |k: usize| (clip[(k + 1) % n] - clip[k]).perp_dot(clip[(k + 2) % n] - clip[(k + 1) % n]);
    if (0..n).any(|k| turn(k) < -1e-6 * (clip[(k + 1) % n] - clip[k]).length_squared()) {
        return None;
    }
    let mut out: Vec<Vec2> = subject.to_vec();
    for k in 0..n {
        let (a, b) = (clip[k], clip[(k + 1) % n]);
        let side = |p: Vec2| (b - a).perp_dot(p - a);
        let input = std::mem::take(&mut out);
        for i in 0..input.len() {
            let (p, q) = (input[i], input[(i + 1) % input.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                out.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
        if out.is_empty() {
            break;
        }
    }
    Some(out)
}

/// Area of a simple polygon given in 2D (shoelace), positive when counter-clockwise.
pub fn signed_area(points: &[Vec2]) -> f32 {
    let n = points.len();
    0.5 * (0..n)
        .map(|i| points[i].perp_dot(points[(i + 1) % n]))
        .sum::<f32>()
}

/// Even-odd point-in-polygon test in 2D (the rasteriser's rule for a texel centre: the patches
/// of a lightmap are the texels whose centres pass it).
pub fn point_in_polygon(outline: &[Vec2], p: Vec2) -> bool {
    let mut inside = false;
    let n = outline.len();
    for i in 0..n {
        let (a, b) = (outline[i], outline[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_clipped_by_a_triangle() {
        let square = rectangle(Vec2::ZERO, Vec2::ONE);
        assert_eq!(signed_area(&square), 1.0);
        let triangle = [Vec2::ZERO, Vec2::new(2.0, 0.0), Vec2::new(0.0, 2.0)];
        let cut = clip_convex(&square, &triangle).unwrap();
        assert_eq!(signed_area(&cut), 1.0);
        let half = [Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)];
        assert!((signed_area(&clip_convex(&square, &half).unwrap()) - 0.5).abs() < 1e-6);
        assert!(point_in_polygon(&half, Vec2::splat(0.25)));
        assert!(!point_in_polygon(&half, Vec2::splat(0.75)));
        // A clip outline turning clockwise somewhere is not convex.
        let dent = [
            Vec2::ZERO,
            Vec2::new(2.0, 0.0),
            Vec2::splat(0.5),
            Vec2::new(0.0, 2.0),
        ];
        assert!(clip_convex(&square, &dent).is_none());
    }

    #[test]
    fn planes_spheres_and_boxes() {
        let plane = Plane::through(Vec3::Y, Vec3::new(5.0, 2.0, -1.0));
        assert_eq!(plane.distance(Vec3::new(0.0, 3.0, 0.0)), 1.0);
        assert_eq!(plane.flipped().distance(Vec3::new(0.0, 3.0, 0.0)), -1.0);
        let points = [
            Vec3::ZERO,
            Vec3::X * 2.0,
            Vec3::Y * 2.0,
            Vec3::new(2.0, 2.0, 0.0),
        ];
        assert_eq!(mean(&points), Vec3::new(1.0, 1.0, 0.0));
        let (centre, radius) = sphere_around(mean(&points), &points);
        assert_eq!(centre, Vec3::new(1.0, 1.0, 0.0));
        assert!((radius - 2f32.sqrt()).abs() < 1e-6);
        assert_eq!(
            bounds(&points),
            Some((Vec3::ZERO, Vec3::new(2.0, 2.0, 0.0)))
        );
        assert_eq!(bounds(&[]), None);
        let flat: Vec<Vec2> = flatten(&points, Vec3::X, Vec3::Y).collect();
        assert_eq!(flat[3], Vec2::new(2.0, 2.0));
    }
}
