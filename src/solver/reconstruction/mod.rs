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
//! position, normal and reflectance (`patch_data.rs`, with the polygons' planes). What each pass
//! draws, and with which program, is an `AtlasDraw` (`atlas_draw.rs`): the paper's draws every
//! patch, as squares of whole 4×4 texel blocks (`cover.rs`), into renderbuffers cleared first,
//! with the program of `programs.rs` and the texture units and uniforms of `uniforms.rs`. The
//! llvmpipe engine's (`solver::engine`) draws only the receivers' blocks after a marking pass;
//! the texels it leaves alone keep the renderbuffers' values, which the last copy also put into
//! the textures. This file does not know it.
//!
//! Two attachments: 0 = radiosity + ΔL, 1 = unshot + ΔL (zero for the texels that shoot).

mod atlas_draw;
mod cover;
mod patch_data;
mod programs;
mod uniforms;

pub(crate) use atlas_draw::{
    begin_squares, end_squares, patch_blocks, AtlasDraw, Pass, WholeAtlas,
};
pub(crate) use cover::{Squares, BLOCK};
pub(crate) use patch_data::PolygonPlanes;
pub use programs::ProgramVariants;
pub(crate) use programs::{compile, fragment, Choices, Variants};
pub(crate) use uniforms::{Uniforms, UNITS};

use super::pass_names::{ACCUMULATION, INITIALISATION, RECONSTRUCTION};
use super::visibility::VisibilityPass;
use super::{Shooter, SolveOptions};
use crate::gl::faults::{self, Fault};
use crate::gl::{Framebuffer, GlContext, GlError, Mesh, Renderbuffer, Texture, TextureFormat};
use crate::patches::PatchLayout;
use crate::scene::Scene;
use glow::HasContext;
use patch_data::PatchData;
use programs::Programs;

/// The two lightmap atlases of section 3.1: accumulated and unshot radiance (RGBA32F, alpha =
/// polygon ID + 1). The reconstruction pass samples them; the copies after it replace them.
pub struct Lightmaps {
    /// Accumulated radiance: what the display shows.
    pub radiosity: Texture,
    /// Unshot radiance: what each polygon has left to shoot.
    pub unshot: Texture,
}

impl Lightmaps {
    /// Both atlases, `width` x `height`, zero.
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

/// What the pass draws into: an FBO of two RGBA32F renderbuffers the size of the atlas (the
/// outputs), and the depth buffer its draw asks for, if any (`AtlasDraw::depth`).
struct Renderbuffers {
    fbo: Framebuffer,
    _radiosity: Renderbuffer,
    _unshot: Renderbuffer,
    width: i32,
    height: i32,
}

impl Renderbuffers {
    fn new(
        ctx: &GlContext,
        width: i32,
        height: i32,
        depth: Option<&Renderbuffer>,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let radiosity = Renderbuffer::new(gl, glow::RGBA32F, width, height)?;
        let unshot = Renderbuffer::new(gl, glow::RGBA32F, width, height)?;
        let fbo = Framebuffer::new(gl)?;
        fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT0, &radiosity);
        fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT1, &unshot);
        if let Some(depth) = depth {
            fbo.attach_renderbuffer(glow::DEPTH_ATTACHMENT, depth);
        }
        fbo.check_complete(RECONSTRUCTION)?;
        Ok(Renderbuffers {
            fbo,
            _radiosity: radiosity,
            _unshot: unshot,
            width,
            height,
        })
    }

    /// Bind the FBO for drawing both outputs; `clear` zeroes them.
    fn begin(&self, ctx: &GlContext, clear: bool) {
        draw_flat(
            ctx,
            &self.fbo,
            &[glow::COLOR_ATTACHMENT0, glow::COLOR_ATTACHMENT1],
            self.width,
            self.height,
            clear,
        );
    }
}

