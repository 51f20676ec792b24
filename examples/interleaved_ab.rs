//! Two GPU solver configurations timed shot by shot, interleaved in one process: the way to see a
//! change of a few per cent on a VM whose speed drifts by ±15 % between runs (docs/perf-log.md,
//! 2026-12-02). Both solvers share one GL context; after each step a `glFinish`, so each step's
//! time is its own work; the solvers take turns at going first, and their first steps are not
//! timed. Two runs of the same configuration agree to about 0.5 %; run A/B and B/A both.
//!
//! `cargo run --release --example interleaved_ab -- SCENE.obj SHOTS A B`, where A and B are
//! comma-separated changes to the fast configuration (`SolveOptions::whole_polygons`):
//! `base` (none), `paper` (the paper-faithful row's options), `accurate` (`radiosity solve`'s
//! default mode), `kN` (N shooters per pass), `fc` (`SolveOptions::face_clusters`),
//! `no-overshoot`, `small=N` (the small shots' item-buffer side), `min=N` (the smallest shots'
//! side, `SolveOptions::min_hemi_res`), `mark=N` (`Tuning::marking_below`), `walk=N`
//! (`Tuning::walk_up_to`, 0: the walk at every side), `gpu` (the GPU profile), or `-SWITCH` to
//! turn off one `Tuning` switch (`-marking_pass`, `-plates`, …; `+receivers_only` turns that
//! one on). The last line says whether the two ended with the same lightmaps.
//! Switches of `Tuning` leave the answer as it is, so both solvers take the same shots; options
//! that change the answer may make them take different ones.
//!
//! After B, optional `emit=NAME=R,G,B` (repeatable, as `--emit`), `patches=N` (as
//! `--patches`; default: `radiosity solve`'s budget for the scene), for third-party scenes, and
//! `threshold=F` (both solvers stop at that unshot share, or at SHOTS):
//! `… lost_empire.obj 2000 accurate accurate,-plates emit=Torch=5,4,2`.

use glow::HasContext;
use gpu_radiosity::gl::{BackendChoice, GlContext};
use gpu_radiosity::pipeline;
use gpu_radiosity::scene::LoadOptions;
use gpu_radiosity::solver::{GpuSolver, ReceiverChoice, SolveOptions};
use std::path::Path;
use std::time::Instant;

/// Steps of each solver left out of the times.
const UNTIMED_ROUNDS: u32 = 10;

