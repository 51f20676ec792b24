//! Beyond the paper, `SolveOptions::face_clusters` (`--face-clusters`, on in the accurate mode;
//! issue 58): shooting from clusters of non-coplanar faces (face-cluster radiosity, Willmott,
//! Heckbert & Garland 1999). A hierarchy over the small polygons of curved surfaces, each node a
//! set of touching polygons whose normals stay within a cone. A small polygon picked by
//! Find_Max_Energy shoots with the largest cluster around it that its error bound allows
//! ([`FaceClusters::shot_of`], [`Bound`]: the [`misdirected`] power within `cut_above` of the
//! emitted power, and a shooting point that sees little of other polygons close in front,
//! `cluster_near.rs`), as one `Shooter` (`ClusterChoice::cluster_of`: the members' summed energy,
//! cleared before the passes and counted as carried in the books, as `clusters.rs`'s are), from
//! the member nearest the power-weighted centre, along the mean normal, with the members'
//! rectangle on that plane as the form factor's outline, and near the cluster the members' own
//! outlines (`cluster_parts.rs`); by reciprocity it delivers no more than it carries. Flat
//! clusters are left to `clusters.rs`, so a scene without small non-coplanar polygons shoots as
//! without.
//!
//! Why: `clusters.rs` groups only coplanar neighbours, so every facet of a column, a chair's seat
//! or a vault shoots alone, with its own visibility pass. Neighbouring facets whose normals
//! differ by a few degrees would shoot nearly the same light from nearly the same place.
//!
//! How: bottom up, greedily, as Garland's dual-graph contraction does: every small polygon (at
//! most `side` patches, not an emitter) is a leaf; the pair of touching clusters whose union has
//! the narrowest cone (then the smallest extent) is merged first, as long as the union's cone
//! half-angle is at most `max_cone` and its bounds fit a cube of `side` patches (the shooter
//! cell a polygon's shot uses). Each node keeps its area-weighted normal sum, its cone and its
//! power-free geometry, so that a shot can choose, polygon by polygon, the largest ancestor
//! whose error bound ([`misdirected`]) it allows, and refine into the children when not.

use super::cluster_near::{Cluster, NearFields, NEAR_FIELD};
use crate::geometry::bounds;
use crate::patches::PatchLayout;
use crate::scene::Scene;
use glam::Vec3;
use std::cmp::Ordering;
use std::collections::{BTreeMap, BinaryHeap};

/// One cluster: a leaf (one polygon) or the union of two children.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// The cluster it was merged into, if any.
    pub parent: Option<u32>,
    /// Its two children; `None` for a leaf.
    pub children: Option<[u32; 2]>,
    /// The polygon of a leaf.
    pub polygon: Option<usize>,
    /// Σ area × normal over its polygons: the direction it shoots along, and its length over
    /// `area` says how flat it is.
    pub normal_sum: Vec3,
    /// Σ area.
    pub area: f32,
    /// Half-angle (radians) of a cone about `normal()` that holds every member's normal.
    pub cone: f32,
    /// The bounds of its polygons' corners.
    pub lo: Vec3,
    /// See `lo`.
    pub hi: Vec3,
    /// Σ patches.
    pub patches: u32,
    /// How many polygons.
    pub size: u32,
}

impl Node {
    /// The unit mean normal (area-weighted).
    pub fn normal(&self) -> Vec3 {
        self.normal_sum.normalize_or_zero()
    }
}

/// The hierarchy: nodes `0..polygons` are not all leaves; a polygon's leaf is `leaf[p]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaceClusters {
    nodes: Vec<Node>,
    leaf: Vec<Option<u32>>,
    /// The near-field part of the bound (`cluster_near.rs`), computed as shots ask.
    near: NearFields,
}

/// A candidate merge, ordered so that the heap pops the narrowest cone, then the smallest extent,
/// then the lowest node IDs (deterministic).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Candidate {
    cone: f32,
    extent: f32,
    a: u32,
    b: u32,
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        // Reversed: BinaryHeap is a max-heap.
        (other.cone.total_cmp(&self.cone))
            .then(other.extent.total_cmp(&self.extent))
            .then(other.a.cmp(&self.a))
            .then(other.b.cmp(&self.b))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Most members a face cluster may shoot with ([`Bound::allows`]): every receiver near its shot
