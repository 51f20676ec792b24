//! `radiosity bench table1`: the paper's Table 1 on this machine — both rooms, both solvers, the
//! same stopping rule — printed beside the paper's numbers. Three rows per room, timed in the
//! same run, each with its accuracy on the simple room (the guard of `validate::guard`): the
//! paper-faithful configuration (one polygon, one visibility and one reconstruction pass per
//! shot: `SolveOptions::paper_faithful`), the default (`SolveOptions::default_with`: cells for
//! large polygons and the speed options beyond the paper), and whole polygons with the speed
//! options (`SolveOptions::whole_polygons`), which is right only where every polygon is small
//! next to the patch size, as in these rooms, and is faster there.
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

use super::{cpu_model, gpu_run, median, peak_memory_mib, room, BenchArgs, ShaderCache};
use crate::gl::{GlContext, GlInfo};
use crate::solver::cpu::CpuSolver;
use crate::solver::{ChosenTuning, SolveOptions};
use crate::validate::guard;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The paper's Table 1 (Intel Core i3 3.6 GHz, GeForce GT705).
const PAPER: [(&str, f64, f64); 2] = [("simple", 4.0, 2.0), ("complex", 139.0, 79.0)];

/// The configurations of each room's rows: the paper's loop, the default, and whole polygons
/// with the default's speed options.
pub const CONFIGURATIONS: [&str; 3] = ["paper-faithful", "default", "whole polygons"];

/// The options of configuration `name` (one of [`CONFIGURATIONS`]).
pub fn configuration(name: &str, threshold: f32) -> SolveOptions {
    match name {
        "default" => SolveOptions::default_with(threshold),
        "whole polygons" => SolveOptions::whole_polygons(threshold),
        _ => SolveOptions::paper_faithful(threshold),
    }
}

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
    /// One of [`CONFIGURATIONS`].
    configuration: &'static str,
    faces: usize,
    vertices: usize,
    lights: usize,
    patches: u64,
    gpu: Times,
    cpu: Times,
    /// CPU loop / GPU loop.
    ratio: f64,
    /// The simple room only: the GPU solution's mean per-patch difference from the exhaustive
    /// CPU solution (`validate::guard`), a fraction.
    #[serde(skip_serializing_if = "Option::is_none")]
    mean_patch_difference: Option<f64>,
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
    /// The tuning profile of the GPU runs (`--tuning` on this renderer) and why.
    tuning: &'static str,
    tuning_reason: String,
    stopping_rule: String,
    /// What `setup_s` and `loop_s` time.
    timing: String,
    /// Mesa's shader cache during the timed GPU setups (`warm` or `cold`) and how it was made so.
    shader_cache: &'static str,
    shader_cache_note: String,
    /// The accuracy guard: what `mean_patch_difference` compares against, and its bound.
    guard: String,
    /// Each configuration's settings, by name.
    options: std::collections::BTreeMap<&'static str, SolveOptions>,
    peak_memory_mib: f64,
    rows: Vec<Row>,
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

/// The cold run: this program in a child process with the shader cache disabled. Returns its
/// setup's and loop's seconds.
fn cold_run_in_child(args: &BenchArgs, name: &str, configuration: &str) -> Result<(f64, f64)> {
    let text = super::run_child(
        args,
        &[
            "table1",
            "--gpu-only",
            "--scenes",
            name,
            "--configuration",
            configuration,
        ],
        &[("MESA_SHADER_CACHE_DISABLE", "true")],
        "the cold-cache GPU run",
    )?;
    let value = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key)?.trim().parse::<f64>().ok())
            .with_context(|| format!("the cold-cache GPU run printed no {key}: {text}"))
    };
    Ok((value("setup_s ")?, value("loop_s ")?))
}

pub fn run(args: &BenchArgs) -> Result<()> {
    if args.gpu_only {
        return run_gpu_only(args);
    }
    let cache = CachePlan::of(args);
    let info_ctx = GlContext::headless(args.backend)?;
    let info = info_ctx.info.clone();
    let tuning = super::chosen_tuning(args, &info_ctx);
    drop(info_ctx);
    let configurations = CONFIGURATIONS.len() as u64;
    let runs_per_configuration = 2 + cache.cold_child as u64;
    let steps =
        args.scenes.len() as u64 * configurations * runs_per_configuration * args.repeat as u64;
    let bar = if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        indicatif::ProgressBar::new(steps)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut rows = Vec::new();
    for name in &args.scenes {
        rows.extend(measure_room(args, name, &cache, &bar)?);
    }
    bar.finish_and_clear();
    let report = report(args, &cache, &info, &tuning, rows);
    print_report(&report, cache.cold_child);
    if let Some(path) = &args.json {
        crate::display::output::write_json(path, &report)?;
    }
    Ok(())
}

