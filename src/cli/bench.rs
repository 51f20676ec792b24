//! `radiosity bench table1`: the paper's Table 1 on this machine — both rooms, both solvers, the
//! same stopping rule — printed beside the paper's numbers.

use crate::gl::{BackendChoice, GlContext};
use crate::patches::{PatchLayout, Resolution};
use crate::scene::bundled;
use crate::solver::cpu::CpuSolver;
use crate::solver::{GpuSolver, SolveOptions};
use anyhow::{Context, Result};
use std::time::Instant;

#[derive(clap::Args, Debug, Clone)]
pub struct BenchArgs {
    /// What to benchmark: `table1`.
    #[arg(value_parser = ["table1"])]
    pub what: String,
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// Stopping rule: unshot power / emitted power.
    #[arg(long, default_value_t = 0.01)]
    pub threshold: f32,
    /// Runs per measurement; the median is reported.
    #[arg(long, default_value_t = 1)]
    pub repeat: u32,
    /// Only these rooms (simple, complex).
    #[arg(long, value_delimiter = ',', default_values_t = ["simple".to_string(), "complex".to_string()])]
    pub scenes: Vec<String>,
    /// Worker threads of the CPU solver (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Also write the table as JSON.
    #[arg(long)]
    pub json: Option<std::path::PathBuf>,
}

/// The paper's Table 1 (Intel Core i3 3.6 GHz, GeForce GT705).
const PAPER: [(&str, f64, f64); 2] = [("simple", 4.0, 2.0), ("complex", 139.0, 79.0)];

#[derive(serde::Serialize)]
struct Row {
    scene: String,
    faces: usize,
    vertices: usize,
    lights: usize,
    patches: u64,
    gpu_shots: u32,
    cpu_shots: u32,
    cpu_seconds: f64,
    gpu_seconds: f64,
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

pub fn run_bench(args: &BenchArgs) -> Result<()> {
    let ctx = GlContext::headless(args.backend)?;
    let options = bench_options(args.threshold);
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let steps = args.scenes.len() as u64 * 2 * args.repeat as u64;
    let bar = if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        indicatif::ProgressBar::new(steps)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut rows = Vec::new();
    for name in &args.scenes {
        let scene = bundled::find(name)
            .with_context(|| {
                format!("no built-in room '{name}': the rooms are simple and complex")
            })?
            .load()?;
        let size = scene
            .patch_size
            .context("the room has no `# patch-size` line")?;
        let layout = PatchLayout::try_new(&scene, Resolution::PatchSize(size))?;
        let (mut gpu_times, mut cpu_times, mut shots) = (Vec::new(), Vec::new(), (0, 0));
        for _ in 0..args.repeat {
            bar.set_message(format!("{name}: GPU"));
            let t = Instant::now();
            let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone())?;
            gpu.solve(|_| {})?;
            gpu_times.push(t.elapsed().as_secs_f64());
            shots.0 = gpu.shots();
            bar.inc(1);
            bar.set_message(format!("{name}: CPU"));
            let t = Instant::now();
            let mut cpu = CpuSolver::new(&scene, &layout, options.clone(), args.threads)?;
            cpu.solve(|_| {});
            cpu_times.push(t.elapsed().as_secs_f64());
            shots.1 = cpu.shots();
            bar.inc(1);
        }
        let (cpu_s, gpu_s) = (median(cpu_times), median(gpu_times));
        let paper = PAPER
            .iter()
            .find(|p| p.0 == name)
            .copied()
            .unwrap_or((name, 0.0, 0.0));
        rows.push(Row {
            scene: name.clone(),
            faces: scene.polygons.len(),
            vertices: scene.vertex_count,
            lights: scene.light_count(),
            patches: layout.patch_count(),
            gpu_shots: shots.0,
            cpu_shots: shots.1,
            cpu_seconds: cpu_s,
            gpu_seconds: gpu_s,
            ratio: cpu_s / gpu_s,
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
    let report = Report {
        machine: cpu_model(),
        cores,
        gl_renderer: ctx.info.renderer.clone(),
        gl_version: ctx.info.version.clone(),
        stopping_rule: format!(
            "unshot power / emitted power <= {}; whole polygons shoot (one pass per shot, as in the paper), polygon form factor, {}² hemicube; median of {} run(s)",
            args.threshold, options.hemi_res, args.repeat
        ),
        options,
        peak_memory_mib: peak_memory_mib(),
        rows,
    };
    println!(
        "{} ({} cores); {} | {}",
        report.machine, report.cores, report.gl_renderer, report.gl_version
    );
    println!("stopping rule: {}", report.stopping_rule);
    println!(
        "| scene | faces | vertices | lights | patches | shots GPU/CPU | CPU s | GPU s | CPU/GPU | paper CPU s | paper GPU s | paper CPU/GPU |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &report.rows {
        println!(
            "| {} | {} | {} | {} | {} | {}/{} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {:.2} |",
            r.scene,
            r.faces,
            r.vertices,
            r.lights,
            r.patches,
            r.gpu_shots,
            r.cpu_shots,
            r.cpu_seconds,
            r.gpu_seconds,
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
