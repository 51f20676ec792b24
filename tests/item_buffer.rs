//! The visibility pass's item buffer holds the right polygon IDs in the right places: every
//! pixel is checked against a CPU ray cast along the direction the projection (the paper's
//! hemispherical one, or the hemicube) maps to that pixel.

mod common;

use common::*;
use glam::Vec3;
use gpu_radiosity::patches::PatchLayout;
use gpu_radiosity::scene::Scene;
use gpu_radiosity::solver::engine::solids::Solids;
use gpu_radiosity::solver::mesh::{self, SceneMesh};
use gpu_radiosity::solver::visibility::{face_rotations, VisibilityPass};
use gpu_radiosity::solver::{GpuSolver, SolveOptions, Tuning, VisibilityKind, Walk};

/// The tuning for llvmpipe with the views drawn (`Tuning::walk_item_buffers` off): the GPU path
/// these tests hold to account. `the_walk_writes_what_the_views_draw` compares the two.
fn drawn() -> Tuning {
    Tuning::llvmpipe().drawing()
}

/// The tuning for llvmpipe with the walk writing the item buffers at every side (the engine's
/// default draws those above `Tuning::walk_up_to`).
fn walked() -> Tuning {
    Tuning {
        walk_up_to: 0,
        ..Tuning::llvmpipe()
    }
}

/// Fraction of item-buffer pixels (away from ID boundaries and the disk's rim) whose ID matches
/// the CPU ray cast, plus the IDs at a few named directions.
fn compare(
    scene: &Scene,
    shooter_polygon: usize,
    tessellation: f32,
    res: u32,
    visibility: VisibilityKind,
) -> (f64, Vec<Option<u32>>) {
    compare_tuned(
        scene,
        shooter_polygon,
        tessellation,
        res,
        visibility,
        drawn(),
    )
}

/// [`compare`] with the visibility pass tuned by `tuning`.
fn compare_tuned(
    scene: &Scene,
    shooter_polygon: usize,
    tessellation: f32,
    res: u32,
    visibility: VisibilityKind,
    tuning: Tuning,
) -> (f64, Vec<Option<u32>>) {
    let ctx = context();
    let layout = gpu_radiosity::patches::PatchLayout::new(
        scene,
        gpu_radiosity::patches::Resolution::Patches(2048),
    );
    let options = SolveOptions {
        hemi_res: res,
        tessellation,
        shooter_cell: 0,
        visibility,
        // The visibility pass as tuned for llvmpipe (views culled, guard band, half side faces,
        // solids' far faces left out), drawn unless the caller says otherwise: what these tests
        // hold against ray casting.
        tuning,
        ..SolveOptions::paper()
    };
    let mut solver = GpuSolver::new(&ctx, scene, &layout, options).unwrap();
    let shooters = solver.shooters_of(shooter_polygon);
    assert_eq!(shooters.len(), 1, "paper mode: one shooter per polygon");
    let shooter = shooters[0];
    solver.shoot(&shooters).unwrap();
    let ids = solver.backend().visibility.read_ids();
    let faces = if visibility == VisibilityKind::Hemicube {
        5
    } else {
        1
    };
    let width = res * faces;
    assert_eq!(ids.len(), (width * res) as usize);

    let to_world = shooter.view().inverse();
    let rotations = face_rotations();
    let expected = |i: u32, j: u32| -> Option<Option<u32>> {
        let (face, i) = (i / res, i % res);
        let u = 2.0 * (i as f32 + 0.5) / res as f32 - 1.0;
        let v = 2.0 * (j as f32 + 0.5) / res as f32 - 1.0;
        let eye = if visibility == VisibilityKind::Hemicube {
            // Face space looks down -z; back to the shooter's eye space.
            let d = rotations[face as usize].transpose() * Vec3::new(u, v, -1.0);
            if d.z > -0.02 * d.length() {
                return None; // behind (or grazing) the shooter's plane
            }
            d
        } else {
            let r2 = u * u + v * v;
            if r2 >= 0.97 {
                return None;
            }
            Vec3::new(u, v, -(1.0 - r2).sqrt())
        };
        let dir = to_world.transform_vector3(eye).normalize();
        Some(first_hit(scene, shooter.position, dir, shooter_polygon).map(|(id, _)| id as u32))
    };
    let cpu: Vec<Option<Option<u32>>> = (0..res)
        .flat_map(|j| (0..width).map(move |i| (i, j)))
        .map(|(i, j)| expected(i, j))
        .collect();
    let (mut agree, mut total) = (0u64, 0u64);
    for j in 1..res - 1 {
        for i in 1..width - 1 {
            if i % res == 0 || i % res == res - 1 {
                continue; // a hemicube face's border
            }
            let at = (j * width + i) as usize;
            let Some(want) = cpu[at] else { continue };
            let neighbours = [at - 1, at + 1, at - width as usize, at + width as usize];
            if neighbours.iter().any(|&n| cpu[n] != Some(want)) {
                continue; // an ID boundary runs through this pixel
            }
            total += 1;
            agree += (ids[at] == want) as u64;
        }
    }
    (agree as f64 / total as f64, ids)
}

