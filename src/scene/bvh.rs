//! A bounding volume hierarchy of the scene's triangles, for exact ray queries: the CPU solver's
//! shadow rays (its twin of the visibility pass; exact rather than a software item buffer, so the
//! CPU solver is an independent reference for the GPU's sampled visibility), the path tracer's
//! rays and the default camera's look at the scene. In `scene` because all three read it and the
//! scene is below them all.

use super::{triangulate, Scene};
use glam::Vec3;

#[derive(Clone, Copy)]
struct Node {
    min: Vec3,
    max: Vec3,
    /// Leaf: first triangle; inner node: index of the left child (the right one follows it).
    first: u32,
    /// Triangles in a leaf; 0 for an inner node.
    count: u32,
}

/// A bounding-volume hierarchy over the scene's triangles: the CPU solver's exact visibility
/// (a ray from the shooter to each receiver).
pub struct Bvh {
    nodes: Vec<Node>,
    triangles: Vec<[Vec3; 3]>,
    polygon: Vec<u32>,
}

const LEAF: usize = 4;

impl Bvh {
    /// The hierarchy of `scene`'s polygons, fanned into triangles.
    pub fn new(scene: &Scene) -> Bvh {
        let mut triangles = Vec::new();
        let mut polygon = Vec::new();
        for (i, p) in scene.polygons.iter().enumerate() {
            for t in triangulate(&p.vertices, p.normal) {
                triangles.push(t.map(|k| p.vertices[k]));
                polygon.push(i as u32);
            }
        }
        let mut order: Vec<usize> = (0..triangles.len()).collect();
        let mut bvh = Bvh {
            nodes: Vec::new(),
            triangles: Vec::new(),
            polygon: Vec::new(),
        };
        bvh.nodes.push(Node {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
            first: 0,
            count: 0,
        });
        bvh.build(0, &mut order, 0, &triangles);
        bvh.triangles = order.iter().map(|&i| triangles[i]).collect();
        bvh.polygon = order.iter().map(|&i| polygon[i]).collect();
        bvh
    }

    /// Build node `at` over `items`, the triangles that will sit at `offset..` in the final order.
    fn build(&mut self, at: usize, items: &mut [usize], offset: usize, triangles: &[[Vec3; 3]]) {
        let (mut min, mut max) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        let (mut cmin, mut cmax) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        for &i in items.iter() {
            for v in triangles[i] {
                min = min.min(v);
                max = max.max(v);
            }
            let c = (triangles[i][0] + triangles[i][1] + triangles[i][2]) / 3.0;
            cmin = cmin.min(c);
            cmax = cmax.max(c);
        }
        if items.len() <= LEAF {
            self.nodes[at] = Node {
                min,
                max,
                first: offset as u32,
                count: items.len() as u32,
            };
            return;
        }
        let extent = cmax - cmin;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let key = |i: &usize| {
            let t = triangles[*i];
            (t[0][axis] + t[1][axis] + t[2][axis]) / 3.0
        };
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
        let left = self.nodes.len();
        self.nodes.push(Node {
            min,
            max,
            first: 0,
            count: 0,
        });
        self.nodes.push(Node {
            min,
            max,
            first: 0,
            count: 0,
        });
        self.nodes[at] = Node {
            min,
            max,
            first: left as u32,
            count: 0,
        };
        let (a, b) = items.split_at_mut(mid);
        self.build(left, a, offset, triangles);
        self.build(left + 1, b, offset + mid, triangles);
    }

    /// The nearest triangle hit by the ray `o + t d` (t > 0), skipping polygon `skip`:
    /// (t, polygon). Used by the path-traced reference in the tests.
    pub fn closest(&self, o: Vec3, d: Vec3, skip: u32) -> Option<(f32, u32)> {
        let inv = d.recip();
        let mut best: Option<(f32, u32)> = None;
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            let limit = best.map_or(f32::MAX, |b| b.0);
            if !slab(o, inv, node.min, node.max, limit) {
                continue;
            }
            if node.count == 0 {
                stack[top] = node.first;
                stack[top + 1] = node.first + 1;
                top += 2;
                continue;
            }
            for k in node.first..node.first + node.count {
                let p = self.polygon[k as usize];
                if p == skip {
                    continue;
                }
                if let Some(t) = intersect(o, d, &self.triangles[k as usize]) {
                    if t > 1e-6 && t < best.map_or(f32::MAX, |b| b.0) {
                        best = Some((t, p));
                    }
                }
            }
        }
        best
    }

    /// Is the open segment from `a` to `b` blocked by a triangle of a polygon other than
    /// `skip_a` and `skip_b` (the receiver's and the shooter's own polygons)?
    pub fn occluded(&self, a: Vec3, b: Vec3, skip_a: u32, skip_b: u32) -> bool {
        let d = b - a;
        let inv = d.recip();
        let (t_min, t_max) = (1e-5, 1.0 - 1e-5);
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if !slab(a, inv, node.min, node.max, t_max) {
                continue;
            }
            if node.count == 0 {
                stack[top] = node.first;
                stack[top + 1] = node.first + 1;
                top += 2;
                continue;
            }
            for k in node.first..node.first + node.count {
                let p = self.polygon[k as usize];
                if p == skip_a || p == skip_b {
                    continue;
                }
                if let Some(t) = intersect(a, d, &self.triangles[k as usize]) {
                    if t > t_min && t < t_max {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// Ray (origin, 1/direction) against a box, for t in [0, t_max].
fn slab(o: Vec3, inv: Vec3, min: Vec3, max: Vec3, t_max: f32) -> bool {
    let t0 = (min - o) * inv;
    let t1 = (max - o) * inv;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element().min(t_max);
    near <= far
}

/// Möller–Trumbore, both sides; t along the unnormalised direction `d`.
fn intersect(o: Vec3, d: Vec3, t: &[Vec3; 3]) -> Option<f32> {
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 * e1.length_squared().max(e2.length_squared()) * d.length() {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - t[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(e2.dot(q) * inv)
}
