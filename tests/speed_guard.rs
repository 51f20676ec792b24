//! The accuracy guard of the speed options (issue 21; `validate::guard`): on the simple Table 1
//! room, every configuration `radiosity bench guard` times, solved on the GPU to the bench's
//! stopping rule, against the CPU solver run exhaustively (exact visibility, to 0.1 % unshot).
//! A speed option may not make the answer worse than the paper-faithful configuration's, and
//! the fast configuration (the one Table 1's fast row times) must stay within 1.5 %.

mod common;

use common::*;
use gpu_radiosity::cli::bench::room;
use gpu_radiosity::solver::GpuSolver;
use gpu_radiosity::solver::{configurations, SolveOptions};
use gpu_radiosity::validate::guard;

#[test]
fn no_speed_option_moves_the_simple_room_away_from_the_exhaustive_solution() {
    let (scene, layout) = room("simple").unwrap();
    let (reference, shots) =
        guard::reference(&scene, &layout, &SolveOptions::paper_faithful(0.01), 0).unwrap();
    println!("reference (whole polygons): {shots} shots");
    let ctx = context();
    let mut differences = Vec::new();
    // The reference shoots whole polygons; the default shoots in cells, another discretisation
    // of the answer (18 % from this reference), which `radiosity bench guard` measures against
    // an exhaustive solution shooting cells (1.72 %; its 3,511 CPU shots take too long for this
    // test) and tests/path_traced.rs on the Cornell box.
    let configurations: Vec<_> = configurations(0.01)
        .into_iter()
        .filter(|(name, _)| *name != "default")
        .collect();
    for (name, options) in configurations {
        let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
        gpu.solve(|_| {}).unwrap();
        let d = guard::mean_patch_difference(&gpu.radiosity_atlas(), &reference);
        println!(
            "{name}: {} shots, mean patch difference {:.3} %",
            gpu.shots(),
            100.0 * d
        );
        differences.push((name, gpu.shots(), d));
    }
    let (_, base_shots, base) = differences[0];
    for &(name, shots, d) in &differences[1..] {
        assert!(
            d <= base,
            "{name}: {:.3} % from the exhaustive solution, the paper-faithful configuration {:.3} %",
            100.0 * d,
            100.0 * base
        );
        // Overshooting saves time by taking fewer shots (the others by cheaper ones).
        if name == "overshoot" || name == "whole polygons" {
            assert!(
                shots < base_shots,
                "{name}: {shots} shots, paper-faithful {base_shots}"
            );
        }
    }
    let (name, _, d) = differences[differences.len() - 1];
    assert_eq!(name, "whole polygons");
    assert!(
        d <= guard::MEAN_DIFFERENCE_BOUND,
        "{name}: {:.3} %",
        100.0 * d
    );
    // README ("Table 1") and docs/accuracy.md quote these.
    let quoted = [
        ("paper-faithful", "1.86", 1352),
        ("overshoot", "1.61", 883),
        ("item buffer by shot", "1.68", 1394),
        ("item buffer turned", "1.82", 1359),
        ("shooters per pass", "1.86", 1346),
        ("whole polygons", "1.25", 906),
    ];
    for &(name, shots, d) in &differences {
        println!("{name}: {:.4} %, {shots} shots", 100.0 * d);
    }
    for ((name, d_quoted, shots_quoted), &(got, shots, d)) in quoted.iter().zip(&differences) {
        assert_eq!(*name, got);
        assert_quoted(
            &format!("{name}, mean patch difference %"),
            100.0 * d,
            d_quoted,
        );
        assert_eq!(shots, *shots_quoted, "{name}: shots");
    }
}

