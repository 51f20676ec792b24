//! Criterion benches of the hot pieces of one shot, on the simple Table 1 room with the settings
//! of `radiosity bench table1` (whole polygons shoot, polygon form factor, 128² hemicube): one
//! visibility pass, one reconstruction pass, the accumulation copies, one Find_Max_Energy (every
//! polygon re-totalled from the read-back unshot atlas + the choice), one whole GPU shot and one
//! CPU shot.
//!
//! GL calls return before llvmpipe has drawn anything, so each GL bench ends with `glFinish`:
//! what is measured is the pass's work, not its submission. `cargo bench --bench passes`.

use criterion::{criterion_group, criterion_main, Criterion};
use glow::HasContext;
use gpu_radiosity::gl::{BackendChoice, GlContext};
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::load_obj;
use gpu_radiosity::solver::cpu::CpuSolver;
use gpu_radiosity::solver::find_max_energy::EnergyTotals;
use gpu_radiosity::solver::reconstruction::{Lightmaps, ReconstructionPass};
use gpu_radiosity::solver::visibility::VisibilityPass;
use gpu_radiosity::solver::{mesh, GpuSolver};
use std::path::Path;

fn passes(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/simple/simple.obj");
    let scene = load_obj(&path).expect("the simple room loads");
    let size = scene.patch_size.expect("the room sets its patch size");
    // The layout the GPU solver works in (no gutters), so that the pieces run as in a solve.
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(size)).without_gutters();
    let options = gpu_radiosity::solver::SolveOptions::paper_faithful(0.01);
    let ctx = GlContext::headless(BackendChoice::Auto).expect("a GL 3.0 context");
    let finish = || unsafe { ctx.gl.finish() };

    // The first shooter (the brightest light), as the solvers would pick it.
    let mut solver = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    let shooters = solver.shooters_of(solver.next_polygon().unwrap());
    let shooter = &shooters[0];

    let (w, h) = (layout.atlas_width as i32, layout.atlas_height as i32);
    let mut visibility = VisibilityPass::new(
        &ctx,
        options.visibility,
        options.hemi_res,
        options.tuning,
        &scene,
    )
    .unwrap();
    // As the solver draws it: coplanar neighbours as plates (hemicube, robust test).
    let plates = match visibility.merge_plates(&scene) {
        Some(plates) => plates.vertex_data(&scene, &layout),
        None => mesh::vertex_data(&scene, &layout),
    };
    let geometry = mesh::upload_scene(&ctx.gl, &plates, scene.polygons.len()).unwrap();
    let patches = mesh::upload(&ctx.gl, &mesh::vertex_data(&scene, &layout)).unwrap();
    let mut reconstruction = ReconstructionPass::new(&ctx, &scene, &layout, &options).unwrap();
    let lightmaps = Lightmaps::new(&ctx, w, h).unwrap();
    reconstruction.emit(&ctx, &patches).unwrap();
    reconstruction.copy_into(&ctx, &lightmaps).unwrap();
    finish();

    let mut group = c.benchmark_group("simple room");
    group.sample_size(30);
    group.bench_function("visibility pass", |b| {
        b.iter(|| {
            visibility.run(&ctx, &geometry, shooter).unwrap();
            finish();
        })
    });
    visibility.run(&ctx, &geometry, shooter).unwrap();
    group.bench_function("reconstruction pass", |b| {
        b.iter(|| {
            reconstruction
                .run(
                    &ctx,
                    &visibility,
                    &lightmaps,
                    std::slice::from_ref(shooter),
                    &options,
                )
                .unwrap();
            finish();
        })
    });
    group.bench_function("accumulation copies", |b| {
        b.iter(|| {
            reconstruction.copy_into(&ctx, &lightmaps).unwrap();
            finish();
        })
    });
    let unshot = solver.unshot_atlas().to_vec();
    let areas: Vec<f64> = (0..scene.polygons.len())
        .map(|p| solver.patch_area(p))
        .collect();
    // Worst case of a shot: every polygon re-totalled from its lightmap rectangle.
    let texels = layout.texel_rects();
    let all: Vec<usize> = (0..scene.polygons.len()).collect();
    let mut totals = EnergyTotals::sum(&unshot, scene.polygons.len(), Some(&areas));
    group.bench_function("Find_Max_Energy", |b| {
        b.iter(|| {
            let width = layout.atlas_width as usize;
            totals.update(&unshot, width, &texels, &all, &areas);
            totals.max_energy_polygons(0.0, 1)
        })
    });
    group.bench_function("GPU shot", |b| {
        b.iter(|| {
            solver.shoot(&shooters).unwrap();
            finish();
        })
    });
    let mut cpu = CpuSolver::new(&scene, &layout, options.clone(), 0).unwrap();
    group.bench_function("CPU shot", |b| b.iter(|| cpu.shoot(&shooters).unwrap()));
    group.finish();
}

criterion_group!(benches, passes);
criterion_main!(benches);
