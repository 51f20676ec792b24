//! Patches: every polygon owns a rectangular lightmap whose texels are its patches (section 3.1's
//! "small patches"), and all lightmaps are packed into one atlas texture (section 3.2, step 5).
//!
//! A polygon's lightmap covers the polygon's bounding rectangle in its own plane, in the
//! orientation (one of its edges) that makes that rectangle smallest, so that a rectangle's
//! lightmap is exactly the rectangle. A texel is a patch when its centre lies inside the polygon
//! (the rasterizer's rule, so the GPU draws exactly these texels).
//!
//! ```text
//!   atlas (texels)                 one lightmap with its 1-texel gutter
//!   +-----+--------+---+           g g g g g g
//!   | L0  |   L1   |L2 |           g p p p p g    p: patch texels (w x h)
//!   +-----+---+----+---+           g p p p p g    g: gutter, filled with copies of the
//!   |  L3     | L4 |               g g g g g g       nearest patch before display
//!   +---------+----+
//! ```

mod atlas;

use crate::geometry::{flatten, point_in_polygon};
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// Where one polygon's patches are and how they map to the world.
#[derive(Clone, Debug)]
pub struct Lightmap {
    /// Texel rectangle of the patches inside the atlas (gutter excluded).
    pub x: u32,
    /// Its bottom row in the atlas.
    pub y: u32,
    /// Its width, texels.
    pub w: u32,
    /// Its height, texels.
    pub h: u32,
    /// World position of the lightmap's corner (texel coordinate (0, 0)).
    pub origin: Vec3,
    /// World vectors spanning the whole lightmap along its width and height.
    pub axis_u: Vec3,
    /// See `axis_u`: along the lightmap's height.
    pub axis_v: Vec3,
}

impl Lightmap {
    /// Its texel rectangle in the atlas, [x0, y0, x1, y1).
    pub fn texels(&self) -> [u32; 4] {
        [self.x, self.y, self.x + self.w, self.y + self.h]
    }

    /// World position of a point given in the lightmap's own texel coordinates.
    pub fn world(&self, s: f32, t: f32) -> Vec3 {
        self.origin + self.axis_u * (s / self.w as f32) + self.axis_v * (t / self.h as f32)
    }

    /// World area of one texel.
    pub fn texel_area(&self) -> f32 {
        self.axis_u.length() * self.axis_v.length() / (self.w * self.h) as f32
    }

    /// An outline given in the lightmap's texel coordinates → its world corners (padded to `N`),
    /// their count (at most `N`) and the outline's world area.
    pub fn world_outline<const N: usize>(&self, outline: &[Vec2]) -> ([Vec3; N], usize, f32) {
        let mut corners = [Vec3::ZERO; N];
        for (c, p) in corners.iter_mut().zip(outline) {
            *c = self.world(p.x, p.y);
        }
        let area = crate::geometry::signed_area(outline).abs() * self.texel_area();
        (corners, outline.len().min(N), area)
    }

    /// The outline of this lightmap's polygon (its `vertices`), as at most `N` world corners
    /// with their area: the polygon's own corners, or the lightmap's rectangle where it has
    /// more than `N`.
    pub fn polygon_outline<const N: usize>(&self, vertices: &[Vec3]) -> ([Vec3; N], usize, f32) {
        let outline: Vec<Vec2> = vertices.iter().map(|&v| self.texel_of(v)).collect();
        let rect = crate::geometry::rectangle(Vec2::ZERO, Vec2::new(self.w as f32, self.h as f32));
        self.world_outline(if outline.len() <= N { &outline } else { &rect })
    }

    /// Lightmap texel coordinates (not atlas) of a world point on the polygon's plane.
    pub fn texel_of(&self, p: Vec3) -> Vec2 {
        let d = p - self.origin;
        Vec2::new(
            d.dot(self.axis_u) / self.axis_u.length_squared() * self.w as f32,
            d.dot(self.axis_v) / self.axis_v.length_squared() * self.h as f32,
        )
    }
}

