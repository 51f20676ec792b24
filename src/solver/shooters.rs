//! Shooters: what carries a polygon's unshot energy in one shot. The paper shoots the whole
//! polygon from its centroid; the accurate mode shoots each cell of K×K patches of its lightmap
//! from the cell's energy-weighted centre, with the cell's outline (its rectangle clipped to the
//! polygon) for the polygon form factor. The GPU and the CPU solvers share this code.

use super::find_max_energy::EnergyTotals;
use super::{Shooter, SolveOptions, MAX_CORNERS};
use crate::geometry::{bounds, clip_convex, mean, rectangle, signed_area};
use crate::patches::{Lightmap, PatchLayout};
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// Lightmap-space outline → world corners (padded to MAX_CORNERS), their count and world area.
fn world_outline(lm: &Lightmap, outline: &[Vec2]) -> ([Vec3; MAX_CORNERS], usize, f32) {
    let mut corners = [Vec3::ZERO; MAX_CORNERS];
    for (c, p) in corners.iter_mut().zip(outline) {
        *c = lm.world(p.x, p.y);
    }
    (
        corners,
        outline.len().min(MAX_CORNERS),
        signed_area(outline).abs() * lm.texel_area(),
    )
}

/// The shooters that carry polygon `p`'s unshot energy: the whole polygon from its centroid
/// (the paper), or one shooter per cell of `shooter_cell`² patches, each at the mean position
/// of its patches with the cell's own unshot energy.
pub fn shooters_of(
    scene: &Scene,
    layout: &PatchLayout,
    options: &SolveOptions,
    unshot: &[f32],
    patch_area: &[f64],
    totals: &EnergyTotals,
    p: usize,
) -> Vec<Shooter> {
    let polygon = &scene.polygons[p];
    let lm = &layout.lightmaps[p];
    let cell = if scene.material(polygon).is_emitter() {
        options.emitter_cell
    } else {
        options.shooter_cell
    };
    let outline: Vec<Vec2> = polygon.vertices.iter().map(|&v| lm.texel_of(v)).collect();
    if cell == 0 {
        let rect = rectangle(Vec2::ZERO, Vec2::new(lm.w as f32, lm.h as f32));
        let corners = if outline.len() <= MAX_CORNERS {
            &outline[..]
        } else {
            &rect[..]
        };
        let (corners, corner_count, area) = world_outline(lm, corners);
        return vec![Shooter {
            polygon: p,
            texels: lm.texels(),
            position: polygon.centroid,
            normal: polygon.normal,
            energy: totals.energy_rgb(p),
            corners,
            corner_count,
            area,
            remainder: Vec3::ZERO,
            hemi_res: options.hemi_res,
            turn: 0.0,
        }];
    }
    let width = layout.atlas_width as usize;
    let patch_area = patch_area[p];
    let texel = |s: u32, t: u32| -> Option<&[f32]> {
        let at = ((lm.y + t) as usize * width + (lm.x + s) as usize) * 4;
        let texel = &unshot[at..at + 4];
        (texel[3] as usize == p + 1).then_some(texel)
    };
    // One shooter for the patches of [x0, x1) × [y0, y1) with energy: at their energy-weighted
    // centre, with the rectangle clipped to the polygon as its outline.
    let shooter = |x0: u32, y0: u32, x1: u32, y1: u32| -> Option<Shooter> {
        let (mut energy, mut position, mut weight) = ([0f64; 3], Vec3::ZERO, 0f32);
        for t in y0..y1 {
            for s in x0..x1 {
                let Some(texel) = texel(s, t) else { continue };
                for c in 0..3 {
                    energy[c] += texel[c] as f64 * patch_area;
                }
                // By magnitude: overshooting leaves negative unshot energy to shoot as well.
                let w = (texel[0] + texel[1] + texel[2]).abs();
                position += w * lm.world(s as f32 + 0.5, t as f32 + 0.5);
                weight += w;
            }
        }
        if weight <= 0.0 {
            return None;
        }
        // The rectangle itself where the polygon is not convex or the clip has too many corners.
        let rect = rectangle(
            Vec2::new(x0 as f32, y0 as f32),
            Vec2::new(x1 as f32, y1 as f32),
        );
        let clipped = clip_convex(&rect, &outline)
            .filter(|c| c.len() >= 3 && c.len() <= MAX_CORNERS && signed_area(c) > 0.0);
        let (corners, corner_count, area) = world_outline(lm, clipped.as_deref().unwrap_or(&rect));
        Some(Shooter {
            polygon: p,
            texels: [lm.x + x0, lm.y + y0, lm.x + x1, lm.y + y1],
            position: position / weight,
            normal: polygon.normal,
            energy: Vec3::new(energy[0] as f32, energy[1] as f32, energy[2] as f32),
            corners,
            corner_count,
            area,
            remainder: Vec3::ZERO,
            hemi_res: options.hemi_res,
            turn: 0.0,
        })
    };
    // A cell shoots from one point, so everything it sends passes the visibility test of that
    // point. Where another polygon's plane cuts through the cell near that polygon (a block
    // standing on the floor), the receivers on that polygon see only the part of the cell in
    // front of them, yet the point may lie behind them (no light at all) or in front (light
    // through the block's edge): such a cell is cut into quarters, down to single patches,
    // until no nearby plane crosses a part.
    let mut shooters = Vec::new();
    let mut parts: Vec<[u32; 4]> = Vec::new();
    for y0 in (0..lm.h).step_by(cell as usize) {
        for x0 in (0..lm.w).step_by(cell as usize) {
            parts.push([x0, y0, (x0 + cell).min(lm.w), (y0 + cell).min(lm.h)]);
        }
    }
    while let Some([x0, y0, x1, y1]) = parts.pop() {
        // A cell whose patches partly have nothing to shoot (buried under a block standing on
        // the floor, or in a shadow nothing has reached yet) would spread its energy over its
        // whole outline, dark part included: its patches with energy shoot one by one. So do
        // those of a cell whose patches have energy of both signs (left by overshooting).
        let (mut lit, mut negative, mut dark) = (0, 0, 0);
        for t in y0..y1 {
            for s in x0..x1 {
                match texel(s, t).map(|v| v[0] + v[1] + v[2]) {
                    Some(sum) if sum > 0.0 => lit += 1,
                    Some(sum) if sum < 0.0 => negative += 1,
                    Some(_) => dark += 1,
                    None => {}
                }
            }
        }
        if lit + negative == 0 {
            continue;
        }
        let single = x1 - x0 == 1 && y1 - y0 == 1;
        if (dark > 0 || (lit > 0 && negative > 0)) && !single {
            for t in y0..y1 {
                for s in x0..x1 {
                    parts.push([s, t, s + 1, t + 1]);
                }
            }
        } else if !single && crossed_nearby(scene, p, lm, [x0, y0, x1, y1]) {
            let (xm, ym) = ((x0 + x1).div_ceil(2), (y0 + y1).div_ceil(2));
            for [a, b, c, d] in [
                [x0, y0, xm, ym],
                [xm, y0, x1, ym],
                [x0, ym, xm, y1],
                [xm, ym, x1, y1],
            ] {
                if a < c && b < d {
                    parts.push([a, b, c, d]);
                }
            }
        } else {
            shooters.extend(shooter(x0, y0, x1, y1));
        }
    }
    // The order of the parts does not change the result but keeps it easy to follow (row by row).
    shooters.sort_by_key(|s| (s.texels[1], s.texels[0]));
    shooters
}

