//! `radiosity bench table1`: the paper's Table 1 on this machine — both rooms, both solvers, the
//! same stopping rule — printed beside the paper's numbers.
//!
//! Each solver's time is split in two. *Setup* is everything before the first shot: for the GPU
//! a new GL context and `GpuSolver::new` (shader compiles, uploads, the emission pass, up to a
//! `glFinish`); for the CPU `CpuSolver::new` (its thread pool, patches and BVH). *Loop* is the
//! shots to the stopping rule. The headline times and the CPU/GPU ratio are the loops.
//!
//! Mesa keeps compiled shaders in an on-disk cache, so the GPU times depend on whether an earlier
//! run filled it: the setup compiles the programs, and llvmpipe compiles each program's variants
//! for the GL state at their first draw, in the loop's first shots. By default
//! (`--shader-cache both`) the bench runs the GPU solver once more per room and repeat with the
//! cache disabled (`MESA_SHADER_CACHE_DISABLE=true`, in a child process: Mesa reads the variable
//! once per process), times the other runs with the cache warm (after one untimed run has filled
//! it), and prints both; the headline figures are the warm ones.

use crate::gl::{BackendChoice, GlContext};
use crate::patches::{PatchLayout, Resolution};
use crate::scene::bundled;
use crate::solver::cpu::CpuSolver;
use crate::solver::{GpuSolver, SolveOptions};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::time::Instant;

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

#[derive(clap::Args, Debug, Clone)]
pub struct BenchArgs {
    /// What to benchmark: `table1`.
    #[arg(value_parser = ["table1"])]
    pub what: String,
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
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
    /// Only these rooms (simple, complex).
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
    /// Internal (the cold measurement's child process): time one GPU run of the first room and
    /// print `setup_s <seconds>`, `loop_s <seconds>` and `shots <n>`.
    #[arg(long, hide = true)]
    pub gpu_only: bool,
}

/// The paper's Table 1 (Intel Core i3 3.6 GHz, GeForce GT705).
const PAPER: [(&str, f64, f64); 2] = [("simple", 4.0, 2.0), ("complex", 139.0, 79.0)];

/// One solver's times on one room (medians over `--repeat`), seconds.
#[derive(serde::Serialize)]
struct Times {
    /// Everything before the first shot (GPU: GL context + `GpuSolver::new`; CPU: `CpuSolver::new`).
    setup_s: f64,
    /// The shots to the stopping rule.
    loop_s: f64,
    shots: u32,
    /// GPU only: the state of Mesa's shader cache during `setup_s`, `warm` or `cold`.
    #[serde(skip_serializing_if = "Option::is_none")]
    shader_cache: Option<&'static str>,
    /// GPU only, `--shader-cache both`: the setup and the loop with the cache disabled (a child
    /// process).
    #[serde(skip_serializing_if = "Option::is_none")]
    setup_cold_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    loop_cold_s: Option<f64>,
}

#[derive(serde::Serialize)]
struct Row {
    scene: String,
    faces: usize,
    vertices: usize,
    lights: usize,
    patches: u64,
    gpu: Times,
    cpu: Times,
    /// CPU loop / GPU loop.
    ratio: f64,
    paper_cpu_seconds: f64,
    paper_gpu_seconds: f64,
    paper_ratio: f64,
}

#[derive(serde::Serialize)]
struct Report {
    machine: String,
    cores: usize,
    gl_renderer: String,
    gl_version: String,
    stopping_rule: String,
    /// What `setup_s` and `loop_s` time.
    timing: String,
    /// Mesa's shader cache during the timed GPU setups (`warm` or `cold`) and how it was made so.
    shader_cache: &'static str,
    shader_cache_note: String,
    options: SolveOptions,
    peak_memory_mib: f64,
    rows: Vec<Row>,
}

/// The bench's solver settings: the paper's loop (one pass per shot, the whole polygon shoots)
/// with the accurate mode's form factor and visibility, which stay stable on these rooms (the
/// paper's point factor creates energy between close polygons and never converges here).
///
/// The hemicube is 128² per face, chosen by measurement on the simple room (README, "Table 1"):
/// against the CPU solver's exact ray casts the mean patch difference is 3.3 % at 64², 1.5 % at
/// 128², 1.1 % at 192² and at 256², while the visibility pass costs about twice as much at 256²
/// as at 128². A 128² face pixel at the room's typical 2.5 m is 4 cm, a third of a patch.
pub fn bench_options(threshold: f32) -> SolveOptions {
    SolveOptions {
        threshold,
        shooter_cell: 0,
        emitter_cell: 0,
        max_shots: 1_000_000,
        hemi_res: BENCH_HEMI_RES,
        ..SolveOptions::accurate()
    }
}

