//! Ear clipping of a planar polygon into triangles for drawing. Polygons stay whole everywhere
//! else (one lightmap, one shooter); only the rasterizer needs triangles.

use crate::geometry::flatten;
use glam::{Vec2, Vec3};

/// Triangles as index triples into `vertices`, counter-clockwise like the polygon.
pub fn triangulate(vertices: &[Vec3], normal: Vec3) -> Vec<[usize; 3]> {
    // A vertex repeated next to itself adds no corner but blocks every ear: triangulate the
    // distinct corners and map back to the caller's indices.
    let mut keep: Vec<usize> = (0..vertices.len()).collect();
    keep.dedup_by(|b, a| vertices[*a] == vertices[*b]);
    while keep.len() > 3 && vertices[keep[0]] == vertices[*keep.last().unwrap()] {
        keep.pop();
    }
    if keep.len() < vertices.len() {
        let distinct: Vec<Vec3> = keep.iter().map(|&i| vertices[i]).collect();
        if distinct.len() < 3 {
            return Vec::new();
        }
        return triangulate(&distinct, normal)
            .into_iter()
            .map(|t| t.map(|k| keep[k]))
            .collect();
    }
    let u = (vertices[1] - vertices[0]).normalize_or_zero();
    let u = if u == Vec3::ZERO {
        normal.any_orthonormal_vector()
    } else {
        u
    };
    let v = normal.cross(u);
    let flat: Vec<Vec2> = flatten(vertices, u, v).collect();
    let mut remaining: Vec<usize> = (0..vertices.len()).collect();
    let mut triangles = Vec::with_capacity(vertices.len().saturating_sub(2));
    let cross = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - a);
    while remaining.len() > 3 {
        let n = remaining.len();
        let ear = (0..n).find(|&i| {
            let (a, b, c) = (
                remaining[(i + n - 1) % n],
                remaining[i],
                remaining[(i + 1) % n],
            );
            let (pa, pb, pc) = (flat[a], flat[b], flat[c]);
            cross(pa, pb, pc) > 0.0
                && remaining.iter().all(|&k| {
                    k == a || k == b || k == c || {
                        let p = flat[k];
                        // Outside (or on the edge of) the candidate ear.
                        cross(pa, pb, p) < 0.0 || cross(pb, pc, p) < 0.0 || cross(pc, pa, p) < 0.0
                    }
                })
        });
        // A polygon with no ear (self-intersecting or collinear) falls back to a fan.
        let i = ear.unwrap_or(1);
        triangles.push([
            remaining[(i + n - 1) % n],
            remaining[i],
            remaining[(i + 1) % n],
        ]);
        remaining.remove(i);
    }
    triangles.push([remaining[0], remaining[1], remaining[2]]);
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn l_shape_gives_four_triangles_covering_its_area() {
        let pts: Vec<Vec3> = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)]
            .iter()
            .map(|&(x, y)| Vec3::new(x, y, 0.0))
            .collect();
        let tris = triangulate(&pts, Vec3::Z);
        assert_eq!(tris.len(), 4);
        let area: f32 = tris
            .iter()
            .map(|t| 0.5 * (pts[t[1]] - pts[t[0]]).cross(pts[t[2]] - pts[t[0]]).z)
            .sum();
        assert!((area - 3.0).abs() < 1e-5, "area {area}");
    }
}
