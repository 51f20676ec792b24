//! Which polygons, and which of their 4×4 blocks of patches, can receive anything from a shot
//! whose item buffer the walk wrote (`Tuning::walk_receivers`; not in the paper, whose
//! reconstruction pass draws every receiver).
//!
//! Why: on Lost Empire a reconstruction pass drew all 9,047 blocks of patches, and its marking
//! pass ran the visibility test of eight shooters on every texel (about two thirds of the pass),
//! though a small shot there reaches a few hundred of 17,000 polygons. The item buffer, written
//! on the CPU, says which.
//!
//! What "can receive" means is the reconstruction shader's test (`Visible` in
//! `glsl/reconstruct.frag`): a patch at direction d from the shooter is seen if d is in front of
//! the shooter and the item-buffer pixel d falls in shows nothing, or the patch's own polygon,
//! or a polygon X whose plane does not put the shooter and the patch on opposite sides by more
//! than the plane slack. A box of patches is left out only if, at every pixel any of its
//! directions can fall in, the polygon shown there hides all of it, by either of two sufficient
//! conditions: the whole box lies beyond X's plane, or the box lies farther from the shooter
//! than the distance at which every ray through the pixel has passed beyond X's plane (a depth
//! per pixel, which prunes large boxes as the hidden-polygon walk does). Both with margins for
//! the GPU's float noise; a polygon whose patches stray from its own plane (a warped face kept
//! whole) hides nothing, since the shader shows it its own patches by ID. A tree of the
//! polygons' boxes is walked first; each polygon kept is then tested block by block (a merged
//! wall may be seen through one gap, and its other blocks need not be drawn).
//!
//! The answer holds every block with a texel the shader finds visible, so the pass's lightmaps
//! stay the same bit for bit: a texel left undrawn is one the marking pass would have
//! discarded, or the pass proper written unchanged.

use super::box_tree::BoxTree;
use super::occlusion::{abs, face_box, floor, Views, BEHIND, FACE_AXES};
use crate::geometry::Plane;
use crate::scene::Scene;
use glam::{Mat3, Vec3, Vec4};

/// Polygons per leaf of the tree.
const LEAF: usize = 4;

/// A polygon with at most this many blocks is drawn whole when any of it may receive: testing
/// each would cost more than drawing the few it could save.
const SMALL: usize = 2;

/// What a polygon shown at a pixel hides from a shot: a point p is beyond its plane, away from
/// the shooter by more than the slack and the noise, where `plane.xyz · p > plane.w`; a box with
/// centre c and half extents e wholly where `plane.xyz · c − |plane.xyz| · e > plane.w`.
#[derive(Clone, Copy, Debug)]
struct Hider {
    plane: Vec4,
    /// `plane.xyz` in the shooter's eye space.
    eye_normal: Vec3,
    /// How far beyond the plane the shooter lies (plus the slack and the noise): a ray from the
    /// shooter is that far beyond the plane at distance `reach / cos`, where `cos` is the
    /// cosine between the ray and `plane.xyz`.
    reach: f32,
}

impl Hider {
    /// Hides nothing: a pixel that shows nothing, a plane the shooter lies in, a warped face.
    const NOTHING: Hider = Hider {
        plane: Vec4::new(0.0, 0.0, 0.0, f32::INFINITY),
        eye_normal: Vec3::ZERO,
        reach: f32::INFINITY,
    };
}

/// Whether the box around `centre` with half extents `half` lies wholly beyond `plane`
/// (`Hider::plane`).
fn hides(plane: Vec4, centre: Vec3, half: Vec3) -> bool {
    let n = plane.truncate();
    n.dot(centre) - n.abs().dot(half) > plane.w
}

/// What a shot can reach: polygons, and the atlas blocks of their patches (rows of blocks), each
/// in no particular order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Reach {
    /// The polygons with a block here.
    pub polygons: Vec<u32>,
    /// The blocks, indices in rows of `width.div_ceil(block)` (`SeenReceivers::new`).
    pub blocks: Vec<u32>,
}

