//! The reconstruction pass's programs: `glsl/reconstruct.frag` in its variants (the paper's one
//! program, and the tuned ones of the marking pass), with the per-shooter functions the shader
//! leaves to the host, and the emission shader of the initialisation.

use crate::gl::program::Source;
use crate::gl::{GlContext, GlError, Program};
use crate::glsl;
use crate::solver::mesh::ATTRIBUTES;
use crate::solver::{FormFactorKind, SolveOptions, VisibilityKind, MAX_SHOOTERS_PER_PASS};

/// The two outputs: 0 = radiosity + ΔL, 1 = unshot + ΔL (zero for the texels that shoot).
pub(super) const OUTPUTS: &[(u32, &str)] = &[(0, "NewRadiosity"), (1, "NewUnshot")];

/// The pass's programs: `glsl/reconstruct.frag` in its variants for one number of shooters per
/// pass (`SHOOTERS`), and the emission shader.
pub(super) struct Programs {
    /// For `shooters` shooters a pass (`SolveOptions::shooters_per_pass`); a pass with fewer
    /// pads the rest (`ReconstructionPass::run`).
    pub for_slots: ShooterPrograms,
    pub shooters: usize,
    /// The choices compiled into `for_slots` (`Tuning::compile_choices`); none: read from
    /// uniforms, so the programs serve any options.
    pub compiled: Option<Choices>,
    /// The programs for one shooter, drawn for each shooter of a pass over the blocks only it
    /// may reach (`Tuning::walk_receivers`, with several shooters a pass and the marking pass).
    pub one: Option<OneShooter>,
    /// The programs for two to [`FEW`] shooters, fewer than `shooters` (`few[k - 2]` for k),
    /// drawn over the blocks that just those shooters of a pass may reach
    /// (`Tuning::few_shooter_programs`); empty without.
    pub few: Vec<FewShooters>,
    /// Writes each patch's emitted radiance (and its polygon ID in alpha) at initialisation.
    pub emission: Program,
}

/// A program for any corner count, and (`Tuning::unroll_quads`) its variant for quadrilateral
/// shooters (`CORNERS` 4).
pub(super) struct Variants {
    any: Program,
    quads: Option<Program>,
}

impl Variants {
    /// `source` compiled by `compile`, and for quadrilaterals too if `quads`.
    fn new(
        compile: &dyn Fn(Source) -> Result<Program, GlError>,
        source: &dyn Fn() -> Source,
        quads: bool,
    ) -> Result<Self, GlError> {
        Ok(Variants {
            any: compile(source())?,
            quads: if quads {
                Some(compile(source().define("CORNERS", 4))?)
            } else {
                None
            },
        })
    }

    /// The one for quadrilaterals if `quad` and it was compiled, else the general one.
    fn get(&self, quad: bool) -> &Program {
        match (&self.quads, quad) {
            (Some(q), true) => q,
            _ => &self.any,
        }
    }
}

/// `glsl/reconstruct.frag` compiled for one number of shooters.
pub(super) struct ShooterPrograms {
    /// The shader as the paper has it: visibility, form factor and GL_ADD in one program.
    literal: Variants,
    /// The marking pass's programs (`Tuning::marking_pass`; the paper's mode builds none).
    marked: Option<MarkedPrograms>,
}

/// The programs of a pass with the marking pass (`Tuning::marking_pass`).
struct MarkedPrograms {
    /// The pass proper after a marking pass (`MARKED`: visibility already tested), clipping the
    /// shooter to each receiver's tangent plane.
    marked: Variants,
    /// The same, compiled for receivers that have the whole shooter above that plane (no
    /// clipping: a third fewer shader instructions on llvmpipe; see `glsl/reconstruct.frag`),
    /// with `Tuning::skip_needless_clipping`.
    above: Option<Variants>,
    /// The marking pass (`MARK`): writes depth where a texel can receive, so that
    /// the programs above shade only those texels' blocks.
    marking: Program,
}

impl ShooterPrograms {
    /// The programs that shade the squares needing the shooter clipped to the receiver's plane
    /// and those that do not: after a marking pass (`marked`) the `MARKED` variants, otherwise
    /// the paper's program for both; unrolled for quadrilateral shooters if `quad`.
    pub fn shading(&self, marked: bool, quad: bool) -> (&Program, &Program) {
        match (&self.marked, marked) {
            (Some(m), true) => {
                let above = m.above.as_ref().unwrap_or(&m.marked);
                (m.marked.get(quad), above.get(quad))
            }
            _ => (self.literal.get(quad), self.literal.get(quad)),
        }
    }

    /// The marking pass's program (built with `Tuning::marking_pass`).
    pub fn marking(&self) -> &Program {
        let m = self.marked.as_ref();
        &m.expect("the marking pass's programs are built with Tuning::marking_pass")
            .marking
    }
}

/// `glsl/reconstruct.frag` compiled for one shooter (`SHOOTERS` 1), for the blocks that only one
/// shooter of a pass may reach (`Tuning::walk_receivers`).
pub(super) struct OneShooter {
    /// The marking pass (`MARK`).
    pub marking: Program,
    /// The pass proper after it (`MARKED`), for any corner count and for quadrilaterals.
    pub marked: [Program; 2],
}

/// The most shooters a few-shooter program serves (`Tuning::few_shooter_programs`). On Lost
/// Empire nine in ten of the blocks that several of a pass's eight shooters reach are reached by
/// two to four; programs for more would save little, and llvmpipe compiles each variant when
/// first drawn (about 0.13 s each without its shader cache).
pub(super) const FEW: u32 = 4;

