//! Coplanar faces that overlap, facing the same way: each would receive the full light that
//! reaches their common area, so a shot would reflect more than it received (a floor given three
//! times reflected 1.2x the emitted power with Kd 0.7). Exact duplicates are dropped with a
//! warning; partial overlaps are refused. Near-linear: polygons are grouped by plane with a hash,
//! and within a plane only those whose boxes share a grid cell are compared.

use super::triangulate::triangulate;
use super::Polygon;
use glam::{DVec2, Vec3};
use std::collections::HashMap;

/// Two faces of one plane that overlap.
#[derive(Debug)]
pub struct Overlap {
    pub a: usize,
    pub b: usize,
}

/// Remove exact duplicates (the same corners in the same turning order) from `polygons`;
/// returns how many were removed, with the object names of the first few.
pub fn drop_duplicates(polygons: &mut Vec<Polygon>) -> (usize, Vec<String>) {
    let mut seen: HashMap<Vec<[u32; 3]>, usize> = HashMap::with_capacity(polygons.len());
    let mut keep = vec![true; polygons.len()];
    let mut names = Vec::new();
    let mut dropped = 0;
    for (i, p) in polygons.iter().enumerate() {
        let bits: Vec<[u32; 3]> = p
            .vertices
            .iter()
            .map(|v| v.to_array().map(f32::to_bits))
            .collect();
        // The same cycle whatever its starting corner: start at the smallest.
        let start = (0..bits.len()).min_by_key(|&k| bits[k]).unwrap_or(0);
        let key: Vec<[u32; 3]> = (0..bits.len())
            .map(|k| bits[(start + k) % bits.len()])
            .collect();
        if let Some(&first) = seen.get(&key) {
            keep[i] = false;
            dropped += 1;
            if names.len() < 5 {
                names.push(format!("'{}' = '{}'", polygons[first].object, p.object));
            }
        } else {
            seen.insert(key, i);
        }
    }
    let mut k = 0;
    polygons.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    (dropped, names)
}

/// The first overlap of two coplanar same-facing polygons (their interiors share an area larger
/// than float noise), if any. `slack`: world units within which a point is on a plane.
pub fn find_overlap(polygons: &[Polygon], slack: f32) -> Option<Overlap> {
    let mut groups: HashMap<[i64; 4], Vec<usize>> = HashMap::new();
    let cell = (10.0 * slack).max(f32::MIN_POSITIVE) as f64;
    for (i, p) in polygons.iter().enumerate() {
        let d = p.plane().offset as f64;
        let key = [
            (p.normal.x * 1e3).round() as i64,
            (p.normal.y * 1e3).round() as i64,
            (p.normal.z * 1e3).round() as i64,
            (d / cell).round() as i64,
        ];
        groups.entry(key).or_default().push(i);
    }
    let mut keys: Vec<_> = groups.keys().copied().collect();
    keys.sort_unstable();
    for key in keys {
        let members = &groups[&key];
        if members.len() > 1 {
            if let Some(o) = overlap_in_plane(polygons, members) {
                return Some(o);
            }
        }
    }
    None
}

