//! Shooters beyond the paper: what carries a polygon's unshot energy in one shot. The paper
//! shoots the whole polygon from its centroid (`progressive::whole_polygon`); the accurate mode
//! shoots each cell of K×K patches of its lightmap from the cell's energy-weighted centre, with
//! the cell's outline (its rectangle clipped to the polygon) for the polygon form factor. The GPU
//! and the CPU solvers share this code.

use super::{Shooter, SolveOptions, MAX_CORNERS};
use crate::geometry::{bounds, clip_convex, rectangle, signed_area};
use crate::patches::{Lightmap, PatchLayout};
use crate::random::Rng;
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// Whether a shot carrying `share` of the emitted power cuts its cells where touching polygons'
/// planes cross them (`cell_parts`): always in the paper's accounting of cells, and beyond it
/// only for shots of at least `SolveOptions::cut_above`. A cut cell shoots from several points,
/// each a visibility pass; most shots carry little (four in five of the simple room's steps
/// under 0.1 % of the emitted power each), and a shot's error at a contact grows with its power.
pub fn cuts_cells(options: &SolveOptions, share: f64) -> bool {
    share.abs() >= options.cut_above as f64
}

/// How a shot of `share` of the emitted power (what it moves, [`shot_magnitude`]) divides its
/// polygon: the side of its cells, and the side down to which a cell that a touching polygon's
/// plane crosses is cut (`None`: not cut). The paper's accounting: cells of `cell` patches, every
/// one cut down to single patches. Beyond it, a shot below `cut_above` ([`cuts_cells`]) shoots from cells of `coarse_cell`
/// where that is wider: the late, small shots of large polygons in a fraction of the passes.
/// Those above [`UNCUT_BELOW`] × `cut_above` are cut down to the ordinary cell where a plane
/// crosses them (near contacts they shoot as the ordinary cells would); the smallest are not
/// cut, as a shot's error at a contact grows with its power.
pub fn cells_of_shot(options: &SolveOptions, cell: u32, share: f64) -> (u32, Option<u32>) {
    if cuts_cells(options, share) {
        (cell, Some(1))
    } else if cell != 0 && options.coarse_cell > cell {
        let cut = share.abs() >= UNCUT_BELOW * options.cut_above as f64;
        (options.coarse_cell, cut.then_some(cell))
    } else {
        (cell, None)
    }
}

/// The power a shot of polygon `p` moves, patch by patch: π·Σ |unshot − `remainder`| × patch
/// area over its patches that have received (RGB mean; without overshooting, `remainder` 0, its
/// unshot power). Beyond the paper, for [`cells_of_shot`]: a shot's error at a contact grows with
/// what it moves there, and with overshooting that is neither what the polygon holds (its
/// remainder too: a large polygon taking back a few percent of an outdated remainder holds much
/// and moves little) nor what the shot carries in sum (light arrived near a contact and the
/// remainder taken back elsewhere cancel in the sum, not at the contact).
pub fn shot_magnitude(
    layout: &PatchLayout,
    unshot: &[f32],
    p: usize,
    remainder: Vec3,
    patch_area: f64,
) -> f64 {
    let lm = &layout.lightmaps[p];
    let width = layout.atlas_width as usize;
    let mut sum = 0f64;
    for t in lm.y..lm.y + lm.h {
        let row = t as usize * width;
        for s in lm.x..lm.x + lm.w {
            let texel = &unshot[(row + s as usize) * 4..][..4];
            let v = Vec3::new(texel[0], texel[1], texel[2]);
            // A patch that has never received shoots nothing (`cell_parts`).
            if texel[3] as usize == p + 1 && v != Vec3::ZERO {
                sum += (v - remainder).abs().element_sum() as f64;
            }
        }
    }
    std::f64::consts::PI * sum * patch_area / 3.0
}

/// The fewest cells a polygon's shot may be held to, however large the scene: an area light is
/// still seen from 64 points.
pub const MIN_CELLS_PER_SHOT: u32 = 64;

/// The most cells one polygon's shot of `scene` is divided into before cutting
/// ([`widened_cell`]): `shot_triangles` (`SolveOptions::shot_triangles`; 0: no limit) over the
/// scene's triangles, at least [`MIN_CELLS_PER_SHOT`].
pub fn max_cells(scene: &Scene, shot_triangles: u64) -> u32 {
    if shot_triangles == 0 {
        return u32::MAX;
    }
    (shot_triangles / scene.triangle_count().max(1))
        .clamp(MIN_CELLS_PER_SHOT as u64, u32::MAX as u64) as u32
}

