//! Reconstruction pass (paper 3.2.2): every receiver drawn orthographically onto its lightmap
//! texels, into an FBO whose colour attachments are *renderbuffers* the size of the atlas. The
//! fragment shader tests visibility against the item buffer and computes the form factor and the
//! received energy; the results are copied into the lightmap textures with glCopyTexSubImage2D.
//!
//! The receivers are rasterised once, at initialisation, into atlas textures holding each patch's
//! position, normal and reflectance (`glsl/patchdata.frag`); every pass then draws squares of
//! whole 4×4 texel blocks covering the lightmaps of the receivers (`cover`) and reads them.
//! llvmpipe runs the whole shader on every block a primitive touches (its discards and branches
//! skip nothing), so the cost of a pass is the number of blocks drawn: the solver's atlas has no
//! gutters (`PatchLayout::without_gutters`) and each block is drawn once. Only receivers that can
//! get anything are covered: some of the polygon in front of the shooter and some of the shooter
//! in front of the polygon (the rest would add exactly zero, and do where a square reaches them),
//! plus the shooter, whose unshot energy is cleared. The renderbuffers are never cleared after
//! initialisation, so the texels not drawn keep what the last copy put into the textures: each
//! copy still moves a whole, current atlas.
//!
//! Two attachments: 0 = radiosity + ΔL, 1 = unshot + ΔL (the shooter's own unshot cleared).
//! The paper adds with GL_ADD while copying; a copy cannot add, so the shader adds the old value
//! it reads from the texture, and the copy replaces the texture with the sum: same result.

