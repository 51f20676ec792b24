//! Clusters, beyond the paper, for scenes made of many small polygons: small coplanar polygons
//! that lie in one square of a grid on their plane shoot together, as one shooter, from one
//! point, with one visibility pass.
//!
//! Why: the paper's loop shoots one polygon per step, each with its own visibility pass. A scene
//! of tens of thousands of polygons of a patch or two each (a voxel world's faces, whose
//! materials differ block by block, so that merging leaves them apart) needs as many steps to
//! shoot its light once, and never reaches the stopping rule (Lost Empire: 6.5 % unshot after
//! 10,000 shots). A small polygon's late shot carries little, and its neighbours in the same
//! plane would shoot nearly the same thing from nearly the same place: one shot serves them all.
//!
//! What keeps it right: a cluster is no larger than the cell a polygon of its shot's size would
//! shoot from (the ordinary cell's side in any shot, `SolveOptions::cluster_cell` only in shots
//! below `SolveOptions::cut_above`, as coarse cells), its members touch (tiles on both sides of
//! a wall standing on them do not) and carry energy of one sign, and it is never an emitter; the
//! cluster shoots from the centre of the member nearest its power-weighted centre (a point on a
//! real surface, not between members, where a column standing among them could hide it), with
//! the rectangle around its members as the outline of the polygon form factor (its energy spread
//! over that rectangle: exact far away, and never more than it carried, by reciprocity); every
//! member's unshot energy is cleared, and the shot's books count each member's energy as carried
//! (`Solver::shoot_step`), so the balance judges it. Which cluster, if any, shoots with the
//! polygon Find_Max_Energy picked is [`ClusterChoice::cluster_of`]. Scenes whose polygons
//! average more than [`AVERAGE_PATCHES`] patches (the Table 1 rooms, the Cornell boxes) have no
//! clusters: their shots stay as they were.

pub use super::cluster_shooter::cluster_shooter;
use super::face_clusters::{self, FaceClusters};
use super::find_max_energy::EnergyTotals;
use super::{item_buffer_side, Shooter, SolveOptions};
use crate::patches::PatchLayout;
use crate::scene::Scene;
use std::collections::BTreeMap;

/// Scenes whose polygons have more patches than this on average form no clusters: their
/// polygons are large enough to shoot alone (the simple room has 9.0, the complex room 10.1;
/// Lost Empire 1.6, the conference room 1.9).
pub const AVERAGE_PATCHES: f64 = 4.0;

/// The small coplanar polygons of a scene grouped into clusters, at two sizes: fine clusters
/// (squares of the ordinary shooter cell) for any shot, coarse ones (squares of
/// `SolveOptions::cluster_cell`) for small shots, as a polygon's cells are
/// (`SolveOptions::coarse_cell`). A fine cluster lies within one coarse cluster.
#[derive(Clone, Debug, Default)]
pub struct Clusters {
    fine: Level,
    coarse: Level,
}

/// One size of clusters.
#[derive(Clone, Debug, Default)]
struct Level {
    /// Per polygon, its cluster's index, if it has one.
    of: Vec<Option<u32>>,
    /// Each cluster's polygons, ascending.
    members: Vec<Vec<usize>>,
}

impl Clusters {
    /// No clusters: every polygon shoots alone (the paper).
    pub fn none(polygons: usize) -> Clusters {
        Clusters {
            fine: Level::none(polygons),
            coarse: Level::none(polygons),
        }
    }

    /// The clusters of `scene` laid out as `layout`, fine in squares of `fine` patches, coarse
    /// in squares of `coarse` (0: no clusters at all; `fine` 0 or above `coarse`: coarse only).
    /// A scene of large polygons ([`AVERAGE_PATCHES`]) has none.
    pub fn new(scene: &Scene, layout: &PatchLayout, fine: u32, coarse: u32) -> Clusters {
        let n = scene.polygons.len();
        if coarse == 0 || !small_polygons(scene, layout) {
            return Clusters::none(n);
        }
        let fine = if fine == 0 || fine >= coarse {
            Level::none(n)
        } else {
            Level::new(scene, layout, fine)
        };
        Clusters {
            fine,
            coarse: Level::new(scene, layout, coarse),
        }
    }

