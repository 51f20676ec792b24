//! `radiosity bench`: timed runs of the solvers.
//!
//! - `table1` (`table1.rs`): the paper's Table 1 on this machine, both rooms and both solvers,
//!   the paper-faithful configuration beside the default and whole polygons.
//! - `guard` (`guard.rs`): every speed option, its time beside its accuracy: on the simple room
//!   against the exhaustive CPU solution (`validate::guard`), on the Cornell box against the
//!   path-traced reference (`validate::path_traced`).
//! - `scaling` (`scaling.rs`): seconds, shots and peak memory against the patch count, both
//!   solvers, with a log-log plot.
//! - `scenes` (`scenes.rs`): the third-party scenes (`scene::third_party`), each solved with
//!   the default to the stopping rule: counts, shots, loop seconds, peak memory.
//!
//! The configurations they time are the solver's (`solver::options`): `SolveOptions::paper_faithful`
//! (the paper's loop: one polygon and one pass per shot), `SolveOptions::default_with` (the
//! default, with the speed options beyond the paper) and `solver::configurations` (each speed
//! option alone, for the guard).

mod guard;
pub mod scaling;
mod scenes;
mod table1;

use crate::gl::{BackendChoice, GlContext};
use crate::patches::{PatchLayout, Resolution};
use crate::scene::bundled;
use crate::solver::{ChosenTuning, GpuSolver, SolveOptions, TuningChoice};
use anyhow::{Context, Result};
use std::time::Instant;

pub use crate::pipeline::peak_memory_mib;
pub use table1::shader_cache_disabled_by_env;

/// Mesa's on-disk shader cache during the timed GPU setups.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaderCache {
    /// Timed runs warm, plus one cold setup per room and repeat in a child process.
    Both,
    /// Timed runs warm (one untimed run first fills the cache).
    Warm,
    /// Every run with the cache disabled (`MESA_SHADER_CACHE_DISABLE=true`).
    Cold,
}

/// `radiosity bench`'s flags.
#[derive(clap::Args, Debug, Clone)]
pub struct BenchArgs {
    /// What to benchmark: `table1` (the paper's Table 1, paper-faithful and fast rows), `guard`
    /// (each speed option's time and accuracy on the simple room and the Cornell box), `scaling` (cost against
    /// patch count, both solvers), `scenes` (the third-party scenes solved with the default).
    #[arg(value_parser = ["table1", "guard", "scaling", "scenes"])]
    pub what: String,
    /// The OpenGL backend of the GPU runs (EGL or OSMesa; `auto` tries both).
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// Speed switches of the GPU runs, as `solve --tuning`: auto (the llvmpipe engine on Mesa's
    /// software rasterisers, the GPU profile elsewhere), paper, llvmpipe, gpu. Every row says
    /// which ran.
    #[arg(long, value_enum, default_value_t = TuningChoice::Auto)]
    pub tuning: TuningChoice,
    /// Stopping rule: unshot power / emitted power (0 < F < 1).
    #[arg(
        long,
        default_value_t = 0.01,
        value_parser = super::values::threshold,
        allow_hyphen_values = true,
    )]
    pub threshold: f32,
    /// Runs per measurement, 1 to 1000; the median is reported.
    #[arg(
        long,
        default_value_t = 1,
        value_parser = clap::value_parser!(u32).range(1..=super::values::MAX_REPEAT as i64),
        allow_hyphen_values = true,
    )]
    pub repeat: u32,
    /// Only these rooms (simple, complex); `scenes`: only these third-party scenes
    /// (cornell-box, tinyobjloader-cornell-box, living-room, lost-empire, conference-room, and
    /// lost-empire-100k: Lost Empire at issue 35's target of ≥ 100,000 patches in ≤ 60 s; all
    /// by default).
    #[arg(
        long,
        value_delimiter = ',',
        default_values_t = ["simple".to_string(), "complex".to_string()],
    )]
    pub scenes: Vec<String>,
    /// Worker threads of the CPU solver (0: one per core; at most 4 per core).
    #[arg(
        long,
        default_value_t = 0,
        value_parser = super::values::threads,
        allow_hyphen_values = true,
    )]
    pub threads: usize,
    /// Also write the table as JSON.
    #[arg(long)]
    pub json: Option<std::path::PathBuf>,
    /// Mesa's on-disk shader cache for the GPU setup: `both` times the runs warm and one setup
    /// per room and repeat cold (`MESA_SHADER_CACHE_DISABLE=true`, in a child process), `warm`
    /// or `cold` only that one. The state is printed, and `cold` is what any run gets when the
    /// environment already disables the cache.
    #[arg(long, value_enum, default_value_t = ShaderCache::Both)]
    pub shader_cache: ShaderCache,
    /// `scaling`: patch-count multiples of the rooms' own (1 to 64).
    #[arg(
        long,
        value_delimiter = ',',
        default_values_t = [1u32, 4, 16],
        value_parser = clap::value_parser!(u32).range(1..=64),
    )]
    pub scales: Vec<u32>,
    /// `scaling`: stop a run after this many seconds of shots (1 to 86400) and extrapolate its
    /// time from its shots per second and the other solver's shot count.
    #[arg(
        long,
        default_value_t = 3600,
        value_parser = clap::value_parser!(u64).range(1..=86_400),
    )]
    pub budget: u64,
    /// `scaling`: write the log-log plot here (PNG).
    #[arg(long)]
    pub plot: Option<std::path::PathBuf>,
    /// `scaling`: print and plot a report saved with `--json` instead of running the solves.
    #[arg(long)]
    pub from: Option<std::path::PathBuf>,
    /// Internal (`scaling`'s child processes): run one solve and print its figures as JSON:
    /// ROOM,SCALE,SOLVER.
    #[arg(long, hide = true)]
    pub one: Option<String>,
    /// `scaling` (and the internal cold run of `table1`): the configuration to time,
    /// `paper-faithful` (one polygon, one pass per shot), `default` (`radiosity solve`'s) or
    /// `whole polygons` (the default's speed options, whole polygons shooting).
    #[arg(long, default_value = "paper-faithful", value_parser = ["paper-faithful", "default", "whole polygons"])]
    pub configuration: String,
    /// Internal (the cold measurement's child process): time one GPU run of the first room and
    /// print `setup_s <seconds>`, `loop_s <seconds>` and `shots <n>`.
    #[arg(long, hide = true)]
    pub gpu_only: bool,
}

