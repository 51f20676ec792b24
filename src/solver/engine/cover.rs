//! What the engine's reconstruction pass draws (`MarkedSquares`): aligned squares of whole 4×4
//! texel blocks covering the blocks it needs (found on a pyramid of block masks,
//! `Cover::pyramid`), as points or triangle pairs (`Squares`); which blocks hold each polygon's
//! patches (`patch_blocks`).
//!
//! Why squares: the engine shades only the blocks a pass needs (the receivers', after a marking
//! pass), where the paper's `WholeAtlas` shades the whole atlas as one quad. Why not the
//! receivers' rectangles: a rectangle is two triangles, and llvmpipe shades every block its
//! diagonal crosses once for each; a thin rectangle of lightmaps costs about twice its area. A
//! square drawn as one point is shaded block by block, once (`Tuning::squares_as_points`).

use crate::gl::{Gl, GlContext, GlError, Mesh};
use crate::patches::PatchLayout;
use crate::solver::reconstruction::ATLAS_VERTEX;
use glow::HasContext;

/// Squares are made of whole blocks of 4×4 texels: llvmpipe shades a block of 4×4 fragments at a
/// time, all of them, even where the primitive covers one.
pub(crate) const BLOCK: u32 = 4;
/// Larger squares would be drawn partly over blocks that need nothing.
const LARGEST_SQUARE: u32 = 64;

/// The squares a pass draws (rebuilt every pass), in runs: for the pass proper, those drawn with
/// the shader that clips the shooter to the receiver's plane, then those drawn without; for the
/// marking pass shooter by shooter (`Tuning::walk_receivers`), each shooter's.
pub(crate) struct Squares {
    /// Points (centre, side) or two triangles each (corner, 0).
    mesh: Mesh,
    vertices: Vec<f32>,
    cover: Cover,
    /// Each run's vertex range (first, count), in the order built.
    runs: Vec<(i32, i32)>,
    /// How many texels the squares cover.
    texels: usize,
    /// Largest square side drawn, texels (a power of two, at least `BLOCK`).
    largest: u32,
    /// Whether the driver's points are large enough for a block.
    points_fit: bool,
    /// Whether the last squares were built as points.
    as_points: bool,
    /// The viewport: the atlas rounded up to whole largest squares, so that every square's
    /// centre lies inside it (a point whose centre is clipped away draws nothing); the scissor
    /// keeps fragments inside the atlas.
    pub(crate) viewport: (i32, i32),
}

impl Squares {
    /// Squares over an atlas of `width` × `height` texels.
    pub(crate) fn new(gl: &Gl, width: i32, height: i32) -> Result<Self, GlError> {
        let mesh = Mesh::new(gl, &[], 3, &ATLAS_VERTEX)?;
        let mut point_range = [0.0f32; 2];
        unsafe { gl.get_parameter_f32_slice(glow::ALIASED_POINT_SIZE_RANGE, &mut point_range) };
        let points_fit = point_range[1] >= BLOCK as f32;
        let largest = if points_fit {
            let fits = 1u32 << (point_range[1] as u32).ilog2();
            fits.clamp(BLOCK, LARGEST_SQUARE)
        } else {
            LARGEST_SQUARE
        };
        let round_up = |t: i32| (t as u32).div_ceil(largest) as i32 * largest as i32;
        Ok(Squares {
            mesh,
            vertices: Vec::new(),
            cover: Cover::default(),
            runs: Vec::new(),
            texels: 0,
            largest,
            points_fit,
            as_points: points_fit,
            viewport: (round_up(width), round_up(height)),
        })
    }

    /// Cover, one run after another, the blocks (`masks`: one per block, rows of `wide` blocks)
    /// whose mask has bit r, for each r below `runs`, as points when `points` asks and the driver
    /// allows, and upload them.
    pub(crate) fn build(&mut self, masks: &[u32], wide: usize, points: bool, runs: usize) {
        self.as_points = points && self.points_fit;
        self.vertices.clear();
        self.runs.clear();
        let (size, points) = (self.viewport, self.as_points);
        let vertices = &mut self.vertices;
        let texels = &mut self.texels;
        *texels = 0;
        self.cover.pyramid(masks, wide, self.largest);
        for r in 0..runs {
            let first = vertices.len() as i32 / 3;
            self.cover.squares(r, |x, y, side| {
                *texels += (side * side) as usize;
                push_square(vertices, points, size, x, y, side)
            });
            self.runs.push((first, vertices.len() as i32 / 3 - first));
        }
        self.mesh.replace(&self.vertices, 3);
    }

    /// Whether the last squares were built as points.
    pub(crate) fn as_points(&self) -> bool {
        self.as_points
    }