/// Item-buffer resolution of the bench (see `bench_options`).
pub const BENCH_HEMI_RES: u32 = 128;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

/// Peak resident memory of this process (VmHWM), MiB.
pub fn peak_memory_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("VmHWM"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map(|kib| kib / 1024.0)
        .unwrap_or(0.0)
}

/// Whether the environment disables Mesa's shader cache (`MESA_SHADER_CACHE_DISABLE`, or its
/// older name `MESA_GLSL_CACHE_DISABLE`, set to a true value).
pub fn shader_cache_disabled_by_env() -> bool {
    ["MESA_SHADER_CACHE_DISABLE", "MESA_GLSL_CACHE_DISABLE"]
        .iter()
        .filter_map(|v| std::env::var(v).ok())
        .any(|v| matches!(v.to_ascii_lowercase().as_str(), "1" | "true" | "yes" | "y"))
}

/// The directory Mesa's shader cache uses (Mesa's rules: `MESA_SHADER_CACHE_DIR`, else
/// `$XDG_CACHE_HOME`, else `$HOME/.cache`, with `mesa_shader_cache` appended; `_sf` or `_db`
/// for the single-file and database caches of later Mesas): the first that holds anything,
/// else the multi-file one (Mesa 22's default).
fn shader_cache_dir() -> Option<PathBuf> {
    let base = [
        "MESA_SHADER_CACHE_DIR",
        "MESA_GLSL_CACHE_DIR",
        "XDG_CACHE_HOME",
    ]
    .iter()
    .find_map(|v| std::env::var_os(v).filter(|s| !s.is_empty()))
    .map(PathBuf::from)
    .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    let dirs = ["", "_sf", "_db"].map(|tail| base.join(format!("mesa_shader_cache{tail}")));
    let filled = dirs.iter().find(|d| shader_cache_filled(Some(d)));
    Some(filled.unwrap_or(&dirs[0]).clone())
}

/// Whether the shader cache directory exists and holds anything.
fn shader_cache_filled(dir: Option<&Path>) -> bool {
    dir.and_then(|d| std::fs::read_dir(d).ok())
        .is_some_and(|mut entries| entries.next().is_some())
}

fn room(name: &str) -> Result<(crate::scene::Scene, PatchLayout)> {
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
/// that no queued upload or emission pass is left for the loop), then the loop. Returns the
/// setup's and the loop's seconds and the shots.
fn gpu_run(
    backend: BackendChoice,
    scene: &crate::scene::Scene,
    layout: &PatchLayout,
    options: &SolveOptions,
) -> Result<(f64, f64, u32)> {
    use glow::HasContext;
    let start = Instant::now();
    let ctx = GlContext::headless(backend)?;
    let mut gpu = GpuSolver::new(&ctx, scene, layout, options.clone())?;
    unsafe { ctx.gl.finish() };
    let setup = start.elapsed().as_secs_f64();
    let start = Instant::now();
    gpu.solve(|_| {})?;
    Ok((setup, start.elapsed().as_secs_f64(), gpu.shots()))
}

/// The cold run: this program in a child process with the shader cache disabled. Returns its
/// setup's and loop's seconds.
fn cold_run_in_child(args: &BenchArgs, backend: &str, name: &str) -> Result<(f64, f64)> {
    let out = std::process::Command::new(std::env::current_exe()?)
        .args(["bench", "table1", "--gpu-only", "--scenes", name])
        .args(["--backend", backend, "--threshold"])
        .arg(args.threshold.to_string())
        .env("MESA_SHADER_CACHE_DISABLE", "true")
        .stderr(std::process::Stdio::inherit())
        .output()
        .context("running the cold-cache GPU run in a child process")?;
    let text = String::from_utf8_lossy(&out.stdout);
    anyhow::ensure!(
        out.status.success(),
        "the cold-cache GPU run failed: {text}"
    );
    let value = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key)?.trim().parse::<f64>().ok())
            .with_context(|| format!("the cold-cache GPU run printed no {key}: {text}"))
    };
    Ok((value("setup_s ")?, value("loop_s ")?))
}