/// Every polygon's lightmap in one atlas texture: one texel per patch, the unit both solvers
/// and the display share.
#[derive(Clone, Debug)]
pub struct PatchLayout {
    /// Atlas width, texels.
    pub atlas_width: u32,
    /// Atlas height, texels.
    pub atlas_height: u32,
    /// Patch size in scene units (the largest side a texel may have).
    pub patch_size: f32,
    /// One lightmap per polygon, in the scene's polygon order.
    pub lightmaps: Vec<Lightmap>,
    /// For every atlas texel (row 0 at the bottom, as in GL), the polygon index + 1 whose patch
    /// it is, or 0.
    pub owner: Vec<u32>,
    /// Patch count per polygon.
    pub patches_per_polygon: Vec<u32>,
}

/// The largest atlas side, in texels (the GL_MAX_TEXTURE_SIZE of most drivers, Mesa's included;
/// the GPU solver also checks the driver's own limit).
pub const MAX_ATLAS_SIDE: u32 = 16384;

/// A patch size the atlas cannot hold; the message suggests one that fits.
#[derive(Debug, thiserror::Error)]
pub enum LayoutError {
    /// One polygon's lightmap alone is larger than an atlas.
    #[error(
        "polygon {polygon} (object '{object}') would need a {w}x{h} lightmap at patch size {size}, \
         more than an atlas of {max}x{max} can hold; the smallest patch size that fits is about \
         {suggest} scene units"
    )]
    Lightmap {
        /// The polygon's index.
        polygon: usize,
        /// Its object (or group) in the file.
        object: String,
        /// The lightmap's width, texels.
        w: u32,
        /// The lightmap's height, texels.
        h: u32,
        /// The patch size asked for.
        size: f32,
        /// The largest atlas side.
        max: u32,
        /// About the smallest patch size that fits.
        suggest: f32,
    },
    /// The lightmaps together do not fit in an atlas.
    #[error(
        "the lightmap atlas would be {w}x{h} texels at patch size {size}, more than {max}x{max}; \
         the smallest patch size that fits is about {suggest} scene units (--patch-size), or \
         ask for fewer --patches"
    )]
    Atlas {
        /// The atlas's width, texels.
        w: u32,
        /// The atlas's height, texels.
        h: u32,
        /// The patch size asked for.
        size: f32,
        /// The largest atlas side.
        max: u32,
        /// About the smallest patch size that fits.
        suggest: f32,
    },
}

/// `x` rounded up to three significant digits, for suggestions in messages.
pub fn three_digits_up(x: f32) -> f32 {
    if !(x > 0.0 && x.is_finite()) {
        return x;
    }
    let scale = 10f32.powi(2 - x.log10().floor() as i32);
    (x * scale).ceil() / scale
}

/// How finely to cut the polygons into patches.
#[derive(Clone, Copy, Debug)]
pub enum Resolution {
    /// Side of a patch in scene units.
    PatchSize(f32),
    /// Aim at about this many patches in all.
    Patches(u32),
}

impl PatchLayout {
    /// The layout of a scene whose atlas is known to fit (tests, generated scenes). User input
    /// goes through [`PatchLayout::try_new`].
    pub fn new(scene: &Scene, resolution: Resolution) -> PatchLayout {
        Self::try_new(scene, resolution).unwrap_or_else(|e| panic!("{e}"))
    }