/// The patches' boxes and planes, and the tree the test walks (built once per solve).
///
/// The boxes and blocks are stored in the tree's leaf order (`BoxTree::order`), not by polygon:
/// a leaf's polygons then lie side by side in memory. The test is bound by memory, not
/// arithmetic (perf put its hottest instructions on loads of boxes looked up by polygon), and a
/// shot touches a few thousand of the scene's polygons, scattered over megabytes otherwise.
#[derive(Clone, Debug, Default)]
pub struct SeenReceivers {
    tree: BoxTree,
    /// Per leaf-order index k (polygon `tree.order[k]`): the box of its patches' positions, as
    /// the reconstruction pass reads them.
    boxes: Vec<(Vec3, Vec3)>,
    /// Per leaf-order index k, `blocks[block_starts[k]..block_starts[k + 1]]`: each atlas block
    /// holding some of the polygon's patches, with the box of those.
    blocks: Vec<(u32, Vec3, Vec3)>,
    block_starts: Vec<u32>,
    /// Per polygon: its plane, as the reconstruction pass reads it (`PolygonPlanes`), or `None`
    /// where its patches stray from it by more than half the slack (it then hides nothing).
    planes: Vec<Option<Plane>>,
    /// World units beyond a plane that count as behind it (`Scene::plane_slack`).
    slack: f32,
    /// World units of float noise in a plane distance (of the scene's largest coordinate).
    noise: f32,
}

/// One shot's scratch space, kept from shot to shot (one per list builder).
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    /// Per ID + 1 (0: nothing shown), what the polygon hides from this shot, for the IDs the
    /// item buffer shows (the others are never read).
    hiders: Vec<Hider>,
    /// Per pixel of the five faces: the plane of what the pixel shows (`Hider::plane`), read
    /// pixel by pixel rather than through the ID (one load in a small array, not two, the
    /// second scattered over a table as long as the scene's polygons).
    planes: Vec<Vec4>,
    /// Per pixel of the five faces (as the walk's item buffer): the distance from the shooter
    /// beyond which every ray through the pixel is hidden by what it shows (∞: none).
    depths: Vec<f32>,
    stack: Vec<u32>,
}

impl SeenReceivers {
    /// The test for `scene`, whose patches lie at `positions`: the reconstruction pass's patch
    /// position atlas, `width` texels wide (RGBA per texel, polygon ID + 1 in alpha, 0 where no
    /// patch), drawn in blocks of `block` × `block` texels.
    pub fn new(scene: &Scene, positions: &[f32], width: usize, block: usize) -> SeenReceivers {
        let n = scene.polygons.len();
        let wide = width.div_ceil(block.max(1));
        let mut patches: Vec<(u32, u32, Vec3)> = (positions.chunks_exact(4).enumerate())
            .filter(|(_, t)| t[3] >= 1.0 && (t[3] as usize) <= n)
            .map(|(i, t)| {
                let (x, y) = (i % width, i / width);
                let b = (y / block * wide + x / block) as u32;
                (t[3] as u32 - 1, b, Vec3::new(t[0], t[1], t[2]))
            })
            .collect();
        patches.sort_unstable_by_key(|&(p, b, _)| (p, b));
        let slack = scene.plane_slack();
        let mut planes: Vec<Option<Plane>> =
            scene.polygons.iter().map(|p| Some(p.plane())).collect();
        let empty = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        let mut boxes = vec![empty; n];
        let mut blocks: Vec<(u32, Vec3, Vec3)> = Vec::new();
        let mut block_starts = vec![0u32; n + 1];
        for &(p, b, x) in &patches {
            let p = p as usize;
            if planes[p].is_some_and(|plane| plane.distance(x).abs() > 0.5 * slack) {
                planes[p] = None;
            }
            boxes[p] = (boxes[p].0.min(x), boxes[p].1.max(x));
            match blocks.last_mut() {
                Some(last) if block_starts[p + 1] > 0 && last.0 == b => {
                    *last = (b, last.1.min(x), last.2.max(x));
                }
                _ => {
                    blocks.push((b, x, x));
                    block_starts[p + 1] += 1;
                }
            }
        }
        for p in 0..n {
            block_starts[p + 1] += block_starts[p];
        }
        let with_patches: Vec<u32> = (0..n as u32)
            .filter(|&p| block_starts[p as usize + 1] > block_starts[p as usize])
            .collect();
        let tree = BoxTree::new(&boxes, with_patches, LEAF);
        // Into leaf order.
        let of = |p: u32| block_starts[p as usize] as usize..block_starts[p as usize + 1] as usize;
        let leaf_boxes = tree.order.iter().map(|&p| boxes[p as usize]).collect();
        let leaf_blocks = (tree.order.iter())
            .flat_map(|&p| blocks[of(p)].iter().copied())
            .collect();
        let leaf_starts = std::iter::once(0)
            .chain(tree.order.iter().scan(0, |end, &p| {
                *end += of(p).len() as u32;
                Some(*end)
            }))
            .collect();
        let (lo, hi) = scene.bounds();
        let largest = lo.abs().max(hi.abs()).max_element();
        SeenReceivers {
            tree,
            boxes: leaf_boxes,
            blocks: leaf_blocks,
            block_starts: leaf_starts,
            planes,
            slack,
            // f32 rounds to 6e-8 of a value; a plane distance adds three products and an offset.
            noise: 2e-6 * largest,
        }
    }

