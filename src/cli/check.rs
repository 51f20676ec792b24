//! `radiosity check [--against DIR]`: render the golden cases on this machine's driver and
//! compare them with the references (for regression-testing a Mesa build): by default the
//! references built into the binary (tests/golden/ when it was built).

use crate::gl::{BackendChoice, GlContext};
use crate::golden::{self, References};
use anyhow::{bail, Result};
use std::path::PathBuf;

#[derive(clap::Args, Debug, Clone)]
pub struct CheckArgs {
    /// Directory of reference images (`<scene>-<mode>.exr`); default: the references built
    /// into the binary (tests/golden/ when it was built).
    #[arg(long)]
    pub against: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// Where difference images of failed cases go.
    #[arg(long, default_value = "golden-diff")]
    pub diff_dir: PathBuf,
}

pub fn run_check(args: &CheckArgs) -> Result<()> {
    let ctx = GlContext::headless(args.backend)?;
    println!(
        "{} | {} | {}",
        ctx.info.vendor, ctx.info.renderer, ctx.info.version
    );
    let references = match &args.against {
        Some(dir) => References::Dir(dir),
        None => References::BuiltIn,
    };
    let results = golden::check(&ctx, &references, &args.diff_dir, false)?;
    println!(
        "{:<20} {:>10} {:>12}  result",
        "case", "RMS %", "outliers %"
    );
    for r in &results {
        println!(
            "{:<20} {:>10.4} {:>12.3}  {}",
            r.case,
            100.0 * r.rms,
            100.0 * r.outliers,
            if r.pass { "pass" } else { "FAIL" }
        );
    }
    println!(
        "tolerances: RMS ≤ {} % of the mean radiance, ≤ {} % of pixels off by more than 5 % of it",
        100.0 * golden::RMS_TOLERANCE,
        100.0 * golden::OUTLIER_TOLERANCE
    );
    let failed = results.iter().filter(|r| !r.pass).count();
    if failed > 0 {
        bail!(
            "{failed} golden case(s) differ; difference images in {}",
            args.diff_dir.display()
        );
    }
    Ok(())
}
