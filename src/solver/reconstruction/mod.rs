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
//! covering them (`cover.rs`), with the programs of `programs.rs` and the texture units and
//! uniforms of `uniforms.rs`. With `Tuning::none()` (the paper's mode) every patch is drawn
//! every pass, into renderbuffers cleared first. The speed switches of `Tuning` run a marking
//! pass so that only the texels the shooter sees compute form factors (and can draw only the
//! receivers' blocks); the texels they leave alone keep the renderbuffers' values, which the
//! last copy also put into the textures.
//!
//! Two attachments: 0 = radiosity + ΔL, 1 = unshot + ΔL (zero for the texels that shoot).

mod cover;
mod lit_share;
mod patch_data;
mod programs;
mod receivers;
mod uniforms;

use super::engine::seen_receivers::Reach;
use super::pass_names::{ACCUMULATION, INITIALISATION, RECONSTRUCTION};
use super::visibility::VisibilityPass;
use super::{Shooter, SolveOptions, Tuning};
use crate::gl::faults::{self, Fault};
use crate::gl::{Framebuffer, GlContext, GlError, Mesh, Renderbuffer, Texture, TextureFormat};
use crate::patches::PatchLayout;
use crate::scene::Scene;
use cover::Squares;
use glow::HasContext;
use patch_data::{PatchData, PolygonPlanes};
use programs::{Choices, Programs};
use receivers::Receivers;
use uniforms::{Uniforms, UNITS};

/// How many runs of squares a pass can have: one bit of a block's mask each (`Squares::build`).
const RUNS: usize = 32;

/// The fewest shooter evaluations (blocks × shooters left out) for which a set of shooters gets a
/// draw of its own with a few-shooter program (`Tuning::few_shooter_programs`): below, the
/// draw's uniforms and state cost the main thread more than the rasteriser saves.
const MIN_SAVED: u32 = 64;

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
        fbo.check_complete(RECONSTRUCTION)?;
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

/// The reconstruction pass (3.2.2): every receiving patch's ΔL = ρ·F·E from the shooters whose
/// item buffers see it, drawn over the atlas into renderbuffers, then added to the lightmaps.
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
    /// The squares the marking pass draws for each shooter, when it marks shooter by shooter
    /// (`mark`).
    marks: Squares,
    /// With how many shooters the last `select_receivers` split the pass shooter by shooter
    /// (`marks`, and the squares' runs after the first two), if it did.
    by_shooter: Option<usize>,
    /// The polygons the last pass drew (receivers and the shooter): the only ones whose unshot
    /// energy it can have changed.
    pub touched: Vec<usize>,
    /// The sets of shooters (bits) whose blocks the last pass shaded with a program for just
    /// them (`Tuning::few_shooter_programs`), in the order of their runs.
    few: Vec<u8>,
    /// Blocks shaded so far by a program for fewer shooters than the pass's, several of them
    /// (`Tuning::few_shooter_programs`).
    pub few_shooter_blocks: u64,
    /// Passes drawn with the programs unrolled for quadrilateral shooters so far.
    pub quad_passes: u32,
    /// Passes drawn with the marking pass so far (`Tuning::marking_below` decides each).
    pub marked_passes: u32,
    /// The share of the patches the last shot lit (`observe`); none before the first readback.
    lit: Option<lit_share::LitShare>,
    /// Whether `observe` estimates it: only for the marking pass's rule (`Tuning::marking_below`).
    watches_lit: bool,
}

impl ReconstructionPass {
    /// The side of the square blocks of texels the pass draws whole.
    pub const BLOCK: u32 = cover::BLOCK;

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
        let marks = Squares::new(gl, width, height)?;
        let patches = PatchData::new(gl, width, height)?;
        let target = Renderbuffers::new(ctx, width, height)?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(RECONSTRUCTION)?;
        Ok(ReconstructionPass {
            programs,
            target,
            patches,
            planes,
            receivers,
            squares,
            marks,
            by_shooter: None,
            touched: Vec::new(),
            few: Vec::new(),
            few_shooter_blocks: 0,
            quad_passes: 0,
            marked_passes: 0,
            lit: None,
            watches_lit: options.tuning.marking_pass && options.tuning.marking_below < 100,
        })
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

