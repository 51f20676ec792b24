//! The checks. Each builds its scene in code (or loads a bundled one), runs the GPU solver, and
//! compares with an answer computed without it.

use super::{direct, Check};
use crate::gl::GlContext;
use crate::patches::{PatchLayout, Resolution};
use crate::scene::{Material, Polygon, Scene};
use crate::solver::{GpuSolver, SolveOptions};
use anyhow::Result;
use glam::Vec3;
use std::f32::consts::PI;

/// A polygon for a scene built in code: outline (counter-clockwise from the front), Kd, Ke.
struct Face {
    outline: Vec<Vec3>,
    kd: f32,
    ke: f32,
}

/// A rectangle centred at `c` spanned by half-axes `u` and `v`; it faces u × v.
fn rect(c: Vec3, u: Vec3, v: Vec3, kd: f32, ke: f32) -> Face {
    Face {
        outline: vec![c - u - v, c + u - v, c + u + v, c - u + v],
        kd,
        ke,
    }
}

/// A disk of radius `r` as a 32-gon of the same area, centred at `c`, facing u × v.
fn disk(c: Vec3, u: Vec3, v: Vec3, r: f32, kd: f32, ke: f32) -> Face {
    let n = 32;
    let scale = r * (PI / (0.5 * n as f32 * (2.0 * PI / n as f32).sin())).sqrt();
    let outline = (0..n)
        .map(|k| {
            let a = 2.0 * PI * k as f32 / n as f32;
            c + (u * a.cos() + v * a.sin()) * scale
        })
        .collect();
    Face { outline, kd, ke }
}

fn scene(name: &str, faces: Vec<Face>) -> Scene {
    let mut materials = Vec::new();
    let mut polygons = Vec::new();
    for (i, f) in faces.into_iter().enumerate() {
        materials.push(Material {
            name: format!("m{i}"),
            kd: Vec3::splat(f.kd),
            ke: Vec3::splat(f.ke),
        });
        polygons.push(
            Polygon::new(f.outline, i, format!("face{i}")).expect("validation faces have area"),
        );
    }
    Scene {
        name: name.into(),
        polygons,
        materials,
        vertex_count: 0,
        camera: None,
        patch_size: None,
        skipped_degenerate: 0,
        faces: 0,
    }
}

/// The inside of the unit cube [0,1]³: six faces looking in (bottom, top, -x, +x, -z, +z).
fn cube(kd: f32, emission: [f32; 6]) -> Vec<Face> {
    let h = 0.5;
    let c = Vec3::splat(0.5);
    let (x, y, z) = (Vec3::X * h, Vec3::Y * h, Vec3::Z * h);
    vec![
        rect(c - y, z, x, kd, emission[0]),
        rect(c + y, x, z, kd, emission[1]),
        rect(c - x, y, z, kd, emission[2]),
        rect(c + x, z, y, kd, emission[3]),
        rect(c - z, x, y, kd, emission[4]),
        rect(c + z, y, x, kd, emission[5]),
    ]
}

fn rgb_mean(v: &[f32]) -> f64 {
    (v[0] as f64 + v[1] as f64 + v[2] as f64) / 3.0
}

/// Shoot all of polygon `emitter`'s energy once; return the radiance atlas and the solver's
/// per-patch areas.
fn one_shot(
    ctx: &GlContext,
    scene: &Scene,
    patch_size: f32,
    options: &SolveOptions,
    emitter: usize,
) -> Result<(Vec<f32>, PatchLayout, Vec<f64>)> {
    let layout = PatchLayout::new(scene, Resolution::PatchSize(patch_size));
    let mut solver = GpuSolver::new(ctx, scene, &layout, options.clone())?;
    let shooters = solver.shooters_of(emitter);
    solver.shoot(&shooters)?;
    let areas = (0..scene.polygons.len())
        .map(|p| solver.patch_area(p))
        .collect();
    Ok((solver.radiosity_atlas(), layout, areas))
}

/// F from `emitter` (Le = 1) to `receiver` (ρ = 1): the power the receiver gets over the power
/// the emitter sends.
fn area_factor(
    ctx: &GlContext,
    scene: &Scene,
    patch_size: f32,
    options: &SolveOptions,
) -> Result<f64> {
    let (atlas, _, areas) = one_shot(ctx, scene, patch_size, options, 0)?;
    let received: f64 = atlas
        .chunks_exact(4)
        .filter(|t| t[3] as usize == 2)
        .map(|t| rgb_mean(t) * areas[1])
        .sum();
    Ok(received / scene.polygons[0].area as f64)
}

/// F from a differential area (a tiny one-patch square, ρ = 1, centred on the point) to the
/// emitter (Le = 1): the receiver's radiance after one shot.
fn point_factor(
    ctx: &GlContext,
    scene: &Scene,
    patch_size: f32,
    options: &SolveOptions,
) -> Result<f64> {
    let (atlas, layout, _) = one_shot(ctx, scene, patch_size, options, 0)?;
    let texels: Vec<&[f32]> = atlas
        .chunks_exact(4)
        .filter(|t| t[3] as usize == 2)
        .collect();
    anyhow::ensure!(
        layout.patches_per_polygon[1] == 1 && texels.len() == 1,
        "the point receiver must be one patch"
    );
    Ok(rgb_mean(texels[0]))
}