    /// Whether there is nothing to test (the default, before `new`).
    pub fn is_empty(&self) -> bool {
        self.tree.nodes.is_empty()
    }

    /// Into `out`, what the shot of `views` whose item buffer is `ids` (per pixel of the five
    /// faces, the shown polygon's ID + 1, 0 for none: `occlusion::Scratch::item_ids`) may reach.
    pub fn receivers(&self, scratch: &mut Scratch, views: &Views, ids: &[u32], out: &mut Reach) {
        out.polygons.clear();
        out.blocks.clear();
        if self.is_empty() {
            return;
        }
        let turn = Mat3::from_mat4(views.view);
        self.hiders(&mut scratch.hiders, views, turn, ids);
        depths(&mut scratch.depths, views, ids, &scratch.hiders);
        scratch.planes.clear();
        (scratch.planes).extend(ids.iter().map(|&n| match scratch.hiders.get(n as usize) {
            Some(hider) => hider.plane,
            None => Hider::NOTHING.plane,
        }));
        let shot = Shot {
            views,
            turn: abs(&turn),
            planes: &scratch.planes,
            depths: &scratch.depths,
            noise: self.noise,
            margin: MARGIN_PIXELS * 2.0 / views.r as f32 + MARGIN_NDC,
        };
        scratch.stack.clear();
        scratch.stack.push(0);
        while let Some(at) = scratch.stack.pop() {
            let node = &self.tree.nodes[at as usize];
            if shot.hidden(node.lo, node.hi) {
                continue;
            }
            if !node.is_leaf() {
                scratch.stack.extend([node.children, node.children + 1]);
                continue;
            }
            for k in node.start as usize..node.end as usize {
                let (lo, hi) = self.boxes[k];
                if shot.hidden(lo, hi) {
                    continue;
                }
                let p = self.tree.order[k] as usize;
                let range = self.block_starts[k] as usize..self.block_starts[k + 1] as usize;
                let blocks = &self.blocks[range];
                if blocks.len() <= SMALL {
                    out.blocks.extend(blocks.iter().map(|&(b, _, _)| b));
                    out.polygons.push(p as u32);
                    continue;
                }
                let before = out.blocks.len();
                out.blocks.extend(
                    (blocks.iter())
                        .filter(|&&(_, lo, hi)| !shot.hidden(lo, hi))
                        .map(|&(b, _, _)| b),
                );
                if out.blocks.len() > before {
                    out.polygons.push(p as u32);
                }
            }
        }
    }

    /// For each ID + 1 that `ids` shows, what that polygon hides from the shot of `views`
    /// (whose rotation into eye space is `turn`).
    fn hiders(&self, hiders: &mut Vec<Hider>, views: &Views, turn: Mat3, ids: &[u32]) {
        hiders.resize(self.planes.len() + 1, Hider::NOTHING);
        // Neighbouring pixels mostly show the same polygon.
        let mut last = 0;
        for &n in ids {
            if n != last && (n as usize) < hiders.len() {
                hiders[n as usize] = self.hider(n as usize - 1, views.s, turn);
                last = n;
            }
        }
        hiders[0] = Hider::NOTHING;
    }

    /// What polygon `x`, shown at a pixel, hides from a shooter at `s` (`turn`: the rotation
    /// into its eye space): the points beyond its plane from the shooter by more than the slack
    /// (and the noise), unless the shooter lies in the plane.
    fn hider(&self, x: usize, s: Vec3, turn: Mat3) -> Hider {
        let Some(Some(plane)) = self.planes.get(x) else {
            return Hider::NOTHING;
        };
        let margin = self.slack + self.noise;
        let hs = plane.distance(s);
        // (NaN, from a degenerate plane, hides nothing too.)
        if hs.abs().partial_cmp(&margin) != Some(std::cmp::Ordering::Greater) {
            return Hider::NOTHING;
        }
        // The side away from the shooter, as a positive distance.
        let side = -hs.signum();
        let normal = side * plane.normal;
        Hider {
            plane: normal.extend(side * plane.offset + margin),
            eye_normal: turn * normal,
            reach: hs.abs() + margin,
        }
    }
}

