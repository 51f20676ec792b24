//! Beyond the paper: the near-field part of a face cluster's error bound (`face_clusters.rs`,
//! [`NEAR_FIELD`]). A face cluster shoots with one visibility pass from one point. Near the
//! cluster its members' own outlines give each receiver its share (`cluster_parts.rs`), but what
//! the one point sees stands for what every member would see. Where other polygons crowd close
//! in front of the cluster (a cushion against a sofa's arm, the fins of a radiator, a book
//! between books) the point, deep in the gap, sees only the facing surface, and what the members
//! nearer the gap's mouth would send out of it is lost: on the living room (issue 58) such
//! clusters left the solve's sums one-signed low. A cluster whose point sees more than
//! [`NEAR_FIELD`] of other polygons within its extent shoots as its children do; columns, vaults
//! and arches standing free see little and keep the gain.
//!
//! Computed lazily, node by node, when a shot's walk up the hierarchy first asks (the conference
//! room's 163,375 clusters would take 40 s all at once; a solve asks for a few thousand).

use super::cluster_shooter::cluster_shooter;
use crate::geometry::bounds;
use crate::patches::PatchLayout;
use crate::scene::Scene;
use glam::Vec3;
use std::collections::HashMap;
use std::sync::OnceLock;

/// The most of its shooting point's view (a form factor, the sum over the polygons outside the
/// cluster whose bounds come nearer to the point than the cluster's extent) that a face cluster
/// may give to such polygons. On the living room (to 1 % unshot, against a solve to 0.1 %;
/// docs/perf-log.md, eighteenth session) 0.5 brings the error to an ordinary solve's.
pub const NEAR_FIELD: f32 = 0.5;

/// What the near field of a cluster depends on.
#[derive(Clone, Debug)]
pub struct Cluster {
    /// Its polygons, ascending.
    pub members: Vec<usize>,
    /// Its mean normal.
    pub normal: Vec3,
    /// Its bounds' largest side.
    pub extent: f32,
}

/// Each cluster's near-field factor once asked for, and the index they are found with.
#[derive(Clone, Debug, Default)]
pub struct NearFields {
    /// The grid's cell side (scene units): the clusters' ordinary extent.
    cell: f32,
    /// The polygons filed by grid cell, built at the first question (a hierarchy whose shots
    /// never ask needs none).
    index: OnceLock<Index>,
    /// Per node, its factor ([`NearFields::of`]) once computed.
    factors: Vec<OnceLock<f32>>,
}

/// The scene's polygons by grid cell.
#[derive(Clone, Debug, Default)]
struct Index {
    /// Each polygon's bounds.
    bounds: Vec<(Vec3, Vec3)>,
    /// The polygons whose bounds reach into each cell.
    grid: HashMap<[i64; 3], Vec<u32>>,
    /// Polygons whose bounds span more than [`MOST_CELLS`] cells: every query looks at them.
    large: Vec<u32>,
}

impl PartialEq for NearFields {
    /// Derived data: two hierarchies are equal by their nodes.
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl NearFields {
    /// For `nodes` clusters, finding polygons in cells `cell` wide.
    pub fn new(cell: f32, nodes: usize) -> Self {
        NearFields {
            cell: cell.max(f32::MIN_POSITIVE),
            index: OnceLock::new(),
            factors: (0..nodes).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Cluster `k`'s near-field factor: the sum of the unoccluded form factors from its
    /// shooting point, along its mean normal, to every polygon outside it whose bounds come
    /// nearer to the point than its extent (0 for a single polygon). The point is the one
    /// `cluster_shooter` takes for members of equal radiance. `cluster` describes it, asked
    /// only the first time.
    pub fn of(
        &self,
        k: u32,
        cluster: impl FnOnce() -> Cluster,
        scene: &Scene,
        layout: &PatchLayout,
    ) -> f32 {
        *self.factors[k as usize].get_or_init(|| self.compute(cluster(), scene, layout))
    }

    fn compute(&self, cluster: Cluster, scene: &Scene, layout: &PatchLayout) -> f32 {
        let Cluster {
            members,
            normal,
            extent: reach,
        } = cluster;
        if members.len() < 2 {
            return 0.0;
        }
        let equal: Vec<(usize, Vec3)> = (members.iter())
            .map(|&q| (q, Vec3::splat(scene.polygons[q].area)))
            .collect();
        let patches = &layout.patches_per_polygon;
        let Some(shooter) = cluster_shooter(scene, patches, &equal, Some(normal)) else {
            return 0.0;
        };
        let at = shooter.position;
        let slack = scene.plane_slack();
        let index = self.index.get_or_init(|| Index::new(scene, self.cell));
        let mut seen: Vec<u32> = index.large.clone();
        for key in cells(key(at - reach, self.cell), key(at + reach, self.cell)) {
            seen.extend(index.grid.get(&key).map_or(&[][..], |v| &v[..]));
        }
        seen.sort_unstable();
        seen.dedup();
        (seen.into_iter().map(|q| q as usize))
            .filter(|q| members.binary_search(q).is_err())
            .filter(|&q| {
                let (lo, hi) = index.bounds[q];
                (lo - at).max(at - hi).max(Vec3::ZERO).length() < reach
            })
            .map(|q| {
                let p = &scene.polygons[q];
                super::form_factor::polygon(at, normal, &p.vertices, p.normal, slack)
            })
            .sum()
    }
}

impl Index {
    /// `scene`'s polygons filed in cells `cell` wide.
    fn new(scene: &Scene, cell: f32) -> Self {
        let bounds: Vec<(Vec3, Vec3)> = (scene.polygons.iter())
            .map(|q| bounds(&q.vertices).expect("a polygon has corners"))
            .collect();
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        let mut large = Vec::new();
        for (q, &(lo, hi)) in bounds.iter().enumerate() {
            let (a, b) = (key(lo, cell), key(hi, cell));
            let span: i64 = (0..3).map(|i| b[i] - a[i] + 1).product();
            if span > MOST_CELLS {
                large.push(q as u32);
                continue;
            }
            for key in cells(a, b) {
                grid.entry(key).or_default().push(q as u32);
            }
        }
        Index {
            bounds,
            grid,
            large,
        }
    }
}

/// The most grid cells a polygon's bounds may span and still be filed by cell (a floor tilted
/// across a whole scene would otherwise fill millions).
const MOST_CELLS: i64 = 512;

fn key(x: Vec3, cell: f32) -> [i64; 3] {
    (x / cell).floor().to_array().map(|v| v as i64)
}

/// The grid cells from `a` to `b`, both included.
fn cells(a: [i64; 3], b: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    (a[0]..=b[0])
        .flat_map(move |x| (a[1]..=b[1]).flat_map(move |y| (a[2]..=b[2]).map(move |z| [x, y, z])))
}
