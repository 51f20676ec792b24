//! The rooms' shell: floor (planks or tiles), a ceiling of tiles in which the light panels sit,
//! walls with a dado and skirting boards, and doorways between rooms.

use crate::builder::Builder;
use crate::geometry::{box_face, q3, Facing, Frame, ALL, NX, NY, NZ, PX, PY, PZ};
use crate::palette::Pal;
use crate::random::SplitMix;

const DADO: f64 = 0.9;
const SKIRT_H: f64 = 0.08;
const SKIRT_D: f64 = 0.015;

/// A wall of a room, by compass: north is +z, east is +x.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    North,
    South,
    East,
    West,
}

/// A room's inside: x from x0 to x1, z from z0 (south) to z1 (north), floor at y = 0.
#[derive(Clone, Copy, Debug)]
pub struct RoomRect {
    pub name: &'static str,
    pub x0: f64,
    pub x1: f64,
    pub z0: f64,
    pub z1: f64,
}

impl RoomRect {
    /// A frame on a wall, `gap` in front of it, facing into the room; `at` is the world x (north
    /// and south walls) or z (east and west walls).
    pub fn wall(&self, side: Side, at: f64, gap: f64) -> Frame {
        match side {
            Side::North => Frame::new(at, 0.0, self.z1 - gap, Facing::NegZ),
            Side::South => Frame::new(at, 0.0, self.z0 + gap, Facing::PosZ),
            Side::West => Frame::new(self.x0 + gap, 0.0, at, Facing::PosX),
            Side::East => Frame::new(self.x1 - gap, 0.0, at, Facing::NegX),
        }
    }
}

/// An opening in one side of a room, from `lo` to `hi` along the wall, `height` high.
#[derive(Clone, Copy)]
pub struct Opening {
    side: Side,
    lo: f64,
    hi: f64,
    height: f64,
}

/// A floor's covering: staggered planks of random oak shades, or a chequer of two tiles.
pub enum Floor {
    Planks {
        width: f64,
        length: f64,
        mats: Vec<usize>,
    },
    Tiles {
        size: f64,
        mats: [usize; 2],
    },
}

/// How a room's shell looks: wall and dado materials, floor, ceiling tiles and light panels.
pub struct Finish {
    pub wall: usize,
    pub dado: usize,
    pub floor: Floor,
    pub ceiling_tile: f64,
    /// Light panels as tile ranges of the ceiling grid: [i0, j0, ni, nj] (i along x, j along z).
    pub lights: Vec<[usize; 4]>,
}

/// Cuts [lo, hi] into tiles of `t`, centred, with equal part tiles at both ends.
fn grid(lo: f64, hi: f64, t: f64) -> Vec<(f64, f64)> {
    let len = hi - lo;
    let mut n = (len / t - 1e-6).ceil() as usize;
    if (len - (n as f64 - 2.0) * t) / 2.0 < 0.25 * t && n > 2 {
        n -= 1;
    }
    let margin = (n as f64 * t - len) / 2.0;
    (0..n)
        .map(|k| {
            let a = if k == 0 {
                lo
            } else {
                lo - margin + k as f64 * t
            };
            let b = if k + 1 == n {
                hi
            } else {
                lo - margin + (k + 1) as f64 * t
            };
            (a, b)
        })
        .collect()
}

