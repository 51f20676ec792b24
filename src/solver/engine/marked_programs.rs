//! The engine's variants of `glsl/reconstruct.frag`, beside the paper's program (`Programs`):
//! the marking pass and the pass proper after it, the variant that does not clip the shooter,
//! and the programs for one and for a few shooters of a pass. Only the variants the tuning
//! draws are compiled.

use crate::gl::program::Source;
use crate::gl::{GlContext, GlError, Program};
use crate::solver::reconstruction::{compile, fragment, Choices, Variants};
use crate::solver::{SolveOptions, Tuning};

/// The engine's programs for one pass set-up.
pub(crate) struct MarkedPrograms {
    /// For every slot of a pass, with the marking pass (`Tuning::marking_pass`).
    pub for_slots: Option<ForSlots>,
    /// The programs for one shooter, drawn for each shooter of a pass over the blocks only it
    /// may reach (`Tuning::walk_receivers`, with several shooters a pass and the marking pass).
    pub one: Option<OneShooter>,
    /// The programs for two to [`FEW`] shooters, fewer than the pass's (`few[k - 2]` for k),
    /// drawn over the blocks that just those shooters of a pass may reach
    /// (`Tuning::few_shooter_programs`); empty without.
    pub few: Vec<FewShooters>,
}

/// The programs of a pass with the marking pass (`Tuning::marking_pass`), for all its slots.
pub(crate) struct ForSlots {
    /// The pass proper after a marking pass (`MARKED`: visibility already tested), clipping the
    /// shooter to each receiver's tangent plane.
    marked: Variants,
    /// The same, compiled for receivers that have the whole shooter above that plane (no
    /// clipping: a third fewer shader instructions on llvmpipe; see `glsl/reconstruct.frag`),
    /// with `Tuning::skip_needless_clipping`.
    above: Option<Variants>,
    /// The marking pass (`MARK`): writes depth where a texel can receive, so that
    /// the programs above shade only those texels' blocks.
    pub marking: Program,
}

impl ForSlots {
    /// The programs that shade the squares needing the shooter clipped to the receiver's plane
    /// and those that do not, after a marking pass; unrolled for quadrilateral shooters if
    /// `quad`, with the near field if `near` (`Variants::get`).
    pub fn shading(&self, quad: bool, near: bool) -> (&Program, &Program) {
        let above = self.above.as_ref().unwrap_or(&self.marked);
        (self.marked.get(quad, near), above.get(quad, near))
    }
}

/// `glsl/reconstruct.frag` compiled for one shooter (`SHOOTERS` 1), for the blocks that only one
/// shooter of a pass may reach (`Tuning::walk_receivers`).
pub(crate) struct OneShooter {
    /// The marking pass (`MARK`).
    pub marking: Program,
    /// The pass proper after it (`MARKED`), for any corner count and for quadrilaterals.
    pub marked: Variants,
}

/// The most shooters a few-shooter program serves (`Tuning::few_shooter_programs`). On Lost
/// Empire nine in ten of the blocks that several of a pass's eight shooters reach are reached by
/// two to four; programs for more would save little, and llvmpipe compiles each variant when
/// first drawn (about 0.13 s each without its shader cache).
pub(crate) const FEW: u32 = 4;

/// `glsl/reconstruct.frag` compiled for a few shooters (`SHOOTERS` 2 to [`FEW`]), for the blocks
/// that just those shooters of a pass may reach (`Tuning::few_shooter_programs`): the pass
/// proper after the marking pass, clipping the shooters to each receiver's plane, for any corner
/// count and for quadrilaterals.
pub(crate) struct FewShooters {
    pub marked: Variants,
}

impl MarkedPrograms {
    /// The variants `options.tuning` draws, with `compiled` choices (those of the paper's
    /// program, `Programs::compiled`).
    pub fn new(
        ctx: &GlContext,
        options: &SolveOptions,
        compiled: Option<Choices>,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let compile = |source: Source| compile(gl, source);
        let shooters = options.shooters_per_pass.max(1);
        let frag = || fragment(shooters, compiled);
        // The near field's variants only where face clusters shoot (`Variants`).
        let near = options.face_clusters;
        let marked = || frag().define("MARKED", 1);
        let above = || marked().define("SHOOTER_ABOVE", 1);
        let tuning: &Tuning = &options.tuning;
        let quads = tuning.unroll_quads;
        let for_slots = if tuning.marking_pass {
            Some(ForSlots {
                marked: Variants::new(&compile, &marked, quads, near)?,
                above: if tuning.skip_needless_clipping() {
                    Some(Variants::new(&compile, &above, quads, near)?)
                } else {
                    None
                },
                marking: compile(frag().define("MARK", 1))?,
            })
        } else {
            None
        };
        let one = if tuning.walk_receivers() && tuning.marking_pass && shooters > 1 {
            let marked = || fragment(1, compiled).define("MARKED", 1);
            Some(OneShooter {
                marking: compile(fragment(1, compiled).define("MARK", 1))?,
                marked: Variants::new(&compile, &marked, true, near)?,
            })
        } else {
            None
        };
        let few = if one.is_some() && tuning.few_shooter_programs() {
            (2..shooters.min(FEW + 1))
                .map(|k| {
                    let marked = || fragment(k, compiled).define("MARKED", 1);
                    Ok(FewShooters {
                        marked: Variants::new(&compile, &marked, true, near)?,
                    })
                })
                .collect::<Result<_, GlError>>()?
        } else {
            Vec::new()
        };
        Ok(MarkedPrograms {
            for_slots,
            one,
            few,
        })
    }
}
