//! Reconstruction pass (paper 3.2.2): every receiver drawn orthographically onto its lightmap
//! texels, into an FBO whose colour attachments are *renderbuffers* the size of the atlas. The
//! fragment shader tests visibility against the item buffer, computes the form factor and the
//! received energy, and adds it to the patch's current values, which it reads from the lightmap
//! textures (the paper's GL_ADD); `copy_into` then copies the sums back into the lightmap
//! textures with glCopyTexSubImage2D, where the next pass and Find_Max_Energy read them.
//!
//! ```text
//!   lightmap textures ──sampled──▶ reconstruct.frag ──old + ΔL──▶ renderbuffers (FBO)
//!          ▲                                                            │
//!          └──────────────────── glCopyTexSubImage2D ◀─────────────────┘
//! ```
//!
//! The receivers are rasterised once, at initialisation, into atlas textures holding each patch's
//! position, normal and reflectance (`glsl/patchdata.frag`); every pass then draws squares of
//! whole 4×4 texel blocks covering the lightmaps (`cover`) and reads them. With
//! `Tuning::none()` (the paper's mode) every patch is drawn every pass, into renderbuffers
//! cleared first. The speed switches of `Tuning` draw only the receivers' blocks, and run a
//! marking pass so that only the texels the shooter sees compute form factors; the texels they
//! leave alone keep the renderbuffers' values, which the last copy also put into the textures.
//!
//! Two attachments: 0 = radiosity + ΔL, 1 = unshot + ΔL (zero for the texels that shoot).

