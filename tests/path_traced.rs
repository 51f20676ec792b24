//! The default (accurate) mode's Cornell box against an independent path-traced reference of the
//! same scene: the mean radiance of each wall, floor, ceiling and block face, within 3 %.
//!
//! The reference is a plain Monte Carlo path tracer on the CPU (cosine-weighted bounces, the
//! light sampled directly, Russian roulette after three bounces), evaluated at a sample of patch
//! centres; it shares nothing with the radiosity solvers but the scene and the ray casting.

mod common;

use common::*;
use glam::Vec3;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::Scene;
use gpu_radiosity::solver::cpu::visibility::Bvh;
use gpu_radiosity::solver::{GpuSolver, SolveOptions};
use rayon::prelude::*;
use std::f32::consts::PI;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn cosine_direction(n: Vec3, rng: &mut Rng) -> Vec3 {
    let (u1, u2) = (rng.next(), rng.next());
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// Irradiance / π from the light, sampled on its area (next event estimation).
fn direct(
    scene: &Scene,
    bvh: &Bvh,
    light: usize,
    x: Vec3,
    n: Vec3,
    skip: u32,
    rng: &mut Rng,
) -> Vec3 {
    let l = &scene.polygons[light];
    let (a, b, d) = (l.vertices[0], l.vertices[1], l.vertices[3]);
    let y = a + (b - a) * rng.next() + (d - a) * rng.next();
    let w = y - x;
    let r2 = w.length_squared();
    let w = w / r2.sqrt();
    let (ci, cl) = (n.dot(w), -l.normal.dot(w));
    if ci <= 0.0 || cl <= 0.0 || bvh.occluded(x, y, skip, light as u32) {
        return Vec3::ZERO;
    }
    scene.material(l).ke * (ci * cl * l.area / (PI * r2))
}

/// Outgoing radiance at x on polygon p (emission excluded: these are receivers).
fn radiance(scene: &Scene, bvh: &Bvh, light: usize, p: usize, x: Vec3, rng: &mut Rng) -> Vec3 {
    let (mut total, mut throughput) = (Vec3::ZERO, scene.material(&scene.polygons[p]).kd);
    let (mut x, mut p) = (x, p);
    for bounce in 0..64 {
        let n = scene.polygons[p].normal;
        total += throughput * direct(scene, bvh, light, x, n, p as u32, rng);
        if bounce >= 3 {
            let survive = throughput.max_element().min(0.95);
            if rng.next() >= survive {
                break;
            }
            throughput /= survive;
        }
        let d = cosine_direction(n, rng);
        let Some((t, q)) = bvh.closest(x, d, p as u32) else {
            break;
        };
        let q = q as usize;
        // Front faces only: a back face and the light (counted by the direct term) end the path.
        if scene.polygons[q].normal.dot(d) >= 0.0 || q == light {
            break;
        }
        x += d * t;
        p = q;
        throughput *= scene.material(&scene.polygons[q]).kd;
    }
    total
}

/// The reference mean radiance (RGB) of polygon `p` over all its patch centres, and the relative
/// standard error of its RGB mean: eight independent batches of `paths / 8` paths per centre.
fn reference(
    scene: &Scene,
    bvh: &Bvh,
    layout: &PatchLayout,
    light: usize,
    p: usize,
    paths: usize,
) -> (Vec3, f32) {
    let centres = patch_centres(layout, p);
    let batches: Vec<Vec3> = (0..8u64)
        .into_par_iter()
        .map(|b| {
            let mut rng = Rng(1000 * p as u64 + 7919 * b + 1);
            let mut sum = Vec3::ZERO;
            for (_, x) in &centres {
                for _ in 0..paths / 8 {
                    sum += radiance(scene, bvh, light, p, *x, &mut rng);
                }
            }
            sum / (centres.len() * (paths / 8)) as f32
        })
        .collect();
    let mean = batches.iter().copied().sum::<Vec3>() / 8.0;
    let m = lum(mean);
    let variance = batches.iter().map(|b| (lum(*b) - m).powi(2)).sum::<f32>() / 7.0;
    (mean, (variance / 8.0).sqrt() / m)
}

fn lum(v: Vec3) -> f32 {
    (v.x + v.y + v.z) / 3.0
}

/// Per polygon but the light: (region, difference %, reference noise %), and the worst
/// difference and noise, of the Cornell box solved with `options` (4,096 patches, the default
/// layout) against the path-traced reference (computed once for the binary's tests).
fn regions_against_the_reference(
    options: SolveOptions,
) -> (Vec<(&'static str, f64, f64)>, f32, f32) {
    static REFERENCE: std::sync::OnceLock<Vec<(Vec3, f32)>> = std::sync::OnceLock::new();
    let scene = load("cornell");
    let light = scene
        .polygons
        .iter()
        .position(|p| scene.material(p).is_emitter())
        .unwrap();
    let layout = PatchLayout::new(&scene, Resolution::Patches(4096));
    let atlas = {
        let ctx = context();
        let mut solver = GpuSolver::new(&ctx, &scene, &layout, options).unwrap();
        solver.solve(|_| {}).unwrap();
        solver.radiosity_atlas()
    };
    // 1,024 paths at every patch centre: the darkest face's reference is good to ~1 %.
    let references = REFERENCE.get_or_init(|| {
        let bvh = Bvh::new(&scene);
        (0..scene.polygons.len())
            .map(|p| {
                if p == light {
                    (Vec3::ZERO, 0.0)
                } else {
                    reference(&scene, &bvh, &layout, light, p, 1024)
                }
            })
            .collect()
    });
    let (mut worst, mut worst_noise) = (0f32, 0f32);
    // (region, difference %, noise %) per polygon; the short block's front is its side facing
    // the camera (at -z).
    let mut regions = Vec::new();
    let front = (0..scene.polygons.len())
        .filter(|&p| scene.polygons[p].object == "short_block")
        .min_by(|&a, &b| {
            scene.polygons[a]
                .normal
                .z
                .total_cmp(&scene.polygons[b].normal.z)
        })
        .unwrap();
    for (p, polygon) in scene.polygons.iter().enumerate() {
        if p == light {
            continue;
        }
        let centres = patch_centres(&layout, p);
        let ours = centres
            .iter()
            .map(|&(at, _)| Vec3::from_slice(&atlas[at * 4..at * 4 + 3]))
            .sum::<Vec3>()
            / centres.len() as f32;
        let (reference, noise) = references[p];
        let err = (lum(ours) - lum(reference)) / lum(reference);
        println!(
            "{:<12} {p:>2}: ours {:.4} {:.4} {:.4}  reference {:.4} {:.4} {:.4} (± {:.2} %)  diff {:+.2} % (RGB mean)",
            polygon.object, ours.x, ours.y, ours.z, reference.x, reference.y, reference.z,
            100.0 * noise, 100.0 * err
        );
        worst = worst.max(err.abs());
        worst_noise = worst_noise.max(noise);
        let region = match (polygon.object.as_str(), polygon.normal.y > 0.9) {
            ("short_block", true) => "short block top",
            ("short_block", false) if p == front => "short block front",
            ("short_block", false) => "short block sides",
            ("tall_block", true) => "tall block top",
            ("tall_block", false) => "tall block faces",
            ("floor", _) => "floor",
            ("ceiling", _) => "ceiling",
            ("back_wall", _) => "back_wall",
            ("red_wall", _) => "red_wall",
            ("green_wall", _) => "green_wall",
            (name, _) => panic!("a polygon of '{name}', which the table does not list"),
        };
        regions.push((region, 100.0 * err as f64, 100.0 * noise as f64));
    }
    (regions, worst, worst_noise)
}

/// The default command (`radiosity solve`: the accurate mode with its own threshold, 0.3 %
/// unshot) lands within 3 % of the path-traced reference in every region (issue 36).
#[test]
fn the_default_command_is_within_3_percent_in_every_region() {
    let options = SolveOptions::accurate();
    assert_eq!(options.threshold, gpu_radiosity::solver::DEFAULT_THRESHOLD);
    let (regions, worst, worst_noise) = regions_against_the_reference(options);
    println!(
        "default: worst region {:.2} % (reference standard error at most {:.2} %)",
        100.0 * worst,
        100.0 * worst_noise
    );
    assert!(worst < 0.03, "a region differs by {:.2} %", 100.0 * worst);
    // No face goes dark: the short block's front (behind every whole-polygon shooter's centroid)
    // is within the bound like the rest.
    let front = regions.iter().find(|r| r.0 == "short block front").unwrap();
    assert!(front.1.abs() < 3.0, "short block front {:+.2} %", front.1);
    // README, docs/accuracy.md and docs/usage.md quote it.
    assert_quoted(
        "default command, worst region %",
        100.0 * worst as f64,
        "1.78",
    );
}

/// Converged further (0.1 % unshot), the default mode's regions, each against the reference.
#[test]
fn cornell_box_matches_a_path_traced_reference() {
    let (regions, worst, worst_noise) = regions_against_the_reference(SolveOptions {
        threshold: 1e-3,
        ..SolveOptions::accurate()
    });
    println!(
        "worst region: {:.2} % (reference standard error at most {:.2} %)",
        100.0 * worst,
        100.0 * worst_noise
    );
    // The reference must be good enough to judge 3 % by.
    assert!(
        worst_noise < 0.015,
        "reference noise {:.2} %",
        100.0 * worst_noise
    );
    assert!(worst < 0.03, "a region differs by {:.2} %", 100.0 * worst);
    // docs/testing.md: "measured: worst 1.60 %, reference noise ≤ 1.22 %".
    assert_quoted("worst region %", 100.0 * worst as f64, "1.60");
    assert_quoted(
        "worst reference noise %",
        100.0 * worst_noise as f64,
        "1.22",
    );
    // paper_notes' table: each region's difference (one polygon) or smallest and largest
    // (several), and its reference's standard error (the largest), in %.
    let table = [
        ("floor", "+1.08", "+1.08", "0.08"),
        ("ceiling", "-0.47", "+1.13", "0.64"),
        ("back_wall", "+0.87", "+0.87", "0.08"),
        ("red_wall", "+1.21", "+1.21", "0.10"),
        ("green_wall", "+0.44", "+0.44", "0.09"),
        ("short block top", "+0.78", "+0.78", "0.10"),
        ("short block sides", "-1.60", "+1.18", "0.75"),
        ("short block front", "-1.39", "-1.39", "1.22"),
        ("tall block top", "+0.54", "+0.54", "0.12"),
        ("tall block faces", "-0.79", "+0.98", "0.33"),
    ];
    assert_eq!(
        regions.len(),
        load("cornell").polygons.len() - 1,
        "every polygon but the light"
    );
    for (region, low, high, noise) in table {
        let rows: Vec<_> = regions.iter().filter(|r| r.0 == region).collect();
        assert!(!rows.is_empty(), "no polygon of {region}");
        let min = rows.iter().map(|r| r.1).fold(f64::INFINITY, f64::min);
        let max = rows.iter().map(|r| r.1).fold(f64::NEG_INFINITY, f64::max);
        let most_noise = rows.iter().map(|r| r.2).fold(0.0, f64::max);
        assert_quoted(&format!("{region}: smallest difference %"), min, low);
        assert_quoted(&format!("{region}: largest difference %"), max, high);
        assert_quoted(&format!("{region}: reference ± %"), most_noise, noise);
    }
    assert_eq!(
        table
            .iter()
            .map(|t| regions.iter().filter(|r| r.0 == t.0).count())
            .sum::<usize>(),
        regions.len(),
        "every polygon is in the table"
    );
}