/// The most cells a shot carrying `share` of the emitted power is divided into before cutting:
/// the scene's `max_cells` ([`max_cells`]) for shots of at least `cut_above`, fewer for smaller
/// ones in proportion to what they carry, never fewer than [`MIN_CELLS_PER_SHOT`]. Beyond the
/// paper, as the cap is. Why: overshooting has a large polygon take back its remainder in many
/// small shots, and the conference room's ceiling light, shooting 0.01–0.05 % of the emitted
/// power from 126 to 286 cells and parts a time, took 271 of a 600 s run's seconds. A shot's
/// error from its cells' sampling grows with what it carries. A shot whose cells and cuts stay
/// within [`MIN_CELLS_PER_SHOT`] (such shots' coarse cells are 16 × 16 patches) shoots as before,
/// as does every shot of the Cornell box, the Table 1 rooms and Lost Empire (lightmaps the same
/// byte for byte); without a cap (`shot_triangles` 0) there is none.
pub fn shot_cap(max_cells: u32, share: f64, cut_above: f32) -> u32 {
    if max_cells == u32::MAX || cut_above <= 0.0 || share.abs() >= cut_above as f64 {
        return max_cells;
    }
    let scaled = (max_cells as f64 * share.abs() / cut_above as f64).ceil() as u32;
    scaled.clamp(MIN_CELLS_PER_SHOT.min(max_cells), max_cells)
}

/// The side of the cells of a polygon whose lightmap is `w` × `h` patches: `cell`, or wider
/// where that would give more than `max_cells` cells ([`max_cells`]). Beyond the paper, as cells
/// are. Why: each cell is a visibility pass of the whole scene, and the conference room's light,
/// its ceiling (225 × 143 patches, in a scene of 331,000 triangles), shot from single patches
/// took 32,000 passes of a quarter of a second each for its first shot, and gigabytes. The
/// polygon form factor stays exact for each cell's outline; only the points whose visibility
/// stands for the cell thin out (about 150 points across that ceiling). No shipped scene reaches its
/// cap (the test below), so their shots are unchanged.
pub fn widened_cell(w: u32, h: u32, cell: u32, max_cells: u32) -> u32 {
    let count = |c: u32| w.div_ceil(c) as u64 * h.div_ceil(c) as u64;
    let mut c = cell.max(1);
    while count(c) > max_cells.max(1) as u64 {
        c += 1;
    }
    c
}

/// The share of `cut_above` below which coarse cells are not cut at all ([`cells_of_shot`]).
pub const UNCUT_BELOW: f64 = 0.1;

/// The shooters that carry polygon `p`'s unshot energy beyond the paper (whose whole polygon
/// shoots from its centroid, `progressive::whole_polygon`): one shooter per cell of `cell`²
/// patches (`cell` at least 1), each at the mean position of its patches with the cell's own
/// unshot energy.
#[allow(clippy::too_many_arguments)]
pub fn shooters_of(
    scene: &Scene,
    layout: &PatchLayout,
    options: &SolveOptions,
    unshot: &[f32],
    patch_area: &[f64],
    p: usize,
    (cell, finest): (u32, Option<u32>),
    max_cells: u32,
) -> Vec<Shooter> {
    let polygon = &scene.polygons[p];
    let lm = &layout.lightmaps[p];
    let outline: Vec<Vec2> = polygon.vertices.iter().map(|&v| lm.texel_of(v)).collect();
    let own = cell;
    let cell = widened_cell(lm.w, lm.h, cell, max_cells);
    let width = layout.atlas_width as usize;
    let patch_area = patch_area[p];
    let texel = |s: u32, t: u32| -> Option<[f32; 3]> {
        let at = ((lm.y + t) as usize * width + (lm.x + s) as usize) * 4;
        let texel = &unshot[at..at + 4];
        (texel[3] as usize == p + 1).then(|| [texel[0], texel[1], texel[2]])
    };
    let mut cells = Vec::new();
    for y0 in (0..lm.h).step_by(cell as usize) {
        for x0 in (0..lm.w).step_by(cell as usize) {
            cells.push([x0, y0, (x0 + cell).min(lm.w), (y0 + cell).min(lm.h)]);
        }
    }
    let mut shooters = Vec::new();
    for part in cell_parts(scene, p, lm, cells, &texel, finest, max_cells) {
        let [x0, y0, x1, y1] = part.rect;
        let Some((mut position, energy)) = part_energy(lm, &part, &texel, patch_area) else {
            continue;
        };
        if cell != own {
            position = stratified_point(lm, &part, &texel, [p as u32, x0, y0]);
        }
        // The rectangle clipped to the polygon; the rectangle itself where the polygon is
        // not convex or the clip has too many corners.
        let rect = rectangle(
            Vec2::new(x0 as f32, y0 as f32),
            Vec2::new(x1 as f32, y1 as f32),
        );
        let clipped = clip_convex(&rect, &outline)
            .filter(|c| c.len() >= 3 && c.len() <= MAX_CORNERS && signed_area(c) > 0.0);
        let (corners, corner_count, area) = lm.world_outline(clipped.as_deref().unwrap_or(&rect));
        shooters.push(Shooter {
            polygon: p,
            texels: [lm.x + x0, lm.y + y0, lm.x + x1, lm.y + y1],
            position,
            normal: polygon.normal,
            energy,
            corners,
            corner_count,
            area,
            patches: part.patches.len() as u32,
            remainder: Vec3::ZERO,
            hemi_res: options.hemi_res,
            turn: 0.0,
            parts: Default::default(),
        });
    }
    // The order of the parts does not change the result but keeps it easy to follow (row by row).
    shooters.sort_by_key(|s| (s.texels[1], s.texels[0]));
    shooters
}

