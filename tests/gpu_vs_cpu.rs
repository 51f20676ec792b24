//! The GPU solver against the CPU solver (same patches, shooters and form factors; exact
//! ray-cast visibility on the CPU) on the Cornell box, patch by patch; and the CPU solver's
//! determinism across thread counts.
//!
//! Tolerances, and why: the two differ only in visibility. The GPU samples it from the shooter
//! (a hemicube of IDs; a patch is hidden when the polygon its pixel shows lies between it and the
//! shooter); the CPU casts an exact ray from each patch centre. They disagree on patches crossed by a shadow boundary and on
//! patches that see part of a shooter cell whose centre is behind them. So: after one shot
//! almost every patch agrees to float precision; after a whole solve the differences spread
//! (every later shot carries them), and we bound their distribution, not the worst patch.

mod common;

use common::*;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::solver::cpu::CpuSolver;
use gpu_radiosity::solver::{GpuSolver, SolveOptions};

fn mean(t: &[f32]) -> f64 {
    (t[0] as f64 + t[1] as f64 + t[2] as f64) / 3.0
}

fn relative_errors(g: &[f32], c: &[f32]) -> Vec<f64> {
    let mut errors: Vec<f64> = g
        .chunks_exact(4)
        .zip(c.chunks_exact(4))
        .filter(|(_, c)| c[3] > 0.0)
        .map(|(g, c)| (mean(g) - mean(c)).abs() / mean(c).max(1e-3))
        .collect();
    errors.sort_by(|a, b| a.total_cmp(b));
    errors
}

#[test]
fn one_shot_agrees_almost_everywhere() {
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(1500));
    let ctx = context();
    let options = SolveOptions::accurate();
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
    let light = gpu.next_polygon().unwrap();
    assert_eq!(cpu.next_polygon(), Some(light));
    let shooters = gpu.shooters_of(light);
    gpu.shoot(&shooters).unwrap();
    cpu.shoot(&shooters).unwrap();
    let errors = relative_errors(&gpu.radiosity_atlas(), &cpu.radiosity_atlas());
    let close = errors.iter().filter(|&&e| e < 1e-2).count();
    let median = errors[errors.len() / 2];
    println!(
        "first shot: {close} of {} patches agree within 1 %; median difference {:.2e}",
        errors.len(),
        median
    );
    assert!(median < 1e-3, "median {median}");
    // The light shoots patch by patch (30 shooters): each casts its own shadow edges.
    assert!(close as f64 >= 0.93 * errors.len() as f64);
    // paper_notes 4: "1,493 patches: after the first shot ... the median per-patch difference
    // is 1.5e-5 and 96 % of patches agree within 1 %".
    assert_eq!(errors.len(), 1493);
    assert_quoted("first shot, median", median, "1.5e-5");
    assert_quoted(
        "first shot, % within 1 %",
        100.0 * close as f64 / errors.len() as f64,
        "96",
    );
}

#[test]
fn a_pane_in_front_of_a_wall_casts_its_shadow() {
    // The simple Table 1 room: window glass 2 mm in front of a wall, cabinet doors 6 mm in front
    // of the carcass, paper 1 mm above a desk. A depth comparison with a pixel's slack lets light
    // through such layers (the GPU once reflected 30 % more of the first shot than the CPU); the
    // shown polygon's plane does not.
    let scene = load("simple");
    let size = scene.patch_size.unwrap();
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(size));
    let ctx = context();
    let options = gpu_radiosity::solver::SolveOptions::paper_faithful(0.01);
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
    let light = gpu.next_polygon().unwrap();
    let shooters = gpu.shooters_of(light);
    let (g, c) = (gpu.shoot(&shooters).unwrap(), cpu.shoot(&shooters).unwrap());
    let reflected = (g.reflected_power - c.reflected_power) / c.reflected_power;
    let errors = relative_errors(&gpu.radiosity_atlas(), &cpu.radiosity_atlas());
    let close = errors.iter().filter(|&&e| e < 1e-2).count() as f64 / errors.len() as f64;
    println!(
        "simple room, first shot: reflected power GPU {:.4} CPU {:.4} ({:+.2} %); {:.2} % of patches within 1 %",
        g.reflected_power,
        c.reflected_power,
        100.0 * reflected,
        100.0 * close
    );
    // The depth-slack test gave +30 %.
    assert!(
        reflected.abs() < 0.02,
        "reflected power differs by {reflected}"
    );
    assert!(close > 0.95, "{close} of the patches within 1 %");
    // paper_notes 4: at the bench's 128² hemicube "the GPU's receivers reflect 0.8 % less power
    // than the CPU's and 97.6 % of patches agree within 1 %" (measured -0.78 %, 97.62 %).
    assert_quoted(
        "simple room, first shot, reflected",
        100.0 * reflected,
        "-0.8",
    );
    assert_quoted("simple room, first shot, within 1 %", 100.0 * close, "97.6");
}