/// sums a factor per member (`cluster_parts.rs`).
pub const MAX_PARTS: u32 = 32;

/// A cone this narrow (radians) counts as flat (`FaceClusters::shot_of`).
pub const FLAT: f32 = 1e-3;

/// The error bound of a face cluster's shot (`FaceClusters::shot_of`), as the solver's options
/// set it (`SolveOptions::face_clusters`).
#[derive(Clone, Copy, Debug)]
pub struct Bound {
    /// The most power a shot may misdirect ([`misdirected`]), and below which it may reach
    /// `coarse_reach` (as a polygon's coarse cells): `cut_above` × the emitted power.
    pub power: f64,
    /// The widest extent (scene units, on every axis) of a cluster carrying more than `power`:
    /// the ordinary shooter cell.
    pub fine_reach: f32,
    /// The most of its shooting point's view other polygons close in front may take
    /// (`cluster_near.rs`): [`NEAR_FIELD`].
    pub near: f32,
}

impl Bound {
    /// The bound for shots of a solve emitting `emitted_power`, with the solve's cut (`cut_above`,
    /// a share of the emitted power) and fine reach (scene units).
    pub fn new(cut_above: f32, emitted_power: f64, fine_reach: f32) -> Self {
        Bound {
            power: cut_above as f64 * emitted_power,
            fine_reach,
            near: NEAR_FIELD,
        }
    }

    /// Whether `node` may shoot as one carrying `power` (its shooting members' unshot power):
    /// also, no more members than a shot's near field sums ([`MAX_PARTS`]).
    pub fn allows(&self, node: &Node, power: f64) -> bool {
        let extent = (node.hi - node.lo).max_element();
        node.size <= MAX_PARTS
            && misdirected(node.cone, power) <= self.power
            && (power < self.power || extent <= self.fine_reach)
    }
}

/// The power, of `power` shot by a cluster of cone half-angle `cone` from its mean plane, that
/// may go in other directions than its members would send it: a member's cosine towards any
/// receiver differs from the mean plane's by at most the sine of the angle between their normals.
pub fn misdirected(cone: f32, power: f64) -> f64 {
    power * (cone.min(std::f32::consts::FRAC_PI_2) as f64).sin()
}

impl FaceClusters {
    /// The hierarchy over `scene`'s polygons of at most `side` patches (`layout`) that are not
    /// emitters, merging touching clusters while the union's cone half-angle stays within
    /// `max_cone` (radians) and its bounds within `side` patches on every axis.
    pub fn new(scene: &Scene, layout: &PatchLayout, side: u32, max_cone: f32) -> FaceClusters {
        let n = scene.polygons.len();
        let mut clusters = FaceClusters {
            nodes: Vec::new(),
            leaf: vec![None; n],
            near: NearFields::default(),
        };
        let reach = side as f32 * layout.patch_size;
        for (p, polygon) in scene.polygons.iter().enumerate() {
            let count = layout.patches_per_polygon[p];
            if count == 0 || count > side || scene.material(polygon).is_emitter() {
                continue;
            }
            let (lo, hi) = bounds(&polygon.vertices).expect("a polygon has corners");
            clusters.leaf[p] = Some(clusters.nodes.len() as u32);
            clusters.nodes.push(Node {
                parent: None,
                children: None,
                polygon: Some(p),
                normal_sum: polygon.normal * polygon.area,
                area: polygon.area,
                cone: 0.0,
                lo,
                hi,
                patches: count,
                size: 1,
            });
        }
        let mut neighbours = clusters.touching(scene, layout.patch_size * 1e-3);
        let mut heap = BinaryHeap::new();
        for a in 0..clusters.nodes.len() as u32 {
            for &b in &neighbours[a as usize] {
                if a < b {
                    clusters.consider(a, b, max_cone, reach, &mut heap);
                }
            }
        }
        while let Some(Candidate { a, b, .. }) = heap.pop() {
            let (na, nb) = (&clusters.nodes[a as usize], &clusters.nodes[b as usize]);
            if na.parent.is_some() || nb.parent.is_some() {
                continue;
            }
            let c = clusters.nodes.len() as u32;
            let union = merged(na, nb);
            clusters.nodes[a as usize].parent = Some(c);
            clusters.nodes[b as usize].parent = Some(c);
            clusters.nodes.push(Node {
                children: Some([a, b]),
                ..union
            });
            // The union's neighbours: the children's, less the children.
            let mut around: Vec<u32> = (neighbours[a as usize].iter())
                .chain(&neighbours[b as usize])
                .copied()
                .filter(|&x| x != a && x != b)
                .collect();
            around.sort_unstable();
            around.dedup();
            for &x in &around {
                let list = &mut neighbours[x as usize];
                list.retain(|&y| y != a && y != b);
                list.push(c);
                clusters.consider(c, x, max_cone, reach, &mut heap);
            }
            neighbours.push(around);
        }
        clusters.near = NearFields::new(reach, clusters.nodes.len());
        clusters
    }

