//! Smooth display of curved surfaces made of many small faces (beyond the paper, whose scenes are
//! rooms of flat walls and boxes).
//!
//! A sphere or column is many flat faces, each with its own lightmap; each face turns a little
//! from its neighbour, so it receives a little more or less light, and the picture is faceted.
//! Radiosity renderers show such surfaces smooth by averaging the radiance where faces of one
//! surface meet (Cohen & Wallace, *Radiosity and Realistic Image Synthesis*, 1993, ch. 9), either
//! at the vertices (per-vertex radiosity, Gouraud-interpolated) or by filtering across
//! neighbouring lightmaps. Here it is both, done where the lightmap is sampled:
//!
//! - **Smooth edges**: two faces share an edge (both ends welded within 1e-5 of the scene's size,
//!   run in opposite directions as on one consistently wound surface), have the same material (a
//!   change of material is a real edge in the picture), and their normals are less than the crease
//!   angle apart (`--smooth-angle`, default [`DEFAULT_ANGLE`]°: a box's 90° edges never qualify).
//!   Coplanar faces (less than [`MIN_BEND`]° apart) only on a curved surface, such as the two
//!   triangles of a sphere's quad: a floor's pieces have no facet to hide.
//! - **Vertices** (Cohen & Wallace's per-vertex radiosity): the corners joined by smooth edges
//!   around a vertex form a group, whose radiance V is the mean of its faces' lightmaps there
//!   (bilinear, as displayed), weighted by each face's interior angle. Faces without a patch have
//!   no light of their own and do not count.
//! - **Along each smooth edge** the target is the mean M of the two faces' lightmaps at the same
//!   point, plus the linear blend of V − M from its two ends: the same value seen from either side,
//!   V at the corners. Sampled per pixel (`glsl/smooth.glsl`), so a column's long facets follow
//!   their texels along the edge instead of a straight line between the corners.
//! - **Inside a face** the display adds to the lightmap the edges' corrections (target − own
//!   lightmap at the nearest point of each edge), blended by inverse squared distance so that on
//!   an edge only that edge's counts: fully within [`FULL_TEXELS`] texel of a smooth edge, fading
//!   out over the next [`FADE_TEXELS`]. A face one or two texels across is thus interpolated
//!   entirely from its edges and corners; a large face (a merged wall with a shadow on it) keeps
//!   its lightmap beyond a thin band along its smooth edges.
//!
//! Filtering by filling each lightmap's gutter from the neighbour was the simpler choice, but a
//! lightmap is the face's bounding rectangle: a triangle's slanted edges run through its texels,
//! not along its gutter, and a face of one texel has no texel at its edge to blend. Per-vertex
//! values alone (Gouraud) were tried first: they draw small faces well but smear a long face's
//! texels between its two ends.
//!
//! Faces with no smooth edge (every face of the Cornell box) are drawn from the lightmap alone,
//! bit for bit as before.

use crate::patches::PatchLayout;
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use std::collections::HashMap;

/// The crease angle by default, degrees: smooths columns of 10 sides and more and tessellated
/// spheres, keeps octagons (45°) and boxes (90°) sharp.
pub const DEFAULT_ANGLE: f32 = 40.0;
/// Crease angles are below this: at a right angle and beyond, a box's corners would be averaged.
pub const MAX_ANGLE: f32 = 90.0;
/// Faces that turn less than this (degrees) from each other are one plane: smooth only when both
/// are facets of a curved surface (each has an edge that bends more). Elsewhere they see the
/// light from the same side, so a jump between them is real light (the floor under a rug beside
/// the floor next to it, cut along the rug's outline) and stays.
pub const MIN_BEND: f32 = 1.0;
/// Within this many texels of a smooth edge a face takes the edges' whole correction (defined
/// into `glsl/smooth.glsl` as `SMOOTH_FULL`)...
pub const FULL_TEXELS: f32 = 1.0;
/// ...fading to none over this many more (`SMOOTH_FADE`).
pub const FADE_TEXELS: f32 = 1.0;
/// A face with more smooth edges than this (a large merged outline) keeps its lightmap, and its
/// neighbours do not blend towards it: the display loops over a face's smooth edges per pixel.
pub const MAX_EDGES: usize = 32;
/// Vertices closer than this share of the scene's size are one vertex.
const WELD: f32 = 1e-5;
/// Floats per smooth edge in [`Smoothing::edge_texels`]: four RGBA texels.
pub const EDGE_FLOATS: usize = 16;

