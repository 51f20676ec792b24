//! What the walk finds a shot may reach (`engine::seen_receivers`, `Tuning::walk_receivers`)
//! holds every patch the reconstruction shader finds visible: checked patch by patch against the
//! shader's test (`Visible` in glsl/reconstruct.frag), written out here again in plain Rust, from
//! shots spread over Lost Empire and the simple room. tests/tuning.rs checks that the lightmaps
//! stay the same bit for bit with the switch on and off.

mod common;

use common::*;
use glam::Vec3;
use gpu_radiosity::scene::Scene;
use gpu_radiosity::solver::engine::seen_receivers::SeenReceivers;
use gpu_radiosity::solver::visibility::VisibilityPass;
use gpu_radiosity::solver::{mesh, GpuSolver, Shooter, SolveOptions, Tuning, VisibilityKind};
use std::collections::HashSet;

/// One shot as the shader sees it: the shooter, its view, its item buffer (`width` pixels a
/// row; `None`: nothing shown), and the polygons' planes with the slack.
struct Shot<'a> {
    shooter: &'a Shooter,
    view: glam::Mat4,
    ids: &'a [Option<u32>],
    width: usize,
    planes: &'a [gpu_radiosity::geometry::Plane],
    slack: f32,
}

/// The shader's visibility test for a patch of polygon `recv` at `pos` in `shot`.
fn shader_sees(shot: &Shot<'_>, pos: Vec3, recv: usize) -> bool {
    let Shot {
        shooter,
        view,
        ids,
        width,
        planes,
        slack,
    } = *shot;
    let d = view.transform_point3(pos);
    if d.z >= 0.0 {
        return false;
    }
    // item_texel: the face of the largest component, each face's coordinates as the shader
    // permutes them.
    let a = d.abs();
    let front = -d.z >= a.x && -d.z >= a.y;
    let side_x = !front && a.x >= a.y;
    let (face, f) = if front {
        (0, Vec3::new(d.x, d.y, -d.z))
    } else if side_x {
        let sx = d.x.signum();
        (
            if d.x > 0.0 { 1 } else { 2 },
            Vec3::new(sx * d.z, d.y, sx * d.x),
        )
    } else {
        let sy = d.y.signum();
        (
            if d.y > 0.0 { 3 } else { 4 },
            Vec3::new(sy * d.x, d.z, sy * d.y),
        )
    };
    let r = shooter.hemi_res as i64;
    let at = |t: f32| (((t * 0.5 + 0.5) * r as f32) as i64).clamp(0, r - 1) as usize;
    let (tx, ty) = (at(f.x / f.z), at(f.y / f.z));
    let shown = ids[ty * width + face * r as usize + tx];
    match shown {
        None => true,
        Some(x) if x as usize == recv => true,
        Some(x) => {
            let plane = planes[x as usize];
            let hs = plane.distance(shooter.position);
            let hr = plane.distance(pos);
            !(hs.abs() > slack && hr.abs() > slack && (hs > 0.0) != (hr > 0.0))
        }
    }
}

/// Shots from two points of every few polygons of `scene` at the resolutions `sides`: checks
/// that each patch the shader sees lies in a block the walk reached, and returns the shots, the
/// blocks reached, the blocks holding a patch the shader sees, and the blocks holding patches,
/// summed over the shots.
fn reach_against_shader(scene: &Scene, patch_size: f32, sides: &[u32]) -> [usize; 4] {
    let ctx = context();
    let layout = layout(scene, patch_size);
    let n = scene.polygons.len();
    let top = *sides.iter().max().unwrap();
    let solver = GpuSolver::new(&ctx, scene, &layout, SolveOptions::accurate()).unwrap();
    let positions = solver.backend().reconstruction.patch_positions();
    let width = layout.without_gutters().atlas_width as usize;
    let mut pass = VisibilityPass::new(
        &ctx,
        VisibilityKind::Hemicube,
        top,
        // The walk at every side (the engine's default draws those above `walk_up_to`).
        Tuning {
            walk_up_to: 0,
            ..Tuning::llvmpipe()
        },
        scene,
    )
    .unwrap();
    let data = pass
        .merge_plates(scene)
        .expect("the engine merges plates")
        .vertex_data(scene, &layout);
    let geometry = mesh::upload_scene(&ctx.gl, &data, n).unwrap();
    pass.use_seen_receivers(SeenReceivers::new(scene, &positions, width, 4));
    let wide = width.div_ceil(4);
    // Every patch: its block and polygon.
    let patches: Vec<(usize, Vec3, usize)> = (positions.chunks_exact(4).enumerate())
        .filter(|(_, t)| t[3] >= 1.0)
        .map(|(i, t)| {
            let block = i / width / 4 * wide + i % width / 4;
            (block, Vec3::new(t[0], t[1], t[2]), t[3] as usize - 1)
        })
        .collect();
    let all: HashSet<usize> = patches.iter().map(|&(b, _, _)| b).collect();
    let planes: Vec<_> = scene.polygons.iter().map(|p| p.plane()).collect();
    let slack = scene.plane_slack();
    let mut shooter = solver.shooters_of(solver.next_polygon().unwrap())[0];
    let mut totals = [0usize; 4];
    for (p, position) in shooting_points(scene, 100) {
        shooter.polygon = p;
        shooter.normal = scene.polygons[p].normal;
        shooter.position = position;
        shooter.hemi_res = sides[totals[0] % sides.len()];
        shooter.turn = totals[0] as f32 * 0.37;
        pass.run(&ctx, &geometry, &shooter).unwrap();
        let reach = pass
            .receivers_seen(0)
            .expect("the walk wrote the item buffer");
        let reached: HashSet<usize> = reach.blocks.iter().map(|&b| b as usize).collect();
        let ids = pass.read_ids();
        let shot = Shot {
            shooter: &shooter,
            view: shooter.view(),
            ids: &ids,
            width: pass.slot_texture(0).width as usize,
            planes: &planes,
            slack,
        };
        let mut seen = HashSet::new();
        for &(block, pos, recv) in &patches {
            if recv != p && shader_sees(&shot, pos, recv) {
                assert!(
                    reached.contains(&block),
                    "shot {} from polygon {p}: a patch of polygon {recv} at {pos} is seen, \
                     its block {block} not reached",
                    totals[0]
                );
                seen.insert(block);
            }
        }
        totals[0] += 1;
        totals[1] += reached.len();
        totals[2] += seen.len();
        totals[3] += all.len();
    }
    totals
}

#[test]
fn the_walk_reaches_every_patch_the_shader_sees() {
    let Some(scene) = third_party_lit("lost-empire/lost_empire.obj", "Torch", [5.0, 4.0, 2.0])
    else {
        return;
    };
    let [shots, reached, seen, all] = reach_against_shader(&scene, 1.1782, &[16, 23, 64]);
    println!("Lost Empire: {shots} shots, blocks reached {reached}, seen {seen}, of {all}");
    assert!(shots >= 150, "{shots} shots");
    // Most of the atlas is left out, and not much more is drawn than the shader needs.
    assert!(reached * 4 < all, "reached {reached} of {all} blocks");
    assert!(reached < 3 * seen, "reached {reached} blocks, {seen} seen");
    let scene = load("simple");
    let [shots, reached, seen, all] =
        reach_against_shader(&scene, scene.patch_size.unwrap(), &[16, 37, 128]);
    println!("simple room: {shots} shots, blocks reached {reached}, seen {seen}, of {all}");
    assert!(shots >= 150, "{shots} shots");
    assert!(reached < all, "reached {reached} of {all} blocks");
}
