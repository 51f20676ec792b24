//! `radiosity check`: render the golden cases and compare them with the references (for
//! regression-testing a Mesa build): by default the references built into the binary
//! (tests/golden/ when it was built). With `--drivers`, the same check on each of Mesa's
//! software drivers, each in a child process (`golden::drivers`); `--junit` and `--json` write
//! the results for CI systems.

use crate::gl::{BackendChoice, BackendKind, GlContext};
use crate::golden::drivers::{self, ChildArgs, Driver, DriverRun, Status};
use crate::golden::{self, report, References};
use anyhow::{bail, Context, Result};
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(clap::Args, Debug, Clone)]
pub struct CheckArgs {
    /// Directory of reference pictures (`<case>.exr`); default: the references built into the
    /// binary (tests/golden/ when it was built).
    #[arg(long)]
    pub against: Option<PathBuf>,
    /// Without --drivers: the GL backend to run on (with --drivers each driver has its own).
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// Mesa drivers to check, each in its own process: a comma-separated list of llvmpipe,
    /// softpipe, osmesa, zink, or `all` (every one that starts here; the others are reported
    /// unavailable). A driver named on its own that cannot start is an error.
    #[arg(long, value_parser = drivers::parse_list)]
    pub drivers: Option<(Vec<Driver>, bool)>,
    /// Only these cases (comma-separated names; see `--list`).
    #[arg(long, value_delimiter = ',')]
    pub cases: Vec<String>,
    /// List the cases and what each exercises, then stop.
    #[arg(long)]
    pub list: bool,
    /// Where difference pictures go (per driver in subfolders with --drivers): written for
    /// every case whose picture is not bit-identical to its reference.
    #[arg(long, default_value = "golden-diff")]
    pub diff_dir: PathBuf,
    /// Write JUnit XML: one testsuite per driver, one testcase per case.
    #[arg(long)]
    pub junit: Option<PathBuf>,
    /// Write the same results as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Seconds a driver may take for all its cases before it is stopped (with --drivers).
    #[arg(long, default_value_t = 1800, value_parser = clap::value_parser!(u64).range(1..))]
    pub timeout: u64,
    /// Internal: the driver this child process checks (set by --drivers).
    #[arg(long, hide = true, value_enum)]
    pub as_driver: Option<Driver>,
    /// Internal: where this child process writes its JSON report.
    #[arg(long, hide = true, requires = "as_driver")]
    pub report: Option<PathBuf>,
}

pub fn run_check(args: &CheckArgs) -> Result<()> {
    let cases = golden::select(&args.cases)?;
    if args.list {
        for case in &cases {
            outln!("{:<18} {}", case.name, case.exercises);
        }
        return Ok(());
    }
    let start = Instant::now();
    let runs = match (&args.drivers, args.as_driver) {
        (_, Some(driver)) => return run_child(args, driver, &cases),
        (Some((list, all)), None) => run_matrix(args, list, *all, &cases)?,
        (None, None) => vec![run_here(args, &cases)?],
    };
    print_rows(&runs);
    if let Some(path) = &args.junit {
        report::write(path, &report::junit(&runs, &cases)?)?;
    }
    if let Some(path) = &args.json {
        let json = serde_json::json!({
            "cases": cases.iter().map(|c| serde_json::json!({"name": c.name, "exercises": c.exercises})).collect::<Vec<_>>(),
            "drivers": runs,
            "tolerances": {
                "rms": golden::RMS_TOLERANCE,
                "outliers": golden::OUTLIER_TOLERANCE,
                "ids_outliers": 0.0,
            },
            "seconds": start.elapsed().as_secs_f64(),
        });
        report::write(path, &serde_json::to_string_pretty(&json)?)?;
    }
    let failed: usize = runs.iter().map(DriverRun::failed).sum();
    let crashed: Vec<&str> = runs
        .iter()
        .filter(|r| r.status == Status::Crashed)
        .map(|r| r.driver.name())
        .collect();
    let explicit = matches!(&args.drivers, Some((_, false)));
    let missing: Vec<&str> = runs
        .iter()
        .filter(|r| explicit && r.status == Status::Unavailable)
        .map(|r| r.driver.name())
        .collect();
    if failed > 0 || !crashed.is_empty() || !missing.is_empty() {
        let mut why = Vec::new();
        if failed > 0 {
            why.push(format!(
                "{failed} case(s) differ from the references (difference pictures in {})",
                args.diff_dir.display()
            ));
        }
        if !crashed.is_empty() {
            why.push(format!("no result from {}", crashed.join(", ")));
        }
        if !missing.is_empty() {
            why.push(format!("{} could not start", missing.join(", ")));
        }
        bail!("{}", why.join("; "));
    }
    Ok(())
}

fn references(args: &CheckArgs) -> References<'_> {
    match &args.against {
        Some(dir) => References::Dir(dir),
        None => References::BuiltIn,
    }
}

