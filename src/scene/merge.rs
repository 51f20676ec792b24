//! Surfaces, not triangles (beyond the paper): connected coplanar faces of one material become one
//! polygon, with one lightmap, before patching.
//!
//! Exporters write a wall as many triangles (a tessellated room, a voxel world's unit quads); as
//! faces, each would be its own lightmap of one or a few texels, so the wall would be faceted and
//! every triangle a shooter. The paper's scenes are modelled with one face per surface; this
//! makes other scenes so.
//!
//! A region grows from a face across shared edges (corners welded by position) to faces of the
//! same material whose corners lie on the region's plane, keeping the region a disk: a face joins
//! only if the edges it shares with the region form one chain and its other corners are new to
//! the region. A face that would close a ring (around a window) or touch the region at a corner
//! only starts, or joins, another region instead, so every region's outline is one simple loop
//! (concave outlines are fine; a hole becomes two polygons around it) and the rest of the
//! program, which takes polygons as one outline each, needs nothing new.

use super::Polygon;
#[cfg(test)]
use glam::DVec3;
use glam::Vec3;
use std::collections::HashMap;

/// How far apart two normals of one region may be: 0.5°.
const MAX_ANGLE_COS: f32 = 0.999_962;

/// What merging did: faces in, polygons out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MergeReport {
    /// Faces before merging.
    pub faces: usize,
    /// Polygons after merging.
    pub polygons: usize,
}

/// Merge connected coplanar faces of one material into single polygons (see the module's
/// comment). `size` is the scene's size (the welding and plane tolerances are 1e-6 and 1e-5 of
/// it). The merged polygons take the object name of their first face; their order follows
/// their first faces.
pub fn merge_coplanar(polygons: &mut Vec<Polygon>, size: f32) -> MergeReport {
    let faces = polygons.len();
    let weld = (1e-6 * size as f64).max(f64::MIN_POSITIVE);
    let plane_slack = 1e-5 * size;
    // Corners welded by position: a grid of `weld`-sized cells.
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    let corner_ids: Vec<Vec<u32>> = polygons
        .iter()
        .map(|p| {
            p.vertices
                .iter()
                .map(|v| {
                    let key = (v.as_dvec3() / weld).round().as_i64vec3().to_array();
                    let next = ids.len() as u32;
                    *ids.entry(key).or_insert(next)
                })
                .collect()
        })
        .collect();
    // Directed edge (a, b) → the face that has it.
    let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
    let mut shared_twice = Vec::new();
    for (f, c) in corner_ids.iter().enumerate() {
        for k in 0..c.len() {
            let e = (c[k], c[(k + 1) % c.len()]);
            if edges.insert(e, f).is_some() {
                shared_twice.push(e);
            }
        }
    }
    // An edge given twice in one direction is not a manifold edge: nothing merges across it.
    for e in shared_twice {
        edges.remove(&e);
    }
    let neighbour = |f: usize, k: usize| -> Option<usize> {
        let c = &corner_ids[f];
        let (a, b) = (c[k], c[(k + 1) % c.len()]);
        edges.get(&(b, a)).copied().filter(|&g| g != f)
    };

    let mut region_of = vec![usize::MAX; faces];
    let mut regions: Vec<Vec<usize>> = Vec::new();
    for seed in 0..faces {
        if region_of[seed] != usize::MAX {
            continue;
        }
        let r = regions.len();
        region_of[seed] = r;
        let mut members = vec![seed];
        let mut corners: std::collections::HashSet<u32> =
            corner_ids[seed].iter().copied().collect();
        let normal = polygons[seed].normal;
        let plane = polygons[seed].plane();
        let material = polygons[seed].material;
        let mut queue = vec![seed];
        while let Some(f) = queue.pop() {
            for k in 0..corner_ids[f].len() {
                let Some(g) = neighbour(f, k) else { continue };
                if region_of[g] != usize::MAX {
                    continue;
                }
                let candidate = &polygons[g];
                if candidate.material != material
                    || candidate.normal.dot(normal) < MAX_ANGLE_COS
                    || candidate
                        .vertices
                        .iter()
                        .any(|v| plane.distance(*v).abs() > plane_slack)
                    || !keeps_a_disk(
                        &corner_ids[g],
                        |k| neighbour(g, k).is_some_and(|h| region_of[h] == r),
                        &corners,
                    )
                {
                    continue;
                }
                region_of[g] = r;
                corners.extend(corner_ids[g].iter().copied());
                members.push(g);
                queue.push(g);
            }
        }
        regions.push(members);
    }

    let mut merged: Vec<(usize, Polygon)> = Vec::with_capacity(regions.len());
    let positions = corner_positions(polygons, &corner_ids);
    for members in &regions {
        let first = members[0];
        if members.len() == 1 {
            merged.push((first, polygons[first].clone()));
            continue;
        }
        let outline = outline(members, &corner_ids, &region_of, &neighbour);
        let vertices = without_straight_corners(outline.iter().map(|id| positions[id]).collect());
        let p = &polygons[first];
        match Polygon::new(vertices, p.material, p.object.clone()) {
            // The area must come out as the faces': otherwise the loop is not the region's
            // outline (it cannot happen for a disk; this keeps the faces if it ever does).
            Some(q)
                if (q.area as f64
                    - members
                        .iter()
                        .map(|&f| polygons[f].area as f64)
                        .sum::<f64>())
                .abs()
                    <= 1e-3 * q.area as f64 =>
            {
                merged.push((first, q))
            }
            _ => merged.extend(members.iter().map(|&f| (f, polygons[f].clone()))),
        }
    }
    merged.sort_by_key(|(first, _)| *first);
    *polygons = merged.into_iter().map(|(_, p)| p).collect();
    MergeReport {
        faces,
        polygons: polygons.len(),
    }
}

