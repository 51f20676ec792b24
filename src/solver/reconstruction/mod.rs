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
//! position, normal and reflectance (`patch_data.rs`, with the polygons' planes); every pass
//! then picks the blocks to draw (`receivers.rs`) and draws squares of whole 4×4 texel blocks
//! covering them (`cover.rs`). With `Tuning::none()` (the paper's mode) every patch is drawn
//! every pass, into renderbuffers cleared first. The speed switches of `Tuning` run a marking
//! pass so that only the texels the shooter sees compute form factors (and can draw only the
//! receivers' blocks); the texels they leave alone keep the renderbuffers' values, which the
//! last copy also put into the textures.
//!
//! Two attachments: 0 = radiosity + ΔL, 1 = unshot + ΔL (zero for the texels that shoot).

mod cover;
mod lit_share;
mod patch_data;
mod receivers;

use super::mesh::ATTRIBUTES;
use super::visibility::VisibilityPass;
use super::{FormFactorKind, Shooter, SolveOptions, Tuning, VisibilityKind};
use crate::gl::faults::{self, Fault};
use crate::gl::program::Source;
use crate::gl::{
    Framebuffer, GlContext, GlError, Mesh, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::glsl;
use crate::patches::PatchLayout;
use crate::scene::Scene;
use cover::Squares;
use glow::HasContext;
use patch_data::{PatchData, PolygonPlanes};
use receivers::Receivers;

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

/// The pass's programs: `glsl/reconstruct.frag` in its variants for one number of shooters per
/// pass (`SHOOTERS`), and the emission shader.
struct Programs {
    /// For `shooters` shooters a pass (`SolveOptions::shooters_per_pass`); a pass with fewer
    /// pads the rest (`ReconstructionPass::run`).
    for_slots: ShooterPrograms,
    shooters: usize,
    /// The choices compiled into `for_slots` (`Tuning::compile_choices`); none: read from
    /// uniforms, so the programs serve any options.
    compiled: Option<Choices>,
    /// Writes each patch's emitted radiance (and its polygon ID in alpha) at initialisation.
    emission: Program,
}

/// `glsl/reconstruct.frag` compiled for one number of shooters.
struct ShooterPrograms {
    /// The shader as the paper has it: visibility, form factor and GL_ADD in one program, for any
    /// corner count and for quadrilateral shooters (`CORNERS`).
    literal: [Program; 2],
    /// The same after a marking pass (`MARKED`: visibility already tested), clipping the shooter
    /// to each receiver's tangent plane.
    marked: [Program; 2],
    /// The same, compiled for receivers that have the whole shooter above that plane (no
    /// clipping: a third fewer shader instructions on llvmpipe; see `glsl/reconstruct.frag`).
    above: [Program; 2],
    /// The marking pass (`MARK`): writes depth where a texel can receive, so that
    /// the programs above shade only those texels' blocks.
    marking: Program,
}

/// A solve's fixed choices that `glsl/reconstruct.frag` branches on: the form factor, the
/// visibility kind and the robust test (the shader's `FormFactorKind`, `HemiCube` and `Robust`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Choices {
    polygon_form_factor: bool,
    hemicube: bool,
    robust: bool,
}

impl Choices {
    fn of(options: &SolveOptions) -> Self {
        Choices {
            polygon_form_factor: options.form_factor == FormFactorKind::Polygon,
            hemicube: options.visibility == VisibilityKind::Hemicube,
            robust: options.robust_visibility,
        }
    }

    /// `source` with the choices compiled in as constants.
    fn define(&self, source: Source) -> Source {
        source
            .define("FORM_FACTOR_KIND", self.polygon_form_factor as i32)
            .define("HEMI_CUBE", self.hemicube as i32)
            .define("ROBUST", self.robust as i32)
    }
}

