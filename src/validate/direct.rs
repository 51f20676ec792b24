//! A direct solve of the same discretisation on the CPU: the full patch-to-patch form-factor
//! matrix (each patch's centre to each other patch's outline, the exact polygon factor), then
//! Jacobi iteration of L = Le + ρ F L. For convex scenes only (no visibility term).

use crate::geometry::{clip_convex, rectangle, signed_area};
use crate::patches::PatchLayout;
use crate::scene::Scene;
use crate::solver::form_factor;
use glam::{Vec2, Vec3};

pub struct Patch {
    pub polygon: usize,
    /// Atlas texel index.
    pub texel: usize,
    pub centre: Vec3,
    pub outline: Vec<Vec3>,
}

/// Every patch with its centre and outline (its texel's square clipped to the polygon).
pub fn patches(scene: &Scene, layout: &PatchLayout) -> Vec<Patch> {
    let mut out = Vec::new();
    for (i, polygon) in scene.polygons.iter().enumerate() {
        let lm = &layout.lightmaps[i];
        let shape: Vec<Vec2> = polygon.vertices.iter().map(|&v| lm.texel_of(v)).collect();
        for t in 0..lm.h {
            for s in 0..lm.w {
                let texel = (lm.y + t) as usize * layout.atlas_width as usize + (lm.x + s) as usize;
                if layout.owner[texel] != i as u32 + 1 {
                    continue;
                }
                let (x0, y0) = (s as f32, t as f32);
                let square = rectangle(Vec2::new(x0, y0), Vec2::new(x0 + 1.0, y0 + 1.0));
                let clipped = clip_convex(&square, &shape)
                    .filter(|c| c.len() >= 3 && signed_area(c) > 0.0)
                    .unwrap_or(square.to_vec());
                out.push(Patch {
                    polygon: i,
                    texel,
                    centre: lm.world(x0 + 0.5, y0 + 0.5),
                    outline: clipped.iter().map(|p| lm.world(p.x, p.y)).collect(),
                });
            }
        }
    }
    out
}

/// Radiance per patch (RGB) after Jacobi iteration to a relative change below 1e-7.
pub fn solve(scene: &Scene, patches: &[Patch]) -> Vec<Vec3> {
    let n = patches.len();
    let normal = |p: &Patch| scene.polygons[p.polygon].normal;
    let f: Vec<f32> = (0..n * n)
        .map(|k| {
            let (i, j) = (k / n, k % n);
            if patches[i].polygon == patches[j].polygon {
                return 0.0;
            }
            form_factor::polygon(
                patches[i].centre,
                normal(&patches[i]),
                &patches[j].outline,
                normal(&patches[j]),
                scene.plane_slack(),
            )
        })
        .collect();
    let emission: Vec<Vec3> = patches
        .iter()
        .map(|p| scene.material(&scene.polygons[p.polygon]).ke)
        .collect();
    let rho: Vec<Vec3> = patches
        .iter()
        .map(|p| scene.material(&scene.polygons[p.polygon]).kd)
        .collect();
    let mut l = emission.clone();
    for _ in 0..1000 {
        let next: Vec<Vec3> = (0..n)
            .map(|i| emission[i] + rho[i] * (0..n).map(|j| f[i * n + j] * l[j]).sum::<Vec3>())
            .collect();
        let change = next
            .iter()
            .zip(&l)
            .map(|(a, b)| ((*a - *b).abs() / a.abs().max(Vec3::splat(1e-9))).max_element())
            .fold(0.0, f32::max);
        l = next;
        if change < 1e-7 {
            break;
        }
    }
    l
}