#[test]
fn item_buffer_from_the_light_of_the_shadow_scene() {
    // Floor 0 (2x2 at y=0), light 1 (at y=2, facing down), occluder 2 (0.6x0.6 at y=1).
    let scene = load("shadow");
    let res = 256;
    let (agreement, ids) = compare(&scene, 1, 2.0, res, VisibilityKind::Hemisphere);
    println!(
        "shadow scene: {:.4} % of interior pixels agree with the CPU",
        100.0 * agreement
    );
    assert!(agreement > 0.999, "agreement {agreement}");
    assert_quoted(
        "shadow scene, tessellated hemisphere",
        100.0 * agreement,
        "100.0",
    );
    let at = |u: f32, v: f32| {
        let i = ((u * 0.5 + 0.5) * res as f32) as u32;
        let j = ((v * 0.5 + 0.5) * res as f32) as u32;
        ids[(j * res + i) as usize]
    };
    // Straight down: the occluder. Its edge is at atan(0.3 / 1): sin = 0.287 on the disk.
    assert_eq!(at(0.0, 0.0), Some(2));
    assert_eq!(at(0.2, 0.0), Some(2));
    // Between the occluder's edge and the floor's edge (sin atan(1/2) = 0.447 along an axis).
    assert_eq!(at(0.37, 0.0), Some(0));
    assert_eq!(at(0.0, -0.37), Some(0));
    // Beyond the floor, nothing.
    assert_eq!(at(0.0, 0.8), None);
    assert_eq!(at(-0.8, 0.0), None);
}

#[test]
fn item_buffer_from_the_cornell_light_matches_ray_casting() {
    let scene = load("cornell");
    let light = scene
        .polygons
        .iter()
        .position(|p| scene.material(p).is_emitter())
        .unwrap();
    let hemisphere = VisibilityKind::Hemisphere;
    let (tessellated, _) = compare(&scene, light, 2.0, 256, hemisphere);
    let (whole, _) = compare(&scene, light, 0.0, 256, hemisphere);
    let (cube, _) = compare(&scene, light, 0.0, 128, VisibilityKind::Hemicube);
    println!(
        "cornell from the light: hemisphere tessellated {:.3} %, whole polygons (paper) {:.3} %; \
         hemicube {:.3} %",
        100.0 * tessellated,
        100.0 * whole,
        100.0 * cube
    );
    // README ("Tests"): 100.0 % with tessellation, 72 % without; hemicube 100.0 %. (Measured
    // 71.948 % without: paper_notes' "71.9 %" is true too, but 0.002 % from reading 72.0, so the
    // quote asserted is the README's.)
    assert_quoted("hemisphere, tessellated", 100.0 * tessellated, "100.0");
    assert_quoted("hemisphere, whole polygons", 100.0 * whole, "72");
    assert_quoted("hemicube", 100.0 * cube, "100.0");
}