/// Does a face with corners `c` keep the region a disk? Its edges shared with the region
/// (`shared(k)` for the edge from corner k) must form one chain, and its other corners must all
/// be new to the region (`corners`): else it would close a ring or touch the region at a corner.
fn keeps_a_disk(
    c: &[u32],
    shared: impl Fn(usize) -> bool,
    corners: &std::collections::HashSet<u32>,
) -> bool {
    let n = c.len();
    let is_shared: Vec<bool> = (0..n).map(&shared).collect();
    let k = is_shared.iter().filter(|&&s| s).count();
    if k == 0 || k == n {
        return false;
    }
    // One run of shared edges around the cycle: exactly one place where a shared edge follows an
    // unshared one.
    let starts = (0..n)
        .filter(|&i| is_shared[i] && !is_shared[(i + n - 1) % n])
        .count();
    if starts != 1 {
        return false;
    }
    // The chain's k edges touch k + 1 corners; the other n − k − 1 must be new.
    let new = c.iter().filter(|v| !corners.contains(v)).count();
    new == n - k - 1
}

/// Every welded corner's position (the first face's copy of it).
fn corner_positions(polygons: &[Polygon], corner_ids: &[Vec<u32>]) -> HashMap<u32, Vec3> {
    let mut positions = HashMap::new();
    for (p, ids) in polygons.iter().zip(corner_ids) {
        for (v, id) in p.vertices.iter().zip(ids) {
            positions.entry(*id).or_insert(*v);
        }
    }
    positions
}

/// The region's outline: its boundary edges (those whose twin face is not in the region), in the
/// faces' winding, walked into one loop. A disk's boundary vertices each start one boundary edge.
fn outline(
    members: &[usize],
    corner_ids: &[Vec<u32>],
    region_of: &[usize],
    neighbour: &impl Fn(usize, usize) -> Option<usize>,
) -> Vec<u32> {
    let r = region_of[members[0]];
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &f in members {
        let c = &corner_ids[f];
        for k in 0..c.len() {
            if neighbour(f, k).is_none_or(|g| region_of[g] != r) {
                next.insert(c[k], c[(k + 1) % c.len()]);
            }
        }
    }
    let Some(&start) = next.keys().min() else {
        return Vec::new();
    };
    let mut loop_ = vec![start];
    let mut at = next[&start];
    while at != start && loop_.len() <= next.len() {
        loop_.push(at);
        match next.get(&at) {
            Some(&n) => at = n,
            None => break,
        }
    }
    loop_
}

/// The outline without the corners where it runs straight on (a tessellated wall's edge passes
/// through every grid line's corner): the same polygon with far fewer corners to clip and draw.
fn without_straight_corners(mut loop_: Vec<Vec3>) -> Vec<Vec3> {
    let mut i = 0;
    while loop_.len() > 3 && i < loop_.len() {
        let n = loop_.len();
        let (a, b, c) = (loop_[(i + n - 1) % n], loop_[i], loop_[(i + 1) % n]);
        let (u, v) = (b - a, c - b);
        let straight = u.dot(v) > 0.0 && u.cross(v).length() <= 1e-6 * u.length() * v.length();
        if straight {
            loop_.remove(i);
        } else {
            i += 1;
        }
    }
    loop_
}