/// `--gpu-only`: one GPU run of `--configuration` on the first room, its times printed for the
/// parent (`cold_run_in_child`).
fn run_gpu_only(args: &BenchArgs) -> Result<()> {
    let name = args.scenes.first().context("no room")?;
    let (scene, layout) = room(name)?;
    let options = configuration(&args.configuration, args.threshold);
    // As in the parent, whose timed contexts are not the process's first (loading the
    // driver is not part of a setup): one context made and dropped before.
    drop(GlContext::headless(args.backend)?);
    let (setup, run, shots, _) = gpu_run((args.backend, args.tuning), &scene, &layout, &options)?;
    outln!("setup_s {setup}\nloop_s {run}\nshots {shots}");
    Ok(())
}

/// How the timed GPU runs meet Mesa's shader cache (`--shader-cache` and the environment).
struct CachePlan {
    /// The environment disables the cache.
    env_cold: bool,
    /// Every timed run is cold (the environment, or `--shader-cache cold`).
    cold: bool,
    /// One more GPU run per configuration and repeat with the cache disabled, in a child process
    /// (`--shader-cache both`, the others warm).
    cold_child: bool,
}

impl CachePlan {
    /// The plan `args` ask for; for `--shader-cache cold`, the cache disabled in this process.
    fn of(args: &BenchArgs) -> Self {
        let env_cold = shader_cache_disabled_by_env();
        if args.shader_cache == ShaderCache::Cold && !env_cold {
            // Before the first context: Mesa reads the variable when it creates its screen.
            std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true");
        }
        let cold = env_cold || args.shader_cache == ShaderCache::Cold;
        CachePlan {
            env_cold,
            cold,
            cold_child: args.shader_cache == ShaderCache::Both && !cold,
        }
    }

    /// The state of the cache during the timed setups (`warm` or `cold`), and how it was made
    /// so.
    fn state_and_note(&self) -> (&'static str, String) {
        let cache_dir = shader_cache_dir();
        let filled = shader_cache_filled(cache_dir.as_deref());
        let dir = cache_dir
            .as_deref()
            .map_or("no cache directory".into(), |d| d.display().to_string());
        let note = if self.cold {
            if self.env_cold {
                "cold: the environment disables Mesa's shader cache (MESA_SHADER_CACHE_DISABLE)"
                    .into()
            } else {
                "cold: --shader-cache cold, MESA_SHADER_CACHE_DISABLE=true".into()
            }
        } else if !filled {
            format!("warm asked for, but Mesa wrote nothing to {dir}: the timed setups were cold")
        } else if self.cold_child {
            format!(
                "warm (the headline): Mesa's shader cache ({dir}) filled by an untimed run first; \
                 cold: one more GPU run per repeat with MESA_SHADER_CACHE_DISABLE=true, in a child \
                 process"
            )
        } else {
            format!("warm: Mesa's shader cache ({dir}) filled by an untimed run first")
        };
        let state = if self.cold || !filled { "cold" } else { "warm" };
        (state, note)
    }
}

/// One room of the bench, with the accuracy guard's reference atlas (the simple room only).
struct Room<'a> {
    name: &'a str,
    scene: crate::scene::Scene,
    layout: crate::patches::PatchLayout,
    reference: Option<Vec<f32>>,
}

/// One configuration's measurements on one room, over the repeats.
#[derive(Default)]
struct Samples {
    gpu_setup_s: Vec<f64>,
    gpu_loop_s: Vec<f64>,
    cpu_setup_s: Vec<f64>,
    cpu_loop_s: Vec<f64>,
    /// `CachePlan::cold_child`'s runs.
    cold_setup_s: Vec<f64>,
    cold_loop_s: Vec<f64>,
    gpu_shots: u32,
    cpu_shots: u32,
    /// The GPU solution's mean per-patch difference from the guard's reference.
    difference: Option<f64>,
}