    /// The layout, or an error (before anything large is allocated) when the atlas would not fit
    /// in a `MAX_ATLAS_SIDE`² texture.
    pub fn try_new(scene: &Scene, resolution: Resolution) -> Result<PatchLayout, LayoutError> {
        let patch_size = match resolution {
            Resolution::PatchSize(s) => s,
            Resolution::Patches(n) => size_for_count(scene, n),
        };
        let max = MAX_ATLAS_SIDE;
        let mut lightmaps: Vec<Lightmap> = Vec::with_capacity(scene.polygons.len());
        let sky = scene.sky_start().unwrap_or(usize::MAX);
        for (i, p) in scene.polygons.iter().enumerate() {
            // A sky quad (`--sky`) is one patch at any patch size: the sky's own coarse
            // resolution, which takes nothing from the scene's.
            let size = if i >= sky { f32::INFINITY } else { patch_size };
            let lm = fit_lightmap(&p.vertices, p.normal, size);
            if lm.w > max - 2 || lm.h > max - 2 {
                // From a lightmap of about 1000 texels: at tiny patch sizes `lm`'s sides saturate.
                let probe = p.bounding_sphere().1 / 500.0;
                let at = fit_lightmap(&p.vertices, p.normal, probe);
                let fits = probe * at.w.max(at.h) as f32 / (max - 2) as f32;
                return Err(LayoutError::Lightmap {
                    polygon: i,
                    object: p.object.clone(),
                    w: lm.w,
                    h: lm.h,
                    size: patch_size,
                    max,
                    suggest: three_digits_up(fits * 1.05),
                });
            }
            lightmaps.push(lm);
        }
        let sizes: Vec<(u32, u32)> = lightmaps.iter().map(|l| (l.w + 2, l.h + 2)).collect();
        let packed = atlas::pack(&sizes);
        if packed.width > max || packed.height > max {
            let scale = packed.width.max(packed.height) as f32 / max as f32;
            return Err(LayoutError::Atlas {
                w: packed.width,
                h: packed.height,
                size: patch_size,
                max,
                suggest: three_digits_up(patch_size * scale * 1.05),
            });
        }
        for (l, &(x, y)) in lightmaps.iter_mut().zip(&packed.positions) {
            l.x = x + 1;
            l.y = y + 1;
        }
        let mut layout = PatchLayout {
            atlas_width: packed.width,
            atlas_height: packed.height,
            patch_size,
            lightmaps,
            owner: vec![0; packed.width as usize * packed.height as usize],
            patches_per_polygon: vec![0; scene.polygons.len()],
        };
        for (i, polygon) in scene.polygons.iter().enumerate() {
            let lm = layout.lightmaps[i].clone();
            let outline: Vec<Vec2> = polygon.vertices.iter().map(|&v| lm.texel_of(v)).collect();
            for t in 0..lm.h {
                for s in 0..lm.w {
                    if point_in_polygon(&outline, Vec2::new(s as f32 + 0.5, t as f32 + 0.5)) {
                        let at =
                            (lm.y + t) as usize * layout.atlas_width as usize + (lm.x + s) as usize;
                        layout.owner[at] = i as u32 + 1;
                        layout.patches_per_polygon[i] += 1;
                    }
                }
            }
        }
        Ok(layout)
    }

    /// The same lightmaps packed edge to edge, without gutters: the solver's own atlas. Only the
    /// display filters between texels and needs the gutters; without them the atlas holds about
    /// twice the patches per texel, and the reconstruction pass, which shades whole blocks of
    /// texels, does about half the work.
    pub fn without_gutters(&self) -> PatchLayout {
        let sizes: Vec<(u32, u32)> = self.lightmaps.iter().map(|l| (l.w, l.h)).collect();
        let packed = atlas::pack(&sizes);
        let mut dense = PatchLayout {
            atlas_width: packed.width,
            atlas_height: packed.height,
            patch_size: self.patch_size,
            lightmaps: self.lightmaps.clone(),
            owner: Vec::new(),
            patches_per_polygon: self.patches_per_polygon.clone(),
        };
        for (l, &(x, y)) in dense.lightmaps.iter_mut().zip(&packed.positions) {
            (l.x, l.y) = (x, y);
        }
        let mut owner = vec![0; packed.width as usize * packed.height as usize];
        self.move_texels(&self.owner, 1, &dense, &mut owner);
        dense.owner = owner;
        dense
    }

    /// An atlas of this layout (`channels` values per texel) moved into `to`, a layout of the
    /// same lightmaps placed elsewhere: every lightmap's texels, the rest zero.
    pub fn move_atlas(&self, data: &[f32], channels: usize, to: &PatchLayout) -> Vec<f32> {
        let mut out = vec![0.0; to.atlas_width as usize * to.atlas_height as usize * channels];
        self.move_texels(data, channels, to, &mut out);
        out
    }

    fn move_texels<T: Copy>(&self, data: &[T], channels: usize, to: &PatchLayout, out: &mut [T]) {
        for (a, b) in self.lightmaps.iter().zip(&to.lightmaps) {
            let row = a.w as usize * channels;
            for t in 0..a.h as usize {
                let from =
                    ((a.y as usize + t) * self.atlas_width as usize + a.x as usize) * channels;
                let into = ((b.y as usize + t) * to.atlas_width as usize + b.x as usize) * channels;
                out[into..into + row].copy_from_slice(&data[from..from + row]);
            }
        }
    }

