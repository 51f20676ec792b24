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
//! draws, and with which program, is an `AtlasDraw` (below): the paper's `WholeAtlas` draws every
//! receiver at once, as one quad over the atlas (a texel that is no patch adds nothing), into
//! renderbuffers cleared first, with
//! the program of `programs.rs` and the texture units and uniforms below (`UNITS`, `Uniforms`).
//! The llvmpipe engine's (`solver::engine`) draws only the receivers' blocks after a marking
//! pass; the texels it leaves alone keep the renderbuffers' values, which the last copy also put
//! into the textures. This file does not know it.
//!
//! Two attachments: 0 = radiosity + ΔL, 1 = unshot + ΔL (zero for the texels that shoot).

mod patch_data;
mod programs;

pub(crate) use patch_data::PolygonPlanes;
pub use programs::ProgramVariants;
pub(crate) use programs::{compile, fragment, Choices};

use super::cluster_parts::ROW_TEXELS;
use super::pass_names::{ACCUMULATION, INITIALISATION, RECONSTRUCTION};
use super::visibility::VisibilityPass;
use super::{FormFactorKind, Part, Shooter, SolveOptions, VisibilityKind, MAX_SHOOTERS_PER_PASS};
use crate::gl::faults::{self, Fault};
use crate::gl::objects::Attribute;
use crate::gl::program::Source;
use crate::gl::{
    Framebuffer, Gl, GlContext, GlError, Mesh, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::patches::PatchLayout;
use crate::scene::Scene;
use glow::HasContext;
use patch_data::PatchData;
use programs::Programs;
use std::any::Any;

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
    /// Beyond the paper: the face clusters' parts of the step (`cluster_parts.rs`), a row each.
    parts: Texture,
}

