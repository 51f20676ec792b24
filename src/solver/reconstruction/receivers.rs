//! Which polygons can receive from a shooter (by where they lie, `Tuning::receivers_only`, or by
//! what the walk's item buffers let each shooter reach, `Tuning::walk_receivers`), and which 4×4
//! blocks of the atlas a pass must therefore draw (those that hold the receivers' patches, not the
//! whole of their lightmap rectangles), with which shader: the CPU half of the reconstruction
//! pass, run before each draw.

use super::cover::BLOCK;
use crate::geometry::sphere_around;
use crate::patches::PatchLayout;
use crate::scene::Scene;
use crate::solver::engine::seen_receivers::Reach;
use crate::solver::{Shooter, Tuning};
use glam::Vec3;

/// Block flags: a polygon that receives with clipping, one that has the whole shooter above it,
/// one that receives nothing; texels that shoot.
const CLIPPED: u8 = 1;
const SHOOTER_ABOVE: u8 = 2;
const NOT_RECEIVING: u8 = 4;
const SHOOTER: u8 = 8;

/// What a receiver gets from a shooter (see `Receivers::reception`).
enum Reception {
    Nothing,
    /// The whole shooter lies above the receiver's plane: no clipping needed.
    ShooterAbove,
    Clipped,
}

/// The polygons' shapes as the receiver test needs them, and the block flags of the last pass.
pub(super) struct Receivers {
    /// Each polygon's vertices (`outlines[starts[i]..starts[i + 1]]`) and normal.
    outlines: Vec<Vec3>,
    starts: Vec<usize>,
    normals: Vec<Vec3>,
    /// Each polygon's bounding sphere (centre, radius).
    bounds: Vec<(Vec3, f32)>,
    /// World units a point must lie beyond a plane to count as behind it (`Scene::plane_slack`).
    slack: f32,
    /// The polygons that have patches (the others have no lightmap texels to draw).
    with_patches: Vec<usize>,
    /// Lightmap rectangles [x0, y0, x1, y1), per polygon.
    texels: Vec<[u32; 4]>,
    /// The blocks that hold patches of polygon p: `blocks[block_starts[p]..block_starts[p + 1]]`
    /// (ascending). A merged polygon's rectangle holds many texels outside its outline, whole
    /// blocks of them on a voxel world's concave walls (Lost Empire: 10,363 blocks in the
    /// rectangles, 9,047 with patches); those are not drawn.
    blocks: Vec<u32>,
    block_starts: Vec<usize>,
    /// Per 4×4 block of the atlas, row by row, which kinds of polygon have texels in it this
    /// pass (`CLIPPED`, `SHOOTER_ABOVE`, `NOT_RECEIVING`, `SHOOTER`).
    flags: Vec<u8>,
    blocks_wide: usize,
    /// Per 4×4 block of the atlas (as `flags`), bit k: shooter k of the pass may send it
    /// something or shoots from it (`Tuning::walk_receivers`; all zero otherwise).
    shooter_bits: Vec<u8>,
    bits_known: bool,
    /// Per polygon, the `stamp` of the last pass whose item buffers let it receive
    /// (`Tuning::walk_receivers`).
    seen: Vec<u32>,
    stamp: u32,
}

impl Receivers {
    pub(super) fn new(scene: &Scene, layout: &PatchLayout) -> Self {
        let texels = layout.texel_rects();
        let with_patches: Vec<usize> = (0..texels.len())
            .filter(|&p| layout.patches_per_polygon[p] > 0)
            .collect();
        let blocks_wide = layout.atlas_width.div_ceil(BLOCK) as usize;
        let blocks = blocks_wide * layout.atlas_height.div_ceil(BLOCK) as usize;
        let (blocks_of, block_starts) = patch_blocks(layout, blocks_wide);
        let mut starts = vec![0];
        let mut outlines = Vec::new();
        for p in &scene.polygons {
            outlines.extend_from_slice(&p.vertices);
            starts.push(outlines.len());
        }
        Receivers {
            outlines,
            starts,
            normals: scene.polygons.iter().map(|p| p.normal).collect(),
            bounds: scene.polygons.iter().map(|p| p.bounding_sphere()).collect(),
            slack: scene.plane_slack(),
            with_patches,
            texels,
            blocks: blocks_of,
            block_starts,
            flags: vec![0; blocks],
            shooter_bits: vec![0; blocks],
            bits_known: false,
            blocks_wide,
            seen: vec![0; scene.polygons.len()],
            stamp: 0,
        }
    }