use super::mesh::ATTRIBUTES;
use super::tuning::Tuning;
use super::visibility::VisibilityPass;
use super::{FormFactorKind, Shooter, SolveOptions, VisibilityKind, MAX_CORNERS};
use crate::gl::objects::Attribute;
use crate::gl::program::Source;
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
/// polygon ID + 1). The reconstruction pass samples them; the copies after it replace them.
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
    /// The shader as the paper has it: visibility, form factor and GL_ADD in one program, for any
    /// corner count and for quadrilateral shooters (`CORNERS`).
    literal: [Program; 2],
    /// The same after a marking pass (`MARKED`: visibility already tested), clipping the shooter
    /// to each receiver's tangent plane.
    program: [Program; 2],
    /// The same, compiled for receivers that have the whole shooter above that plane (no
    /// clipping: a third fewer shader instructions on llvmpipe; see `glsl/reconstruct.frag`).
    above: [Program; 2],
    /// The marking pass (`MARK`): writes depth where a texel can receive, so that
    /// the programs above shade only those texels' blocks.
    marking: Program,
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
    /// Per 4×4 block of the atlas, row by row, which kinds of polygon have texels in it this
    /// pass (`CLIPPED`, `SHOOTER_ABOVE`, `NOT_RECEIVING`).
    block_flags: Vec<u8>,
    cover: Cover,
    /// How many of `square_vertices` draw with the clipping shader (the rest without).
    clipped_vertices: i32,
    /// Passes drawn with the programs unrolled for quadrilateral shooters so far.
    pub quad_passes: u32,
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
    /// Each polygon's bounding sphere (centre, radius).
    bounds: Vec<(Vec3, f32)>,
    _radiosity_rb: Renderbuffer,
    _unshot_rb: Renderbuffer,
    _marks_rb: Renderbuffer,
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
        let squares_in = &[(0, "Corner"), (1, "Size")];
        let compile =
            |source: Source| Program::new(gl, glsl!("atlas.vert"), source, squares_in, outputs);
        let frag = || glsl!("reconstruct.frag");
        let literal = [compile(frag())?, compile(frag().define("CORNERS", 4))?];
        let marked = || frag().define("MARKED", 1);
        let program = [compile(marked())?, compile(marked().define("CORNERS", 4))?];
        let above = [
            compile(marked().define("SHOOTER_ABOVE", 1))?,
            compile(marked().define("SHOOTER_ABOVE", 1).define("CORNERS", 4))?,
        ];
        let marking = compile(frag().define("MARK", 1))?;
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
        let blocks = blocks_wide * (height as u32).div_ceil(BLOCK) as usize;
        let mut starts = vec![0];
        let mut outlines = Vec::new();
        for p in &scene.polygons {
            outlines.extend_from_slice(&p.vertices);
            starts.push(outlines.len());
        }
        let normals = scene.polygons.iter().map(|p| p.normal).collect();
        let bounds = scene.polygons.iter().map(|p| p.bounding_sphere()).collect();
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
        let marks_rb = Renderbuffer::new(gl, glow::DEPTH_COMPONENT32F, width, height)?;
        fbo.attach_renderbuffer(glow::DEPTH_ATTACHMENT, &marks_rb);
        fbo.check_complete(NAME)?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(NAME)?;
        Ok(ReconstructionPass {
            literal,
            program,
            above,
            marking,
            planes,
            plane_slack,
            emission,
            patches,
            squares,
            square_vertices: Vec::new(),
            block_flags: vec![0; blocks],
            cover: Cover::default(),
            clipped_vertices: 0,
            quad_passes: 0,
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
            bounds,
            _radiosity_rb: radiosity_rb,
            _unshot_rb: unshot_rb,
            _marks_rb: marks_rb,
            fbo,
            width,
            height,
        })
    }

    /// Bind the renderbuffers' FBO; `clear` zeroes them.
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

    /// Can polygon `p` receive anything from `shooter`, and is the whole shooter above `p`'s
    /// plane? Some of `p` must lie in front of the shooter and some of the shooter in front of
    /// `p` (with float slack: never wrongly no; and never wrongly "wholly above"). `reach` is the
    /// shooter's bounding sphere (centre, radius). Most polygons are decided by the two bounding
    /// spheres, with a margin of one slack over the float noise; the rest corner by corner.
    fn reception(&self, p: usize, shooter: &Shooter, reach: (Vec3, f32)) -> Reception {
        let slack = self.plane_slack;
        let outline = &self.outlines[self.starts[p]..self.starts[p + 1]];
        let (centre, radius) = self.bounds[p];
        let base = shooter.corners[0];
        let ahead = shooter.normal.dot(centre - base);
        let in_front = if ahead - radius > 0.0 {
            true
        } else if ahead + radius < -2.0 * slack {
            false
        } else {
            outline
                .iter()
                .any(|&v| shooter.normal.dot(v - base) > -slack)
        };
        if !in_front {
            return Reception::Nothing;
        }
        let n = self.normals[p];
        let height = n.dot(reach.0 - outline[0]);
        let (lowest, highest) = if height - reach.1 > 2.0 * slack {
            (height - reach.1, height + reach.1)
        } else if height + reach.1 < -2.0 * slack {
            return Reception::Nothing;
        } else {
            let mut range = (f32::INFINITY, f32::NEG_INFINITY);
            for &c in shooter.corners[..shooter.corner_count.max(1)]
                .iter()
                .chain(std::iter::once(&shooter.position))
            {
                let h = n.dot(c - outline[0]);
                range = (range.0.min(h), range.1.max(h));
            }
            range
        };
        if highest <= -slack {
            Reception::Nothing
        } else if shooter.corner_count > 0 && lowest > slack {
            Reception::ShooterAbove
        } else {
            Reception::Clipped
        }
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

    /// The receivers to draw for `shooter`: the lightmaps of the polygons that can receive
    /// (every polygon with patches unless `tuning.receivers_only`) and the shooter's texels,
    /// covered by aligned squares of whole 4×4 blocks (`cover`), split by the shader that draws
    /// them; `touched` gets the receivers and the shooter.
    fn select_receivers(&mut self, shooter: &Shooter, tuning: &Tuning) {
        self.touched.clear();
        self.block_flags.fill(0);
        let corners = &shooter.corners[..shooter.corner_count.max(1)];
        let reach = (
            shooter.position,
            corners
                .iter()
                .map(|c| c.distance(shooter.position))
                .fold(0.0, f32::max),
        );
        let bw = self.blocks_wide;
        let mark = |flags: &mut [u8], [x0, y0, x1, y1]: [u32; 4], flag: u8| {
            for by in y0 / BLOCK..y1.div_ceil(BLOCK) {
                let row = by as usize * bw;
                let blocks = row + (x0 / BLOCK) as usize..row + x1.div_ceil(BLOCK) as usize;
                for f in &mut flags[blocks] {
                    *f |= flag;
                }
            }
        };
        for k in 0..self.with_patches.len() {
            let p = self.with_patches[k];
            let flag = if !tuning.receivers_only {
                CLIPPED
            } else if p == shooter.polygon {
                // The shooter sends nothing to itself: only its shooting texels are drawn.
                0
            } else {
                match self.reception(p, shooter, reach) {
                    Reception::Nothing => NOT_RECEIVING,
                    Reception::ShooterAbove => SHOOTER_ABOVE,
                    Reception::Clipped => CLIPPED,
                }
            };
            if flag != NOT_RECEIVING {
                self.touched.push(p);
            }
            if flag != 0 {
                mark(&mut self.block_flags, self.texels[p], flag);
            }
        }
        // The shooting texels are drawn to clear their unshot energy.
        mark(&mut self.block_flags, shooter.texels, SHOOTER);
        // Only blocks that hold receivers or shooting texels are drawn; without clipping only
        // where every other polygon in the block has the shooter above it (a polygon that
        // receives nothing must get its exact zero from the clipped factor; the shooter's texels
        // get zero from either).
        let skip = tuning.skip_needless_clipping && tuning.marking_pass;
        let above = |f: &u8| skip && *f & !SHOOTER == SHOOTER_ABOVE;
        let clipped = |f: &u8| *f & (SHOOTER_ABOVE | CLIPPED | SHOOTER) != 0 && !above(f);
        self.square_vertices.clear();
        let (size, points) = (self.viewport, self.squares_as_points);
        let vertices = &mut self.square_vertices;
        let (flags, largest) = (&self.block_flags, self.largest_square);
        self.cover
            .squares(flags, bw, largest, clipped, |x, y, side| {
                push_square(vertices, points, size, x, y, side)
            });
        self.clipped_vertices = vertices.len() as i32 / 3;
        self.cover.squares(flags, bw, largest, above, |x, y, side| {
            push_square(vertices, points, size, x, y, side)
        });
        self.squares.replace(&self.square_vertices, 3);
    }

    /// One reconstruction: for every patch drawn, its radiance and unshot radiance read from the
    /// lightmap textures plus ΔL from `shooter`, written into the two renderbuffers; the shooting
    /// texels' unshot radiance zero. `copy_into` then carries the result into the textures.
    pub fn run(
        &mut self,
        ctx: &GlContext,
        visibility: &VisibilityPass,
        lightmaps: &Lightmaps,
        shooter: &Shooter,
        options: &SolveOptions,
    ) -> Result<(), GlError> {
        let tuning = options.tuning;
        self.select_receivers(shooter, &tuning);
        // When every texel is recomputed from the textures this pass, nothing of the last pass
        // stays in the renderbuffers.
        self.begin(ctx, tuning.writes_every_texel());
        visibility.item_buffer.bind(0);
        lightmaps.radiosity.bind(1);
        lightmaps.unshot.bind(2);
        self.planes.bind(3);
        self.patches.position.bind(4);
        self.patches.normal.bind(5);
        self.patches.reflectance.bind(6);
        let gl = &ctx.gl;
        unsafe {
            gl.viewport(0, 0, self.viewport.0, self.viewport.1);
            gl.enable(glow::SCISSOR_TEST);
            gl.scissor(0, 0, self.width, self.height);
            if self.squares_as_points {
                gl.enable(glow::PROGRAM_POINT_SIZE);
            }
        }
        let mut corners = [0.0f32; 3 * MAX_CORNERS];
        for (c, v) in corners.chunks_exact_mut(3).zip(&shooter.corners) {
            c.copy_from_slice(&v.to_array());
        }
        let uniforms = |p: &Program| {
            p.use_program();
            p.set_i32("PatchPosition", 4);
            p.set_i32("PatchNormal", 5);
            p.set_i32("PatchReflectance", 6);
            p.set_i32("LightmapRadiosity", 1);
            p.set_i32("LightmapUnshot", 2);
            p.set_ivec4("ShooterTexels", shooter.texels.map(|t| t as i32));
            p.set_i32("HemiItemBuffer", 0);
            p.set_mat4("ShooterView", &shooter.view().to_cols_array());
            p.set_vec3("ShootPos", shooter.position.to_array());
            p.set_vec3("ShootNormal", shooter.normal.to_array());
            p.set_vec3("ShootEnergy", shooter.energy.to_array());
            p.set_f32("ShooterId", shooter.polygon as f32);
            p.set_i32(
                "FormFactorKind",
                (options.form_factor == FormFactorKind::Polygon) as i32,
            );
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
            p.set_i32("PlanesShift", self.planes.width.trailing_zeros() as i32);
            p.set_f32("PlaneSlack", self.plane_slack);
        };
        let mode = if self.squares_as_points {
            glow::POINTS
        } else {
            glow::TRIANGLES
        };
        let total = self.squares.vertex_count;
        if tuning.marking_pass {
            // Marking: depth 1 cleared, the squares' depth (½) written where a texel can
            // receive or shoots, nothing else; the pass proper then shades those texels only.
            unsafe {
                gl.depth_mask(true);
                gl.clear_depth_f64(1.0);
                gl.clear(glow::DEPTH_BUFFER_BIT);
                gl.enable(glow::DEPTH_TEST);
                gl.depth_func(glow::ALWAYS);
                gl.color_mask(false, false, false, false);
            }
            uniforms(&self.marking);
            self.squares.draw_arrays(mode, 0, total);
            unsafe {
                gl.depth_func(glow::EQUAL);
                gl.depth_mask(false);
                gl.color_mask(true, true, true, true);
            }
        }
        let quad = (tuning.unroll_quads && shooter.corner_count == 4) as usize;
        self.quad_passes += quad as u32;
        let (clipping, not_clipping) = if tuning.marking_pass {
            (&self.program[quad], &self.above[quad])
        } else {
            (&self.literal[quad], &self.literal[quad])
        };
        let split = self.clipped_vertices;
        for (p, first, count) in [(clipping, 0, split), (not_clipping, split, total - split)] {
            if count > 0 {
                uniforms(p);
                self.squares.draw_arrays(mode, first, count);
            }
        }
        unsafe {
            gl.disable(glow::PROGRAM_POINT_SIZE);
            gl.disable(glow::DEPTH_TEST);
            gl.disable(glow::SCISSOR_TEST);
            gl.active_texture(glow::TEXTURE0);
        }
        ctx.check(NAME)
    }

    /// The squares the last pass drew with the clipping shader and with the one that does not
    /// clip.
    pub fn squares_drawn(&self) -> (usize, usize) {
        let per_square = if self.squares_as_points { 1 } else { 6 };
        let clipped = self.clipped_vertices as usize / per_square;
        let all = self.squares.vertex_count as usize / per_square;
        (clipped, all - clipped)
    }

    /// Each polygon's lightmap rectangle [x0, y0, x1, y1) in the atlas.
    pub fn texels(&self) -> &[[u32; 4]] {
        &self.texels
    }

    /// Make the renderbuffers hold what `lightmaps` hold, after the textures were replaced from
    /// outside (`GpuSolver::load_atlases`): the tuned passes leave the texels they do not draw as
    /// the renderbuffers have them.
    pub fn load_from(&self, ctx: &GlContext, lightmaps: &Lightmaps) -> Result<(), GlError> {
        let source = Framebuffer::new(&ctx.gl)?;
        for (attachment, texture) in [
            (glow::COLOR_ATTACHMENT0, &lightmaps.radiosity),
            (glow::COLOR_ATTACHMENT1, &lightmaps.unshot),
        ] {
            source.attach_texture(glow::COLOR_ATTACHMENT0, texture);
            source.blit_to(&self.fbo, attachment, self.width, self.height);
        }
        ctx.check(COPY_NAME)
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

/// Block flags: a polygon that receives with clipping, one that has the whole shooter above it,
/// one that receives nothing; texels that shoot.
const CLIPPED: u8 = 1;
const SHOOTER_ABOVE: u8 = 2;
const NOT_RECEIVING: u8 = 4;
const SHOOTER: u8 = 8;

/// What a receiver gets from a shooter (see `ReconstructionPass::reception`).
enum Reception {
    Nothing,
    /// The whole shooter lies above the receiver's plane: no clipping needed.
    ShooterAbove,
    Clipped,
}

/// Squares are made of whole blocks of 4×4 texels: llvmpipe shades a block of 4×4 fragments at a
/// time, all of them, even where the primitive covers one.
const BLOCK: u32 = 4;
/// Larger squares would be drawn partly over blocks that need nothing.
const LARGEST_SQUARE: u32 = 64;

/// Covers blocks with squares (see `Cover::squares`); keeps its scratch space between passes.
#[derive(Default)]
struct Cover {
    /// Summed-area table of the set blocks: entry (x, y) counts those in [0, x) × [0, y).
    sums: Vec<u32>,
    stack: Vec<(usize, usize, usize)>,
}

impl Cover {
    /// Cover the blocks for which `is_set` holds (`blocks`: rows of `wide` blocks) with aligned
    /// squares of whole blocks, none larger than `largest` texels, each block exactly once:
    /// `emit(x, y, side)` in texels. A square is split into its four quarters unless all of its
    /// blocks inside the grid are set.
    ///
    /// Why squares and not the receivers' rectangles: a rectangle is two triangles, and llvmpipe
    /// shades every block its diagonal crosses once for each; a thin rectangle of lightmaps costs
    /// about twice its area. A square drawn as one point is shaded block by block, once.
    fn squares<T>(
        &mut self,
        blocks: &[T],
        wide: usize,
        largest: u32,
        is_set: impl Fn(&T) -> bool,
        mut emit: impl FnMut(u32, u32, u32),
    ) {
        let high = blocks.len() / wide.max(1);
        let row = wide + 1;
        self.sums.clear();
        self.sums.resize(row * (high + 1), 0);
        for y in 0..high {
            let mut run = 0;
            for x in 0..wide {
                run += is_set(&blocks[y * wide + x]) as u32;
                self.sums[(y + 1) * row + x + 1] = self.sums[y * row + x + 1] + run;
            }
        }
        let sums = &self.sums;
        let count = |x0: usize, y0: usize, x1: usize, y1: usize| {
            sums[y1 * row + x1] + sums[y0 * row + x0] - sums[y0 * row + x1] - sums[y1 * row + x0]
        };
        let top = (largest / BLOCK) as usize;
        for y in (0..high).step_by(top) {
            for x in (0..wide).step_by(top) {
                self.stack.push((x, y, top));
                while let Some((x, y, side)) = self.stack.pop() {
                    let (x1, y1) = ((x + side).min(wide), (y + side).min(high));
                    let set = count(x, y, x1, y1) as usize;
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
                            self.stack.push((x + dx, y + dy, half));
                        }
                    }
                }
            }
        }
    }
}

/// The polygons' planes as an RGBA32F texture (see `ReconstructionPass::planes`).
fn polygon_planes(ctx: &GlContext, scene: &Scene) -> Result<Texture, GlError> {
    let n = scene.polygons.len().max(1);
    let largest = 1usize << (ctx.info.max_texture_size.max(1) as u32).ilog2();
    let width = n.next_power_of_two().min(largest);
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
        Cover::default().squares(
            &blocks,
            wide,
            LARGEST_SQUARE,
            |&b| b,
            |x, y, side| {
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
            },
        );
        for (i, (&set, &n)) in blocks.iter().zip(&drawn).enumerate() {
            assert_eq!(n, set as u32, "block {i}: set {set}, drawn {n} times");
        }
        assert!(sides.len() >= 3, "sides used: {sides:?}");
    }
}