/// One smooth edge as one face sees it: its corners at the edge's ends, and the neighbour's
/// corners at the same two points.
#[derive(Clone, Copy, Debug)]
struct Edge {
    a: u32,
    b: u32,
    neighbour_a: u32,
    neighbour_b: u32,
}

/// The smooth edges and vertex groups of a scene at one crease angle, computed once from the
/// geometry; [`Smoothing::edge_texels`] evaluates them on a radiance atlas for the display.
#[derive(Clone, Debug)]
pub struct Smoothing {
    angle: f32,
    /// Polygon `i`'s corners are `first[i]..first[i + 1]`, its vertices in order.
    first: Vec<usize>,
    /// Each corner's vertex in atlas texel coordinates (its lightmap coordinate).
    texel: Vec<Vec2>,
    /// Each corner's share of its vertex: its polygon's interior angle there (radians).
    share: Vec<f32>,
    /// Does the corner's polygon have patches (light of its own to average)?
    lit: Vec<bool>,
    /// The groups of two or more corners: `members[starts[g]..starts[g + 1]]`.
    starts: Vec<usize>,
    members: Vec<u32>,
    /// Smooth edges, by polygon: polygon `i`'s are `edges[ranges[i].0..][..ranges[i].1]`.
    edges: Vec<Edge>,
    ranges: Vec<(u32, u32)>,
}

impl Smoothing {
    /// The smooth edges of `scene` laid out as `layout`, at a crease angle of `angle` degrees
    /// (0: none).
    pub fn new(scene: &Scene, layout: &PatchLayout, angle: f32) -> Smoothing {
        let mut first = Vec::with_capacity(scene.polygons.len() + 1);
        let (mut texel, mut share, mut lit) = (Vec::new(), Vec::new(), Vec::new());
        let size = Vec2::new(layout.atlas_width as f32, layout.atlas_height as f32);
        for (i, p) in scene.polygons.iter().enumerate() {
            first.push(texel.len());
            let n = p.vertices.len();
            for k in 0..n {
                let v = p.vertices[k];
                texel.push(layout.atlas_uv(i, v) * size);
                share.push(interior_angle(
                    p.vertices[(k + n - 1) % n],
                    v,
                    p.vertices[(k + 1) % n],
                    p.normal,
                ));
                lit.push(layout.patches_per_polygon[i] > 0);
            }
        }
        first.push(texel.len());
        let mut smoothing = Smoothing {
            angle,
            first,
            texel,
            share,
            lit,
            starts: vec![0],
            members: Vec::new(),
            edges: Vec::new(),
            ranges: vec![(0, 0); scene.polygons.len()],
        };
        if angle > 0.0 {
            smoothing.find_edges(scene);
        }
        smoothing
    }

    /// No smooth edges, for triangles that are not a scene's polygons
    /// ([`super::DisplayMesh::from_triangles`]).
    pub fn none() -> Smoothing {
        Smoothing {
            angle: 0.0,
            first: vec![0],
            texel: Vec::new(),
            share: Vec::new(),
            lit: Vec::new(),
            starts: vec![0],
            members: Vec::new(),
            edges: Vec::new(),
            ranges: Vec::new(),
        }
    }

    /// The crease angle, degrees.
    pub fn angle(&self) -> f32 {
        self.angle
    }

    /// Polygons with at least one smooth edge (the display changes only these).
    pub fn smoothed_polygons(&self) -> usize {
        self.ranges.iter().filter(|r| r.1 > 0).count()
    }

    /// Does polygon `i` have a smooth edge?
    pub fn is_smoothed(&self, polygon: usize) -> bool {
        self.ranges[polygon].1 > 0
    }

    /// Smooth edges, each counted once per face that has it.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Does the display change anything? When not, it is the lightmap alone.
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Polygon `i`'s corners (its vertices in order) in [`Smoothing::vertex_radiance`].
    pub fn corners(&self, polygon: usize) -> std::ops::Range<usize> {
        self.first[polygon]..self.first[polygon + 1]
    }