#[test]
fn hemicube_from_a_wall_of_the_box() {
    // From the centre of a wall, the five other faces: every direction hits one of them.
    let scene = load("box");
    let (agreement, ids) = compare(&scene, 2, 0.0, 64, VisibilityKind::Hemicube);
    println!("box from a wall, hemicube: {:.4} %", 100.0 * agreement);
    assert!(agreement > 0.999, "agreement {agreement}");
    assert_quoted("box from a wall, hemicube", 100.0 * agreement, "100.0");
    // The front face's centre looks straight across the box at the opposite wall.
    let opposite = scene
        .polygons
        .iter()
        .position(|p| p.normal.dot(scene.polygons[2].normal) < -0.99)
        .unwrap() as u32;
    assert_eq!(ids[(32 * 5 * 64 + 32) as usize], Some(opposite));
}

#[test]
fn hemicube_in_the_furnished_room_matches_ray_casting() {
    // The simple Table 1 room: furniture everywhere, so each hemicube face draws only the
    // polygons whose bounding spheres reach into it (and above the shooter's horizon). Culling
    // must never drop a polygon that a looked-up pixel shows.
    let scene = load("simple");
    let find = |name: &str| {
        scene
            .polygons
            .iter()
            .position(|p| p.object == name)
            .unwrap_or_else(|| panic!("no polygon of {name}"))
    };
    for name in ["light_study_1", "desk_1", "wall_study_8"] {
        let (agreement, _) = compare(&scene, find(name), 0.0, 64, VisibilityKind::Hemicube);
        println!(
            "simple room from {name}, hemicube: {:.3} %",
            100.0 * agreement
        );
        assert!(agreement > 0.995, "{name}: agreement {agreement}");
        // README: the hemicube's 100.0 % holds "also in the furnished simple room".
        assert_quoted(name, 100.0 * agreement, "100.0");
        // And the item buffer the walk writes instead (`Tuning::walk_item_buffers`).
        let hemicube = VisibilityKind::Hemicube;
        let (walked, _) = compare_tuned(&scene, find(name), 0.0, 64, hemicube, walked());
        println!("  written by the walk: {:.3} %", 100.0 * walked);
        assert_quoted(name, 100.0 * walked, "100.0");
    }
}

/// Item buffers of two visibility passes (each with its mesh) from 458 points of the simple
/// room: every 7th polygon's centroid and a point near its first corner (on a shelf, that may lie
/// under a book). Returns (shooters, pixels, pixels where `a` differs from `b`'s IDs mapped by
/// `shown`).
fn item_buffers_differ(
    ctx: &gpu_radiosity::gl::GlContext,
    scene: &Scene,
    a: (&mut VisibilityPass, &SceneMesh),
    b: (&mut VisibilityPass, &SceneMesh),
    shown: impl Fn(u32) -> u32,
) -> (usize, usize, usize) {
    let layout = layout(scene, scene.patch_size.unwrap());
    let solver = GpuSolver::new(ctx, scene, &layout, SolveOptions::accurate()).unwrap();
    // Only the position, normal and polygon of a shooter matter to the visibility pass.
    let mut shooter = solver.shooters_of(solver.next_polygon().unwrap())[0];
    let (mut differ, mut pixels, mut runs) = (0usize, 0usize, 0usize);
    for p in (0..scene.polygons.len()).step_by(7) {
        let polygon = &scene.polygons[p];
        shooter.polygon = p;
        shooter.normal = polygon.normal;
        for position in [
            polygon.centroid,
            polygon.vertices[0] + 0.05 * (polygon.centroid - polygon.vertices[0]),
        ] {
            shooter.position = position;
            a.0.run(ctx, a.1, &shooter).unwrap();
            b.0.run(ctx, b.1, &shooter).unwrap();
            let (x, y) = (a.0.read_ids(), b.0.read_ids());
            pixels += x.len();
            runs += 1;
            differ += x
                .iter()
                .zip(&y)
                .filter(|(x, y)| **x != y.map(&shown))
                .count();
        }
    }
    (runs, pixels, differ)
}

fn simple_room() -> (Scene, PatchLayout) {
    let scene = load("simple");
    let layout = layout(&scene, scene.patch_size.unwrap());
    (scene, layout)
}