impl Programs {
    fn new(ctx: &GlContext, options: &SolveOptions) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let squares_in = &[(0, "Corner"), (1, "Size")];
        let compile =
            |source: Source| Program::new(gl, glsl!("atlas.vert"), source, squares_in, OUTPUTS);
        let compiled = options.tuning.compile_choices.then(|| Choices::of(options));
        let shooters = options.shooters_per_pass.max(1);
        let frag = || {
            let source = glsl!("reconstruct.frag").define("SHOOTERS", shooters as i32);
            match &compiled {
                Some(choices) => choices.define(source),
                None => source,
            }
        };
        let marked = || frag().define("MARKED", 1);
        let above = || marked().define("SHOOTER_ABOVE", 1);
        let for_slots = ShooterPrograms {
            literal: [compile(frag())?, compile(frag().define("CORNERS", 4))?],
            marked: [compile(marked())?, compile(marked().define("CORNERS", 4))?],
            above: [compile(above())?, compile(above().define("CORNERS", 4))?],
            marking: compile(frag().define("MARK", 1))?,
        };
        Ok(Programs {
            for_slots,
            shooters: shooters as usize,
            compiled,
            emission: Program::new(
                gl,
                glsl!("lightmap.vert"),
                glsl!("emission.frag"),
                ATTRIBUTES,
                OUTPUTS,
            )?,
        })
    }
}

/// `f`'s values for each of `shooters`, one after another: a uniform array's contents.
fn per_shooter<T, const N: usize>(shooters: &[Shooter], f: impl Fn(&Shooter) -> [T; N]) -> Vec<T> {
    shooters.iter().flat_map(f).collect()
}

/// The two outputs: 0 = radiosity + ΔL, 1 = unshot + ΔL (zero for the texels that shoot).
const OUTPUTS: &[(u32, &str)] = &[(0, "NewRadiosity"), (1, "NewUnshot")];

/// What the pass draws into: an FBO of two RGBA32F renderbuffers the size of the atlas (the
/// outputs), and a depth renderbuffer for the marking pass.
struct Renderbuffers {
    fbo: Framebuffer,
    _radiosity: Renderbuffer,
    _unshot: Renderbuffer,
    _marks: Renderbuffer,
    width: i32,
    height: i32,
}

