//! What each view of the visibility pass may leave out, for llvmpipe's sake (none of it is in the
//! paper, which draws the whole scene into each view). Every test here is switched by
//! [`Tuning`] and changes nothing the reconstruction pass reads, or only depth ties (each switch
//! says which): polygons behind the shooter or outside a hemicube face (`cull_views`), plates
//! drawn once under their representative (`plates`), the far faces of convex solids
//! (`cull_solids`), polygons falling between the pixel centres (`cull_between_samples`), and the
//! polygons wholly inside the guard band drawn first, apart (`split_unclipped`).
//!
//! [`Culling::asked`] says whether any of it runs; without it the pass draws
//! [`DrawList::whole`], the scene's triangles as they are.

use super::occlusion::{self, Occluders};
use super::plates::Plates;
use super::samples::{self, Outlines};
use super::seen_receivers::{self, Reach, SeenReceivers};
use super::solids::Solids;
use crate::geometry::{mean, sphere_around, Plane};
use crate::scene::Scene;
use crate::solver::mesh::SceneMesh;
use crate::solver::visibility::{face_rotations, front_half, DrawList, ViewDraw};
use crate::solver::{Shooter, Tuning, VisibilityKind};
use glam::{Mat3, Mat4, Vec3};

/// The culling of one visibility pass: what it knows of the scene, and its buffers (reused from
/// shot to shot).
pub struct Culling {
    kind: VisibilityKind,
    tuning: Tuning,
    /// The near plane's distance (the pass's `near_far[0]`).
    near: f32,
    /// The far plane's distance (the pass's `near_far[1]`).
    far: f32,
    /// The hemicube faces' guard band (`VisibilityPass`'s `guard`, 1 on the hemisphere).
    guard: i32,
    /// Each polygon's bounding sphere (centre, radius); a plate's around the whole plate.
    spheres: Vec<(Vec3, f32)>,
    /// Each polygon's plane.
    planes: Vec<Plane>,
    /// The scene's convex solids, whose faces turned away from the shooter are left out (see
    /// `solids`: the item buffer stays the same).
    pub(super) solids: Solids,
    /// Each drawn polygon's corners, for `Tuning::cull_between_samples`.
    outlines: Outlines,
    /// The drawn polygons' convex pieces and a tree of their boxes, for `Tuning::cull_hidden`.
    occluders: Occluders,
    /// Which polygons can receive from a shot whose item buffer the walk wrote
    /// (`Tuning::walk_receivers`; empty until `use_seen_receivers`).
    seen: SeenReceivers,
    /// The lists of `draw_list` (those of `build` belong to the caller).
    lists: Lists,
    /// How many times a view left a polygon out as falling between the pixel centres, over all
    /// shots (`Tuning::cull_between_samples`; `VisibilityPass::run_pass` adds its lists'
    /// counts after each pass).
    pub missed: u64,
    /// How many polygons in front of a shooter were left out as hidden, over all shots
    /// (`Tuning::cull_hidden`; counted as `missed` is).
    pub hidden: u64,
}

/// The triangles of a [`SceneMesh`] without its GL objects, which stay on the GL thread.
#[derive(Clone, Copy)]
pub struct Triangles<'a> {
    /// Every polygon's triangles as corner indices, polygon after polygon.
    pub triangles: &'a [u32],
    /// Polygon `i`'s triangles: (first index, index count) in `triangles`.
    pub ranges: &'a [(u32, u32)],
}

impl<'a> Triangles<'a> {
    /// `mesh`'s triangles.
    pub fn of(mesh: &'a SceneMesh) -> Self {
        Triangles {
            triangles: &mesh.triangles,
            ranges: &mesh.ranges,
        }
    }
}