#[test]
fn leaving_out_the_far_faces_of_solids_keeps_the_item_buffer() {
    // The simple Table 1 room: 1,127 of its 1,602 polygons belong to convex solids (books closed
    // by their shelves, furniture boxes). The item buffers with and without the solids' far
    // faces must match pixel for pixel, but for the rare pixel whose centre lies on an edge
    // where a near and a far face meet (measured: 601 of 37.5 million). The corner points test
    // the near-plane margin: a keyboard's side face 0.5 mm above the desk once saw the desk's
    // underside through the clipped desk top, and the floor when the underside was left out.
    let ctx = context();
    let (scene, layout) = simple_room();
    let solids = Solids::find(&scene);
    let in_solids = solids.solid_of.iter().filter(|s| s.is_some()).count();
    assert_eq!(
        (solids.count(), in_solids),
        (211, 1127),
        "solids, polygons in solids"
    );
    let n = scene.polygons.len();
    let geometry = mesh::upload_scene(&ctx.gl, &mesh::vertex_data(&scene, &layout), n).unwrap();
    let pass = |tuning| VisibilityPass::new(&ctx, VisibilityKind::Hemicube, 128, tuning, &scene);
    let mut culled = pass(drawn()).unwrap();
    let mut full = pass(Tuning {
        cull_solids: false,
        ..drawn()
    })
    .unwrap();
    let (runs, pixels, differ) = item_buffers_differ(
        &ctx,
        &scene,
        (&mut culled, &geometry),
        (&mut full, &geometry),
        |id| id,
    );
    println!("{runs} shooters: {differ} of {pixels} item-buffer pixels differ");
    // paper_notes 3.2.1: "from 458 points of the simple room: fewer than 700 of 37.5 million
    // pixels differ" (601 on Mesa 22.3.6's llvmpipe; pixel centres on edges are left to the
    // rasteriser, so the count is bounded, not pinned).
    assert_eq!((runs, pixels), (458, 37_519_360));
    assert!(differ < 700, "{differ} of {pixels} pixels differ");
}

#[test]
fn plates_show_the_same_planes() {
    // Coplanar neighbours merged into plates (the simple room's floor planks and ceiling tiles:
    // 199 polygons drawn as part of another) are drawn under one ID: the item buffer must
    // equal the unmerged one with each ID replaced by its plate's, but for pixel centres on the
    // joints that merging removed.
    let ctx = context();
    let (scene, layout) = simple_room();
    let n = scene.polygons.len();
    let pass = || VisibilityPass::new(&ctx, VisibilityKind::Hemicube, 128, drawn(), &scene);
    let mut merged = pass().unwrap();
    let plates = merged
        .merge_plates(&scene)
        .expect("the engine merges plates")
        .clone();
    assert_eq!(
        plates.merged_away(),
        199,
        "polygons drawn as part of another"
    );
    let plated = mesh::upload_scene(&ctx.gl, &plates.vertex_data(&scene, &layout), n).unwrap();
    let geometry = mesh::upload_scene(&ctx.gl, &mesh::vertex_data(&scene, &layout), n).unwrap();
    let mut single = pass().unwrap();
    let (runs, pixels, differ) = item_buffers_differ(
        &ctx,
        &scene,
        (&mut merged, &plated),
        (&mut single, &geometry),
        |id| plates.representative[id as usize] as u32,
    );
    println!("{runs} shooters: {differ} of {pixels} item-buffer pixels differ");
    // paper_notes 3.2.1: "from the same 458 points ... but for fewer than 100 of 37.5 million
    // pixels" (85 on Mesa 22.3.6's llvmpipe: centres on removed joints).
    assert_eq!((runs, pixels), (458, 37_519_360));
    assert!(differ < 100, "{differ} of {pixels} pixels differ");
}

