//! Form factors on the CPU: the same formulas the reconstruction shader evaluates (tests hold the
//! GPU against these, and the CPU solver uses them).
//!
//! - `point`: the paper's F = cos θ_i cos θ_j / (π r²), per unit shooter area, each cosine
//!   clamped at zero (a receiver behind the shooter or facing away gets nothing).
//! - `polygon`: the exact factor from a differential receiver area to a polygon (Lambert's
//!   contour formula), after clipping the polygon to the receiver's side of its tangent plane.
//!   It stays finite however close the receiver is, which the point factor does not.

use glam::Vec3;
use std::f32::consts::PI;

/// Point-to-point kernel cos θ_i cos θ_j / (π r²): multiply by the shooter's area for a factor.
/// Each cosine is clamped at zero on its own: a receiver behind the shooter's plane, or facing
/// away from the shooter, gets nothing. (The paper clamps the product, max(cos θ_i cos θ_j, 0),
/// which passes a receiver that is both: two negative cosines.)
pub fn point(receiver: Vec3, receiver_normal: Vec3, shooter: Vec3, shooter_normal: Vec3) -> f32 {
    let r = shooter - receiver;
    let d2 = r.dot(r);
    let r = r / d2.sqrt();
    receiver_normal.dot(r).max(0.0) * (-shooter_normal.dot(r)).max(0.0) / (PI * d2)
}

/// One edge's term of Lambert's contour integral, corners `a` to `b` relative to the receiver:
/// the angle the edge subtends times the cosine between its plane and the receiver's normal.
fn edge_term(a: Vec3, b: Vec3, n: Vec3) -> f32 {
    let c = a.cross(b);
    let len = c.length();
    if len > 0.0 {
        len.atan2(a.dot(b)) * c.dot(n) / len
    } else {
        0.0
    }
}

/// Factor from a differential area at `x` (normal `n`) to the convex polygon `corners` (normal
/// `polygon_normal`); 0 when `x` is behind the polygon. The polygon is clipped to the receiver's
/// side of its tangent plane edge by edge, as `glsl/reconstruct.frag` does: a convex outline
/// leaves that side at most once and comes back at most once, so the clipped outline is the
/// edges above the plane, cut where they cross it, closed by one edge from the exit to the entry
/// point (no list of clipped corners, no allocation).
pub fn polygon(x: Vec3, n: Vec3, corners: &[Vec3], polygon_normal: Vec3) -> f32 {
    let Some(&last) = corners.last() else {
        return 0.0;
    };
    if polygon_normal.dot(x - corners[0]) <= 0.0 {
        return 0.0;
    }
    let mut a = last - x;
    let mut da = a.dot(n);
    let (mut sum, mut exit, mut entry) = (0.0, Vec3::ZERO, Vec3::ZERO);
    for &corner in corners {
        let b = corner - x;
        let db = b.dot(n);
        let cut = || a + (b - a) * (da / (da - db));
        match (da > 0.0, db > 0.0) {
            (true, true) => sum += edge_term(a, b, n),
            (true, false) => {
                exit = cut();
                sum += edge_term(a, exit, n);
            }
            (false, true) => {
                entry = cut();
                sum += edge_term(entry, b, n);
            }
            (false, false) => {}
        }
        a = b;
        da = db;
    }
    sum += edge_term(exit, entry, n);
    (sum.abs() / (2.0 * PI)).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/conventions.md: differential area parallel to a rectangle, normal through a corner.
    fn corner_factor(a: f32, b: f32, c: f32) -> f32 {
        let (aa, bb) = (a / c, b / c);
        let (sa, sb) = ((1.0 + aa * aa).sqrt(), (1.0 + bb * bb).sqrt());
        (aa / sa * (bb / sa).atan() + bb / sb * (aa / sb).atan()) / (2.0 * PI)
    }

    fn square(c: f32) -> Vec<Vec3> {
        // Facing down (-z) at height c, seen from the origin below: counter-clockwise from below.
        vec![
            Vec3::new(0., 0., c),
            Vec3::new(0., 1., c),
            Vec3::new(1., 1., c),
            Vec3::new(1., 0., c),
        ]
    }

    #[test]
    fn matches_the_closed_forms() {
        let f = polygon(Vec3::ZERO, Vec3::Z, &square(1.0), Vec3::NEG_Z);
        assert!((f - 0.13853).abs() < 1e-4, "{f}");
        assert!((corner_factor(1.0, 1.0, 1.0) - 0.13853).abs() < 1e-4);
        let centred: Vec<Vec3> = square(1.0)
            .iter()
            .map(|p| *p - Vec3::new(0.5, 0.5, 0.0))
            .collect();
        assert!((polygon(Vec3::ZERO, Vec3::Z, &centred, Vec3::NEG_Z) - 0.23946).abs() < 1e-4);
        let near: Vec<Vec3> = centred
            .iter()
            .map(|p| *p - Vec3::new(0.0, 0.0, 0.5))
            .collect();
        assert!((polygon(Vec3::ZERO, Vec3::Z, &near, Vec3::NEG_Z) - 0.55413).abs() < 1e-4);
        // Behind the polygon: nothing.
        assert_eq!(
            polygon(Vec3::new(0.0, 0.0, 2.0), Vec3::Z, &square(1.0), Vec3::NEG_Z),
            0.0
        );
    }

    #[test]
    fn clipping_keeps_a_perpendicular_neighbour_finite() {
        // A receiver on the floor right next to a wall: finite, below the 1/2 of a half-space.
        let wall = [
            Vec3::new(0., 0., 0.),
            Vec3::new(0., 0., 1.),
            Vec3::new(0., 1., 1.),
            Vec3::new(0., 1., 0.),
        ];
        let f = polygon(Vec3::new(0.001, 0.0, 0.5), Vec3::Y, &wall, Vec3::X);
        assert!(f > 0.45 && f < 0.5, "{f}");
        // The point factor of a unit-area shooter 5 cm away is over 30: energy out of nothing.
        assert!(
            point(
                Vec3::new(0.05, 0.0, 0.5),
                Vec3::Y,
                Vec3::new(0.0, 0.05, 0.5),
                Vec3::X
            ) > 30.0
        );
    }
}
