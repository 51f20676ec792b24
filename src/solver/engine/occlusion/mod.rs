//! Polygons hidden behind nearer ones, left out of a shot's views (`Tuning::cull_hidden`; not in
//! the paper, which draws the whole scene into each view).
//!
//! Why: on Lost Empire a small shot's views drew about 55,000 triangles (17,000 polygons in front
//! of the shooter, half the world), and about 200 polygons showed in the item buffer: the rest
//! lay behind the walls of the cave or valley the shooter stands in. llvmpipe transforms, sets
//! up and bins every triangle it is given on the thread that issues the draws.
//!
//! How: the views' own pixel centres, for this shot's resolution and turn, each record how far
//! along its ray the nearest drawn polygon met so far lies. A tree of boxes around the polygons
//! is walked nearest first; a box is left out, with all it holds, when at every drawn pixel
//! centre its projection can reach, something nearer is already recorded; a polygon that is
//! kept records itself at the centres it covers, piece by convex piece.
//!
//! Why it changes no pixel: a polygon left out lies, at every pixel centre it could cover,
//! behind a polygon that is drawn there (kept polygons are drawn in every view where they
//! cover a pixel centre), so the depth test would have hidden it. Margins keep it so through
//! the GPU's rounding: a centre counts as covered only 1/64 pixel inside a piece, a box reaches
//! 1/64 pixel beyond its projection, and nearer means nearer by 0.2 % (a float depth buffer at
//! the far end of the views tells distances apart to about 0.06 %). A piece covers only if the
//! near plane cannot clip it, and the far plane neither. The exception: a polygon whose plane
//! passes through the eye is drawn as triangles of no area whose depths are noise, and the
//! GPU may show it at a centre in front of what lies nearer; left out, the centre shows the
//! nearer polygon (tests/item_buffer.rs checks that those are the only pixels that change).

mod pieces;

use super::box_tree::BoxTree;
use super::plates::Plates;
use crate::geometry::bounds;
use crate::scene::Scene;
use glam::{Mat3, Mat4, Vec3};
use pieces::{convex, convex_pieces, without_spikes, MAX_PIECE};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Polygons per leaf of the tree.
const LEAF: usize = 4;

/// How much nearer than a box what covers a pixel centre must be (relative): the GPU compares
/// depths, not distances, and a float depth buffer at the far end of the views (near 1e-4, far
/// 2 × the scene's size) tells apart distances only about 6e-4 apart.
const NEARER: f32 = 2e-3;

/// A plane nearer the eye than this share of the walk's clearance (`Walk::clear`) is seen
/// edge-on: the item buffer the walk writes shows nothing of it, as the GPU draws nothing of it
/// (bar depth noise).
const EDGE_ON: f32 = 0.01;

/// How far behind the shooter's plane a box must lie to be left out without a look (radians
/// below the horizon, about): more than the float noise of the views' transforms.
pub(super) const BEHIND: f32 = 1e-4;

/// The scene's polygons as the visibility pass draws them, for the test: a tree of boxes and
/// each polygon's convex pieces. Built once per scene (and again for plates).
///
/// Boxes and pieces are stored in the tree's leaf order (`BoxTree::order`), not by polygon, so
/// that a leaf's polygons lie side by side in memory: the walk is bound by the loads of what
/// it visits, a few thousand polygons a shot scattered over megabytes otherwise.
#[derive(Clone, Debug, Default)]
pub struct Occluders {
    /// The tree of the drawn polygons' boxes.
    tree: BoxTree,
    /// Per polygon: its index in leaf order (`u32::MAX`: not drawn).
    rank: Vec<u32>,
    /// Per leaf-order index: the drawn outline's box (lower, upper corner).
    boxes: Vec<(Vec3, Vec3)>,
    /// Per leaf-order index k: its convex pieces in `pieces`, `starts[k]..starts[k + 1]`.
    starts: Vec<u32>,
    /// Every drawn polygon's convex pieces (its outline if convex, else `convex_pieces`): each
    /// piece's corners in `corners`, `pieces[k]..pieces[k + 1]`.
    pieces: Vec<u32>,
    /// The pieces' corners.
    corners: Vec<Vec3>,
    /// Per piece: its plane's normal (Newell's, not normalised), computed once rather than
    /// per shot.
    normals: Vec<Vec3>,
}