#[test]
fn solids_and_plates_of_both_rooms() {
    // paper_notes 3.2.1's counts: the simple room has 211 solids (1,127 of its 1,602 polygons),
    // the complex one 1,216 (6,555 of 8,549); plates merge away 199 and 846 polygons.
    use gpu_radiosity::solver::engine::plates::Plates;
    for (name, solids_n, in_solids_n, merged_n) in
        [("simple", 211, 1127, 199), ("complex", 1216, 6555, 846)]
    {
        let scene = load(name);
        let solids = Solids::find(&scene);
        let in_solids = solids.solid_of.iter().filter(|s| s.is_some()).count();
        let plates = Plates::find(&scene, |p| solids.solid_of[p].is_none());
        println!(
            "{name}: {} solids ({in_solids} of {} polygons), {} polygons merged into plates",
            solids.count(),
            scene.polygons.len(),
            plates.merged_away()
        );
        assert_eq!(
            (solids.count(), in_solids, plates.merged_away()),
            (solids_n, in_solids_n, merged_n),
            "{name}: solids, polygons in solids, merged into plates"
        );
    }
}

#[test]
fn a_pass_whose_draw_lists_are_built_aside_draws_the_same_item_buffers() {
    // `VisibilityPass::run_pass` builds each next shot's draw list on another thread while the
    // draws of this one are issued (or on the drawing thread, when it would otherwise wait;
    // which thread builds which list depends on timing): every slot must hold what
    // `run_in_slot` draws into it, pixel for pixel, at the shots' own resolutions (here 128²
    // and 16² to 64² per face).
    let ctx = context();
    let (scene, layout) = simple_room();
    let n = scene.polygons.len();
    let geometry = mesh::upload_scene(&ctx.gl, &mesh::vertex_data(&scene, &layout), n).unwrap();
    let slots = 8;
    let pass = || {
        VisibilityPass::with_slots(&ctx, VisibilityKind::Hemicube, 128, drawn(), &scene, slots)
            .unwrap()
    };
    let (mut aside, mut one_by_one) = (pass(), pass());
    let solver = GpuSolver::new(&ctx, &scene, &layout, SolveOptions::accurate()).unwrap();
    let template = solver.shooters_of(solver.next_polygon().unwrap())[0];
    let mut compared = 0;
    for (round, first) in (0..n).step_by(97).enumerate() {
        let shooters: Vec<_> = (0..slots as usize)
            .map(|k| {
                let p = (first + 13 * k) % n;
                let polygon = &scene.polygons[p];
                let mut shooter = template;
                shooter.polygon = p;
                shooter.normal = polygon.normal;
                shooter.position = polygon.centroid;
                shooter.hemi_res = [128, 16, 37, 64][(round + k) % 4];
                shooter
            })
            .collect();
        aside.run_pass(&ctx, &geometry, &shooters).unwrap();
        for (slot, shooter) in shooters.iter().enumerate() {
            one_by_one
                .run_in_slot(&ctx, &geometry, shooter, slot)
                .unwrap();
            assert_eq!(
                aside.read_slot_ids(slot),
                one_by_one.read_slot_ids(slot),
                "round {round}, slot {slot}"
            );
            compared += 1;
        }
    }
    assert!(compared >= 100, "{compared} item buffers compared");
    assert_eq!(
        aside.missed(),
        one_by_one.missed(),
        "polygons between centres"
    );
    assert!(aside.missed() > 0, "the small shots leave polygons out");
}