    /// The primitive they are drawn with.
    pub(crate) fn mode(&self) -> u32 {
        if self.as_points {
            glow::POINTS
        } else {
            glow::TRIANGLES
        }
    }

    /// The vertex range (first, count) of run `k` of the last `build` (none: empty).
    pub(crate) fn run(&self, k: usize) -> (i32, i32) {
        self.runs.get(k).copied().unwrap_or((0, 0))
    }

    /// Draw every square (the marking pass, for all shooters at once).
    pub(crate) fn draw_all(&self) {
        self.draw(0, self.mesh.vertex_count);
    }

    pub(crate) fn draw(&self, first: i32, count: i32) {
        self.mesh.draw_arrays(self.mode(), first, count);
    }

    /// How many texels the last pass's squares covered.
    pub(crate) fn texels(&self) -> usize {
        self.texels
    }

    /// How many squares the last pass drew with the clipping shader and with the other (run 1;
    /// every other run clips).
    pub(crate) fn drawn(&self) -> (usize, usize) {
        let per_square = if self.as_points { 1 } else { 6 };
        let above = self.run(1).1 as usize / per_square;
        let all = self.mesh.vertex_count as usize / per_square;
        (all - above, above)
    }
}

/// Set the viewport and scissor for `squares` over an atlas of `size` texels (and points of any
/// size, if drawn as points).
pub(crate) fn begin_squares(ctx: &GlContext, squares: &Squares, size: (i32, i32)) {
    let gl = &ctx.gl;
    unsafe {
        let (w, h) = squares.viewport;
        gl.viewport(0, 0, w, h);
        gl.enable(glow::SCISSOR_TEST);
        gl.scissor(0, 0, size.0, size.1);
        if squares.as_points() {
            gl.enable(glow::PROGRAM_POINT_SIZE);
        }
    }
}

/// Undo `begin_squares` (and a marking pass's depth test).
pub(crate) fn end_squares(ctx: &GlContext) {
    let gl = &ctx.gl;
    unsafe {
        gl.disable(glow::PROGRAM_POINT_SIZE);
        gl.disable(glow::DEPTH_TEST);
        gl.disable(glow::SCISSOR_TEST);
        gl.active_texture(glow::TEXTURE0);
    }
}

/// The vertices of square (`x`, `y`, `side`, texels) in a viewport of `size` texels: one point
/// (centre, side) or two triangles (corner, 0).
fn push_square(vertices: &mut Vec<f32>, points: bool, size: (i32, i32), x: u32, y: u32, side: u32) {
    let ndc = |t: u32, extent: i32| t as f32 / extent as f32 * 2.0 - 1.0;
    if points {
        // A point's centre; an even-sided point covers the pixels centred within side/2.
        let (cx, cy) = (ndc(x * 2 + side, size.0 * 2), ndc(y * 2 + side, size.1 * 2));
        vertices.extend_from_slice(&[cx, cy, side as f32]);
    } else {
        let (x0, y0) = (ndc(x, size.0), ndc(y, size.1));
        let (x1, y1) = (ndc(x + side, size.0), ndc(y + side, size.1));
        for [u, v] in [[x0, y0], [x1, y0], [x1, y1], [x0, y0], [x1, y1], [x0, y1]] {
            vertices.extend_from_slice(&[u, v, 0.0]);
        }
    }
}

/// Covers blocks with squares (see `Cover::squares`); keeps its scratch space between passes.
#[derive(Default)]
struct Cover {
    /// Per level of squares (1, 2, 4, … blocks a side), per square: the OR and the AND of the
    /// masks of its blocks inside the grid.
    pyramid: Vec<Vec<(u32, u32)>>,
    /// The grid's blocks across and up.
    wide: usize,
    high: usize,
    stack: Vec<(usize, usize, usize)>,
}

impl Cover {
    /// Prepare to cover the blocks of `masks` (rows of `wide` blocks) with squares of at most
    /// `largest` texels: one pass over the blocks builds each square's OR and AND of masks, and
    /// every `squares` then only descends where its bit is set (a pass shooter by shooter
    /// covers eighteen sets of blocks).
    fn pyramid(&mut self, masks: &[u32], wide: usize, largest: u32) {
        self.wide = wide;
        self.high = masks.len() / wide.max(1);
        let top = (largest / BLOCK).max(1).ilog2() as usize;
        self.pyramid.resize_with(top + 1, Vec::new);
        self.pyramid.truncate(top + 1);
        self.pyramid[0].clear();
        self.pyramid[0].extend(masks.iter().map(|&m| (m, m)));
        for level in 1..=top {
            let (w, h) = self.size(level);
            let (below_w, below_h) = self.size(level - 1);
            let (done, rest) = self.pyramid.split_at_mut(level);
            let (below, here) = (&done[level - 1], &mut rest[0]);
            here.clear();
            here.resize(w * h, (0, u32::MAX));
            for y in 0..below_h {
                for x in 0..below_w {
                    let (any, all) = below[y * below_w + x];
                    let up = &mut here[(y / 2) * w + x / 2];
                    *up = (up.0 | any, up.1 & all);
                }
            }
        }
    }

