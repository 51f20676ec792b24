//! `radiosity bench scaling`: how the cost grows with the patch count. Each room is solved at
//! `--scales` times its own patch count (the patch side divided by √scale), by both solvers, with
//! the paper-faithful configuration (`SolveOptions::paper_faithful`; `--configuration default` or
//! `"whole polygons"` for the others),
//! each run in a child process of its own so that its peak memory is its own. A run that has
//! not converged after `--budget` seconds of shots stops there; its loop time is then
//! extrapolated, and marked so, from a run of the same room and solver that did converge
//! (whole polygons shoot, so the shots hardly depend on the patch count): the stopped run has
//! done the share of its work that the converged run had done after as many shots (their
//! `progress`). The first shots cost more than the last (they light most of the room), so
//! seconds per shot times shots would overestimate: 533 s for a run measured at 300 s. Without
//! such a run, seconds per shot times the shot count of a converged run of the same room. The
//! exponent is the least-squares slope of log(loop time) against log(patches).

use super::{median, room, BenchArgs};
use crate::display::scaling_plot;
use crate::gl::GlContext;
use crate::patches::{PatchLayout, Resolution};
use crate::solver::cpu::CpuSolver;
use crate::solver::{Backend, GpuSolver, Solver};
use anyhow::{Context, Result};
use std::time::Instant;

/// One run's figures, as the child prints them (JSON).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Run {
    /// The room measured (`simple`, `complex`).
    pub room: String,
    /// How many times the room's patch count the run used.
    pub scale: u32,
    /// The solver (`gpu`, `cpu`).
    pub solver: String,
    /// The patches of the run's layout.
    pub patches: u64,
    /// Seconds from loading to the first shot (contexts, programs, atlases).
    pub setup_s: f64,
    /// Loop seconds measured (to convergence, or to the budget).
    pub loop_s: f64,
    /// Shots made in the loop seconds.
    pub shots: u32,
    /// Whether the run reached the stopping rule within the budget.
    pub complete: bool,
    /// Peak resident memory of the child process, MiB.
    pub peak_mib: f64,
    /// Seconds per named pass (visibility, reconstruction, ...).
    pub passes: Vec<(String, f64)>,
    /// The loop time to convergence: `loop_s` if complete, else extrapolated (set by the
    /// parent).
    #[serde(default)]
    pub loop_to_convergence_s: f64,
    /// The shot count `loop_to_convergence_s` assumes.
    #[serde(default)]
    pub shots_to_convergence: u32,
    /// Loop seconds after every `PROGRESS_STEP` shots, for extrapolating the runs of the same
    /// room and solver that the budget stops.
    #[serde(default)]
    pub progress: Vec<f64>,
}

impl Run {
    /// The run as a point of the scaling plot.
    fn point(&self) -> scaling_plot::Point {
        scaling_plot::Point {
            room: self.room.clone(),
            solver: self.solver.clone(),
            patches: self.patches,
            loop_s: self.loop_to_convergence_s,
            measured: self.complete,
        }
    }
}

/// Shots between two entries of `Run::progress`.
const PROGRESS_STEP: u32 = 100;

/// Solve until converged or until `budget` seconds of shots have passed: the loop seconds,
/// whether it converged, and the seconds after every [`PROGRESS_STEP`] shots.
fn run_until<B: Backend>(solver: &mut Solver<B>, budget: f64) -> Result<(f64, bool, Vec<f64>)> {
    let start = Instant::now();
    solver.restart_clock();
    let mut progress = Vec::new();
    while start.elapsed().as_secs_f64() < budget {
        if solver.step()?.is_none() {
            return Ok((start.elapsed().as_secs_f64(), true, progress));
        }
        if solver.shots().is_multiple_of(PROGRESS_STEP) {
            progress.push(start.elapsed().as_secs_f64());
        }
    }
    Ok((start.elapsed().as_secs_f64(), solver.converged(), progress))
}

/// The seconds `r` (a converged run) had spent after `shots` shots, from its progress
/// (linear between entries; `None` beyond the last).
fn seconds_after(r: &Run, shots: u32) -> Option<f64> {
    let k = shots / PROGRESS_STEP;
    let before = |k: u32| match k {
        0 => Some(0.0),
        k => r.progress.get(k as usize - 1).copied(),
    };
    let (a, b) = (before(k)?, before(k + 1)?);
    Some(a + (b - a) * (shots % PROGRESS_STEP) as f64 / PROGRESS_STEP as f64)
}

