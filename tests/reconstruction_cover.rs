//! The reconstruction pass draws the receivers as squares of whole 4×4 blocks over an atlas
//! without gutters; what it computes must not depend on how the squares are drawn (points, or
//! triangle pairs where an implementation's points are too small) nor on where the lightmaps
//! lie in the atlas.

mod common;

use common::*;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::solver::{GpuSolver, Tuning};

#[test]
fn squares_drawn_as_points_or_triangles_give_the_same_lightmaps() {
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()));
    let ctx = context();
    let options = gpu_radiosity::cli::bench::bench_options(0.01);
    let mut points = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    let mut triangles = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
    assert!(
        points.backend().reconstruction.squares_as_points,
        "llvmpipe draws wide points"
    );
    triangles.backend_mut().reconstruction.squares_as_points = false;
    for _ in 0..40 {
        let a = points.step().unwrap().unwrap();
        let b = triangles.step().unwrap().unwrap();
        assert_eq!(a.shooter, b.shooter);
    }
    let (a, b) = (points.radiosity_atlas(), triangles.radiosity_atlas());
    assert!(a.iter().any(|&v| v > 0.0));
    assert!(a == b, "the two covers computed different radiance");
    assert_eq!(points.unshot_atlas(), triangles.unshot_atlas());
}

#[test]
fn atlases_come_back_in_the_callers_layout() {
    // The solver packs the lightmaps without gutters; what it hands out is in the layout it was
    // given: every patch texel carries its polygon's ID + 1, every other texel is zero.
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(scene.patch_size.unwrap()));
    let dense = layout.without_gutters();
    assert!(dense.atlas_width * dense.atlas_height < layout.atlas_width * layout.atlas_height);
    assert_eq!(dense.patch_count(), layout.patch_count());
    let ctx = context();
    let mut solver = GpuSolver::new(
        &ctx,
        &scene,
        &layout,
        gpu_radiosity::cli::bench::bench_options(0.01),
    )
    .unwrap();
    solver.step().unwrap().unwrap();
    let atlas = solver.radiosity_atlas();
    assert_eq!(atlas.len(), layout.owner.len() * 4);
    for (texel, &owner) in atlas.chunks_exact(4).zip(&layout.owner) {
        assert_eq!(texel[3], owner as f32);
    }
}

#[test]
fn skipping_needless_clipping_changes_nothing_but_float_noise() {
    // Blocks whose receivers all have the whole shooter above their plane are drawn with the
    // shader variant that does not clip it: the same contour integral, so the same lightmaps up
    // to float rounding.
    let off = |t: &mut Tuning| t.skip_needless_clipping = false;
    on_both_rooms(off, |name, mut split, mut clipped| {
        let (mut cheap, mut full) = (0, 0);
        for _ in 0..40 {
            let a = split.step().unwrap().unwrap();
            let b = clipped.step().unwrap().unwrap();
            assert_eq!(a.shooter, b.shooter, "{name}");
            let (c, u) = split.backend().reconstruction.squares_drawn();
            full += c;
            cheap += u;
            assert_eq!(clipped.backend().reconstruction.squares_drawn().1, 0);
        }
        assert!(
            cheap > 0 && full > 0,
            "{name}: squares {full} clipped, {cheap} not"
        );
        let (a, b) = (split.radiosity_atlas(), clipped.radiosity_atlas());
        let diff: f64 = a.iter().zip(&b).map(|(x, y)| (x - y).abs() as f64).sum();
        let total: f64 = b.iter().map(|y| y.abs() as f64).sum();
        eprintln!(
            "{name}: {full} squares clipped, {cheap} not; L1 difference {:.2e}",
            diff / total
        );
        assert!(
            diff / total < 1e-6,
            "{name}: L1 difference {}",
            diff / total
        );
        // paper_notes 3.2.2, clipping only where needed: "Cornell box, 40 shots with shooter
        // cells, L1 difference 1.3e-8; simple room, 0".
        match name {
            "cornell" => assert_quoted("cornell: L1 difference", diff / total, "1.3e-8"),
            _ => assert_eq!(diff, 0.0, "{name}: L1 difference"),
        }
    });
}

#[test]
fn programs_unrolled_for_quadrilaterals_give_the_same_lightmaps() {
    // Quadrilateral shooters are drawn with programs compiled for four corners (`CORNERS`):
    // the same sums in the same order as the loop over a corner count read at run time, so
    // the same lightmaps, bit for bit (measured on both rooms).
    let off = |t: &mut Tuning| t.unroll_quads = false;
    on_both_rooms(off, |name, mut unrolled, mut looped| {
        for _ in 0..40 {
            let a = unrolled.step().unwrap().unwrap();
            let b = looped.step().unwrap().unwrap();
            assert_eq!(a.shooter, b.shooter, "{name}");
        }
        assert!(
            unrolled.backend().reconstruction.quad_passes > 0,
            "{name}: no quadrilateral shooter"
        );
        assert_eq!(looped.backend().reconstruction.quad_passes, 0);
        let (a, b) = (unrolled.radiosity_atlas(), looped.radiosity_atlas());
        assert!(a.iter().any(|&v| v > 0.0), "{name}");
        assert!(
            a == b,
            "{name}: the unrolled programs computed different radiance"
        );
        assert_eq!(unrolled.unshot_atlas(), looped.unshot_atlas(), "{name}");
    });
}

#[test]
fn the_papers_passes_and_the_tuned_ones_give_the_same_lightmaps() {
    // With every switch of `Tuning` off, each pass draws every patch and tests visibility in the
    // one shader, as the paper does: the same answer as the tuned passes, up to float rounding
    // (the variant that does not clip sums the same terms in another order).
    on_both_rooms(
        |t| *t = Tuning::none(),
        |name, mut tuned, mut paper| {
            for _ in 0..20 {
                let a = tuned.step().unwrap().unwrap();
                let b = paper.step().unwrap().unwrap();
                assert_eq!(a.shooter, b.shooter, "{name}");
            }
            for (a, b) in [
                (tuned.radiosity_atlas(), paper.radiosity_atlas()),
                (tuned.unshot_atlas(), paper.unshot_atlas()),
            ] {
                let diff: f64 = a.iter().zip(&b).map(|(x, y)| (x - y).abs() as f64).sum();
                let total: f64 = b.iter().map(|y| y.abs() as f64).sum();
                assert!(total > 0.0, "{name}");
                assert!(
                    diff / total < 1e-6,
                    "{name}: L1 difference {}",
                    diff / total
                );
            }
        },
    );
}

/// Run `check` on two solvers made alike but for `tweak` applied to the second one's tuning,
/// for the Cornell box with its default options (shooter cells) and for the simple room with the
/// bench's.
fn on_both_rooms(
    tweak: impl Fn(&mut Tuning),
    mut check: impl FnMut(&str, GpuSolver<'_>, GpuSolver<'_>),
) {
    for (name, options) in [
        ("cornell", gpu_radiosity::solver::SolveOptions::default()),
        ("simple", gpu_radiosity::cli::bench::bench_options(0.01)),
    ] {
        let scene = load(name);
        let resolution = scene
            .patch_size
            .map_or(Resolution::Patches(4096), Resolution::PatchSize);
        let layout = PatchLayout::new(&scene, resolution);
        let ctx = context();
        let mut tweaked = options.clone();
        tweak(&mut tweaked.tuning);
        let a = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
        let b = GpuSolver::new(&ctx, &scene, &layout, tweaked).unwrap();
        check(name, a, b);
    }
}
