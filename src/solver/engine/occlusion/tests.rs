//! The walk's unit tests: small scenes whose hidden and shown polygons are known.

use super::pieces::{convex, convex_pieces};
use super::*;
use crate::solver::visibility::face_rotations;

/// A shot from the origin looking up +z (its eye space's -z), `r` pixels a face, every
/// pixel drawn.
fn views(r: usize) -> Views {
    Views {
        s: Vec3::ZERO,
        normal: Vec3::Z,
        view: Mat4::look_at_rh(Vec3::ZERO, Vec3::Z, Vec3::Y),
        rotations: face_rotations(),
        r,
        drawn: [[0, 0, r, r]; 5],
    }
}

fn walk(views: &Views) -> Walk<'_> {
    Walk {
        views,
        near: 1e-3 / (2.0 * 3f32.sqrt()),
        clear: 1e-3,
        far: 100.0,
    }
}

fn square(z: f32, half: f32) -> Vec<Vec3> {
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| Vec3::new(x * half, y * half, z))
        .collect()
}

#[test]
fn a_ceiling_over_the_front_face_hides_what_lies_beyond_it_and_nothing_nearer() {
    let v = views(8);
    let w = walk(&v);
    let mut cover = Vec::new();
    v.clear(&mut cover);
    // A ceiling at height 1 reaching 45° each way covers the whole front face.
    w.cover(&mut cover, &square(1.0, 1.01), Vec3::Z, 0b11111, None);
    let front = &cover[..64];
    assert!(front.iter().all(|&d| (1.0..=3f32.sqrt()).contains(&d)));
    // Beyond the ceiling, a box is hidden.
    let (lo, hi) = (Vec3::new(-0.5, -0.5, 2.0), Vec3::new(0.5, 0.5, 3.0));
    assert!(w.hidden(&cover, w.distance(lo, hi), lo, hi));
    // Below it (nearer), it is not.
    let (lo, hi) = (Vec3::new(-0.1, -0.1, 0.5), Vec3::new(0.1, 0.1, 0.6));
    assert!(!w.hidden(&cover, w.distance(lo, hi), lo, hi));
    // Beyond it but reaching past its edge into a side face, where nothing covers: kept.
    let (lo, hi) = (Vec3::new(2.0, -0.5, 1.5), Vec3::new(3.0, 0.5, 2.0));
    assert!(!w.hidden(&cover, w.distance(lo, hi), lo, hi));
}

#[test]
fn a_piece_between_pixel_centres_covers_none_and_an_undrawn_pixel_hides_everything() {
    let mut v = views(4);
    let w = walk(&v);
    let mut cover = Vec::new();
    v.clear(&mut cover);
    // Centres of the front face lie at tangent ±0.25, ±0.75: a square of half 0.2 around
    // the middle covers none.
    w.cover(&mut cover, &square(1.0, 0.2), Vec3::Z, 0b11111, None);
    assert!(cover[..16].iter().all(|d| d.is_infinite()));
    // A face of which nothing is drawn: a box seen only there is hidden.
    v.drawn = [[0, 0, 0, 0]; 5];
    let w = walk(&v);
    v.clear(&mut cover);
    let (lo, hi) = (Vec3::new(-0.5, -0.5, 2.0), Vec3::new(0.5, 0.5, 3.0));
    assert!(w.hidden(&cover, w.distance(lo, hi), lo, hi));
}