/// The child: one room, scale and solver.
fn one(args: &BenchArgs, spec: &str) -> Result<()> {
    let [name, scale, solver] = spec.split(',').collect::<Vec<_>>()[..] else {
        anyhow::bail!("--one wants ROOM,SCALE,SOLVER, got {spec}");
    };
    let scale: u32 = scale.parse().context("the scale")?;
    let (scene, base) = room(name)?;
    let size = base.patch_size / (scale as f32).sqrt();
    let layout = PatchLayout::try_new(&scene, Resolution::PatchSize(size))?;
    let options = super::table1::configuration(&args.configuration, args.threshold);
    let budget = args.budget as f64;
    let start = Instant::now();
    let (setup_s, (loop_s, complete, progress), shots, times) = match solver {
        "gpu" => {
            use glow::HasContext;
            let ctx = GlContext::headless(args.backend)?;
            let options = crate::solver::SolveOptions {
                tuning: super::chosen_tuning(args, &ctx).tuning(),
                ..options
            };
            let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options)?;
            unsafe { ctx.gl.finish() };
            let setup = start.elapsed().as_secs_f64();
            let result = run_until(&mut gpu, budget)?;
            (setup, result, gpu.shots(), gpu.times().clone())
        }
        _ => {
            let mut cpu = CpuSolver::new(&scene, &layout, options, args.threads)?;
            let setup = start.elapsed().as_secs_f64();
            let result = run_until(&mut cpu, budget)?;
            (setup, result, cpu.shots(), cpu.times().clone())
        }
    };
    let run = Run {
        room: name.into(),
        scale,
        solver: solver.into(),
        patches: layout.patch_count(),
        setup_s,
        loop_s,
        shots,
        complete,
        peak_mib: super::peak_memory_mib(),
        passes: times.iter().map(|(k, v)| (k.to_string(), v)).collect(),
        loop_to_convergence_s: 0.0,
        shots_to_convergence: 0,
        progress,
    };
    outln!("{}", serde_json::to_string(&run)?);
    Ok(())
}

/// Fill in every run's `loop_to_convergence_s` and `shots_to_convergence`: its own for the runs
/// that converged; for those the budget stopped, by the share of its work the largest converged
/// run of the same room and solver had done after as many shots (see the module comment), and
/// failing that, by seconds per shot and the median shot count of the room's converged runs.
fn extrapolate(runs: &mut [Run]) {
    for k in 0..runs.len() {
        let r = &runs[k];
        let known: Vec<f64> = runs
            .iter()
            .filter(|c| c.room == r.room && c.complete)
            .map(|c| c.shots as f64)
            .collect();
        let share = runs
            .iter()
            .filter(|c| c.room == r.room && c.solver == r.solver && c.complete)
            .max_by_key(|c| c.patches)
            .and_then(|c| Some((seconds_after(c, r.shots)? / c.loop_s, c.shots)));
        let r = &mut runs[k];
        if r.complete {
            r.loop_to_convergence_s = r.loop_s;
            r.shots_to_convergence = r.shots;
        } else if let Some((share, shots)) = share.filter(|&(share, _)| share > 0.0) {
            r.loop_to_convergence_s = r.loop_s / share;
            r.shots_to_convergence = shots;
        } else if !known.is_empty() && r.shots > 0 {
            let shots = median(known).round() as u32;
            r.loop_to_convergence_s = r.loop_s / r.shots as f64 * shots as f64;
            r.shots_to_convergence = shots;
        }
    }
}

/// Run one child and read its figures.
fn child(args: &BenchArgs, name: &str, scale: u32, solver: &str) -> Result<Run> {
    let spec = format!("{name},{scale},{solver}");
    let (budget, threads) = (args.budget.to_string(), args.threads.to_string());
    let text = super::run_child(
        args,
        &[
            "scaling",
            "--one",
            &spec,
            "--configuration",
            &args.configuration,
            "--budget",
            &budget,
            "--threads",
            &threads,
        ],
        &[],
        &format!("the {solver} run of {name} at {scale}x"),
    )?;
    let line = text.lines().last().unwrap_or("");
    serde_json::from_str(line).with_context(|| format!("reading the child's figures: {text}"))
}