#[test]
fn the_simple_room_solved_on_both() {
    // The Table 1 bench's solve of the simple room (its options, to 1 % unshot) on both solvers:
    // the shots docs/numbers.md gives (GPU 1,352, CPU 1,398, as on 2026-12-03: the row scales
    // no shot back since 2026-12-07; 1,333 and 1,377 while it did) and the mean patch
    // difference (1.49 %: mean absolute difference over the mean radiance, RGB means).
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()));
    let ctx = context();
    let options = gpu_radiosity::solver::SolveOptions::paper_faithful(0.01);
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    gpu.solve(|_| {}).unwrap();
    let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
    cpu.solve(|_| {}).unwrap();
    let (g, c) = (gpu.radiosity_atlas(), cpu.radiosity_atlas());
    let (mut diff, mut sum, mut n) = (0.0, 0.0, 0usize);
    for (g, c) in g.chunks_exact(4).zip(c.chunks_exact(4)) {
        if c[3] > 0.0 {
            diff += (mean(g) - mean(c)).abs();
            sum += mean(c);
            n += 1;
        }
    }
    let difference = diff / sum;
    println!(
        "simple room: {n} patches, GPU {} shots, CPU {} shots; mean patch difference {:.4} %",
        gpu.shots(),
        cpu.shots(),
        100.0 * difference
    );
    assert_eq!(n, 14445);
    assert_eq!((gpu.shots(), cpu.shots()), (1352, 1398), "shots GPU, CPU");
    assert_quoted(
        "simple room, mean patch difference",
        100.0 * difference,
        "1.49",
    );
}

#[test]
fn gpu_and_cpu_agree_patch_by_patch() {
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(1500));
    let ctx = context();
    // The accurate mode only: the paper's mode is checked against the CPU shot by shot
    // (tests/single_shot.rs); over whole solves the two disagree by far more than visibility
    // (measured: mean 95 %, GPU 44 shots, CPU 559), and a figure no test can bound is not printed.
    {
        let mode = "accurate";
        let options = SolveOptions {
            threshold: 1e-3,
            ..SolveOptions::accurate()
        };
        let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
        gpu.solve(|_| {}).unwrap();
        let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
        cpu.solve(|_| {}).unwrap();
        let errors = relative_errors(&gpu.radiosity_atlas(), &cpu.radiosity_atlas());
        let q = |f: f64| errors[((errors.len() - 1) as f64 * f) as usize];
        let avg = errors.iter().sum::<f64>() / errors.len() as f64;
        println!(
            "{mode}: {} patches, GPU {} shots, CPU {} shots; relative difference mean {:.4} %, median {:.4} %, 95th {:.3} %",
            errors.len(),
            gpu.shots(),
            cpu.shots(),
            100.0 * avg,
            100.0 * q(0.5),
            100.0 * q(0.95),
        );
        // Nearly the same shots to the threshold (measured: GPU 57, CPU 55; overshooting counts
        // only patches that have received, and a patch at a contact may receive a trace on one
        // solver and nothing on the other).
        assert!(
            gpu.shots().abs_diff(cpu.shots()) * 10 <= cpu.shots(),
            "shots"
        );
        assert!(q(0.5) < 0.01, "median {}", q(0.5));
        assert!(q(0.95) < 0.05, "95th percentile {}", q(0.95));
        assert!(avg < 0.025, "mean {avg}");
        // docs/accuracy.md: "after a whole solve (threshold 0.001) ... median 0.08 %, 95th
        // percentile 1.09 %, mean 0.42 %".
        assert_quoted("whole solve, median %", 100.0 * q(0.5), "0.08");
        assert_quoted("whole solve, 95th percentile %", 100.0 * q(0.95), "1.09");
        assert_quoted("whole solve, mean %", 100.0 * avg, "0.42");
    }
}

#[test]
fn the_cpu_solver_gives_the_same_bits_for_any_thread_count() {
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(800));
    let run = |threads| {
        let mut cpu = CpuSolver::new(&scene, &layout, SolveOptions::accurate(), threads).unwrap();
        cpu.solve(|_| {}).unwrap();
        cpu.radiosity_atlas()
    };
    let one = run(1);
    for threads in [2, 3] {
        assert!(
            one.iter()
                .zip(run(threads))
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{threads} threads"
        );
    }
}
