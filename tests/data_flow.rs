//! The paper's data flow (section 3.2.2): the lightmaps live in two textures; each
//! reconstruction pass reads them, adds ΔL and writes renderbuffers that glCopyTexSubImage2D
//! copies back into the textures; the next pass and Find_Max_Energy read the textures. These
//! tests change the textures between shots from outside and check that the next shot starts from
//! what they hold, in both modes (the paper's untuned passes and the tuned accurate ones).

mod common;

use common::*;
use gpu_radiosity::solver::{GpuSolver, SolveOptions};

fn modes() -> [(&'static str, SolveOptions); 2] {
    [
        ("paper", SolveOptions::paper()),
        ("accurate", SolveOptions::accurate()),
    ]
}

/// Patch texels of an atlas (alpha: polygon ID + 1), with their polygon.
fn patches(atlas: &[f32]) -> impl Iterator<Item = (usize, usize)> + '_ {
    atlas
        .chunks_exact(4)
        .enumerate()
        .filter(|(_, t)| t[3] > 0.0)
        .map(|(i, t)| (i, t[3] as usize - 1))
}

#[test]
fn a_shot_leaves_its_sums_in_the_textures() {
    // After one shot of the Cornell box's light: in the unshot texture the light's texels that
    // shot hold zero, and every other patch holds exactly what it gained (its radiance less its
    // emission, which only the light has). Both are read back from the textures: without the
    // copies they would still hold the emission.
    let scene = load("cornell");
    let layout = layout(&scene, 20.0);
    let ctx = context();
    for (mode, options) in modes() {
        let mut solver = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
        let light = solver.next_polygon().unwrap();
        let before = solver.radiosity_atlas();
        let record = solver.step().unwrap().unwrap();
        assert_eq!(record.shooter, light, "{mode}");
        let (radiance, unshot) = (solver.radiosity_atlas(), solver.unshot_atlas());
        let mut gained = 0;
        for (i, polygon) in patches(&radiance) {
            let rgb = |a: &[f32]| [a[i * 4], a[i * 4 + 1], a[i * 4 + 2]];
            if polygon == light {
                assert_eq!(
                    rgb(&radiance),
                    rgb(&before),
                    "{mode}: the light receives nothing"
                );
                continue;
            }
            assert_eq!(rgb(&before), [0.0; 3], "{mode}: only the light emits");
            assert_eq!(rgb(&unshot), rgb(&radiance), "{mode}: texel {i}");
            gained += (rgb(&radiance)[0] > 0.0) as usize;
        }
        assert!(gained > 1000, "{mode}: only {gained} patches received");
        // The whole light shot in the paper's mode; a cell of it in the accurate mode.
        let zeroed = patches(&unshot)
            .filter(|&(i, p)| p == light && unshot[i * 4..i * 4 + 3] == [0.0; 3])
            .count();
        assert!(zeroed > 0, "{mode}: no texel of the light was cleared");
        if mode == "paper" {
            assert_eq!(zeroed, layout.patches_per_polygon[light] as usize, "{mode}");
        }
    }
}

#[test]
fn the_next_shot_starts_from_what_the_textures_hold() {
    // Two solvers alike; after one shot, the second one's radiance texture gets 0.25 more on
    // every patch. After the next shot (the same shooter: the unshot texture is unchanged) the
    // two differ by exactly that on every patch: the pass added its ΔL to the texture's values.
    let scene = load("cornell");
    let layout = layout(&scene, 20.0);
    let ctx = context();
    for (mode, options) in modes() {
        let mut a = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
        let mut b = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
        a.step().unwrap().unwrap();
        b.step().unwrap().unwrap();
        let mut radiance = b.radiosity_atlas();
        for (i, _) in patches(&radiance.clone()) {
            for c in &mut radiance[i * 4..i * 4 + 3] {
                *c += 0.25;
            }
        }
        b.load_atlases(&radiance, &b.unshot_atlas()).unwrap();
        let (x, y) = (a.step().unwrap().unwrap(), b.step().unwrap().unwrap());
        assert_eq!(x.shooter, y.shooter, "{mode}");
        assert!(x.reflected_power > 0.0, "{mode}");
        let (ra, rb) = (a.radiosity_atlas(), b.radiosity_atlas());
        let mut patches_seen = 0;
        for (i, _) in patches(&ra) {
            for c in 0..3 {
                let d = rb[i * 4 + c] - ra[i * 4 + c];
                assert!(
                    (d - 0.25).abs() <= 1e-5 * (1.0 + ra[i * 4 + c].abs()),
                    "{mode}: texel {i} channel {c}: {} against {}",
                    rb[i * 4 + c],
                    ra[i * 4 + c]
                );
            }
            patches_seen += 1;
        }
        assert!(patches_seen > 1000, "{mode}");
        assert_eq!(a.unshot_atlas(), b.unshot_atlas(), "{mode}");
    }
}

#[test]
fn find_max_energy_reads_the_unshot_texture() {
    // Give one wall the most unshot energy in the texture: Find_Max_Energy picks it, it shoots,
    // and its texels in the unshot texture are zero afterwards (all of them in the paper's mode,
    // where the whole polygon shoots at once).
    let scene = load("cornell");
    let layout = layout(&scene, 20.0);
    let ctx = context();
    for (mode, options) in modes() {
        let mut solver = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
        let light = solver.next_polygon().unwrap();
        let wall = (0..scene.polygons.len())
            .find(|&p| p != light && layout.patches_per_polygon[p] > 50)
            .unwrap();
        let mut unshot = solver.unshot_atlas();
        for (i, p) in patches(&unshot.clone()) {
            if p == wall {
                unshot[i * 4..i * 4 + 3].copy_from_slice(&[100.0; 3]);
            }
        }
        solver
            .load_atlases(&solver.radiosity_atlas(), &unshot)
            .unwrap();
        assert_eq!(solver.next_polygon(), Some(wall), "{mode}");
        let record = solver.step().unwrap().unwrap();
        assert_eq!(record.shooter, wall, "{mode}");
        let after = solver.unshot_atlas();
        // Cleared to 0 in the paper; in the accurate mode to the overshoot remainder (ρ times the
        // ambient still to come, negative): either way none of the 100 is left.
        let cleared = patches(&after)
            .filter(|&(i, p)| p == wall && after[i * 4..i * 4 + 3].iter().all(|&v| v <= 0.0))
            .count();
        assert!(cleared > 0, "{mode}");
        if mode == "paper" {
            assert_eq!(cleared, layout.patches_per_polygon[wall] as usize, "{mode}");
        }
    }
}