fn overlap_in_plane(polygons: &[Polygon], members: &[usize]) -> Option<Overlap> {
    let normal = polygons[members[0]].normal;
    let (u, v) = normal.any_orthonormal_pair();
    let origin = polygons[members[0]].vertices[0];
    let flat = |p: &Polygon| -> Vec<DVec2> {
        p.vertices
            .iter()
            .map(|&q| {
                let d = (q - origin).as_dvec3();
                DVec2::new(d.dot(u.as_dvec3()), d.dot(v.as_dvec3()))
            })
            .collect()
    };
    let outlines: Vec<Vec<DVec2>> = members.iter().map(|&m| flat(&polygons[m])).collect();
    let boxes: Vec<(DVec2, DVec2)> = outlines
        .iter()
        .map(|o| {
            o.iter().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            })
        })
        .collect();
    // Grid broad phase: cells the size of the median box; a box covering many cells is kept
    // aside and compared with every box of the plane (few are that large).
    let mut sizes: Vec<f64> = boxes
        .iter()
        .map(|(lo, hi)| (*hi - *lo).max_element())
        .collect();
    sizes.sort_by(f64::total_cmp);
    let cell = sizes[sizes.len() / 2].max(1e-30);
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    let mut large = Vec::new();
    let index = |x: f64| (x / cell).floor() as i64;
    for (k, (lo, hi)) in boxes.iter().enumerate() {
        let (x0, x1, y0, y1) = (index(lo.x), index(hi.x), index(lo.y), index(hi.y));
        if (x1 - x0 + 1) * (y1 - y0 + 1) > 16 {
            large.push(k);
            continue;
        }
        for x in x0..=x1 {
            for y in y0..=y1 {
                grid.entry((x, y)).or_default().push(k);
            }
        }
    }
    let triangles: Vec<Vec<[DVec2; 3]>> = members
        .iter()
        .zip(&outlines)
        .map(|(&m, o)| {
            triangulate(&polygons[m].vertices, normal)
                .into_iter()
                .map(|t| t.map(|i| o[i]))
                .collect()
        })
        .collect();
    let boxes_meet = |a: usize, b: usize| {
        let (p, q) = (boxes[a], boxes[b]);
        p.0.x < q.1.x && q.0.x < p.1.x && p.0.y < q.1.y && q.0.y < p.1.y
    };
    let test = |a: usize, b: usize| -> Option<Overlap> {
        (a != b && boxes_meet(a, b) && overlap(&triangles[a], &triangles[b])).then(|| Overlap {
            a: members[a.min(b)],
            b: members[a.max(b)],
        })
    };
    let mut keys: Vec<_> = grid.keys().copied().collect();
    keys.sort_unstable();
    for key in keys {
        let cell = &grid[&key];
        for (i, &a) in cell.iter().enumerate() {
            for &b in &cell[i + 1..] {
                if let Some(o) = test(a, b) {
                    return Some(o);
                }
            }
        }
    }
    for &a in &large {
        for b in 0..members.len() {
            if let Some(o) = test(a, b) {
                return Some(o);
            }
        }
    }
    None
}

/// Do two triangulated outlines share area? Triangles of each are tested pairwise with the
/// separating-axis test, shared edges and corners (tiles side by side) not counting.
fn overlap(a: &[[DVec2; 3]], b: &[[DVec2; 3]]) -> bool {
    a.iter().any(|s| b.iter().any(|t| triangles_overlap(s, t)))
}

fn triangles_overlap(s: &[DVec2; 3], t: &[DVec2; 3]) -> bool {
    let size = s
        .iter()
        .chain(t)
        .fold(0.0f64, |m, p| m.max(p.x.abs()).max(p.y.abs()));
    // Penetration deeper than float noise of coordinates of this magnitude.
    let eps = 1e-5 * size;
    for tri in [s, t] {
        let orient = (tri[1] - tri[0]).perp_dot(tri[2] - tri[0]).signum();
        for i in 0..3 {
            let (p, q) = (tri[i], tri[(i + 1) % 3]);
            let edge = q - p;
            let len = edge.length();
            if len == 0.0 {
                return false;
            }
            // Outward normal of this edge.
            let n = DVec2::new(edge.y, -edge.x) * orient / len;
            let limit = n.dot(p);
            let other = if std::ptr::eq(tri, s) { t } else { s };
            let nearest = other
                .iter()
                .map(|x| n.dot(*x))
                .fold(f64::INFINITY, f64::min);
            if nearest >= limit - eps {
                return false;
            }
        }
    }
    true
}

/// Messages name a polygon by its object and first corner.
pub fn describe(p: &Polygon) -> String {
    let c: Vec3 = p.vertices[0];
    format!(
        "a face of '{}' ({} corners, first at {} {} {})",
        p.object,
        p.vertices.len(),
        c.x,
        c.y,
        c.z
    )
}
