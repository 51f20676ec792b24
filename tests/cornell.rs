//! The bundled Cornell box, solved with the default settings: colour bleeds from the coloured
//! walls onto the white ones, and the blocks cast shadows on the floor.

mod common;

use common::*;
use glam::Vec3;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::solver::{GpuSolver, SolveOptions};

#[test]
fn colour_bleeding_and_shadows() {
    let scene = load("cornell");
    let layout = PatchLayout::new(&scene, Resolution::Patches(4096));
    let ctx = context();
    let mut solver = GpuSolver::new(&ctx, &scene, &layout, SolveOptions::default()).unwrap();
    solver.solve(|_| {}).unwrap();
    assert!(solver.unshot_fraction() <= 0.01);
    let atlas = solver.radiosity_atlas();
    let index = |name: &str| {
        scene
            .polygons
            .iter()
            .position(|p| p.object == name)
            .unwrap()
    };
    // Mean radiance of a polygon's patches whose centres satisfy `pick`.
    let mean = |p: usize, pick: &dyn Fn(Vec3) -> bool| {
        let (mut sum, mut n) = (Vec3::ZERO, 0);
        for (at, pos) in patch_centres(&layout, p) {
            if pick(pos) {
                sum += Vec3::from_slice(&atlas[at * 4..at * 4 + 3]);
                n += 1;
            }
        }
        assert!(n > 0);
        sum / n as f32
    };
    let back = index("back_wall");
    // The red wall is at x ≈ 556, the green one at x = 0.
    let near_red = mean(back, &|p| p.x > 480.0 && p.y > 150.0);
    let near_green = mean(back, &|p| p.x < 76.0 && p.y > 150.0);
    println!("back wall near red {near_red}, near green {near_green}");
    let ratio = |v: Vec3| v.x / v.y;
    assert!(
        ratio(near_red) > 1.15 * ratio(near_green),
        "red bleeds onto the back wall"
    );
    assert!(
        near_green.y / near_green.z > 1.1 * near_red.y / near_red.z,
        "green bleeds too"
    );

    // The short block (x 82..290, z 65..272, 165 high) shades the floor in front of it; the floor
    // at the same depth on the other side sees the light.
    let floor = index("floor");
    let shaded = mean(floor, &|p| (150.0..230.0).contains(&p.x) && p.z < 40.0);
    let open = mean(floor, &|p| (400.0..480.0).contains(&p.x) && p.z < 40.0);
    println!("floor in front of the short block {shaded}, open floor {open}");
    assert!(
        shaded.length() < 0.7 * open.length(),
        "the short block casts a shadow"
    );
}