    /// The receivers to draw for `shooters` (`Receivers::select`), covered by aligned squares of
    /// whole 4×4 blocks, split by the shader that draws them; `touched` gets the receivers and
    /// the shooters.
    fn select_receivers(
        &mut self,
        shooters: &[Shooter],
        tuning: &Tuning,
        visibility: &VisibilityPass,
    ) {
        // Each shooter's receivers, if the walk found them for every one
        // (`Tuning::walk_receivers`).
        let seen: Option<Vec<&Reach>> = if tuning.walk_receivers {
            (0..shooters.len())
                .map(|k| visibility.receivers_seen(k))
                .collect()
        } else {
            None
        };
        let seen = seen.as_deref();
        self.receivers
            .select(shooters, tuning, seen, &mut self.touched);
        let (clipped, above) = Receivers::shaders(tuning);
        let wide = self.receivers.blocks_wide();
        let points = tuning.squares_as_points;
        let flags = self.receivers.flags();
        // Shooter by shooter where the walk found each one's reach (and this pass marks): each
        // marks only the blocks it may reach, and the blocks that only one shooter may reach
        // are shaded by it alone. Lost Empire's shots each reach a quarter of the atlas or less,
        // eight of them most of it, and half the blocks they reach only one of them reaches.
        self.by_shooter = match (self.receivers.shooter_bits(), tuning.marking_pass) {
            (Some(_), true) if self.programs.one.is_some() => Some(shooters.len()),
            _ => None,
        };
        // The pass proper's runs as bits of a mask per block: 0 and 1 the blocks to shade with
        // the clipping shader and without; shooter by shooter, those only for the blocks several
        // shooters reach, 2 + k those only shooter k reaches, and 2 + count + j those only the
        // shooters of set `few[j]` reach (`Tuning::few_shooter_programs`).
        self.few.clear();
        let Some(count) = self.by_shooter else {
            let runs: Vec<u32> = (flags.iter())
                .map(|f| clipped(f) as u32 | (above(f) as u32) << 1)
                .collect();
            self.squares.build(&runs, wide, points, 2);
            return;
        };
        let bits = self.receivers.shooter_bits().expect("checked above");
        // The sets of shooters whose blocks the few-shooter programs shade, each with a run
        // after the shooters' own (blocks that need no clipping stay with the pass's program,
        // which has the variant for them).
        self.few = self.few_shooter_sets(flags, bits, &clipped);
        let mut set_of = [0u8; 256];
        for (j, &set) in self.few.iter().enumerate() {
            set_of[set as usize] = j as u8 + 1;
        }
        let runs: Vec<u32> = (flags.iter().zip(bits))
            .map(|(f, &b)| match b.count_ones() {
                0 => 0,
                1 if *f != 0 => 1 << (2 + b.trailing_zeros()),
                1 => 0,
                _ => match set_of[b as usize] as usize {
                    j if j > 0 && clipped(f) => 1 << (2 + count + j - 1),
                    _ => clipped(f) as u32 | (above(f) as u32) << 1,
                },
            })
            .collect();
        self.few_shooter_blocks += (flags.iter().zip(bits))
            .filter(|&(f, &b)| clipped(f) && set_of[b as usize] != 0)
            .count() as u64;
        // The marks' runs are the shooters' own bits.
        let marks: Vec<u32> = bits.iter().map(|&b| b as u32).collect();
        self.squares
            .build(&runs, wide, points, 2 + count + self.few.len());
        self.marks.build(&marks, wide, points, count);
    }