/// The area-weighted mean normal of `polygons` (for tests).
#[cfg(test)]
fn mean_normal(polygons: &[Polygon]) -> DVec3 {
    polygons
        .iter()
        .map(|p| p.normal.as_dvec3() * p.area as f64)
        .sum::<DVec3>()
        .normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(x: f32, z: f32, material: usize) -> Polygon {
        let v = |a: f32, b: f32| Vec3::new(a, 0.0, b);
        // Counter-clockwise seen from above (+y).
        Polygon::new(
            vec![v(x, z), v(x, z + 1.0), v(x + 1.0, z + 1.0), v(x + 1.0, z)],
            material,
            "floor".into(),
        )
        .unwrap()
    }

    fn grid(n: i32, skip: impl Fn(i32, i32) -> bool) -> Vec<Polygon> {
        let mut out = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if !skip(i, j) {
                    out.push(quad(i as f32, j as f32, 0));
                }
            }
        }
        out
    }

    #[test]
    fn a_grid_of_quads_becomes_one_polygon_of_their_area() {
        let mut p = grid(10, |_, _| false);
        let report = merge_coplanar(&mut p, 14.0);
        assert_eq!(
            report,
            MergeReport {
                faces: 100,
                polygons: 1
            }
        );
        assert!((p[0].area - 100.0).abs() < 1e-3, "{}", p[0].area);
        assert!(p[0].normal.y > 0.999);
        assert!(p[0].is_planar(1e-6));
        // The outline's straight runs through the grid's corners are dropped: a square.
        assert_eq!(p[0].vertices.len(), 4, "{:?}", p[0].vertices);
    }

    #[test]
    fn triangles_of_quads_merge_and_an_l_shape_stays_concave() {
        let mut p = Vec::new();
        for q in grid(4, |i, j| i >= 2 && j >= 2) {
            let v = &q.vertices;
            p.push(Polygon::new(vec![v[0], v[1], v[2]], 0, "t".into()).unwrap());
            p.push(Polygon::new(vec![v[0], v[2], v[3]], 0, "t".into()).unwrap());
        }
        let report = merge_coplanar(&mut p, 6.0);
        assert_eq!(report.polygons, 1);
        assert!((p[0].area - 12.0).abs() < 1e-3);
        // Ear clipping covers the L exactly.
        let tris = crate::scene::triangulate(&p[0].vertices, p[0].normal);
        let area: f32 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|k| p[0].vertices[k]);
                0.5 * (b - a).cross(c - a).dot(p[0].normal)
            })
            .sum();
        assert!((area - 12.0).abs() < 1e-3, "{area}");
    }

    #[test]
    fn a_ring_around_a_hole_becomes_polygons_without_holes() {
        let mut p = grid(5, |i, j| i == 2 && j == 2);
        let report = merge_coplanar(&mut p, 7.0);
        assert!(report.polygons >= 2 && report.polygons < 24, "{report:?}");
        let area: f32 = p.iter().map(|q| q.area).sum();
        assert!((area - 24.0).abs() < 1e-3, "{area}");
        // Every polygon's outline is simple: its triangles cover its area.
        for q in &p {
            let tris = crate::scene::triangulate(&q.vertices, q.normal);
            let covered: f32 = tris
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|k| q.vertices[k]);
                    0.5 * (b - a).cross(c - a).dot(q.normal)
                })
                .sum();
            assert!(
                (covered - q.area).abs() < 1e-3 * q.area.max(1.0),
                "{covered} {}",
                q.area
            );
        }
    }

    #[test]
    fn materials_planes_and_windings_keep_faces_apart() {
        // Two materials.
        let mut p = vec![quad(0.0, 0.0, 0), quad(1.0, 0.0, 1)];
        assert_eq!(merge_coplanar(&mut p, 3.0).polygons, 2);
        // A step out of the plane.
        let mut lifted = quad(1.0, 0.0, 0);
        lifted.vertices.iter_mut().for_each(|v| {
            if v.x > 1.5 {
                v.y += 0.1
            }
        });
        let lifted = Polygon::new(lifted.vertices, 0, "f".into()).unwrap();
        let mut p = vec![quad(0.0, 0.0, 0), lifted];
        assert_eq!(merge_coplanar(&mut p, 3.0).polygons, 2);
        // A face turned over (its front down): not the same surface.
        let mut down = quad(1.0, 0.0, 0);
        down.vertices.reverse();
        let down = Polygon::new(down.vertices, 0, "f".into()).unwrap();
        let mut p = vec![quad(0.0, 0.0, 0), down];
        assert_eq!(merge_coplanar(&mut p, 3.0).polygons, 2);
        // Touching at a corner only.
        let mut p = vec![quad(0.0, 0.0, 0), quad(1.0, 1.0, 0)];
        assert_eq!(merge_coplanar(&mut p, 3.0).polygons, 2);
        assert!(mean_normal(&p).y > 0.99);
    }
}