/// Single-shot configuration factors against the closed forms of docs/conventions.md.
pub fn form_factor_checks(
    ctx: &GlContext,
    mode: &'static str,
    options: &SolveOptions,
) -> Result<Vec<Check>> {
    let (x, y, z) = (Vec3::X, Vec3::Y, Vec3::Z);
    // rect(c, u, v) faces u × v: z × x = +y, x × z = -y.
    let tiny = |c: Vec3| rect(c, z * 5e-4, x * 5e-4, 1.0, 0.0);
    let down = |c: Vec3, a: f32, b: f32| rect(c, x * (0.5 * a), z * (0.5 * b), 0.0, 1.0);
    let up = |c: Vec3, a: f32, b: f32| rect(c, z * (0.5 * b), x * (0.5 * a), 1.0, 0.0);
    let mut checks = Vec::new();
    let ps = 1.0 / 32.0;

    let corner = scene(
        "corner",
        vec![down(Vec3::new(0.5, 1.0, 0.5), 1.0, 1.0), tiny(Vec3::ZERO)],
    );
    checks.push(Check::new(
        "dA to 1x1 rectangle over its corner, c = 1",
        mode,
        0.13853,
        point_factor(ctx, &corner, ps, options)?,
        0.01,
    ));
    let centre = scene("centre", vec![down(Vec3::Y, 1.0, 1.0), tiny(Vec3::ZERO)]);
    checks.push(Check::new(
        "dA to unit square, centred, distance 1",
        mode,
        0.23946,
        point_factor(ctx, &centre, ps, options)?,
        0.01,
    ));
    let near = scene(
        "near",
        vec![down(Vec3::Y * 0.5, 1.0, 1.0), tiny(Vec3::ZERO)],
    );
    checks.push(Check::new(
        "dA to unit square, centred, distance 0.5",
        mode,
        0.55413,
        point_factor(ctx, &near, ps, options)?,
        0.01,
    ));

    for (side, expected) in [(1.0, 0.19982), (2.0, 0.41525), (0.5, 0.06859)] {
        let s = scene(
            "parallel",
            vec![down(Vec3::Y, side, side), up(Vec3::ZERO, side, side)],
        );
        let got = area_factor(ctx, &s, side / 32.0, options)?;
        checks.push(Check::new(
            format!("parallel squares X = Y = {side}"),
            mode,
            expected,
            got,
            0.02,
        ));
    }
    // A wall in x = 0 facing +x and a floor in y = 0 facing +y, sharing the edge along z.
    let perpendicular = scene(
        "perpendicular",
        vec![
            rect(Vec3::new(0.0, 0.5, 0.5), y * 0.5, z * 0.5, 0.0, 1.0),
            rect(Vec3::new(0.5, 0.0, 0.5), z * 0.5, x * 0.5, 1.0, 0.0),
        ],
    );
    checks.push(Check::new(
        "perpendicular unit squares, shared edge",
        mode,
        0.20004,
        area_factor(ctx, &perpendicular, ps, options)?,
        0.02,
    ));
    for (r, expected) in [(1.0, 0.38197), (0.5, 0.17157)] {
        let s = scene(
            "disks",
            vec![
                disk(Vec3::Y, x, z, r, 0.0, 1.0),
                disk(Vec3::ZERO, z, x, r, 1.0, 0.0),
            ],
        );
        let got = area_factor(ctx, &s, r / 16.0, options)?;
        checks.push(Check::new(
            format!("coaxial disks r = {r}, h = 1"),
            mode,
            expected,
            got,
            0.02,
        ));
    }
    Ok(checks)
}

/// Solve to an unshot fraction of 1e-4 and return the radiance atlas with the layout.
fn solve(
    ctx: &GlContext,
    scene: &Scene,
    patch_size: f32,
    options: &SolveOptions,
) -> Result<(Vec<f32>, PatchLayout, Vec<f64>)> {
    let layout = PatchLayout::new(scene, Resolution::PatchSize(patch_size));
    let options = SolveOptions {
        threshold: 1e-4,
        max_shots: 5000,
        ..options.clone()
    };
    let mut solver = GpuSolver::new(ctx, scene, &layout, options)?;
    solver.solve(|_| {})?;
    let areas = (0..scene.polygons.len())
        .map(|p| solver.patch_area(p))
        .collect();
    Ok((solver.radiosity_atlas(), layout, areas))
}

/// The furnace: a closed cube, ρ = 0.5 and Le = 1 on every face, has L = 2 everywhere.
pub fn furnace(ctx: &GlContext, mode: &'static str, options: &SolveOptions) -> Result<Check> {
    let s = scene("furnace", cube(0.5, [1.0; 6]));
    let (atlas, _, _) = solve(ctx, &s, 1.0 / 16.0, options)?;
    let values: Vec<f64> = atlas
        .chunks_exact(4)
        .filter(|t| t[3] > 0.0)
        .map(rgb_mean)
        .collect();
    let worst = values
        .iter()
        .copied()
        .max_by(|a, b| (a - 2.0).abs().total_cmp(&(b - 2.0).abs()))
        .unwrap_or(0.0);
    Ok(Check::new(
        "furnace: closed cube, L = 2 (worst patch)",
        mode,
        2.0,
        worst,
        0.01,
    ))
}