    /// Each polygon's lightmap rectangle [x0, y0, x1, y1) in the atlas.
    pub(super) fn texels(&self) -> &[[u32; 4]] {
        &self.texels
    }

    /// The block flags of the last `select` (rows of `blocks_wide()` blocks).
    pub(super) fn flags(&self) -> &[u8] {
        &self.flags
    }

    /// Which shooters of the last `select` may send each block something or shoot from it
    /// (bit k: shooter k), if it was given their reach (`Tuning::walk_receivers`).
    pub(super) fn shooter_bits(&self) -> Option<&[u8]> {
        self.bits_known.then_some(&self.shooter_bits[..])
    }

    pub(super) fn blocks_wide(&self) -> usize {
        self.blocks_wide
    }

    /// Flag the blocks a pass for `shooters` must draw: the shooting texels, and the blocks
    /// that can receive from any of them: those `seen` lists for some shooter when given
    /// (`Tuning::walk_receivers`), else the lightmaps of every polygon with patches (only those
    /// in front with `tuning.receivers_only`). A polygon has the shooters above it only if it
    /// has every one of them above it (a shooter's own polygon, which it sends nothing, aside).
    /// `touched` gets the receivers and the shooters.
    pub(super) fn select(
        &mut self,
        shooters: &[Shooter],
        tuning: &Tuning,
        seen: Option<&[&Reach]>,
        touched: &mut Vec<usize>,
    ) {
        touched.clear();
        self.flags.fill(0);
        self.bits_known = seen.is_some() && shooters.len() <= 8;
        if self.bits_known {
            self.shooter_bits.fill(0);
        }
        match seen {
            Some(reaches) => self.select_seen(reaches, touched),
            None => self.select_in_front(shooters, tuning, touched),
        }
        let bw = self.blocks_wide;
        let mark = |flags: &mut [u8], [x0, y0, x1, y1]: [u32; 4], flag: u8| {
            for by in y0 / BLOCK..y1.div_ceil(BLOCK) {
                let row = by as usize * bw;
                let blocks = row + (x0 / BLOCK) as usize..row + x1.div_ceil(BLOCK) as usize;
                for f in &mut flags[blocks] {
                    *f |= flag;
                }
            }
        };
        // The shooting texels are drawn to clear their unshot energy.
        for (k, s) in shooters.iter().enumerate() {
            mark(&mut self.flags, s.texels, SHOOTER);
            if self.bits_known {
                mark(&mut self.shooter_bits, s.texels, 1 << k);
            }
            if !touched.contains(&s.polygon) {
                touched.push(s.polygon);
            }
        }
    }

