//! The llvmpipe engine: what the GPU solver does besides the paper, for Mesa's software
//! rasteriser, which is a CPU (docs/llvmpipe.md). None of it is needed to read the paper's
//! passes (`visibility/`, `reconstruction/`), which call it only through their interfaces:
//!
//! - what fills a visibility pass's item buffers ([`ItemBufferFill`]): [`CulledViews`]
//!   leaves out what cannot show (`culling`: bounding spheres, `solids`, `samples`, and the
//!   hidden-polygon walk of `occlusion` over the `box_tree`), draws coplanar neighbours as
//!   `plates`, or writes the item buffer itself; `seen_receivers` finds from it what each shot
//!   may reach;
//! - what a reconstruction pass draws and with which program (`AtlasDraw`): `MarkedSquares`
//!   draws only the blocks that can receive (`receivers`), after a marking pass whose rule
//!   watches the share of patches each shot lit (`lit_share`), with the variants of
//!   `marked_programs` (for one and for a few shooters of a pass too).
//!
//! Which of it runs is switched by [`Tuning`]; the constructors below read a tuning and give the
//! paper's parts where it asks for nothing of the engine.

mod box_tree;
mod cover;
pub mod culled_views;
pub mod culling;
mod lit_share;
mod marked_programs;
mod marked_squares;
pub mod occlusion;
pub mod plates;
mod receivers;
pub mod samples;
pub mod seen_receivers;
pub mod solids;

pub use culled_views::CulledViews;
use marked_squares::MarkedSquares;

use super::reconstruction::{AtlasDraw, Choices, ProgramVariants, ReconstructionPass, WholeAtlas};
use super::visibility::{
    DepthFormat, DrawnViews, FaceArea, ItemBufferFill, ViewSetup, VisibilityPass,
};
use super::{SolveOptions, Tuning, VisibilityKind};
use crate::gl::{GlContext, GlError};
use crate::patches::PatchLayout;
use crate::scene::Scene;
use plates::Plates;
use seen_receivers::{Reach, SeenReceivers};

/// How `tuning` draws the views.
pub fn view_setup(tuning: &Tuning) -> ViewSetup {
    ViewSetup {
        depth: if tuning.float_depth {
            DepthFormat::Float32
        } else {
            DepthFormat::Int24
        },
        faces: if tuning.half_side_faces {
            FaceArea::AboveHorizon
        } else {
            FaceArea::Whole
        },
        guard_band: tuning.guard_band,
    }
}

/// The visibility pass as a [`Tuning`] asks for it: the paper's drawn views, or the engine's
/// [`CulledViews`].
impl VisibilityPass {
    /// A pass with one item buffer (the paper's: one shooter per pass).
    pub fn new(
        ctx: &GlContext,
        kind: VisibilityKind,
        resolution: u32,
        tuning: Tuning,
        scene: &Scene,
    ) -> Result<Self, GlError> {
        Self::with_slots(ctx, kind, resolution, tuning, scene, 1)
    }

    /// A pass with `slots` item buffers, one for each shooter of one reconstruction pass
    /// (`SolveOptions::shooters_per_pass`; `run_in_slot`).
    pub fn with_slots(
        ctx: &GlContext,
        kind: VisibilityKind,
        resolution: u32,
        tuning: Tuning,
        scene: &Scene,
        slots: u32,
    ) -> Result<Self, GlError> {
        // Passes of several shooters walk every side (`Tuning::walk_up_to`): the reach the walk
        // finds lets their reconstruction skip most of the atlas, which a drawn slot forfeits
        // for the whole pass.
        let tuning = if slots > 1 {
            Tuning {
                walk_up_to: 0,
                ..tuning
            }
        } else {
            tuning
        };
        let fill: Box<dyn ItemBufferFill> = if CulledViews::wanted(&tuning, kind) {
            Box::new(CulledViews::new(
                ctx, scene, kind, resolution, tuning, slots,
            ))
        } else {
            Box::new(DrawnViews)
        };
        let setup = view_setup(&tuning);
        Self::with_fill(ctx, kind, resolution, setup, scene, slots, fill)
    }

    /// The engine's fill, if this pass has it.
    fn engine(&self) -> Option<&CulledViews> {
        self.fill().as_any().downcast_ref()
    }

    /// Merge coplanar polygons outside the solids into plates (`Tuning::plates`; hemicube only:
    /// the hemispherical projection needs small polygons, and bigger ones would curve more). The
    /// caller then draws a mesh made by `Plates::vertex_data` from the plates returned; the item
    /// buffer shows each plate under its representative's ID. Only for the robust visibility
    /// test, which reads the shown polygon's plane, not its ID alone. `None` without the
    /// engine: the caller draws the scene's own mesh.
    pub fn merge_plates(&mut self, scene: &Scene) -> Option<&Plates> {
        let engine: &mut CulledViews = self.fill_mut().as_any_mut().downcast_mut()?;
        Some(engine.merge_plates(scene))
    }

    /// The polygon whose ID the item buffer shows where polygon `p` is seen.
    pub fn shown_as(&self, p: usize) -> usize {
        self.engine().map_or(p, |e| e.plates.representative[p])
    }

    /// How many times a view left a polygon out as falling between the pixel centres, over all
    /// passes (`Tuning::cull_between_samples`).
    pub fn missed(&self) -> u64 {
        self.engine().map_or(0, |e| e.culling.missed)
    }

    /// How many polygons in front of a shooter were left out as hidden, over all passes
    /// (`Tuning::cull_hidden`), where the views were drawn: a walk that writes the item buffer
    /// (`Tuning::walk_item_buffers`) does not list the polygons in front of the shooter, so it
    /// counts none.
    pub fn hidden(&self) -> u64 {
        self.engine().map_or(0, |e| e.culling.hidden)
    }