    /// Polygon `i`'s smooth edges in [`Smoothing::edge_texels`]: (first, count).
    pub fn edge_range(&self, polygon: usize) -> (u32, u32) {
        self.ranges[polygon]
    }

    /// The radiance V of every vertex group (per corner; `None` for corners in no group, or in a
    /// group of faces without patches), for `atlas` (RGBA radiance, rows bottom to top, `width`
    /// x `height` texels, dilated as the display samples it).
    pub fn vertex_radiance(&self, atlas: &[f32], width: u32, height: u32) -> Vec<Option<Vec3>> {
        let mut out = vec![None; self.texel.len()];
        for g in 0..self.starts.len() - 1 {
            let group = &self.members[self.starts[g]..self.starts[g + 1]];
            let (mut sum, mut total) = (Vec3::ZERO, 0.0);
            for &c in group.iter().filter(|&&c| self.lit[c as usize]) {
                let l = bilinear(atlas, width, height, self.texel[c as usize]);
                sum += l * self.share[c as usize];
                total += self.share[c as usize];
            }
            if total > 0.0 {
                for &c in group {
                    out[c as usize] = Some(sum / total);
                }
            }
        }
        out
    }

    /// The smooth edges for the display shader, [`EDGE_FLOATS`] per edge (`glsl/smooth.glsl`):
    /// the face's ends A and B and the neighbour's (atlas texel coordinates), then at each end
    /// V − M (the vertex radiance minus the mean of the two faces there) with whether the face and
    /// its neighbour have patches.
    pub fn edge_texels(&self, atlas: &[f32], width: u32, height: u32) -> Vec<f32> {
        let v = self.vertex_radiance(atlas, width, height);
        let lit = |c: u32| self.lit[c as usize] as u32 as f32;
        let mut out = Vec::with_capacity(self.edges.len() * EDGE_FLOATS);
        for e in &self.edges {
            let at = |c: u32| self.texel[c as usize];
            out.extend_from_slice(&[at(e.a).x, at(e.a).y, at(e.b).x, at(e.b).y]);
            let (na, nb) = (at(e.neighbour_a), at(e.neighbour_b));
            out.extend_from_slice(&[na.x, na.y, nb.x, nb.y]);
            // The patch flags of the face and of its neighbour ride in the two alpha slots.
            let flags = [lit(e.a), lit(e.neighbour_a)];
            for ((own, other), flag) in [(e.a, e.neighbour_a), (e.b, e.neighbour_b)]
                .into_iter()
                .zip(flags)
            {
                let (wo, wn) = (lit(own), lit(other));
                let mean = if wo + wn > 0.0 {
                    (bilinear(atlas, width, height, at(own)) * wo
                        + bilinear(atlas, width, height, at(other)) * wn)
                        / (wo + wn)
                } else {
                    Vec3::ZERO
                };
                let k = v[own as usize].map_or(Vec3::ZERO, |v| v - mean);
                out.extend_from_slice(&[k.x, k.y, k.z, flag]);
            }
        }
        out
    }