#[test]
fn the_written_item_buffer_shows_the_nearest_piece_clipped_to_the_near_plane() {
    let v = views(8);
    let w = walk(&v);
    let (mut cover, mut ids) = (Vec::new(), vec![0u32; 5 * 64]);
    v.clear(&mut cover);
    // Far first, then near: the nearer one shows wherever both reach.
    w.cover(
        &mut cover,
        &square(2.0, 2.1),
        Vec3::Z,
        0b11111,
        Some((&mut ids, 7)),
    );
    w.cover(
        &mut cover,
        &square(1.0, 0.5),
        Vec3::Z,
        0b11111,
        Some((&mut ids, 9)),
    );
    let front = &ids[..64];
    // Centres at tangent ±0.125, ±0.375, …: the near square (tangent ±0.5) covers the 4 × 4
    // in the middle, edges included (its edges pass through no centre here; see below).
    assert_eq!(front.iter().filter(|&&id| id == 9).count(), 16);
    assert_eq!(front.iter().filter(|&&id| id == 7).count(), 48);
    // A wall at x = 1 from behind the eye (z = -1) to z = 3, facing it: the front face sees
    // its part in front of the near plane, which the walk's own cover leaves out (a piece
    // reaching behind the eye records nothing there).
    let wall: Vec<Vec3> = [(-1.0, -0.9), (3.0, -0.9), (3.0, 0.9), (-1.0, 0.9)]
        .iter()
        .map(|&(z, y)| Vec3::new(1.0, y, z))
        .collect();
    let (mut exact, mut walked) = (Vec::new(), Vec::new());
    v.clear(&mut exact);
    v.clear(&mut walked);
    let mut ids = vec![0u32; 5 * 64];
    w.cover(&mut exact, &wall, Vec3::NEG_X, 0b00001, Some((&mut ids, 3)));
    w.cover(&mut walked, &wall, Vec3::NEG_X, 0b00001, None);
    // Face space x is world -x here (the eye looks up +z with y up): in the columns at
    // tangent -0.875, -0.625 and -0.375 (depth 1/0.875 to 1/0.375) the wall reaches
    // tangents up to ±0.79, ±0.56 and ±0.34: 6, 4 and 2 centres.
    let shown: Vec<usize> = (0..64).filter(|&i| ids[i] == 3).collect();
    assert_eq!(shown.len(), 12, "{shown:?}");
    assert!(shown.iter().all(|&i| i % 8 < 3), "{shown:?}");
    assert!(walked[..64].iter().all(|d| d.is_infinite()));
    // An edge through a row of centres: the written item buffer counts them as covered.
    let mut ids = vec![0u32; 5 * 64];
    let mut edge = Vec::new();
    v.clear(&mut edge);
    let through: Vec<Vec3> = [(-1.0, -1.0), (0.125, -1.0), (0.125, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, 1.0))
        .collect();
    w.cover(&mut edge, &through, Vec3::Z, 0b00001, Some((&mut ids, 5)));
    assert_eq!(ids[..64].iter().filter(|&&id| id == 5).count(), 5 * 8);
}

#[test]
fn a_box_behind_the_shooters_plane_is_hidden_and_one_touching_it_is_not() {
    let v = views(8);
    let w = walk(&v);
    let mut cover = Vec::new();
    v.clear(&mut cover);
    let behind = (Vec3::new(1.0, 1.0, -2.0), Vec3::new(5.0, 5.0, -0.01));
    assert!(w.hidden(&cover, w.distance(behind.0, behind.1), behind.0, behind.1));
    // Touching the plane: it may cover a pixel centre on the horizon.
    let flat = (Vec3::new(1.0, 1.0, -2.0), Vec3::new(5.0, 5.0, 0.0));
    assert!(!w.hidden(&cover, w.distance(flat.0, flat.1), flat.0, flat.1));
}

#[test]
fn a_concave_outline_becomes_fewer_convex_pieces_than_triangles() {
    // An L of three unit squares: two convex pieces (it cannot be fewer), four triangles.
    let l: Vec<Vec3> = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
        .iter()
        .map(|&(x, y)| Vec3::new(x as f32, y as f32, 0.0))
        .collect();
    let pieces = convex_pieces(&l, Vec3::Z);
    assert_eq!(pieces.len(), 2, "{pieces:?}");
    let corners: Vec<Vec<Vec3>> = (pieces.iter())
        .map(|p| p.iter().map(|&k| l[k]).collect())
        .collect();
    assert!(corners.iter().all(|c| convex(c, Vec3::Z)));
    // Together they cover the L's area, 3.
    let area: f32 = (corners.iter())
        .map(|c| {
            let n = c.len();
            (0..n).map(|i| c[i].cross(c[(i + 1) % n]).z).sum::<f32>() / 2.0
        })
        .sum();
    assert!((area - 3.0).abs() < 1e-6, "{area}");
}

#[test]
fn the_face_axes_are_the_face_rotations() {
    for (k, rotation) in face_rotations().iter().enumerate() {
        for axis in 0..3 {
            let mut v = Vec3::ZERO;
            v[axis] = 1.0;
            let turned = *rotation * v;
            for (row, &(a, sign)) in FACE_AXES[k].iter().enumerate() {
                let expected = if a == axis { sign } else { 0.0 };
                assert_eq!(
                    turned[row], expected,
                    "face {k}, eye axis {axis}, row {row}"
                );
            }
        }
    }
}

#[test]
fn the_tangent_range_of_a_box_reaching_down_to_the_eye_plane_is_bounded_by_its_sign() {
    assert_eq!(tangent_range(1.0, 2.0, -1.0, 2.0), (0.5, 1.0));
    assert_eq!(tangent_range(-2.0, -1.0, -1.0, 2.0), (-1.0, -0.5));
    assert_eq!(tangent_range(-1.0, 1.0, 1.0, 2.0), (-1.0, 1.0));
    assert_eq!(tangent_range(0.5, 1.0, 1.0, 2.0), (0.25, 1.0));
}