/// Least-squares slope of log(y) against log(x).
pub fn exponent(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .map(|p| (p.0.ln(), p.1.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as f64;
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / n,
        logs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// The pass that took most of a run's time.
fn dominant(run: &Run) -> String {
    let total: f64 = run.passes.iter().map(|p| p.1).sum();
    run.passes
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or("-".into(), |(k, v)| {
            format!("{k} {:.0} %", 100.0 * v / total.max(1e-12))
        })
}

/// What `--from` reads of a saved report.
#[derive(serde::Deserialize)]
struct Saved {
    machine: String,
    configuration: String,
    threshold: f32,
    budget_s: u64,
    runs: Vec<Run>,
}

#[derive(serde::Serialize)]
struct Report {
    machine: String,
    configuration: String,
    threshold: f32,
    budget_s: u64,
    runs: Vec<Run>,
    /// Per room and solver: the exponent of loop time against patches.
    exponents: Vec<(String, String, f64)>,
}

/// `radiosity bench scaling`: cost against patch count, both solvers, with its plot and JSON.
pub fn run(args: &BenchArgs) -> Result<()> {
    if let Some(spec) = &args.one {
        return one(args, spec);
    }
    let mut runs = Vec::new();
    let mut header = (
        super::cpu_model(),
        args.configuration.clone(),
        args.threshold,
        args.budget,
    );
    if let Some(path) = &args.from {
        // A saved report: print and plot it again without solving.
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let saved: Saved = serde_json::from_str(&text).with_context(|| {
            format!("{} is not a `bench scaling --json` report", path.display())
        })?;
        header = (
            saved.machine,
            saved.configuration,
            saved.threshold,
            saved.budget_s,
        );
        runs = saved.runs;
    } else {
        for name in &args.scenes {
            for &scale in &args.scales {
                for solver in ["gpu", "cpu"] {
                    eprintln!("scaling: {name} at {scale}x, {solver}");
                    runs.push(child(args, name, scale, solver)?);
                }
            }
        }
    }
    let rooms: Vec<String> = runs.iter().fold(Vec::new(), |mut rooms, r| {
        if !rooms.contains(&r.room) {
            rooms.push(r.room.clone());
        }
        rooms
    });
    extrapolate(&mut runs);
    let mut exponents = Vec::new();
    for name in &rooms {
        for solver in ["gpu", "cpu"] {
            let points: Vec<(f64, f64)> = runs
                .iter()
                .filter(|r| &r.room == name && r.solver == solver)
                .map(|r| (r.patches as f64, r.loop_to_convergence_s))
                .collect();
            if let Some(e) = exponent(&points) {
                exponents.push((name.clone(), solver.to_string(), e));
            }
        }
    }
    let (machine, configuration, threshold, budget_s) = header;
    outln!(
        "{machine}; configuration {configuration}, threshold {threshold}, budget {budget_s} s per run"
    );
    outln!("| room | scale | patches | solver | setup s | loop s | shots | s per shot | peak MiB | most time in |");
    outln!("|---|---|---|---|---|---|---|---|---|---|");
    for r in &runs {
        let (loop_s, note) = if r.complete {
            (format!("{:.1}", r.loop_s), String::new())
        } else {
            (
                format!(
                    "{:.0} (extrapolated; stopped after {:.0} s)",
                    r.loop_to_convergence_s, r.loop_s
                ),
                format!(" of {}", r.shots_to_convergence),
            )
        };
        outln!(
            "| {} | {}x | {} | {} | {:.2} | {} | {}{} | {:.4} | {:.0} | {} |",
            r.room,
            r.scale,
            r.patches,
            r.solver,
            r.setup_s,
            loop_s,
            r.shots,
            note,
            r.loop_s / r.shots.max(1) as f64,
            r.peak_mib,
            dominant(r)
        );
    }
    for (room, solver, e) in &exponents {
        outln!("exponent {room} {solver}: loop time ∝ patches^{e:.2}");
    }
    if let Some(path) = &args.plot {
        let points: Vec<_> = runs.iter().map(Run::point).collect();
        let rgb = scaling_plot::draw(&points, &exponents, &configuration)?;
        let (width, height) = scaling_plot::SIZE;
        crate::display::output::write_atomic(
            path,
            crate::display::output::Payload::Png {
                width,
                height,
                rgb: &rgb,
            },
        )?;
    }
    if let Some(path) = &args.json {
        let report = Report {
            machine,
            configuration,
            threshold,
            budget_s,
            runs,
            exponents,
        };
        crate::display::output::write_json(path, &report)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_exponent_of_a_power_law() {
        let points: Vec<(f64, f64)> = [1.0f64, 4.0, 16.0]
            .iter()
            .map(|&x| (x, 3.0 * x.powf(1.5)))
            .collect();
        assert!((exponent(&points).unwrap() - 1.5).abs() < 1e-9);
        assert_eq!(exponent(&points[..1]), None);
    }

    fn run(solver: &str, patches: u64, loop_s: f64, shots: u32, progress: Vec<f64>) -> Run {
        Run {
            room: "room".into(),
            scale: 1,
            solver: solver.into(),
            patches,
            setup_s: 0.0,
            loop_s,
            shots,
            complete: !progress.is_empty(),
            peak_mib: 0.0,
            passes: Vec::new(),
            loop_to_convergence_s: 0.0,
            shots_to_convergence: 0,
            progress,
        }
    }

    #[test]
    fn a_stopped_run_is_extrapolated_by_the_share_of_work_a_converged_one_had_done() {
        // A converged run of 400 shots whose first shots cost most: half its 10 s after 100.
        let converged = run("cpu", 100, 10.0, 400, vec![5.0, 7.0, 8.5, 10.0]);
        assert_eq!(seconds_after(&converged, 150), Some(6.0));
        assert_eq!(seconds_after(&converged, 0), Some(0.0));
        assert_eq!(seconds_after(&converged, 450), None);
        // A larger run stopped after 150 shots and 30 s: 60 % of the work, 50 s in all (seconds
        // per shot would say 80 s). The GPU's stopped run has no converged GPU run to follow:
        // seconds per shot times the room's converged shot count.
        let mut runs = vec![
            converged,
            run("cpu", 400, 30.0, 150, Vec::new()),
            run("gpu", 400, 3.0, 150, Vec::new()),
        ];
        extrapolate(&mut runs);
        assert_eq!(runs[0].loop_to_convergence_s, 10.0);
        assert!((runs[1].loop_to_convergence_s - 50.0).abs() < 1e-9);
        assert_eq!(runs[1].shots_to_convergence, 400);
        assert!((runs[2].loop_to_convergence_s - 8.0).abs() < 1e-9);
    }
}