    /// The squares across and up at `level` (2^level blocks a side).
    fn size(&self, level: usize) -> (usize, usize) {
        (
            self.wide.div_ceil(1 << level),
            self.high.div_ceil(1 << level),
        )
    }

    /// Cover the blocks of the last `pyramid` whose mask has bit `bit` with aligned squares of
    /// whole blocks, each block exactly once: `emit(x, y, side)` in texels. A square is split
    /// into its four quarters unless all of its blocks inside the grid have the bit.
    fn squares(&mut self, bit: usize, mut emit: impl FnMut(u32, u32, u32)) {
        let Some(bit) = 1u32.checked_shl(bit as u32) else {
            return;
        };
        let top = self.pyramid.len() - 1;
        let (w, h) = self.size(top);
        for y in 0..h {
            for x in 0..w {
                self.stack.push((x, y, top));
                while let Some((x, y, level)) = self.stack.pop() {
                    let (any, all) = self.pyramid[level][y * self.size(level).0 + x];
                    if any & bit == 0 {
                        continue;
                    }
                    if all & bit != 0 {
                        let t = |b: usize| (b << level) as u32 * BLOCK;
                        emit(t(x), t(y), BLOCK << level);
                        continue;
                    }
                    // Not all set: not a single block, so there are quarters.
                    let (cw, ch) = self.size(level - 1);
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let (cx, cy) = (2 * x + dx, 2 * y + dy);
                        if cx < cw && cy < ch {
                            self.stack.push((cx, cy, level - 1));
                        }
                    }
                }
            }
        }
    }
}