use super::mesh::ATTRIBUTES;
use super::visibility::VisibilityPass;
use super::{FormFactorKind, Shooter, SolveOptions, VisibilityKind};
use crate::gl::objects::Attribute;
use crate::gl::{
    Framebuffer, GlContext, GlError, Mesh, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::glsl;
use crate::patches::PatchLayout;
use crate::scene::Scene;
use glam::Vec3;
use glow::HasContext;

pub const NAME: &str = "reconstruction";
pub const INIT_NAME: &str = "initialisation";
pub const COPY_NAME: &str = "accumulation";

/// The two lightmap atlases of section 3.1: accumulated and unshot radiance (RGBA32F, alpha =
/// polygon ID + 1), which the reconstruction pass reads and its copies replace.
pub struct Lightmaps {
    pub radiosity: Texture,
    pub unshot: Texture,
}

impl Lightmaps {
    pub fn new(ctx: &GlContext, width: i32, height: i32) -> Result<Self, GlError> {
        let make = || {
            Texture::new(
                &ctx.gl,
                width,
                height,
                TextureFormat::Rgba32F,
                glow::NEAREST,
            )
        };
        Ok(Lightmaps {
            radiosity: make()?,
            unshot: make()?,
        })
    }
}

/// Each patch's geometry as atlas textures (RGBA32F): position + polygon ID + 1, normal, Kd.
struct PatchData {
    program: Program,
    position: Texture,
    normal: Texture,
    reflectance: Texture,
    fbo: Framebuffer,
}

pub struct ReconstructionPass {
    program: Program,
    /// Each polygon's plane (unit normal n, n·x of its points), texel ID at (ID % width, ID /
    /// width): the robust visibility test asks whether the polygon a pixel shows lies between
    /// the shooter and the receiver.
    planes: Texture,
    /// World units a point must lie beyond a plane to count as behind it (float noise: 1e-5 of
    /// the scene's size; the rooms' thinnest gap, a sheet of paper on a desk, is 1 mm in 7 m).
    plane_slack: f32,
    emission: Program,
    patches: PatchData,
    /// The squares a pass draws (rebuilt every pass): points (centre, side) or two triangles
    /// each (corner, 0).
    squares: Mesh,
    square_vertices: Vec<f32>,
    /// Which 4×4 blocks of the atlas hold a receiver this pass, row by row.
    blocks: Vec<bool>,
    blocks_wide: usize,
    /// Largest square side drawn, texels (a power of two, at least `BLOCK`).
    largest_square: u32,
    /// Squares drawn as points (llvmpipe rasterises a point's square in one piece) or, where the
    /// implementation's points are too small, as triangle pairs.
    pub squares_as_points: bool,
    /// The viewport: the atlas rounded up to whole largest squares, so that every square's
    /// centre lies inside it (a point whose centre is clipped away draws nothing); the scissor
    /// keeps fragments inside the atlas.
    viewport: (i32, i32),
    /// The polygons that have patches (the others have no lightmap texels to draw).
    with_patches: Vec<usize>,
    /// Lightmap rectangles [x0, y0, x1, y1), per polygon.
    texels: Vec<[u32; 4]>,
    /// The polygons the last pass drew (receivers and the shooter): the only ones whose unshot
    /// energy it can have changed.
    pub touched: Vec<usize>,
    /// Each polygon's vertices (`outlines[starts[i]..starts[i + 1]]`) and normal, to tell which
    /// can receive from a shooter.
    outlines: Vec<Vec3>,
    starts: Vec<usize>,
    normals: Vec<Vec3>,
    _radiosity_rb: Renderbuffer,
    _unshot_rb: Renderbuffer,
    fbo: Framebuffer,
    width: i32,
    height: i32,
}

impl ReconstructionPass {
    pub fn new(ctx: &GlContext, scene: &Scene, layout: &PatchLayout) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let (width, height) = (layout.atlas_width as i32, layout.atlas_height as i32);
        let planes = polygon_planes(ctx, scene)?;
        let (lo, hi) = scene.bounds();
        let plane_slack = 1e-5 * (hi - lo).length();
        let outputs = &[(0, "NewRadiosity"), (1, "NewUnshot")];
        let program = Program::new(
            gl,
            glsl!("atlas.vert"),
            glsl!("reconstruct.frag"),
            &[(0, "Corner"), (1, "Size")],
            outputs,
        )?;
        let texels = layout.texel_rects();
        let with_patches: Vec<usize> = (0..texels.len())
            .filter(|&p| layout.patches_per_polygon[p] > 0)
            .collect();
        let squares = Mesh::new(
            gl,
            &[],
            3,
            &[
                Attribute {
                    location: 0,
                    size: 2,
                    offset: 0,
                },
                Attribute {
                    location: 1,
                    size: 1,
                    offset: 2,
                },
            ],
        )?;
        let mut point_range = [0.0f32; 2];
        unsafe { gl.get_parameter_f32_slice(glow::ALIASED_POINT_SIZE_RANGE, &mut point_range) };
        let squares_as_points = point_range[1] >= BLOCK as f32;
        let largest_square = if squares_as_points {
            let fits = 1u32 << (point_range[1] as u32).ilog2();
            fits.clamp(BLOCK, LARGEST_SQUARE)
        } else {
            LARGEST_SQUARE
        };
        let round_up = |t: i32| (t as u32).div_ceil(largest_square) as i32 * largest_square as i32;
        let blocks_wide = (width as u32).div_ceil(BLOCK) as usize;
        let blocks = vec![false; blocks_wide * (height as u32).div_ceil(BLOCK) as usize];
        let mut starts = vec![0];
        let mut outlines = Vec::new();
        for p in &scene.polygons {
            outlines.extend_from_slice(&p.vertices);
            starts.push(outlines.len());
        }
        let normals = scene.polygons.iter().map(|p| p.normal).collect();
        let make = || Texture::new(gl, width, height, TextureFormat::Rgba32F, glow::NEAREST);
        let patches = PatchData {
            program: Program::new(
                gl,
                glsl!("lightmap.vert"),
                glsl!("patchdata.frag"),
                ATTRIBUTES,
                &[
                    (0, "PatchPosition"),
                    (1, "PatchNormal"),
                    (2, "PatchReflectance"),
                ],
            )?,
            position: make()?,
            normal: make()?,
            reflectance: make()?,
            fbo: Framebuffer::new(gl)?,
        };
        patches
            .fbo
            .attach_texture(glow::COLOR_ATTACHMENT0, &patches.position);
        patches
            .fbo
            .attach_texture(glow::COLOR_ATTACHMENT1, &patches.normal);
        patches
            .fbo
            .attach_texture(glow::COLOR_ATTACHMENT2, &patches.reflectance);
        patches.fbo.check_complete(INIT_NAME)?;
        let emission = Program::new(
            gl,
            glsl!("lightmap.vert"),
            glsl!("emission.frag"),
            ATTRIBUTES,
            outputs,
        )?;
        let radiosity_rb = Renderbuffer::new(gl, glow::RGBA32F, width, height)?;
        let unshot_rb = Renderbuffer::new(gl, glow::RGBA32F, width, height)?;
        let fbo = Framebuffer::new(gl)?;
        fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT0, &radiosity_rb);
        fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT1, &unshot_rb);
        fbo.check_complete(NAME)?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(NAME)?;
        Ok(ReconstructionPass {
            program,
            planes,
            plane_slack,
            emission,
            patches,
            squares,
            square_vertices: Vec::new(),
            blocks,
            blocks_wide,
            largest_square,
            squares_as_points,
            viewport: (round_up(width), round_up(height)),
            with_patches,
            texels,
            touched: Vec::new(),
            outlines,
            starts,
            normals,
            _radiosity_rb: radiosity_rb,
            _unshot_rb: unshot_rb,
            fbo,
            width,
            height,
        })
    }

    /// Bind the renderbuffers' FBO; `clear` zeroes them (initialisation only).
    fn begin(&self, ctx: &GlContext, clear: bool) {
        Self::target(
            ctx,
            &self.fbo,
            &[glow::COLOR_ATTACHMENT0, glow::COLOR_ATTACHMENT1],
            self.width,
            self.height,
            clear,
        );
    }

    /// Bind `fbo` for drawing flat into the atlas: its `buffers`, no depth, blending, culling
    /// or scissor; `clear` zeroes it (texels that are no patch stay zero: alpha 0, no polygon).
    fn target(
        ctx: &GlContext,
        fbo: &Framebuffer,
        buffers: &[u32],
        width: i32,
        height: i32,
        clear: bool,
    ) {
        let gl = &ctx.gl;
        fbo.bind();
        unsafe {
            gl.viewport(0, 0, width, height);
            gl.draw_buffers(buffers);
            gl.disable(glow::DEPTH_TEST);
            gl.disable(glow::BLEND);
            gl.disable(glow::CULL_FACE);
            gl.disable(glow::SCISSOR_TEST);
            if clear {
                gl.clear_color(0.0, 0.0, 0.0, 0.0);
                gl.clear(glow::COLOR_BUFFER_BIT);
            }
        }
    }

    /// Can polygon `p` receive anything from `shooter`? Some of it must lie in front of the
    /// shooter and some of the shooter in front of it (with float slack: never wrongly no).
    fn can_receive(&self, p: usize, shooter: &Shooter) -> bool {
        let outline = &self.outlines[self.starts[p]..self.starts[p + 1]];
        let slack = self.plane_slack;
        let base = shooter.corners[0];
        let in_front = outline
            .iter()
            .any(|&v| shooter.normal.dot(v - base) > -slack);
        let n = self.normals[p];
        let sees = shooter.corners[..shooter.corner_count.max(1)]
            .iter()
            .chain(std::iter::once(&shooter.position))
            .any(|&c| n.dot(c - outline[0]) > -slack);
        in_front && sees
    }

    /// Rasterise every patch's geometry into the patch textures, then write each patch's emitted
    /// radiance (and its polygon ID in alpha) into both attachments.
    pub fn emit(&self, ctx: &GlContext, mesh: &Mesh) -> Result<(), GlError> {
        Self::target(
            ctx,
            &self.patches.fbo,
            &[
                glow::COLOR_ATTACHMENT0,
                glow::COLOR_ATTACHMENT1,
                glow::COLOR_ATTACHMENT2,
            ],
            self.width,
            self.height,
            true,
        );
        self.patches.program.use_program();
        mesh.draw();
        ctx.check(INIT_NAME)?;
        self.begin(ctx, true);
        self.emission.use_program();
        mesh.draw();
        ctx.check(INIT_NAME)
    }

    /// The receivers to draw for `shooter`: the lightmaps of the polygons that can receive (and
    /// the shooter's), covered by aligned squares of whole 4×4 blocks (`cover`).
    fn select_receivers(&mut self, shooter: &Shooter) {
        self.touched.clear();
        self.blocks.fill(false);
        let bw = self.blocks_wide;
        for k in 0..self.with_patches.len() {
            let p = self.with_patches[k];
            if p != shooter.polygon && !self.can_receive(p, shooter) {
                continue;
            }
            self.touched.push(p);
            let [x0, y0, x1, y1] = self.texels[p];
            for by in y0 / BLOCK..y1.div_ceil(BLOCK) {
                let row = by as usize * bw;
                self.blocks[row + (x0 / BLOCK) as usize..row + x1.div_ceil(BLOCK) as usize]
                    .fill(true);
            }
        }
        self.square_vertices.clear();
        let size = self.viewport;
        let points = self.squares_as_points;
        cover(&self.blocks, bw, self.largest_square, |x, y, side| {
            let ndc = |t: u32, extent: i32| t as f32 / extent as f32 * 2.0 - 1.0;
            if points {
                // A point's centre; an even-sided point covers the pixels centred within side/2.
                let (cx, cy) = (ndc(x * 2 + side, size.0 * 2), ndc(y * 2 + side, size.1 * 2));
                self.square_vertices
                    .extend_from_slice(&[cx, cy, side as f32]);
            } else {
                let (x0, y0) = (ndc(x, size.0), ndc(y, size.1));
                let (x1, y1) = (ndc(x + side, size.0), ndc(y + side, size.1));
                for [u, v] in [[x0, y0], [x1, y0], [x1, y1], [x0, y0], [x1, y1], [x0, y1]] {
                    self.square_vertices.extend_from_slice(&[u, v, 0.0]);
                }
            }
        });
        self.squares.replace(&self.square_vertices, 3);
    }

    /// One reconstruction: ΔL for every patch from `shooter`, added to `radiosity` and `unshot`
    /// (read as textures) into the two renderbuffers.
    pub fn run(
        &mut self,
        ctx: &GlContext,
        visibility: &VisibilityPass,
        lightmaps: &Lightmaps,
        shooter: &Shooter,
        options: &SolveOptions,
    ) -> Result<(), GlError> {
        self.select_receivers(shooter);
        self.begin(ctx, false);
        self.program.use_program();
        visibility.item_buffer.bind(0);
        self.planes.bind(3);
        lightmaps.radiosity.bind(1);
        lightmaps.unshot.bind(2);
        self.patches.position.bind(4);
        self.patches.normal.bind(5);
        self.patches.reflectance.bind(6);
        self.program.set_i32("PatchPosition", 4);
        self.program.set_i32("PatchNormal", 5);
        self.program.set_i32("PatchReflectance", 6);
        self.program.set_i32("HemiItemBuffer", 0);
        self.program.set_i32("Radiosity", 1);
        self.program.set_i32("Unshot", 2);
        self.program
            .set_mat4("ShooterView", &shooter.view().to_cols_array());
        self.program
            .set_vec3("ShootPos", shooter.position.to_array());
        self.program
            .set_vec3("ShootNormal", shooter.normal.to_array());
        self.program
            .set_vec3("ShootEnergy", shooter.energy.to_array());
        self.program.set_f32("ShooterId", shooter.polygon as f32);
        self.program
            .set_vec4("ShooterTexels", shooter.texels.map(|v| v as f32));
        let p = &self.program;
        p.set_i32(
            "FormFactorKind",
            (options.form_factor == FormFactorKind::Polygon) as i32,
        );
        let corners: Vec<f32> = shooter.corners.iter().flat_map(|c| c.to_array()).collect();
        p.set_vec3_array("ShootCorners", &corners);
        p.set_i32("ShootCornerCount", shooter.corner_count as i32);
        p.set_f32("ShootArea", shooter.area);
        p.set_i32(
            "HemiCube",
            (options.visibility == VisibilityKind::Hemicube) as i32,
        );
        p.set_i32("Robust", options.robust_visibility as i32);
        p.set_i32("PolygonPlanes", 3);
        p.set_i32("PlanesWidth", self.planes.width);
        p.set_f32("PlaneSlack", self.plane_slack);
        unsafe {
            let gl = &ctx.gl;
            gl.viewport(0, 0, self.viewport.0, self.viewport.1);
            gl.enable(glow::SCISSOR_TEST);
            gl.scissor(0, 0, self.width, self.height);
            if self.squares_as_points {
                gl.enable(glow::PROGRAM_POINT_SIZE);
                self.squares.draw_points();
                gl.disable(glow::PROGRAM_POINT_SIZE);
            } else {
                self.squares.draw();
            }
            gl.disable(glow::SCISSOR_TEST);
            gl.active_texture(glow::TEXTURE0);
        }
        ctx.check(NAME)
    }

    /// Each polygon's lightmap rectangle [x0, y0, x1, y1) in the atlas.
    pub fn texels(&self) -> &[[u32; 4]] {
        &self.texels
    }

    /// Read the new unshot atlas (attachment 1) for Find_Max_Energy.
    pub fn read_unshot(&self, out: &mut Vec<f32>) {
        self.fbo
            .read_f32(glow::COLOR_ATTACHMENT1, self.width, self.height, out);
    }

    /// The paper's accumulation: glCopyTexSubImage2D from the renderbuffers into the lightmaps.
    pub fn copy_into(&self, ctx: &GlContext, lightmaps: &Lightmaps) -> Result<(), GlError> {
        self.fbo
            .copy_to_texture(glow::COLOR_ATTACHMENT0, &lightmaps.radiosity);
        self.fbo
            .copy_to_texture(glow::COLOR_ATTACHMENT1, &lightmaps.unshot);
        unsafe {
            ctx.gl.read_buffer(glow::COLOR_ATTACHMENT0);
            ctx.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
        ctx.check(COPY_NAME)
    }
}