/// Some of a cell's patches and the rectangle of the cell (or of a quarter of it) they lie in,
/// whose texels their shot clears.
struct Part {
    patches: Vec<(u32, u32)>,
    rect: [u32; 4],
}

/// The parts of the cells `cells` of polygon `p` that shoot on their own.
///
/// A cell shoots from one point, so everything it sends passes the visibility test of that
/// point. Where the plane of a nearby polygon cuts through the cell (a block standing on the
/// floor), the receivers on that polygon see only the part of the cell in front of them, yet the
/// point may lie behind them (no light at all: the Cornell box's short block front stayed black)
/// or in front (light through the block's edge): such a cell is cut into quarters, down to parts
/// of side `finest` (single patches in the paper's accounting; `None`: not cut), until no such
/// plane crosses a part (see [`cells_of_shot`]). Only polygons of at least a quarter of the part's
/// area count (`crossed`): a book beside a wall's cell sees little of it either way, and cutting
/// for every small face made the simple room's walls shoot from a hundred parts each.
///
/// The cuts are made level by level (every crossed cell into quarters, then every crossed
/// quarter, …), and only while the parts stay within `max_cells` more than the cells (in a
/// level that does not fit whole, the crossed rectangles that carry the most go first)
/// ([`max_cells`]; beyond the paper, as the cap is): each part is a visibility pass of the whole
/// scene, and the conference room's first shots, their cells held to 151, were cut into 1,065 to
/// 3,174 parts (issue 58: 4 shots in 300 s; held, 461). Where the cuts stay within that, as in
/// every shipped scene (whose caps are 1,000 cells or more), every crossed part is cut as
/// before, and the shooters are the same.
///
/// Patches of both signs (left by overshooting) shoot apart, so that neither cancels the other;
/// patches with nothing to shoot go with the positive ones (the part's texels are cleared
/// together, to their remainder when overshooting, so every patch must belong to a part). A part
/// with nothing to shoot (buried under a block) is left as it is.
fn cell_parts(
    scene: &Scene,
    p: usize,
    lm: &Lightmap,
    cells: Vec<[u32; 4]>,
    texel: &impl Fn(u32, u32) -> Option<[f32; 3]>,
    finest: Option<u32>,
    max_cells: u32,
) -> Vec<Part> {
    let budget = (cells.len() as u64).saturating_add(max_cells as u64);
    let mut parts = Vec::new();
    let mut level = cells;
    while !level.is_empty() {
        // The rectangles of this level that shoot something, with their patches by sign.
        let mut live = Vec::new();
        for rect in level {
            let [x0, y0, x1, y1] = rect;
            let (mut positive, mut negative, mut lit) = (Vec::new(), Vec::new(), false);
            let mut weight = 0f32;
            for t in y0..y1 {
                for s in x0..x1 {
                    match texel(s, t).map(|v| v[0] + v[1] + v[2]) {
                        Some(sum) if sum < 0.0 => {
                            weight -= sum;
                            negative.push((s, t));
                        }
                        Some(sum) => {
                            lit |= sum > 0.0;
                            weight += sum;
                            positive.push((s, t));
                        }
                        None => {}
                    }
                }
            }
            if lit || !negative.is_empty() {
                let cuttable = finest.is_some_and(|side| x1 - x0 > side || y1 - y0 > side);
                let cut = cuttable && crossed(scene, p, lm, rect);
                live.push((rect, positive, negative, cut, weight));
            }
        }
        // The crossed rectangles of this level whose quarters fit the budget are cut, those
        // that carry the most first (each cut adds at most three parts).
        let room = budget.saturating_sub(parts.len() as u64 + live.len() as u64) / 3;
        let mut crossings: Vec<usize> = (0..live.len()).filter(|&i| live[i].3).collect();
        if crossings.len() as u64 > room {
            crossings.sort_by(|&i, &j| live[j].4.total_cmp(&live[i].4).then(i.cmp(&j)));
            for &i in &crossings[room as usize..] {
                live[i].3 = false;
            }
        }
        let mut next = Vec::new();
        for (rect, positive, negative, cut, _) in live {
            if cut {
                let [x0, y0, x1, y1] = rect;
                let (xm, ym) = ((x0 + x1).div_ceil(2), (y0 + y1).div_ceil(2));
                for [a, b, c, d] in [
                    [x0, y0, xm, ym],
                    [xm, y0, x1, ym],
                    [x0, ym, xm, y1],
                    [xm, ym, x1, y1],
                ] {
                    if a < c && b < d {
                        next.push([a, b, c, d]);
                    }
                }
                continue;
            }
            for patches in [positive, negative] {
                if !patches.is_empty() {
                    parts.push(Part { patches, rect });
                }
            }
        }
        level = next;
    }
    parts
}