    /// The sets of shooters (bit k: shooter k of the pass) whose blocks a program for just them
    /// shades (`Tuning::few_shooter_programs`): of the sets of two to `FEW` shooters that
    /// alone reach some blocks to shade with clipping (`clipped`), those that save the most
    /// shooter evaluations (blocks × shooters left out), as many as the cover's runs hold, none
    /// that saves fewer than `MIN_SAVED`.
    fn few_shooter_sets(
        &self,
        flags: &[u8],
        bits: &[u8],
        clipped: impl Fn(&u8) -> bool,
    ) -> Vec<u8> {
        let few = self.programs.few.len() as u32;
        if few == 0 {
            return Vec::new();
        }
        let slots = self.programs.shooters as u32;
        let mut blocks = [0u32; 256];
        for (f, &b) in flags.iter().zip(bits) {
            if clipped(f) {
                blocks[b as usize] += 1;
            }
        }
        let mut sets: Vec<(u32, u8)> = (0..=255u8)
            .filter(|b| (2..2 + few).contains(&b.count_ones()))
            .map(|b| (blocks[b as usize] * (slots - b.count_ones()), b))
            .filter(|&(saved, _)| saved >= MIN_SAVED)
            .collect();
        sets.sort_unstable_by(|a, b| b.cmp(a));
        let room = RUNS - 2 - self.by_shooter.unwrap_or(0);
        sets.iter().take(room).map(|&(_, b)| b).collect()
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
        let tuning = self.tuning_of_pass(options.tuning);
        self.select_receivers(shooters, &tuning, visibility);
        let slots = self.with_idle_slots(shooters);
        // When every texel is recomputed from the textures this pass, nothing of the last pass
        // stays in the renderbuffers.
        self.target.begin(ctx, tuning.writes_every_texel());
        self.bind_textures(visibility, lightmaps, shooters.len());
        self.begin_squares(ctx);
        let uniforms = Uniforms::new(&slots, options, &self.planes);
        // Shooter by shooter (`select_receivers`): each shooter's own uniforms, for its marks
        // and for the blocks it alone reaches.
        let each: Option<Vec<Uniforms>> = self.by_shooter.map(|_| {
            (shooters.iter())
                .map(|s| Uniforms::new(std::slice::from_ref(s), options, &self.planes))
                .collect()
        });
        if tuning.marking_pass {
            self.mark(ctx, &uniforms, each.as_deref(), visibility);
        }
        let quad = tuning.unroll_quads && slots.iter().all(|s| s.corner_count == 4);
        self.quad_passes += quad as u32;
        let (clipping, not_clipping) = self.programs.for_slots.shading(tuning.marking_pass, quad);
        let [clipped, above] = [self.squares.run(0), self.squares.run(1)];
        for (p, (first, count)) in [(clipping, clipped), (not_clipping, above)] {
            if count > 0 {
                uniforms.set(p);
                self.squares.draw(first, count);
            }
        }
        if let Some(each) = &each {
            self.shade_alone(each, shooters, visibility, tuning.unroll_quads);
        }
        self.shade_few(shooters, options, visibility, tuning.unroll_quads);
        self.end_squares(ctx);
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

    /// `tuning` for this pass: the marking pass only if the last shot lit little enough
    /// (`Tuning::marking_below`), counted in `marked_passes`.
    fn tuning_of_pass(&mut self, mut tuning: Tuning) -> Tuning {
        let lit = self.lit_share();
        tuning.marking_pass &= tuning.marks_after(lit);
        if let Some(l) = &mut self.lit {
            l.passed();
        }
        self.marked_passes += tuning.marking_pass as u32;
        tuning
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

    /// Set the viewport and scissor for the squares (and points of any size, if drawn as
    /// points).
    fn begin_squares(&self, ctx: &GlContext) {
        let gl = &ctx.gl;
        unsafe {
            let (w, h) = self.squares.viewport;
            gl.viewport(0, 0, w, h);
            gl.enable(glow::SCISSOR_TEST);
            gl.scissor(0, 0, self.target.width, self.target.height);
            if self.squares.as_points() {
                gl.enable(glow::PROGRAM_POINT_SIZE);
            }
        }
    }

    /// The marking pass: depth 1 cleared, the squares' depth (½) written where a texel can
    /// receive or shoots, nothing else; then depth test EQUAL without writing, so that the pass
    /// proper shades those texels only.
    ///
    /// With the blocks each shooter may reach (`Tuning::walk_receivers`; `each`: each shooter's
    /// uniforms), each shooter marks its own blocks with the one-shooter program, its item
    /// buffer on the first shooter's unit: the same marks (a texel is marked if any shooter
    /// marks it), for a visibility test per reached texel instead of one per shooter on every
    /// drawn texel.
    fn mark(
        &self,
        ctx: &GlContext,
        uniforms: &Uniforms,
        each: Option<&[Uniforms]>,
        visibility: &VisibilityPass,
    ) {
        let gl = &ctx.gl;
        unsafe {
            gl.depth_mask(true);
            gl.clear_depth_f64(1.0);
            gl.clear(glow::DEPTH_BUFFER_BIT);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::ALWAYS);
            gl.color_mask(false, false, false, false);
        }
        match (each, &self.programs.one) {
            (Some(each), Some(one)) => {
                for (k, own) in each.iter().enumerate() {
                    let (first, count) = self.marks.run(k);
                    if count == 0 {
                        continue;
                    }
                    visibility.slot_texture(k).bind(UNITS.item_buffers[0]);
                    own.set(&one.marking);
                    self.marks.draw(first, count);
                }
                visibility.slot_texture(0).bind(UNITS.item_buffers[0]);
            }
            _ => {
                uniforms.set(self.programs.for_slots.marking());
                self.squares.draw_all();
            }
        }
        unsafe {
            gl.depth_func(glow::EQUAL);
            gl.depth_mask(false);
            gl.color_mask(true, true, true, true);
        }
    }

    /// The pass proper over the blocks only one shooter may reach (`select_receivers`; `each`:
    /// each shooter's uniforms), each by that shooter alone, with its item buffer on the first
    /// shooter's unit: the same sums, bit for bit, since every other shooter adds exactly zero
    /// there (`seen_receivers`).
    fn shade_alone(
        &self,
        each: &[Uniforms],
        shooters: &[Shooter],
        visibility: &VisibilityPass,
        unroll_quads: bool,
    ) {
        let Some(one) = &self.programs.one else {
            return;
        };
        for (k, (own, shooter)) in each.iter().zip(shooters).enumerate() {
            let (first, count) = self.squares.run(2 + k);
            if count == 0 {
                continue;
            }
            let quad = unroll_quads && shooter.corner_count == 4;
            visibility.slot_texture(k).bind(UNITS.item_buffers[0]);
            own.set(&one.marked[quad as usize]);
            self.squares.draw(first, count);
        }
        visibility.slot_texture(0).bind(UNITS.item_buffers[0]);
    }

    /// The pass proper over the blocks each set of `self.few` (`select_receivers`) alone may
    /// reach, by the program for that many shooters, given just those shooters' uniforms and
    /// item buffers (in their order in the pass): the same sums, bit for bit, since every other
    /// shooter adds exactly +0.0 there, as in `shade_alone`.
    fn shade_few(
        &self,
        shooters: &[Shooter],
        options: &SolveOptions,
        visibility: &VisibilityPass,
        unroll_quads: bool,
    ) {
        let base = 2 + self.by_shooter.unwrap_or(0);
        for (j, &set) in self.few.iter().enumerate() {
            let members: Vec<usize> = (0..shooters.len()).filter(|k| set >> k & 1 != 0).collect();
            let programs = &self.programs.few[members.len() - 2];
            let chosen: Vec<Shooter> = members.iter().map(|&k| shooters[k]).collect();
            let quad = (unroll_quads && chosen.iter().all(|s| s.corner_count == 4)) as usize;
            for (slot, &k) in members.iter().enumerate() {
                visibility.slot_texture(k).bind(UNITS.item_buffers[slot]);
            }
            let (first, count) = self.squares.run(base + j);
            if count > 0 {
                Uniforms::new(&chosen, options, &self.planes).set(&programs.marked[quad]);
                self.squares.draw(first, count);
            }
        }
        // Each unit back to its own shooter's item buffer, as `bind_textures` left them.
        if !self.few.is_empty() {
            for (k, &unit) in UNITS.item_buffers[..self.programs.shooters]
                .iter()
                .enumerate()
            {
                let slot = if k < shooters.len() { k } else { 0 };
                visibility.slot_texture(slot).bind(unit);
            }
        }
    }

    /// Undo `begin_squares` and `mark`'s state.
    fn end_squares(&self, ctx: &GlContext) {
        let gl = &ctx.gl;
        unsafe {
            gl.disable(glow::PROGRAM_POINT_SIZE);
            gl.disable(glow::DEPTH_TEST);
            gl.disable(glow::SCISSOR_TEST);
            gl.active_texture(glow::TEXTURE0);
        }
    }

    /// The squares the last pass drew with the clipping shader and with the one that does not
    /// clip.
    pub fn squares_drawn(&self) -> (usize, usize) {
        self.squares.drawn()
    }

    /// Take the unshot atlas read back after a shot (or, the first time, after the emission):
    /// how much of it the shot lit decides whether the next pass marks first.
    pub fn observe(&mut self, unshot: &[f32]) {
        if !self.watches_lit {
            return;
        }
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

    /// The patch position atlas (RGBA: position, polygon ID + 1; `emit` rasterises it).
    pub fn patch_positions(&self) -> Vec<f32> {
        let mut positions = Vec::new();
        self.patches.position.read_f32(&mut positions);
        positions
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