/// Into `depths`, per pixel of `views`' five faces, the distance from the shooter beyond which
/// every ray through the pixel lies beyond the plane of the polygon `ids` shows there (by
/// `hiders`), ∞ where none does. A ray along unit direction q is beyond the plane by more than
/// the margin from distance `reach / (n·q)` on (n the plane's normal away from the shooter);
/// over a pixel, n·q is at least its value at the centre less the pixel's half width in each
/// tangent, over the longest |q| (q = (u, v, −1) in the face's space).
fn depths(depths: &mut Vec<f32>, views: &Views, ids: &[u32], hiders: &[Hider]) {
    let r = views.r;
    depths.clear();
    depths.resize(5 * r * r, f32::INFINITY);
    let pixel = 2.0 / r as f32;
    // Half a pixel, and the directions rounded into it from beyond (`Shot::hidden`'s margin).
    let half = 0.5 * pixel + 2.0 * MARGIN_PIXELS * pixel + 2.0 * MARGIN_NDC;
    let corner = std::f32::consts::SQRT_2 * half;
    for (k, (axes, &[x, y, w, h])) in FACE_AXES.iter().zip(&views.drawn).enumerate() {
        for j in y..y + h {
            let v = (j as f32 + 0.5) * pixel - 1.0;
            for i in x..x + w {
                let at = k * r * r + j * r + i;
                let Some(hider) = ids.get(at).and_then(|&n| hiders.get(n as usize)) else {
                    continue;
                };
                if hider.reach.is_infinite() {
                    continue;
                }
                let e = hider.eye_normal;
                let n = Vec3::from_array(axes.map(|(axis, sign)| sign * e[axis]));
                let u = (i as f32 + 0.5) * pixel - 1.0;
                let q = Vec3::new(u, v, -1.0);
                let least = n.dot(q) - (n.x.abs() + n.y.abs()) * half;
                if least > 0.0 {
                    depths[at] = hider.reach * (q.length() + corner) / least;
                }
            }
        }
    }
}

/// How far beyond a box's projection (in pixels, and in NDC) a direction may be rounded: more
/// than llvmpipe's vertex snapping and the float noise between this transform and the GPU's.
const MARGIN_PIXELS: f32 = 1.0 / 64.0;
const MARGIN_NDC: f32 = 1e-4;

/// One shot, as the test reads it.
struct Shot<'a> {
    views: &'a Views,
    /// The view's rotation with every entry made positive: it carries a box's half extents
    /// into eye space.
    turn: Mat3,
    /// Per pixel of the five faces, the plane of what it shows (`Scratch::planes`).
    planes: &'a [Vec4],
    /// Per pixel, the distance beyond which it hides everything (`depths`).
    depths: &'a [f32],
    /// World units of float noise in a coordinate (`SeenReceivers::noise`).
    noise: f32,
    /// How far beyond a box's projection (NDC) a direction may be rounded, noise aside.
    margin: f32,
}

