//! No shot creates energy (issue 36): every shot of the default solve reflects at most Σ ρ × the
//! power it carried (`ShotRecord::received_power`, less the atlas's float noise, ≤ `carried_power`
//! × 1.005; the solver itself judges each channel), on the Table 1 rooms, the Cornell box (ours,
//! the two published ones and the archive's family of eight), a non-planar 10,000-corner face and
//! a plant of crossed double-sided quads on both solvers, and Lost Empire (a third-party voxel
//! world of 112,499 faces) and the decimated living room (28,650 triangles) solved to 1 %.
//! Each test walks every shot of its solve.
//!
//! `received_power` is what the receivers gained over their reflectance (the incident power),
//! measured per channel from the lightmaps, independently of the form factors that sent it.

mod common;

use common::*;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::{load_obj, Scene};
use gpu_radiosity::solver::find_max_energy::{EMITTED_NOISE, TOLERANCE};
use gpu_radiosity::solver::{default_max_shots, CpuSolver, GpuSolver, ShotRecord, SolveOptions};

/// Every shot of `history` within its bound once the float noise of the atlas's sums
/// (`find_max_energy::EMITTED_NOISE` of the `emitted` power) is taken off what it received, as the solver
/// judges it; the worst ratio of the shots that are within it without that allowance.
fn walk(name: &str, history: &[ShotRecord], emitted: f64) -> f64 {
    assert!(!history.is_empty(), "{name}: no shot");
    let mut worst = 0f64;
    for r in history {
        assert!(
            r.carried_power > 0.0,
            "{name}: shot {} carried nothing",
            r.shot
        );
        let ratio = r.received_power / r.carried_power;
        // As the solver judges a shot: what it received less the float noise, against what it
        // carried (a shot of 1e-5 of the emitted power may read 1.005x on noise alone).
        let noise = EMITTED_NOISE * emitted;
        assert!(
            r.received_power - noise <= TOLERANCE * r.carried_power,
            "{name}: shot {} (polygon {}) received {:.4}x what it carried ({:.3e} of the \
             emitted power, float noise {:.3e} of it)",
            r.shot,
            r.shooter,
            ratio,
            r.carried_power / emitted,
            EMITTED_NOISE
        );
        if ratio <= TOLERANCE {
            worst = worst.max(ratio);
        } else {
            println!(
                "{name}: shot {} read {ratio:.4}x carrying {:.3e} of the emitted power: float noise",
                r.shot,
                r.carried_power / emitted
            );
        }
    }
    println!(
        "{name}: {} shots, worst received/carried {worst:.5}",
        history.len()
    );
    worst
}

/// Solve `scene` with the default options on the GPU and walk every shot.
fn default_solve(name: &str, scene: &Scene, layout: &PatchLayout) -> (f64, u32) {
    let ctx = context();
    let mut solver = GpuSolver::new(&ctx, scene, layout, SolveOptions::accurate()).unwrap();
    solver.solve(|_| {}).unwrap();
    assert!(solver.converged(), "{name}: {}", solver.unshot_fraction());
    let corrections = solver.ledger().corrections();
    println!("{name}: {corrections} shots scaled back");
    (
        walk(name, solver.history(), solver.emitted_power()),
        corrections,
    )
}

#[test]
fn every_shot_of_the_cornell_boxes_is_within_its_bound() {
    let cornell = load("cornell");
    default_solve(
        "cornell",
        &cornell,
        &PatchLayout::new(&cornell, Resolution::Patches(4096)),
    );
    // The archive's box as published (two faces given twice, dropped by the loader).
    if let Some(path) = third_party("cornell-box/CornellBox-Original.obj") {
        let mcguire = load_obj(&path).unwrap();
        default_solve(
            "CornellBox-Original",
            &mcguire,
            &PatchLayout::new(&mcguire, Resolution::Patches(4096)),
        );
    }
    // The OBJ library's box, its light made an emitter as its README says.
    let tiny = third_party_lit(
        "tinyobjloader-cornell-box/cornell_box.obj",
        "light",
        [20.0; 3],
    );
    if let Some(tiny) = tiny {
        default_solve(
            "tinyobjloader cornell_box",
            &tiny,
            &PatchLayout::new(&tiny, Resolution::Patches(4096)),
        );
    }
}