pub fn run_bench(args: &BenchArgs) -> Result<()> {
    let options = bench_options(args.threshold);
    if args.gpu_only {
        let name = args.scenes.first().context("no room")?;
        let (scene, layout) = room(name)?;
        // As in the parent, whose timed contexts are not the process's first (loading the
        // driver is not part of a setup): one context made and dropped before.
        drop(GlContext::headless(args.backend)?);
        let (setup, run, shots) = gpu_run(args.backend, &scene, &layout, &options)?;
        println!("setup_s {setup}\nloop_s {run}\nshots {shots}");
        return Ok(());
    }
    let env_cold = shader_cache_disabled_by_env();
    if args.shader_cache == ShaderCache::Cold && !env_cold {
        // Before the first context: Mesa reads the variable when it creates its screen.
        std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true");
    }
    let cold = env_cold || args.shader_cache == ShaderCache::Cold;
    let cold_child = args.shader_cache == ShaderCache::Both && !cold;
    let info_ctx = GlContext::headless(args.backend)?;
    let info = info_ctx.info.clone();
    drop(info_ctx);
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let steps = args.scenes.len() as u64 * (2 + cold_child as u64) * args.repeat as u64;
    let bar = if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        indicatif::ProgressBar::new(steps)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut rows = Vec::new();
    for name in &args.scenes {
        let (scene, layout) = room(name)?;
        if !cold {
            // Fill the shader cache: one untimed setup and a few shots (llvmpipe compiles and
            // caches its shader variants at their first draw).
            bar.set_message(format!("{name}: GPU, filling the shader cache"));
            let warm_up = SolveOptions {
                max_shots: 3,
                ..options.clone()
            };
            gpu_run(args.backend, &scene, &layout, &warm_up)?;
        }
        // GPU setup, loop; CPU setup, loop; GPU setup, loop with the cache disabled.
        let mut t = [(); 6].map(|_| Vec::new());
        let mut shots = (0, 0);
        for _ in 0..args.repeat {
            if cold_child {
                bar.set_message(format!("{name}: GPU, shader cache disabled"));
                let (setup, run) = cold_run_in_child(args, info.backend.name(), name)?;
                t[4].push(setup);
                t[5].push(run);
                bar.inc(1);
            }
            bar.set_message(format!("{name}: GPU"));
            let (setup, run, n) = gpu_run(args.backend, &scene, &layout, &options)?;
            t[0].push(setup);
            t[1].push(run);
            shots.0 = n;
            bar.inc(1);
            bar.set_message(format!("{name}: CPU"));
            let start = Instant::now();
            let mut cpu = CpuSolver::new(&scene, &layout, options.clone(), args.threads)?;
            t[2].push(start.elapsed().as_secs_f64());
            let start = Instant::now();
            cpu.solve(|_| {})?;
            t[3].push(start.elapsed().as_secs_f64());
            shots.1 = cpu.shots();
            bar.inc(1);
        }
        let [gpu_setup_s, gpu_loop_s, cpu_setup_s, cpu_loop_s, cold_setup_s, cold_loop_s] = t;
        let paper = PAPER
            .iter()
            .find(|p| p.0 == name)
            .copied()
            .unwrap_or((name, 0.0, 0.0));
        let gpu = Times {
            setup_s: median(gpu_setup_s),
            loop_s: median(gpu_loop_s),
            shots: shots.0,
            shader_cache: Some(if cold { "cold" } else { "warm" }),
            setup_cold_s: (!cold_setup_s.is_empty()).then(|| median(cold_setup_s)),
            loop_cold_s: (!cold_loop_s.is_empty()).then(|| median(cold_loop_s)),
        };
        let cpu = Times {
            setup_s: median(cpu_setup_s),
            loop_s: median(cpu_loop_s),
            shots: shots.1,
            shader_cache: None,
            setup_cold_s: None,
            loop_cold_s: None,
        };
        rows.push(Row {
            scene: name.clone(),
            faces: scene.polygons.len(),
            vertices: scene.vertex_count,
            lights: scene.light_count(),
            patches: layout.patch_count(),
            ratio: cpu.loop_s / gpu.loop_s,
            gpu,
            cpu,
            paper_cpu_seconds: paper.1,
            paper_gpu_seconds: paper.2,
            paper_ratio: if paper.2 > 0.0 {
                paper.1 / paper.2
            } else {
                0.0
            },
        });
    }
    bar.finish_and_clear();
    let cache_dir = shader_cache_dir();
    let dir = cache_dir
        .as_deref()
        .map_or("no cache directory".into(), |d| d.display().to_string());
    let shader_cache_note = if cold {
        if env_cold {
            "cold: the environment disables Mesa's shader cache (MESA_SHADER_CACHE_DISABLE)".into()
        } else {
            "cold: --shader-cache cold, MESA_SHADER_CACHE_DISABLE=true".into()
        }
    } else if !shader_cache_filled(cache_dir.as_deref()) {
        format!("warm asked for, but Mesa wrote nothing to {dir}: the timed setups were cold")
    } else if cold_child {
        format!(
            "warm (the headline): Mesa's shader cache ({dir}) filled by an untimed run first; \
             cold: one more GPU run per repeat with MESA_SHADER_CACHE_DISABLE=true, in a child \
             process"
        )
    } else {
        format!("warm: Mesa's shader cache ({dir}) filled by an untimed run first")
    };
    let state = if cold || !shader_cache_filled(cache_dir.as_deref()) {
        "cold"
    } else {
        "warm"
    };
    for r in &mut rows {
        r.gpu.shader_cache = Some(state);
    }
    let report = Report {
        machine: cpu_model(),
        cores,
        gl_renderer: info.renderer.clone(),
        gl_version: info.version.clone(),
        stopping_rule: format!(
            "unshot power / emitted power <= {}; whole polygons shoot (one pass per shot, as in the paper), polygon form factor, {}² hemicube; median of {} run(s)",
            args.threshold, options.hemi_res, args.repeat
        ),
        timing: "setup: everything before the first shot (GPU: a new GL context, not the process's \
                 first, and GpuSolver::new, i.e. shader compiles, uploads and the emission pass, \
                 to a glFinish; CPU: \
                 CpuSolver::new, its patches and BVH); loop: the shots to the stopping rule \
                 (llvmpipe compiles a shader's variants at their first draw, in the loop's first \
                 shots); CPU/GPU compares the loops; the paper gives one time per solver"
            .into(),
        shader_cache: state,
        shader_cache_note,
        options,
        peak_memory_mib: peak_memory_mib(),
        rows,
    };
    println!(
        "{} ({} cores); {} | {}",
        report.machine, report.cores, report.gl_renderer, report.gl_version
    );
    println!("stopping rule: {}", report.stopping_rule);
    println!("timing: {}", report.timing);
    println!("shader cache: {}", report.shader_cache_note);
    let gpu_header = if cold_child {
        "GPU setup s cold / warm | GPU loop s cold / warm".to_string()
    } else {
        format!("GPU setup s ({state}) | GPU loop s ({state})")
    };
    println!(
        "| scene | faces | vertices | lights | patches | shots GPU/CPU | CPU setup s | CPU loop s | {gpu_header} | CPU/GPU loops | paper CPU s | paper GPU s | paper CPU/GPU |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &report.rows {
        let (setup, run) = match (r.gpu.setup_cold_s, r.gpu.loop_cold_s) {
            (Some(s), Some(l)) => (
                format!("{s:.3} / {:.3}", r.gpu.setup_s),
                format!("{l:.2} / {:.2}", r.gpu.loop_s),
            ),
            _ => (
                format!("{:.3}", r.gpu.setup_s),
                format!("{:.2}", r.gpu.loop_s),
            ),
        };
        println!(
            "| {} | {} | {} | {} | {} | {}/{} | {:.3} | {:.2} | {} | {} | {:.2} | {:.1} | {:.1} | {:.2} |",
            r.scene,
            r.faces,
            r.vertices,
            r.lights,
            r.patches,
            r.gpu.shots,
            r.cpu.shots,
            r.cpu.setup_s,
            r.cpu.loop_s,
            setup,
            run,
            r.ratio,
            r.paper_cpu_seconds,
            r.paper_gpu_seconds,
            r.paper_ratio
        );
    }
    println!("peak memory: {:.0} MiB", report.peak_memory_mib);
    if let Some(path) = &args.json {
        crate::display::output::write_json(path, &report)?;
    }
    Ok(())
}