impl Shot<'_> {
    /// Whether no patch in the box (lower corner `lo`, upper `hi`) can be seen: the box lies
    /// behind the shooter's plane, or at every pixel any of its directions can fall in, what
    /// the pixel shows hides it.
    fn hidden(&self, lo: Vec3, hi: Vec3) -> bool {
        let views = self.views;
        // Wholly behind the shooter's plane (by more than the walk's float slack).
        let reach = Vec3::select(views.normal.cmpgt(Vec3::ZERO), hi, lo) - views.s;
        let ahead = reach.dot(views.normal);
        if ahead < 0.0 && ahead * ahead > BEHIND * BEHIND * reach.length_squared() {
            return true;
        }
        let (centre, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let distance = (lo - views.s).max(views.s - hi).max(Vec3::ZERO).length();
        let r = views.r;
        // The GPU finds a direction's pixel from the patch in eye space: besides the rounding
        // of the pixel (and of the reciprocals below), float noise of the scene's coordinates
        // relative to the distance. Where that is within the usual margin, the depths (which
        // allow for twice it) apply too.
        let (m, far) = if self.noise <= MARGIN_NDC * distance {
            (self.margin + MARGIN_NDC, distance * (1.0 - 1e-4))
        } else {
            (self.margin + self.noise / distance.max(1e-30), 0.0)
        };
        if m >= 1.0 {
            return false;
        }
        let hides = |at: usize| far > self.depths[at] || hides(self.planes[at], centre, half);
        // The box in eye space.
        let eye = views.view.transform_point3(centre);
        // Most boxes that are not hidden show at their centre: look there first.
        if let Some(at) = self.pixel_of(eye) {
            if !hides(at) {
                return false;
            }
        }
        let extent = self.turn * half;
        let (elo, ehi) = (eye - extent, eye + extent);
        for (k, &axes) in FACE_AXES.iter().enumerate() {
            let (x, y, (w_lo, w_hi)) = face_box((elo, ehi), axes);
            // Beyond the face's side planes (|x|, |y| ≤ w, widened by the margin): no division.
            let edge = w_hi * (1.0 + m);
            if w_hi <= 0.0 || x.0 > edge || x.1 < -edge || y.0 > edge || y.1 < -edge {
                continue;
            }
            let (Some((i0, i1)), Some((j0, j1))) = (
                tangent_pixels(x, w_lo, w_hi, m, r),
                tangent_pixels(y, w_lo, w_hi, m, r),
            ) else {
                continue;
            };
            // No direction in front of the shooter falls beyond the drawn part of a face
            // (`front_half`), but one just in front of it may round into the first pixel
            // beyond, which shows nothing (and so hides nothing).
            let [x, y, w, h] = views.drawn[k];
            let (i0, j0) = (i0.max(x.saturating_sub(1)), j0.max(y.saturating_sub(1)));
            let (i1, j1) = (i1.min(x + w), j1.min(y + h));
            for j in j0..=j1 {
                let row = k * r * r + j * r;
                if !(i0..=i1).all(|i| hides(row + i)) {
                    return false;
                }
            }
        }
        true
    }

    /// The pixel (index in `ids`) the reconstruction shader looks up for a patch at `d` (eye
    /// space), as it finds it (`item_texel` in `glsl/reconstruct.frag`); `None` behind the
    /// shooter.
    fn pixel_of(&self, d: Vec3) -> Option<usize> {
        if d.z >= 0.0 {
            return None;
        }
        let a = d.abs();
        let front = -d.z >= a.x && -d.z >= a.y;
        let side_x = !front && a.x >= a.y;
        let (face, f) = if front {
            (0, Vec3::new(d.x, d.y, -d.z))
        } else if side_x {
            let sx = d.x.signum();
            (
                if d.x > 0.0 { 1 } else { 2 },
                Vec3::new(sx * d.z, d.y, sx * d.x),
            )
        } else {
            let sy = d.y.signum();
            (
                if d.y > 0.0 { 3 } else { 4 },
                Vec3::new(sy * d.x, d.z, sy * d.y),
            )
        };
        let r = self.views.r;
        let (i, j) = (pixel(f.x / f.z, r), pixel(f.y / f.z, r));
        Some(face * r * r + j * r + i)
    }
}

/// The pixel of a face (r a side) a direction with tangent `t` (NDC) falls in, as the
/// reconstruction shader finds it: floor((t / 2 + 1/2) r), clamped to the face.
fn pixel(t: f32, r: usize) -> usize {
    floor((t * 0.5 + 0.5) * r as f32).clamp(0.0, r as f32 - 1.0) as usize
}