/// The archive's Cornell box family as published, each solved as `radiosity solve FILE` does
/// (the default budget of patches, the default stopping rule), every shot's books walked. The
/// white one (every wall `Kd 1`, open front) stopped at shot 111 on both solvers, its unshot
/// power by magnitude past twice the emitted power: each wall was predicted to shoot all that the
/// others held, and every wall sat at its remainder (`solver/overshoot.rs`, `MAX_SHARE`).
#[test]
fn every_box_of_the_cornell_family_solves_with_the_defaults_within_its_bound() {
    let ctx = context();
    for variant in CORNELL_FAMILY {
        let name = format!("CornellBox-{variant}");
        let Some(path) = cornell_family_box(variant) else {
            return;
        };
        let scene = load_obj(&path).unwrap();
        let layout = PatchLayout::new(
            &scene,
            gpu_radiosity::pipeline::resolution(&scene, None, None),
        );
        let options = SolveOptions {
            max_shots: default_max_shots(scene.polygons.len()),
            ..SolveOptions::accurate()
        };
        let started = std::time::Instant::now();
        let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
        gpu.solve(|_| {}).unwrap();
        assert!(
            gpu.unshot_fraction() <= options.threshold as f64,
            "{name}: {} unshot after {} shots",
            gpu.unshot_fraction(),
            gpu.shots()
        );
        walk(&name, gpu.history(), gpu.emitted_power());
        println!(
            "{name}: {} polygons, {} patches, {} shots, {:.1} s",
            scene.polygons.len(),
            layout.patch_count(),
            gpu.shots(),
            started.elapsed().as_secs_f64()
        );
        if variant == "Empty-White" {
            // It failed on the CPU solver as well, at the same shot.
            let mut cpu = CpuSolver::new(&scene, &layout, options.clone(), 0).unwrap();
            cpu.solve(|_| {}).unwrap();
            assert!(cpu.unshot_fraction() <= options.threshold as f64);
            walk(&format!("{name}, CPU"), cpu.history(), cpu.emitted_power());
            // Overshooting's swings stay bounded: uncapped, the floor's shot left 1.79x the
            // emitted power unshot by magnitude at shot 2 and 1.98x at shot 3.
            let peak = (gpu.history().iter())
                .map(|r| r.unshot_fraction)
                .fold(0.0, f64::max);
            assert!(peak < 1.5, "{name}: {peak} of the emitted power unshot");
        }
    }
}

/// The simple room: before shots were scaled back, 194 of about 940 steps reflected more than
/// they carried, up to 3.72x (patch centres in the 6 mm gap between the cabinet doors, whose
/// texels the doors mostly cover).
#[test]
fn every_shot_of_the_simple_room_is_within_its_bound() {
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()));
    let (_, corrections) = default_solve("simple", &scene, &layout);
    assert!(corrections > 0, "the check found nothing to scale back");
}

/// Every shot of the complex room's default solve (about 9,800 shots since small shots shoot
/// from coarse cells; before, the default stopped at its shot limit and the test walked only
/// the first 300).
#[test]
fn every_shot_of_the_complex_room_is_within_its_bound() {
    let scene = load("complex");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()));
    default_solve("complex", &scene, &layout);
}