/// Room `name`'s rows: each configuration timed `--repeat` times on both solvers.
fn measure_room(
    args: &BenchArgs,
    name: &str,
    cache: &CachePlan,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<Row>> {
    let (scene, layout) = room(name)?;
    // The accuracy guard's reference, on the simple room (the complex room's would take the
    // CPU solver an hour).
    let reference = if name == "simple" {
        bar.set_message(format!(
            "{name}: the exhaustive CPU solution (accuracy guard)"
        ));
        let base = SolveOptions::paper_faithful(args.threshold);
        Some(guard::reference(&scene, &layout, &base, args.threads)?.0)
    } else {
        None
    };
    let room = Room {
        name,
        scene,
        layout,
        reference,
    };
    if !cache.cold {
        // Fill the shader cache: one untimed setup and a few shots of each configuration
        // (llvmpipe compiles and caches its shader variants at their first draw).
        bar.set_message(format!("{name}: GPU, filling the shader cache"));
        for c in CONFIGURATIONS {
            let warm_up = SolveOptions {
                max_shots: 3,
                ..configuration(c, args.threshold)
            };
            gpu_run(
                (args.backend, args.tuning),
                &room.scene,
                &room.layout,
                &warm_up,
            )?;
        }
    }
    // The configurations alternate within each repeat, so that all see the same machine.
    let mut samples = [(); CONFIGURATIONS.len()].map(|_| Samples::default());
    for _ in 0..args.repeat {
        for (c, samples) in CONFIGURATIONS.iter().zip(&mut samples) {
            time_configuration(args, &room, c, cache.cold_child, bar, samples)?;
        }
    }
    Ok((CONFIGURATIONS.iter().zip(samples))
        .map(|(c, samples)| row(&room, c, samples, cache.cold))
        .collect())
}

/// One repeat of configuration `c` on `room`: GPU setup, loop (and the cold ones in a child
/// process if `cold_child`); CPU setup, loop.
fn time_configuration(
    args: &BenchArgs,
    room: &Room,
    c: &str,
    cold_child: bool,
    bar: &indicatif::ProgressBar,
    samples: &mut Samples,
) -> Result<()> {
    let name = room.name;
    let options = configuration(c, args.threshold);
    if cold_child {
        bar.set_message(format!("{name}, {c}: GPU, shader cache disabled"));
        let (setup, run) = cold_run_in_child(args, name, c)?;
        samples.cold_setup_s.push(setup);
        samples.cold_loop_s.push(run);
        bar.inc(1);
    }
    bar.set_message(format!("{name}, {c}: GPU"));
    let (setup, run, n, atlas) = gpu_run(
        (args.backend, args.tuning),
        &room.scene,
        &room.layout,
        &options,
    )?;
    samples.gpu_setup_s.push(setup);
    samples.gpu_loop_s.push(run);
    samples.gpu_shots = n;
    if let Some(reference) = &room.reference {
        samples.difference = Some(guard::mean_patch_difference(&atlas, reference));
    }
    bar.inc(1);
    bar.set_message(format!("{name}, {c}: CPU"));
    let start = Instant::now();
    let mut cpu = CpuSolver::new(&room.scene, &room.layout, options, args.threads)?;
    samples.cpu_setup_s.push(start.elapsed().as_secs_f64());
    let start = Instant::now();
    cpu.solve(|_| {})?;
    samples.cpu_loop_s.push(start.elapsed().as_secs_f64());
    samples.cpu_shots = cpu.shots();
    bar.inc(1);
    Ok(())
}

/// The row of configuration `c` on `room`: the medians of `samples`, beside the paper's times.
fn row(room: &Room, c: &'static str, samples: Samples, cold: bool) -> Row {
    let name = room.name;
    let paper = PAPER
        .iter()
        .find(|p| p.0 == name)
        .copied()
        .unwrap_or((name, 0.0, 0.0));
    let median_if_any = |v: Vec<f64>| (!v.is_empty()).then(|| median(v));
    let gpu = Times {
        setup_s: median(samples.gpu_setup_s),
        loop_s: median(samples.gpu_loop_s),
        shots: samples.gpu_shots,
        shader_cache: Some(if cold { "cold" } else { "warm" }),
        setup_cold_s: median_if_any(samples.cold_setup_s),
        loop_cold_s: median_if_any(samples.cold_loop_s),
    };
    let cpu = Times {
        setup_s: median(samples.cpu_setup_s),
        loop_s: median(samples.cpu_loop_s),
        shots: samples.cpu_shots,
        shader_cache: None,
        setup_cold_s: None,
        loop_cold_s: None,
    };
    Row {
        scene: name.to_string(),
        configuration: c,
        faces: room.scene.polygons.len(),
        vertices: room.scene.vertex_count,
        lights: room.scene.light_count(),
        patches: room.layout.patch_count(),
        ratio: cpu.loop_s / gpu.loop_s,
        gpu,
        cpu,
        mean_patch_difference: samples.difference,
        paper_cpu_seconds: paper.1,
        paper_gpu_seconds: paper.2,
        paper_ratio: if paper.2 > 0.0 {
            paper.1 / paper.2
        } else {
            0.0
        },
    }
}

/// The report of `rows`, with what was measured and how.
fn report(
    args: &BenchArgs,
    cache: &CachePlan,
    info: &GlInfo,
    tuning: &ChosenTuning,
    mut rows: Vec<Row>,
) -> Report {
    let (state, shader_cache_note) = cache.state_and_note();
    for r in &mut rows {
        r.gpu.shader_cache = Some(state);
    }
    Report {
        machine: cpu_model(),
        cores: std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1),
        gl_renderer: info.renderer.clone(),
        gl_version: info.version.clone(),
        tuning: tuning.name(),
        tuning_reason: tuning.reason.clone(),
        stopping_rule: format!(
            "unshot power / emitted power <= {}; paper-faithful: whole polygons shoot (one pass \
             per shot, as in the paper), polygon form factor, {}² hemicube; default: `radiosity \
             solve`'s settings (cells of 4×4 patches, overshooting, the item buffer by shot and \
             turned, {} shooters per pass); whole polygons: the default's speed options with \
             whole polygons shooting; the default and whole polygons scale back a shot that \
             delivered more than it carried, the paper-faithful row only reports it, as the paper \
             has no such step; median of {} run(s)",
            args.threshold,
            crate::solver::BENCH_HEMI_RES,
            crate::solver::MAX_SHOOTERS_PER_PASS,
            args.repeat
        ),
        timing:
            "setup: everything before the first shot (GPU: a new GL context, not the process's \
                 first, and GpuSolver::new, i.e. shader compiles, uploads and the emission pass, \
                 to a glFinish; CPU: \
                 CpuSolver::new, its patches and BVH); loop: the shots to the stopping rule \
                 (llvmpipe compiles a shader's variants at their first draw, in the loop's first \
                 shots); CPU/GPU compares the loops; the paper gives one time per solver"
                .into(),
        shader_cache: state,
        shader_cache_note,
        guard: format!(
            "mean per-patch difference of the GPU solution from the CPU solver's (exact \
             visibility, the paper-faithful shooters) run to {} unshot, simple room only; \
             bound {} %",
            guard::REFERENCE_THRESHOLD,
            100.0 * guard::MEAN_DIFFERENCE_BOUND
        ),
        options: CONFIGURATIONS
            .iter()
            .map(|&c| {
                let options = configuration(c, args.threshold);
                let tuning = tuning.tuning();
                (c, SolveOptions { tuning, ..options })
            })
            .collect(),
        peak_memory_mib: peak_memory_mib(),
        rows,
    }
}