/// One shot's scratch space (kept from shot to shot, one per list builder).
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    /// Per pixel of the five faces: how far along its centre's ray the nearest kept polygon
    /// lies (∞: none yet; −∞: a pixel not drawn, `Views::drawn`).
    cover: Vec<f32>,
    /// The shot's number, stamped into `candidate` and `kept` (no clearing per shot).
    stamp: u32,
    /// Per leaf-order index (`Occluders::rank`): the stamp of the last shot that would draw
    /// the polygon.
    candidate: Vec<u32>,
    /// Per polygon: the stamp of the last shot that kept it.
    kept: Vec<u32>,
    /// The walk's boxes, nearest first.
    heap: BinaryHeap<(Reverse<u32>, u32)>,
    /// Per pixel of the five faces (as `cover`), the nearest kept polygon's ID + 1 (0: none),
    /// when the walk writes the item buffer (`Tuning::walk_item_buffers`).
    ids: Vec<u32>,
}

impl Scratch {
    /// The item buffer the last walk wrote (`write_item_buffer`; empty after `retain_shown`): per
    /// pixel of the five faces, face after face, each row by row from the bottom, the nearest
    /// polygon's ID + 1, 0 where none (or the pixel is not drawn, `Views::drawn`).
    pub fn item_ids(&self) -> &[u32] {
        &self.ids
    }
}

impl Occluders {
    /// The polygons drawn under `plates` (each plate as its representative's outline).
    pub fn new(scene: &Scene, plates: &Plates) -> Occluders {
        let n = scene.polygons.len();
        let mut boxes = vec![(Vec3::ZERO, Vec3::ZERO); n];
        // Per polygon, its convex pieces' corners, until the tree gives their order.
        let mut pieces: Vec<Vec<Vec<Vec3>>> = vec![Vec::new(); n];
        let mut drawn = Vec::new();
        for (p, polygon) in scene.polygons.iter().enumerate() {
            if plates.representative[p] != p {
                continue;
            }
            let outline = without_spikes(plates.outlines.get(&p).unwrap_or(&polygon.vertices));
            let outline = &outline[..];
            let Some(bounds) = bounds(outline) else {
                continue;
            };
            boxes[p] = bounds;
            pieces[p] = if outline.len() <= MAX_PIECE && convex(outline, polygon.normal) {
                vec![outline.to_vec()]
            } else {
                (convex_pieces(outline, polygon.normal).iter())
                    .map(|piece| piece.iter().map(|&k| outline[k]).collect())
                    .collect()
            };
            drawn.push(p as u32);
        }
        let tree = BoxTree::new(&boxes, drawn, LEAF);
        let mut o = Occluders {
            rank: vec![u32::MAX; n],
            starts: Vec::with_capacity(tree.order.len() + 1),
            ..Occluders::default()
        };
        for (k, &p) in tree.order.iter().enumerate() {
            o.rank[p as usize] = k as u32;
            o.boxes.push(boxes[p as usize]);
            o.starts.push(o.pieces.len() as u32);
            for piece in &pieces[p as usize] {
                o.push_piece(piece.iter().copied());
            }
        }
        o.starts.push(o.pieces.len() as u32);
        o.pieces.push(o.corners.len() as u32);
        o.tree = tree;
        o
    }

    /// Append a convex piece with these corners, and its plane's normal.
    fn push_piece(&mut self, corners: impl Iterator<Item = Vec3>) {
        let start = self.corners.len();
        self.pieces.push(start as u32);
        self.corners.extend(corners);
        let piece = &self.corners[start..];
        let n = piece.len();
        // Newell's normal: the piece's plane, whatever its corners.
        let normal = (0..n).fold(Vec3::ZERO, |sum, k| {
            sum + piece[k].cross(piece[(k + 1) % n])
        });
        self.normals.push(normal);
    }