/// Uniform ρ = 0.5 with one emitter (the top of a closed cube): Σ A L = Σ A Le / (1 - ρ).
pub fn energy_balance(
    ctx: &GlContext,
    mode: &'static str,
    options: &SolveOptions,
) -> Result<Check> {
    let s = scene("balance", cube(0.5, [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]));
    let (atlas, _, areas) = solve(ctx, &s, 1.0 / 16.0, options)?;
    let total: f64 = atlas
        .chunks_exact(4)
        .filter(|t| t[3] > 0.0)
        .map(|t| rgb_mean(t) * areas[t[3] as usize - 1])
        .sum();
    Ok(Check::new(
        "closed cube, one emitter: sum A L = sum A Le / (1 - rho)",
        mode,
        2.0,
        total,
        0.01,
    ))
}

/// The progressive solution against a direct Jacobi solve of the same discretisation (every
/// patch its own shooter, exact polygon factors), patch by patch: the worst relative difference.
pub fn direct_solve(ctx: &GlContext) -> Result<Check> {
    // A closed cube (convex: every patch sees every other) lit by its top, with a different
    // reflectance on each face, so radiances differ from patch to patch and face to face.
    let mut faces = cube(0.5, [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
    for (face, kd) in faces.iter_mut().zip([0.8, 0.3, 0.7, 0.5, 0.6, 0.4]) {
        face.kd = kd;
    }
    let s = scene("direct", faces);
    let options = SolveOptions {
        shooter_cell: 1,
        emitter_cell: 1,
        threshold: 1e-5,
        max_shots: 5000,
        ..SolveOptions::accurate()
    };
    let layout = PatchLayout::new(&s, Resolution::PatchSize(1.0 / 6.0));
    let mut solver = GpuSolver::new(ctx, &s, &layout, options)?;
    solver.solve(|_| {})?;
    let atlas = solver.radiosity_atlas();
    let patches = direct::patches(&s, &layout);
    let cpu = direct::solve(&s, &patches);
    let (mut worst, mut at) = (0.0f64, (0.0, 0.0));
    for (p, l) in patches.iter().zip(&cpu) {
        let gpu = rgb_mean(&atlas[p.texel * 4..p.texel * 4 + 3]);
        let want = (l.x + l.y + l.z) as f64 / 3.0;
        let err = (gpu - want).abs() / want.max(1e-9);
        if err > worst {
            worst = err;
            at = (want, gpu);
        }
    }
    Ok(Check::with_error(
        format!(
            "progressive vs direct solve, {} patches (worst patch)",
            patches.len()
        ),
        "accurate",
        at.0,
        at.1,
        worst,
        0.01,
    ))
}

/// The Cornell box's mean radiance per wall at about 4096 patches and at half the patch size.
pub fn refinement(ctx: &GlContext) -> Result<Vec<Check>> {
    let scene = crate::scene::bundled::cornell().load()?;
    let walls = ["floor", "ceiling", "back_wall", "red_wall", "green_wall"];
    let coarse = PatchLayout::new(&scene, Resolution::Patches(4096)).patch_size;
    let mut means = Vec::new();
    for size in [coarse, coarse / 2.0] {
        let (atlas, _, areas) = solve_to(ctx, &scene, size, 0.01)?;
        let mean = |wall: &str| {
            let (mut sum, mut area) = (0.0, 0.0);
            for t in atlas.chunks_exact(4).filter(|t| t[3] > 0.0) {
                let p = t[3] as usize - 1;
                if scene.polygons[p].object == wall {
                    sum += rgb_mean(t) * areas[p];
                    area += areas[p];
                }
            }
            sum / area
        };
        means.push(walls.map(mean));
    }
    Ok(walls
        .iter()
        .enumerate()
        .map(|(i, wall)| {
            Check::new(
                format!("Cornell {wall}: mean L, patch size halved"),
                "accurate",
                means[0][i],
                means[1][i],
                0.01,
            )
        })
        .collect())
}

fn solve_to(
    ctx: &GlContext,
    scene: &Scene,
    patch_size: f32,
    threshold: f32,
) -> Result<(Vec<f32>, PatchLayout, Vec<f64>)> {
    let layout = PatchLayout::new(scene, Resolution::PatchSize(patch_size));
    let options = SolveOptions {
        threshold,
        ..SolveOptions::accurate()
    };
    let mut solver = GpuSolver::new(ctx, scene, &layout, options)?;
    solver.solve(|_| {})?;
    let areas = (0..scene.polygons.len())
        .map(|p| solver.patch_area(p))
        .collect();
    Ok((solver.radiosity_atlas(), layout, areas))
}