/// One shot's draw list and the scratch space it is built in: the caller may keep several
/// (one per shooter of a pass), and build them on other threads ([`Culling::build`]).
#[derive(Clone, Debug, Default)]
pub struct Lists {
    /// Per solid, whether the shooter is clear of it.
    outside: Vec<bool>,
    /// The polygons in front of the shooter: (polygon, sphere centre in eye space, radius).
    in_front: Vec<(usize, Vec3, f32)>,
    /// The triangles each view draws, views one after another, each view's unclipped polygons
    /// first.
    indices: Vec<u32>,
    /// One view's polygons that may need clipping, gathered to follow its others.
    clipped: Vec<u32>,
    /// Where each view's triangles are in `indices`.
    views: [ViewDraw; 5],
    /// How many times a view of this shot left a polygon out as falling between the pixel
    /// centres.
    pub missed: u64,
    /// The hidden polygons' test's scratch space (`Tuning::cull_hidden`).
    occlusion: occlusion::Scratch,
    /// The item buffer the walk wrote (`Tuning::walk_item_buffers`), as the texture's RGBA8
    /// bytes of its lower-left 5r × r pixels; empty when the views are to be drawn.
    item_buffer: Vec<u8>,
    /// How many polygons in front of the shooters were left out as hidden.
    pub hidden: u64,
    /// What the shot may reach (`Tuning::walk_receivers`), if known.
    receivers: Option<Reach>,
    /// The receivers' test's scratch space.
    seen: seen_receivers::Scratch,
}

impl Lists {
    /// What the last shot may reach, when the walk wrote its item buffer and the receivers'
    /// test is set up (`Tuning::walk_receivers`); `None` otherwise.
    pub fn receivers(&self) -> Option<&Reach> {
        self.receivers.as_ref()
    }

    /// The item buffer written by the walk instead of a draw list (`Tuning::walk_item_buffers`):
    /// RGBA8 bytes of the lower-left 5r × r pixels, rows bottom to top; `None` when the last
    /// list is to be drawn.
    pub fn written_item_buffer(&self) -> Option<&[u8]> {
        (!self.item_buffer.is_empty()).then_some(&self.item_buffer[..])
    }

    /// The draw list built last.
    pub fn draw_list(&self) -> DrawList<'_> {
        DrawList {
            indices: &self.indices,
            views: self.views,
        }
    }
}

impl Culling {
    /// Whether `tuning` asks a pass of `kind` to cull (or split) at all; if not, every view
    /// draws [`DrawList::whole`].
    pub fn asked(tuning: &Tuning, kind: VisibilityKind) -> bool {
        let hemicube = kind == VisibilityKind::Hemicube;
        tuning.cull_views
            || hemicube
                && (tuning.cull_solids || tuning.cull_between_samples || tuning.split_unclipped)
    }

    /// The culling of `scene`'s polygons, every polygon alone (see [`Culling::use_plates`]), for
    /// views with near and far planes `near_far` and guard band `guard`.
    pub fn new(
        scene: &Scene,
        kind: VisibilityKind,
        tuning: Tuning,
        near_far: [f32; 2],
        guard: i32,
    ) -> Self {
        let none = Plates::none(scene.polygons.len());
        // Only what the tuning asks for: the paper's passes (and the GPU profile) build none of
        // it, and draw the whole scene into every view.
        let asked = Self::asked(&tuning, kind);
        let hemicube = kind == VisibilityKind::Hemicube;
        let solids = asked && hemicube && tuning.cull_solids || hemicube && tuning.plates;
        Culling {
            kind,
            tuning,
            near: near_far[0],
            far: near_far[1],
            guard,
            spheres: (scene.polygons.iter())
                .filter(|_| asked)
                .map(|p| p.bounding_sphere())
                .collect(),
            planes: (scene.polygons.iter())
                .filter(|_| asked)
                .map(|p| p.plane())
                .collect(),
            solids: if solids {
                Solids::find(scene)
            } else {
                Solids::default()
            },
            outlines: Self::outlines_of(scene, kind, &tuning, &none),
            occluders: Self::occluders_of(scene, kind, &tuning, &none),
            seen: SeenReceivers::default(),
            lists: Lists::default(),
            missed: 0,
            hidden: 0,
        }
    }

    /// What `Tuning::cull_between_samples` needs (hemicube only), for polygons shown as `plates`.
    fn outlines_of(
        scene: &Scene,
        kind: VisibilityKind,
        tuning: &Tuning,
        plates: &Plates,
    ) -> Outlines {
        if Self::asked(tuning, kind)
            && tuning.cull_between_samples
            && kind == VisibilityKind::Hemicube
        {
            Outlines::new(scene, plates)
        } else {
            Outlines::default()
        }
    }

    /// What `Tuning::cull_hidden` needs (only on the hemicube: the hemispherical projection draws
    /// straight edges where the true outline curves).
    fn occluders_of(
        scene: &Scene,
        kind: VisibilityKind,
        tuning: &Tuning,
        plates: &Plates,
    ) -> Occluders {
        if tuning.cull_hidden() && kind == VisibilityKind::Hemicube {
            Occluders::new(scene, plates)
        } else {
            Occluders::default()
        }
    }