/// Squares are made of whole blocks of 4×4 texels: llvmpipe shades a block of 4×4 fragments at a
/// time, all of them, even where the primitive covers one.
const BLOCK: u32 = 4;
/// Larger squares would be drawn partly over blocks that need nothing.
const LARGEST_SQUARE: u32 = 64;

/// Cover the set `blocks` (rows of `wide` blocks) with aligned squares of whole blocks, none
/// larger than `largest` texels, each block exactly once: `emit(x, y, side)` in texels. A
/// square is split into its four quarters unless all of its blocks inside the grid are set.
///
/// Why squares and not the receivers' rectangles: a rectangle is two triangles, and llvmpipe
/// shades every block its diagonal crosses once for each; a thin rectangle of lightmaps costs
/// about twice its area. A square drawn as one point is shaded block by block, once.
fn cover(blocks: &[bool], wide: usize, largest: u32, mut emit: impl FnMut(u32, u32, u32)) {
    let high = blocks.len() / wide.max(1);
    let top = (largest / BLOCK) as usize;
    let mut stack = Vec::new();
    for y in (0..high).step_by(top) {
        for x in (0..wide).step_by(top) {
            stack.push((x, y, top));
            while let Some((x, y, side)) = stack.pop() {
                let (x1, y1) = ((x + side).min(wide), (y + side).min(high));
                let set = (y..y1)
                    .map(|by| {
                        blocks[by * wide + x..by * wide + x1]
                            .iter()
                            .filter(|&&b| b)
                            .count()
                    })
                    .sum::<usize>();
                if set == 0 {
                    continue;
                }
                if set == (x1 - x) * (y1 - y) {
                    let t = |b: usize| b as u32 * BLOCK;
                    emit(t(x), t(y), t(side));
                    continue;
                }
                let half = side / 2;
                for (dx, dy) in [(0, 0), (half, 0), (0, half), (half, half)] {
                    if x + dx < wide && y + dy < high {
                        stack.push((x + dx, y + dy, half));
                    }
                }
            }
        }
    }
}