/// The item buffers of `scene`'s shooters with `Tuning::cull_hidden` on and off, from every
/// `step`th polygon's centroid and a point near its first corner, at several sides and turns:
/// (shots, pixels compared, polygons left out). Every pixel that differs must have shown,
/// without the culling, a polygon whose plane passes through the eye (seen edge-on, drawn as
/// triangles of no area whose depth is noise: `engine::occlusion`).
fn hidden_polygons_left_out(
    scene: &Scene,
    patch_size: f32,
    sides: &[u32],
) -> (usize, usize, usize, u64) {
    let ctx = context();
    let layout = layout(scene, patch_size);
    let n = scene.polygons.len();
    let top = *sides.iter().max().unwrap();
    let pass = |tuning| VisibilityPass::new(&ctx, VisibilityKind::Hemicube, top, tuning, scene);
    let mut culled = pass(drawn()).unwrap();
    let mut whole = pass(Tuning {
        walk: Walk::Off,
        ..drawn()
    })
    .unwrap();
    // As the solver draws them: plates as one polygon.
    let data = culled
        .merge_plates(scene)
        .expect("the engine merges plates")
        .vertex_data(scene, &layout);
    whole.merge_plates(scene);
    let geometry = mesh::upload_scene(&ctx.gl, &data, n).unwrap();
    let solver = GpuSolver::new(&ctx, scene, &layout, SolveOptions::accurate()).unwrap();
    let mut shooter = solver.shooters_of(solver.next_polygon().unwrap())[0];
    let (mut shots, mut pixels, mut differ) = (0, 0, 0);
    for p in (0..n).step_by(n / 150 + 1) {
        let polygon = &scene.polygons[p];
        shooter.polygon = p;
        shooter.normal = polygon.normal;
        for position in [
            polygon.centroid,
            polygon.vertices[0] + 0.05 * (polygon.centroid - polygon.vertices[0]),
        ] {
            shooter.position = position;
            shooter.hemi_res = sides[shots % sides.len()];
            shooter.turn = shots as f32 * 0.37;
            culled.run(&ctx, &geometry, &shooter).unwrap();
            whole.run(&ctx, &geometry, &shooter).unwrap();
            let (a, b) = (culled.read_ids(), whole.read_ids());
            let width = culled.slot_texture(0).width as usize;
            let r = shooter.hemi_res as usize;
            for (i, (a, b)) in a.iter().zip(&b).enumerate() {
                if i % width >= 5 * r || i / width >= r {
                    continue;
                }
                pixels += 1;
                if a != b {
                    differ += 1;
                    let q = &scene.polygons[b.expect("the culled view shows less") as usize];
                    let off_plane = q.normal.dot(position - q.centroid).abs();
                    let distance = (q.centroid - position).length();
                    assert!(
                        off_plane <= 1e-4 * distance,
                        "shot {shots} (polygon {p}), pixel {i}: {a:?} instead of {b:?}, whose \
                         plane passes {off_plane} from the eye"
                    );
                }
            }
            shots += 1;
        }
    }
    (shots, pixels, differ, culled.hidden())
}

#[test]
fn leaving_out_hidden_polygons_changes_only_pixels_of_polygons_seen_edge_on() {
    // Lost Empire, where it pays: a small shot shows about 200 of the 17,000 polygons in front
    // of it (docs/perf-log.md, 2026-12-06, seventh session).
    let Some(scene) = third_party_lit("lost-empire/lost_empire.obj", "Torch", [5.0, 4.0, 2.0])
    else {
        return;
    };
    let (shots, pixels, differ, hidden) =
        hidden_polygons_left_out(&scene, 1.1782, &[16, 19, 23, 64]);
    println!("Lost Empire: {shots} shots, {differ} of {pixels} pixels differ, {hidden} left out");
    assert!(
        hidden > 10_000 * shots as u64,
        "{hidden} left out in {shots} shots"
    );
    // The simple Table 1 room: furniture hides the walls behind it.
    let scene = load("simple");
    let (shots, pixels, differ, hidden) =
        hidden_polygons_left_out(&scene, scene.patch_size.unwrap(), &[16, 37, 128]);
    println!("simple room: {shots} shots, {differ} of {pixels} pixels differ, {hidden} left out");
    assert!(
        hidden > 100 * shots as u64,
        "{hidden} left out in {shots} shots"
    );
}

