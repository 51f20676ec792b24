//! Plates: coplanar polygons that share whole edges, merged while their union stays convex (a
//! floor of tiles or planks, a ceiling of tiles becomes one or a few large polygons). The
//! hemicube's visibility pass draws a plate once, under the ID of its first polygon: the
//! reconstruction pass's robust test reads only the shown polygon's plane, which every polygon
//! of a plate shares, so it answers the same for every receiver; on llvmpipe a few large
//! triangles cost much less to set up and bin than hundreds of small ones.

use crate::patches::PatchLayout;
use crate::scene::Scene;
use crate::solver::mesh::push_polygon;
use glam::Vec3;
use std::collections::HashMap;

/// The plates of a scene: which polygon stands for each, and the merged outlines drawn.
#[derive(Clone, Debug, Default)]
pub struct Plates {
    /// Per polygon: the first polygon of its plate (itself if it is alone).
    pub representative: Vec<usize>,
    /// Per representative of a merged plate: the plate's outline, counter-clockwise.
    pub outlines: HashMap<usize, Vec<Vec3>>,
}

impl Plates {
    /// Every polygon on its own.
    pub fn none(polygons: usize) -> Plates {
        Plates {
            representative: (0..polygons).collect(),
            outlines: HashMap::new(),
        }
    }

    /// The vertex data of the hemicube's visibility pass (as `mesh::vertex_data` gives the
    /// scene's): each merged plate as one polygon under its representative's ID, the other
    /// polygons as they are.
    pub fn vertex_data(&self, scene: &Scene, layout: &PatchLayout) -> Vec<f32> {
        let mut data = Vec::new();
        for (i, p) in scene.polygons.iter().enumerate() {
            if self.representative[i] == i {
                let outline = self.outlines.get(&i).unwrap_or(&p.vertices);
                push_polygon(&mut data, scene, layout, i, outline);
            }
        }
        data
    }

    /// Merge the coplanar neighbours among `candidates` (polygons that may be merged).
    pub fn find(scene: &Scene, candidates: impl Fn(usize) -> bool) -> Plates {
        let n = scene.polygons.len();
        let slack = scene.plane_slack();
        let mut plates = Plates::none(n);
        // Coplanar groups: same plane up to float noise (keys rounded; neighbours across a
        // rounding boundary just stay apart).
        let mut groups: HashMap<[i64; 4], Vec<usize>> = HashMap::new();
        for (i, p) in scene.polygons.iter().enumerate() {
            if !candidates(i) {
                continue;
            }
            let d = p.plane().offset;
            let key = [
                (p.normal.x * 1e4).round() as i64,
                (p.normal.y * 1e4).round() as i64,
                (p.normal.z * 1e4).round() as i64,
                (d / (10.0 * slack)).round() as i64,
            ];
            groups.entry(key).or_default().push(i);
        }
        let mut keys: Vec<_> = groups.keys().copied().collect();
        keys.sort_unstable();
        for key in keys {
            let members = &groups[&key];
            if members.len() < 2 {
                continue;
            }
            let plane = scene.polygons[members[0]].plane();
            // Each plate: (outline, polygons), `None` once merged into another. Plates meet at
            // whole edges, so an edge map finds a plate's neighbours in constant time: a sweep
            // tries each plate's edges once, and sweeps repeat while they merge anything (the
            // rows of a grid merge in one, the rows into one rectangle in the next few). Was a
            // restart of an all-pairs search after every merge: 40,000 tiles took 30 s.
            let mut live: Vec<Option<(Vec<Vec3>, Vec<usize>)>> = members
                .iter()
                .map(|&m| Some((scene.polygons[m].vertices.clone(), vec![m])))
                .collect();
            let key = |u: Vec3, v: Vec3| {
                (
                    u.to_array().map(f32::to_bits),
                    v.to_array().map(f32::to_bits),
                )
            };
            let mut edges: HashMap<_, usize> = HashMap::new();
            for (k, plate) in live.iter().enumerate() {
                let outline = &plate.as_ref().unwrap().0;
                for i in 0..outline.len() {
                    edges.insert(key(outline[i], outline[(i + 1) % outline.len()]), k);
                }
            }
            loop {
                let mut merged_any = false;
                for a in 0..live.len() {
                    let mut i = 0;
                    while let Some((outline, _)) = &live[a] {
                        if i >= outline.len() {
                            break;
                        }
                        let (u, v) = (outline[i], outline[(i + 1) % outline.len()]);
                        i += 1;
                        let Some(&b) = edges.get(&key(v, u)) else {
                            continue;
                        };
                        if b == a || live[b].is_none() {
                            continue;
                        }
                        let other = &live[b].as_ref().unwrap().0;
                        let Some(union) = merge(outline, other, plane.normal, slack) else {
                            continue;
                        };
                        let (old_b, taken) = live[b].take().unwrap();
                        let (old_a, mut polygons) = live[a].take().unwrap();
                        for o in [&old_a, &old_b] {
                            for j in 0..o.len() {
                                edges.remove(&key(o[j], o[(j + 1) % o.len()]));
                            }
                        }
                        for j in 0..union.len() {
                            edges.insert(key(union[j], union[(j + 1) % union.len()]), a);
                        }
                        polygons.extend(taken);
                        live[a] = Some((union, polygons));
                        merged_any = true;
                        i = 0;
                    }
                }
                if !merged_any {
                    break;
                }
            }
            for (outline, polygons) in live.into_iter().flatten() {
                if polygons.len() < 2 {
                    continue;
                }
                let first = *polygons.iter().min().unwrap();
                for &p in &polygons {
                    plates.representative[p] = first;
                }
                plates.outlines.insert(first, outline);
            }
        }
        plates
    }

