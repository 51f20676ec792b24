//! A solve stepped shot by shot, printing each step's shooters, item-buffer sides,
//! passes and the named pass times (issue 58, the conference room).
//! `cargo run --release --example shot_probe -- SCENE.obj SECONDS [emit=NAME=R,G,B]...
//! [shot_triangles=N] [small=N] [hemi=N] [walk=N] [-walk_item_buffers]`: one line per step (its
//! first polygon, that polygon's shooters and their item-buffer sides, the passes, the seconds,
//! the share of the emitted power, the unshot fraction, and the seconds of each named pass).
use gpu_radiosity::gl::{BackendChoice, GlContext};
use gpu_radiosity::pipeline;
use gpu_radiosity::scene::LoadOptions;
use gpu_radiosity::solver::{GpuSolver, SolveOptions};
use std::path::Path;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut load = LoadOptions::default();
    let mut o = SolveOptions::accurate();
    o.threshold = 0.01;
    for extra in &args[3..] {
        if let Some(rule) = extra.strip_prefix("emit=") {
            load.emit.push(gpu_radiosity::cli::emission(rule).unwrap());
        } else if let Some(v) = extra.strip_prefix("shot_triangles=") {
            o.shot_triangles = v.parse().unwrap();
        } else if let Some(v) = extra.strip_prefix("small=") {
            o.small_hemi_res = v.parse().unwrap();
        } else if let Some(v) = extra.strip_prefix("hemi=") {
            o.hemi_res = v.parse().unwrap();
        } else if let Some(v) = extra.strip_prefix("walk=") {
            o.tuning.walk_up_to = v.parse().unwrap();
        } else if extra == "-walk_item_buffers" {
            o.tuning = o.tuning.drawing();
        } else {
            panic!("unknown {extra}");
        }
    }
    let seconds: f64 = args[2].parse().unwrap();
    let (scene, _) = pipeline::load_scene_with(Some(Path::new(&args[1])), &load).unwrap();
    let layout = pipeline::lay_out(&scene, None, None).unwrap();
    let ctx = GlContext::headless(BackendChoice::Auto).unwrap();
    let mut solver = GpuSolver::new(&ctx, &scene, &layout, o).unwrap();
    let start = Instant::now();
    let mut last: std::collections::BTreeMap<&str, f64> = Default::default();
    while start.elapsed().as_secs_f64() < seconds {
        let polys = solver.next_polygons(8);
        let first = polys.first().copied();
        let sides: Vec<u32> = first
            .map(|p| solver.shooters_of(p).iter().map(|s| s.hemi_res).collect())
            .unwrap_or_default();
        let (p0, t0) = (solver.passes(), Instant::now());
        let Some(r) = solver.step().unwrap() else {
            break;
        };
        let dt = t0.elapsed().as_secs_f64();
        let mut parts = String::new();
        for (k, v) in solver.times().iter() {
            let d = v - last.get(k).copied().unwrap_or(0.0);
            last.insert(k, v);
            parts += &format!(" {}={:.2}", &k[..4], d);
        }
        let (mn, mx) = (sides.iter().min(), sides.iter().max());
        println!(
            "t={:.0} shot {} poly {:?} ({}) cells {} side {:?}-{:?} passes {} step {:.1}s share {:.4} unshot {:.4} |{}",
            start.elapsed().as_secs_f64(),
            r.shot,
            first,
            first.map(|p| scene.polygons[p].object.clone()).unwrap_or_default(),
            sides.len(),
            mn,
            mx,
            solver.passes() - p0,
            dt,
            r.shot_power / solver.emitted_power(),
            r.unshot_fraction,
            parts
        );
    }
}