/// `glsl/reconstruct.frag` compiled for a few shooters (`SHOOTERS` 2 to [`FEW`]), for the blocks
/// that just those shooters of a pass may reach (`Tuning::few_shooter_programs`): the pass
/// proper after the marking pass, clipping the shooters to each receiver's plane, for any corner
/// count and for quadrilaterals.
pub(super) struct FewShooters {
    pub marked: [Program; 2],
}

/// A solve's fixed choices that `glsl/reconstruct.frag` branches on: the form factor, the
/// visibility kind and the robust test (the shader's `FormFactorKind`, `HemiCube` and `Robust`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Choices {
    polygon_form_factor: bool,
    hemicube: bool,
    robust: bool,
}

impl Choices {
    pub fn of(options: &SolveOptions) -> Self {
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
    pub fn new(ctx: &GlContext, options: &SolveOptions) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let squares_in = &[(0, "Corner"), (1, "Size")];
        let compile =
            |source: Source| Program::new(gl, glsl!("atlas.vert"), source, squares_in, OUTPUTS);
        let compiled = options.tuning.compile_choices.then(|| Choices::of(options));
        let shooters = options.shooters_per_pass.max(1);
        // The shooters' texture units (`uniforms::UNITS`) are counted out for so many.
        if shooters > MAX_SHOOTERS_PER_PASS {
            return Err(GlError::Limit(format!(
                "{shooters} shooters per reconstruction pass; at most {MAX_SHOOTERS_PER_PASS}"
            )));
        }
        let frag_for = |shooters: u32| {
            let source = glsl!("reconstruct.frag")
                .define("SHOOTERS", shooters as i32)
                .append(&per_shooter_functions(shooters as usize));
            match &compiled {
                Some(choices) => choices.define(source),
                None => source,
            }
        };
        let frag = || frag_for(shooters);
        let marked = || frag().define("MARKED", 1);
        let above = || marked().define("SHOOTER_ABOVE", 1);
        let tuning = &options.tuning;
        // Only the variants the tuning draws: the paper's mode compiles the one program.
        let quads = tuning.unroll_quads;
        let for_slots = ShooterPrograms {
            literal: Variants::new(&compile, &frag, quads)?,
            marked: if tuning.marking_pass {
                Some(MarkedPrograms {
                    marked: Variants::new(&compile, &marked, quads)?,
                    above: if tuning.skip_needless_clipping {
                        Some(Variants::new(&compile, &above, quads)?)
                    } else {
                        None
                    },
                    marking: compile(frag().define("MARK", 1))?,
                })
            } else {
                None
            },
        };
        let one = if tuning.walk_receivers && tuning.marking_pass && shooters > 1 {
            let marked = || frag_for(1).define("MARKED", 1);
            Some(OneShooter {
                marking: compile(frag_for(1).define("MARK", 1))?,
                marked: [compile(marked())?, compile(marked().define("CORNERS", 4))?],
            })
        } else {
            None
        };
        let few = if one.is_some() && tuning.few_shooter_programs {
            (2..shooters.min(FEW + 1))
                .map(|k| {
                    let marked = || frag_for(k).define("MARKED", 1);
                    Ok(FewShooters {
                        marked: [compile(marked())?, compile(marked().define("CORNERS", 4))?],
                    })
                })
                .collect::<Result<_, GlError>>()?
        } else {
            Vec::new()
        };
        Ok(Programs {
            for_slots,
            shooters: shooters as usize,
            compiled,
            one,
            few,
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

/// The bodies of the functions `glsl/reconstruct.frag` declares for its shooters one by one,
/// written out for `shooters` of them so that every array index is a constant (the shader's
/// comment above `main` shows them for two).
pub(super) fn per_shooter_functions(shooters: usize) -> String {
    let each = |line: &dyn Fn(usize) -> String| (0..shooters).map(line).collect::<String>();
    let any = (0..shooters)
        .map(|k| format!("Receives({k}, HemiItemBuffer[{k}])"))
        .collect::<Vec<_>>()
        .join(" || ");
    format!(
        "void ShootsFromEach(ivec2 texel)\n{{\n{}}}\n\
         bool ReceivesFromAny()\n{{\n    return {any};\n}}\n\
         vec3 ReceivedFromEach()\n{{\n    vec3 delta = vec3(0.0);\n{}    return delta;\n}}\n",
        each(&|k| format!("    ShootsFrom(texel, {k});\n")),
        each(&|k| format!("    delta += Received({k}, HemiItemBuffer[{k}]);\n")),
    )
}

#[cfg(test)]
mod tests {
    use super::per_shooter_functions;

    #[test]
    fn the_shaders_comment_shows_what_the_host_writes() {
        // The example above `main` in glsl/reconstruct.frag is the reader's only view of these
        // functions: it must be what the host writes for two shooters (up to spacing).
        let shader = include_str!("../../../glsl/reconstruct.frag");
        let example: String = (shader.lines())
            .skip_while(|l| !l.contains("for SHOOTERS = 2 they read:"))
            .skip(1)
            .take_while(|l| l.starts_with("//"))
            .map(|l| l.trim_start_matches("//"))
            .collect();
        let squeeze = |s: &str| s.split_whitespace().collect::<String>();
        assert!(example.contains("ReceivedFromEach"), "example not found");
        assert_eq!(squeeze(&example), squeeze(&per_shooter_functions(2)));
    }
}