    /// Polygons that were merged into another's plate (drawn by their representative).
    pub fn merged_away(&self) -> usize {
        self.representative
            .iter()
            .enumerate()
            .filter(|(i, &r)| *i != r)
            .count()
    }
}

/// The union of two convex outlines sharing a whole edge (a runs u→v, b runs v→u), if it is
/// convex; corners left in the middle of a straight side are dropped.
fn merge(a: &[Vec3], b: &[Vec3], normal: Vec3, slack: f32) -> Option<Vec<Vec3>> {
    let (na, nb) = (a.len(), b.len());
    for i in 0..na {
        let (u, v) = (a[i], a[(i + 1) % na]);
        let Some(j) = (0..nb).find(|&j| b[j] == v && b[(j + 1) % nb] == u) else {
            continue;
        };
        // a from v round to u, then b from after u round to before v.
        let mut union: Vec<Vec3> = (0..na).map(|k| a[(i + 1 + k) % na]).collect();
        union.extend((0..nb - 2).map(|k| b[(j + 2 + k) % nb]));
        let union = drop_straight_corners(union, normal, slack);
        let m = union.len();
        let convex = m >= 3
            && (0..m).all(|k| {
                let (p, q, r) = (union[k], union[(k + 1) % m], union[(k + 2) % m]);
                (q - p).cross(r - q).dot(normal) >= -slack * (q - p).length()
            });
        return convex.then_some(union);
    }
    None
}

fn drop_straight_corners(mut v: Vec<Vec3>, normal: Vec3, slack: f32) -> Vec<Vec3> {
    let straight = |v: &[Vec3], k: usize| {
        let m = v.len();
        let (p, q, r) = (v[(k + m - 1) % m], v[k], v[(k + 1) % m]);
        (q - p).cross(r - q).dot(normal).abs() <= slack * (r - p).length()
            && (q - p).dot(r - q) > 0.0
    };
    while v.len() > 3 {
        match (0..v.len()).find(|&k| straight(&v, k)) {
            Some(k) => {
                v.remove(k);
            }
            None => break,
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::test_scene as scene;
    use crate::scene::Polygon;

    fn tile(x0: f32, z0: f32, x1: f32, z1: f32) -> Polygon {
        // Facing +y: counter-clockwise seen from above.
        let v = [[x0, 0., z0], [x0, 0., z1], [x1, 0., z1], [x1, 0., z0]];
        Polygon::new(v.map(Vec3::from_array).to_vec(), 0, "floor".into()).unwrap()
    }

    #[test]
    fn a_grid_of_tiles_becomes_one_rectangle() {
        let mut tiles = Vec::new();
        for i in 0..4 {
            for j in 0..3 {
                tiles.push(tile(i as f32, j as f32, i as f32 + 1.0, j as f32 + 1.0));
            }
        }
        let plates = Plates::find(&scene(tiles), |_| true);
        assert!(plates.representative.iter().all(|&r| r == 0));
        let outline = &plates.outlines[&0];
        assert_eq!(outline.len(), 4, "{outline:?}");
        let area = crate::scene::Polygon::new(outline.clone(), 0, "p".into())
            .unwrap()
            .area;
        assert!((area - 12.0).abs() < 1e-5);
    }

    #[test]
    fn an_l_shape_stays_two_plates_and_a_gap_is_not_bridged() {
        // Three tiles in an L: any two merge, the third would make the union concave.
        let l = vec![
            tile(0., 0., 1., 1.),
            tile(1., 0., 2., 1.),
            tile(0., 1., 1., 2.),
        ];
        let plates = Plates::find(&scene(l), |_| true);
        assert_eq!(plates.merged_away(), 1);
        // Tiles with a gap between them share no edge.
        let gap = vec![tile(0., 0., 1., 1.), tile(1.5, 0., 2.5, 1.)];
        assert_eq!(Plates::find(&scene(gap), |_| true).merged_away(), 0);
        // Not a candidate: left alone.
        let two = vec![tile(0., 0., 1., 1.), tile(1., 0., 2., 1.)];
        assert_eq!(Plates::find(&scene(two), |p| p != 1).merged_away(), 0);
    }
}