/// What one part shoots: its energy-weighted centre and its energy (Σ L·A, RGB). A part whose
/// patches have nothing to shoot (beside a part of the other sign) shoots from their middle: its
/// texels are cleared all the same, to their remainder when overshooting.
fn part_energy(
    lm: &Lightmap,
    part: &Part,
    texel: &impl Fn(u32, u32) -> Option<[f32; 3]>,
    patch_area: f64,
) -> Option<(Vec3, Vec3)> {
    if part.patches.is_empty() {
        return None;
    }
    let (mut energy, mut position, mut weight) = ([0f64; 3], Vec3::ZERO, 0f32);
    for &(s, t) in &part.patches {
        let Some(v) = texel(s, t) else { continue };
        for c in 0..3 {
            energy[c] += v[c] as f64 * patch_area;
        }
        // By magnitude: overshooting leaves negative unshot energy to shoot as well.
        let w = (v[0] + v[1] + v[2]).abs();
        position += w * lm.world(s as f32 + 0.5, t as f32 + 0.5);
        weight += w;
    }
    if weight <= 0.0 {
        for &(s, t) in &part.patches {
            position += lm.world(s as f32 + 0.5, t as f32 + 0.5);
        }
        weight = part.patches.len() as f32;
    }
    Some((
        position / weight,
        Vec3::new(energy[0] as f32, energy[1] as f32, energy[2] as f32),
    ))
}

/// Where a widened cell ([`widened_cell`]) sees from: the centre of one of its patches, drawn
/// with probability proportional to its unshot energy by a number seeded with the polygon and
/// the cell (`key`: polygon, first column, first row), instead of the energy-weighted centre. Why: with centres, the cells of a row
/// stand in a straight line, so an occluder's edge parallel to it hides or shows the whole row
/// at once, and the few rows of a widened polygon band the penumbra; points drawn per cell break
/// the rows up (stratified sampling), and each one lies on the polygon. The shadow scene's light
/// held to 64 cells against its 225 (`tests/shot_cells.rs`): the floor's mean 1.7 % darker with
/// centres, 0.7 % brighter with drawn points; floor patches off by more than 5 % of the
/// brightest 910 and 493 of 3,481.
fn stratified_point(
    lm: &Lightmap,
    part: &Part,
    texel: &impl Fn(u32, u32) -> Option<[f32; 3]>,
    key: [u32; 3],
) -> Vec3 {
    let weight = |&(s, t): &(u32, u32)| texel(s, t).map_or(0.0, |v| (v[0] + v[1] + v[2]).abs());
    let total: f32 = part.patches.iter().map(weight).sum();
    let [p, x0, y0] = key.map(u64::from);
    let mut left = Rng::new(p << 40 ^ x0 << 20 ^ y0).uniform() * total;
    let mut chosen = part.patches[part.patches.len() / 2];
    for patch in &part.patches {
        let w = weight(patch);
        if w > 0.0 {
            chosen = *patch;
            if left < w {
                break;
            }
            left -= w;
        }
    }
    lm.world(chosen.0 as f32 + 0.5, chosen.1 as f32 + 0.5)
}