    /// Keep in `in_front` (polygon, …) only the polygons that may show from a shooter at `s`
    /// with normal `normal`, in their order; `near`/`far`: the views' clipping distances.
    /// Returns how many were left out.
    pub fn retain_shown(
        &self,
        scratch: &mut Scratch,
        views: &Views,
        near: f32,
        far: f32,
        in_front: &mut Vec<(usize, Vec3, f32)>,
    ) -> usize {
        if self.tree.nodes.is_empty() {
            return 0;
        }
        let stamp = scratch.next_stamp(self.boxes.len(), self.rank.len());
        let mut candidate = std::mem::take(&mut scratch.candidate);
        for &(p, _, _) in in_front.iter() {
            if let Some(&k) = self.rank.get(p).filter(|&&k| k != u32::MAX) {
                candidate[k as usize] = stamp;
            }
        }
        self.walk(scratch, views, near, far, false, |k, _| {
            candidate[k] == stamp
        });
        scratch.candidate = candidate;
        let before = in_front.len();
        in_front.retain(|&(p, _, _)| scratch.kept[p] == stamp);
        before - in_front.len()
    }

    /// Write the item buffer of the views ([`Scratch::item_ids`]; `Tuning::walk_item_buffers`)
    /// as the polygons for which `in_front(p)` holds would draw it: the same walk as
    /// [`retain_shown`](Self::retain_shown), but asked whether a polygon is in front of the
    /// shooter only when it reaches it, rather than given the list of them (on Lost Empire a
    /// small shot's walk reaches about 1,600 of the 48,596 polygons, and listing those in front
    /// read every polygon every shot). A polygon left out lies, at every centre it could reach,
    /// behind what is recorded there, so the nearest polygon at each centre is one the walk kept.
    pub fn write_item_buffer(
        &self,
        scratch: &mut Scratch,
        views: &Views,
        near: f32,
        far: f32,
        in_front: impl Fn(usize) -> bool,
    ) {
        scratch.next_stamp(self.boxes.len(), self.rank.len());
        self.walk(scratch, views, near, far, true, |_, p| in_front(p));
    }

    /// The walk: the tree nearest first, each box left out when hidden, each polygon of a leaf
    /// for which `candidate(leaf-order index, polygon)` holds kept (stamped in `kept`) unless
    /// hidden, and its pieces recorded at the centres they cover; with `record`, their IDs too.
    fn walk(
        &self,
        scratch: &mut Scratch,
        views: &Views,
        near: f32,
        far: f32,
        record: bool,
        candidate: impl Fn(usize, usize) -> bool,
    ) {
        let stamp = scratch.stamp;
        views.clear(&mut scratch.cover);
        scratch.ids.clear();
        if record {
            scratch.ids.resize(scratch.cover.len(), 0);
        }
        let walk = Walk {
            views,
            near,
            clear: 2.0 * near * 3f32.sqrt(),
            far,
        };
        scratch.heap.clear();
        // No polygon drawn: the buffers stay clear.
        let Some(root) = self.tree.nodes.first() else {
            return;
        };
        scratch
            .heap
            .push((Reverse(walk.distance(root.lo, root.hi).to_bits()), 0));
        while let Some((Reverse(bits), at)) = scratch.heap.pop() {
            let node = self.tree.nodes[at as usize];
            if walk.hidden(&scratch.cover, f32::from_bits(bits), node.lo, node.hi) {
                continue;
            }
            if !node.is_leaf() {
                for child in [node.children, node.children + 1] {
                    let c = &self.tree.nodes[child as usize];
                    let d = walk.distance(c.lo, c.hi);
                    scratch.heap.push((Reverse(d.to_bits()), child));
                }
                continue;
            }
            for at in node.start as usize..node.end as usize {
                let p = self.tree.order[at] as usize;
                if !candidate(at, p) {
                    continue;
                }
                let (lo, hi) = self.boxes[at];
                if walk.hidden(&scratch.cover, walk.distance(lo, hi), lo, hi) {
                    continue;
                }
                scratch.kept[p] = stamp;
                let range = self.starts[at] as usize..self.starts[at + 1] as usize;
                let faces = walk.faces_reached(lo, hi);
                for k in range {
                    let piece = &self.corners[self.pieces[k] as usize..self.pieces[k + 1] as usize];
                    let ids = record.then_some((&mut scratch.ids[..], p as u32 + 1));
                    walk.cover(&mut scratch.cover, piece, self.normals[k], faces, ids);
                }
            }
        }
    }
}

