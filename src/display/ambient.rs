//! The ambient term of Cohen, Chen, Wallace and Greenberg (1988), for showing an unconverged
//! solution: the unshot energy, spread evenly over the scene and reflected with the average
//! reflectance's geometric series, added to every patch for display only (the lightmap output
//! stays the solver's own answer).
//!
//! L_amb = R · Σ ΔL_i A_i / Σ A_i with R = 1 / (1 - ρ_avg), ρ_avg = Σ ρ_i A_i / Σ A_i, per
//! channel; patch j shows L_j + ρ_j · L_amb.

use crate::scene::Scene;
use glam::Vec3;

/// The ambient radiance of an unshot atlas (RGBA, alpha = polygon ID + 1) with per-polygon patch
/// areas.
pub fn ambient(scene: &Scene, unshot: &[f32], patch_area: &[f64]) -> Vec3 {
    let (mut unshot_sum, mut area_sum) = ([0f64; 3], 0f64);
    for t in unshot.chunks_exact(4).filter(|t| t[3] > 0.0) {
        let a = patch_area[t[3] as usize - 1];
        for c in 0..3 {
            unshot_sum[c] += t[c] as f64 * a;
        }
        area_sum += a;
    }
    let total_area: f64 = scene.polygons.iter().map(|p| p.area as f64).sum();
    let mut rho = [0f64; 3];
    for p in &scene.polygons {
        let kd = scene.material(p).kd;
        for c in 0..3 {
            rho[c] += kd[c] as f64 * p.area as f64 / total_area;
        }
    }
    if area_sum <= 0.0 {
        return Vec3::ZERO;
    }
    let l = |c: usize| (unshot_sum[c] / area_sum / (1.0 - rho[c].min(0.999))) as f32;
    Vec3::new(l(0), l(1), l(2))
}

/// Add ρ_j · L_amb to every patch of a radiance atlas (RGBA, alpha = polygon ID + 1).
pub fn add_ambient(scene: &Scene, atlas: &mut [f32], ambient: Vec3) {
    for t in atlas.chunks_exact_mut(4).filter(|t| t[3] > 0.0) {
        let kd = scene.material(&scene.polygons[t[3] as usize - 1]).kd;
        for c in 0..3 {
            t[c] += kd[c] * ambient[c];
        }
    }
}