    /// The polygons of `p`'s coarse (`coarse`) or fine cluster (`p` among them), or `None` if
    /// it has none of that size.
    pub fn members_of(&self, p: usize, coarse: bool) -> Option<&[usize]> {
        let level = if coarse { &self.coarse } else { &self.fine };
        let c = (*level.of.get(p)?)?;
        Some(&level.members[c as usize])
    }

    /// How many coarse clusters there are.
    pub fn count(&self) -> usize {
        self.coarse.members.len()
    }

    /// How many fine clusters there are.
    pub fn fine_count(&self) -> usize {
        self.fine.members.len()
    }

    /// How many polygons belong to a cluster (every one of a fine cluster is in a coarse one).
    pub fn clustered_polygons(&self) -> usize {
        self.coarse.members.iter().map(Vec::len).sum()
    }
}

/// Whether `scene`'s own polygons average at most [`AVERAGE_PATCHES`] patches (`layout`): only
/// then do its small polygons shoot in clusters, coplanar or not (`face_clusters.rs`).
pub fn small_polygons(scene: &Scene, layout: &PatchLayout) -> bool {
    // The scene's own polygons decide: the sky (`--sky`) has one patch to a quad.
    let own = scene.own_polygons().len();
    let patches = layout.patch_count() - (scene.polygons.len() - own) as u64;
    own > 0 && patches as f64 / own as f64 <= AVERAGE_PATCHES
}

impl Level {
    fn none(polygons: usize) -> Level {
        Level {
            of: vec![None; polygons],
            members: Vec::new(),
        }
    }

    /// Polygons of at most `side` patches that are not emitters, grouped by plane (normal and
    /// offset, to a thousandth and a hundredth of a patch) and by square of `side` × `side`
    /// patches on it, then split into groups that touch (share a corner): tiles on both sides
    /// of a wall standing on them do not, and must not shoot from one side. Groups of one are
    /// left alone.
    fn new(scene: &Scene, layout: &PatchLayout, side: u32) -> Level {
        let n = scene.polygons.len();
        let length = side as f32 * layout.patch_size;
        let offset_step = layout.patch_size * 0.01;
        // A BTreeMap, so that the clusters come in the same order on every run.
        let mut groups: BTreeMap<([i32; 3], i64, i64, i64), Vec<usize>> = BTreeMap::new();
        for (p, polygon) in scene.polygons.iter().enumerate() {
            let count = layout.patches_per_polygon[p];
            if count == 0 || count > side || scene.material(polygon).is_emitter() {
                continue;
            }
            let normal = (polygon.normal * 1000.0).round();
            let key_normal = normal.to_array().map(|v| v as i32);
            // The grid's axes from the rounded normal, so that every member uses the same ones.
            let (u, v) = normal.normalize().any_orthonormal_pair();
            let c = polygon.centroid;
            let key = (
                key_normal,
                (polygon.normal.dot(c) / offset_step).round() as i64,
                (c.dot(u) / length).floor() as i64,
                (c.dot(v) / length).floor() as i64,
            );
            groups.entry(key).or_default().push(p);
        }
        let mut level = Level::none(n);
        let corner = layout.patch_size * 1e-3;
        for group in groups.into_values().filter(|m| m.len() > 1) {
            for members in touching(scene, &group, corner) {
                let index = level.members.len() as u32;
                for &p in &members {
                    level.of[p] = Some(index);
                }
                level.members.push(members);
            }
        }
        level
    }
}