fn configuration(changes: &str) -> SolveOptions {
    let mut o = gpu_radiosity::solver::SolveOptions::whole_polygons(0.01);
    for change in changes.split(',') {
        let t = &mut o.tuning;
        match change {
            "" | "base" => {}
            "paper" => o = gpu_radiosity::solver::SolveOptions::paper_faithful(0.01),
            "accurate" => o = SolveOptions::accurate(),
            k if k.starts_with('k') => o.shooters_per_pass = k[1..].parse().expect("kN: a count"),
            "no-overshoot" => o.overshoot = false,
            "fc" => o.face_clusters = true,
            small if small.starts_with("small=") => {
                o.small_hemi_res = small[6..].parse().expect("small=N: a resolution")
            }
            min if min.starts_with("min=") => {
                o.min_hemi_res = min[4..].parse().expect("min=N: a resolution")
            }
            walk if walk.starts_with("walk=") => {
                t.walk_up_to = walk[5..].parse().expect("walk=N: a side (0: every side)")
            }
            "gpu" => *t = gpu_radiosity::solver::Tuning::gpu(),
            mark if mark.starts_with("mark=") => {
                t.marking_below = mark[5..].parse().expect("mark=N: a percentage")
            }
            "-receivers_only" => t.receivers = ReceiverChoice::Every,
            "+receivers_only" => t.receivers = ReceiverChoice::InFront,
            "-marking_pass" => {
                t.marking_pass = false;
                // Few-shooter programs need the marking pass.
                t.walk = t.walk.min(gpu_radiosity::solver::Walk::ReceiversFound);
            }
            "-skip_needless_clipping" => t.receivers = t.receivers.min(ReceiverChoice::InFront),
            "-unroll_quads" => t.unroll_quads = false,
            "-compile_choices" => t.compile_choices = false,
            "-squares_as_points" => t.squares_as_points = false,
            "-guard_band" => t.guard_band = 1,
            "-cull_views" => t.cull_views = false,
            "-split_unclipped" => t.split_unclipped = false,
            "-half_side_faces" => t.half_side_faces = false,
            "-plates" => t.plates = false,
            "-cull_solids" => t.cull_solids = false,
            "-cull_between_samples" => t.cull_between_samples = false,
            "-cull_hidden" => t.walk = gpu_radiosity::solver::Walk::Off,
            "-walk_item_buffers" => *t = t.drawing(),
            "-flush_visibility" => t.flush_visibility = false,
            other => panic!("unknown change '{other}' (see the file's comment)"),
        }
    }
    o
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 5 {
        eprintln!(
            "usage: interleaved_ab SCENE.obj SHOTS A B [emit=NAME=R,G,B]... [patches=N] [threshold=F] \
             (see examples/interleaved_ab.rs)"
        );
        std::process::exit(2);
    }
    let mut options = LoadOptions::default();
    let mut patches = None;
    let mut threshold = None;
    for extra in &args[5..] {
        if let Some(rule) = extra.strip_prefix("emit=") {
            // The same parser and checks as `radiosity solve --emit`.
            options
                .emit
                .push(gpu_radiosity::cli::emission(rule).unwrap_or_else(|e| panic!("emit=: {e}")));
        } else if let Some(n) = extra.strip_prefix("patches=") {
            patches = Some(n.parse().expect("patches=N: a count"));
        } else if let Some(t) = extra.strip_prefix("threshold=") {
            threshold = Some(t.parse::<f32>().expect("threshold=F: a share"));
        } else {
            panic!("unknown argument '{extra}' (see the file's comment)");
        }
    }
    let (scene, _) =
        pipeline::load_scene_with(Some(Path::new(&args[1])), &options).expect("the scene loads");
    let shots: u32 = args[2].parse().expect("SHOTS is a number");
    let layout = pipeline::lay_out(&scene, None, patches).expect("the atlas fits");
    let ctx = GlContext::headless(BackendChoice::Auto).expect("a GL 3.0 context");
    let mut solvers = [&args[3], &args[4]].map(|changes| {
        let mut options = configuration(changes);
        if let Some(t) = threshold {
            // The stopping rule given, and no shot limit short of SHOTS.
            options.threshold = t;
            options.max_shots = shots;
        }
        GpuSolver::new(&ctx, &scene, &layout, options).expect("the solver starts")
    });
    let mut seconds = [0.0; 2];
    let mut done = [0u32; 2];
    unsafe { ctx.gl.finish() };
    let mut round = 0;
    while done.iter().any(|&n| n < shots) {
        // Each round the other one first; the first rounds untimed (they compile the programs,
        // which the first solver to draw pays for both when Mesa's shader cache is cold).
        let order = if round % 2 == 0 { [0, 1] } else { [1, 0] };
        for k in order {
            if done[k] >= shots {
                continue;
            }
            let start = Instant::now();
            done[k] = match solvers[k].step().expect("the shot succeeds") {
                Some(record) => record.shot,
                None => shots,
            };
            unsafe { ctx.gl.finish() };
            if round >= UNTIMED_ROUNDS {
                seconds[k] += start.elapsed().as_secs_f64();
            }
        }
        round += 1;
    }
    let shot = |k: usize| solvers[k].shots();
    println!(
        "A {}: {:.3} s, {} shots; B {}: {:.3} s, {} shots; B/A {:.3}",
        args[3],
        seconds[0],
        shot(0),
        args[4],
        seconds[1],
        shot(1),
        seconds[1] / seconds[0]
    );
    println!(
        "passes: A {}, B {}; unshot: A {:.5}, B {:.5}; face-cluster steps: A {}, B {}",
        solvers[0].passes(),
        solvers[1].passes(),
        solvers[0].unshot_fraction(),
        solvers[1].unshot_fraction(),
        solvers[0].face_cluster_shots(),
        solvers[1].face_cluster_shots()
    );
    // Options that change the answer: how far B's radiance is from A's, patch by patch
    // (|B − A| / A, A at least 1e-3) and in sum.
    let (a, b) = (solvers[0].radiosity_atlas(), solvers[1].radiosity_atlas());
    let mean = |t: &[f32]| (t[0] as f64 + t[1] as f64 + t[2] as f64) / 3.0;
    let mut d: Vec<f64> = (a.chunks_exact(4).zip(b.chunks_exact(4)))
        .filter(|(a, _)| a[3] > 0.0)
        .map(|(a, b)| (mean(b) - mean(a)).abs() / mean(a).max(1e-3))
        .collect();
    d.sort_by(f64::total_cmp);
    let q = |f: f64| 100.0 * d[((d.len() - 1) as f64 * f) as usize];
    let sum = |x: &[f32]| {
        x.chunks_exact(4)
            .filter(|t| t[3] > 0.0)
            .map(mean)
            .sum::<f64>()
    };
    println!(
        "B against A, patch by patch: median {:.3} %, 90th {:.3} %, 95th {:.3} %, 99th {:.3} %; \
         sum of radiance {:+.3} %",
        q(0.5),
        q(0.9),
        q(0.95),
        q(0.99),
        100.0 * (sum(&b) - sum(&a)) / sum(&a)
    );
    let marked = |k: usize| solvers[k].backend().reconstruction.marked_passes();
    println!(
        "passes with the marking pass: A {}, B {}",
        marked(0),
        marked(1)
    );
    let missed = |k: usize| solvers[k].backend().visibility.missed();
    println!(
        "polygon views left out between pixel centres: A {}, B {}",
        missed(0),
        missed(1)
    );
    // Switches of `Tuning` must leave the answer as it is: say whether they did.
    let same = solvers[0].radiosity_atlas() == solvers[1].radiosity_atlas()
        && solvers[0].unshot_atlas() == solvers[1].unshot_atlas();
    println!(
        "lightmaps: {}",
        if same {
            "bit for bit the same"
        } else {
            "different"
        }
    );
}