/// Does the plane of another polygon near the lightmap rectangle `[x0, y0, x1, y1)` of polygon
/// `p` cut through it? "Near": the other polygon's bounding box comes within the rectangle's
/// diagonal of the rectangle's centre.
fn crossed_nearby(scene: &Scene, p: usize, lm: &Lightmap, [x0, y0, x1, y1]: [u32; 4]) -> bool {
    let corners = [
        lm.world(x0 as f32, y0 as f32),
        lm.world(x1 as f32, y0 as f32),
        lm.world(x1 as f32, y1 as f32),
        lm.world(x0 as f32, y1 as f32),
    ];
    let centre = mean(&corners);
    let reach = (corners[2] - corners[0]).length();
    // Planes that merely touch the cell (a wall meeting the floor along its edge) do not count.
    let slack = 1e-3 * reach;
    let normal = scene.polygons[p].normal;
    scene.polygons.iter().enumerate().any(|(q, other)| {
        if q == p || other.normal.dot(normal).abs() > 0.999 {
            return false;
        }
        let Some((lo, hi)) = bounds(&other.vertices) else {
            return false;
        };
        if centre.clamp(lo, hi).distance(centre) > reach {
            return false;
        }
        let anchor = other.vertices[0];
        let (mut below, mut above) = (false, false);
        for c in corners {
            let d = (c - anchor).dot(other.normal);
            below |= d < -slack;
            above |= d > slack;
        }
        below && above
    })
}
