//! The command line: one file per subcommand.

/// `println!` for the reports the commands print on standard output (see [`print_out`]).
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::print_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub mod bench;
mod check;
mod info;
mod solve;
mod stopping;
mod validate;
mod values;
mod view;

use clap::{Parser, Subcommand};

pub use solve::{run_solve, SolveArgs};
pub use values::emission;

/// The command line: a subcommand and the flags every subcommand takes.
#[derive(Parser, Debug)]
#[command(
    name = "radiosity",
    version,
    about = "Progressive refinement radiosity on the GPU (OpenGL 3.0, GLSL 1.30)"
)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// Let a scene's `mtllib` lines name files outside the scene's folder (absolute paths,
    /// `../`); without it they are refused.
    #[arg(long, global = true)]
    pub allow_outside_materials: bool,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Solve a scene and write image.png, image.exr, lightmap.exr and stats.json.
    Solve(SolveArgs),
    /// Benchmarks: `table1` replicates the paper's Table 1 (CPU vs GPU on the two rooms).
    Bench(bench::BenchArgs),
    /// Compare renders of the bundled scenes with golden images (regression-test a Mesa build).
    Check(check::CheckArgs),
    /// List the OpenGL backends that work here, with their renderer and limits.
    Info(info::InfoArgs),
    /// Check the solver against closed forms, the furnace and a direct solve; print the table.
    Validate(validate::ValidateArgs),
    /// Open a window that lights the scene shot by shot, with the passes' pictures and a panel.
    View(view::ViewArgs),
}

/// A usage error found after parsing (values that are fine alone but not together, such as
/// `--eye` equal to `--target`): `main` exits with status 2, as clap does for its own.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// Run the parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    crate::scene::allow_outside_materials(cli.allow_outside_materials);
    match cli.command {
        Command::Solve(args) => run_solve(&args).map(|_| ()),
        Command::Validate(args) => validate::run_validate(&args),
        Command::Info(args) => info::run_info(&args),
        Command::Check(args) => check::run_check(&args),
        Command::Bench(args) => bench::run_bench(&args),
        Command::View(args) => view::run_view(&args),
    }
}

/// Write to standard output without panicking when it is gone: a reader that stops early
/// (`radiosity bench table1 | head`) ends the report, not the command, whose files are still
/// written. Any other write error is reported once on standard error; nothing more is printed.
pub fn print_out(text: std::fmt::Arguments) {
    use std::io::Write;
    use std::sync::atomic::{AtomicBool, Ordering};
    static GONE: AtomicBool = AtomicBool::new(false);
    if GONE.load(Ordering::Relaxed) {
        return;
    }
    if let Err(e) = std::io::stdout().lock().write_fmt(text) {
        GONE.store(true, Ordering::Relaxed);
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            eprintln!("warning: cannot write to standard output ({e}); the rest of the report is not printed");
        }
    }
}