impl ReconstructionPass {
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
            parts: parts_texture(gl, 1)?,
        })
    }

    /// Beyond the paper (face clusters): give the next passes `parts`, the rows their
    /// shooters' `parts` point at (`glsl/reconstruct.frag`'s `ShootParts`).
    pub fn set_parts(&mut self, ctx: &GlContext, parts: &[Part]) -> Result<(), GlError> {
        let rows = parts.len().max(1);
        if rows > self.parts.height as usize {
            self.parts = parts_texture(&ctx.gl, rows.next_power_of_two() as i32)?;
        }
        let mut data = vec![0.0f32; self.parts.height as usize * PART_WIDTH * 4];
        for (row, part) in data.chunks_exact_mut(PART_WIDTH * 4).zip(parts) {
            row[..ROW_TEXELS * 4].copy_from_slice(part.texels().as_flattened());
        }
        self.parts.upload_f32(&data);
        ctx.check(RECONSTRUCTION)
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
            near: has_parts(&slots),
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
        self.parts.bind(UNITS.parts);
        let (position, normal, reflectance) = (
            UNITS.patch_position,
            UNITS.patch_normal,
            UNITS.patch_reflectance,
        );
        self.patches.bind(position, normal, reflectance);
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

    /// How many texels the last pass drew.
    pub fn texels_drawn(&self) -> usize {
        self.draw.texels_drawn()
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
    /// Whether a shooter is a face cluster's with parts (`cluster_parts.rs`): the programs
    /// with the near field then.
    pub near: bool,
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

    /// How many texels the last pass drew (the pass proper's).
    fn texels_drawn(&self) -> usize;

    /// This draw as `Any`, for the engine to find its own.
    fn as_any(&self) -> &dyn Any;
}

/// The layout of `glsl/atlas.vert`'s vertices, three floats each: `Corner` (clip space), then
/// `Size` (a point's side in texels; unused by triangles). The paper's quad and the engine's
/// squares both draw with it.
pub(crate) const ATLAS_VERTEX: [Attribute; 2] = [
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
];

/// The paper's draw: every receiver, each pass, with the paper's program. Since each patch's
/// geometry is already in the patch textures, one quad over the whole atlas draws every receiver
/// at once: each fragment reads its patch, and a texel that is no patch adds nothing (the same
/// lightmaps as drawing each receiver's rectangle, bit for bit, in a fraction of the time on
/// llvmpipe: perf-log, sixteenth session). The shooters' texels are drawn too, which clears their
/// unshot energy.
pub(crate) struct WholeAtlas {
    /// Two triangles over the atlas, in clip space ([`ATLAS_VERTEX`]).
    atlas: Mesh,
    /// The polygons with patches, and per polygon whether it is one of them.
    receivers: Vec<usize>,
    receives: Vec<bool>,
    /// The atlas's texels.
    texels: usize,
}

impl WholeAtlas {
    /// The draw for an atlas laid out as `layout`.
    pub fn new(gl: &Gl, layout: &PatchLayout) -> Result<Self, GlError> {
        let receives: Vec<bool> = (layout.patches_per_polygon.iter())
            .map(|&n| n > 0)
            .collect();
        let receivers: Vec<usize> = (0..receives.len()).filter(|&p| receives[p]).collect();
        let mut vertices = Vec::new();
        for [u, v] in [
            [-1.0, -1.0],
            [1.0, -1.0],
            [1.0, 1.0],
            [-1.0, -1.0],
            [1.0, 1.0],
            [-1.0, 1.0],
        ] {
            vertices.extend_from_slice(&[u, v, 0.0f32]);
        }
        let atlas = Mesh::new(gl, &vertices, 3, &ATLAS_VERTEX)?;
        Ok(WholeAtlas {
            atlas,
            receivers,
            receives,
            texels: (layout.atlas_width * layout.atlas_height) as usize,
        })
    }
}

impl AtlasDraw for WholeAtlas {
    fn select(
        &mut self,
        shooters: &[Shooter],
        _visibility: &VisibilityPass,
        touched: &mut Vec<usize>,
    ) -> bool {
        touched.clone_from(&self.receivers);
        // A shooter without patches of its own (none in the paper) has no texels to clear.
        for s in shooters {
            if !self.receives[s.polygon] && !touched.contains(&s.polygon) {
                touched.push(s.polygon);
            }
        }
        true
    }

    fn draw(&mut self, ctx: &GlContext, pass: &Pass) {
        unsafe { ctx.gl.viewport(0, 0, pass.size.0, pass.size.1) };
        pass.uniforms
            .set(pass.programs.paper.get(pass.quad, pass.near));
        self.atlas.draw();
        unsafe { ctx.gl.active_texture(glow::TEXTURE0) };
    }

    fn texels_drawn(&self) -> usize {
        self.texels
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// A program for any corner count, and (`ProgramVariants::quads`) its variant for
/// quadrilateral shooters (`CORNERS` 4); and where face clusters shoot, both again with their
/// near field (`FACE_CLUSTERS`), for the passes that have a face cluster's shooter: its code
/// costs llvmpipe a quarter more per texel even where it runs no part (the conference room's
/// accumulation: 393 s against 311 s in the same number of passes).
pub(crate) struct Variants {
    plain: [Option<Program>; 2],
    near: [Option<Program>; 2],
}

impl Variants {
    /// `source` compiled by `compile`, and for quadrilaterals too if `quads`, each with the near
    /// field too if `near`.
    pub fn new(
        compile: &dyn Fn(Source) -> Result<Program, GlError>,
        source: &dyn Fn() -> Source,
        quads: bool,
        near: bool,
    ) -> Result<Self, GlError> {
        let both = |with_near: bool| -> Result<[Option<Program>; 2], GlError> {
            let source = || {
                let s = source();
                if with_near {
                    s.define("FACE_CLUSTERS", 1)
                } else {
                    s
                }
            };
            Ok([
                Some(compile(source())?),
                if quads {
                    Some(compile(source().define("CORNERS", 4))?)
                } else {
                    None
                },
            ])
        };
        Ok(Variants {
            plain: both(false)?,
            near: if near { both(true)? } else { [None, None] },
        })
    }

    /// The one for quadrilaterals if `quad` and it was compiled, else the general one; with
    /// the near field if `near` (a pass with a face cluster's shooter).
    pub fn get(&self, quad: bool, near: bool) -> &Program {
        let set = if near && self.near[0].is_some() {
            &self.near
        } else {
            &self.plain
        };
        match (&set[1], quad) {
            (Some(q), true) => q,
            _ => set[0].as_ref().expect("always compiled"),
        }
    }

    /// Whether it has the variant for quadrilaterals.
    pub fn has_quads(&self) -> bool {
        self.plain[1].is_some()
    }
}

/// Whether any of `shooters` is a face cluster's with parts: its pass needs the programs with
/// the near field ([`Variants::get`]).
pub(crate) fn has_parts(shooters: &[Shooter]) -> bool {
    shooters.iter().any(|s| s.parts.count > 0)
}

/// The width of the parts' texture: a row of `ROW_TEXELS`, rounded up to a power of two.
const PART_WIDTH: usize = ROW_TEXELS.next_power_of_two();

/// A texture for `rows` parts, a row each (`ReconstructionPass::set_parts`).
fn parts_texture(gl: &Gl, rows: i32) -> Result<Texture, GlError> {
    Texture::new(
        gl,
        PART_WIDTH as i32,
        rows,
        TextureFormat::Rgba32F,
        glow::NEAREST,
    )
}

/// The texture unit of each texture `glsl/reconstruct.frag` samples (named after its sampler).
pub(crate) struct TextureUnits {
    /// `HemiItemBuffer[k]`: shooter k's item buffer.
    pub item_buffers: [u32; MAX_SHOOTERS_PER_PASS as usize],
    /// `LightmapRadiosity`: the radiosity lightmap as the last copy left it.
    pub lightmap_radiosity: u32,
    /// `LightmapUnshot`: the unshot lightmap as the last copy left it.
    pub lightmap_unshot: u32,
    /// `PolygonPlanes`: each polygon's plane, for the robust test.
    pub polygon_planes: u32,
    /// `PatchPosition`, `PatchNormal`, `PatchReflectance`: the receivers' side of the factor.
    pub patch_position: u32,
    pub patch_normal: u32,
    pub patch_reflectance: u32,
    /// `ShootParts`: the face clusters' parts (beyond the paper).
    pub parts: u32,
}

/// The pass's texture units: shooter 0's item buffer on unit 0 (the paper's one), the lightmaps,
/// planes and patch data on 1 to 6, the other shooters' item buffers on 7 to 13, the parts on 14
/// (OpenGL 3.0 promises 16 units).
pub(crate) const UNITS: TextureUnits = TextureUnits {
    item_buffers: [0, 7, 8, 9, 10, 11, 12, 13],
    lightmap_radiosity: 1,
    lightmap_unshot: 2,
    polygon_planes: 3,
    patch_position: 4,
    patch_normal: 5,
    patch_reflectance: 6,
    parts: 14,
};

/// The uniforms of one pass, the shooters' as arrays of one element per shooter (the corners:
/// `MAX_CORNERS` each), ready to be given to each program the pass draws with.
pub(crate) struct Uniforms<'a> {
    texels: Vec<i32>,
    remainders: Vec<f32>,
    hemi_res: Vec<i32>,
    views: Vec<f32>,
    positions: Vec<f32>,
    normals: Vec<f32>,
    energies: Vec<f32>,
    ids: Vec<f32>,
    corners: Vec<f32>,
    corner_counts: Vec<i32>,
    areas: Vec<f32>,
    part_rows: Vec<i32>,
    reaches: Vec<f32>,
    /// `UNITS.item_buffers` of the shooters.
    item_units: Vec<i32>,
    options: &'a SolveOptions,
    planes: &'a PolygonPlanes,
}

/// `f`'s values for each of `shooters`, one after another: a uniform array's contents.
fn per_shooter<T, const N: usize>(shooters: &[Shooter], f: impl Fn(&Shooter) -> [T; N]) -> Vec<T> {
    shooters.iter().flat_map(f).collect()
}

impl<'a> Uniforms<'a> {
    /// The uniforms for `shooters` (every slot of the programs filled) under `options`.
    pub fn new(shooters: &[Shooter], options: &'a SolveOptions, planes: &'a PolygonPlanes) -> Self {
        Uniforms {
            texels: per_shooter(shooters, |s| s.texels.map(|t| t as i32)),
            remainders: per_shooter(shooters, |s| s.remainder.to_array()),
            hemi_res: per_shooter(shooters, |s| [s.hemi_res as i32]),
            views: per_shooter(shooters, |s| s.view().to_cols_array()),
            positions: per_shooter(shooters, |s| s.position.to_array()),
            normals: per_shooter(shooters, |s| s.normal.to_array()),
            energies: per_shooter(shooters, |s| s.energy.to_array()),
            ids: per_shooter(shooters, |s| [s.polygon as f32]),
            corners: (shooters.iter())
                .flat_map(|s| s.corners.iter().flat_map(|v| v.to_array()))
                .collect(),
            corner_counts: per_shooter(shooters, |s| [s.corner_count as i32]),
            areas: per_shooter(shooters, |s| [s.area]),
            part_rows: per_shooter(shooters, |s| [s.parts.first as i32, s.parts.count as i32]),
            reaches: per_shooter(shooters, |s| [s.parts.reach]),
            item_units: (UNITS.item_buffers[..shooters.len()].iter())
                .map(|&u| u as i32)
                .collect(),
            options,
            planes,
        }
    }

    /// Use `p` and give it the uniforms: samplers, shooters, choices, planes.
    pub fn set(&self, p: &Program) {
        let unit = |u: u32| u as i32;
        p.use_program();
        p.set_i32("PatchPosition", unit(UNITS.patch_position));
        p.set_i32("PatchNormal", unit(UNITS.patch_normal));
        p.set_i32("PatchReflectance", unit(UNITS.patch_reflectance));
        p.set_i32("LightmapRadiosity", unit(UNITS.lightmap_radiosity));
        p.set_i32("LightmapUnshot", unit(UNITS.lightmap_unshot));
        p.set_i32("PolygonPlanes", unit(UNITS.polygon_planes));
        p.set_i32_array("HemiItemBuffer", &self.item_units);
        p.set_ivec4_array("ShooterTexels", &self.texels);
        p.set_vec3_array("ShooterRemainder", &self.remainders);
        p.set_i32_array("HemiRes", &self.hemi_res);
        p.set_mat4_array("ShooterView", &self.views);
        p.set_vec3_array("ShootPos", &self.positions);
        p.set_vec3_array("ShootNormal", &self.normals);
        p.set_vec3_array("ShootEnergy", &self.energies);
        p.set_f32_array("ShooterId", &self.ids);
        p.set_vec3_array("ShootCorners", &self.corners);
        p.set_i32_array("ShootCornerCount", &self.corner_counts);
        p.set_f32_array("ShootArea", &self.areas);
        p.set_i32("ShootParts", unit(UNITS.parts));
        p.set_ivec2_array("ShootPartRows", &self.part_rows);
        p.set_f32_array("ShootReach", &self.reaches);
        let options = self.options;
        let polygon = options.form_factor == FormFactorKind::Polygon;
        p.set_i32("FormFactorKind", polygon as i32);
        let hemicube = options.visibility == VisibilityKind::Hemicube;
        p.set_i32("HemiCube", hemicube as i32);
        p.set_i32("Robust", options.robust_visibility as i32);
        let planes = &self.planes.texture;
        p.set_i32("PlanesWidth", planes.width);
        p.set_i32("PlanesShift", planes.width.trailing_zeros() as i32);
        p.set_f32("PlaneSlack", self.planes.slack);
    }
}