/// `group`'s polygons split into sets that touch, directly or through each other (a corner
/// within `tolerance` of another's); sets of one left out; each ascending, in order of their
/// first polygon.
fn touching(scene: &Scene, group: &[usize], tolerance: f32) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..group.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut first_at: std::collections::HashMap<[i64; 3], usize> = Default::default();
    for (i, &p) in group.iter().enumerate() {
        for x in &scene.polygons[p].vertices {
            let key = (*x / tolerance).round().to_array().map(|v| v as i64);
            let j = *first_at.entry(key).or_insert(i);
            let (a, b) = (root(&mut parent, i), root(&mut parent, j));
            parent[a.max(b)] = a.min(b);
        }
    }
    let mut sets: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (i, &p) in group.iter().enumerate() {
        let r = root(&mut parent, i);
        sets.entry(r).or_default().push(p);
    }
    sets.into_values().filter(|s| s.len() > 1).collect()
}

/// The hierarchy a solve with `options` shoots from on `scene` (laid out as `layout`), if any.
/// Without cells, coarse clusters or a bound (the paper's mode) there is nothing to bound a face
/// cluster's shot by; scenes of large polygons (the Table 1 rooms: their small non-coplanar ones
/// would shoot 1–3 % fewer shots) shoot as without, as they do without coplanar clusters; and a
/// hierarchy of flat clusters only (Lost Empire's blocks) would shoot nothing `clusters.rs` does
/// not. Without one the reconstruction shader leaves the near field's code out.
pub fn face_clusters(
    scene: &Scene,
    layout: &PatchLayout,
    options: &SolveOptions,
) -> Option<FaceClusters> {
    let applies = options.face_clusters
        && options.shooter_cell > 0
        && options.cluster_cell > 0
        && options.cut_above > 0.0
        && small_polygons(scene, layout);
    if !applies {
        return None;
    }
    let cone = super::FACE_CONE_DEGREES.to_radians();
    let hierarchy = FaceClusters::new(scene, layout, options.cluster_cell, cone);
    (hierarchy.nodes().iter())
        .any(|n| n.children.is_some() && n.cone > face_clusters::FLAT)
        .then_some(hierarchy)
}

/// A polygon whose unshot energy a cluster's shooter carries: the shooter's index among the
/// step's shooters, and the energy (Σ L·A, RGB) the shot takes from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Member {
    /// Index of its cluster's shooter in the step's shooters.
    pub shooter: usize,
    /// The polygon.
    pub polygon: usize,
    /// What it carries: its unshot energy when the step began.
    pub energy: glam::Vec3,
    /// Whether its cluster is a face cluster (`face_clusters.rs`), not a coplanar one.
    pub face: bool,
}

/// What choosing a step's cluster shots reads of the solve (`Solver::next_shooters`).
pub struct ClusterChoice<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The caller's layout (patch size, patches per polygon).
    pub layout: &'a PatchLayout,
    /// The solve's options (`cut_above`, `shooter_cell`, the item-buffer sides).
    pub options: &'a SolveOptions,
    /// Every polygon's unshot energy, as last read back.
    pub totals: &'a EnergyTotals,
    /// The scene's emitted power.
    pub emitted_power: f64,
    /// The coplanar clusters.
    pub clusters: &'a Clusters,
    /// The face clusters (`SolveOptions::face_clusters`), if the solve uses them.
    pub face_clusters: Option<&'a FaceClusters>,
}

