//! Where a solve's shots go, and what face clusters would make of them (issue 58; the numbers in
//! the notes on shooting from clusters of non-coplanar faces).
//!
//! ```sh
//! cargo run --release --example cluster_survey -- SCENE.obj out/SCENE/stats.json [MATERIAL=R,G,B]
//! ```
//!
//! Reads the scene as `radiosity solve` does (the default patch budget, `--emit` given as the
//! third argument) and the solve's `stats.json`, and prints, for the steps of its history: the
//! class of each step's first shooter (emitter, a polygon larger than a cluster cell, a member of
//! a coplanar cluster, a small polygon alone), the objects that took most steps, and how many
//! distinct cone clusters (`solver::face_clusters`, at three cone half-angles) the small shooters
//! fall in.

use gpu_radiosity::patches::PatchLayout;
use gpu_radiosity::scene::{load_obj_with, Emission, LoadOptions};
use gpu_radiosity::solver::clusters::Clusters;
use gpu_radiosity::solver::face_clusters::FaceClusters;
use gpu_radiosity::solver::SolveOptions;
use std::collections::{BTreeMap, BTreeSet};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let emit = match args.get(2) {
        Some(e) => {
            let (material, rgb) = e.split_once('=').expect("MATERIAL=R,G,B");
            let v: Vec<f32> = rgb.split(',').map(|x| x.parse().unwrap()).collect();
            vec![Emission {
                material: material.into(),
                ke: [v[0], v[1], v[2]],
            }]
        }
        None => Vec::new(),
    };
    let scene = load_obj_with(
        args[0].as_ref(),
        &LoadOptions {
            emit,
            ..Default::default()
        },
    )?;
    let layout = PatchLayout::new(
        &scene,
        gpu_radiosity::pipeline::resolution(&scene, None, None),
    );
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&args[1])?)?;
    let history = stats["history"].as_array().expect("a history");
    let options = SolveOptions::accurate();
    let side = options.cluster_cell;
    let t = std::time::Instant::now();
    let coplanar = Clusters::new(&scene, &layout, options.shooter_cell, options.cluster_cell);
    println!(
        "{}: {} polygons, {} patches; {} coplanar clusters of {} polygons ({:.1} s)",
        scene.name,
        scene.polygons.len(),
        layout.patch_count(),
        coplanar.count(),
        coplanar.clustered_polygons(),
        t.elapsed().as_secs_f64()
    );
    let steps: Vec<(usize, f64, u64)> = history
        .iter()
        .scan(0u64, |last, r| {
            let shot = r["shot"].as_u64().unwrap();
            let polygons = shot - *last;
            *last = shot;
            Some((
                r["shooter"].as_u64().unwrap() as usize,
                r["carried_power"].as_f64().unwrap(),
                polygons,
            ))
        })
        .collect();
    let emitted = stats["emitted_power"].as_f64().unwrap();
    let mut classes: BTreeMap<&str, (usize, u64, f64)> = BTreeMap::new();
    let mut objects: BTreeMap<&str, usize> = BTreeMap::new();
    for &(p, carried, polygons) in &steps {
        let polygon = &scene.polygons[p];
        let class = if scene.material(polygon).is_emitter() {
            "emitter"
        } else if layout.patches_per_polygon[p] > side {
            "larger than a cell"
        } else if coplanar.members_of(p, true).is_some() {
            "in a coplanar cluster"
        } else {
            "small, alone"
        };
        let e = classes.entry(class).or_default();
        e.0 += 1;
        e.1 += polygons;
        e.2 += carried / emitted;
        *objects.entry(polygon.object.as_str()).or_default() += 1;
    }
    println!(
        "{} steps, {} shots, {:.4} unshot",
        steps.len(),
        stats["shots"],
        stats["unshot_fraction"]
    );
    println!("| first shooter of the step | steps | shots | carried (share of emitted) |");
    println!("|---|---|---|---|");
    for (class, (n, shots, carried)) in &classes {
        println!("| {class} | {n} | {shots} | {carried:.4} |");
    }
    let mut top: Vec<(&str, usize)> = objects.into_iter().collect();
    top.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
    println!("objects with most steps:");
    for (o, n) in top.iter().take(12) {
        println!("  {n:6} {o}");
    }
    for degrees in [10.0f32, 20.0, 30.0] {
        let t = std::time::Instant::now();
        let cones = FaceClusters::new(&scene, &layout, side, degrees.to_radians());
        let built = t.elapsed().as_secs_f64();
        let roots: Vec<u32> = cones.roots().collect();
        let clustered: u32 = roots.iter().map(|&r| cones.nodes()[r as usize].size).sum();
        // The small shooters' roots: a step whose shooter lies in a root another step already
        // took would have been shot with it, had the cluster shot as one.
        let (mut small, mut in_cone) = (0, 0);
        let mut distinct: BTreeSet<u32> = BTreeSet::new();
        for &(p, _, _) in &steps {
            let Some(leaf) = cones.leaf_of(p) else {
                continue;
            };
            small += 1;
            let mut at = leaf;
            while let Some(up) = cones.nodes()[at as usize].parent {
                at = up;
            }
            if at != leaf {
                in_cone += 1;
                distinct.insert(at);
            }
        }
        println!(
            "cone {degrees}°: {} clusters of {clustered} polygons (built in {built:.1} s); of {} \
             steps, {small} shot a small polygon, {in_cone} one in a cone cluster, from {} \
             distinct clusters",
            roots.len(),
            steps.len(),
            distinct.len()
        );
    }
    Ok(())
}