/// A deeply non-planar 10,000-corner face (a zigzag crown, split by the loader into triangles
/// on its mean plane) under a lamp: its first shots reflected 1.33x before, on both solvers.
#[test]
fn every_shot_of_a_non_planar_face_is_within_its_bound_on_both_solvers() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::write(
        d.join("crown.mtl"),
        "newmtl floor\nKd 0.7 0.7 0.7\nnewmtl lamp\nKd 0 0 0\nKe 10 10 10\n",
    )
    .unwrap();
    let n = 10_000;
    let s = String::from(
        "mtllib crown.mtl\nusemtl lamp\nv -0.5 3 -0.5\nv 0.5 3 -0.5\nv 0.5 3 0.5\nv -0.5 3 0.5\n\
         f 1 2 3 4\n",
    ) + &zigzag_crown(4, n);
    std::fs::write(d.join("crown.obj"), s).unwrap();
    let scene = load_obj(&d.join("crown.obj")).unwrap();
    assert!(scene.polygons.len() > 1000, "{}", scene.polygons.len());
    let layout = PatchLayout::new(&scene, Resolution::Patches(4000));
    let options = SolveOptions {
        max_shots: 60,
        ..SolveOptions::accurate()
    };
    let ctx = context();
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    gpu.solve(|_| {}).unwrap();
    let gpu_worst = walk("crown, GPU", gpu.history(), gpu.emitted_power());
    let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
    cpu.solve(|_| {}).unwrap();
    let cpu_worst = walk("crown, CPU", cpu.history(), cpu.emitted_power());
    // Light did reach the crown (the lamp's form factor to it is about a tenth): the bound is not
    // met by shooting nothing.
    assert!(
        gpu_worst > 0.05 && cpu_worst > 0.05,
        "{gpu_worst} {cpu_worst}"
    );
}

/// A plant as exporters write one (Lost Empire's flowers): two quads crossed through each
/// other's centres, each given twice, back to back, one patch each, on a floor under a lamp.
/// The form factor at a patch centre on the shooter's plane was the contour integral of
/// float-noise heights: the back face read 1, the crossing quad 0.5, and those shots reflected
/// up to 3.7 times what they carried. Now a receiver on the shooter's plane gets nothing (the
/// exact value); the books are walked with shots left as they were (`conserve` off), on both
/// solvers, so that the scaling back cannot hide the cause.
#[test]
fn crossed_double_sided_quads_create_no_energy_on_both_solvers() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::write(
        d.join("plant.mtl"),
        "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl flower\nKd 0.99 0.99 0.05\n\
         newmtl lamp\nKd 0 0 0\nKe 10 10 10\n",
    )
    .unwrap();
    // Quad A along (1, 0, 1), quad B along (1, 0, -1), crossing at (0.3, 0.5, 0.7): 0.9 of a
    // block along each axis, as Mineways writes them, at coordinates that are not binary
    // fractions (a texel centre lands on the other face's plane give or take float noise, as in
    // Lost Empire). Each face, then its reverse.
    let (cx, cz, h) = (0.3f32, 0.7f32, 0.45f32);
    let v = |x: f32, y: f32, z: f32| format!("v {} {y} {}\n", cx + x, cz + z);
    let obj = String::from(
        "mtllib plant.mtl\n\
         v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n\
         v -0.5 3 -0.5\nv 0.5 3 -0.5\nv 0.5 3 0.5\nv -0.5 3 0.5\n",
    ) + &[
        v(-h, 0.0, -h),
        v(h, 0.0, h),
        v(h, 1.0, h),
        v(-h, 1.0, -h),
        v(-h, 0.0, h),
        v(h, 0.0, -h),
        v(h, 1.0, -h),
        v(-h, 1.0, h),
    ]
    .concat()
        + "usemtl floor\nf 4 3 2 1\n\
           usemtl lamp\nf 5 6 7 8\n\
           usemtl flower\nf 9 10 11 12\nf 12 11 10 9\nf 13 14 15 16\nf 16 15 14 13\n";
    std::fs::write(d.join("plant.obj"), obj).unwrap();
    let scene = load_obj(&d.join("plant.obj")).unwrap();
    assert_eq!(scene.polygons.len(), 6, "the back faces are kept");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(1.0));
    // One shooter per step, so that each flower face's shot has books of its own.
    let options = SolveOptions {
        conserve: false,
        shooters_per_pass: 1,
        max_shots: 40,
        ..SolveOptions::accurate()
    };
    let ctx = context();
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    gpu.solve(|_| {}).unwrap();
    let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
    cpu.solve(|_| {}).unwrap();
    for (name, history, emitted) in [
        ("plant, GPU", gpu.history(), gpu.emitted_power()),
        ("plant, CPU", cpu.history(), cpu.emitted_power()),
    ] {
        // The flowers shot: the walk covers the case.
        let flowers = history
            .iter()
            .filter(|r| {
                scene.material(&scene.polygons[r.shooter]).name == "flower"
                    && r.carried_power > 1e-3 * emitted
            })
            .count();
        assert!(flowers >= 4, "{name}: {flowers} shots of the flowers");
        walk(name, history, emitted);
    }
}

