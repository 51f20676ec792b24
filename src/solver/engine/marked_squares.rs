//! The llvmpipe engine's [`AtlasDraw`]: a reconstruction pass draws only the blocks that can
//! receive (`receivers.rs`: by where they lie, or by what the walk's item buffers let each shooter
//! reach), runs a marking pass first so that only the texels a shooter sees compute form factors,
//! marks and shades shooter by shooter where the walk found each one's reach, and shades the
//! blocks that a few shooters of a pass reach with programs for just those. The texels it leaves
//! alone keep the renderbuffers' values, which the last copy also put into the textures. Every
//! switch it reads is documented in [`Tuning`]; the same sums, bit for bit.

use super::cover::{begin_squares, end_squares, Squares};
use super::lit_share::LitShare;
use super::marked_programs::MarkedPrograms;
use super::receivers::Receivers;
use super::seen_receivers::Reach;
use crate::gl::{GlContext, GlError, Renderbuffer};
use crate::patches::PatchLayout;
use crate::scene::Scene;
use crate::solver::reconstruction::{has_parts, AtlasDraw, Pass, Uniforms, UNITS};
use crate::solver::visibility::VisibilityPass;
use crate::solver::{Shooter, SolveOptions, Tuning};
use glow::HasContext;
use std::any::Any;

/// How many runs of squares a pass can have: one bit of a block's mask each (`Squares::build`).
const RUNS: usize = 32;

/// The fewest shooter evaluations (blocks × shooters left out) for which a set of shooters gets a
/// draw of its own with a few-shooter program (`Tuning::few_shooter_programs`): below, the
/// draw's uniforms and state cost the main thread more than the rasteriser saves.
const MIN_SAVED: u32 = 64;

/// The engine's reconstruction draw.
pub(crate) struct MarkedSquares {
    /// The switches of the solve.
    tuning: Tuning,
    /// The switches of the current pass (`tuning_of_pass`: the marking pass or not).
    pass_tuning: Tuning,
    programs: MarkedPrograms,
    /// How many shooters the programs serve.
    shooters: usize,
    /// The marking pass's depth buffer, attached to the pass's FBO.
    marks_depth: Renderbuffer,
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
    /// The sets of shooters (bits) whose blocks the last pass shaded with a program for just
    /// them (`Tuning::few_shooter_programs`), in the order of their runs.
    few: Vec<u8>,
    /// Blocks shaded so far by a program for fewer shooters than the pass's, several of them
    /// (`Tuning::few_shooter_programs`).
    pub few_shooter_blocks: u64,
    /// Passes drawn with the marking pass so far (`Tuning::marking_below` decides each).
    pub marked_passes: u32,
    /// The share of the patches the last shot lit (`observe`); none before the first readback.
    lit: Option<LitShare>,
    /// Whether `observe` estimates it: only for the marking pass's rule (`Tuning::marking_below`).
    watches_lit: bool,
}

impl MarkedSquares {
    /// Whether `tuning` asks the reconstruction for anything the paper's whole-atlas draw does
    /// not do.
    pub fn wanted(tuning: &Tuning) -> bool {
        tuning.marking_pass
            || tuning.receivers_only()
            || tuning.walk_receivers()
            || tuning.squares_as_points
    }

    /// The draw for `scene` laid out as `layout` (without gutters) under `options`, whose
    /// paper's programs were compiled with `compiled` choices.
    pub fn new(
        ctx: &GlContext,
        scene: &Scene,
        layout: &PatchLayout,
        options: &SolveOptions,
        compiled: Option<crate::solver::reconstruction::Choices>,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let (width, height) = (layout.atlas_width as i32, layout.atlas_height as i32);
        let tuning = options.tuning;
        Ok(MarkedSquares {
            tuning,
            pass_tuning: tuning,
            programs: MarkedPrograms::new(ctx, options, compiled)?,
            shooters: options.shooters_per_pass.max(1) as usize,
            marks_depth: Renderbuffer::new(gl, glow::DEPTH_COMPONENT32F, width, height)?,
            receivers: Receivers::new(scene, layout),
            squares: Squares::new(gl, width, height)?,
            marks: Squares::new(gl, width, height)?,
            by_shooter: None,
            few: Vec::new(),
            few_shooter_blocks: 0,
            marked_passes: 0,
            lit: None,
            watches_lit: tuning.marking_pass && tuning.marking_below < 100,
        })
    }

    /// The share of the patches each pass of the last shot lit at least, as `observe`
    /// estimated it (`LitShare::per_pass`).
    pub fn lit_share(&self) -> f32 {
        self.lit.as_ref().map_or(0.0, |l| l.per_pass())
    }

    /// `tuning` for this pass: the marking pass only if the last shot lit little enough
    /// (`Tuning::marking_below`), counted in `marked_passes`.
    fn tuning_of_pass(&mut self) -> Tuning {
        let mut tuning = self.tuning;
        let lit = self.lit_share();
        tuning.marking_pass &= tuning.marks_after(lit);
        if let Some(l) = &mut self.lit {
            l.passed();
        }
        self.marked_passes += tuning.marking_pass as u32;
        tuning
    }