/// A room's floor, ceiling (with its light panels), walls (with holes for `openings`) and
/// skirting boards; the room's box joins the interior.
pub fn shell(
    b: &mut Builder,
    rng: &mut SplitMix,
    p: &Pal,
    room: &RoomRect,
    h: f64,
    finish: &Finish,
    openings: &[Opening],
) {
    b.interior
        .push(([room.x0, 0.0, room.z0], [room.x1, h, room.z1]));
    let floor_name = format!("floor_{}", room.name);
    match &finish.floor {
        Floor::Planks {
            width,
            length,
            mats,
        } => {
            let rows = grid(room.z0, room.z1, *width);
            for (j, &(za, zb)) in rows.iter().enumerate() {
                // Staggered joints, no piece shorter than a third of a plank.
                let offset = [0.0, 0.4, 0.75, 0.2, 0.55][j % 5] * length;
                let mut cuts = vec![room.x0];
                let mut x = room.x0 + length - offset;
                while x < room.x1 - length / 3.0 {
                    if x - cuts[cuts.len() - 1] >= length / 3.0 {
                        cuts.push(x);
                    }
                    x += length;
                }
                cuts.push(room.x1);
                for w in cuts.windows(2) {
                    let m = rng.pick(mats);
                    b.rect(&floor_name, m, [w[0], 0.0, za], [w[1], 0.0, zb], PY);
                }
            }
        }
        Floor::Tiles { size, mats } => {
            for (i, &(xa, xb)) in grid(room.x0, room.x1, *size).iter().enumerate() {
                for (j, &(za, zb)) in grid(room.z0, room.z1, *size).iter().enumerate() {
                    b.rect(
                        &floor_name,
                        mats[(i + j) % 2],
                        [xa, 0.0, za],
                        [xb, 0.0, zb],
                        PY,
                    );
                }
            }
        }
    }

    let gx = grid(room.x0, room.x1, finish.ceiling_tile);
    let gz = grid(room.z0, room.z1, finish.ceiling_tile);
    let lit = |i: usize, j: usize| {
        finish
            .lights
            .iter()
            .any(|l| (l[0]..l[0] + l[2]).contains(&i) && (l[1]..l[1] + l[3]).contains(&j))
    };
    let ceiling_name = format!("ceiling_{}", room.name);
    for (i, &(xa, xb)) in gx.iter().enumerate() {
        for (j, &(za, zb)) in gz.iter().enumerate() {
            if !lit(i, j) {
                b.rect(&ceiling_name, p.ceiling, [xa, h, za], [xb, h, zb], NY);
            }
        }
    }
    for l in &finish.lights {
        let (xa, xb) = (gx[l[0]].0, gx[l[0] + l[2] - 1].1);
        let (za, zb) = (gz[l[1]].0, gz[l[1] + l[3] - 1].1);
        b.rect(
            &format!("light_{}", room.name),
            p.light,
            [xa, h, za],
            [xb, h, zb],
            NY,
        );
    }

    for side in [Side::North, Side::South, Side::East, Side::West] {
        let (a0, a1) = match side {
            Side::North | Side::South => (room.x0, room.x1),
            _ => (room.z0, room.z1),
        };
        let mut holes: Vec<&Opening> = openings.iter().filter(|o| o.side == side).collect();
        holes.sort_by(|x, y| x.lo.total_cmp(&y.lo));
        let mut solid = Vec::new();
        let mut at = a0;
        for o in &holes {
            solid.push((at, o.lo));
            at = o.hi;
        }
        solid.push((at, a1));
        let name = format!("wall_{}", room.name);
        // The wall plane as a flat box between `a` and `b` along it, y0 to y1.
        let plane = |a: f64, b: f64, y0: f64, y1: f64| -> ([f64; 3], [f64; 3], u8) {
            match side {
                Side::North => ([a, y0, room.z1], [b, y1, room.z1], NZ),
                Side::South => ([a, y0, room.z0], [b, y1, room.z0], PZ),
                Side::West => ([room.x0, y0, a], [room.x0, y1, b], PX),
                Side::East => ([room.x1, y0, a], [room.x1, y1, b], NX),
            }
        };
        for &(a, bb) in &solid {
            if bb - a < 1e-6 {
                continue;
            }
            let (lo, hi, f) = plane(a, bb, 0.0, DADO);
            b.rect(&name, finish.dado, lo, hi, f);
            let (lo, hi, f) = plane(a, bb, DADO, h);
            b.rect(&name, finish.wall, lo, hi, f);
            // Skirting: front and top. East and west boards stop short of the corners, where the
            // north and south boards run through.
            let (mut sa, mut sb) = (a, bb);
            if matches!(side, Side::East | Side::West) {
                if (sa - room.z0).abs() < 1e-9 {
                    sa += SKIRT_D;
                }
                if (sb - room.z1).abs() < 1e-9 {
                    sb -= SKIRT_D;
                }
            }
            let (lo, hi, keep) = match side {
                Side::North => (
                    [sa, 0.0, room.z1 - SKIRT_D],
                    [sb, SKIRT_H, room.z1],
                    NZ | PY,
                ),
                Side::South => (
                    [sa, 0.0, room.z0],
                    [sb, SKIRT_H, room.z0 + SKIRT_D],
                    PZ | PY,
                ),
                Side::West => (
                    [room.x0, 0.0, sa],
                    [room.x0 + SKIRT_D, SKIRT_H, sb],
                    PX | PY,
                ),
                Side::East => (
                    [room.x1 - SKIRT_D, 0.0, sa],
                    [room.x1, SKIRT_H, sb],
                    NX | PY,
                ),
            };
            b.cuboid("skirting", p.skirting, lo, hi, ALL & !keep);
        }
        for o in &holes {
            let (lo, hi, f) = plane(o.lo, o.hi, o.height, h);
            b.rect(&name, finish.wall, lo, hi, f);
        }
    }
}

/// A doorway through the wall between two rooms: the inner faces of the opening (jambs, head,
/// threshold), facing into it.
pub struct Doorway {
    /// The passage runs along x (else along z).
    pub along_x: bool,
    /// Where the passage starts and ends along its axis: the two rooms' facing walls.
    pub through: (f64, f64),
    /// Its span across the passage (z if it runs along x, else x).
    pub across: (f64, f64),
    pub height: f64,
}

impl Doorway {
    /// Its jambs and head in `m`, its threshold in `floor`; the passage joins the interior.
    pub fn place(&self, b: &mut Builder, m: usize, floor: usize) {
        let (a, c) = self.through;
        let (lo, hi) = self.across;
        let height = self.height;
        let faces = if self.along_x {
            vec![
                box_face(q3([a, 0.0, lo]), q3([c, height, lo]), PZ),
                box_face(q3([a, 0.0, hi]), q3([c, height, hi]), NZ),
                box_face(q3([a, height, lo]), q3([c, height, hi]), NY),
            ]
        } else {
            vec![
                box_face(q3([lo, 0.0, a]), q3([lo, height, c]), PX),
                box_face(q3([hi, 0.0, a]), q3([hi, height, c]), NX),
                box_face(q3([lo, height, a]), q3([hi, height, c]), NY),
            ]
        };
        b.polys("doorway", m, faces);
        let (lo3, hi3) = if self.along_x {
            ([a, 0.0, lo], [c, height, hi])
        } else {
            ([lo, 0.0, a], [hi, height, c])
        };
        b.rect("doorway_floor", floor, lo3, [hi3[0], 0.0, hi3[2]], PY);
        b.interior.push((lo3, hi3));
    }

    /// The hole it makes in the wall on `side` of one of the two rooms.
    pub fn opening(&self, side: Side) -> Opening {
        Opening {
            side,
            lo: self.across.0,
            hi: self.across.1,
            height: self.height,
        }
    }
}
