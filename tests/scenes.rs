//! The bundled scenes load as docs/conventions.md describes them, and their patches are laid out
//! consistently (the CPU's patch map is the one the GPU rasterises).

mod common;

use common::*;
use glam::Vec3;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::solver::{GpuSolver, SolveOptions};

#[test]
fn cornell_box_faces_the_inside_and_has_its_camera() {
    let scene = load("cornell");
    assert_eq!(scene.polygons.len(), 19);
    assert_eq!(scene.light_count(), 1);
    let centre = Vec3::new(278.0, 274.0, 280.0);
    for p in &scene.polygons {
        let m = scene.material(p);
        if m.is_emitter() {
            assert!(p.normal.dot(Vec3::NEG_Y) > 0.999, "the light faces down");
            assert_eq!(m.ke, Vec3::new(17.0, 12.0, 4.0));
        }
        if ["floor", "ceiling", "back_wall", "red_wall", "green_wall"].contains(&p.object.as_str())
        {
            assert!(
                p.normal.dot(centre - p.centroid) > 0.0,
                "{} faces the inside",
                p.object
            );
        }
    }
    let camera = scene
        .camera
        .expect("the OBJ carries the CONVENTIONS.md camera");
    assert_eq!(camera.eye, Vec3::new(278.0, 273.0, -800.0));
    assert!((camera.fov_y - 39.3077).abs() < 1e-4);
    // The ceiling's four quads and the light tile the measured ceiling.
    let ceiling: f32 = scene
        .polygons
        .iter()
        .filter(|p| p.object == "ceiling" || p.object == "light")
        .map(|p| p.area)
        .sum();
    assert!(
        (ceiling - 556.0 * 559.2).abs() < 1.0,
        "ceiling area {ceiling}"
    );
}

#[test]
fn patches_lie_inside_their_polygons_and_add_up() {
    for name in ["cornell", "box", "shadow"] {
        let scene = load(name);
        for target in [100, 1000, 5000] {
            let layout = PatchLayout::new(&scene, Resolution::Patches(target));
            let total = layout.patch_count();
            assert_eq!(
                total,
                layout.owner.iter().filter(|&&o| o > 0).count() as u64
            );
            // Within 25 % of the target (lightmaps are whole texels).
            assert!(
                (total as f64 / target as f64 - 1.0).abs() < 0.25,
                "{name}: {total} for {target}"
            );
            for (i, p) in scene.polygons.iter().enumerate() {
                assert!(
                    layout.patches_per_polygon[i] > 0 || p.area < 4.0 * layout.patch_size.powi(2)
                );
                for (_, pos) in patch_centres(&layout, i) {
                    assert!((pos - p.vertices[0]).dot(p.normal).abs() < 0.1 * layout.patch_size);
                }
            }
            // Rectangles get lightmaps that fit them exactly: every texel is a patch.
            if name == "box" {
                for (i, lm) in layout.lightmaps.iter().enumerate() {
                    assert_eq!(layout.patches_per_polygon[i], lm.w * lm.h);
                }
            }
        }
    }
}

#[test]
fn the_gpu_rasterises_exactly_the_cpu_patches() {
    let ctx = context();
    for name in ["cornell", "shadow"] {
        let scene = load(name);
        let layout = PatchLayout::new(&scene, Resolution::Patches(3000));
        let solver = GpuSolver::new(&ctx, &scene, &layout, SolveOptions::default()).unwrap();
        assert_eq!(
            solver.ledger().patches(),
            layout.patches_per_polygon,
            "{name}"
        );
        // And the texels themselves: alpha carries the polygon ID + 1.
        let atlas = solver.radiosity_atlas();
        let gpu_owner: Vec<u32> = atlas.chunks_exact(4).map(|t| t[3] as u32).collect();
        assert_eq!(gpu_owner, layout.owner, "{name}");
    }
}