    /// The receivers to draw for `shooters` (`Receivers::select`), covered by aligned squares of
    /// whole 4×4 blocks, split by the shader that draws them; `touched` gets the receivers and
    /// the shooters.
    fn select_receivers(
        &mut self,
        shooters: &[Shooter],
        visibility: &VisibilityPass,
        touched: &mut Vec<usize>,
    ) {
        let tuning = self.pass_tuning;
        // Each shooter's receivers, if the walk found them for every one
        // (`Tuning::walk_receivers`).
        let seen: Option<Vec<&Reach>> = if tuning.walk_receivers() {
            (0..shooters.len())
                .map(|k| visibility.receivers_seen(k))
                .collect()
        } else {
            None
        };
        let seen = seen.as_deref();
        self.receivers.select(shooters, &tuning, seen, touched);
        let (clipped, above) = Receivers::shaders(&tuning);
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
        let slots = self.shooters as u32;
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
                let for_slots = self.programs.for_slots.as_ref();
                let for_slots = for_slots.expect("the marking pass's programs, with marking_pass");
                uniforms.set(&for_slots.marking);
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
    fn shade_alone(&self, each: &[Uniforms], shooters: &[Shooter], visibility: &VisibilityPass) {
        let Some(one) = &self.programs.one else {
            return;
        };
        for (k, (own, shooter)) in each.iter().zip(shooters).enumerate() {
            let (first, count) = self.squares.run(2 + k);
            if count == 0 {
                continue;
            }
            let quad = self.tuning.unroll_quads && shooter.corner_count == 4;
            visibility.slot_texture(k).bind(UNITS.item_buffers[0]);
            let near = shooter.parts.count > 0;
            own.set(one.marked.get(quad, near));
            self.squares.draw(first, count);
        }
        visibility.slot_texture(0).bind(UNITS.item_buffers[0]);
    }

    /// The pass proper over the blocks each set of `self.few` (`select_receivers`) alone may
    /// reach, by the program for that many shooters, given just those shooters' uniforms and
    /// item buffers (in their order in the pass): the same sums, bit for bit, since every other
    /// shooter adds exactly +0.0 there, as in `shade_alone`.
    fn shade_few(&self, pass: &Pass) {
        let (shooters, visibility) = (pass.shooters, pass.visibility);
        let base = 2 + self.by_shooter.unwrap_or(0);
        for (j, &set) in self.few.iter().enumerate() {
            let members: Vec<usize> = (0..shooters.len()).filter(|k| set >> k & 1 != 0).collect();
            let programs = &self.programs.few[members.len() - 2];
            let chosen: Vec<Shooter> = members.iter().map(|&k| shooters[k]).collect();
            let unroll = self.tuning.unroll_quads;
            let quad = unroll && chosen.iter().all(|s| s.corner_count == 4);
            for (slot, &k) in members.iter().enumerate() {
                visibility.slot_texture(k).bind(UNITS.item_buffers[slot]);
            }
            let (first, count) = self.squares.run(base + j);
            if count > 0 {
                let program = programs.marked.get(quad, has_parts(&chosen));
                Uniforms::new(&chosen, pass.options, pass.planes).set(program);
                self.squares.draw(first, count);
            }
        }
        // Each unit back to its own shooter's item buffer, as the pass bound them.
        if !self.few.is_empty() {
            for (k, &unit) in UNITS.item_buffers[..self.shooters].iter().enumerate() {
                let slot = if k < shooters.len() { k } else { 0 };
                visibility.slot_texture(slot).bind(unit);
            }
        }
    }
}

impl MarkedSquares {
    /// The squares the last pass drew.
    pub fn squares(&self) -> &Squares {
        &self.squares
    }
}

impl AtlasDraw for MarkedSquares {
    fn depth(&self) -> Option<&Renderbuffer> {
        Some(&self.marks_depth)
    }

    fn select(
        &mut self,
        shooters: &[Shooter],
        visibility: &VisibilityPass,
        touched: &mut Vec<usize>,
    ) -> bool {
        self.pass_tuning = self.tuning_of_pass();
        self.select_receivers(shooters, visibility, touched);
        self.pass_tuning.writes_every_texel()
    }

    fn draw(&mut self, ctx: &GlContext, pass: &Pass) {
        let tuning = self.pass_tuning;
        let (shooters, visibility) = (pass.shooters, pass.visibility);
        begin_squares(ctx, &self.squares, pass.size);
        // Shooter by shooter (`select_receivers`): each shooter's own uniforms, for its marks
        // and for the blocks it alone reaches.
        let each: Option<Vec<Uniforms>> = self.by_shooter.map(|_| {
            (shooters.iter())
                .map(|s| Uniforms::new(std::slice::from_ref(s), pass.options, pass.planes))
                .collect()
        });
        if tuning.marking_pass {
            self.mark(ctx, pass.uniforms, each.as_deref(), visibility);
        }
        let paper = pass.programs.paper.get(pass.quad, pass.near);
        let (clipping, not_clipping) = match (&self.programs.for_slots, tuning.marking_pass) {
            (Some(marked), true) => marked.shading(pass.quad, pass.near),
            _ => (paper, paper),
        };
        let [clipped, above] = [self.squares.run(0), self.squares.run(1)];
        for (p, (first, count)) in [(clipping, clipped), (not_clipping, above)] {
            if count > 0 {
                pass.uniforms.set(p);
                self.squares.draw(first, count);
            }
        }
        if let Some(each) = &each {
            self.shade_alone(each, shooters, visibility);
        }
        self.shade_few(pass);
        end_squares(ctx);
    }

    /// How much of the unshot atlas the shot lit decides whether the next pass marks first.
    fn observe(&mut self, unshot: &[f32]) {
        if !self.watches_lit {
            return;
        }
        match &mut self.lit {
            Some(lit) => lit.observe(unshot),
            None => self.lit = Some(LitShare::new(unshot)),
        }
    }

    fn texels_drawn(&self) -> usize {
        self.squares.texels()
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