/// The check in this process, on whatever driver the backend gives.
fn run_here(args: &CheckArgs, cases: &[&golden::Case]) -> Result<DriverRun> {
    let ctx = GlContext::headless(args.backend)?;
    let driver = Driver::ALL
        .into_iter()
        .find(|d| {
            d.recognises(&ctx.info.renderer)
                && (ctx.info.backend == BackendKind::Osmesa) == (*d == Driver::Osmesa)
        })
        .unwrap_or(Driver::Llvmpipe);
    let mut run = DriverRun::new(driver);
    run.environment.clear();
    fill_info(&mut run, &ctx);
    let t = Instant::now();
    run.outcomes = golden::check(&ctx, cases, &references(args), &args.diff_dir, false)?;
    run.seconds = t.elapsed().as_secs_f64();
    Ok(run)
}

fn fill_info(run: &mut DriverRun, ctx: &GlContext) {
    run.vendor = ctx.info.vendor.clone();
    run.renderer = ctx.info.renderer.clone();
    run.version = ctx.info.version.clone();
}

/// A child of `--drivers`: check, and write the report whatever happens short of a crash.
fn run_child(args: &CheckArgs, driver: Driver, cases: &[&golden::Case]) -> Result<()> {
    let path = args.report.clone().context("--as-driver needs --report")?;
    let mut run = DriverRun::new(driver);
    let ctx = match GlContext::headless(args.backend) {
        Ok(ctx) => ctx,
        Err(e) => {
            run.status = Status::Unavailable;
            run.reason = e.tried;
            return drivers::write_report(&path, &run);
        }
    };
    fill_info(&mut run, &ctx);
    if !driver.recognises(&run.renderer) {
        // The parent reports it unavailable; running the cases would only cost time.
        return drivers::write_report(&path, &run);
    }
    // Write the report after each case, so a crash in a later case keeps the earlier results.
    for case in cases {
        // Twice: a driver may differ from the references within the tolerances, never from
        // itself (`golden::Rerun`).
        let outcome = golden::check_twice(&ctx, &[case], &references(args), &args.diff_dir);
        match outcome {
            Ok(mut o) => run.outcomes.append(&mut o),
            Err(e) => {
                run.status = Status::Crashed;
                run.reason = format!("{e:#}");
                drivers::write_report(&path, &run)?;
                return Err(e);
            }
        }
        drivers::write_report(&path, &run)?;
    }
    drivers::write_report(&path, &run)
}

fn run_matrix(
    args: &CheckArgs,
    list: &[Driver],
    all: bool,
    cases: &[&golden::Case],
) -> Result<Vec<DriverRun>> {
    let exe = std::env::current_exe().context("cannot find the radiosity executable")?;
    let child = ChildArgs {
        exe: &exe,
        against: args.against.as_deref(),
        cases: &args.cases,
        diff_dir: &args.diff_dir,
        timeout: Duration::from_secs(args.timeout),
    };
    let mut runs = Vec::new();
    for &driver in list {
        eprintln!("checking {} ({} case(s))…", driver.name(), cases.len());
        let run = drivers::run(driver, &child)?;
        if all && run.status == Status::Unavailable {
            eprintln!("{} is unavailable here: {}", driver.name(), run.reason);
        }
        runs.push(run);
    }
    Ok(runs)
}

fn print_rows(runs: &[DriverRun]) {
    outln!(
        "{:<9} {:<17} {:>8} {:>8} {:>10} {:>9} {:>6} {:>8}  result",
        "driver",
        "case",
        "RMS %",
        "plain %",
        "outliers %",
        "differ %",
        "s",
        "again"
    );
    for run in runs {
        match run.status {
            Status::Ran | Status::Crashed => {
                for o in &run.outcomes {
                    let c = &o.comparison;
                    // The second render: "same" bit for bit, else the share of values that
                    // differ; "-" when the case ran once.
                    let again = match &o.rerun {
                        None => "-".to_string(),
                        Some(r) if r.differing == 0.0 => "same".to_string(),
                        Some(r) => format!("{:.3}%", 100.0 * r.differing),
                    };
                    outln!(
                        "{:<9} {:<17} {:>8.4} {:>8.4} {:>10.3} {:>9.3} {:>6.1} {:>8}  {}",
                        run.driver.name(),
                        c.case,
                        100.0 * c.rms,
                        100.0 * c.rms_plain,
                        100.0 * c.outliers,
                        100.0 * c.differing,
                        o.seconds,
                        again,
                        if c.pass { "pass" } else { "FAIL" }
                    );
                }
                if run.status == Status::Crashed {
                    outln!(
                        "{:<9} {:<17} crashed: {}",
                        run.driver.name(),
                        "-",
                        run.reason
                    );
                }
            }
            Status::Unavailable => {
                outln!(
                    "{:<9} {:<17} unavailable: {}",
                    run.driver.name(),
                    "-",
                    run.reason
                )
            }
        }
    }
    for run in runs.iter().filter(|r| !r.renderer.is_empty()) {
        outln!(
            "{}: {} | {} ({:.0} s)",
            run.driver.name(),
            run.renderer,
            run.version,
            run.seconds
        );
    }
    outln!(
        "tolerances: radiance RMS ≤ {} % of the mean and ≤ {} % of pixels off by more than 5 % of \
         it, each pixel against the nearest of its reference's 3x3 neighbourhood; IDs exact up to \
         an edge",
        100.0 * golden::RMS_TOLERANCE,
        100.0 * golden::OUTLIER_TOLERANCE
    );
}