impl Scratch {
    /// A new shot's stamp, for `drawn` polygons in leaf order of `n` in the scene (the stamps
    /// cleared when they wrap, or the scene changed).
    fn next_stamp(&mut self, drawn: usize, n: usize) -> u32 {
        if self.candidate.len() != drawn || self.kept.len() != n {
            self.candidate = vec![0; drawn];
            self.kept = vec![0; n];
            self.stamp = 0;
        }
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.candidate.fill(0);
            self.kept.fill(0);
            self.stamp = 1;
        }
        self.stamp
    }
}

/// One shot's views as the GPU draws them: the shooter's view (world to its eye space), each
/// hemicube face's rotation of that eye space (the face looks down -z, a 90° frustum), `r`
/// pixels a side, and the part of each face drawn (x, y, width, height;
/// `Tuning::half_side_faces`).
pub struct Views {
    /// The shooter's position.
    pub s: Vec3,
    /// The shooter's normal.
    pub normal: Vec3,
    /// World to the shooter's eye space.
    pub view: Mat4,
    /// Each face's rotation of the eye space (`face_rotations`).
    pub rotations: [Mat3; 5],
    /// Pixels per face side.
    pub r: usize,
    /// The drawn part of each face.
    pub drawn: [[usize; 4]; 5],
}

/// `x.floor()` without a call into the C library (no SSE4.1 rounding by default); exact for
/// |x| < 2³¹, and saturating beyond, which the callers clamp.
pub(super) fn floor(x: f32) -> f32 {
    let i = x as i32 as f32;
    if i > x {
        i - 1.0
    } else {
        i
    }
}

impl Views {
    /// Every drawn pixel uncovered (∞), the others covered at any depth (−∞: nothing there is
    /// ever read, so nothing behind them matters).
    fn clear(&self, cover: &mut Vec<f32>) {
        let r = self.r;
        cover.clear();
        cover.resize(5 * r * r, f32::NEG_INFINITY);
        for (k, &[x, y, w, h]) in self.drawn.iter().enumerate() {
            for row in y..y + h {
                let at = k * r * r + row * r;
                cover[at + x..at + x + w].fill(f32::INFINITY);
            }
        }
    }

    /// How far inside a piece (NDC) a pixel centre must lie to count as covered, and how far
    /// outside a box's projection one still counts as reached: more than llvmpipe's vertex
    /// snapping (1/256 pixel), and the float noise between this transform and the GPU's.
    fn margin(&self) -> f32 {
        2.0 / self.r as f32 / 64.0 + 1e-4
    }

    /// The pixels of a face whose centres lie within [lo, hi] (NDC, widened by `margin`; an
    /// empty range when first > last).
    fn pixels(&self, lo: f32, hi: f32, margin: f32) -> (usize, usize) {
        let r = self.r as f32;
        let first = -floor(-((lo - margin + 1.0) * 0.5 * r - 0.5));
        let last = floor((hi + margin + 1.0) * 0.5 * r - 0.5).min(r - 1.0);
        if first > last || last < 0.0 {
            (1, 0)
        } else {
            (first.max(0.0) as usize, last as usize)
        }
    }

    /// Per face, the tangent ranges (x, then y; NDC, within [-1, 1]) the box (lower corner
    /// `lo`, upper `hi`) may reach in it; `None` where it lies wholly outside the face's
    /// frustum, by more than `tolerance` (NDC) beyond its edges (within it: the edge). The box
    /// around the box in eye space, then in each face's space (a face's rotation permutes the
    /// axes, so its box is exact there).
    pub(super) fn footprints(&self, lo: Vec3, hi: Vec3, tolerance: f32) -> [Option<Footprint>; 5] {
        let eye = self.eye_box(lo, hi);
        FACE_AXES.map(|axes| footprint(eye, axes, tolerance))
    }