/// The CPU solver follows overshooting and several shooters per pass (here three: the cells of
/// one polygon, or of several, share a pass) the way the GPU does (the item buffer's resolution
/// is the GPU's alone), so the two still agree patch by patch on the Cornell box, within the
/// bounds `tests/gpu_vs_cpu.rs` sets without them.
#[test]
fn the_cpu_twin_follows_the_speed_options() {
    use gpu_radiosity::patches::{PatchLayout, Resolution};
    use gpu_radiosity::solver::cpu::CpuSolver;
    use gpu_radiosity::solver::SolveOptions;
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(1500));
    let options = SolveOptions {
        threshold: 1e-3,
        overshoot: true,
        shooters_per_pass: 3,
        ..SolveOptions::accurate()
    };
    let gpu_atlas = {
        let ctx = context();
        let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
        gpu.solve(|_| {}).unwrap();
        (gpu.radiosity_atlas(), gpu.shots())
    };
    let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
    cpu.solve(|_| {}).unwrap();
    let mean = |t: &[f32]| (t[0] as f64 + t[1] as f64 + t[2] as f64) / 3.0;
    let mut errors: Vec<f64> = (gpu_atlas.0.chunks_exact(4))
        .zip(cpu.radiosity_atlas().chunks_exact(4))
        .filter(|(_, c)| c[3] > 0.0)
        .map(|(g, c)| (mean(g) - mean(c)).abs() / mean(c).max(1e-3))
        .collect();
    errors.sort_by(|a, b| a.total_cmp(b));
    let q = |f: f64| errors[((errors.len() - 1) as f64 * f) as usize];
    let avg = errors.iter().sum::<f64>() / errors.len() as f64;
    println!(
        "GPU {} shots, CPU {} shots; relative difference mean {:.4} %, median {:.4} %, 95th {:.3} %",
        gpu_atlas.1,
        cpu.shots(),
        100.0 * avg,
        100.0 * q(0.5),
        100.0 * q(0.95)
    );
    assert!(
        gpu_atlas.1.abs_diff(cpu.shots()) <= gpu_atlas.1 / 20,
        "shots"
    );
    assert!(q(0.5) < 0.01, "median {}", q(0.5));
    assert!(q(0.95) < 0.05, "95th percentile {}", q(0.95));
    assert!(avg < 0.025, "mean {avg}");
}

/// Overshooting changes the path, not the destination: solved far down (1e-5 unshot), the
/// Cornell box comes out the same with and without it, and with fewer shots.
#[test]
fn overshooting_converges_to_the_same_solution_in_fewer_shots() {
    use gpu_radiosity::patches::{PatchLayout, Resolution};
    use gpu_radiosity::solver::cpu::CpuSolver;
    use gpu_radiosity::solver::SolveOptions;
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(400));
    let solve = |overshoot: bool| {
        let options = SolveOptions {
            threshold: 1e-5,
            shooter_cell: 0,
            emitter_cell: 0,
            overshoot,
            ..SolveOptions::accurate()
        };
        let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
        cpu.solve(|_| {}).unwrap();
        // Never more unshot power, in magnitude, than was emitted.
        for r in cpu.history() {
            assert!(
                r.unshot_fraction <= 1.0 + 1e-6,
                "shot {}: {}",
                r.shot,
                r.unshot_fraction
            );
        }
        (cpu.radiosity_atlas(), cpu.shots())
    };
    let (plain, plain_shots) = solve(false);
    let (over, over_shots) = solve(true);
    let d = guard::mean_patch_difference(&over, &plain);
    println!("without {plain_shots} shots, with {over_shots}; mean patch difference {d:.2e}");
    assert!(
        over_shots < plain_shots,
        "{over_shots} against {plain_shots}"
    );
    assert!(d < 1e-4, "mean patch difference {d}");
}

