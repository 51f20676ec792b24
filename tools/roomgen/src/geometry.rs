//! Geometry of the generator: integer coordinates (exact planes, exact text), box faces by bit,
//! and local frames (furniture is described in its own axes and turned to face the room).

/// Integer coordinates in tenths of a millimetre.
pub type Q3 = [i64; 3];
const PER_METRE: f64 = 10_000.0;

/// Metres to integer coordinates.
pub fn q(x: f64) -> i64 {
    (x * PER_METRE).round() as i64
}

pub fn q3(p: [f64; 3]) -> Q3 {
    p.map(q)
}

/// "-1.25" for -12500: the shortest exact decimal.
pub fn decimal(v: i64) -> String {
    let sign = if v < 0 { "-" } else { "" };
    let a = v.unsigned_abs();
    let (int, frac) = (a / 10_000, a % 10_000);
    if frac == 0 {
        format!("{sign}{int}")
    } else {
        let f = format!("{frac:04}");
        format!("{sign}{int}.{}", f.trim_end_matches('0'))
    }
}

// Box faces, one bit each. In a local frame: left, right, bottom, top, back, front.
pub const NX: u8 = 1;
pub const PX: u8 = 2;
pub const NY: u8 = 4;
pub const PY: u8 = 8;
pub const NZ: u8 = 16;
pub const PZ: u8 = 32;
pub const ALL: u8 = 63;
pub const LEFT: u8 = NX;
pub const RIGHT: u8 = PX;
pub const BOTTOM: u8 = NY;
pub const TOP: u8 = PY;
pub const BACK: u8 = NZ;
pub const FRONT: u8 = PZ;

/// One face of the box [lo, hi], counter-clockwise seen from outside the box.
pub fn box_face(lo: Q3, hi: Q3, bit: u8) -> Vec<Q3> {
    let c = |i: bool, j: bool, k: bool| {
        [
            if i { hi[0] } else { lo[0] },
            if j { hi[1] } else { lo[1] },
            if k { hi[2] } else { lo[2] },
        ]
    };
    let (o, l) = (false, true);
    match bit {
        NX => vec![c(o, o, o), c(o, o, l), c(o, l, l), c(o, l, o)],
        PX => vec![c(l, o, o), c(l, l, o), c(l, l, l), c(l, o, l)],
        NY => vec![c(o, o, o), c(l, o, o), c(l, o, l), c(o, o, l)],
        PY => vec![c(o, l, o), c(o, l, l), c(l, l, l), c(l, l, o)],
        NZ => vec![c(o, o, o), c(o, l, o), c(l, l, o), c(l, o, o)],
        PZ => vec![c(o, o, l), c(l, o, l), c(l, l, l), c(o, l, l)],
        _ => unreachable!("one face bit"),
    }
}

/// Where a piece of furniture's front faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Facing {
    PosX,
    NegX,
    PosZ,
    NegZ,
}

impl Facing {
    /// World (axis, sign) of the local u (right, seen from the front) and w (front) axes; local
    /// v is world +y. (u, v, w) is right-handed, so orientations survive the mapping.
    fn axes(self) -> ((usize, f64), (usize, f64)) {
        match self {
            Facing::PosZ => ((0, 1.0), (2, 1.0)),
            Facing::NegZ => ((0, -1.0), (2, -1.0)),
            Facing::PosX => ((2, -1.0), (0, 1.0)),
            Facing::NegX => ((2, 1.0), (0, -1.0)),
        }
    }
}

/// A local frame: origin and facing (a rotation about +y by a multiple of 90°).
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    o: [f64; 3],
    facing: Facing,
}

impl Frame {
    pub fn new(x: f64, y: f64, z: f64, facing: Facing) -> Frame {
        Frame {
            o: [x, y, z],
            facing,
        }
    }

    pub fn world(&self, p: [f64; 3]) -> [f64; 3] {
        let ((ua, us), (wa, ws)) = self.facing.axes();
        let mut r = self.o;
        r[1] += p[1];
        r[ua] += us * p[0];
        r[wa] += ws * p[2];
        r
    }

    /// The same facing, moved to local (u, v, w).
    pub fn at(&self, u: f64, v: f64, w: f64) -> Frame {
        Frame {
            o: self.world([u, v, w]),
            facing: self.facing,
        }
    }

    pub fn world_box(&self, lo: [f64; 3], hi: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let (a, b) = (self.world(lo), self.world(hi));
        (
            [a[0].min(b[0]), a[1].min(b[1]), a[2].min(b[2])],
            [a[0].max(b[0]), a[1].max(b[1]), a[2].max(b[2])],
        )
    }

    /// Local face bits to world face bits.
    pub fn world_bits(&self, local: u8) -> u8 {
        let ((ua, us), (wa, ws)) = self.facing.axes();
        let mut out = 0;
        for bit in 0..6 {
            if local & (1 << bit) == 0 {
                continue;
            }
            let positive = bit % 2 == 1;
            let (axis, sign) = match bit / 2 {
                0 => (ua, us),
                1 => (1, 1.0),
                _ => (wa, ws),
            };
            out |= 1 << (2 * axis + usize::from(positive == (sign > 0.0)));
        }
        out
    }
}