/// The middle value of `v` (the upper one of an even count): a run's figure robust to one slow sample.
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// The CPU's model name from /proc/cpuinfo, for the report ("unknown CPU" elsewhere).
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

/// A bundled Table 1 room (`simple` or `complex`) and its layout at the room's own patch size.
pub fn room(name: &str) -> Result<(crate::scene::Scene, PatchLayout)> {
    let scene = bundled::find(name)
        .with_context(|| format!("no built-in room '{name}': the rooms are simple and complex"))?
        .load()?;
    let size = scene
        .patch_size
        .context("the room has no `# patch-size` line")?;
    let layout = PatchLayout::try_new(&scene, Resolution::PatchSize(size))?;
    Ok((scene, layout))
}

/// One timed GPU run: the setup (a new GL context and `GpuSolver::new`, up to a `glFinish`, so
/// that no queued upload or emission pass is left for the loop), then the loop, with `options`'
/// tuning replaced by `tuning`'s on the context's renderer. Returns the setup's and the
/// loop's seconds, the shots and the solution (the radiance atlas).
pub fn gpu_run(
    (backend, tuning): (BackendChoice, TuningChoice),
    scene: &crate::scene::Scene,
    layout: &PatchLayout,
    options: &SolveOptions,
) -> Result<(f64, f64, u32, Vec<f32>)> {
    use glow::HasContext;
    let start = Instant::now();
    let ctx = GlContext::headless(backend)?;
    let options = SolveOptions {
        tuning: tuning.resolve(false, Some(&ctx.info.renderer)).tuning(),
        ..options.clone()
    };
    let mut gpu = GpuSolver::new(&ctx, scene, layout, options)?;
    unsafe { ctx.gl.finish() };
    let setup = start.elapsed().as_secs_f64();
    let start = Instant::now();
    gpu.solve(|_| {})?;
    let run = start.elapsed().as_secs_f64();
    Ok((setup, run, gpu.shots(), gpu.radiosity_atlas()))
}

/// `args.tuning` resolved on `ctx`'s renderer (the benches' configurations are all beyond the
/// paper's mode, so `auto` picks by renderer).
pub fn chosen_tuning(args: &BenchArgs, ctx: &GlContext) -> ChosenTuning {
    args.tuning.resolve(false, Some(&ctx.info.renderer))
}

/// A child process of this program: `bench` with `args`, the backend, tuning and threshold of
/// `parent`,
/// and `env`, its stderr passed through. Returns what it printed, or an error naming `what`.
pub fn run_child(
    parent: &BenchArgs,
    args: &[&str],
    env: &[(&str, &str)],
    what: &str,
) -> Result<String> {
    use clap::ValueEnum;
    let backend = parent
        .backend
        .to_possible_value()
        .context("a backend name")?;
    let tuning = parent.tuning.to_possible_value().context("a tuning name")?;
    let out = std::process::Command::new(std::env::current_exe()?)
        .arg("bench")
        .args(args)
        .args(["--backend", backend.get_name()])
        .args(["--tuning", tuning.get_name()])
        .args(["--threshold", &parent.threshold.to_string()])
        .envs(env.iter().copied())
        .stderr(std::process::Stdio::inherit())
        .output()
        .with_context(|| format!("running {what} in a child process"))?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    anyhow::ensure!(out.status.success(), "{what} failed: {text}");
    Ok(text)
}

/// `radiosity bench`: run the benchmark `args.what` names.
pub fn run_bench(args: &BenchArgs) -> Result<()> {
    match args.what.as_str() {
        "guard" => guard::run(args),
        "scaling" => scaling::run(args),
        "scenes" => scenes::run(args),
        _ => table1::run(args),
    }
}