/// A small shot draws only the lower-left corner of the item buffer, at its own resolution, and
/// the pass pictures show what that shot drew: the Cornell box's light (the first shot, most of
/// the power) at 256² per face, its fifth shot at 64².
#[test]
fn small_shots_draw_a_smaller_item_buffer() {
    let dir = tempfile::tempdir().unwrap();
    // One side for every small shot (`--min-hemi-res 0`: not the default's cube-root sides).
    let options = [
        "--small-hemi-res",
        "64",
        "--small-shot",
        "0.5",
        "--min-hemi-res",
        "0",
    ];
    let run = ["--dump-passes", "1,5", "--max-shots", "5"];
    solve_whole_polygons(dir.path(), &[&options[..], &run].concat());
    for (shot, size) in [(1, (1280, 256)), (5, (320, 64))] {
        let png = image::open(dir.path().join(format!("shot-{shot:03}-itembuffer.png"))).unwrap();
        assert_eq!((png.width(), png.height()), size, "shot {shot}");
        // Something was seen in it (not a stale or empty corner).
        let seen = png.to_rgb8().pixels().filter(|p| p.0 != [0, 0, 0]).count();
        assert!(
            seen > (size.0 * size.1 / 4) as usize,
            "shot {shot}: {seen} pixels"
        );
    }
    // A resolution above the item buffer's is refused with both named.
    let out = dir.path().join("refused");
    let out = out.to_str().unwrap();
    let (code, stderr) = run_refused(&[
        "solve",
        "--hemi-res",
        "64",
        "--small-hemi-res",
        "128",
        "--out",
        out,
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("128") && stderr.contains("16..=64"),
        "{stderr}"
    );
}

/// `--min-hemi-res`: below `--small-shot` the item buffer's side falls with the cube root of the
/// shot's share of the emitted power, down to the least; the pass pictures show the side each
/// shot drew at, which its share in stats.json gives.
#[test]
fn the_smallest_shots_draw_smaller_still() {
    let dir = tempfile::tempdir().unwrap();
    let options = [
        "--small-hemi-res",
        "128",
        "--small-shot",
        "0.5",
        "--min-hemi-res",
        "16",
    ];
    let run = ["--dump-passes", "1,2,5,9", "--max-shots", "9"];
    solve_whole_polygons(dir.path(), &[&options[..], &run].concat());
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["min_hemi_res"], 16);
    let emitted = stats["emitted_power"].as_f64().unwrap();
    let mut sides = Vec::new();
    for shot in [1, 2, 5, 9] {
        let power = stats["history"][shot - 1]["shot_power"].as_f64().unwrap();
        let share = power.abs() / emitted;
        let side = if share >= 0.5 {
            256
        } else {
            ((128.0 * (share / 0.5).cbrt()).round() as u32).clamp(16, 128)
        };
        let png = image::open(dir.path().join(format!("shot-{shot:03}-itembuffer.png"))).unwrap();
        assert_eq!(
            (png.width(), png.height()),
            (5 * side, side),
            "shot {shot}: share {share:.4}"
        );
        sides.push(side);
    }
    // The light's shot at the full side, later ones below the small shots' side.
    assert_eq!(sides[0], 256, "{sides:?}");
    assert!(sides[2..].iter().all(|&s| s < 128), "{sides:?}");
    // Without a small shots' resolution, or above it, refused with what it needs named.
    for extra in [
        &["--small-hemi-res", "0", "--min-hemi-res", "16"][..],
        &["--small-hemi-res", "32", "--min-hemi-res", "64"],
    ] {
        let out = dir.path().join("refused");
        let out = out.to_str().unwrap();
        let (code, stderr) =
            run_refused(&[&["solve", "--max-shots", "1"], extra, &["--out", out]].concat());
        assert_eq!(code, 1, "{stderr}");
        assert!(
            stderr.contains("smallest shots") && stderr.contains("--min-hemi-res"),
            "{stderr}"
        );
    }
}

