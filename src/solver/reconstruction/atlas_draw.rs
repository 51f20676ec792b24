//! What a reconstruction pass draws and with which program: the interface ([`AtlasDraw`]) and
//! the paper's way, every patch of the atlas with the one program ([`WholeAtlas`]). The llvmpipe
//! engine's (`solver::engine::marked_squares`) draws only the receivers' blocks, after a
//! marking pass, with programs for fewer shooters where it can.
//!
//! Either way the atlas is drawn as aligned squares of whole 4×4 texel blocks (`cover.rs`)
//! over the blocks that hold patches: a texel outside every patch stays as the clear left it.

use super::cover::{Squares, BLOCK};
use super::patch_data::PolygonPlanes;
use super::programs::Programs;
use super::uniforms::Uniforms;
use crate::gl::{Gl, GlContext, GlError, Renderbuffer};
use crate::patches::PatchLayout;
use crate::solver::visibility::VisibilityPass;
use crate::solver::{Shooter, SolveOptions};
use glow::HasContext;
use std::any::Any;

/// What one reconstruction pass hands its draw: the programs, the uniforms of every slot, and
/// what they were made from.
pub(crate) struct Pass<'a> {
    /// The pass's programs (the paper's and the emission).
    pub programs: &'a Programs,
    /// The uniforms of every slot of the programs (`shooters` and idle ones after them).
    pub uniforms: &'a Uniforms<'a>,
    /// The pass's shooters, one per item buffer of `visibility`.
    pub shooters: &'a [Shooter],
    /// The solve's options (for uniforms of fewer shooters).
    pub options: &'a SolveOptions,
    /// The polygons' planes (for uniforms of fewer shooters).
    pub planes: &'a PolygonPlanes,
    /// The item buffers.
    pub visibility: &'a VisibilityPass,
    /// Whether every shooter is a quadrilateral and the programs have the variant for them.
    pub quad: bool,
    /// The atlas's width and height, texels.
    pub size: (i32, i32),
}

/// What a reconstruction pass draws and with which program: the whole atlas with the paper's
/// program ([`WholeAtlas`]), or the llvmpipe engine's marked squares.
pub(crate) trait AtlasDraw: Any {
    /// A depth buffer the size of the atlas for the pass's FBO, if the draws test depth (the
    /// engine's marking pass); the paper's draw has none.
    fn depth(&self) -> Option<&Renderbuffer> {
        None
    }

    /// Choose what the pass for `shooters` draws; `touched` gets the polygons it draws
    /// (receivers and shooters). Whether it writes every texel of the atlas, so that the
    /// renderbuffers can be cleared first.
    fn select(
        &mut self,
        shooters: &[Shooter],
        visibility: &VisibilityPass,
        touched: &mut Vec<usize>,
    ) -> bool;

    /// Draw it into the bound renderbuffers, every texture on its unit.
    fn draw(&mut self, ctx: &GlContext, pass: &Pass);

    /// Take the unshot atlas read back after a shot (or after the emission); the paper's draw
    /// does not look.
    fn observe(&mut self, _unshot: &[f32]) {}

    /// The squares the last pass drew (the pass proper's).
    fn squares(&self) -> &Squares;

    /// This draw as `Any`, for the engine to find its own.
    fn as_any(&self) -> &dyn Any;
}

/// The paper's draw: every patch of the atlas, each pass, with the paper's program.
pub(crate) struct WholeAtlas {
    squares: Squares,
    /// The blocks that hold patches of polygon p: `blocks[block_starts[p]..block_starts[p + 1]]`.
    blocks: Vec<u32>,
    block_starts: Vec<usize>,
    /// The polygons that have patches.
    with_patches: Vec<usize>,
    /// Per 4×4 block of the atlas, row by row, 1 if the pass draws it.
    drawn: Vec<u32>,
    blocks_wide: usize,
}

impl WholeAtlas {
    /// The draw for an atlas laid out as `layout`.
    pub fn new(gl: &Gl, layout: &PatchLayout) -> Result<Self, GlError> {
        let (width, height) = (layout.atlas_width as i32, layout.atlas_height as i32);
        let blocks_wide = layout.atlas_width.div_ceil(BLOCK) as usize;
        let (blocks, block_starts) = patch_blocks(layout, blocks_wide);
        Ok(WholeAtlas {
            squares: Squares::new(gl, width, height)?,
            blocks,
            block_starts,
            with_patches: (0..layout.patches_per_polygon.len())
                .filter(|&p| layout.patches_per_polygon[p] > 0)
                .collect(),
            drawn: vec![0; blocks_wide * layout.atlas_height.div_ceil(BLOCK) as usize],
            blocks_wide,
        })
    }
}

impl AtlasDraw for WholeAtlas {
    /// Every polygon with patches receives; the shooting texels are drawn too, to clear their
    /// unshot energy.
    fn select(
        &mut self,
        shooters: &[Shooter],
        _visibility: &VisibilityPass,
        touched: &mut Vec<usize>,
    ) -> bool {
        touched.clear();
        self.drawn.fill(0);
        for &p in &self.with_patches {
            touched.push(p);
            for &b in &self.blocks[self.block_starts[p]..self.block_starts[p + 1]] {
                self.drawn[b as usize] = 1;
            }
        }
        for s in shooters {
            let [x0, y0, x1, y1] = s.texels;
            for by in y0 / BLOCK..y1.div_ceil(BLOCK) {
                let row = by as usize * self.blocks_wide;
                let blocks = row + (x0 / BLOCK) as usize..row + x1.div_ceil(BLOCK) as usize;
                self.drawn[blocks].fill(1);
            }
            if !touched.contains(&s.polygon) {
                touched.push(s.polygon);
            }
        }
        self.squares.build(&self.drawn, self.blocks_wide, false, 1);
        true
    }

    fn draw(&mut self, ctx: &GlContext, pass: &Pass) {
        begin_squares(ctx, &self.squares, pass.size);
        let (first, count) = self.squares.run(0);
        if count > 0 {
            pass.uniforms.set(pass.programs.paper.get(pass.quad));
            self.squares.draw(first, count);
        }
        end_squares(ctx);
    }

    fn squares(&self) -> &Squares {
        &self.squares
    }

    fn as_any(&self) -> &dyn Any {
        self
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
