//! The validation suite: the GPU solver against independent answers — closed-form configuration
//! factors, the furnace, energy balance, a direct (Jacobi) solve of the same discretisation on
//! the CPU, and convergence under refinement. `radiosity validate` prints the table; the tests in
//! `tests/validation.rs` run the same checks and require them to pass. The references of
//! `radiosity bench guard` live here too: the exhaustive CPU solve (`guard`) and a path tracer
//! of the Cornell box (`path_traced`).

mod cases;
mod direct;
pub mod guard;
pub mod path_traced;

pub use cases::*;

use crate::gl::GlContext;
use crate::solver::SolveOptions;

/// One line of the report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Check {
    /// What is checked, with its scene.
    pub name: String,
    /// `paper` or `accurate`.
    pub mode: &'static str,
    /// The closed form's or the reference's value.
    pub expected: f64,
    /// The solver's value.
    pub got: f64,
    /// |got - expected| / |expected| (or the worst per-patch value, where the name says so).
    pub error: f64,
    /// The largest `error` that passes.
    pub tolerance: f64,
    /// Whether `error` is within `tolerance` (and the figures are finite).
    pub pass: bool,
}

impl Check {
    /// A check of `got` against `expected`, its relative error and verdict computed.
    pub fn new(
        name: impl Into<String>,
        mode: &'static str,
        expected: f64,
        got: f64,
        tolerance: f64,
    ) -> Check {
        let error = ((got - expected) / expected).abs();
        Check::with_error(name, mode, expected, got, error, tolerance)
    }

    /// A check whose error is measured elsewhere (e.g. the worst patch of many).
    pub fn with_error(
        name: impl Into<String>,
        mode: &'static str,
        expected: f64,
        got: f64,
        error: f64,
        tolerance: f64,
    ) -> Check {
        Check {
            name: name.into(),
            mode,
            expected,
            got,
            error,
            tolerance,
            pass: error <= tolerance,
        }
    }
}

/// The two modes the report compares.
pub fn modes() -> [(&'static str, SolveOptions); 2] {
    [
        ("paper", SolveOptions::paper()),
        ("accurate", SolveOptions::accurate()),
    ]
}

/// Every check, in both modes where that makes sense. `quick` skips the refinement check (the
/// slowest; the tests run it on its own).
pub fn run_all(
    ctx: &GlContext,
    quick: bool,
    mut progress: impl FnMut(&Check),
) -> anyhow::Result<Vec<Check>> {
    let mut checks = Vec::new();
    let mut push = |c: Check, checks: &mut Vec<Check>| {
        progress(&c);
        checks.push(c);
    };
    for (mode, options) in modes() {
        for c in form_factor_checks(ctx, mode, &options)? {
            push(c, &mut checks);
        }
        push(furnace(ctx, mode, &options)?, &mut checks);
        push(energy_balance(ctx, mode, &options)?, &mut checks);
    }
    push(direct_solve(ctx)?, &mut checks);
    if !quick {
        for c in refinement(ctx)? {
            push(c, &mut checks);
        }
    }
    Ok(checks)
}

/// The report as a text table.
pub fn table(checks: &[Check]) -> String {
    let mut out = format!(
        "{:<52} {:<9} {:>10} {:>10} {:>9} {:>7}  {}\n",
        "check", "mode", "expected", "got", "error %", "tol %", "pass"
    );
    for c in checks {
        out += &format!(
            "{:<52} {:<9} {:>10.5} {:>10.5} {:>9.3} {:>7.2}  {}\n",
            c.name,
            c.mode,
            c.expected,
            c.got,
            100.0 * c.error,
            100.0 * c.tolerance,
            if c.pass { "pass" } else { "FAIL" }
        );
    }
    out
}