/// `--rotate-item-buffer` turns each shot's item buffer about the shooter's normal by the
/// golden-ratio sequence of angles: the first shot's turn is zero, so its item buffer is the
/// unturned one, and the second's is not; stats.json records the option.
#[test]
fn the_item_buffer_turns_shot_by_shot() {
    let dir = tempfile::tempdir().unwrap();
    let solve = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let run = ["--dump-passes", "1,2", "--max-shots", "2"];
        // One 64² item buffer for every shot (no smaller ones for small shots), turned or not.
        let fixed = ["--hemi-res", "64", "--small-hemi-res", "0"];
        solve_whole_polygons(&out, &[&fixed[..], extra, &run].concat());
        out
    };
    let (plain, turned) = (
        solve("plain", &["--rotate-item-buffer", "false"]),
        solve("turned", &["--rotate-item-buffer"]),
    );
    let picture = |dir: &std::path::Path, shot: u32| {
        image::open(dir.join(format!("shot-{shot:03}-itembuffer.png")))
            .unwrap()
            .to_rgb8()
    };
    assert_eq!(picture(&plain, 1), picture(&turned, 1), "shot 1 turns by 0");
    let (a, b) = (picture(&plain, 2), picture(&turned, 2));
    let changed = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
    assert!(
        changed > (a.width() * a.height() / 20) as usize,
        "{changed} pixels changed"
    );
    let stats = |dir: &std::path::Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("stats.json")).unwrap()).unwrap()
    };
    assert_eq!(stats(&plain)["rotate_item_buffer"], false);
    assert_eq!(stats(&turned)["rotate_item_buffer"], true);
}

/// Several shooters per pass (`--shooters-per-pass`) shoot simultaneously: from one state, a
/// pass of the two polygons with the most unshot power adds to every patch what each of them
/// alone would add, and leaves each shooter's texels with what the other sends them (their own
/// unshot energy shot). On both solvers; one step counts two shots and one pass.
#[test]
fn the_shooters_of_one_pass_shoot_simultaneously() {
    use gpu_radiosity::patches::{PatchLayout, Resolution};
    use gpu_radiosity::solver::cpu::CpuSolver;
    use gpu_radiosity::solver::{Backend, Solver};
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(600));
    // The light's shot first, so that several polygons have power; then the state S.
    let start = after_the_lights_shot(&scene, &layout);
    // From S: the two shooters together, and each alone.
    fn from<B: Backend>(
        solver: &mut Solver<'_, B>,
        start: &(Vec<f32>, Vec<f32>),
        alone: Option<usize>,
    ) -> (Vec<f32>, Vec<f32>, Vec<usize>) {
        solver.load_atlases(&start.0, &start.1).unwrap();
        let top = solver.next_polygons(2);
        match alone {
            Some(i) => {
                let shooters = solver.shooters_of(top[i]);
                solver.shoot(&shooters).unwrap();
            }
            None => {
                let (shots, passes) = (solver.shots(), solver.passes());
                solver.step().unwrap();
                assert_eq!((solver.shots(), solver.passes()), (shots + 2, passes + 1));
            }
        }
        (solver.radiosity_atlas(), solver.unshot_atlas(), top)
    }
    let check = |name: &str,
                 joint: (Vec<f32>, Vec<f32>, Vec<usize>),
                 a: (Vec<f32>, Vec<f32>, Vec<usize>),
                 b: (Vec<f32>, Vec<f32>, Vec<usize>)| {
        let top = joint.2.clone();
        assert_eq!(top.len(), 2, "{name}");
        assert!(top[0] != top[1]);
        let rects = [
            layout.lightmaps[top[0]].texels(),
            layout.lightmaps[top[1]].texels(),
        ];
        let width = layout.atlas_width as usize;
        let inside = |[x0, y0, x1, y1]: [u32; 4], t: usize| {
            let (x, y) = ((t % width) as u32, (t / width) as u32);
            (x0..x1).contains(&x) && (y0..y1).contains(&y)
        };
        let (mut worst, mut received) = (0f32, 0usize);
        for t in 0..layout.atlas_width as usize * layout.atlas_height as usize {
            for c in 0..3 {
                let i = t * 4 + c;
                let (da, db) = (a.0[i] - start.0[i], b.0[i] - start.0[i]);
                received += (da > 0.0 && db > 0.0) as usize;
                let radiosity = start.0[i] + da + db;
                // A shooter's texels: what the other sends them; the others: both add.
                let unshot = if inside(rects[0], t) {
                    db
                } else if inside(rects[1], t) {
                    da
                } else {
                    start.1[i] + da + db
                };
                for (got, want) in [(joint.0[i], radiosity), (joint.1[i], unshot)] {
                    worst = worst.max((got - want).abs() / want.abs().max(1e-3));
                }
            }
        }
        println!("{name}: polygons {top:?}, {received} channels received from both, worst relative difference {worst:.2e}");
        assert!(received > 100, "{name}: {received}");
        assert!(worst < 1e-4, "{name}: {worst}");
    };
    // Without overshooting: each alone would leave its own remainder in its texels.
    let options = |k| SolveOptions {
        overshoot: false,
        ..whole_polygons(k)
    };
    let cpu = |k| CpuSolver::new(&scene, &layout, options(k), 0).unwrap();
    check(
        "CPU",
        from(&mut cpu(2), &start, None),
        from(&mut cpu(1), &start, Some(0)),
        from(&mut cpu(1), &start, Some(1)),
    );
    let ctx = context();
    let gpu = |k| GpuSolver::new(&ctx, &scene, &layout, options(k)).unwrap();
    check(
        "GPU",
        from(&mut gpu(2), &start, None),
        from(&mut gpu(1), &start, Some(0)),
        from(&mut gpu(1), &start, Some(1)),
    );
}