/// Print `report`: the machine and settings, then the table (the GPU columns cold / warm if
/// `cold_child`).
fn print_report(report: &Report, cold_child: bool) {
    let state = report.shader_cache;
    outln!(
        "{} ({} cores); {} | {}",
        report.machine,
        report.cores,
        report.gl_renderer,
        report.gl_version
    );
    outln!("tuning: {} ({})", report.tuning, report.tuning_reason);
    outln!("stopping rule: {}", report.stopping_rule);
    outln!("timing: {}", report.timing);
    outln!("shader cache: {}", report.shader_cache_note);
    outln!("accuracy: {}", report.guard);
    let gpu_header = if cold_child {
        "GPU setup s cold / warm | GPU loop s cold / warm".to_string()
    } else {
        format!("GPU setup s ({state}) | GPU loop s ({state})")
    };
    outln!(
        "| scene | configuration | faces | vertices | lights | patches | shots GPU/CPU | CPU setup s | CPU loop s | {gpu_header} | CPU/GPU loops | mean patch diff | paper CPU s | paper GPU s | paper CPU/GPU |"
    );
    outln!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
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
        let difference = r
            .mean_patch_difference
            .map_or("—".to_string(), |d| format!("{:.2} %", 100.0 * d));
        outln!(
            "| {} | {} | {} | {} | {} | {} | {}/{} | {:.3} | {:.2} | {} | {} | {:.2} | {} | {:.1} | {:.1} | {:.2} |",
            r.scene,
            r.configuration,
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
            difference,
            r.paper_cpu_seconds,
            r.paper_gpu_seconds,
            r.paper_ratio
        );
    }
    outln!("peak memory: {:.0} MiB", report.peak_memory_mib);
}