/// Per polygon, the blocks (indices in rows of `wide`) that hold its patches, ascending, one
/// list after another, and where each polygon's list starts (one more entry than polygons).
pub(crate) fn patch_blocks(layout: &PatchLayout, wide: usize) -> (Vec<u32>, Vec<usize>) {
    let width = layout.atlas_width as usize;
    let b = BLOCK as usize;
    // (polygon, block) of every patch texel; `owner` is the polygon ID + 1, 0 for no patch.
    let mut pairs: Vec<(u32, u32)> = (layout.owner.iter().enumerate())
        .filter(|&(_, &o)| o != 0)
        .map(|(i, &o)| (o - 1, ((i / width / b) * wide + i % width / b) as u32))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    let polygons = layout.patches_per_polygon.len();
    let mut starts = vec![0; polygons + 1];
    for &(p, _) in &pairs {
        starts[p as usize + 1] += 1;
    }
    for p in 0..polygons {
        starts[p + 1] += starts[p];
    }
    (pairs.into_iter().map(|(_, block)| block).collect(), starts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patches::Resolution;
    use crate::scene::bundled;
    use std::collections::BTreeSet;

    #[test]
    fn cover_draws_every_set_block_once_and_nothing_else() {
        // 37 x 23 blocks (not a multiple of any square), three sets of blocks as three bits of
        // the masks: a pseudo-random pattern with solid patches, so that squares of every size
        // appear, and two others.
        let (wide, high) = (37usize, 23usize);
        let masks: Vec<u32> = (0..wide * high)
            .map(|i| {
                let (x, y) = (i % wide, i / wide);
                ((x < 20 && y < 17 || (x * 7 + y * 13) % 5 < 2) as u32)
                    | (((x * 7 + y * 13) % 5 < 2) as u32) << 1
                    | ((x % 3 == 0) as u32) << 2
            })
            .collect();
        let mut cover = Cover::default();
        cover.pyramid(&masks, wide, LARGEST_SQUARE);
        for bit in 0..3 {
            let mut drawn = vec![0u32; masks.len()];
            let mut sides = std::collections::BTreeSet::new();
            cover.squares(bit, |x, y, side| {
                assert!(
                    x % side == 0 && y % side == 0,
                    "bit {bit}: square {x},{y} side {side} unaligned"
                );
                sides.insert(side);
                let b = |t: u32| (t / BLOCK) as usize;
                for by in b(y)..b(y + side).min(high) {
                    for bx in b(x)..b(x + side).min(wide) {
                        drawn[by * wide + bx] += 1;
                    }
                }
            });
            for (i, (&m, &n)) in masks.iter().zip(&drawn).enumerate() {
                let set = m >> bit & 1;
                assert_eq!(n, set, "bit {bit}, block {i}: set {set}, drawn {n} times");
            }
            if bit == 0 {
                assert!(sides.len() >= 3, "sides used: {sides:?}");
            }
        }
    }

    #[test]
    fn a_square_as_a_point_or_two_triangles_covers_the_same_texels() {
        // A 16-texel square at (8, 4) in a 64 × 32 viewport: the point's centre is the triangles'
        // centre, its size their side.
        let (mut point, mut triangles) = (Vec::new(), Vec::new());
        push_square(&mut point, true, (64, 32), 8, 4, 16);
        push_square(&mut triangles, false, (64, 32), 8, 4, 16);
        assert_eq!(point.len(), 3);
        assert_eq!(triangles.len(), 18);
        let corners: Vec<[f32; 2]> = triangles.chunks(3).map(|v| [v[0], v[1]]).collect();
        let (lo, hi) = (corners[0], corners[2]);
        assert_eq!(point[0], 0.5 * (lo[0] + hi[0]));
        assert_eq!(point[1], 0.5 * (lo[1] + hi[1]));
        assert_eq!(point[2], 16.0);
        assert_eq!((hi[0] - lo[0]) * 64.0 / 2.0, 16.0);
    }

    #[test]
    fn each_polygon_lists_exactly_the_blocks_that_hold_its_patches() {
        let (mut listed, mut in_rectangles) = (0, 0);
        for scene in &bundled::ALL {
            let scene = scene.load().unwrap();
            let layout = PatchLayout::new(&scene, Resolution::Patches(4096)).without_gutters();
            let wide = layout.atlas_width.div_ceil(BLOCK) as usize;
            let (blocks, starts) = patch_blocks(&layout, wide);
            let (width, b) = (layout.atlas_width as usize, BLOCK as usize);
            for (p, [x0, y0, x1, y1]) in layout.texel_rects().into_iter().enumerate() {
                let mine = &blocks[starts[p]..starts[p + 1]];
                let expected: BTreeSet<u32> = (layout.owner.iter().enumerate())
                    .filter(|&(_, &o)| o == p as u32 + 1)
                    .map(|(i, _)| ((i / width) / b * wide + (i % width) / b) as u32)
                    .collect();
                assert_eq!(
                    mine,
                    expected.into_iter().collect::<Vec<_>>(),
                    "polygon {p}"
                );
                listed += mine.len();
                if layout.patches_per_polygon[p] > 0 {
                    let (bx, by) = (
                        x1.div_ceil(BLOCK) - x0 / BLOCK,
                        y1.div_ceil(BLOCK) - y0 / BLOCK,
                    );
                    in_rectangles += (bx * by) as usize;
                }
            }
        }
        // The bundled scenes' lightmaps fill their rectangles' blocks.
        assert_eq!(listed, in_rectangles);
    }

    #[test]
    fn a_concave_polygon_lists_fewer_blocks_than_its_rectangle() {
        // An L-shaped floor of three unit squares, merged into one polygon, under a small light:
        // a quarter of its rectangle holds no patch.
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path();
        std::fs::write(
            dir.join("l.mtl"),
            "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl light\nKd 0 0 0\nKe 1 1 1\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("l.obj"),
            "mtllib l.mtl\nv 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 0 1\nv 1 0 1\nv 2 0 1\nv 0 0 2\n\
             v 1 0 2\nv 0.4 1 0.4\nv 0.6 1 0.4\nv 0.6 1 0.6\nv 0.4 1 0.6\nusemtl floor\n\
             f 1 4 5 2\nf 2 5 6 3\nf 4 7 8 5\nusemtl light\nf 9 10 11 12\n",
        )
        .unwrap();
        let scene = crate::scene::load_obj(&dir.join("l.obj")).unwrap();
        assert_eq!(scene.polygons.len(), 2, "the L merged into one polygon");
        let layout = PatchLayout::new(&scene, Resolution::Patches(4096)).without_gutters();
        let wide = layout.atlas_width.div_ceil(BLOCK) as usize;
        let (_, starts) = patch_blocks(&layout, wide);
        let floor = (0..2)
            .max_by_key(|&p| layout.patches_per_polygon[p])
            .unwrap();
        let [x0, y0, x1, y1] = layout.texel_rects()[floor];
        let rectangle = (x1.div_ceil(BLOCK) - x0 / BLOCK) * (y1.div_ceil(BLOCK) - y0 / BLOCK);
        let listed = starts[floor + 1] - starts[floor];
        // Three quarters of the rectangle, give or take the blocks along the inner edges.
        let share = listed as f64 / rectangle as f64;
        assert!(
            (0.7..0.85).contains(&share),
            "{listed} of {rectangle} blocks"
        );
    }
}