impl ClusterChoice<'_> {
    /// Beyond the paper: the shooter of `p`'s cluster ([`Clusters`]) and its members, when `p`
    /// belongs to one and at least two of its members have something to shoot of the same sign
    /// as `p`'s (not in `taken`; every channel ≥ 0, or with overshooting every channel ≤ 0: a
    /// shot carries light or takes back what was overshot, never both): the coarse cluster when
    /// its members carry less than `cut_above` of the emitted power together (as a polygon's
    /// coarse cells), else the fine one. `None`: `p` shoots alone.
    pub fn cluster_of(&self, p: usize, taken: &[usize]) -> Option<(Shooter, Vec<Member>)> {
        let totals = self.totals;
        let sign = |e: glam::Vec3| {
            if e.min_element() >= 0.0 && e.max_element() > 0.0 {
                1
            } else if e.max_element() <= 0.0 && e.min_element() < 0.0 {
                -1
            } else {
                0
            }
        };
        let of_p = sign(totals.energy_rgb(p));
        if of_p == 0 {
            return None;
        }
        if let Some(found) = self.face_cluster_of(p, taken, |q| sign(totals.energy_rgb(q)) == of_p)
        {
            return Some(found);
        }
        let shooting = |coarse: bool| -> Option<Vec<(usize, glam::Vec3)>> {
            let members: Vec<(usize, glam::Vec3)> = (self.clusters.members_of(p, coarse)?)
                .iter()
                .filter(|q| !taken.contains(q))
                .map(|&q| (q, totals.energy_rgb(q)))
                .filter(|&(_, e)| sign(e) == of_p)
                .collect();
            (members.len() >= 2 && members.iter().any(|&(q, _)| q == p)).then_some(members)
        };
        let small = |members: &Vec<(usize, glam::Vec3)>| {
            let power: f64 = members.iter().map(|&(q, _)| totals.magnitude(q)).sum();
            power < self.options.cut_above as f64 * self.emitted_power
        };
        let members = match shooting(true) {
            Some(coarse) if small(&coarse) => coarse,
            _ => shooting(false)?,
        };
        self.cluster_shot(members, None)
    }

    /// Beyond the paper (`SolveOptions::face_clusters`): the shooter of the face cluster that
    /// `p` shoots with and its members, those not in `taken` and of `p`'s sign (`same_sign`),
    /// when the cluster its error bound allows is not flat (`FaceClusters::shot_of`): it shoots
    /// along the cluster's mean normal, and only its direction errs.
    fn face_cluster_of(
        &self,
        p: usize,
        taken: &[usize],
        same_sign: impl Fn(usize) -> bool,
    ) -> Option<(Shooter, Vec<Member>)> {
        let hierarchy = self.face_clusters?;
        let totals = self.totals;
        let bound = face_clusters::Bound::new(
            self.options.cut_above,
            self.emitted_power,
            self.options.shooter_cell as f32 * self.layout.patch_size,
        );
        let power = |q: usize| (!taken.contains(&q) && same_sign(q)).then(|| totals.magnitude(q));
        let (members, normal) = hierarchy.shot_of(p, power, &bound, self.scene, self.layout)?;
        let members = (members.into_iter())
            .map(|q| (q, totals.energy_rgb(q)))
            .collect();
        self.cluster_shot(members, Some(normal))
    }

    /// The one shooter of cluster `members` (polygon, unshot energy), along `normal` when a face
    /// cluster's ([`cluster_shooter`]), and its members.
    fn cluster_shot(
        &self,
        members: Vec<(usize, glam::Vec3)>,
        normal: Option<glam::Vec3>,
    ) -> Option<(Shooter, Vec<Member>)> {
        let patches = &self.layout.patches_per_polygon;
        let mut shooter = cluster_shooter(self.scene, patches, &members, normal)?;
        shooter.hemi_res = item_buffer_side(self.options, shooter.power() / self.emitted_power);
        let members = members
            .into_iter()
            .map(|(polygon, energy)| Member {
                shooter: 0,
                polygon,
                energy,
                face: normal.is_some(),
            })
            .collect();
        Some((shooter, members))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patches::{PatchLayout, Resolution};
    use crate::scene::{Polygon, Scene};
    use glam::Vec3;

    /// A floor of `n` × `n` quads of 1×1 (each its own polygon, as faces of different
    /// materials stay after merging), and a light above it.
    fn floor(n: usize) -> Scene {
        let quad = |x: f32, z: f32, y: f32| {
            vec![
                Vec3::new(x, y, z),
                Vec3::new(x, y, z + 1.0),
                Vec3::new(x + 1.0, y, z + 1.0),
                Vec3::new(x + 1.0, y, z),
            ]
        };
        let mut polygons: Vec<Polygon> = (0..n * n)
            .map(|i| Polygon::new(quad((i % n) as f32, (i / n) as f32, 0.0), 0, "floor".into()))
            .collect::<Option<_>>()
            .unwrap();
        let mut light = quad(0.0, 0.0, 5.0);
        light.reverse();
        polygons.push(Polygon::new(light, 1, "light".into()).unwrap());
        with_light(polygons)
    }

    /// A scene of `polygons` whose material 1 is a light.
    fn with_light(polygons: Vec<Polygon>) -> Scene {
        let mut scene = crate::scene::test_scene(polygons);
        scene.materials.push(crate::scene::Material {
            name: "light".into(),
            kd: Vec3::ZERO,
            ke: Vec3::ONE,
        });
        scene
    }

    #[test]
    fn small_coplanar_polygons_in_one_square_form_a_cluster() {
        let scene = floor(8);
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(1.0));
        let clusters = Clusters::new(&scene, &layout, 2, 4);
        // 64 floor quads of one patch each, in squares of 4×4 patches: 4 coarse clusters of 16
        // (or more squares where the grid does not line up with the floor), 16 or more fine
        // ones in squares of 2×2; the light alone.
        assert_eq!(clusters.clustered_polygons(), 64);
        assert!((4..=9).contains(&clusters.count()), "{}", clusters.count());
        assert!(
            (16..=25).contains(&clusters.fine_count()),
            "{}",
            clusters.fine_count()
        );
        let light = scene.polygons.len() - 1;
        assert!(clusters.members_of(light, true).is_none());
        let coarse = clusters.members_of(0, true).unwrap();
        let fine = clusters.members_of(0, false).unwrap();
        assert!(fine.contains(&0) && fine.iter().all(|p| coarse.contains(p)));
        assert!(fine.len() < coarse.len());
        assert_eq!(Clusters::new(&scene, &layout, 2, 0).count(), 0);
    }

    #[test]
    fn polygons_that_do_not_touch_do_not_cluster() {
        // Every other quad of a row of 8 (as tiles on both sides of walls standing on the
        // floor): none touches another, so none clusters, though all lie in one square.
        let all = floor(8);
        let scene = with_light(
            (0..8)
                .step_by(2)
                .chain(std::iter::once(all.polygons.len() - 1))
                .map(|p| all.polygons[p].clone())
                .collect(),
        );
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(1.0));
        assert_eq!(Clusters::new(&scene, &layout, 0, 8).clustered_polygons(), 0);
    }

    #[test]
    fn a_cluster_shoots_its_members_energy_from_a_member_within_their_rectangle() {
        let scene = floor(4);
        let layout = PatchLayout::new(&scene, Resolution::PatchSize(1.0));
        let members = [(0, Vec3::ONE), (5, Vec3::splat(3.0)), (15, Vec3::ONE)];
        let s = cluster_shooter(&scene, &layout.patches_per_polygon, &members, None).unwrap();
        assert_eq!(s.energy, Vec3::splat(5.0));
        assert_eq!(s.patches, 3);
        // The power-weighted centre is nearest polygon 5's centroid.
        assert_eq!(s.polygon, 5);
        assert_eq!(s.position, scene.polygons[5].centroid);
        // The rectangle around quads 0 (0..1 × 0..1) and 15 (3..4 × 3..4): 4 × 4, on the floor,
        // counter-clockwise seen from above.
        assert!((s.area - 16.0).abs() < 1e-4, "{}", s.area);
        let c = &s.corners[..4];
        assert!(c.iter().all(|p| p.y.abs() < 1e-5));
        let turn = (c[1] - c[0]).cross(c[2] - c[1]);
        assert!(turn.dot(Vec3::Y) > 0.0);
        assert!(cluster_shooter(&scene, &[1; 17], &[], None).is_none());
    }
}
