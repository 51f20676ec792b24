//! The accuracy guard of the speed options: a solution against the CPU solver run exhaustively
//! (to 0.1 % unshot) on the same patches, by the mean per-patch difference. The speed options
//! (overshooting, smaller item buffers for small shots) change which shots are taken and how
//! finely each is sampled, so "the same bits" no longer applies; this figure says how far the
//! answer moved. `radiosity bench guard` and `bench table1` print it; `tests/speed_guard.rs`
//! fails when a speed option breaks the bound.

use crate::patches::PatchLayout;
use crate::scene::Scene;
use crate::solver::cpu::CpuSolver;
use crate::solver::{SolveError, SolveOptions};

/// The reference's stopping rule: unshot power / emitted power.
pub const REFERENCE_THRESHOLD: f32 = 1e-3;

/// The bound the speed options must keep on the simple room: the mean per-patch difference of
/// the paper-faithful bench configuration against the reference (docs/accuracy.md), a fraction.
pub const MEAN_DIFFERENCE_BOUND: f64 = 0.015;

/// The reference solution: the CPU solver (exact ray-cast visibility) with `options`' shooters
/// and form factor, to [`REFERENCE_THRESHOLD`], none of the speed options. RGBA atlas in
/// `layout`. Configurations that shoot alike ([`same_shooters`]) share a reference: one that
/// shoots cells is measured against a reference that shoots cells, since whole polygons and
/// cells are two discretisations of the answer (on the simple room they differ by far more than
/// any speed option moves it).
pub fn reference(
    scene: &Scene,
    layout: &PatchLayout,
    options: &SolveOptions,
    threads: usize,
) -> Result<(Vec<f32>, u32), SolveError> {
    let options = SolveOptions {
        threshold: REFERENCE_THRESHOLD,
        max_shots: 1_000_000,
        overshoot: false,
        small_hemi_res: 0,
        min_hemi_res: 0,
        rotate_item_buffer: false,
        ..options.clone()
    };
    let mut cpu = CpuSolver::new(scene, layout, options, threads)?;
    cpu.solve(|_| {})?;
    Ok((cpu.radiosity_atlas(), cpu.shots()))
}

/// Whether two configurations shoot from the same shooters (whole polygons or cells of the same
/// side, cut alike), so that one [`reference()`] serves both.
pub fn same_shooters(a: &SolveOptions, b: &SolveOptions) -> bool {
    // Whole polygons are never cut: the cut rule matters only where cells shoot.
    let key = |o: &SolveOptions| {
        let cells = o.shooter_cell != 0 || o.emitter_cell != 0;
        (
            o.shooter_cell,
            o.emitter_cell,
            if cells { o.cut_above } else { 0.0 },
            // Coarse cells are used only by shots that are not cut.
            if cells && o.cut_above > 0.0 {
                o.coarse_cell
            } else {
                0
            },
        )
    };
    key(a) == key(b)
}

/// Mean absolute per-patch difference over the mean radiance: Σ|a − b| / Σ b over the patches
/// (texels whose alpha, the polygon ID + 1, is not 0), radiance as the RGB mean. Both atlases
/// RGBA in the same layout.
pub fn mean_patch_difference(solution: &[f32], reference: &[f32]) -> f64 {
    let mean = |t: &[f32]| (t[0] as f64 + t[1] as f64 + t[2] as f64) / 3.0;
    let (mut difference, mut sum) = (0.0, 0.0);
    for (a, b) in solution.chunks_exact(4).zip(reference.chunks_exact(4)) {
        if b[3] > 0.0 {
            difference += (mean(a) - mean(b)).abs();
            sum += mean(b);
        }
    }
    if sum > 0.0 {
        difference / sum
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_difference_is_relative_to_the_mean_and_skips_non_patches() {
        let reference = [2.0, 2.0, 2.0, 1.0, 4.0, 4.0, 4.0, 2.0, 9.0, 9.0, 9.0, 0.0];
        let solution = [2.0, 2.0, 2.0, 1.0, 3.4, 3.4, 3.4, 2.0, 0.0, 0.0, 0.0, 0.0];
        assert!((mean_patch_difference(&solution, &reference) - 0.1).abs() < 1e-6);
        assert_eq!(mean_patch_difference(&reference, &reference), 0.0);
    }
}