    /// Weld the vertices, find the smooth edges, and join the corners they connect into groups.
    fn find_edges(&mut self, scene: &Scene) {
        let corners = self.texel.len();
        let weld_ids = weld(scene, WELD * scene.size());
        let cos_crease = self.angle.to_radians().cos();
        let cos_flat = MIN_BEND.to_radians().cos();
        let first = self.first.clone();
        // Corner k of polygon i, which is also where its edge k starts.
        let corner = |i: u32, k: u32| {
            let n = scene.polygons[i as usize].vertices.len() as u32;
            first[i as usize] as u32 + k % n
        };
        // Each edge by its welded ends (smaller first): the polygons having it, with the index of
        // its first corner there.
        let mut shared: HashMap<(u32, u32), Vec<(u32, u32)>> = HashMap::new();
        for (i, p) in scene.polygons.iter().enumerate() {
            for k in 0..p.vertices.len() as u32 {
                let (a, b) = (
                    weld_ids[corner(i as u32, k) as usize],
                    weld_ids[corner(i as u32, k + 1) as usize],
                );
                if a != b {
                    shared
                        .entry((a.min(b), a.max(b)))
                        .or_default()
                        .push((i as u32, k));
                }
            }
        }
        // The pairs of faces that are one surface across an edge: they run it both ways, have
        // one material, and turn less than the crease angle: (first corners, cosine).
        let mut pairs: Vec<(u32, u32, f32)> = Vec::new();
        for sharing in shared.values() {
            for (x, &(i, k)) in sharing.iter().enumerate() {
                for &(j, m) in &sharing[x + 1..] {
                    let (p, q) = (&scene.polygons[i as usize], &scene.polygons[j as usize]);
                    let cos = p.normal.dot(q.normal);
                    let opposite =
                        weld_ids[corner(i, k) as usize] == weld_ids[corner(j, m + 1) as usize];
                    if i != j && opposite && p.material == q.material && cos > cos_crease {
                        pairs.push((corner(i, k), corner(j, m), cos));
                    }
                }
            }
        }
        pairs.sort_unstable_by_key(|&(a, b, _)| (a, b));
        // The polygons with corners, and those of curved surfaces: with an edge that bends.
        let mut polygon_of = vec![0u32; corners];
        for i in 0..scene.polygons.len() {
            polygon_of[first[i]..first[i + 1]].fill(i as u32);
        }
        let mut curved = vec![false; scene.polygons.len()];
        for &(a, b, cos) in &pairs {
            if cos < cos_flat {
                curved[polygon_of[a as usize] as usize] = true;
                curved[polygon_of[b as usize] as usize] = true;
            }
        }
        // Coplanar neighbours are smooth only when both are facets of a curved surface (the two
        // triangles of a sphere's planar quad): elsewhere they see the light alike, and a jump
        // between them is real light, such as the floor under a rug beside the floor next to it.
        let mut parent: Vec<u32> = (0..corners as u32).collect();
        // For each edge (by its first corner), the neighbour's edge across it whose normal is
        // closest (an edge three faces share has two candidates): (its first corner, cosine).
        let mut across: Vec<Option<(u32, f32)>> = vec![None; corners];
        let next = |c: u32| {
            let i = polygon_of[c as usize];
            corner(i, c - first[i as usize] as u32 + 1)
        };
        for &(a, b, cos) in &pairs {
            let on_curve = [a, b]
                .iter()
                .all(|&c| curved[polygon_of[c as usize] as usize]);
            if cos >= cos_flat && !on_curve {
                continue;
            }
            union(&mut parent, a, next(b));
            union(&mut parent, next(a), b);
            for (from, to) in [(a, b), (b, a)] {
                if across[from as usize].is_none_or(|(_, c)| cos > c) {
                    across[from as usize] = Some((to, cos));
                }
            }
        }
        self.group_corners(&mut parent);

        // The polygons with too many smooth edges.
        let mut count = vec![0usize; scene.polygons.len()];
        for (c, a) in across.iter().enumerate() {
            if a.is_some() {
                count[polygon_of[c] as usize] += 1;
            }
        }
        let kept = |c: u32| count[polygon_of[c as usize] as usize] <= MAX_EDGES;
        // The neighbour's edge runs the other way: its first corner is at our B.
        for (c, a) in across.iter().enumerate() {
            let c = c as u32;
            let Some((other, _)) = *a else { continue };
            if !(kept(c) && kept(other)) {
                continue;
            }
            let i = polygon_of[c as usize] as usize;
            if self.ranges[i].1 == 0 {
                self.ranges[i].0 = self.edges.len() as u32;
            }
            self.ranges[i].1 += 1;
            self.edges.push(Edge {
                a: c,
                b: next(c),
                neighbour_a: next(other),
                neighbour_b: other,
            });
        }
    }