    /// Queue the merge of roots `a` and `b` if their union is within the bounds.
    fn consider(
        &self,
        a: u32,
        b: u32,
        max_cone: f32,
        reach: f32,
        heap: &mut BinaryHeap<Candidate>,
    ) {
        let union = merged(&self.nodes[a as usize], &self.nodes[b as usize]);
        let extent = (union.hi - union.lo).max_element();
        if union.cone <= max_cone && extent <= reach {
            heap.push(Candidate {
                cone: union.cone,
                extent,
                a,
                b,
            });
        }
    }

    /// Per leaf, the leaves whose polygons share a corner with its own (within `tolerance`),
    /// ascending.
    fn touching(&self, scene: &Scene, tolerance: f32) -> Vec<Vec<u32>> {
        let mut at: BTreeMap<[i64; 3], Vec<u32>> = BTreeMap::new();
        for (i, node) in self.nodes.iter().enumerate() {
            let p = node.polygon.expect("leaves only");
            for x in &scene.polygons[p].vertices {
                let key = (*x / tolerance).round().to_array().map(|v| v as i64);
                at.entry(key).or_default().push(i as u32);
            }
        }
        let mut neighbours = vec![Vec::new(); self.nodes.len()];
        for mut list in at.into_values() {
            list.sort_unstable();
            list.dedup();
            // A fan of many faces around one corner (a pole) is joined as a chain: it stays
            // connected without a pair for every two of its faces.
            if list.len() > 16 {
                for w in list.windows(2) {
                    neighbours[w[0] as usize].push(w[1]);
                    neighbours[w[1] as usize].push(w[0]);
                }
                continue;
            }
            for (k, &a) in list.iter().enumerate() {
                for &b in &list[k + 1..] {
                    neighbours[a as usize].push(b);
                    neighbours[b as usize].push(a);
                }
            }
        }
        for list in &mut neighbours {
            list.sort_unstable();
            list.dedup();
        }
        neighbours
    }

    /// Every node, leaves first.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// Polygon `p`'s leaf, if it is in the hierarchy.
    pub fn leaf_of(&self, p: usize) -> Option<u32> {
        self.leaf.get(p).copied().flatten()
    }

    /// The polygons of node `node`, ascending.
    pub fn members(&self, node: u32) -> Vec<usize> {
        let mut out = Vec::new();
        let mut stack = vec![node];
        while let Some(k) = stack.pop() {
            let n = &self.nodes[k as usize];
            match (n.children, n.polygon) {
                (Some([a, b]), _) => stack.extend([a, b]),
                (None, Some(p)) => out.push(p),
                (None, None) => {}
            }
        }
        out.sort_unstable();
        out
    }

    /// The largest cluster of two or more polygons that holds `p` and that `allows` (given the
    /// node's index and the node; with every smaller one on the way up from `p`'s leaf): the node
    /// a shot of `p` would shoot, or `None` when `p` should shoot alone. `allows` should grow
    /// stricter up the tree (a larger cluster carries more power and has a wider cone, as
    /// [`misdirected`] does).
    pub fn shooting_cluster(&self, p: usize, allows: impl Fn(u32, &Node) -> bool) -> Option<u32> {
        let mut at = self.leaf_of(p)?;
        let mut best = None;
        while let Some(up) = self.nodes[at as usize].parent {
            if !allows(up, &self.nodes[up as usize]) {
                break;
            }
            best = Some(up);
            at = up;
        }
        best
    }