impl Renderbuffers {
    fn new(ctx: &GlContext, width: i32, height: i32) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let radiosity = Renderbuffer::new(gl, glow::RGBA32F, width, height)?;
        let unshot = Renderbuffer::new(gl, glow::RGBA32F, width, height)?;
        let fbo = Framebuffer::new(gl)?;
        fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT0, &radiosity);
        fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT1, &unshot);
        let marks = Renderbuffer::new(gl, glow::DEPTH_COMPONENT32F, width, height)?;
        fbo.attach_renderbuffer(glow::DEPTH_ATTACHMENT, &marks);
        fbo.check_complete(NAME)?;
        Ok(Renderbuffers {
            fbo,
            _radiosity: radiosity,
            _unshot: unshot,
            _marks: marks,
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

pub struct ReconstructionPass {
    programs: Programs,
    target: Renderbuffers,
    /// Per-patch position, normal and reflectance (the receivers' side of the form factor).
    patches: PatchData,
    planes: PolygonPlanes,
    /// Which polygons can receive, and the blocks they cover.
    receivers: Receivers,
    /// The squares each pass draws over those blocks.
    squares: Squares,
    /// The polygons the last pass drew (receivers and the shooter): the only ones whose unshot
    /// energy it can have changed.
    pub touched: Vec<usize>,
    /// Passes drawn with the programs unrolled for quadrilateral shooters so far.
    pub quad_passes: u32,
    /// Passes drawn with the marking pass so far (`Tuning::marking_below` decides each).
    pub marked_passes: u32,
    /// The share of the patches the last shot lit (`observe`); none before the first readback.
    lit: Option<lit_share::LitShare>,
}

impl ReconstructionPass {
    /// The pass for `scene` laid out as `layout`, serving up to `options.shooters_per_pass`
    /// shooters a pass (and, with `Tuning::compile_choices`, only `options`' choices of form
    /// factor, visibility kind and robust test).
    pub fn new(
        ctx: &GlContext,
        scene: &Scene,
        layout: &PatchLayout,
        options: &SolveOptions,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let (width, height) = (layout.atlas_width as i32, layout.atlas_height as i32);
        let planes = PolygonPlanes::new(ctx, scene)?;
        let programs = Programs::new(ctx, options)?;
        let receivers = Receivers::new(scene, layout);
        let squares = Squares::new(gl, width, height)?;
        let patches = PatchData::new(gl, width, height)?;
        let target = Renderbuffers::new(ctx, width, height)?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(NAME)?;
        Ok(ReconstructionPass {
            programs,
            target,
            patches,
            planes,
            receivers,
            squares,
            touched: Vec::new(),
            quad_passes: 0,
            marked_passes: 0,
            lit: None,
        })
    }

    /// Rasterise every patch's geometry into the patch textures, then write each patch's emitted
    /// radiance (and its polygon ID in alpha) into both attachments.
    pub fn emit(&self, ctx: &GlContext, mesh: &Mesh) -> Result<(), GlError> {
        self.patches.rasterise(ctx, mesh)?;
        self.target.begin(ctx, true);
        self.programs.emission.use_program();
        mesh.draw();
        ctx.check(INIT_NAME)
    }

    /// The receivers to draw for `shooters` (`Receivers::select`), covered by aligned squares of
    /// whole 4×4 blocks, split by the shader that draws them; `touched` gets the receivers and
    /// the shooters.
    fn select_receivers(&mut self, shooters: &[Shooter], tuning: &Tuning) {
        self.receivers.select(shooters, tuning, &mut self.touched);
        let (clipped, above) = Receivers::shaders(tuning);
        self.squares.build(
            self.receivers.flags(),
            self.receivers.blocks_wide(),
            tuning.squares_as_points,
            clipped,
            above,
        );
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
        if let Some(compiled) = self.programs.compiled {
            if compiled != Choices::of(options) {
                return Err(GlError::Limit(format!(
                    "the reconstruction programs were compiled for {compiled:?}, not for {:?}",
                    Choices::of(options)
                )));
            }
        }
        let count = shooters.len();
        let slots = self.programs.shooters;
        if count == 0 || count > slots {
            return Err(GlError::Limit(format!(
                "{count} shooters in one reconstruction pass; it was set up for 1 to {slots}"
            )));
        }
        let mut tuning = options.tuning;
        let lit = self.lit_share();
        tuning.marking_pass &= tuning.marks_after(lit);
        if let Some(l) = &mut self.lit {
            l.passed();
        }
        self.marked_passes += tuning.marking_pass as u32;
        self.select_receivers(shooters, &tuning);
        // The programs serve `slots` shooters. A pass with fewer (a step's last polygons, or a
        // polygon whose cells fill the pass alone) fills the other slots with copies of its
        // first shooter that carry no energy and own no texels, seeing through its item
        // buffer: they add exactly zero and mark only what it marks. One set of programs
        // rather than one per count: compiling them all cost the set-up more than the few
        // short passes cost the loop.
        let idle = Shooter {
            energy: glam::Vec3::ZERO,
            texels: [0; 4],
            remainder: glam::Vec3::ZERO,
            ..shooters[0]
        };
        let shooters: Vec<Shooter> = (shooters.iter().copied())
            .chain(std::iter::repeat_n(idle, slots - count))
            .collect();
        let shooters = &shooters[..];
        // When every texel is recomputed from the textures this pass, nothing of the last pass
        // stays in the renderbuffers.
        self.target.begin(ctx, tuning.writes_every_texel());
        // Shooter 0's item buffer on unit 0, the others' on units 7, 8, … (the idle ones get
        // shooter 0's).
        let units: Vec<i32> = (0..slots)
            .map(|k| if k == 0 { 0 } else { 6 + k as i32 })
            .collect();
        for (k, &unit) in units.iter().enumerate() {
            let slot = if k < count { k } else { 0 };
            visibility.slot_texture(slot).bind(unit as u32);
        }
        lightmaps.radiosity.bind(1);
        lightmaps.unshot.bind(2);
        self.planes.texture.bind(3);
        self.patches.bind(4);
        let gl = &ctx.gl;
        let points = self.squares.as_points();
        unsafe {
            let (w, h) = self.squares.viewport;
            gl.viewport(0, 0, w, h);
            gl.enable(glow::SCISSOR_TEST);
            gl.scissor(0, 0, self.target.width, self.target.height);
            if points {
                gl.enable(glow::PROGRAM_POINT_SIZE);
            }
        }
        // The shooters' uniforms, one array element per shooter (the corners: MAX_CORNERS each).
        let texels = per_shooter(shooters, |s| s.texels.map(|t| t as i32));
        let remainders = per_shooter(shooters, |s| s.remainder.to_array());
        let hemi_res = per_shooter(shooters, |s| [s.hemi_res as i32]);
        let views = per_shooter(shooters, |s| s.view().to_cols_array());
        let positions = per_shooter(shooters, |s| s.position.to_array());
        let normals = per_shooter(shooters, |s| s.normal.to_array());
        let energies = per_shooter(shooters, |s| s.energy.to_array());
        let ids = per_shooter(shooters, |s| [s.polygon as f32]);
        let corners: Vec<f32> = (shooters.iter())
            .flat_map(|s| s.corners.iter().flat_map(|v| v.to_array()))
            .collect();
        let corner_counts = per_shooter(shooters, |s| [s.corner_count as i32]);
        let areas = per_shooter(shooters, |s| [s.area]);
        let planes = &self.planes;
        let programs = &self.programs.for_slots;
        let uniforms = |p: &Program| {
            p.use_program();
            p.set_i32("PatchPosition", 4);
            p.set_i32("PatchNormal", 5);
            p.set_i32("PatchReflectance", 6);
            p.set_i32("LightmapRadiosity", 1);
            p.set_i32("LightmapUnshot", 2);
            p.set_ivec4_array("ShooterTexels", &texels);
            p.set_vec3_array("ShooterRemainder", &remainders);
            p.set_i32_array("HemiRes", &hemi_res);
            p.set_i32_array("HemiItemBuffer", &units);
            p.set_mat4_array("ShooterView", &views);
            p.set_vec3_array("ShootPos", &positions);
            p.set_vec3_array("ShootNormal", &normals);
            p.set_vec3_array("ShootEnergy", &energies);
            p.set_f32_array("ShooterId", &ids);
            p.set_i32(
                "FormFactorKind",
                (options.form_factor == FormFactorKind::Polygon) as i32,
            );
            p.set_vec3_array("ShootCorners", &corners);
            p.set_i32_array("ShootCornerCount", &corner_counts);
            p.set_f32_array("ShootArea", &areas);
            p.set_i32(
                "HemiCube",
                (options.visibility == VisibilityKind::Hemicube) as i32,
            );
            p.set_i32("Robust", options.robust_visibility as i32);
            p.set_i32("PolygonPlanes", 3);
            p.set_i32("PlanesWidth", planes.texture.width);
            p.set_i32("PlanesShift", planes.texture.width.trailing_zeros() as i32);
            p.set_f32("PlaneSlack", planes.slack);
        };
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
            uniforms(&programs.marking);
            self.squares.draw_all();
            unsafe {
                gl.depth_func(glow::EQUAL);
                gl.depth_mask(false);
                gl.color_mask(true, true, true, true);
            }
        }
        let quads = shooters.iter().all(|s| s.corner_count == 4);
        let quad = (tuning.unroll_quads && quads) as usize;
        self.quad_passes += quad as u32;
        let (clipping, not_clipping) = if tuning.marking_pass {
            (&programs.marked[quad], &programs.above[quad])
        } else {
            (&programs.literal[quad], &programs.literal[quad])
        };
        let [clipped, above] = self.squares.runs();
        for (p, (first, count)) in [(clipping, clipped), (not_clipping, above)] {
            if count > 0 {
                uniforms(p);
                self.squares.draw(first, count);
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
        self.squares.drawn()
    }

    /// Take the unshot atlas read back after a shot (or, the first time, after the emission):
    /// how much of it the shot lit decides whether the next pass marks first.
    pub fn observe(&mut self, unshot: &[f32]) {
        match &mut self.lit {
            Some(lit) => lit.observe(unshot),
            None => self.lit = Some(lit_share::LitShare::new(unshot)),
        }
    }

    /// The share of the patches each pass of the last shot lit at least, as `observe`
    /// estimated it (`LitShare::per_pass`).
    pub fn lit_share(&self) -> f32 {
        self.lit.as_ref().map_or(0.0, |l| l.per_pass())
    }

    /// How many texels the last pass's squares covered.
    pub fn texels_drawn(&self) -> usize {
        self.squares.texels()
    }

    /// Whether the last pass drew its squares as points (`Tuning::squares_as_points`, where the
    /// driver's points are large enough) rather than as triangle pairs.
    pub fn drew_points(&self) -> bool {
        self.squares.as_points()
    }

    /// Each polygon's lightmap rectangle [x0, y0, x1, y1) in the atlas.
    pub fn texels(&self) -> &[[u32; 4]] {
        self.receivers.texels()
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
        ctx.check(COPY_NAME)
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
        ctx.check(COPY_NAME)
    }
}