/// The polygons' planes as an RGBA32F texture (see `ReconstructionPass::planes`).
fn polygon_planes(ctx: &GlContext, scene: &Scene) -> Result<Texture, GlError> {
    let n = scene.polygons.len().max(1);
    let width = n.min(ctx.info.max_texture_size.max(1) as usize);
    let height = n.div_ceil(width);
    let mut data = vec![0.0f32; width * height * 4];
    for (texel, p) in data.chunks_exact_mut(4).zip(&scene.polygons) {
        texel.copy_from_slice(&[p.normal.x, p.normal.y, p.normal.z, p.normal.dot(p.centroid)]);
    }
    let texture = Texture::new(
        &ctx.gl,
        width as i32,
        height as i32,
        TextureFormat::Rgba32F,
        glow::NEAREST,
    )?;
    texture.upload_f32(&data);
    Ok(texture)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cover_draws_every_set_block_once_and_nothing_else() {
        // 37 x 23 blocks (not a multiple of any square), a pseudo-random pattern with solid
        // patches, so that squares of every size appear.
        let (wide, high) = (37usize, 23usize);
        let blocks: Vec<bool> = (0..wide * high)
            .map(|i| {
                let (x, y) = (i % wide, i / wide);
                (x < 20 && y < 17) || (x * 7 + y * 13) % 5 < 2
            })
            .collect();
        let mut drawn = vec![0u32; blocks.len()];
        let mut sides = std::collections::BTreeSet::new();
        cover(&blocks, wide, LARGEST_SQUARE, |x, y, side| {
            assert!(
                x % side == 0 && y % side == 0,
                "square {x},{y} side {side} unaligned"
            );
            sides.insert(side);
            let b = |t: u32| (t / BLOCK) as usize;
            for by in b(y)..b(y + side).min(high) {
                for bx in b(x)..b(x + side).min(wide) {
                    drawn[by * wide + bx] += 1;
                }
            }
        });
        for (i, (&set, &n)) in blocks.iter().zip(&drawn).enumerate() {
            assert_eq!(n, set as u32, "block {i}: set {set}, drawn {n} times");
        }
        assert!(sides.len() >= 3, "sides used: {sides:?}");
    }
}