    /// Find the receivers of every shot whose item buffer the walk writes from now on
    /// (`Tuning::walk_receivers`; `receivers_seen`).
    pub fn use_seen_receivers(&mut self, seen: SeenReceivers) {
        let engine = self.fill_mut().as_any_mut().downcast_mut::<CulledViews>();
        if let Some(engine) = engine {
            engine.use_seen_receivers(seen);
        }
    }

    /// What the last shot in slot `slot` may reach, when the walk wrote its item buffer and
    /// `use_seen_receivers` set up the test (`Tuning::walk_receivers`); `None` if not known.
    pub fn receivers_seen(&self, slot: usize) -> Option<&Reach> {
        self.engine()?.receivers.get(slot)?.as_ref()
    }
}

/// After the emission, with the patch positions rasterised: set up the receivers' test of the
/// walk (`Tuning::walk_receivers`, on the hemicube) for an atlas `width` texels wide. The
/// paper's passes need nothing.
pub fn after_emission(
    visibility: &mut VisibilityPass,
    reconstruction: &ReconstructionPass,
    scene: &Scene,
    options: &SolveOptions,
    width: usize,
) {
    let tuning = &options.tuning;
    if tuning.walk_receivers() && options.visibility == VisibilityKind::Hemicube {
        let positions = reconstruction.patch_positions();
        let block = cover::BLOCK as usize;
        visibility.use_seen_receivers(SeenReceivers::new(scene, &positions, width, block));
    }
}

/// Which variants of the paper's program `tuning` compiles.
pub fn program_variants(tuning: &Tuning) -> ProgramVariants {
    ProgramVariants {
        choices_compiled: tuning.compile_choices,
        quads: tuning.unroll_quads,
    }
}

/// The reconstruction pass as `options.tuning` asks for it: the paper's whole-atlas draw, or the
/// engine's `MarkedSquares`.
impl ReconstructionPass {
    /// The pass for `scene` laid out as `layout` (without gutters), serving up to
    /// `options.shooters_per_pass` shooters a pass (and, with `Tuning::compile_choices`, only
    /// `options`' choices of form factor, visibility kind and robust test).
    pub fn new(
        ctx: &GlContext,
        scene: &Scene,
        layout: &PatchLayout,
        options: &SolveOptions,
    ) -> Result<Self, GlError> {
        let tuning = &options.tuning;
        let variants = program_variants(tuning);
        let draw: Box<dyn AtlasDraw> = if MarkedSquares::wanted(tuning) {
            let compiled = variants.choices_compiled.then(|| Choices::of(options));
            let draw = MarkedSquares::new(ctx, scene, layout, options, compiled)?;
            Box::new(draw)
        } else {
            Box::new(WholeAtlas::new(&ctx.gl, layout)?)
        };
        Self::with_draw(ctx, scene, layout, options, variants, draw)
    }

    /// The engine's draw, if this pass has it.
    fn engine(&self) -> Option<&MarkedSquares> {
        self.atlas_draw().as_any().downcast_ref()
    }

    /// The squares the last pass drew with the clipping shader and with the one that does not
    /// clip (none without the engine's draw).
    pub fn squares_drawn(&self) -> (usize, usize) {
        self.engine().map_or((0, 0), |e| e.squares().drawn())
    }

    /// Whether the last pass drew its squares as points (`Tuning::squares_as_points`, where the
    /// driver's points are large enough) rather than as triangle pairs (the paper's draw:
    /// rectangles of triangle pairs).
    pub fn drew_points(&self) -> bool {
        self.engine().is_some_and(|e| e.squares().as_points())
    }

    /// Passes drawn with the marking pass so far (`Tuning::marking_below` decides each).
    pub fn marked_passes(&self) -> u32 {
        self.engine().map_or(0, |e| e.marked_passes)
    }

    /// Blocks shaded so far by a program for fewer shooters than the pass's, several of them
    /// (`Tuning::few_shooter_programs`).
    pub fn few_shooter_blocks(&self) -> u64 {
        self.engine().map_or(0, |e| e.few_shooter_blocks)
    }

    /// The share of the patches each pass of the last shot lit at least, as the marking rule
    /// estimated it (`Tuning::marking_below`; 0 without it).
    pub fn lit_share(&self) -> f32 {
        self.engine().map_or(0.0, |e| e.lit_share())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_and_gpu_profiles_get_the_papers_parts_and_none_of_the_engine() {
        for kind in [VisibilityKind::Hemicube, VisibilityKind::Hemisphere] {
            for tuning in [Tuning::none(), Tuning::gpu()] {
                assert!(!CulledViews::wanted(&tuning, kind), "{tuning:?}");
                assert!(!MarkedSquares::wanted(&tuning), "{tuning:?}");
            }
            assert!(CulledViews::wanted(&Tuning::llvmpipe(), kind));
        }
        assert!(MarkedSquares::wanted(&Tuning::llvmpipe()));
        // The paper's profile draws the views and compiles the program as the paper does.
        assert_eq!(view_setup(&Tuning::none()), ViewSetup::PAPER);
        assert_eq!(program_variants(&Tuning::none()), ProgramVariants::PAPER);
        // The GPU profile: the paper's views but for the half side faces, and two variants.
        let gpu = view_setup(&Tuning::gpu());
        assert_eq!((gpu.faces, gpu.guard_band), (FaceArea::AboveHorizon, 1));
        let variants = program_variants(&Tuning::gpu());
        assert!(variants.choices_compiled && variants.quads);
    }
}
