//! `radiosity bench guard`: every speed option on the simple room, its GPU loop time and shots
//! beside its accuracy (the mean per-patch difference from the exhaustive CPU solution,
//! `validate::guard`), so that no option is timed without its price in accuracy.

use super::{gpu_run, median, room, BenchArgs};
use crate::solver::configurations;
use crate::solver::SolveOptions;
use crate::validate::guard;
use anyhow::Result;
use std::time::Instant;

#[derive(serde::Serialize)]
struct Row {
    configuration: &'static str,
    overshoot: bool,
    small_hemi_res: u32,
    small_shot: f32,
    min_hemi_res: u32,
    rotate_item_buffer: bool,
    shooters_per_pass: u32,
    gpu_loop_s: f64,
    shots: u32,
    /// A fraction; bound: `guard::MEAN_DIFFERENCE_BOUND`.
    mean_patch_difference: f64,
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let name = "simple";
    let (scene, layout) = room(name)?;
    let configurations = configurations(args.threshold);
    let start = Instant::now();
    let (reference, reference_shots) =
        guard::reference(&scene, &layout, &configurations[0].1, args.threads)?;
    outln!(
        "reference: CPU solver to {} unshot, {} shots, {:.1} s; bound {} %",
        guard::REFERENCE_THRESHOLD,
        reference_shots,
        start.elapsed().as_secs_f64(),
        100.0 * guard::MEAN_DIFFERENCE_BOUND
    );
    // A few untimed shots of each fill Mesa's shader cache; then the configurations alternate
    // within each repeat, so that all of them see the same machine.
    for (_, options) in &configurations {
        gpu_run(
            args.backend,
            &scene,
            &layout,
            &SolveOptions {
                max_shots: 10,
                ..options.clone()
            },
        )?;
    }
    let mut times = vec![Vec::new(); configurations.len()];
    let mut results = vec![(0, 0.0); configurations.len()];
    for _ in 0..args.repeat {
        for (k, (_, options)) in configurations.iter().enumerate() {
            let (_, run, shots, atlas) = gpu_run(args.backend, &scene, &layout, options)?;
            times[k].push(run);
            results[k] = (shots, guard::mean_patch_difference(&atlas, &reference));
        }
    }
    outln!("| configuration | GPU loop s | shots | mean patch diff |");
    outln!("|---|---|---|---|");
    let mut rows = Vec::new();
    for ((name, options), (times, (shots, difference))) in configurations
        .into_iter()
        .zip(times.into_iter().zip(results))
    {
        let row = Row {
            configuration: name,
            overshoot: options.overshoot,
            small_hemi_res: options.small_hemi_res,
            small_shot: options.small_shot,
            min_hemi_res: options.min_hemi_res,
            rotate_item_buffer: options.rotate_item_buffer,
            shooters_per_pass: options.shooters_per_pass,
            gpu_loop_s: median(times),
            shots,
            mean_patch_difference: difference,
        };
        outln!(
            "| {} | {:.2} | {} | {:.2} % |",
            row.configuration,
            row.gpu_loop_s,
            row.shots,
            100.0 * row.mean_patch_difference
        );
        rows.push(row);
    }
    if let Some(path) = &args.json {
        crate::display::output::write_json(path, &rows)?;
    }
    Ok(())
}