    /// Every lightmap's texel rectangle [x0, y0, x1, y1), in polygon order.
    pub fn texel_rects(&self) -> Vec<[u32; 4]> {
        self.lightmaps.iter().map(Lightmap::texels).collect()
    }

    /// The patches of every polygon (gutters not counted).
    pub fn patch_count(&self) -> u64 {
        self.patches_per_polygon.iter().map(|&n| n as u64).sum()
    }

    /// Lightmap coordinates of a polygon's vertex, normalised to the atlas (0 to 1 on each axis).
    pub fn atlas_uv(&self, polygon: usize, p: Vec3) -> Vec2 {
        let lm = &self.lightmaps[polygon];
        let t = lm.texel_of(p);
        Vec2::new(
            (lm.x as f32 + t.x) / self.atlas_width as f32,
            (lm.y as f32 + t.y) / self.atlas_height as f32,
        )
    }

    /// Fill every texel that is not a patch, inside a lightmap and its gutter, with the mean of
    /// neighbouring patch texels of the same polygon, so that bilinear filtering at display time
    /// never mixes in black or another polygon's light.
    pub fn dilate(&self, rgba: &mut [f32]) {
        const NEIGHBOURS: [(i64, i64); 8] = [
            (-1, 0),
            (1, 0),
            (0, -1),
            (0, 1),
            (-1, -1),
            (1, -1),
            (-1, 1),
            (1, 1),
        ];
        let (w, h) = (self.atlas_width as i64, self.atlas_height as i64);
        let mut filled = self.owner.clone();
        // Texels already queued for the next ring (stamped with the ring number), so that a
        // texel next to several filled ones is computed once.
        let mut queued = vec![0u32; self.owner.len()];
        let mut ring = Vec::new();
        let mut next = Vec::new();
        let mut writes: Vec<(usize, [f32; 4])> = Vec::new();
        for (index, lm) in self.lightmaps.iter().enumerate() {
            let id = index as u32 + 1;
            let (x0, y0) = (lm.x as i64 - 1, lm.y as i64 - 1);
            let (x1, y1) = ((lm.x + lm.w) as i64, (lm.y + lm.h) as i64);
            // Grow the filled region a ring at a time until the lightmap and its gutter are full
            // (a lightmap with no patch at all stays as it is). Each ring reads only texels
            // filled before it. Only the last ring's neighbours can join the next one, so the
            // work is linear in the lightmap's area (a full rescan per ring is quadratic for a
            // long sliver with few patches).
            ring.clear();
            for y in y0..=y1 {
                for x in x0..=x1 {
                    if filled[(y * w + x) as usize] == id {
                        ring.push((x, y));
                    }
                }
            }
            let mut stamp = 0u32;
            while !ring.is_empty() {
                stamp += 1;
                next.clear();
                for &(x, y) in &ring {
                    for (dx, dy) in NEIGHBOURS {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < x0 || ny < y0 || nx > x1 || ny > y1 {
                            continue;
                        }
                        let at = (ny * w + nx) as usize;
                        if filled[at] != id && queued[at] != stamp {
                            queued[at] = stamp;
                            next.push((nx, ny));
                        }
                    }
                }
                writes.clear();
                for &(x, y) in &next {
                    let mut sum = [0f32; 4];
                    let mut n = 0.0;
                    for (dx, dy) in NEIGHBOURS {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < 0 || ny < 0 || nx >= w || ny >= h {
                            continue;
                        }
                        let nat = (ny * w + nx) as usize;
                        if filled[nat] == id {
                            for c in 0..4 {
                                sum[c] += rgba[nat * 4 + c];
                            }
                            n += 1.0;
                        }
                    }
                    writes.push(((y * w + x) as usize, sum.map(|v| v / n)));
                }
                for &(at, v) in &writes {
                    rgba[at * 4..at * 4 + 4].copy_from_slice(&v);
                    filled[at] = id;
                }
                std::mem::swap(&mut ring, &mut next);
            }
            // The stamps restart at 1 for the next lightmap: clear this one's.
            for y in y0..=y1 {
                let row = (y * w) as usize;
                queued[row + x0 as usize..=row + x1 as usize].fill(0);
            }
        }
    }
}