/// Lost Empire (issue 35's voxel world as published: 112,499 faces, 48,596 polygons after
/// merging, 75,524 patches from the default budget, lit by its 809 torches) solved to 1 % with
/// the defaults, as `radiosity solve lost_empire.obj --emit Torch=5,4,2 --threshold 0.01` does
/// (docs/gallery.md): the stopping rule reached, every step within its bound, and few scaled
/// back (126 of 2,103 steps, measured 2026-12-06, tenth session; 4,274 of 4,841 while receivers on a
/// shooter's plane read float noise, which cost 33,875 shots instead of 14,752).
#[test]
fn lost_empire_solves_to_one_percent_and_every_step_is_within_its_bound() {
    let Some(scene) = third_party_lit("lost-empire/lost_empire.obj", "Torch", [5.0, 4.0, 2.0])
    else {
        return;
    };
    let layout = PatchLayout::new(
        &scene,
        gpu_radiosity::pipeline::resolution(&scene, None, None),
    );
    let options = SolveOptions {
        threshold: 0.01,
        max_shots: default_max_shots(scene.polygons.len()),
        ..SolveOptions::accurate()
    };
    let ctx = context();
    let mut solver = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
    solver.solve(|_| {}).unwrap();
    let (steps, corrections) = (solver.history().len(), solver.ledger().corrections());
    println!(
        "Lost Empire: {} polygons, {} patches, {} shots in {steps} steps, {corrections} scaled back, \
         {:.4} unshot",
        scene.polygons.len(),
        layout.patch_count(),
        solver.shots(),
        solver.unshot_fraction()
    );
    assert!(
        solver.unshot_fraction() <= 0.01,
        "{}",
        solver.unshot_fraction()
    );
    walk("Lost Empire", solver.history(), solver.emitted_power());
    assert!(
        (corrections as usize) * 8 < steps,
        "{corrections} of {steps} steps scaled back"
    );
}

/// The decimated living room (issue 35's tessellated room, 28,650 triangles, CC BY 3.0) loads as
/// published with its own light (`BackLight`, `Ke 1.6`), its walls merged (28,650 faces → 23,341
/// polygons) and a budget that gives large surfaces more than one texel (41,342 patches), and the
/// defaults solve it to the 1 % stopping rule (about 17,600 shots, 11,100 passes and 3.5 minutes
/// alone on the 2-core llvmpipe VM) with every shot's books kept.
#[test]
fn living_room_loads_as_published_and_solves_to_one_percent_keeping_its_books() {
    let Some(path) = third_party("living-room/living_room.obj") else {
        return;
    };
    let scene = load_obj(&path).unwrap();
    assert_eq!(scene.faces, 28_650);
    assert_eq!(scene.polygons.len(), 23_341);
    assert_eq!(scene.emitting_materials(), ["BackLight"]);
    let layout = PatchLayout::new(
        &scene,
        gpu_radiosity::pipeline::resolution(&scene, None, None),
    );
    assert_eq!(layout.patch_count(), 41_342);
    // The walls: one polygon each, many patches (not one texel per face).
    let widest = layout.patches_per_polygon.iter().max().copied().unwrap();
    assert!(widest >= 200, "largest polygon: {widest} patches");
    let options = SolveOptions {
        threshold: 0.01,
        max_shots: default_max_shots(scene.polygons.len()),
        ..SolveOptions::accurate()
    };
    let ctx = context();
    let mut solver = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
    solver.solve(|_| {}).unwrap();
    let (steps, corrections) = (solver.history().len(), solver.ledger().corrections());
    println!(
        "living room: largest polygon {widest} patches, {} shots in {steps} steps, {} passes, \
         {corrections} scaled back, {:.4} unshot",
        solver.shots(),
        solver.passes(),
        solver.unshot_fraction()
    );
    assert!(
        solver.unshot_fraction() <= 0.01,
        "{}",
        solver.unshot_fraction()
    );
    walk("living room", solver.history(), solver.emitted_power());
    assert!(
        (corrections as usize) * 8 < steps,
        "{corrections} of {steps} steps scaled back"
    );
}