    /// `select`'s receivers from the blocks and polygons each shooter's item buffer lets
    /// receive (`Tuning::walk_receivers`).
    fn select_seen(&mut self, reaches: &[&Reach], touched: &mut Vec<usize>) {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.fill(0);
            self.stamp = 1;
        }
        for (k, reach) in reaches.iter().enumerate() {
            for &b in &reach.blocks {
                self.flags[b as usize] |= CLIPPED;
                if self.bits_known {
                    self.shooter_bits[b as usize] |= 1 << k;
                }
            }
            for &p in &reach.polygons {
                if self.seen[p as usize] != self.stamp {
                    self.seen[p as usize] = self.stamp;
                    touched.push(p as usize);
                }
            }
        }
    }

    /// `select`'s receivers by where they lie: every polygon with patches, or (with
    /// `tuning.receivers_only`) those some shooter is in front of and in front of some shooter.
    fn select_in_front(&mut self, shooters: &[Shooter], tuning: &Tuning, touched: &mut Vec<usize>) {
        let reaches: Vec<(Vec3, f32)> = shooters
            .iter()
            .map(|s| sphere_around(s.position, &s.corners[..s.corner_count.max(1)]))
            .collect();
        for &p in &self.with_patches {
            let flag = if !tuning.receivers_only {
                CLIPPED
            } else {
                // Each shooter's reception, its own polygon left out (only its shooting texels
                // are drawn for it): above only if above every other shooter.
                let mut flag = 0;
                for (s, &reach) in shooters.iter().zip(&reaches) {
                    if p == s.polygon {
                        continue;
                    }
                    flag |= match self.reception(p, s, reach) {
                        Reception::Nothing => NOT_RECEIVING,
                        Reception::ShooterAbove => SHOOTER_ABOVE,
                        Reception::Clipped => CLIPPED,
                    };
                }
                match flag {
                    0 | NOT_RECEIVING | SHOOTER_ABOVE => flag,
                    _ => CLIPPED,
                }
            };
            if flag != NOT_RECEIVING {
                touched.push(p);
            }
            if flag != 0 {
                for &b in &self.blocks[self.block_starts[p]..self.block_starts[p + 1]] {
                    self.flags[b as usize] |= flag;
                }
            }
        }
    }

    /// Which flagged blocks to draw with the shader that clips the shooter to the receiver's
    /// plane, and which with the one that does not. Only blocks that hold receivers or shooting
    /// texels are drawn; without clipping (`Tuning::skip_needless_clipping`, after a marking
    /// pass) only where every other polygon in the block has the shooter above it (a polygon
    /// that receives nothing must get its exact zero from the clipped factor; the shooter's
    /// texels get zero from either).
    pub(super) fn shaders(tuning: &Tuning) -> (impl Fn(&u8) -> bool, impl Fn(&u8) -> bool) {
        let skip = tuning.skip_needless_clipping && tuning.marking_pass;
        let above = move |f: &u8| skip && *f & !SHOOTER == SHOOTER_ABOVE;
        let clipped = move |f: &u8| *f & (SHOOTER_ABOVE | CLIPPED | SHOOTER) != 0 && !above(f);
        (clipped, above)
    }

    /// Can polygon `p` receive anything from `shooter`, and is the whole shooter above `p`'s
    /// plane? Some of `p` must lie in front of the shooter and some of the shooter in front of
    /// `p` (with float slack: never wrongly no; and never wrongly "wholly above"). `reach` is the
    /// shooter's bounding sphere (centre, radius). Most polygons are decided by the two bounding
    /// spheres, with a margin of one slack over the float noise; the rest corner by corner.
    fn reception(&self, p: usize, shooter: &Shooter, reach: (Vec3, f32)) -> Reception {
        let slack = self.slack;
        let outline = &self.outlines[self.starts[p]..self.starts[p + 1]];
        let (centre, radius) = self.bounds[p];
        let base = shooter.corners[0];
        let ahead = shooter.normal.dot(centre - base);
        let in_front = if ahead - radius > 0.0 {
            true
        } else if ahead + radius < -2.0 * slack {
            false
        } else {
            outline
                .iter()
                .any(|&v| shooter.normal.dot(v - base) > -slack)
        };
        if !in_front {
            return Reception::Nothing;
        }
        let n = self.normals[p];
        let height = n.dot(reach.0 - outline[0]);
        let (lowest, highest) = if height - reach.1 > 2.0 * slack {
            (height - reach.1, height + reach.1)
        } else if height + reach.1 < -2.0 * slack {
            return Reception::Nothing;
        } else {
            let mut range = (f32::INFINITY, f32::NEG_INFINITY);
            for &c in shooter.corners[..shooter.corner_count.max(1)]
                .iter()
                .chain(std::iter::once(&shooter.position))
            {
                let h = n.dot(c - outline[0]);
                range = (range.0.min(h), range.1.max(h));
            }
            range
        };
        if highest <= -slack {
            Reception::Nothing
        } else if shooter.corner_count > 0 && lowest > slack {
            Reception::ShooterAbove
        } else {
            Reception::Clipped
        }
    }
}