    /// The shot of `p` with its face cluster: the members that shoot (`p` among them) and the
    /// cluster's mean normal, or `None` when `p` shoots alone or the cluster its bound allows is
    /// flat (its cone 0: the coplanar clusters of `clusters.rs` take those, as without face
    /// clusters). `power(q)` is what polygon q would carry in this shot (its unshot power by
    /// magnitude), `None` when q may not shoot now (taken by the step, or of the other sign).
    /// The bound ([`Bound::allows`]): the largest cluster whose misdirected power is within the
    /// bound, if at least two of its members shoot; refining a cluster that is not allowed is
    /// the walk stopping at a child.
    pub fn shot_of(
        &self,
        p: usize,
        power: impl Fn(usize) -> Option<f64>,
        bound: &Bound,
        scene: &Scene,
        layout: &PatchLayout,
    ) -> Option<(Vec<usize>, Vec3)> {
        let shooting = |node: u32| -> (Vec<usize>, f64) {
            let (mut members, mut sum) = (Vec::new(), 0.0);
            for q in self.members(node) {
                if let Some(w) = power(q) {
                    members.push(q);
                    sum += w;
                }
            }
            (members, sum)
        };
        // The near field last: the costliest test, computed once per node when first asked.
        // Flat clusters shoot as coplanar ones do (below): their near field does not matter.
        let allows = |id: u32, node: &Node| {
            bound.allows(node, shooting(id).1)
                && (node.cone <= FLAT || self.near_field(id, scene, layout) <= bound.near)
        };
        let node = self.shooting_cluster(p, allows)?;
        let n = &self.nodes[node as usize];
        // A flat cluster's normals agree to a thousandth of a radian (`angle` reads 0 for
        // parallel ones): those shoot as before.
        if n.cone <= FLAT {
            return None;
        }
        let (members, _) = shooting(node);
        (members.len() >= 2 && members.contains(&p)).then(|| (members, n.normal()))
    }

    /// Node `k`'s near-field factor (`cluster_near.rs`): how much of its shooting point's view
    /// other polygons closer than its extent take.
    pub fn near_field(&self, k: u32, scene: &Scene, layout: &PatchLayout) -> f32 {
        let node = &self.nodes[k as usize];
        let cluster = || Cluster {
            members: self.members(k),
            normal: node.normal(),
            extent: (node.hi - node.lo).max_element(),
        };
        self.near.of(k, cluster, scene, layout)
    }

    /// Clusters of two or more polygons that were merged into nothing larger (the roots).
    pub fn roots(&self) -> impl Iterator<Item = u32> + '_ {
        (self.nodes.iter().enumerate())
            .filter(|(_, n)| n.parent.is_none() && n.children.is_some())
            .map(|(i, _)| i as u32)
    }
}

/// The union of two clusters: normal sums and areas added, bounds joined, and a cone about the
/// union's mean normal that holds both children's cones (a bound: each child's normals lie within
/// its cone about its own mean).
fn merged(a: &Node, b: &Node) -> Node {
    let normal_sum = a.normal_sum + b.normal_sum;
    let mean = normal_sum.normalize_or_zero();
    let spread = |n: &Node| {
        if mean == Vec3::ZERO {
            return std::f32::consts::PI;
        }
        angle(n.normal(), mean) + n.cone
    };
    Node {
        parent: None,
        children: None,
        polygon: None,
        normal_sum,
        area: a.area + b.area,
        cone: spread(a).max(spread(b)),
        lo: a.lo.min(b.lo),
        hi: a.hi.max(b.hi),
        patches: a.patches + b.patches,
        size: a.size + b.size,
    }
}

