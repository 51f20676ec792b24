//! Which polygons can receive from a shooter (`Tuning::receivers_only`), and which 4×4 blocks of
//! the atlas a pass must therefore draw, with which shader: the CPU half of the reconstruction
//! pass, run before each draw.

use super::cover::BLOCK;
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
    /// Per 4×4 block of the atlas, row by row, which kinds of polygon have texels in it this
    /// pass (`CLIPPED`, `SHOOTER_ABOVE`, `NOT_RECEIVING`, `SHOOTER`).
    flags: Vec<u8>,
    blocks_wide: usize,
}

impl Receivers {
    pub(super) fn new(scene: &Scene, layout: &PatchLayout) -> Self {
        let texels = layout.texel_rects();
        let with_patches: Vec<usize> = (0..texels.len())
            .filter(|&p| layout.patches_per_polygon[p] > 0)
            .collect();
        let blocks_wide = layout.atlas_width.div_ceil(BLOCK) as usize;
        let blocks = blocks_wide * layout.atlas_height.div_ceil(BLOCK) as usize;
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
            flags: vec![0; blocks],
            blocks_wide,
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

    pub(super) fn blocks_wide(&self) -> usize {
        self.blocks_wide
    }

    /// Flag the blocks a pass for `shooters` must draw: the lightmaps of the polygons that can
    /// receive from any of them (every polygon with patches unless `tuning.receivers_only`) and
    /// the shooting texels. A polygon has the shooters above it only if it has every one of them
    /// above it (a shooter's own polygon, which it sends nothing, aside). `touched` gets the
    /// receivers and the shooters.
    pub(super) fn select(
        &mut self,
        shooters: &[Shooter],
        tuning: &Tuning,
        touched: &mut Vec<usize>,
    ) {
        touched.clear();
        self.flags.fill(0);
        let reaches: Vec<(Vec3, f32)> = shooters
            .iter()
            .map(|s| sphere_around(s.position, &s.corners[..s.corner_count.max(1)]))
            .collect();
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
                mark(&mut self.flags, self.texels[p], flag);
            }
        }
        // The shooting texels are drawn to clear their unshot energy.
        for s in shooters {
            mark(&mut self.flags, s.texels, SHOOTER);
            if !touched.contains(&s.polygon) {
                touched.push(s.polygon);
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
