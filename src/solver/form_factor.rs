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
///
/// Within `slack` world units (`Scene::plane_slack`) of a plane counts as on it, and a point on
/// the polygon's plane, or a polygon lying in the point's tangent plane, gets 0: the exact value
/// (the polygon is seen edge-on), where the contour integral of float-noise heights reads
/// anything up to 1. Scenes made by exporters put such pairs everywhere: the two faces of a
/// double-sided quad lie back to back, and a plant of crossed quads has each quad's centre on
/// the other (Lost Empire's flowers read 1 and 0.5: shots delivering 3.7 times what they carried).
pub fn polygon(x: Vec3, n: Vec3, corners: &[Vec3], polygon_normal: Vec3, slack: f32) -> f32 {
    let Some(&last) = corners.last() else {
        return 0.0;
    };
    if polygon_normal.dot(x - corners[0]) <= slack {
        return 0.0;
    }
    let mut a = last - x;
    let mut da = a.dot(n);
    let (mut sum, mut exit, mut entry) = (0.0, Vec3::ZERO, Vec3::ZERO);
    let mut highest = da;
    for &corner in corners {
        let b = corner - x;
        let db = b.dot(n);
        highest = highest.max(db);
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
    if highest <= slack {
        return 0.0;
    }
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

    /// 1e-5 of a scene a unit across (`Scene::plane_slack`).
    const SLACK: f32 = 1e-5;

    #[test]
    fn matches_the_closed_forms() {
        let f = polygon(Vec3::ZERO, Vec3::Z, &square(1.0), Vec3::NEG_Z, SLACK);
        assert!((f - 0.13853).abs() < 1e-4, "{f}");
        assert!((corner_factor(1.0, 1.0, 1.0) - 0.13853).abs() < 1e-4);
        let centred: Vec<Vec3> = square(1.0)
            .iter()
            .map(|p| *p - Vec3::new(0.5, 0.5, 0.0))
            .collect();
        assert!(
            (polygon(Vec3::ZERO, Vec3::Z, &centred, Vec3::NEG_Z, SLACK) - 0.23946).abs() < 1e-4
        );
        let near: Vec<Vec3> = centred
            .iter()
            .map(|p| *p - Vec3::new(0.0, 0.0, 0.5))
            .collect();
        assert!((polygon(Vec3::ZERO, Vec3::Z, &near, Vec3::NEG_Z, SLACK) - 0.55413).abs() < 1e-4);
        // Behind the polygon: nothing.
        assert_eq!(
            polygon(
                Vec3::new(0.0, 0.0, 2.0),
                Vec3::Z,
                &square(1.0),
                Vec3::NEG_Z,
                SLACK
            ),
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
        let f = polygon(Vec3::new(0.001, 0.0, 0.5), Vec3::Y, &wall, Vec3::X, SLACK);
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

    #[test]
    fn a_polygon_seen_edge_on_sends_nothing() {
        // Lost Empire's flowers: the two faces of a double-sided quad back to back (float noise
        // apart), and a second quad crossing the first through its centre. The contour integral
        // at noise heights read 1 and 0.5.
        let quad = |u: Vec3| {
            let v = Vec3::Y;
            [-u - v, u - v, u + v, -u + v].map(|c| c * 0.5)
        };
        let front = Vec3::new(1.0, 0.0, 1.0).normalize();
        let along = Vec3::new(1.0, 0.0, -1.0).normalize();
        let shooter = quad(-along);
        let noise = Vec3::splat(-4e-7);
        assert_eq!(polygon(noise, -front, &shooter, front, SLACK), 0.0);
        assert_eq!(polygon(-noise, -front, &shooter, front, SLACK), 0.0);
        assert_eq!(polygon(noise, along, &shooter, front, SLACK), 0.0);
        assert_eq!(polygon(Vec3::ZERO, -along, &shooter, front, SLACK), 0.0);
        // Just beyond the slack, the back face's twin facing it is a receiver again: the
        // polygon covers nearly all of its hemisphere.
        let beyond = polygon(front * 3.0 * SLACK, -front, &shooter, front, SLACK);
        assert!(beyond > 0.99, "{beyond}");
        // Without the slack the noise decides (what the solver did): up to all of it.
        assert!(polygon(-noise, -front, &shooter, front, 0.0) > 0.99);
        // Clear of the plane, the factor is the closed form's: a receiver facing the quad's
        // centre from half its side away.
        let facing = polygon(front * 0.5, -front, &shooter, front, SLACK);
        assert!((facing - 0.55413).abs() < 1e-4, "{facing}");
    }
}