    /// The groups: classes of two or more corners, in the order of their smallest corner (the
    /// root), each in corner order, so the same whatever the order the edges were found in.
    fn group_corners(&mut self, parent: &mut [u32]) {
        let corners = parent.len();
        let roots: Vec<u32> = (0..corners as u32).map(|c| find(parent, c)).collect();
        let mut count = vec![0u32; corners];
        for &r in &roots {
            count[r as usize] += 1;
        }
        let mut slot = vec![u32::MAX; corners];
        let mut groups: Vec<Vec<u32>> = Vec::new();
        for (c, &r) in roots.iter().enumerate() {
            if count[r as usize] < 2 {
                continue;
            }
            if slot[r as usize] == u32::MAX {
                slot[r as usize] = groups.len() as u32;
                groups.push(Vec::new());
            }
            groups[slot[r as usize] as usize].push(c as u32);
        }
        for group in groups {
            self.members.extend_from_slice(&group);
            self.starts.push(self.members.len());
        }
    }
}

/// The interior angle at `v` of a counter-clockwise polygon (seen from `normal`), between the
/// edges to `prev` and `next`: in (0, 2π), above π at a reflex corner.
fn interior_angle(prev: Vec3, v: Vec3, next: Vec3, normal: Vec3) -> f32 {
    let (to_next, to_prev) = (next - v, prev - v);
    let a = normal
        .dot(to_next.cross(to_prev))
        .atan2(to_next.dot(to_prev));
    if a < 0.0 {
        a + std::f32::consts::TAU
    } else {
        a
    }
}

/// A welded vertex ID for every corner of every polygon (in polygon order): corners within
/// `tolerance` of each other get one ID. Positions are hashed on a grid of cells `tolerance`
/// wide, and each is compared with the vertices of the 27 cells around it.
fn weld(scene: &Scene, tolerance: f32) -> Vec<u32> {
    let tolerance = tolerance.max(f32::MIN_POSITIVE);
    let cell = |p: Vec3| (p / tolerance).floor().to_array().map(|c| c as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut welded: Vec<Vec3> = Vec::new();
    let mut ids = Vec::new();
    for p in scene
        .polygons
        .iter()
        .flat_map(|p| p.vertices.iter().copied())
    {
        let [x, y, z] = cell(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let key = [
                        x.saturating_add(dx),
                        y.saturating_add(dy),
                        z.saturating_add(dz),
                    ];
                    for &id in grid.get(&key).into_iter().flatten() {
                        if welded[id as usize].distance(p) <= tolerance {
                            found = Some(id);
                            break 'search;
                        }
                    }
                }
            }
        }
        let id = found.unwrap_or_else(|| {
            let id = welded.len() as u32;
            welded.push(p);
            grid.entry([x, y, z]).or_default().push(id);
            id
        });
        ids.push(id);
    }
    ids
}

fn find(parent: &mut [u32], mut c: u32) -> u32 {
    while parent[c as usize] != c {
        let up = parent[parent[c as usize] as usize];
        parent[c as usize] = up;
        c = up;
    }
    c
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        // The smaller index is the root: the groups do not depend on the order of the edges.
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        parent[hi as usize] = lo;
    }
}