/// A pass with fewer shooters than it was set up for fills the other slots with shooters that
/// carry nothing: from one state, two polygons shot through a pass set up for eight leave the
/// same lightmaps, bit for bit, as through one set up for two; and the step that begins a solve
/// (the lights alone have power) takes fewer polygons than its slots.
#[test]
fn a_pass_with_idle_slots_adds_what_a_full_one_adds() {
    use gpu_radiosity::patches::{PatchLayout, Resolution};
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(600));
    let start = after_the_lights_shot(&scene, &layout);
    let ctx = context();
    let shoot_two = |k: u32| {
        let mut gpu = GpuSolver::new(&ctx, &scene, &layout, whole_polygons(k)).unwrap();
        gpu.load_atlases(&start.0, &start.1).unwrap();
        let top = gpu.next_polygons(2);
        let shooters: Vec<_> = top.iter().flat_map(|&p| gpu.shooters_of(p)).collect();
        assert_eq!(shooters.len(), 2);
        gpu.shoot(&shooters).unwrap();
        assert_eq!(gpu.passes(), 1);
        (gpu.radiosity_atlas(), gpu.unshot_atlas())
    };
    let (two, eight) = (shoot_two(2), shoot_two(8));
    assert!(two.0 != start.0, "the pass added nothing");
    assert!(two.0 == eight.0, "radiance differs with idle slots");
    assert!(two.1 == eight.1, "unshot radiance differs with idle slots");
    // The first step: the light alone has power, and one polygon is shot through eight slots.
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, whole_polygons(8)).unwrap();
    gpu.step().unwrap();
    assert_eq!((gpu.shots(), gpu.passes()), (1, 1));
}

/// `--shooters-per-pass` on the command line: a solve with two shooters per pass records the
/// option and one pass per two shots (the first shot, the light alone, aside); a count outside
/// 1..=8 and the pass pictures (which picture one shooter per pass) are refused with the reason.
#[test]
fn shooters_per_pass_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("two");
    solve_whole_polygons(&out, &["--shooters-per-pass", "2", "--max-shots", "9"]);
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["shooters_per_pass"], 2, "{stats}");
    let history = stats["history"].as_array().unwrap();
    // The light alone first (nothing else has power yet), then two polygons a step.
    let shots: Vec<u64> = history
        .iter()
        .map(|r| r["shot"].as_u64().unwrap())
        .collect();
    assert_eq!(shots, [1, 3, 5, 7, 9], "{shots:?}");
    let refused = |extra: &[&str], needle: &str| {
        let out = dir.path().join("refused");
        let out = out.to_str().unwrap();
        let (_, stderr) = run_refused(&[&["solve"], extra, &["--out", out]].concat());
        assert!(stderr.contains(needle), "{stderr}");
    };
    refused(&["--shooters-per-pass", "9"], "1..=8");
    refused(&["--shooters-per-pass", "0"], "1..=8");
    refused(
        &["--shooters-per-pass", "2", "--dump-passes", "1"],
        "--shooters-per-pass 1",
    );
}