    /// The box around the box (lower corner `lo`, upper `hi`) in eye space.
    fn eye_box(&self, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
        debug_assert_eq!(self.rotations, crate::solver::visibility::face_rotations());
        let rotation = Mat3::from_mat4(self.view);
        let centre = self.view.transform_point3(0.5 * (lo + hi));
        let half = abs(&rotation) * (0.5 * (hi - lo));
        (centre - half, centre + half)
    }
}

/// One face's tangent ranges of the box `(elo, ehi)` in eye space (see `Views::footprints`);
/// `axes`: the face's `FACE_AXES`.
fn footprint(eye: (Vec3, Vec3), axes: [(usize, f32); 3], tolerance: f32) -> Option<Footprint> {
    let ((xlo, xhi), (ylo, yhi), (w_lo, w_hi)) = face_box(eye, axes);
    if w_hi <= 0.0 {
        return None;
    }
    // Clamped to the face, a range beyond an edge comes out reversed.
    let (u0, u1) = tangent_range(xlo, xhi, w_lo, w_hi);
    let (v0, v1) = tangent_range(ylo, yhi, w_lo, w_hi);
    (u0 <= u1 + tolerance && v0 <= v1 + tolerance)
        .then_some(((u0.min(u1), u0.max(u1)), (v0.min(v1), v0.max(v1))))
}

/// The box `(elo, ehi)` in eye space as ranges in the space of the face whose `FACE_AXES` are
/// `axes`: across (x), up (y), and depth along the face's axis (w = −z). Each face's rotation
/// only permutes and negates the eye space's axes, so no products are needed.
pub(super) fn face_box(
    (elo, ehi): (Vec3, Vec3),
    axes: [(usize, f32); 3],
) -> ((f32, f32), (f32, f32), (f32, f32)) {
    let range = |(axis, sign): (usize, f32)| {
        if sign > 0.0 {
            (elo[axis], ehi[axis])
        } else {
            (-ehi[axis], -elo[axis])
        }
    };
    let (zlo, zhi) = range(axes[2]);
    (range(axes[0]), range(axes[1]), (-zhi, -zlo))
}

/// Each hemicube face's rotation (`face_rotations`) as the eye-space axis and sign of the
/// face's x, y and z: front (x, y, z), +x (z, y, -x), -x (-z, y, x), +y (x, z, -y),
/// -y (-x, z, y).
pub(super) const FACE_AXES: [[(usize, f32); 3]; 5] = [
    [(0, 1.0), (1, 1.0), (2, 1.0)],
    [(2, 1.0), (1, 1.0), (0, -1.0)],
    [(2, -1.0), (1, 1.0), (0, 1.0)],
    [(0, 1.0), (2, 1.0), (1, -1.0)],
    [(0, -1.0), (2, 1.0), (1, 1.0)],
];

/// Where a box may reach in a face: its tangent ranges across and up (NDC).
pub(super) type Footprint = ((f32, f32), (f32, f32));

/// One shot's walk: its views, and the clipping distances.
struct Walk<'a> {
    views: &'a Views,
    /// The views' near plane: the depth (along a face's axis) where the GPU clips, and where
    /// the written item buffer clips too.
    near: f32,
    /// A piece whose plane lies nearer than this may be clipped by the near plane.
    clear: f32,
    far: f32,
}

/// Bounds of x / w over lo ≤ x ≤ hi, 0 < w ≤ w_hi (w_lo ≤ 0: w reaches down to 0), clamped to a
/// face's [-1, 1].
fn tangent_range(lo: f32, hi: f32, w_lo: f32, w_hi: f32) -> (f32, f32) {
    let (a, b) = if w_lo > 0.0 {
        ((lo / w_lo).min(lo / w_hi), (hi / w_lo).max(hi / w_hi))
    } else {
        (
            if lo >= 0.0 { lo / w_hi } else { -1.0 },
            if hi <= 0.0 { hi / w_hi } else { 1.0 },
        )
    };
    (a.max(-1.0), b.min(1.0))
}