/// GL's bilinear lookup (GL_LINEAR, clamped to the edge) of an RGBA atlas at a point in texel
/// coordinates: what the display shader samples there.
pub fn bilinear(atlas: &[f32], width: u32, height: u32, at: Vec2) -> Vec3 {
    let (w, h) = (width as i64, height as i64);
    let p = at - Vec2::splat(0.5);
    let (x0, y0) = (p.x.floor(), p.y.floor());
    let (fx, fy) = (p.x - x0, p.y - y0);
    let texel = |x: i64, y: i64| {
        let (x, y) = (x.clamp(0, w - 1), y.clamp(0, h - 1));
        let at = ((y * w + x) * 4) as usize;
        Vec3::new(atlas[at], atlas[at + 1], atlas[at + 2])
    };
    let (x0, y0) = (x0 as i64, y0 as i64);
    let bottom = texel(x0, y0).lerp(texel(x0 + 1, y0), fx);
    let top = texel(x0, y0 + 1).lerp(texel(x0 + 1, y0 + 1), fx);
    bottom.lerp(top, fy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patches::Resolution;
    use crate::scene::{test_scene, Polygon};

    fn polygon(vertices: &[Vec3]) -> Polygon {
        Polygon::new(vertices.to_vec(), 0, "t".into()).unwrap()
    }

    fn smoothing(polygons: Vec<Polygon>, angle: f32) -> (Scene, PatchLayout, Smoothing) {
        let scene = test_scene(polygons);
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(0.25));
        let s = Smoothing::new(&scene, &layout, angle);
        (scene, layout, s)
    }

    /// A prism of `sides` quads around the y axis (radius 1, height 2), normals outward, with its
    /// top cap.
    fn prism(sides: usize) -> Vec<Polygon> {
        let at = |i: usize, y: f32| {
            let phi = std::f32::consts::TAU * i as f32 / sides as f32;
            Vec3::new(phi.cos(), y, -phi.sin())
        };
        let mut faces: Vec<Polygon> = (0..sides)
            .map(|i| polygon(&[at(i, 0.0), at(i + 1, 0.0), at(i + 1, 2.0), at(i, 2.0)]))
            .collect();
        faces.push(polygon(&(0..sides).map(|i| at(i, 2.0)).collect::<Vec<_>>()));
        faces
    }

    /// The unit cube's six sides, each cut into `n` × `n` tiles, normals outward.
    fn cube(n: usize) -> Vec<Polygon> {
        let mut faces = Vec::new();
        for axis in 0..3 {
            for side in [0.0, 1.0] {
                let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
                let point = |a: usize, b: usize| {
                    let mut p = [0.0; 3];
                    p[axis] = side;
                    p[u] = a as f32 / n as f32;
                    p[w] = b as f32 / n as f32;
                    Vec3::from_array(p)
                };
                for a in 0..n {
                    for b in 0..n {
                        let mut q = [
                            point(a, b),
                            point(a + 1, b),
                            point(a + 1, b + 1),
                            point(a, b + 1),
                        ];
                        let f = polygon(&q);
                        if f.normal[axis] * (side - 0.5) < 0.0 {
                            q.reverse();
                        }
                        faces.push(polygon(&q));
                    }
                }
            }
        }
        faces
    }

    #[test]
    fn boxes_stay_sharp_and_prisms_smooth_below_the_crease() {
        assert!(smoothing(cube(1), DEFAULT_ANGLE).2.is_empty());
        // Twelve sides turn 30° from each other: smooth; the cap meets them at 90°.
        let (_, _, s) = smoothing(prism(12), DEFAULT_ANGLE);
        assert_eq!(s.smoothed_polygons(), 12);
        assert!(!s.is_smoothed(12));
        // Each side has two smooth edges; each vertex of the sides joins two corners.
        assert_eq!(s.edge_count(), 24);
        assert_eq!(s.starts.len() - 1, 24);
        // An octagon's 45° edges are creases at 40°, smooth at 50°; 0 turns smoothing off.
        assert_eq!(smoothing(prism(8), 40.0).2.smoothed_polygons(), 0);
        assert_eq!(smoothing(prism(8), 50.0).2.smoothed_polygons(), 8);
        assert!(smoothing(prism(12), 0.0).2.is_empty());
        // Each side cut into two coplanar triangles: all facets of the curve, the diagonals too.
        let triangles: Vec<Polygon> = prism(12)[..12]
            .iter()
            .flat_map(|q| {
                let v = &q.vertices;
                [polygon(&[v[0], v[1], v[2]]), polygon(&[v[0], v[2], v[3]])]
            })
            .collect();
        let (_, _, s) = smoothing(triangles, DEFAULT_ANGLE);
        assert_eq!((s.smoothed_polygons(), s.edge_count()), (24, 48));
    }

    #[test]
    fn vertices_average_their_surface_and_not_across_the_crease() {
        // Coplanar tiles have nothing to smooth; the cube's edges are creases.
        assert!(smoothing(cube(2), DEFAULT_ANGLE).2.is_empty());
        let (scene, layout, s) = smoothing(prism(12), DEFAULT_ANGLE);
        // Each side its own constant radiance (i + 1), the cap 100, dilated as displayed.
        let (w, h) = (layout.atlas_width, layout.atlas_height);
        let mut atlas = vec![0.0; (w * h * 4) as usize];
        let value = |i: usize| if i == 12 { 100.0 } else { i as f32 + 1.0 };
        for (texel, &owner) in atlas.chunks_exact_mut(4).zip(&layout.owner) {
            if owner > 0 {
                let v = value(owner as usize - 1);
                texel.copy_from_slice(&[v, v, v, owner as f32]);
            }
        }
        layout.dilate(&mut atlas);
        let v = s.vertex_radiance(&atlas, w, h);
        // Every side's corner is the mean of the two sides that meet there (equal right
        // angles), the top ones too: the cap does not count. The cap's corners are alone.
        for i in 0..12 {
            let p = &scene.polygons[i];
            for (k, c) in s.corners(i).enumerate() {
                let around = (-p.vertices[k].z).atan2(p.vertices[k].x);
                let step = std::f32::consts::TAU / 12.0;
                let j = (around.rem_euclid(std::f32::consts::TAU) / step).round() as usize % 12;
                let expect = 0.5 * (value(j) + value((j + 11) % 12));
                let got = v[c].expect("a side's corner is in a group").x;
                assert!(
                    (got - expect).abs() < 1e-4,
                    "side {i} corner {k}: {got} != {expect}"
                );
            }
        }
        assert!(s.corners(12).all(|c| v[c].is_none()));
        // The records' ends: V − M, which is 0 where only two sides meet.
        let texels = s.edge_texels(&atlas, w, h);
        assert_eq!(texels.len(), s.edge_count() * EDGE_FLOATS);
        for record in texels.chunks_exact(EDGE_FLOATS) {
            assert!(record[8..11]
                .iter()
                .chain(&record[12..15])
                .all(|k| k.abs() < 1e-4));
            assert_eq!((record[11], record[15]), (1.0, 1.0));
        }
    }

    #[test]
    fn materials_winding_and_welding_decide_what_is_smooth() {
        // Two quads hinged along x = 1 at 20°.
        let turn = 20f32.to_radians();
        let far = Vec3::new(1.0 + turn.cos(), turn.sin(), 0.0);
        let a = [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, -1.0),
        ];
        let b = [
            Vec3::new(1.0, 0.0, 0.0),
            far,
            far - Vec3::Z,
            Vec3::new(1.0, 0.0, -1.0),
        ];
        assert_eq!(
            smoothing(vec![polygon(&a), polygon(&b)], 40.0)
                .2
                .smoothed_polygons(),
            2
        );
        assert_eq!(
            smoothing(vec![polygon(&a), polygon(&b)], 15.0)
                .2
                .smoothed_polygons(),
            0
        );
        // A change of material is an edge in the picture.
        let mut other = polygon(&b);
        other.material = 1;
        let mut scene = test_scene(vec![polygon(&a), other]);
        scene.materials.push(scene.materials[0].clone());
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(0.25));
        assert!(Smoothing::new(&scene, &layout, 40.0).is_empty());
        // The second face wound the other way faces away: not one surface.
        let mut reversed = b;
        reversed.reverse();
        assert!(smoothing(vec![polygon(&a), polygon(&reversed)], 40.0)
            .2
            .is_empty());
        // Ends a hair apart (exported without shared indices) are welded; a visible gap is not.
        let nudged = b.map(|v| if v.x == 1.0 { v + Vec3::splat(1e-7) } else { v });
        assert_eq!(
            smoothing(vec![polygon(&a), polygon(&nudged)], 40.0)
                .2
                .smoothed_polygons(),
            2
        );
        let apart = b.map(|v| v + Vec3::new(0.01, 0.0, 0.0));
        assert!(smoothing(vec![polygon(&a), polygon(&apart)], 40.0)
            .2
            .is_empty());
    }

    #[test]
    fn edge_records_meet_at_the_vertex_average() {
        // A unit square and a triangle hinged at 20° on their shared edge x = 1, z in [-1, 0].
        let turn = 20f32.to_radians();
        let tip = Vec3::new(1.0 + turn.cos(), turn.sin(), -0.5);
        let square = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, -1.0),
        ];
        let triangle = [Vec3::X, tip, Vec3::new(1.0, 0.0, -1.0)];
        let (scene, layout, s) = smoothing(vec![polygon(&square), polygon(&triangle)], 40.0);
        assert_eq!(
            (s.edge_count(), s.edge_range(0), s.edge_range(1)),
            (2, (0, 1), (1, 1))
        );
        let (w, h) = (layout.atlas_width, layout.atlas_height);
        let mut atlas = vec![0.0; (w * h * 4) as usize];
        for (texel, &owner) in atlas.chunks_exact_mut(4).zip(&layout.owner) {
            if owner > 0 {
                let v = if owner == 1 { 1.0 } else { 3.0 };
                texel.copy_from_slice(&[v, v, v, owner as f32]);
            }
        }
        layout.dilate(&mut atlas);
        // At each end: the square's 90° corner and the triangle's, weighted by angle.
        let corner_angle = |p: &Polygon, k: usize| {
            let n = p.vertices.len();
            interior_angle(
                p.vertices[(k + n - 1) % n],
                p.vertices[k],
                p.vertices[(k + 1) % n],
                p.normal,
            )
        };
        let t = &scene.polygons[1];
        let (ta, tb) = (corner_angle(t, 0), corner_angle(t, 2));
        let half = std::f32::consts::FRAC_PI_2;
        let expect = |angle: f32| (half * 1.0 + angle * 3.0) / (half + angle) - 2.0;
        let texels = s.edge_texels(&atlas, w, h);
        // The square's edge runs from (1,0,0) to (1,0,-1), the triangle's back.
        let square_edge = &texels[..EDGE_FLOATS];
        assert!(
            (square_edge[8] - expect(ta)).abs() < 1e-4,
            "{square_edge:?}"
        );
        assert!(
            (square_edge[12] - expect(tb)).abs() < 1e-4,
            "{square_edge:?}"
        );
        // The neighbour's ends are the triangle's own corners at the same points.
        let triangle_edge = &texels[EDGE_FLOATS..];
        assert_eq!(
            square_edge[4..8],
            [
                triangle_edge[2],
                triangle_edge[3],
                triangle_edge[0],
                triangle_edge[1]
            ]
        );
        assert_eq!(
            triangle_edge[4..8],
            [
                square_edge[2],
                square_edge[3],
                square_edge[0],
                square_edge[1]
            ]
        );
        assert!((triangle_edge[8] - square_edge[12]).abs() < 1e-6);
    }

    #[test]
    fn a_face_with_too_many_smooth_edges_keeps_its_lightmap() {
        // A 40-gon with a ring of 40 quads around it, sloping 10° down: a shallow dome.
        let n = 40;
        let ring = |i: usize, r: f32, y: f32| {
            let phi = std::f32::consts::TAU * i as f32 / n as f32;
            Vec3::new(r * phi.cos(), y, -r * phi.sin())
        };
        let up = |mut v: Vec<Vec3>| {
            if polygon(&v).normal.y < 0.0 {
                v.reverse();
            }
            polygon(&v)
        };
        let drop = -(10f32.to_radians().tan());
        let mut faces = vec![up((0..n).map(|i| ring(i, 1.0, 0.0)).collect())];
        for i in 0..n {
            let (a, b) = (ring(i, 1.0, 0.0), ring(i + 1, 1.0, 0.0));
            faces.push(up(vec![a, ring(i, 2.0, drop), ring(i + 1, 2.0, drop), b]));
        }
        let (_, _, s) = smoothing(faces, DEFAULT_ANGLE);
        assert!(!s.is_smoothed(0));
        // The quads still blend with each other, not towards the cap.
        assert_eq!((s.smoothed_polygons(), s.edge_count()), (n, 2 * n));
    }

    #[test]
    fn bilinear_lookups_match_gl() {
        // 2 x 2 texels: 0 1 / 2 3 (bottom row first).
        let atlas: Vec<f32> = [0.0, 1.0, 2.0, 3.0]
            .iter()
            .flat_map(|&v| [v, v, v, 1.0])
            .collect();
        let at = |x: f32, y: f32| bilinear(&atlas, 2, 2, Vec2::new(x, y)).x;
        assert_eq!(at(0.5, 0.5), 0.0);
        assert_eq!(at(1.5, 1.5), 3.0);
        assert_eq!(at(1.0, 1.0), 1.5);
        assert_eq!(at(1.0, 0.5), 0.5);
        // Clamped to the edge.
        assert_eq!(at(0.0, 0.0), 0.0);
        assert_eq!(at(2.0, 0.5), 1.0);
    }
}