/// Bind `fbo` for drawing flat into the atlas: its `buffers`, no depth, blending, culling
/// or scissor; `clear` zeroes it (texels that are no patch stay zero: alpha 0, no polygon).
fn draw_flat(
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

/// The reconstruction pass (3.2.2): every receiving patch's ΔL = ρ·F·E from the shooters whose
/// item buffers see it, drawn over the atlas into renderbuffers, then added to the lightmaps.
pub struct ReconstructionPass {
    programs: Programs,
    target: Renderbuffers,
    /// Per-patch position, normal and reflectance (the receivers' side of the form factor).
    patches: PatchData,
    planes: PolygonPlanes,
    /// Each polygon's lightmap rectangle [x0, y0, x1, y1) in the atlas.
    texels: Vec<[u32; 4]>,
    /// What each pass draws, and with which program.
    draw: Box<dyn AtlasDraw>,
    /// The polygons the last pass drew (receivers and the shooter): the only ones whose unshot
    /// energy it can have changed.
    pub touched: Vec<usize>,
    /// Passes drawn with the programs unrolled for quadrilateral shooters so far.
    pub quad_passes: u32,
}

impl ReconstructionPass {
    /// The side of the square blocks of texels the pass draws whole.
    pub const BLOCK: u32 = cover::BLOCK;

    /// The paper's pass for `scene` laid out as `layout`: every patch drawn each pass with the
    /// one program, for `options.shooters_per_pass` shooters a pass.
    pub fn paper(
        ctx: &GlContext,
        scene: &Scene,
        layout: &PatchLayout,
        options: &SolveOptions,
    ) -> Result<Self, GlError> {
        let draw = Box::new(WholeAtlas::new(&ctx.gl, layout)?);
        Self::with_draw(ctx, scene, layout, options, ProgramVariants::PAPER, draw)
    }

    /// The pass for `scene` laid out as `layout`, serving up to `options.shooters_per_pass`
    /// shooters a pass with the paper's program in `variants` (with `choices_compiled`, only
    /// `options`' choices of form factor, visibility kind and robust test), drawn by `draw`.
    pub(crate) fn with_draw(
        ctx: &GlContext,
        scene: &Scene,
        layout: &PatchLayout,
        options: &SolveOptions,
        variants: ProgramVariants,
        draw: Box<dyn AtlasDraw>,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let (width, height) = (layout.atlas_width as i32, layout.atlas_height as i32);
        let planes = PolygonPlanes::new(ctx, scene)?;
        let programs = Programs::new(ctx, options, variants)?;
        let patches = PatchData::new(gl, width, height)?;
        let target = Renderbuffers::new(ctx, width, height, draw.depth())?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(RECONSTRUCTION)?;
        Ok(ReconstructionPass {
            programs,
            target,
            patches,
            planes,
            texels: layout.texel_rects(),
            draw,
            touched: Vec::new(),
            quad_passes: 0,
        })
    }

    /// What each pass draws.
    pub(crate) fn atlas_draw(&self) -> &dyn AtlasDraw {
        &*self.draw
    }

    /// Rasterise every patch's geometry into the patch textures, then write each patch's emitted
    /// radiance (and its polygon ID in alpha) into both attachments.
    pub fn emit(&self, ctx: &GlContext, mesh: &Mesh) -> Result<(), GlError> {
        self.patches.rasterise(ctx, mesh)?;
        self.target.begin(ctx, true);
        self.programs.emission.use_program();
        mesh.draw();
        ctx.check(INITIALISATION)
    }

    /// One reconstruction: for every patch drawn, its radiance and unshot radiance read from the
    /// lightmap textures plus ΔL from each of `shooters` (one in the paper; their item buffers
    /// stacked in `visibility`'s, in this order), written into the two renderbuffers; the
    /// shooting texels' unshot radiance their remainder (zero in the paper) plus what the other
    /// shooters send them. `copy_into` then carries the result into the textures.
    pub fn run(
        &mut self,
        ctx: &GlContext,
        visibility: &VisibilityPass,
        lightmaps: &Lightmaps,
        shooters: &[Shooter],
        options: &SolveOptions,
    ) -> Result<(), GlError> {
        self.refuse(shooters.len(), options)?;
        let every_texel = self.draw.select(shooters, visibility, &mut self.touched);
        let slots = self.with_idle_slots(shooters);
        // When every texel is recomputed from the textures this pass, nothing of the last pass
        // stays in the renderbuffers.
        self.target.begin(ctx, every_texel);
        self.bind_textures(visibility, lightmaps, shooters.len());
        let quad = self.programs.paper.has_quads() && slots.iter().all(|s| s.corner_count == 4);
        self.quad_passes += quad as u32;
        let uniforms = Uniforms::new(&slots, options, &self.planes);
        let pass = Pass {
            programs: &self.programs,
            uniforms: &uniforms,
            shooters,
            options,
            planes: &self.planes,
            visibility,
            quad,
            size: (self.target.width, self.target.height),
        };
        self.draw.draw(ctx, &pass);
        ctx.check(RECONSTRUCTION)
    }

    /// Refuse a pass the programs cannot serve: other choices than those compiled in, or no
    /// shooters, or more than the programs' slots.
    fn refuse(&self, count: usize, options: &SolveOptions) -> Result<(), GlError> {
        if let Some(compiled) = self.programs.compiled {
            if compiled != Choices::of(options) {
                return Err(GlError::Limit(format!(
                    "the reconstruction programs were compiled for {compiled:?}, not for {:?}",
                    Choices::of(options)
                )));
            }
        }
        let slots = self.programs.shooters;
        if count == 0 || count > slots {
            return Err(GlError::Limit(format!(
                "{count} shooters in one reconstruction pass; it was set up for 1 to {slots}"
            )));
        }
        Ok(())
    }

    /// `shooters` and idle ones after them, one per slot of the programs. A pass with fewer
    /// shooters than slots (a step's last polygons, or a polygon whose cells fill the pass
    /// alone) fills the others with copies of its first shooter that carry no energy and own
    /// no texels, seeing through its item buffer: they add exactly zero and mark only what it
    /// marks. One set of programs rather than one per count: compiling them all cost the
    /// set-up more than the few short passes cost the loop.
    fn with_idle_slots(&self, shooters: &[Shooter]) -> Vec<Shooter> {
        let idle = Shooter {
            energy: glam::Vec3::ZERO,
            texels: [0; 4],
            remainder: glam::Vec3::ZERO,
            ..shooters[0]
        };
        let idle_slots = self.programs.shooters - shooters.len();
        (shooters.iter().copied())
            .chain(std::iter::repeat_n(idle, idle_slots))
            .collect()
    }

    /// Bind every texture the programs sample to its unit of [`UNITS`]: the item buffers of
    /// the first `count` slots (the idle slots get the first's), the lightmaps, the planes and
    /// the patch data.
    fn bind_textures(&self, visibility: &VisibilityPass, lightmaps: &Lightmaps, count: usize) {
        for (k, &unit) in UNITS.item_buffers[..self.programs.shooters]
            .iter()
            .enumerate()
        {
            let slot = if k < count { k } else { 0 };
            visibility.slot_texture(slot).bind(unit);
        }
        lightmaps.radiosity.bind(UNITS.lightmap_radiosity);
        lightmaps.unshot.bind(UNITS.lightmap_unshot);
        self.planes.texture.bind(UNITS.polygon_planes);
        let (position, normal, reflectance) = (
            UNITS.patch_position,
            UNITS.patch_normal,
            UNITS.patch_reflectance,
        );
        self.patches.bind(position, normal, reflectance);
    }

    /// The squares the last pass drew with the clipping shader and with the one that does not
    /// clip.
    pub fn squares_drawn(&self) -> (usize, usize) {
        self.draw.squares().drawn()
    }

    /// Take the unshot atlas read back after a shot (or, the first time, after the emission),
    /// for the draw to watch (the engine's marking rule; the paper's does not look).
    pub fn observe(&mut self, unshot: &[f32]) {
        self.draw.observe(unshot);
    }

    /// The patch position atlas (RGBA: position, polygon ID + 1; `emit` rasterises it).
    pub fn patch_positions(&self) -> Vec<f32> {
        let mut positions = Vec::new();
        self.patches.position.read_f32(&mut positions);
        positions
    }

    /// How many texels the last pass's squares covered.
    pub fn texels_drawn(&self) -> usize {
        self.draw.squares().texels()
    }

    /// Whether the last pass drew its squares as points (`Tuning::squares_as_points`, where the
    /// driver's points are large enough) rather than as triangle pairs.
    pub fn drew_points(&self) -> bool {
        self.draw.squares().as_points()
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
            source.blit_to(
                &self.target.fbo,
                attachment,
                self.target.width,
                self.target.height,
            );
        }
        ctx.check(ACCUMULATION)
    }

    /// Beyond the paper (clusters): zero the unshot radiance (RGB; alpha, the polygon ID, kept)
    /// of the texel rectangles `rects` in the unshot renderbuffer, by scissored clears, and
    /// copy the rectangle around them into the unshot texture (one glCopyTexSubImage2D, as
    /// `copy_into`; outside `rects` the renderbuffer already holds what the texture holds, see
    /// `load_from`), so that the two agree whether or not the next pass draws those texels,
    /// and the next pass reads the copy before anything overwrites it.
    pub fn clear_unshot(
        &self,
        ctx: &GlContext,
        lightmaps: &Lightmaps,
        rects: &[[u32; 4]],
    ) -> Result<(), GlError> {
        let gl = &ctx.gl;
        self.target.begin(ctx, false);
        unsafe {
            gl.color_mask(true, true, true, false);
            gl.enable(glow::SCISSOR_TEST);
            for &[x0, y0, x1, y1] in rects {
                gl.scissor(x0 as i32, y0 as i32, (x1 - x0) as i32, (y1 - y0) as i32);
                // Draw buffer 1 is the unshot renderbuffer (`Renderbuffers::begin`).
                gl.clear_buffer_f32_slice(glow::COLOR, 1, &[0.0; 4]);
            }
            gl.disable(glow::SCISSOR_TEST);
            gl.color_mask(true, true, true, true);
        }
        if let Some(around) = rects.iter().copied().reduce(|a, b| {
            [
                a[0].min(b[0]),
                a[1].min(b[1]),
                a[2].max(b[2]),
                a[3].max(b[3]),
            ]
        }) {
            self.target.fbo.copy_rect_to_texture(
                glow::COLOR_ATTACHMENT1,
                &lightmaps.unshot,
                around,
            );
        }
        unsafe {
            gl.read_buffer(glow::COLOR_ATTACHMENT0);
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
        ctx.check(ACCUMULATION)
    }

    /// The paper's accumulation: glCopyTexSubImage2D from the renderbuffers into the lightmaps.
    pub fn copy_into(&self, ctx: &GlContext, lightmaps: &Lightmaps) -> Result<(), GlError> {
        if !faults::active(Fault::SkipAccumulationCopy) {
            self.target
                .fbo
                .copy_to_texture(glow::COLOR_ATTACHMENT0, &lightmaps.radiosity);
        }
        self.target
            .fbo
            .copy_to_texture(glow::COLOR_ATTACHMENT1, &lightmaps.unshot);
        unsafe {
            ctx.gl.read_buffer(glow::COLOR_ATTACHMENT0);
            ctx.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
        ctx.check(ACCUMULATION)
    }
}