    /// This culling, leaving a stand-in that culls nothing in its place (for `build` on
    /// another thread while the owner issues draws).
    pub fn take(&mut self) -> Culling {
        let empty = Culling {
            spheres: Vec::new(),
            planes: Vec::new(),
            solids: Solids::default(),
            outlines: Outlines::default(),
            occluders: Occluders::default(),
            seen: SeenReceivers::default(),
            lists: Lists::default(),
            missed: 0,
            hidden: 0,
            ..*self
        };
        std::mem::replace(self, empty)
    }

    /// The item buffer the walk wrote for the last `draw_list`, if it wrote one
    /// ([`Lists::written_item_buffer`]).
    pub fn written_item_buffer(&self) -> Option<&[u8]> {
        self.lists.written_item_buffer()
    }

    /// The draw list `draw_list` built last.
    pub fn last_list(&self) -> DrawList<'_> {
        self.lists.draw_list()
    }

    /// The receivers of the last `draw_list` ([`Lists::receivers`]).
    pub fn receivers(&self) -> Option<&Reach> {
        self.lists.receivers()
    }

    /// Find the receivers of every shot whose item buffer the walk writes from now on
    /// (`Tuning::walk_receivers`; [`Lists::receivers`]).
    pub fn use_seen_receivers(&mut self, seen: SeenReceivers) {
        self.seen = seen;
    }

    /// Cull by `plates` from now on: each plate's sphere and outline stand for its polygons.
    pub fn use_plates(&mut self, scene: &Scene, plates: &Plates) {
        if !self.spheres.is_empty() {
            for (&p, outline) in &plates.outlines {
                self.spheres[p] = sphere_around(mean(outline), outline);
            }
        }
        self.outlines = Self::outlines_of(scene, self.kind, &self.tuning, plates);
        self.occluders = Self::occluders_of(scene, self.kind, &self.tuning, plates);
    }

    /// The triangles of `mesh` each view draws for `shooter` (whose view matrix is `view`), at
    /// this shot's resolution `res` (per face), with polygons shown as `plates` shows them.
    pub fn draw_list(
        &mut self,
        mesh: &SceneMesh,
        shooter: &Shooter,
        view: Mat4,
        plates: &Plates,
        res: i32,
    ) -> DrawList<'_> {
        let mut lists = std::mem::take(&mut self.lists);
        self.build(&mut lists, Triangles::of(mesh), shooter, view, plates, res);
        self.missed += std::mem::take(&mut lists.missed);
        self.hidden += std::mem::take(&mut lists.hidden);
        self.lists = lists;
        self.lists.draw_list()
    }

    /// [`draw_list`](Self::draw_list) into `lists` (`Lists::draw_list` then gives it), reading
    /// only what the culling knows of the scene: several shots' lists can be built at once.
    pub fn build(
        &self,
        lists: &mut Lists,
        mesh: Triangles<'_>,
        shooter: &Shooter,
        view: Mat4,
        plates: &Plates,
        res: i32,
    ) {
        // The hidden-polygon walk, and the item buffer it writes, only at the sides where it
        // pays (`Tuning::walk_up_to`).
        let side = res.max(1) as u32;
        let hidden = self.tuning.walks_hidden(side) && self.kind == VisibilityKind::Hemicube;
        let write = hidden && self.tuning.walks(side);
        if !write {
            self.find_in_front(lists, shooter, view, plates);
        }
        if hidden {
            let Lists {
                occlusion,
                in_front,
                ..
            } = lists;
            let r = res.max(1) as usize;
            let views = occlusion::Views {
                s: shooter.position,
                normal: shooter.normal,
                view,
                rotations: face_rotations(),
                r,
                drawn: std::array::from_fn(|k| {
                    let rect = if self.tuning.half_side_faces {
                        front_half(k, r as i32)
                    } else {
                        [0, 0, r as i32, r as i32]
                    };
                    rect.map(|x| x as usize)
                }),
            };
            if write {
                // The walk writes the item buffer: no triangles to draw.
                let in_front = self.in_front(shooter, view, plates);
                (self.occluders)
                    .write_item_buffer(occlusion, &views, self.near, self.far, in_front);
                item_bytes(occlusion.item_ids(), r, &mut lists.item_buffer);
                let mut receivers = lists.receivers.take().unwrap_or_default();
                lists.receivers = (!self.seen.is_empty()).then(|| {
                    let (scratch, ids) = (&mut lists.seen, occlusion.item_ids());
                    self.seen.receivers(scratch, &views, ids, &mut receivers);
                    receivers
                });
                lists.indices.clear();
                lists.views = [ViewDraw::default(); 5];
                return;
            }
            lists.hidden += (self.occluders)
                .retain_shown(occlusion, &views, self.near, self.far, in_front)
                as u64;
        }
        lists.item_buffer.clear();
        lists.receivers = None;
        let views = match self.kind {
            VisibilityKind::Hemisphere => 1,
            VisibilityKind::Hemicube => 5,
        };
        let mut draws = [ViewDraw::default(); 5];
        lists.indices.clear();
        for (rotation, draw) in face_rotations().iter().zip(&mut draws).take(views) {
            *draw = self.add_view(lists, mesh, *rotation, view, res);
        }
        lists.views = draws;
    }

    /// Append to `indices` the triangles of the view turned by `rotation` (a hemicube face;
    /// the hemisphere's one view is the front face's): the polygons of `in_front` wholly inside
    /// the guarded frustum and beyond the near plane (no vertex to clip: llvmpipe's fast path),
    /// then the others; without `split_unclipped`, all of them as "others", in the scene's order.
    fn add_view(
        &self,
        lists: &mut Lists,
        mesh: Triangles<'_>,
        rotation: Mat3,
        view: Mat4,
        res: i32,
    ) -> ViewDraw {
        let first = lists.indices.len();
        lists.clipped.clear();
        let face = Mat4::from_mat3(rotation) * view;
        for i in 0..lists.in_front.len() {
            let (p, c, radius) = lists.in_front[i];
            let inside = match self.kind {
                VisibilityKind::Hemisphere => false,
                VisibilityKind::Hemicube => {
                    let missed = &mut lists.missed;
                    match self.place_on_face(p, rotation * c, radius, &face, res, missed) {
                        Some(inside) => inside,
                        None => continue,
                    }
                }
            };
            let (start, count) = mesh.ranges[p];
            let corners = &mesh.triangles[start as usize..(start + count) as usize];
            if inside {
                lists.indices.extend_from_slice(corners);
            } else {
                lists.clipped.extend_from_slice(corners);
            }
        }
        let unclipped = lists.indices.len() - first;
        let Lists {
            indices, clipped, ..
        } = lists;
        indices.extend_from_slice(clipped);
        ViewDraw {
            first,
            unclipped,
            clipped: lists.indices.len() - first - unclipped,
        }
    }

    /// Where polygon `p` goes in a hemicube face (`face`: its view matrix), its sphere's centre
    /// at `f` in face space: `None` left out (outside the face, or between the pixel centres at
    /// `res` pixels per side), `Some(true)` wholly inside the guarded frustum, `Some(false)` a
    /// polygon that may need clipping.
    #[allow(clippy::too_many_arguments)]
    fn place_on_face(
        &self,
        p: usize,
        f: Vec3,
        radius: f32,
        face: &Mat4,
        res: i32,
        missed: &mut u64,
    ) -> Option<bool> {
        let tuning = &self.tuning;
        let near = self.near;
        // Outside one of the face's four 45° side planes (unit normals (±1, 0, -1)/√2 and
        // (0, ±1, -1)/√2 in face space).
        let reach = radius * std::f32::consts::SQRT_2;
        if tuning.cull_views && (-f.z - f.x.abs() < -reach || -f.z - f.y.abs() < -reach) {
            return None;
        }
        // Pixels across per unit of tangent, to tell which polygons project small enough to
        // fall between the pixel centres (`samples`).
        let pixels_per_tangent = res as f32 / 2.0;
        let depth = -f.z - radius;
        if tuning.cull_between_samples
            && depth > 2.0 * near
            && 2.0 * radius / depth * pixels_per_tangent < samples::MAX_EXTENT
            && samples::misses_every_centre(self.outlines.of(p), face, res as f32, 2.0 * near)
        {
            *missed += 1;
            return None;
        }
        // Inside the guarded side planes (normals (±1, 0, -g)/√(1 + g²), ...).
        let g = self.guard as f32;
        let side = (1.0 + g * g).sqrt();
        Some(
            tuning.split_unclipped
                && -f.z - radius > 2.0 * near
                && -g * f.z - f.x.abs() > radius * side
                && -g * f.z - f.y.abs() > radius * side,
        )
    }

    /// `in_front`: the plates' representatives that any view may need, with their spheres'
    /// centres in the shooter's eye space (once for all the views). Left out: what lies wholly
    /// behind the shooter's plane (nothing it could hide is looked up), the shooter's own plate,
    /// and the faces of solids turned away from a shooter outside them.
    fn find_in_front(&self, lists: &mut Lists, shooter: &Shooter, view: Mat4, plates: &Plates) {
        let s = shooter.position;
        lists.outside.clear();
        (lists.outside).extend((0..self.solids.count()).map(|k| self.clear_of_solid(k, s)));
        lists.in_front.clear();
        let shooter_plate = plates.representative[shooter.polygon];
        for p in 0..self.spheres.len() {
            if plates.representative[p] != p {
                continue;
            }
            let outside = |k: usize| lists.outside[k];
            if let Some(c) = self.in_front_of(p, shooter_plate, s, view, outside) {
                lists.in_front.push((p, c, self.spheres[p].1));
            }
        }
    }

    /// What [`find_in_front`](Self::find_in_front) lists, as a test of one polygon at a time
    /// (each solid's side of the shooter found when asked), for the walk that writes the item
    /// buffer and reaches only a small part of the scene (`Occluders::write_item_buffer`).
    fn in_front<'a>(
        &'a self,
        shooter: &Shooter,
        view: Mat4,
        plates: &'a Plates,
    ) -> impl Fn(usize) -> bool + 'a {
        let s = shooter.position;
        let shooter_plate = plates.representative[shooter.polygon];
        move |p| {
            let outside = |k: usize| self.clear_of_solid(k, s);
            plates.representative[p] == p
                && self
                    .in_front_of(p, shooter_plate, s, view, outside)
                    .is_some()
        }
    }

    /// Whether the shooter at `s` is clear of solid `k`, so that its far faces may be left out:
    /// only where projected straight edges are exact (the hemicube; the hemispherical projection
    /// drawn with straight edges lets a far face peek past the near ones), and clear of the near
    /// plane too (geometry nearer is clipped away, and a clipped near face would show the far
    /// face behind it; on a face axis, depth ≥ distance / √3).
    fn clear_of_solid(&self, k: usize, s: Vec3) -> bool {
        self.tuning.cull_solids
            && self.kind == VisibilityKind::Hemicube
            && self.solids.clear_of(k, s, self.near * 3f32.sqrt())
    }

    /// Plate representative `p`'s sphere centre in the eye space of `view` (shooter at `s`,
    /// on plate `shooter_plate`) if any view may need it, `None` if it is left out: wholly
    /// behind the shooter's plane, or the shooter's own plate (which lies in the shooter's
    /// plane, which the near plane clips away, and the shaders put beyond the far plane), or a
    /// face of a solid turned away from a shooter `outside` it.
    fn in_front_of(
        &self,
        p: usize,
        shooter_plate: usize,
        s: Vec3,
        view: Mat4,
        outside: impl Fn(usize) -> bool,
    ) -> Option<Vec3> {
        let (centre, radius) = self.spheres[p];
        let c = view.transform_point3(centre);
        if self.tuning.cull_views && (p == shooter_plate || c.z >= radius) {
            return None;
        }
        if let Some(k) = self.solids.solid_of.get(p).copied().flatten() {
            if self.planes[p].distance(s) < -self.solids.slack && outside(k) {
                return None;
            }
        }
        Some(c)
    }
}

/// The walk's item buffer (`ids`: per face, r × r IDs + 1, row by row from the bottom) as the
/// texture's bytes: the five faces side by side, each pixel's ID + 1 spread over red, green and
/// blue as `glsl/item_id.glsl` encodes it, alpha 255; a pixel showing nothing all zero, as the
/// pass's clear leaves it.
fn item_bytes(ids: &[u32], r: usize, bytes: &mut Vec<u8>) {
    bytes.clear();
    bytes.resize(5 * r * r * 4, 0);
    for (k, face) in ids.chunks_exact(r * r).enumerate() {
        for (y, row) in face.chunks_exact(r).enumerate() {
            let at = (y * 5 * r + k * r) * 4;
            for (pixel, &n) in bytes[at..at + 4 * r].chunks_exact_mut(4).zip(row) {
                if n != 0 {
                    pixel.copy_from_slice(&[n as u8, (n >> 8) as u8, (n >> 16) as u8, 255]);
                }
            }
        }
    }
}