impl Walk<'_> {
    /// The distance from the shooter to the box.
    fn distance(&self, lo: Vec3, hi: Vec3) -> f32 {
        let s = self.views.s;
        (lo - s).max(s - hi).max(Vec3::ZERO).length()
    }

    /// Whether nothing in the box (lower corner `lo`, upper `hi`, at `distance`) can show: it
    /// lies wholly behind the shooter's plane, or at every drawn pixel centre its projection
    /// can reach something is drawn nearer.
    fn hidden(&self, cover: &[f32], distance: f32, lo: Vec3, hi: Vec3) -> bool {
        let v = self.views;
        // The farthest the box reaches along the normal: at the corner picked per axis. Strictly
        // behind the plane: a pixel centre may lie on the horizon itself (an odd side), and a
        // polygon touching the plane may cover it.
        let reach = Vec3::select(v.normal.cmpgt(Vec3::ZERO), hi, lo) - v.s;
        if reach.dot(v.normal) < -BEHIND * reach.length() {
            return true;
        }
        let limit = distance * (1.0 - NEARER);
        if limit <= self.clear {
            return false;
        }
        let (r, m) = (v.r, v.margin());
        // Face by face, so that a box seen in one face costs no other face's footprint.
        let eye = v.eye_box(lo, hi);
        for (k, &axes) in FACE_AXES.iter().enumerate() {
            let Some(((u0, u1), (v0, v1))) = footprint(eye, axes, 0.0) else {
                continue;
            };
            let ((i0, i1), (j0, j1)) = (v.pixels(u0, u1, m), v.pixels(v0, v1, m));
            if i0 > i1 || j0 > j1 {
                continue;
            }
            for j in j0..=j1 {
                let at = k * r * r + j * r;
                if cover[at + i0..=at + i1].iter().any(|&d| d >= limit) {
                    return false;
                }
            }
        }
        true
    }

    /// The faces (bit k: face k) in whose frustum part of the box (lower corner `lo`, upper
    /// `hi`) may lie.
    fn faces_reached(&self, lo: Vec3, hi: Vec3) -> u8 {
        (self.views.footprints(lo, hi, 0.0).iter().enumerate())
            .filter(|(_, reach)| reach.is_some())
            .fold(0, |faces, (k, _)| faces | 1 << k)
    }

    /// Record, at each pixel centre of the faces `faces` that the convex `piece` (plane normal
    /// `normal`) covers, how far along the centre's ray it lies (if nearer than what is
    /// recorded). Without `ids`, for the culling alone: a centre counts only well inside the
    /// piece (`Views::margin`), and a piece the near plane could clip records nothing. With
    /// `ids` (`Tuning::walk_item_buffers`), as the item buffer: every centre inside the piece
    /// (edges included), the piece clipped to the near plane as the GPU clips it, and the
    /// nearest piece's ID (`ids.1`, the polygon's ID + 1) written into `ids.0`.
    fn cover(
        &self,
        cover: &mut [f32],
        piece: &[Vec3],
        normal: Vec3,
        faces: u8,
        mut ids: Option<(&mut [u32], u32)>,
    ) {
        let v = self.views;
        let n = piece.len();
        let length = normal.length();
        let exact = ids.is_some();
        // Degenerate; too near (the near plane could clip it) unless clipped; seen edge-on
        // (its plane through the eye: the GPU draws it as nothing, up to depth noise).
        let plane_distance = (normal.dot(piece[0] - v.s) / length).abs();
        let too_near = if exact {
            EDGE_ON * self.clear
        } else {
            self.clear
        };
        if length == 0.0 || plane_distance <= too_near {
            return;
        }
        let farthest = piece
            .iter()
            .map(|&p| (p - v.s).length())
            .fold(0.0, f32::max);
        // (NaN, from a piece at infinity, fails too.)
        if farthest.partial_cmp(&self.far) != Some(std::cmp::Ordering::Less) {
            return;
        }
        let mut eye = [Vec3::ZERO; MAX_PIECE];
        for (e, &p) in eye.iter_mut().zip(piece) {
            *e = v.view.transform_point3(p);
        }
        let eye_normal = v.view.transform_vector3(normal);
        let (r, m) = (v.r, if exact { 0.0 } else { v.margin() });
        let pixel = 2.0 / r as f32;
        for (k, face) in v.rotations.iter().enumerate() {
            if faces & (1 << k) == 0 {
                continue;
            }
            // The piece in the face's tangent plane (one corner more if clipped), and a point
            // of its plane.
            let mut p = [glam::Vec2::ZERO; MAX_PIECE + 1];
            let mut q0 = Vec3::ZERO;
            let mut count = 0;
            for i in 0..n {
                let a = *face * eye[i];
                let b = *face * eye[(i + 1) % n];
                let (da, db) = (-a.z - self.near, -b.z - self.near);
                if !exact && -a.z <= 0.0 {
                    // Behind the eye: the walk needs no cover from it.
                    count = 0;
                    break;
                }
                if !exact || da >= 0.0 {
                    q0 = if count == 0 { a } else { q0 };
                    p[count] = glam::Vec2::new(a.x, a.y) / -a.z;
                    count += 1;
                }
                if exact && (da >= 0.0) != (db >= 0.0) {
                    let c = a + (b - a) * (da / (da - db));
                    q0 = if count == 0 { c } else { q0 };
                    p[count] = glam::Vec2::new(c.x, c.y) / -c.z;
                    count += 1;
                }
            }
            if count < 3 {
                continue;
            }
            let p = &p[..count];
            let (lo, hi) = p.iter().fold(
                (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN)),
                |(lo, hi), &t| (lo.min(t), hi.max(t)),
            );
            let ((i0, i1), (j0, j1)) = (v.pixels(lo.x, hi.x, -m), v.pixels(lo.y, hi.y, -m));
            if i0 > i1 || j0 > j1 {
                continue;
            }
            let area: f32 = (0..count).map(|i| p[i].perp_dot(p[(i + 1) % count])).sum();
            if area == 0.0 {
                continue;
            }
            let turn = area.signum();
            // The piece's plane in face space: a centre's ray (x, y, -1) meets it at depth t.
            let plane = *face * eye_normal;
            let offset = plane.dot(q0);
            for j in j0..=j1 {
                let y = (j as f32 + 0.5) * pixel - 1.0;
                // The centres of this row inside every edge by the margin: each edge's test
                // turn · (along × (c − from)) ≥ m·|along| is a bound on c.x along the row.
                let (mut left, mut right) = (-1.0f32, 1.0f32);
                for i in 0..count {
                    let (from, to) = (p[i], p[(i + 1) % count]);
                    let along = to - from;
                    let a = -turn * along.y;
                    let b = turn * along.x * (y - from.y) + turn * along.y * from.x
                        - m * along.length();
                    if a > 0.0 {
                        left = left.max(-b / a);
                    } else if a < 0.0 {
                        right = right.min(-b / a);
                    } else if b < 0.0 {
                        right = -2.0;
                    }
                }
                let (i0, i1) = v.pixels(left, right, 0.0);
                let row = k * r * r + j * r;
                for i in i0..=i1 {
                    let ray = Vec3::new((i as f32 + 0.5) * pixel - 1.0, y, -1.0);
                    let t = offset / plane.dot(ray);
                    if t > 0.0 {
                        let d = t * ray.length();
                        if d < cover[row + i] {
                            cover[row + i] = d;
                            if let Some((ids, id)) = &mut ids {
                                ids[row + i] = *id;
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The matrix of absolute values (to carry a box's half extents through a rotation).
pub(super) fn abs(m: &Mat3) -> Mat3 {
    Mat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs())
}

#[cfg(test)]
mod tests;