/// The bounding rectangle of a planar polygon in its own plane, oriented along whichever edge
/// gives the smallest rectangle, cut into texels no larger than `patch_size`.
fn fit_lightmap(vertices: &[Vec3], normal: Vec3, patch_size: f32) -> Lightmap {
    let (u, v, lo, hi) = best_rectangle(vertices, normal);
    let plane = normal * vertices[0].dot(normal);
    let size = hi - lo;
    let w = ((size.x / patch_size).ceil() as u32).max(1);
    let h = ((size.y / patch_size).ceil() as u32).max(1);
    Lightmap {
        x: 0,
        y: 0,
        w,
        h,
        origin: plane + u * lo.x + v * lo.y,
        axis_u: u * size.x,
        axis_v: v * size.y,
    }
}

/// The smallest bounding rectangle along one of the polygon's edges: axes u, v and the corners
/// in (u, v) coordinates. O(n²) in the corners; it does not depend on the patch size.
fn best_rectangle(vertices: &[Vec3], normal: Vec3) -> (Vec3, Vec3, Vec2, Vec2) {
    let n = vertices.len();
    let mut best: Option<(f32, Vec3, Vec3, Vec2, Vec2)> = None;
    for i in 0..n {
        let edge = vertices[(i + 1) % n] - vertices[i];
        let u = (edge - normal * edge.dot(normal)).normalize_or_zero();
        if u == Vec3::ZERO {
            continue;
        }
        let v = normal.cross(u);
        let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
        for q in flatten(vertices, u, v) {
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let area = (hi - lo).x * (hi - lo).y;
        if best.as_ref().is_none_or(|b| area < b.0 * 0.999) {
            best = Some((area, u, v, lo, hi));
        }
    }
    let (_, u, v, lo, hi) = best.expect("polygons with area have a non-degenerate edge");
    (u, v, lo, hi)
}

/// The patch size that gives about `target` patches: start from area / target and refine.
fn size_for_count(scene: &Scene, target: u32) -> f32 {
    // The rectangles once (they do not depend on the patch size); then each step of the search
    // only divides.
    // The sky's quads are one patch each, outside the budget (`try_new`).
    let sizes: Vec<Vec2> = scene
        .own_polygons()
        .iter()
        .map(|p| {
            let (_, _, lo, hi) = best_rectangle(&p.vertices, p.normal);
            hi - lo
        })
        .collect();
    let count = |s: f32| -> u64 {
        sizes
            .iter()
            .map(|d| {
                ((d.x / s).ceil().max(1.0) as u64).saturating_mul((d.y / s).ceil().max(1.0) as u64)
            })
            .fold(0u64, |a, b| a.saturating_add(b))
    };
    let target = target.max(1) as u64;
    let area: f32 = scene.own_polygons().iter().map(|p| p.area).sum();
    let mut size = (area / target as f32).sqrt();
    // Bisection on the (monotone) lightmap texel count; patches are a little fewer than texels.
    // Thin shapes need far more texels than area / size² suggests: widen the bracket until it
    // holds the answer.
    let (mut small, mut large) = (size * 0.25, size * 4.0);
    // Beyond the scene's diagonal every lightmap is one texel: no larger size changes anything.
    let (lo, hi) = scene.bounds();
    let ceiling = 2.0 * (hi - lo).length().max(size);
    for _ in 0..64 {
        if count(large) <= target || large >= ceiling {
            break;
        }
        large = (large * 4.0).min(ceiling);
    }
    for _ in 0..64 {
        if count(small) > target || small < f32::MIN_POSITIVE * 1e6 {
            break;
        }
        small *= 0.25;
    }
    for _ in 0..40 {
        size = 0.5 * (small + large);
        if count(size) > target {
            small = size;
        } else {
            large = size;
        }
    }
    // A target is a target, not a demand: never so fine that one lightmap outgrows the atlas (a
    // long sliver), which would refuse a scene that a slightly coarser size lays out.
    let longest = sizes.iter().map(|d| d.max_element()).fold(0.0, f32::max);
    large.max(longest / (MAX_ATLAS_SIDE - 2) as f32 * 1.001)
}