/// Per polygon, the blocks (indices in rows of `wide`) that hold its patches, ascending, one
/// list after another, and where each polygon's list starts (one more entry than polygons).
fn patch_blocks(layout: &PatchLayout, wide: usize) -> (Vec<u32>, Vec<usize>) {
    let width = layout.atlas_width as usize;
    let b = BLOCK as usize;
    // (polygon, block) of every patch texel; `owner` is the polygon ID + 1, 0 for no patch.
    let mut pairs: Vec<(u32, u32)> = (layout.owner.iter().enumerate())
        .filter(|&(_, &o)| o != 0)
        .map(|(i, &o)| (o - 1, ((i / width / b) * wide + i % width / b) as u32))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    let polygons = layout.patches_per_polygon.len();
    let mut starts = vec![0; polygons + 1];
    for &(p, _) in &pairs {
        starts[p as usize + 1] += 1;
    }
    for p in 0..polygons {
        starts[p + 1] += starts[p];
    }
    (pairs.into_iter().map(|(_, block)| block).collect(), starts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patches::Resolution;
    use crate::scene::bundled;
    use std::collections::BTreeSet;

    #[test]
    fn each_polygon_lists_exactly_the_blocks_that_hold_its_patches() {
        let (mut listed, mut in_rectangles) = (0, 0);
        for scene in &bundled::ALL {
            let scene = scene.load().unwrap();
            let layout = PatchLayout::new(&scene, Resolution::Patches(4096)).without_gutters();
            let wide = layout.atlas_width.div_ceil(BLOCK) as usize;
            let (blocks, starts) = patch_blocks(&layout, wide);
            let (width, b) = (layout.atlas_width as usize, BLOCK as usize);
            for (p, [x0, y0, x1, y1]) in layout.texel_rects().into_iter().enumerate() {
                let mine = &blocks[starts[p]..starts[p + 1]];
                let expected: BTreeSet<u32> = (layout.owner.iter().enumerate())
                    .filter(|&(_, &o)| o == p as u32 + 1)
                    .map(|(i, _)| ((i / width) / b * wide + (i % width) / b) as u32)
                    .collect();
                assert_eq!(
                    mine,
                    expected.into_iter().collect::<Vec<_>>(),
                    "polygon {p}"
                );
                listed += mine.len();
                if layout.patches_per_polygon[p] > 0 {
                    let (bx, by) = (
                        x1.div_ceil(BLOCK) - x0 / BLOCK,
                        y1.div_ceil(BLOCK) - y0 / BLOCK,
                    );
                    in_rectangles += (bx * by) as usize;
                }
            }
        }
        // The bundled scenes' lightmaps fill their rectangles' blocks.
        assert_eq!(listed, in_rectangles);
    }

    #[test]
    fn a_concave_polygon_lists_fewer_blocks_than_its_rectangle() {
        // An L-shaped floor of three unit squares, merged into one polygon, under a small light:
        // a quarter of its rectangle holds no patch.
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path();
        std::fs::write(
            dir.join("l.mtl"),
            "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl light\nKd 0 0 0\nKe 1 1 1\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("l.obj"),
            "mtllib l.mtl\nv 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 0 1\nv 1 0 1\nv 2 0 1\nv 0 0 2\n\
             v 1 0 2\nv 0.4 1 0.4\nv 0.6 1 0.4\nv 0.6 1 0.6\nv 0.4 1 0.6\nusemtl floor\n\
             f 1 4 5 2\nf 2 5 6 3\nf 4 7 8 5\nusemtl light\nf 9 10 11 12\n",
        )
        .unwrap();
        let scene = crate::scene::load_obj(&dir.join("l.obj")).unwrap();
        assert_eq!(scene.polygons.len(), 2, "the L merged into one polygon");
        let layout = PatchLayout::new(&scene, Resolution::Patches(4096)).without_gutters();
        let wide = layout.atlas_width.div_ceil(BLOCK) as usize;
        let (_, starts) = patch_blocks(&layout, wide);
        let floor = (0..2)
            .max_by_key(|&p| layout.patches_per_polygon[p])
            .unwrap();
        let [x0, y0, x1, y1] = layout.texel_rects()[floor];
        let rectangle = (x1.div_ceil(BLOCK) - x0 / BLOCK) * (y1.div_ceil(BLOCK) - y0 / BLOCK);
        let listed = starts[floor + 1] - starts[floor];
        // Three quarters of the rectangle, give or take the blocks along the inner edges.
        let share = listed as f64 / rectangle as f64;
        assert!(
            (0.7..0.85).contains(&share),
            "{listed} of {rectangle} blocks"
        );
    }
}
