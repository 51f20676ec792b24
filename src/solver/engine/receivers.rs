//! Which polygons can receive from a shooter (by where they lie, `Tuning::receivers_only`, or by
//! what the walk's item buffers let each shooter reach, `Tuning::walk_receivers`), and which 4×4
//! blocks of the atlas a pass must therefore draw (those that hold the receivers' patches, not the
//! whole of their lightmap rectangles), with which shader: the CPU half of the reconstruction
//! pass, run before each draw.

use super::cover::{patch_blocks, BLOCK};
use super::seen_receivers::Reach;
use crate::geometry::sphere_around;
use crate::patches::PatchLayout;
use crate::scene::Scene;
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
pub(crate) struct Receivers {
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
    pub(crate) fn new(scene: &Scene, layout: &PatchLayout) -> Self {
        let with_patches: Vec<usize> = (0..layout.patches_per_polygon.len())
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

    /// The block flags of the last `select` (rows of `blocks_wide()` blocks).
    pub(crate) fn flags(&self) -> &[u8] {
        &self.flags
    }

    /// Which shooters of the last `select` may send each block something or shoot from it
    /// (bit k: shooter k), if it was given their reach (`Tuning::walk_receivers`).
    pub(crate) fn shooter_bits(&self) -> Option<&[u8]> {
        self.bits_known.then_some(&self.shooter_bits[..])
    }

    pub(crate) fn blocks_wide(&self) -> usize {
        self.blocks_wide
    }

    /// Flag the blocks a pass for `shooters` must draw: the shooting texels, and the blocks
    /// that can receive from any of them: those `seen` lists for some shooter when given
    /// (`Tuning::walk_receivers`), else the lightmaps of every polygon with patches (only those
    /// in front with `tuning.receivers_only()`). A polygon has the shooters above it only if it
    /// has every one of them above it (a shooter's own polygon, which it sends nothing, aside).
    /// `touched` gets the receivers and the shooters.
    pub(crate) fn select(
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
    /// `tuning.receivers_only()`) those some shooter is in front of and in front of some shooter.
    fn select_in_front(&mut self, shooters: &[Shooter], tuning: &Tuning, touched: &mut Vec<usize>) {
        let reaches: Vec<(Vec3, f32)> = shooters
            .iter()
            .map(|s| sphere_around(s.position, &s.corners[..s.corner_count.max(1)]))
            .collect();
        for &p in &self.with_patches {
            let flag = if !tuning.receivers_only() {
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
    pub(crate) fn shaders(tuning: &Tuning) -> (impl Fn(&u8) -> bool, impl Fn(&u8) -> bool) {
        let skip = tuning.skip_needless_clipping() && tuning.marking_pass;
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