/// Several shooters per pass change the order, not the destination: solved far down (1e-5
/// unshot) on the CPU, the Cornell box in the accurate mode, whole polygons shooting but the
/// light in cells of one patch (so that steps of several polygons, and a polygon whose cells
/// take several passes, both occur), comes out the same with one shooter per pass and with
/// three. (A step whose polygons spread over several passes lost what a later shooter received
/// from an earlier pass: 21 % in a region of the path-traced test.)
#[test]
fn shooters_per_pass_converge_to_the_same_solution() {
    use gpu_radiosity::patches::{PatchLayout, Resolution};
    use gpu_radiosity::solver::cpu::CpuSolver;
    use gpu_radiosity::solver::SolveOptions;
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(400));
    let solve = |k: u32| {
        let options = SolveOptions {
            threshold: 1e-5,
            shooters_per_pass: k,
            shooter_cell: 0,
            // Every shot's cells cut: which shots cut (by their share of the power) would
            // otherwise depend on the order, and the discretisation with it.
            cut_above: 0.0,
            ..SolveOptions::accurate()
        };
        let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
        cpu.solve(|_| {}).unwrap();
        // Steps of more than one polygon: fewer records in the history than shots.
        let steps = cpu.history().len() as u32;
        assert_eq!(
            steps < cpu.shots(),
            k > 1,
            "{steps} steps, {} shots",
            cpu.shots()
        );
        (cpu.radiosity_atlas(), cpu.shots(), cpu.passes())
    };
    let (one, one_shots, one_passes) = solve(1);
    let (three, three_shots, three_passes) = solve(3);
    let d = guard::mean_patch_difference(&three, &one);
    println!(
        "one per pass: {one_shots} shots, {one_passes} passes; three: {three_shots} shots, \
         {three_passes} passes; mean patch difference {d:.2e}"
    );
    assert!(three_passes * 2 < one_passes, "{three_passes} passes");
    // Measured 1.67e-4: the shots scaled back (`conserve`) and the overshoot estimates differ
    // with the order; the energy lost to a pass spread over several steps was 21 % in a region.
    assert!(d < 5e-4, "mean patch difference {d}");
}

/// `radiosity solve` of the default scene with whole polygons shooting and emitting (no cells)
/// and `args`, into `out`.
fn solve_whole_polygons(out: &std::path::Path, args: &[&str]) {
    let args = ["solve", "--shooter-cell", "0", "--emitter-cell", "0"]
        .iter()
        .chain(args)
        .chain(&["--out"])
        .map(std::ffi::OsStr::new)
        .chain([out.as_os_str()]);
    run_ok(args);
}

/// The accurate mode with whole polygons shooting (the light too), `k` to a pass.
fn whole_polygons(k: u32) -> gpu_radiosity::solver::SolveOptions {
    gpu_radiosity::solver::SolveOptions {
        shooter_cell: 0,
        emitter_cell: 0,
        shooters_per_pass: k,
        ..gpu_radiosity::solver::SolveOptions::accurate()
    }
}

/// Radiance and unshot atlases after the CPU solver's first shot (the light's) with
/// [`whole_polygons`]: a state in which several polygons have power.
fn after_the_lights_shot(
    scene: &gpu_radiosity::scene::Scene,
    layout: &gpu_radiosity::patches::PatchLayout,
) -> (Vec<f32>, Vec<f32>) {
    let mut cpu =
        gpu_radiosity::solver::cpu::CpuSolver::new(scene, layout, whole_polygons(1), 0).unwrap();
    cpu.step().unwrap();
    (cpu.radiosity_atlas(), cpu.unshot_atlas())
}
