//! The reconstruction pass's programs: the paper's `glsl/reconstruct.frag` (and its variants
//! with the solve's choices compiled in and for quadrilateral shooters), with the per-shooter
//! functions the shader leaves to the host, and the emission shader of the initialisation.

use super::Variants;
use crate::gl::program::Source;
use crate::gl::{GlContext, GlError, Program};
use crate::glsl;
use crate::solver::mesh::ATTRIBUTES;
use crate::solver::{FormFactorKind, SolveOptions, VisibilityKind, MAX_SHOOTERS_PER_PASS};

/// The two outputs: 0 = radiosity + ΔL, 1 = unshot + ΔL (zero for the texels that shoot).
pub(crate) const OUTPUTS: &[(u32, &str)] = &[(0, "NewRadiosity"), (1, "NewUnshot")];

/// The pass's programs: the paper's `glsl/reconstruct.frag` for one number of shooters per
/// pass (`SHOOTERS`), and the emission shader. The llvmpipe engine compiles its own variants
/// beside them (`solver::engine::marked_programs`).
pub(crate) struct Programs {
    /// The shader as the paper has it: visibility, form factor and GL_ADD in one program, for
    /// `shooters` shooters a pass (`SolveOptions::shooters_per_pass`; a pass with fewer pads
    /// the rest, `ReconstructionPass::run`).
    pub paper: Variants,
    /// How many shooters the programs serve.
    pub shooters: usize,
    /// The choices compiled into the programs ([`ProgramVariants::choices_compiled`]); none:
    /// read from uniforms, so the programs serve any options.
    pub compiled: Option<Choices>,
    /// Writes each patch's emitted radiance (and its polygon ID in alpha) at initialisation.
    pub emission: Program,
}

/// Which variants of the paper's program a pass compiles. The paper's: the one program, which
/// reads the solve's choices from uniforms ([`ProgramVariants::PAPER`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProgramVariants {
    /// The solve's fixed choices (form factor, visibility kind, robust test) compiled in as
    /// constants (`Tuning::compile_choices`); the programs then serve only those.
    pub choices_compiled: bool,
    /// A variant for quadrilateral shooters, whose loops unroll (`Tuning::unroll_quads`).
    pub quads: bool,
}

impl ProgramVariants {
    /// The paper's one program.
    pub const PAPER: ProgramVariants = ProgramVariants {
        choices_compiled: false,
        quads: false,
    };
}

/// A solve's fixed choices that `glsl/reconstruct.frag` branches on: the form factor, the
/// visibility kind and the robust test (the shader's `FormFactorKind`, `HemiCube` and `Robust`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Choices {
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

/// Compile `glsl/atlas.vert` (squares of texels) with the fragment `source` into a program
/// writing the pass's two outputs.
pub(crate) fn compile(gl: &crate::gl::Gl, source: Source) -> Result<Program, GlError> {
    let squares_in = &[(0, "Corner"), (1, "Size")];
    Program::new(gl, glsl!("atlas.vert"), source, squares_in, OUTPUTS)
}

/// `glsl/reconstruct.frag` for `shooters` shooters, with `compiled` choices as constants
/// (without the face clusters' near field: [`Variants`] adds it).
pub(crate) fn fragment(shooters: u32, compiled: Option<Choices>) -> Source {
    let source = glsl!("reconstruct.frag")
        .define("SHOOTERS", shooters as i32)
        .append(&per_shooter_functions(shooters as usize));
    match &compiled {
        Some(choices) => choices.define(source),
        None => source,
    }
}

impl Programs {
    /// The programs for `options.shooters_per_pass` shooters, in `variants`.
    pub fn new(
        ctx: &GlContext,
        options: &SolveOptions,
        variants: ProgramVariants,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let compiled = variants.choices_compiled.then(|| Choices::of(options));
        let shooters = options.shooters_per_pass.max(1);
        // The shooters' texture units (`reconstruction::UNITS`) are counted out for so many.
        if shooters > MAX_SHOOTERS_PER_PASS {
            return Err(GlError::Limit(format!(
                "{shooters} shooters per reconstruction pass; at most {MAX_SHOOTERS_PER_PASS}"
            )));
        }
        let compile = |source: Source| compile(gl, source);
        let paper = || fragment(shooters, compiled);
        Ok(Programs {
            paper: Variants::new(&compile, &paper, variants.quads, options.face_clusters)?,
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