/// The angle between unit vectors `a` and `b`, accurate near 0 (an `acos` of a float dot product
/// reads 3e-4 rad for parallel normals, and the cones of a flat floor's clusters would grow with
/// every merge).
fn angle(a: Vec3, b: Vec3) -> f32 {
    a.cross(b).length().atan2(a.dot(b))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patches::{PatchLayout, Resolution};
    use crate::scene::{test_scene, Material, Polygon};

    /// A cylinder of radius 1 about Y, `around` facets round and `rows` rows of height `h`,
    /// facing out, then its top cap of `around` triangles.
    fn cylinder(around: usize, rows: usize, h: f32) -> Vec<Polygon> {
        let at = |k: usize, y: f32| {
            let a = std::f32::consts::TAU * (k % around) as f32 / around as f32;
            Vec3::new(a.cos(), y, -a.sin())
        };
        let mut polygons = Vec::new();
        for r in 0..rows {
            let (y0, y1) = (r as f32 * h, (r + 1) as f32 * h);
            for k in 0..around {
                let quad = vec![at(k, y0), at(k + 1, y0), at(k + 1, y1), at(k, y1)];
                polygons.push(Polygon::new(quad, 0, "column".into()).unwrap());
            }
        }
        let top = rows as f32 * h;
        for k in 0..around {
            let tri = vec![Vec3::new(0.0, top, 0.0), at(k, top), at(k + 1, top)];
            polygons.push(Polygon::new(tri, 0, "cap".into()).unwrap());
        }
        polygons
    }

    /// Every node's cone holds its members' normals, its members touch (the node is connected),
    /// its bounds fit `reach`, and its counts add up.
    fn check(scene: &Scene, c: &FaceClusters, max_cone: f32, reach: f32) {
        for (i, node) in c.nodes().iter().enumerate() {
            let members = c.members(i as u32);
            assert_eq!(members.len() as u32, node.size);
            assert!(node.cone <= max_cone + 1e-6, "{}", node.cone);
            assert!((node.hi - node.lo).max_element() <= reach + 1e-5);
            for &p in &members {
                let n = scene.polygons[p].normal;
                assert!(angle(n, node.normal()) <= node.cone + 1e-4, "{p} in {i}");
            }
        }
    }

    #[test]
    fn a_faceted_column_clusters_within_its_cone_and_never_over_its_rim() {
        // 48 facets round (7.5° apart), 16 rows, faces of about 0.13 × 0.125.
        let scene = test_scene(cylinder(48, 16, 0.125));
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(0.2));
        let max_cone = 20f32.to_radians();
        let side = 8;
        let c = FaceClusters::new(&scene, &layout, side, max_cone);
        check(&scene, &c, max_cone, side as f32 * 0.2);
        let roots: Vec<u32> = c.roots().collect();
        assert!(!roots.is_empty());
        // No cluster holds both a side facet and a cap triangle (90° apart).
        for &r in &roots {
            let members = c.members(r);
            let caps = members.iter().filter(|&&p| p >= 48 * 16).count();
            assert!(caps == 0 || caps == members.len(), "{members:?}");
        }
        // The side facets form clusters several facets round and several rows high: far fewer
        // shooters than facets.
        let side_roots = roots.iter().filter(|&&r| c.members(r)[0] < 48 * 16).count();
        assert!(side_roots * 8 <= 48 * 16, "{side_roots} clusters");
        let widest = (roots.iter().map(|&r| c.nodes()[r as usize].size)).max();
        assert!(widest >= Some(12), "{widest:?}");
    }

    #[test]
    fn a_flat_floor_clusters_with_no_cone_and_a_fold_splits() {
        // Tiles of 1 × 1 on the floor (y = 0) and on a wall (x = 0) standing on its edge.
        let tile = |o: Vec3, u: Vec3, v: Vec3| {
            Polygon::new(vec![o, o + u, o + u + v, o + v], 0, "tile".into()).unwrap()
        };
        let mut polygons = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                let (x, z) = (i as f32, j as f32);
                polygons.push(tile(Vec3::new(x, 0.0, z), Vec3::Z, Vec3::X));
                polygons.push(tile(Vec3::new(0.0, x, z), Vec3::Y, Vec3::Z));
            }
        }
        let scene = test_scene(polygons);
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(1.0));
        let c = FaceClusters::new(&scene, &layout, 8, 20f32.to_radians());
        check(&scene, &c, 20f32.to_radians(), 8.0);
        let roots: Vec<u32> = c.roots().collect();
        assert_eq!(roots.len(), 2, "the floor and the wall");
        for &r in &roots {
            assert_eq!(c.nodes()[r as usize].size, 16);
            assert!(c.nodes()[r as usize].cone < 1e-6);
        }
    }

    #[test]
    fn emitters_large_polygons_and_strangers_are_left_out() {
        let mut polygons = cylinder(24, 2, 0.25);
        // A far quad touching nothing.
        polygons.push(
            Polygon::new(
                vec![
                    Vec3::new(5.0, 0.0, 5.0),
                    Vec3::new(5.0, 0.0, 5.2),
                    Vec3::new(5.2, 0.0, 5.2),
                    Vec3::new(5.2, 0.0, 5.0),
                ],
                0,
                "alone".into(),
            )
            .unwrap(),
        );
        let mut scene = test_scene(polygons);
        scene.materials.push(Material {
            name: "lamp".into(),
            kd: Vec3::ZERO,
            ke: Vec3::ONE,
        });
        scene.polygons[0].material = 1;
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(0.25));
        let c = FaceClusters::new(&scene, &layout, 4, 30f32.to_radians());
        assert_eq!(c.leaf_of(0), None, "an emitter");
        let alone = scene.polygons.len() - 1;
        let leaf = c.leaf_of(alone).unwrap();
        assert_eq!(c.nodes()[leaf as usize].parent, None);
        assert_eq!(c.shooting_cluster(alone, |_, _| true), None);
        // With side 1, only polygons of one patch are leaves: the column's facets (0.26 × 0.25)
        // are, the caps' triangles too; nothing larger than a patch.
        let one = FaceClusters::new(&scene, &layout, 1, 30f32.to_radians());
        for (p, &k) in layout.patches_per_polygon.iter().enumerate() {
            assert_eq!(
                one.leaf_of(p).is_some(),
                k == 1 && p != 0,
                "{p}: {k} patches"
            );
        }
        // The same scene gives the same hierarchy.
        assert_eq!(FaceClusters::new(&scene, &layout, 4, 30f32.to_radians()), c);
    }

    #[test]
    fn a_shot_takes_the_largest_cluster_its_bound_allows() {
        let scene = test_scene(cylinder(48, 16, 0.125));
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(0.2));
        let c = FaceClusters::new(&scene, &layout, 8, 20f32.to_radians());
        let p = 100;
        let all = c.shooting_cluster(p, |_, _| true).unwrap();
        assert_eq!(c.nodes()[all as usize].parent, None);
        assert!(c.members(all).contains(&p));
        assert_eq!(c.shooting_cluster(p, |_, _| false), None);
        // A bound on what may go astray: a shot of power 1 allows 0.1 misdirected; the node is
        // the largest within it, and its parent is not.
        let allows = |n: &Node| misdirected(n.cone, 1.0) <= 0.1;
        let node = c.shooting_cluster(p, |_, n| allows(n)).unwrap();
        assert!(allows(&c.nodes()[node as usize]));
        if let Some(up) = c.nodes()[node as usize].parent {
            assert!(!allows(&c.nodes()[up as usize]));
        }
        assert!(c.members(node).contains(&p) && c.members(node).len() >= 2);
        // Misdirected power grows with the cone.
        assert_eq!(misdirected(0.0, 1.0), 0.0);
        assert!(misdirected(0.2, 1.0) > misdirected(0.1, 1.0));
    }

    #[test]
    fn a_shot_is_refined_as_its_power_grows_and_flat_clusters_are_left_alone() {
        let scene = test_scene(cylinder(48, 16, 0.125));
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(0.2));
        let c = FaceClusters::new(&scene, &layout, 8, 20f32.to_radians());
        let p = 100;
        let bound = Bound {
            power: 1.0,
            fine_reach: 4.0 * 0.2,
            near: NEAR_FIELD,
        };
        // Each facet carries `w`: the larger the shot, the smaller the cluster the bound allows,
        // down to none (the facet shoots alone).
        let sizes: Vec<usize> = [1e-3, 1e-2, 0.05, 0.2, 10.0]
            .iter()
            .map(|&w| {
                c.shot_of(p, |_| Some(w), &bound, &scene, &layout)
                    .map_or(1, |(m, _)| m.len())
            })
            .collect();
        assert!(sizes.windows(2).all(|s| s[1] <= s[0]), "{sizes:?}");
        assert!(sizes[0] >= 12 && sizes[4] == 1, "{sizes:?}");
        // The members that may not shoot now stay out; the rest still hold p.
        let (all, normal) = c
            .shot_of(p, |_| Some(1e-3), &bound, &scene, &layout)
            .unwrap();
        let odd = |q: usize| q % 2 == 1 || q == p;
        let (some, _) = c
            .shot_of(p, |q| odd(q).then_some(1e-3), &bound, &scene, &layout)
            .unwrap();
        assert!(some.contains(&p) && some.iter().all(|&q| odd(q)) && some.len() < all.len());
        // Within the bound: what may go astray of the members' power along the mean normal.
        let node = c.shooting_cluster(p, |_, _| true).unwrap();
        assert!(normal.dot(c.nodes()[node as usize].normal()) > 0.9);
        // A flat floor's cluster is the coplanar clusters' to shoot.
        let flat = test_scene(
            (0..16)
                .map(|i| {
                    let o = Vec3::new((i % 4) as f32, 0.0, (i / 4) as f32);
                    Polygon::new(
                        vec![o, o + Vec3::Z, o + Vec3::X + Vec3::Z, o + Vec3::X],
                        0,
                        "t".into(),
                    )
                    .unwrap()
                })
                .collect(),
        );
        let flat_layout = PatchLayout::new(&flat, Resolution::PatchSize(1.0));
        let f = FaceClusters::new(&flat, &flat_layout, 8, 20f32.to_radians());
        assert!(f.shooting_cluster(0, |_, _| true).is_some());
        assert_eq!(
            f.shot_of(0, |_| Some(1e-3), &bound, &flat, &flat_layout),
            None
        );
    }

    #[test]
    fn a_cluster_with_a_surface_close_in_front_shoots_as_its_children() {
        // A column alone: its side clusters see nothing near in front (the cap lies behind
        // their planes).
        let mut polygons = cylinder(48, 16, 0.125);
        let alone = test_scene(polygons.clone());
        let alone_layout = PatchLayout::new(&alone, Resolution::PatchSize(0.2));
        let free = FaceClusters::new(&alone, &alone_layout, 8, 20f32.to_radians());
        let inner = |c: &FaceClusters| {
            (0..c.nodes().len() as u32)
                .filter(|&k| c.nodes()[k as usize].children.is_some())
                .collect::<Vec<u32>>()
        };
        let most = (inner(&free).into_iter())
            .map(|k| free.near_field(k, &alone, &alone_layout))
            .fold(0f32, f32::max);
        assert!(most <= 0.05, "{most}");
        // A wall 1 cm from its side at x = 1, facing the column: the clusters on that side see
        // it; those facing away do not.
        let mut wall: Vec<Vec3> = [(1.01, -1.0, -1.0), (1.01, -1.0, 3.0), (1.01, 3.0, 3.0)]
            .iter()
            .chain(&[(1.01, 3.0, -1.0)])
            .map(|&(x, y, z)| Vec3::new(x, z, y))
            .collect();
        if Polygon::new(wall.clone(), 0, "wall".into())
            .unwrap()
            .normal
            .x
            > 0.0
        {
            wall.reverse();
        }
        polygons.push(Polygon::new(wall, 0, "wall".into()).unwrap());
        let scene = test_scene(polygons);
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(0.2));
        let c = FaceClusters::new(&scene, &layout, 8, 20f32.to_radians());
        let facing = |k: u32| c.nodes()[k as usize].normal().x;
        let (front, back): (Vec<u32>, Vec<u32>) =
            inner(&c).into_iter().partition(|&k| facing(k) > 0.9);
        assert!(!front.is_empty() && !back.is_empty());
        let near = |k: u32| c.near_field(k, &scene, &layout);
        assert!(front.iter().all(|&k| near(k) > NEAR_FIELD), "{front:?}");
        assert!(back
            .iter()
            .filter(|&&k| facing(k) < 0.0)
            .all(|&k| near(k) == 0.0));
        // A cheap shot of a facet facing the wall shoots alone, or with a cluster that sees less;
        // one facing away keeps the cluster it had without the wall.
        let bound = Bound {
            power: 1.0,
            fine_reach: 4.0 * 0.2,
            near: NEAR_FIELD,
        };
        let shot = |p: usize| c.shot_of(p, |_| Some(1e-3), &bound, &scene, &layout);
        let p = (0..48 * 16)
            .find(|&p| scene.polygons[p].normal.x > 0.99)
            .unwrap();
        if let Some((members, _)) = shot(p) {
            let node = c.shooting_cluster(p, |_, n| bound.allows(n, 1e-3)).unwrap();
            assert!(members.len() >= 2 && members.len() < c.members(node).len());
        }
        let away = (0..48 * 16)
            .find(|&p| scene.polygons[p].normal.x < -0.99)
            .unwrap();
        let without = free.shot_of(away, |_| Some(1e-3), &bound, &alone, &alone_layout);
        assert!(without.is_some());
        assert_eq!(shot(away).map(|s| s.0), without.map(|s| s.0));
    }
}