/// Does the plane of another polygon touching the lightmap rectangle `[x0, y0, x1, y1)` of
/// polygon `p` cut through it? "Touching": the other polygon's bounding box comes within a tenth
/// of the rectangle's diagonal of the rectangle's (a table top a metre from a wall crosses the
/// wall's plane, but none of its receivers sees the wall from behind); only polygons of at least
/// a quarter of the rectangle's area count (see `cell_parts`).
fn crossed(scene: &Scene, p: usize, lm: &Lightmap, [x0, y0, x1, y1]: [u32; 4]) -> bool {
    let corners = [
        lm.world(x0 as f32, y0 as f32),
        lm.world(x1 as f32, y0 as f32),
        lm.world(x1 as f32, y1 as f32),
        lm.world(x0 as f32, y1 as f32),
    ];
    let (cell_lo, cell_hi) = bounds(&corners).expect("four corners");
    let reach = (corners[2] - corners[0]).length();
    let area = (corners[1] - corners[0]).length() * (corners[3] - corners[0]).length();
    // Planes that merely touch the cell (a wall meeting the floor along its edge) do not count.
    let slack = 1e-3 * reach;
    let normal = scene.polygons[p].normal;
    scene.polygons.iter().enumerate().any(|(q, other)| {
        if q == p || other.normal.dot(normal).abs() > 0.999 || other.area < 0.25 * area {
            return false;
        }
        let Some((lo, hi)) = bounds(&other.vertices) else {
            return false;
        };
        if aabb_gap((cell_lo, cell_hi), (lo, hi)) > 0.1 * reach {
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

/// The gap between two axis-aligned boxes (0 where they overlap).
fn aabb_gap((a_lo, a_hi): (Vec3, Vec3), (b_lo, b_hi): (Vec3, Vec3)) -> f32 {
    (b_lo - a_hi).max(a_lo - b_hi).max(Vec3::ZERO).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_shots_are_held_to_fewer_cells_in_proportion_never_below_the_floor() {
        // The conference room's cap, 151 cells; cut_above 0.3 %.
        assert_eq!(shot_cap(151, 0.5, 0.003), 151);
        assert_eq!(shot_cap(151, 0.003, 0.003), 151);
        assert_eq!(shot_cap(151, -0.0015, 0.003), 76);
        assert_eq!(shot_cap(151, 0.0002, 0.003), MIN_CELLS_PER_SHOT);
        // No cap, or no cut_above: as before.
        assert_eq!(shot_cap(u32::MAX, 1e-9, 0.003), u32::MAX);
        assert_eq!(shot_cap(151, 1e-9, 0.0), 151);
        // A scene's cap below the floor (none: max_cells is at least the floor) stays.
        assert_eq!(shot_cap(10, 1e-9, 0.003), 10);
    }

    #[test]
    fn cells_widen_only_past_the_cap() {
        assert_eq!(widened_cell(16, 16, 1, 256), 1); // 256 cells: at the cap
        assert_eq!(widened_cell(17, 16, 1, 256), 2); // 272 → 9 × 8 = 72
        assert_eq!(widened_cell(64, 64, 4, 256), 4);
        assert_eq!(widened_cell(256, 1, 1, 256), 1);
        assert_eq!(widened_cell(257, 1, 1, 256), 2);
        // The conference room's ceiling from single patches, 32,175 cells, held to 151.
        let c = widened_cell(225, 143, 1, 151);
        assert_eq!((c, 225u32.div_ceil(c) * 143u32.div_ceil(c)), (15, 150));
        assert!(225u32.div_ceil(c - 1) * 143u32.div_ceil(c - 1) > 151);
    }
}