/// The pixels of a face (r a side) across one axis that the directions to a box may fall in:
/// its range `(lo, hi)` along the axis at depths from `w_lo` to `w_hi` (w_hi > 0; w_lo ≤ 0:
/// down to the eye plane), widened by `m` (NDC); `None` if they miss the face by more.
fn tangent_pixels(
    (lo, hi): (f32, f32),
    w_lo: f32,
    w_hi: f32,
    m: f32,
    r: usize,
) -> Option<(usize, usize)> {
    let inv_hi = 1.0 / w_hi;
    let (t0, t1) = if w_lo > 0.0 {
        let inv_lo = 1.0 / w_lo;
        (
            (lo * inv_lo).min(lo * inv_hi),
            (hi * inv_lo).max(hi * inv_hi),
        )
    } else {
        (
            if lo >= 0.0 {
                lo * inv_hi
            } else {
                f32::NEG_INFINITY
            },
            if hi <= 0.0 {
                hi * inv_hi
            } else {
                f32::INFINITY
            },
        )
    };
    let (t0, t1) = (t0 - m, t1 + m);
    (t0 <= 1.0 && t1 >= -1.0).then(|| (pixel(t0.max(-1.0), r), pixel(t1.min(1.0), r)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::visibility::{face_rotations, front_half};
    use glam::Mat4;

    /// A shooter at the origin looking up +z at a wall (z = 1) that fills its front face, and
    /// what lies about it; each polygon's patches are its corners drawn a tenth towards its
    /// centre, in a 4×4 block of its own.
    #[test]
    fn a_box_is_left_out_only_where_every_pixel_hides_it() {
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path();
        let mut mtl = String::from("newmtl light\nKd 0 0 0\nKe 1 1 1\n");
        let mut obj = String::from("mtllib t.mtl\n");
        // (name, z, x and y from, to); each faces the shooter (-z), the light faces +z.
        let quads = [
            ("wall", 1.0, -3.0, 3.0),
            ("behind", 2.0, -0.2, 0.2),
            ("near", 0.5, 0.3, 0.5),
            ("poster", 1.0 - 1e-6, -0.6, -0.4),
            ("gap", 2.0, 0.6, 0.8),
            ("light", -5.0, -1.0, 1.0),
        ];
        for (k, &(name, z, a, b)) in quads.iter().enumerate() {
            if name != "light" {
                mtl += &format!("newmtl {name}\nKd 0.5 0.5 0.5\n");
            }
            obj += &format!("v {a} {a} {z}\nv {a} {b} {z}\nv {b} {b} {z}\nv {b} {a} {z}\n");
            let v = 4 * k + 1;
            let (p, q) = if name == "light" {
                (v + 3, v + 1)
            } else {
                (v + 1, v + 3)
            };
            obj += &format!("usemtl {name}\nf {v} {p} {} {q}\n", v + 2);
        }
        std::fs::write(dir.join("t.mtl"), mtl).unwrap();
        std::fs::write(dir.join("t.obj"), obj).unwrap();
        let scene = crate::scene::load_obj(&dir.join("t.obj")).unwrap();
        assert_eq!(scene.polygons.len(), quads.len());
        let find = |z: f32, x: f32| {
            (scene.polygons.iter())
                .position(|p| (p.centroid.z - z).abs() < 1e-3 && (p.centroid.x - x).abs() < 1e-3)
                .unwrap()
        };
        let id: Vec<usize> = quads
            .iter()
            .map(|&(_, z, a, b)| find(z, 0.5 * (a + b)))
            .collect();
        // The patch position atlas: polygon p's block at x = 4p.
        let width = 4 * scene.polygons.len();
        let mut positions = vec![0.0f32; width * 4 * 4];
        for (p, polygon) in scene.polygons.iter().enumerate() {
            for (k, &v) in polygon.vertices.iter().enumerate() {
                let at = (4 * p + k) * 4;
                let x = v + 0.1 * (polygon.centroid - v);
                positions[at..at + 4].copy_from_slice(&[x.x, x.y, x.z, p as f32 + 1.0]);
            }
        }
        let seen = SeenReceivers::new(&scene, &positions, width, 4);
        let r = 8;
        let views = Views {
            s: Vec3::ZERO,
            normal: Vec3::Z,
            view: Mat4::look_at_rh(Vec3::ZERO, Vec3::Z, Vec3::Y),
            rotations: face_rotations(),
            r,
            drawn: std::array::from_fn(|k| front_half(k, r as i32).map(|v| v as usize)),
        };
        // The front face shows the wall, but for the pixel the gap's quad lies in, which shows
        // nothing; the side faces show nothing.
        let mut ids = vec![0u32; 5 * r * r];
        ids[..r * r].fill(id[0] as u32 + 1);
        let gap = views.view.transform_point3(scene.polygons[id[4]].centroid);
        let pixel = |t: f32| ((t * 0.5 + 0.5) * r as f32) as usize;
        ids[pixel(-gap.y / gap.z) * r + pixel(-gap.x / gap.z)] = 0;
        let mut reach = Reach::default();
        seen.receivers(&mut Scratch::default(), &views, &ids, &mut reach);
        let reached = |k: usize| reach.polygons.contains(&(id[k] as u32));
        // The wall, what lies in front of it, what lies in its plane, and what lies behind the
        // pixel that shows nothing may receive.
        for k in [0, 2, 3, 4] {
            assert!(reached(k), "{} not reached: {reach:?}", quads[k].0);
            assert!(reach.blocks.contains(&(id[k] as u32)), "{}", quads[k].0);
        }
        // What lies behind the wall, and behind the shooter, may not.
        for k in [1, 5] {
            assert!(!reached(k), "{} reached: {reach:?}", quads[k].0);
        }
        assert_eq!(reach.blocks.len(), 4);
    }
}
