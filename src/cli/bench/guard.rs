//! `radiosity bench guard`: every speed option, its GPU loop time and shots beside its accuracy,
//! so that no option is timed without its price in accuracy. Two accuracies: on the simple room
//! the mean per-patch difference from the exhaustive CPU solution (`validate::guard`), and on the
//! Cornell box the worst region against the path-traced reference (`validate::path_traced`).

use super::{gpu_run, median, room, BenchArgs};
use crate::patches::{PatchLayout, Resolution};
use crate::scene::bundled;
use crate::solver::configurations;
use crate::solver::SolveOptions;
use crate::validate::guard;
use crate::validate::path_traced::{self, CORNELL_PATCHES, CORNELL_PATHS};
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
    /// The simple room.
    gpu_loop_s: f64,
    shots: u32,
    /// A fraction, against the exhaustive solution that shoots as this configuration does
    /// (`guard::same_shooters`); bound: `guard::MEAN_DIFFERENCE_BOUND`.
    mean_patch_difference: f64,
    /// The Cornell box (4,096 patches).
    cornell_gpu_loop_s: f64,
    cornell_shots: u32,
    /// The region whose polygon differs most from the path-traced reference.
    cornell_worst_region: &'static str,
    /// That polygon's |difference| from the reference, a fraction (RGB mean).
    cornell_worst_difference: f64,
}

/// The last repeat's figures of one configuration: shots and accuracy on each scene.
#[derive(Clone, Default)]
struct Measured {
    shots: u32,
    difference: f64,
    cornell_shots: u32,
    cornell_region: &'static str,
    cornell_worst: f64,
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let (scene, layout) = room("simple")?;
    let cornell = bundled::cornell().load()?;
    let cornell_layout = PatchLayout::try_new(&cornell, Resolution::Patches(CORNELL_PATCHES))?;
    let configurations = configurations(args.threshold);
    // One exhaustive reference per kind of shooter (whole polygons, cells): each configuration is
    // measured against the discretisation it shoots.
    let mut references: Vec<(SolveOptions, Vec<f32>)> = Vec::new();
    for (name, options) in &configurations {
        if references
            .iter()
            .any(|(o, _)| guard::same_shooters(o, options))
        {
            continue;
        }
        let start = Instant::now();
        let (reference, shots) = guard::reference(&scene, &layout, options, args.threads)?;
        outln!(
            "simple room reference for {name}'s shooters: CPU solver to {} unshot, {} shots, \
             {:.1} s; bound {} %",
            guard::REFERENCE_THRESHOLD,
            shots,
            start.elapsed().as_secs_f64(),
            100.0 * guard::MEAN_DIFFERENCE_BOUND
        );
        references.push((options.clone(), reference));
    }
    let reference_of = |options: &SolveOptions| -> &[f32] {
        let found = references
            .iter()
            .find(|(o, _)| guard::same_shooters(o, options));
        &found.expect("a reference for every configuration").1
    };
    let start = Instant::now();
    let traced = path_traced::Reference::new(&cornell, &cornell_layout, CORNELL_PATHS)?;
    outln!(
        "Cornell box reference: path traced, {} paths at each of {} patch centres, {:.1} s; \
         worst reference standard error {:.2} %",
        CORNELL_PATHS,
        cornell_layout.patches_per_polygon.iter().sum::<u32>(),
        start.elapsed().as_secs_f64(),
        100.0
            * traced
                .polygons
                .iter()
                .map(|&(_, noise)| noise)
                .fold(0.0, f32::max)
    );
    // A few untimed shots of each fill Mesa's shader cache; then the configurations alternate
    // within each repeat, so that all of them see the same machine.
    for (_, options) in &configurations {
        let warm = SolveOptions {
            max_shots: 10,
            ..options.clone()
        };
        gpu_run((args.backend, args.tuning), &scene, &layout, &warm)?;
        gpu_run(
            (args.backend, args.tuning),
            &cornell,
            &cornell_layout,
            &warm,
        )?;
    }
    let mut times = vec![Vec::new(); configurations.len()];
    let mut cornell_times = vec![Vec::new(); configurations.len()];
    let mut results = vec![Measured::default(); configurations.len()];
    for _ in 0..args.repeat {
        for (k, (_, options)) in configurations.iter().enumerate() {
            let (_, run, shots, atlas) =
                gpu_run((args.backend, args.tuning), &scene, &layout, options)?;
            times[k].push(run);
            let (_, cornell_run, cornell_shots, cornell_atlas) = gpu_run(
                (args.backend, args.tuning),
                &cornell,
                &cornell_layout,
                options,
            )?;
            cornell_times[k].push(cornell_run);
            let comparison =
                path_traced::compare(&cornell, &cornell_layout, &traced, &cornell_atlas)?;
            results[k] = Measured {
                shots,
                difference: guard::mean_patch_difference(&atlas, reference_of(options)),
                cornell_shots,
                cornell_region: comparison.worst_row().map_or("", |r| r.region),
                cornell_worst: comparison.worst as f64,
            };
        }
    }
    outln!(
        "| configuration | GPU loop s | shots | mean patch diff | Cornell GPU loop s | Cornell shots | Cornell worst region |"
    );
    outln!("|---|---|---|---|---|---|---|");
    let mut rows = Vec::new();
    for (((name, options), measured), (times, cornell_times)) in configurations
        .into_iter()
        .zip(results)
        .zip(times.into_iter().zip(cornell_times))
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
            shots: measured.shots,
            mean_patch_difference: measured.difference,
            cornell_gpu_loop_s: median(cornell_times),
            cornell_shots: measured.cornell_shots,
            cornell_worst_region: measured.cornell_region,
            cornell_worst_difference: measured.cornell_worst,
        };
        outln!(
            "| {} | {:.2} | {} | {:.2} % | {:.2} | {} | {:.2} % ({}) |",
            row.configuration,
            row.gpu_loop_s,
            row.shots,
            100.0 * row.mean_patch_difference,
            row.cornell_gpu_loop_s,
            row.cornell_shots,
            100.0 * row.cornell_worst_difference,
            row.cornell_worst_region
        );
        rows.push(row);
    }
    if let Some(path) = &args.json {
        crate::display::output::write_json(path, &rows)?;
    }
    Ok(())
}