/// The item buffers written by the walk (`Tuning::walk_item_buffers`) and drawn by the GPU, from
/// the first two shooter cells of every `step`th polygon (as the solver shoots them, from their
/// patches), at several sides and turns: (shots, pixels compared, pixels that differ).
fn walked_against_drawn(scene: &Scene, patch_size: f32, sides: &[u32]) -> (usize, usize, usize) {
    let ctx = context();
    let layout = layout(scene, patch_size);
    let n = scene.polygons.len();
    let top = *sides.iter().max().unwrap();
    let pass = |tuning| VisibilityPass::new(&ctx, VisibilityKind::Hemicube, top, tuning, scene);
    let mut walked = pass(walked()).unwrap();
    let mut views = pass(drawn()).unwrap();
    let data = walked
        .merge_plates(scene)
        .expect("the engine merges plates")
        .vertex_data(scene, &layout);
    views.merge_plates(scene);
    let geometry = mesh::upload_scene(&ctx.gl, &data, n).unwrap();
    let solver = GpuSolver::new(&ctx, scene, &layout, SolveOptions::accurate()).unwrap();
    let mut shooter = solver.shooters_of(solver.next_polygon().unwrap())[0];
    let slack = scene.plane_slack();
    let (mut shots, mut pixels, mut differ) = (0, 0, 0);
    for (p, position) in shooting_points(scene, 150) {
        shooter.polygon = p;
        shooter.normal = scene.polygons[p].normal;
        shooter.position = position;
        shooter.hemi_res = sides[shots % sides.len()];
        shooter.turn = shots as f32 * 0.37;
        walked.run(&ctx, &geometry, &shooter).unwrap();
        views.run(&ctx, &geometry, &shooter).unwrap();
        assert_eq!(walked.drawn(), views.drawn(), "shot {shots}");
        let (a, b) = (walked.read_ids(), views.read_ids());
        let width = walked.slot_texture(0).width as usize;
        let r = shooter.hemi_res as usize;
        for (i, (a, b)) in a.iter().zip(&b).enumerate() {
            let (x, y) = (i % width, i / width);
            if x >= 5 * r || y >= r {
                continue;
            }
            // Only the pixels the reconstruction pass reads: the side faces' upper halves.
            let face = x / r;
            let [fx, fy, fw, fh] =
                gpu_radiosity::solver::visibility::front_half(face, r as i32).map(|v| v as usize);
            let (u, v) = (x % r, y);
            if u < fx || u >= fx + fw || v < fy || v >= fy + fh {
                continue;
            }
            pixels += 1;
            // Back-to-back faces in one plane (leaves, glass, the two sides of a sheet) tie
            // in depth everywhere: the GPU shows the one drawn first, the walk the one it
            // met first. The robust test reads only the shown plane, which they share.
            let one_plane = |a: Option<u32>, b: Option<u32>| match (a, b) {
                (Some(a), Some(b)) => {
                    let (p, q) = (&scene.polygons[a as usize], &scene.polygons[b as usize]);
                    p.normal.dot(q.normal).abs() > 0.9999
                        && p.plane().distance(q.centroid).abs() <= slack
                }
                _ => false,
            };
            differ += (a != b && !one_plane(*a, *b)) as usize;
        }
        shots += 1;
    }
    (shots, pixels, differ)
}

#[test]
fn the_walk_writes_what_the_views_draw() {
    // Lost Empire, where it pays (docs/perf-log.md, 2026-12-06, tenth session), and the simple
    // Table 1 room. The walk records the nearest polygon at every pixel centre; the GPU draws
    // them. They part only where a centre lies on an edge (the GPU's fill rule gives it to one
    // side, the walk to the nearer or the first polygon) or two polygons tie in depth.
    let Some(scene) = third_party_lit("lost-empire/lost_empire.obj", "Torch", [5.0, 4.0, 2.0])
    else {
        return;
    };
    let (shots, pixels, differ) = walked_against_drawn(&scene, 1.1782, &[16, 19, 23, 64]);
    println!("Lost Empire: {shots} shots, {differ} of {pixels} pixels differ");
    assert!(
        shots >= 300 && pixels > 1_000_000,
        "{shots} shots, {pixels} pixels"
    );
    // 5,883 of 1,185,750 on Mesa 22.3.6's llvmpipe (docs/perf-log.md, tenth session).
    assert!(differ * 100 < pixels, "{differ} of {pixels} pixels differ");
    let scene = load("simple");
    let (shots, pixels, differ) =
        walked_against_drawn(&scene, scene.patch_size.unwrap(), &[16, 37, 128]);
    println!("simple room: {shots} shots, {differ} of {pixels} pixels differ");
    // 8,294 of 5,248,565.
    assert!(shots >= 250, "{shots} shots");
    assert!(differ * 200 < pixels, "{differ} of {pixels} pixels differ");
}
