//! A deterministic generator of the paper's two virtual indoor rooms (section 4, Table 1), with
//! exactly the paper's counts:
//!
//! | room | faces | vertices | lights | patches |
//! |---|---|---|---|---|
//! | simple | 1,602 | 6,431 | 2 | 14,445 |
//! | complex | 8,549 | 35,785 | 6 | 86,077 |
//!
//! "Faces" are the polygons `load_obj` keeps, "vertices" the `v` lines of the OBJ, "lights" the
//! polygons whose material emits, "patches" the patches of `PatchLayout` at the scene's own
//! `# patch-size`.
//!
//! Both rooms are built in metres (+y up) from axis-aligned boxes, vertical cylinders and flat
//! discs: a shell (plank or tiled floor, a ceiling of tiles in which the emissive light panels
//! sit, walls with a dado and skirting boards, doorways between rooms) and furniture (bookcases,
//! tables with legs, chairs, sofas, beds, cabinets, a kitchen, lamps, plants, rugs, pictures...).
//! Coordinates are kept as integers in tenths of a millimetre, so every box face is exactly planar
//! and the text is exact; the only randomness is a splitmix64 stream with a fixed seed.
//!
//! The counts are hit at generation time, in this order:
//! 1. **faces**: the room and its furniture are fixed; the faces still missing (less the three
//!    tuning polygons below) are filled with books on the bookcases' shelves (5 faces each: a book's
//!    bottom rests on the shelf) and 0–4 sheets of paper on a desk (1 face each);
//! 2. **vertices**: every piece uses its own vertices (4 per quad) except a few shared-vertex
//!    pieces; n-gon caps and discs add n − 4 each. The one free count left is the number of sides
//!    of a round rug, chosen so that the vertex total is exact;
//! 3. **patches**: two rectangles (a rug on the floor and the canvas of a picture) have sides of
//!    (k − ½) patch sizes, so exactly a·b and c·d patches. The patch size is searched in steps of
//!    0.1 mm from a per-room starting value (0.143 m, 0.113 m): the first size at which the
//!    patches of everything else, counted with `PatchLayout` itself, do not change at ±0.01 % of
//!    the size (no lightmap side on a multiple of it, so no rounding can flip the count) and
//!    a·b + c·d can make up exactly what is missing, with every side within its range (closest
//!    to the preferred sizes), is the one written as `# patch-size`. The simple room gets
//!    0.1428 m, the complex one 0.1127 m.
//!
//! The generator then loads its own output back the way `load_obj` would (same text, same `f32`
//! parsing) and asserts the four counts.

use crate::patches::{PatchLayout, Resolution};
use crate::scene::{Material, Polygon, Scene};
use glam::Vec3;
use std::collections::HashMap;
use std::fmt::Write as _;

/// Which of the paper's two rooms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Room {
    Simple,
    Complex,
}

/// The four counts of Table 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Counts {
    pub faces: usize,
    pub vertices: usize,
    pub lights: usize,
    pub patches: u64,
}

impl Room {
    pub fn name(self) -> &'static str {
        match self {
            Room::Simple => "simple",
            Room::Complex => "complex",
        }
    }

    /// The paper's counts (Table 1).
    pub fn targets(self) -> Counts {
        match self {
            Room::Simple => Counts {
                faces: 1_602,
                vertices: 6_431,
                lights: 2,
                patches: 14_445,
            },
            Room::Complex => Counts {
                faces: 8_549,
                vertices: 35_785,
                lights: 6,
                patches: 86_077,
            },
        }
    }

    /// Where the search for the patch size starts, in metres: chosen by hand so that the fixed
    /// content leaves about the rectangles' preferred sizes to make up.
    fn patch_size(self) -> f64 {
        match self {
            Room::Simple => 0.143,
            Room::Complex => 0.113,
        }
    }

    fn seed(self) -> u64 {
        match self {
            Room::Simple => 0x5EED_0001,
            Room::Complex => 0x5EED_0002,
        }
    }

    fn camera(self) -> &'static str {
        match self {
            Room::Simple => "eye 4.9 1.62 0.32 target 1.6 0.95 3.7 up 0 1 0 fov 62",
            Room::Complex => "eye 0.4 1.6 0.6 target 5.3 1.0 4.4 up 0 1 0 fov 64",
        }
    }
}

/// A generated room: the OBJ and MTL texts, and what the tests need to check them.
pub struct GeneratedScene {
    pub obj: String,
    pub mtl: String,
    pub counts: Counts,
    pub patch_size: f32,
    /// The empty space of the rooms (each room's box, each doorway's opening), min and max
    /// corners in metres: every vertex lies in their union, and every wall, floor and ceiling
    /// polygon has this space in front of it and none behind it.
    pub interior: Vec<(Vec3, Vec3)>,
    /// How the counts were hit, in words (also a comment line of the OBJ).
    pub tuning: String,
}

/// Generate `room`; the OBJ names `mtl_file` (to be written next to it) in its `mtllib` line.
pub fn generate(room: Room, mtl_file: &str) -> GeneratedScene {
    let target = room.targets();
    let mut b = Builder::default();
    let mut rng = SplitMix(room.seed());
    let plan = match room {
        Room::Simple => simple(&mut b, &mut rng),
        Room::Complex => complex(&mut b, &mut rng),
    };

    // 1. Faces: books (5 faces) and sheets of paper (1 face); 3 faces are kept for the round rug
    //    and the two tuning rectangles.
    let (faces, _) = b.counts();
    let spare = target
        .faces
        .checked_sub(faces + 3)
        .expect("the fixed content has more faces than the target");
    fill_books(&mut b, &mut rng, &plan.shelves, &plan.books, spare / 5);
    plan.papers.place(&mut b, spare % 5);

    // 2. Vertices: the round rug has whatever is left, less the two rectangles' 8.
    let (_, vertices) = b.counts();
    let sides = target
        .vertices
        .checked_sub(vertices + 8)
        .expect("the content has more vertices than the target");
    assert!(
        (12..=400).contains(&sides),
        "the round rug would have {sides} sides: rebalance the fixed content"
    );
    let r = &plan.round_rug;
    b.hdisc("rug_round", r.material, [r.x, RUG_Y, r.z], r.radius, sides);

    // 3. Patches: the patch size, in steps of 0.1 mm from the room's starting value, is the first
    //    at which the count of everything but the two rectangles is robust (the same at ±0.01 %
    //    of it) and the rectangles can make up exactly what is missing.
    let fixed = b.scene(1.0);
    let [t0, t1] = &plan.tuners;
    let start = q(room.patch_size());
    let (size_text, patch_size, (a, bb, c, d)) = (0..400i64)
        .map(|k| start + if k % 2 == 0 { k / 2 } else { -(k + 1) / 2 })
        .find_map(|tenths| {
            let text = decimal(tenths);
            let s: f32 = text.parse().expect("a decimal");
            let rest = patch_count(&fixed, s);
            let robust = [1.0 - 1e-4, 1.0 + 1e-4]
                .iter()
                .all(|f| patch_count(&fixed, s * f) == rest);
            let missing = target.patches.checked_sub(rest).filter(|_| robust)?;
            solve_rectangles(missing, t0, t1, s as f64).map(|sizes| (text, s, sizes))
        })
        .expect("no patch size near the starting one gives the target: rebalance the content");
    t0.place(&mut b, patch_size as f64, a, bb);
    t1.place(&mut b, patch_size as f64, c, d);

    let scene = b.scene(patch_size);
    let counts = Counts {
        faces: scene.polygons.len(),
        vertices: scene.vertex_count,
        lights: scene.light_count(),
        patches: patch_count(&scene, patch_size),
    };
    assert_eq!(counts, target, "{} room", room.name());

    let tuning = format!(
        "{} books, {} sheet(s) of paper, a {sides}-sided round rug, a {a}×{bb}-patch rug and a \
         {c}×{d}-patch canvas",
        spare / 5,
        spare % 5
    );
    let obj = b.obj_text(room, &counts, &size_text, mtl_file, &tuning);
    let mtl = b.mtl_text(room);
    let interior = b
        .interior
        .iter()
        .map(|(lo, hi)| {
            (
                Vec3::from(lo.map(|v| v as f32)),
                Vec3::from(hi.map(|v| v as f32)),
            )
        })
        .collect();
    GeneratedScene {
        obj,
        mtl,
        counts,
        patch_size,
        interior,
        tuning,
    }
}

fn patch_count(scene: &Scene, patch_size: f32) -> u64 {
    PatchLayout::new(scene, Resolution::PatchSize(patch_size)).patch_count()
}

/// a·b + c·d = `missing` with every side within its range, closest to the preferred sizes.
fn solve_rectangles(missing: u64, t0: &Tuner, t1: &Tuner, s: f64) -> Option<(u32, u32, u32, u32)> {
    let (a0, b0) = (Tuner::range(t0.a, s), Tuner::range(t0.b, s));
    let (a1, b1) = (Tuner::range(t1.a, s), Tuner::range(t1.b, s));
    let mut best: Option<(u32, (u32, u32, u32, u32))> = None;
    for a in a0.0..=a0.2 {
        for b in b0.0..=b0.2 {
            let Some(rest) = missing.checked_sub(a as u64 * b as u64) else {
                continue;
            };
            for c in a1.0..=a1.2 {
                if rest % c as u64 != 0 {
                    continue;
                }
                let d = rest / c as u64;
                if d < b1.0 as u64 || d > b1.2 as u64 {
                    continue;
                }
                let d = d as u32;
                let cost =
                    a.abs_diff(a0.1) + b.abs_diff(b0.1) + c.abs_diff(a1.1) + d.abs_diff(b1.1);
                if best.is_none_or(|(bc, _)| cost < bc) {
                    best = Some((cost, (a, b, c, d)));
                }
            }
        }
    }
    best.map(|(_, sizes)| sizes)
}

// ---------------------------------------------------------------------------------------------
// Deterministic randomness

/// splitmix64 (Steele, Lea, Flood 2014): tiny, fast, and the same everywhere.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [a, b), rounded to the millimetre.
    fn mm(&mut self, a: f64, b: f64) -> f64 {
        let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        ((a + (b - a) * u) * 1000.0).round() / 1000.0
    }

    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[(self.next() % items.len() as u64) as usize]
    }
}

// ---------------------------------------------------------------------------------------------
// Geometry: integer coordinates, boxes, cylinders, discs, local frames

/// Integer coordinates in tenths of a millimetre.
type Q3 = [i64; 3];
const PER_METRE: f64 = 10_000.0;

fn q(x: f64) -> i64 {
    (x * PER_METRE).round() as i64
}

fn q3(p: [f64; 3]) -> Q3 {
    p.map(q)
}

/// "-1.25" for -12500: the shortest exact decimal.
fn decimal(v: i64) -> String {
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
const NX: u8 = 1;
const PX: u8 = 2;
const NY: u8 = 4;
const PY: u8 = 8;
const NZ: u8 = 16;
const PZ: u8 = 32;
const ALL: u8 = 63;
const LEFT: u8 = NX;
const RIGHT: u8 = PX;
const BOTTOM: u8 = NY;
const TOP: u8 = PY;
const BACK: u8 = NZ;
const FRONT: u8 = PZ;

/// One face of the box [lo, hi], counter-clockwise seen from outside the box.
fn box_face(lo: Q3, hi: Q3, bit: u8) -> Vec<Q3> {
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
enum Facing {
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
struct Frame {
    o: [f64; 3],
    facing: Facing,
}

impl Frame {
    fn new(x: f64, y: f64, z: f64, facing: Facing) -> Frame {
        Frame {
            o: [x, y, z],
            facing,
        }
    }

    fn world(&self, p: [f64; 3]) -> [f64; 3] {
        let ((ua, us), (wa, ws)) = self.facing.axes();
        let mut r = self.o;
        r[1] += p[1];
        r[ua] += us * p[0];
        r[wa] += ws * p[2];
        r
    }

    /// The same facing, moved to local (u, v, w).
    fn at(&self, u: f64, v: f64, w: f64) -> Frame {
        Frame {
            o: self.world([u, v, w]),
            facing: self.facing,
        }
    }

    fn world_box(&self, lo: [f64; 3], hi: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let (a, b) = (self.world(lo), self.world(hi));
        (
            [a[0].min(b[0]), a[1].min(b[1]), a[2].min(b[2])],
            [a[0].max(b[0]), a[1].max(b[1]), a[2].max(b[2])],
        )
    }

    /// Local face bits to world face bits.
    fn world_bits(&self, local: u8) -> u8 {
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

struct Piece {
    name: String,
    material: usize,
    vertices: Vec<Q3>,
    faces: Vec<Vec<usize>>,
}

struct Mat {
    name: String,
    kd: [f64; 3],
    ke: [f64; 3],
}

#[derive(Default)]
struct Builder {
    pieces: Vec<Piece>,
    materials: Vec<Mat>,
    counters: HashMap<String, usize>,
    interior: Vec<([f64; 3], [f64; 3])>,
    /// While set, boxes share their corners between their faces.
    shared: bool,
}

impl Builder {
    fn material(&mut self, name: &str, kd: [f64; 3]) -> usize {
        self.emitter(name, kd, [0.0; 3])
    }

    fn emitter(&mut self, name: &str, kd: [f64; 3], ke: [f64; 3]) -> usize {
        if let Some(i) = self.materials.iter().position(|m| m.name == name) {
            return i;
        }
        self.materials.push(Mat {
            name: name.into(),
            kd,
            ke,
        });
        self.materials.len() - 1
    }

    fn counts(&self) -> (usize, usize) {
        self.pieces.iter().fold((0, 0), |(f, v), p| {
            (f + p.faces.len(), v + p.vertices.len())
        })
    }

    fn unique(&mut self, base: &str) -> String {
        let n = self.counters.entry(base.to_string()).or_insert(0);
        *n += 1;
        format!("{base}_{n}")
    }

    /// A piece whose faces each have their own vertices.
    fn polys(&mut self, base: &str, material: usize, faces: Vec<Vec<Q3>>) {
        assert!(!faces.is_empty(), "{base}: a piece without faces");
        let name = self.unique(base);
        let mut vertices = Vec::new();
        let mut indices = Vec::new();
        for f in faces {
            indices.push((vertices.len()..vertices.len() + f.len()).collect());
            vertices.extend(f);
        }
        self.pieces.push(Piece {
            name,
            material,
            vertices,
            faces: indices,
        });
    }

    /// A piece whose faces share their corners.
    fn shared_polys(&mut self, base: &str, material: usize, faces: Vec<Vec<Q3>>) {
        let name = self.unique(base);
        let mut vertices: Vec<Q3> = Vec::new();
        let mut indices = Vec::new();
        for f in faces {
            let mut face = Vec::new();
            for v in f {
                let i = vertices.iter().position(|&w| w == v).unwrap_or_else(|| {
                    vertices.push(v);
                    vertices.len() - 1
                });
                face.push(i);
            }
            indices.push(face);
        }
        self.pieces.push(Piece {
            name,
            material,
            vertices,
            faces: indices,
        });
    }

    fn box_faces(lo: Q3, hi: Q3, omit: u8) -> Vec<Vec<Q3>> {
        (0..6)
            .map(|b| 1u8 << b)
            .filter(|&bit| omit & bit == 0)
            .map(|bit| box_face(lo, hi, bit))
            .collect()
    }

    /// A world box, without the faces in `omit` (those resting on or against something).
    fn cuboid(&mut self, base: &str, m: usize, lo: [f64; 3], hi: [f64; 3], omit: u8) {
        let (lo, hi) = (q3(lo), q3(hi));
        assert!((0..3).all(|i| lo[i] <= hi[i]), "{base}: an inside-out box");
        if self.shared {
            self.shared_polys(base, m, Self::box_faces(lo, hi, omit));
        } else {
            self.polys(base, m, Self::box_faces(lo, hi, omit));
        }
    }

    /// A box in a local frame.
    fn lbox(&mut self, fr: &Frame, base: &str, m: usize, lo: [f64; 3], hi: [f64; 3], omit: u8) {
        let (a, b) = fr.world_box(lo, hi);
        self.cuboid(base, m, a, b, fr.world_bits(omit));
    }

    /// One rectangle: the `face` side of the (flat) local box [lo, hi].
    fn lrect(&mut self, fr: &Frame, base: &str, m: usize, lo: [f64; 3], hi: [f64; 3], face: u8) {
        self.lbox(fr, base, m, lo, hi, ALL & !face);
    }

    /// One world rectangle.
    fn rect(&mut self, base: &str, m: usize, lo: [f64; 3], hi: [f64; 3], face: u8) {
        self.cuboid(base, m, lo, hi, ALL & !face);
    }

    /// n points on a horizontal circle, by increasing angle (clockwise seen from above).
    fn ring(c: [f64; 3], r: f64, n: usize) -> Vec<Q3> {
        (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                [q(c[0] + r * a.cos()), q(c[1]), q(c[2] + r * a.sin())]
            })
            .collect()
    }

    /// A vertical n-sided cylinder standing on `bottom` (world), with the caps in `caps`
    /// (TOP, BOTTOM) and, if `sides`, its n side quads.
    #[allow(clippy::too_many_arguments)]
    fn cylinder(
        &mut self,
        base: &str,
        m: usize,
        bottom: [f64; 3],
        r: f64,
        h: f64,
        n: usize,
        caps: u8,
        sides: bool,
    ) {
        let lo = Self::ring(bottom, r, n);
        let hi = Self::ring([bottom[0], bottom[1] + h, bottom[2]], r, n);
        let mut faces = Vec::new();
        if sides {
            for k in 0..n {
                let k1 = (k + 1) % n;
                faces.push(vec![lo[k], hi[k], hi[k1], lo[k1]]);
            }
        }
        if caps & TOP != 0 {
            faces.push(hi.iter().rev().copied().collect());
        }
        if caps & BOTTOM != 0 {
            faces.push(lo.clone());
        }
        self.polys(base, m, faces);
    }

    /// A cylinder placed in a local frame (its axis stays vertical).
    #[allow(clippy::too_many_arguments)]
    fn lcylinder(
        &mut self,
        fr: &Frame,
        base: &str,
        m: usize,
        bottom: [f64; 3],
        r: f64,
        h: f64,
        n: usize,
        caps: u8,
        sides: bool,
    ) {
        let c = fr.world(bottom);
        self.cylinder(base, m, c, r, h, n, caps, sides);
    }

    /// A flat horizontal n-gon facing up.
    fn hdisc(&mut self, base: &str, m: usize, c: [f64; 3], r: f64, n: usize) {
        let face = Self::ring(c, r, n).into_iter().rev().collect();
        self.polys(base, m, vec![face]);
    }

    /// A flat vertical n-gon in a local frame's (u, v) plane at depth w, facing the front.
    #[allow(clippy::too_many_arguments)]
    fn vdisc(
        &mut self,
        fr: &Frame,
        base: &str,
        m: usize,
        u: f64,
        v: f64,
        w: f64,
        r: f64,
        n: usize,
    ) {
        let face = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                q3(fr.world([u + r * a.cos(), v + r * a.sin(), w]))
            })
            .collect();
        self.polys(base, m, vec![face]);
    }

    /// The scene `load_obj` would read from this builder's text (same decimals, same f32
    /// parsing), for counting.
    fn scene(&self, patch_size: f32) -> Scene {
        let coord = |v: i64| -> f32 { decimal(v).parse().expect("a decimal") };
        let materials = self
            .materials
            .iter()
            .map(|m| Material {
                name: m.name.clone(),
                kd: Vec3::from(m.kd.map(|c| c as f32)),
                ke: Vec3::from(m.ke.map(|c| c as f32)),
            })
            .collect();
        let mut polygons = Vec::new();
        let mut vertex_count = 0;
        for p in &self.pieces {
            let vs: Vec<Vec3> = p
                .vertices
                .iter()
                .map(|v| Vec3::new(coord(v[0]), coord(v[1]), coord(v[2])))
                .collect();
            vertex_count += vs.len();
            for f in &p.faces {
                let poly = Polygon::new(
                    f.iter().map(|&i| vs[i]).collect(),
                    p.material,
                    p.name.clone(),
                );
                polygons.push(poly.unwrap_or_else(|| panic!("{}: a degenerate face", p.name)));
            }
        }
        Scene {
            name: String::new(),
            polygons,
            materials,
            vertex_count,
            camera: None,
            patch_size: Some(patch_size),
            skipped_degenerate: 0,
        }
    }

    fn obj_text(
        &self,
        room: Room,
        counts: &Counts,
        patch_size: &str,
        mtl_file: &str,
        tuning: &str,
    ) -> String {
        let mut s = String::new();
        let name = room.name();
        let _ = writeln!(
            s,
            "# The paper's \"{name}\" room (Yu Ping, Table 1): {} faces, {} vertices, {} lights, {} patches \
             at the patch size below.",
            counts.faces, counts.vertices, counts.lights, counts.patches
        );
        let _ = writeln!(
            s,
            "# Generated by `radiosity scene {name}` (src/scene/generate.rs); do not edit by hand. Metres, +y up."
        );
        let _ = writeln!(
            s,
            "# Front face = counter-clockwise seen from the front: walls, floors and ceilings face the inside of \
             the rooms,"
        );
        let _ = writeln!(
            s,
            "# the light panels (in the ceiling's plane) face down, furniture faces outward."
        );
        let _ = writeln!(s, "# The counts are made exact by: {tuning}.");
        let _ = writeln!(s, "# camera {}", room.camera());
        let _ = writeln!(s, "# patch-size {patch_size}");
        let _ = writeln!(s, "mtllib {mtl_file}");
        let mut base = 1;
        for p in &self.pieces {
            let _ = writeln!(s, "\no {}", p.name);
            for v in &p.vertices {
                let _ = writeln!(s, "v {} {} {}", decimal(v[0]), decimal(v[1]), decimal(v[2]));
            }
            let _ = writeln!(s, "usemtl {}", self.materials[p.material].name);
            for f in &p.faces {
                s.push('f');
                for &i in f {
                    let _ = write!(s, " {}", base + i);
                }
                s.push('\n');
            }
            base += p.vertices.len();
        }
        s
    }

    fn mtl_text(&self, room: Room) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# Materials of the \"{}\" room (src/scene/generate.rs). Kd = diffuse reflectance (linear RGB);",
            room.name()
        );
        let _ = writeln!(s, "# Ke = emitted radiance, front face only.");
        let c = |v: [f64; 3]| {
            v.map(|x| {
                let t = format!("{x:.3}");
                let t = t.trim_end_matches('0').trim_end_matches('.').to_string();
                if t.is_empty() {
                    "0".to_string()
                } else {
                    t
                }
            })
            .join(" ")
        };
        for m in &self.materials {
            let _ = writeln!(s, "\nnewmtl {}", m.name);
            let _ = writeln!(s, "Ka 0 0 0");
            let _ = writeln!(s, "Kd {}", c(m.kd));
            let _ = writeln!(s, "Ks 0 0 0");
            let _ = writeln!(s, "Ke {}", c(m.ke));
            let _ = writeln!(s, "illum 1");
        }
        s
    }
}

// ---------------------------------------------------------------------------------------------
// Tuning pieces

/// Height of rugs above the floor.
const RUG_Y: f64 = 0.004;

/// A shelf's free space, in its bookcase's frame.
#[derive(Clone, Copy)]
struct Shelf {
    fr: Frame,
    u0: f64,
    u1: f64,
    v0: f64,
    clearance: f64,
    w_back: f64,
    w_front: f64,
}

/// Where sheets of paper go: a loose stack on a desk top (frame at the top's height), its first
/// sheet's corner at (u0, w).
struct Papers {
    fr: Frame,
    u0: f64,
    w: f64,
    material: usize,
}

impl Papers {
    fn place(&self, b: &mut Builder, n: usize) {
        for k in 0..n {
            // Lying flat, 1 mm above the desk and each other, each shifted a little.
            let (u, w, y) = (
                self.u0 + 0.025 * k as f64,
                self.w - 0.02 * k as f64,
                0.001 * (k + 1) as f64,
            );
            b.lrect(
                &self.fr,
                "paper",
                self.material,
                [u, y, w],
                [u + 0.21, y, w + 0.297],
                TOP,
            );
        }
    }
}

struct RoundRug {
    x: f64,
    z: f64,
    radius: f64,
    material: usize,
}

/// A rectangle of (a − ½) × (b − ½) patch sizes, so exactly a·b patches. (min, preferred, max)
/// for each side in metres.
struct Tuner {
    kind: TunerKind,
    material: usize,
    a: (f64, f64, f64),
    b: (f64, f64, f64),
}

enum TunerKind {
    /// A rug on the floor centred at (x, z), side a along x.
    Rug { x: f64, z: f64 },
    /// A picture's canvas centred at (0, v) of a wall frame, at depth w, side a along u.
    Canvas { fr: Frame, v: f64, w: f64 },
}

impl Tuner {
    fn place(&self, b: &mut Builder, s: f64, na: u32, nb: u32) {
        let (la, lb) = ((na as f64 - 0.5) * s, (nb as f64 - 0.5) * s);
        match self.kind {
            TunerKind::Rug { x, z } => b.rect(
                "rug",
                self.material,
                [x - la / 2.0, RUG_Y, z - lb / 2.0],
                [x + la / 2.0, RUG_Y, z + lb / 2.0],
                PY,
            ),
            TunerKind::Canvas { fr, v, w } => b.lrect(
                &fr,
                "canvas",
                self.material,
                [-la / 2.0, v - lb / 2.0, w],
                [la / 2.0, v + lb / 2.0, w],
                FRONT,
            ),
        }
    }

    /// (min, preferred, max) sides in patches: sides of (n − ½) patch sizes within the range.
    fn range(side: (f64, f64, f64), s: f64) -> (u32, u32, u32) {
        let n = |m: f64| m / s + 0.5;
        (
            n(side.0).ceil() as u32,
            n(side.1).round() as u32,
            n(side.2).floor() as u32,
        )
    }
}

struct Plan {
    shelves: Vec<Shelf>,
    books: Vec<usize>,
    papers: Papers,
    round_rug: RoundRug,
    tuners: [Tuner; 2],
}

/// `count` books spread evenly over the shelves (from the left on every other shelf, from the
/// right on the others), each a box without its bottom (5 faces).
fn fill_books(
    b: &mut Builder,
    rng: &mut SplitMix,
    shelves: &[Shelf],
    mats: &[usize],
    count: usize,
) {
    let n = shelves.len();
    let mut placed = 0;
    for (i, s) in shelves.iter().enumerate() {
        // This shelf's share, plus whatever earlier shelves could not hold.
        let want = count * (i + 1) / n - placed;
        let mut books = Vec::new();
        let mut width = 0.0;
        while books.len() < want {
            let t = rng.mm(0.018, 0.048);
            if width + t > s.u1 - s.u0 - 0.008 {
                break;
            }
            let h = rng.mm(0.17, (s.clearance - 0.03).min(0.3));
            let d = rng.mm(0.14, (s.w_front - s.w_back - 0.02).min(0.24));
            books.push((t, h, d, rng.pick(mats)));
            width += t + 0.002;
        }
        let mut u = if i % 2 == 0 {
            s.u0 + 0.004
        } else {
            s.u1 - 0.004 - width
        };
        let front = s.w_front - 0.012;
        for (t, h, d, m) in books {
            b.lbox(
                &s.fr,
                "book",
                m,
                [u, s.v0, front - d],
                [u + t, s.v0 + h, front],
                BOTTOM,
            );
            u += t + 0.002;
            placed += 1;
        }
    }
    assert_eq!(
        placed, count,
        "the bookcases hold {placed} books, {count} are needed"
    );
}

// ---------------------------------------------------------------------------------------------
// Materials

struct Pal {
    light: usize,
    ceiling: usize,
    skirting: usize,
    oak: Vec<usize>,
    wood: usize,
    walnut: usize,
    white: usize,
    black: usize,
    steel: usize,
    glass: usize,
    paper: usize,
    cream: usize,
    terracotta: usize,
    leaf: usize,
    leaf_dark: usize,
    books: Vec<usize>,
    blue: usize,
    red: usize,
    grey: usize,
    green: usize,
    mustard: usize,
    rug_red: usize,
    rug_blue: usize,
    canvas: usize,
    frame: usize,
    ceramic: usize,
    screen: usize,
    brass: usize,
}

fn palette(b: &mut Builder) -> Pal {
    Pal {
        light: b.emitter("light", [0.78; 3], [16.0, 14.0, 11.0]),
        ceiling: b.material("ceiling", [0.82, 0.82, 0.8]),
        skirting: b.material("skirting", [0.85, 0.84, 0.8]),
        oak: vec![
            b.material("oak_a", [0.56, 0.4, 0.24]),
            b.material("oak_b", [0.5, 0.35, 0.2]),
            b.material("oak_c", [0.6, 0.44, 0.27]),
        ],
        wood: b.material("wood", [0.66, 0.5, 0.32]),
        walnut: b.material("walnut", [0.34, 0.21, 0.12]),
        white: b.material("white_paint", [0.8, 0.8, 0.78]),
        black: b.material("black", [0.05, 0.05, 0.055]),
        steel: b.material("steel", [0.55, 0.56, 0.58]),
        glass: b.material("window_glass", [0.55, 0.66, 0.78]),
        paper: b.material("paper", [0.88, 0.88, 0.85]),
        cream: b.material("cream", [0.85, 0.8, 0.68]),
        terracotta: b.material("terracotta", [0.62, 0.3, 0.17]),
        leaf: b.material("leaf", [0.2, 0.45, 0.14]),
        leaf_dark: b.material("leaf_dark", [0.12, 0.32, 0.1]),
        books: vec![
            b.material("book_red", [0.55, 0.1, 0.08]),
            b.material("book_blue", [0.1, 0.2, 0.5]),
            b.material("book_green", [0.12, 0.38, 0.18]),
            b.material("book_ochre", [0.7, 0.52, 0.16]),
            b.material("book_cream", [0.8, 0.76, 0.62]),
            b.material("book_black", [0.08, 0.08, 0.09]),
            b.material("book_teal", [0.1, 0.42, 0.45]),
            b.material("book_brown", [0.4, 0.24, 0.14]),
        ],
        blue: b.material("fabric_blue", [0.16, 0.26, 0.5]),
        red: b.material("fabric_red", [0.6, 0.14, 0.1]),
        grey: b.material("fabric_grey", [0.45, 0.45, 0.46]),
        green: b.material("fabric_green", [0.25, 0.42, 0.26]),
        mustard: b.material("fabric_mustard", [0.75, 0.56, 0.15]),
        rug_red: b.material("rug_red", [0.58, 0.16, 0.12]),
        rug_blue: b.material("rug_blue", [0.2, 0.3, 0.52]),
        canvas: b.material("canvas", [0.72, 0.5, 0.28]),
        frame: b.material("picture_frame", [0.2, 0.14, 0.09]),
        ceramic: b.material("ceramic", [0.86, 0.86, 0.84]),
        screen: b.material("screen", [0.03, 0.03, 0.04]),
        brass: b.material("brass", [0.7, 0.55, 0.25]),
    }
}

// ---------------------------------------------------------------------------------------------
// Rooms: floor, ceiling with light panels, walls with a dado, skirting boards, doorways

const DADO: f64 = 0.9;
const SKIRT_H: f64 = 0.08;
const SKIRT_D: f64 = 0.015;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    North,
    South,
    East,
    West,
}

/// A room's inside: x from x0 to x1, z from z0 (south) to z1 (north), floor at y = 0.
#[derive(Clone, Copy, Debug)]
struct RoomRect {
    name: &'static str,
    x0: f64,
    x1: f64,
    z0: f64,
    z1: f64,
}

impl RoomRect {
    /// A frame on a wall, `gap` in front of it, facing into the room; `at` is the world x (north
    /// and south walls) or z (east and west walls).
    fn wall(&self, side: Side, at: f64, gap: f64) -> Frame {
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
struct Opening {
    side: Side,
    lo: f64,
    hi: f64,
    height: f64,
}

enum Floor {
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

struct Finish {
    wall: usize,
    dado: usize,
    floor: Floor,
    ceiling_tile: f64,
    /// Light panels as tile ranges of the ceiling grid: [i0, j0, ni, nj] (i along x, j along z).
    lights: Vec<[usize; 4]>,
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

fn shell(
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
/// threshold), facing into it. `along_x`: the passage runs along x, from x = a to x = c, and
/// spans [lo, hi] in z; otherwise along z, spanning [lo, hi] in x.
#[allow(clippy::too_many_arguments)]
fn doorway(
    b: &mut Builder,
    m: usize,
    floor: usize,
    along_x: bool,
    a: f64,
    c: f64,
    lo: f64,
    hi: f64,
    height: f64,
) {
    let faces = if along_x {
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
    let (lo3, hi3) = if along_x {
        ([a, 0.0, lo], [c, height, hi])
    } else {
        ([lo, 0.0, a], [hi, height, c])
    };
    b.rect("doorway_floor", floor, lo3, [hi3[0], 0.0, hi3[2]], PY);
    b.interior.push((lo3, hi3));
}

// ---------------------------------------------------------------------------------------------
// Furniture, each in a local frame: u across (centred), v up, w from the back (0) to the front.

/// A table: top and four legs.
#[allow(clippy::too_many_arguments)]
fn table(
    b: &mut Builder,
    fr: &Frame,
    name: &str,
    w: f64,
    d: f64,
    h: f64,
    top: usize,
    legs: usize,
    leg: f64,
) {
    let t = 0.035;
    b.lbox(fr, name, top, [-w / 2.0, h - t, 0.0], [w / 2.0, h, d], 0);
    let inset = 0.04;
    for (u, ww) in [
        (-w / 2.0 + inset, inset),
        (w / 2.0 - inset - leg, inset),
        (-w / 2.0 + inset, d - inset - leg),
        (w / 2.0 - inset - leg, d - inset - leg),
    ] {
        b.lbox(
            fr,
            &format!("{name}_leg"),
            legs,
            [u, 0.0, ww],
            [u + leg, h - t, ww + leg],
            TOP | BOTTOM,
        );
    }
}

/// A chair facing +w: legs, seat, back posts and two slats.
fn chair(b: &mut Builder, fr: &Frame, wood: usize, seat: usize) {
    let (w, d, sh, leg) = (0.44, 0.44, 0.46, 0.035);
    let st = 0.04;
    b.lbox(
        fr,
        "chair_seat",
        seat,
        [-w / 2.0, sh - st, 0.0],
        [w / 2.0, sh, d],
        0,
    );
    for (u, ww) in [
        (-w / 2.0 + 0.01, 0.01),
        (w / 2.0 - 0.01 - leg, 0.01),
        (-w / 2.0 + 0.01, d - 0.01 - leg),
        (w / 2.0 - 0.01 - leg, d - 0.01 - leg),
    ] {
        b.lbox(
            fr,
            "chair_leg",
            wood,
            [u, 0.0, ww],
            [u + leg, sh - st, ww + leg],
            TOP | BOTTOM,
        );
    }
    let (p0, p1) = (0.01, 0.01 + leg);
    for u in [-w / 2.0 + 0.01, w / 2.0 - 0.01 - leg] {
        b.lbox(
            fr,
            "chair_post",
            wood,
            [u, sh, p0],
            [u + leg, 0.92, p1],
            BOTTOM,
        );
    }
    for (v0, v1) in [(0.62, 0.7), (0.8, 0.88)] {
        b.lbox(
            fr,
            "chair_slat",
            wood,
            [-w / 2.0 + 0.01 + leg, v0, p0 + 0.008],
            [w / 2.0 - 0.01 - leg, v1, p1 - 0.008],
            LEFT | RIGHT,
        );
    }
}

/// A bookcase against a wall (back at w = 0); returns its shelves' free spaces.
#[allow(clippy::too_many_arguments)]
fn bookcase(
    b: &mut Builder,
    fr: &Frame,
    w: f64,
    h: f64,
    d: f64,
    rows: usize,
    m: usize,
    back: usize,
) -> Vec<Shelf> {
    let t = 0.02;
    let (ul, ur) = (-w / 2.0, w / 2.0);
    b.lbox(
        fr,
        "bookcase_side",
        m,
        [ul, 0.0, 0.0],
        [ul + t, h, d],
        BOTTOM,
    );
    b.lbox(
        fr,
        "bookcase_side",
        m,
        [ur - t, 0.0, 0.0],
        [ur, h, d],
        BOTTOM,
    );
    b.lbox(
        fr,
        "bookcase_top",
        m,
        [ul + t, h - t, 0.0],
        [ur - t, h, d],
        LEFT | RIGHT,
    );
    b.lrect(
        fr,
        "bookcase_back",
        back,
        [ul + t, 0.08, 0.0],
        [ur - t, h - t, 0.01],
        FRONT,
    );
    b.lbox(
        fr,
        "bookcase_plinth",
        m,
        [ul + t, 0.0, d - 0.03],
        [ur - t, 0.08, d - 0.01],
        LEFT | RIGHT | BOTTOM,
    );
    let bottom = 0.08;
    let pitch = (h - t - bottom) / rows as f64;
    let mut shelves = Vec::new();
    for k in 0..rows {
        let v = bottom + k as f64 * pitch;
        let omit = if k == 0 {
            LEFT | RIGHT | BACK | BOTTOM
        } else {
            LEFT | RIGHT | BACK
        };
        b.lbox(
            fr,
            "bookcase_shelf",
            m,
            [ul + t, v, 0.01],
            [ur - t, v + t, d - 0.01],
            omit,
        );
        shelves.push(Shelf {
            fr: *fr,
            u0: ul + t,
            u1: ur - t,
            v0: v + t,
            clearance: pitch - t,
            w_back: 0.01,
            w_front: d - 0.01,
        });
    }
    shelves
}

#[derive(Clone, Copy)]
enum Fronts {
    Doors(usize),
    Drawers(usize),
}

/// A cabinet against a wall: recessed plinth, carcass, doors or drawers with handles.
#[allow(clippy::too_many_arguments)]
fn cabinet(
    b: &mut Builder,
    fr: &Frame,
    w: f64,
    h: f64,
    d: f64,
    body: usize,
    front: usize,
    fronts: Fronts,
    handle: usize,
) {
    let plinth = 0.08;
    b.lbox(
        fr,
        "cabinet_plinth",
        body,
        [-w / 2.0 + 0.03, 0.0, 0.03],
        [w / 2.0 - 0.03, plinth, d - 0.07],
        TOP | BOTTOM | BACK,
    );
    b.lbox(
        fr,
        "cabinet",
        body,
        [-w / 2.0, plinth, 0.0],
        [w / 2.0, h, d - 0.02],
        BACK | BOTTOM,
    );
    let (v0, v1) = (plinth + 0.01, h - 0.01);
    match fronts {
        Fronts::Doors(n) => {
            let dw = w / n as f64;
            for k in 0..n {
                let u0 = -w / 2.0 + k as f64 * dw + 0.003;
                let u1 = u0 + dw - 0.006;
                b.lbox(
                    fr,
                    "cabinet_door",
                    front,
                    [u0, v0, d - 0.02],
                    [u1, v1, d],
                    BACK,
                );
                // Handles near the meeting edges.
                let hu = if k % 2 == 0 { u1 - 0.05 } else { u0 + 0.03 };
                let hv = (v1 - 0.12).min(1.05);
                b.lbox(
                    fr,
                    "handle",
                    handle,
                    [hu, hv - 0.12, d],
                    [hu + 0.02, hv, d + 0.025],
                    BACK,
                );
            }
        }
        Fronts::Drawers(n) => {
            let dh = (v1 - v0) / n as f64;
            for k in 0..n {
                let a = v0 + k as f64 * dh + 0.003;
                let c = a + dh - 0.006;
                b.lbox(
                    fr,
                    "drawer",
                    front,
                    [-w / 2.0 + 0.003, a, d - 0.02],
                    [w / 2.0 - 0.003, c, d],
                    BACK,
                );
                let hv = c - 0.05;
                b.lbox(
                    fr,
                    "handle",
                    handle,
                    [-0.06, hv - 0.02, d],
                    [0.06, hv, d + 0.025],
                    BACK,
                );
            }
        }
    }
}

/// A sofa (or an armchair) against its back: base, arms, back, seat and back cushions.
#[allow(clippy::too_many_arguments)]
fn sofa(b: &mut Builder, fr: &Frame, w: f64, d: f64, body: usize, cushion: usize, seats: usize) {
    let arm = 0.18;
    let (ul, ur) = (-w / 2.0, w / 2.0);
    b.lbox(
        fr,
        "sofa_base",
        body,
        [ul + arm, 0.06, 0.0],
        [ur - arm, 0.4, d],
        BOTTOM | LEFT | RIGHT,
    );
    for (a, c) in [(ul, ul + arm), (ur - arm, ur)] {
        b.lbox(fr, "sofa_arm", body, [a, 0.0, 0.0], [c, 0.64, d], BOTTOM);
    }
    b.lbox(
        fr,
        "sofa_back",
        body,
        [ul + arm, 0.4, 0.0],
        [ur - arm, 0.86, 0.2],
        BOTTOM | LEFT | RIGHT,
    );
    let inner = (ur - ul - 2.0 * arm) / seats as f64;
    for k in 0..seats {
        let a = ul + arm + k as f64 * inner + 0.005;
        let c = a + inner - 0.01;
        b.lbox(
            fr,
            "sofa_cushion",
            cushion,
            [a, 0.4, 0.2],
            [c, 0.53, d - 0.02],
            BOTTOM,
        );
        b.lbox(
            fr,
            "sofa_cushion",
            cushion,
            [a, 0.53, 0.2],
            [c, 0.82, 0.34],
            BOTTOM,
        );
    }
    // Little feet under the base.
    for u in [ul + arm + 0.03, ur - arm - 0.07] {
        for ww in [0.04, d - 0.08] {
            b.lbox(
                fr,
                "sofa_foot",
                body,
                [u, 0.0, ww],
                [u + 0.04, 0.06, ww + 0.04],
                TOP | BOTTOM,
            );
        }
    }
}

/// A bed with its head at w = 0: headboard, frame on legs, mattress, duvet, pillows.
#[allow(clippy::too_many_arguments)]
fn bed(
    b: &mut Builder,
    fr: &Frame,
    w: f64,
    l: f64,
    wood: usize,
    sheet: usize,
    duvet: usize,
    pillow: usize,
) {
    b.lbox(
        fr,
        "headboard",
        wood,
        [-w / 2.0 - 0.03, 0.0, 0.0],
        [w / 2.0 + 0.03, 1.05, 0.06],
        BOTTOM,
    );
    b.lbox(
        fr,
        "bed_frame",
        wood,
        [-w / 2.0, 0.12, 0.06],
        [w / 2.0, 0.34, l + 0.06],
        BACK,
    );
    for u in [-w / 2.0 + 0.02, w / 2.0 - 0.07] {
        for ww in [0.08, l + 0.06 - 0.07] {
            b.lbox(
                fr,
                "bed_leg",
                wood,
                [u, 0.0, ww],
                [u + 0.05, 0.12, ww + 0.05],
                TOP | BOTTOM,
            );
        }
    }
    b.lbox(
        fr,
        "mattress",
        sheet,
        [-w / 2.0 + 0.02, 0.34, 0.08],
        [w / 2.0 - 0.02, 0.54, l + 0.04],
        BOTTOM,
    );
    b.lbox(
        fr,
        "duvet",
        duvet,
        [-w / 2.0, 0.54, 0.62],
        [w / 2.0, 0.6, l + 0.06],
        BOTTOM,
    );
    let n = if w > 1.2 { 2 } else { 1 };
    let pw = (w - 0.16) / n as f64;
    for k in 0..n {
        let a = -w / 2.0 + 0.08 + k as f64 * pw + 0.02;
        b.lbox(
            fr,
            "pillow",
            pillow,
            [a, 0.54, 0.14],
            [a + pw - 0.04, 0.66, 0.52],
            BOTTOM,
        );
    }
}

/// A potted plant standing at local (0, 0, 0) of `fr`: pot, soil, and a stylised shrub.
fn plant(b: &mut Builder, fr: &Frame, p: &Pal, r: f64, height: f64) {
    let pot_h = 0.4 * r.max(0.2) / 0.2 * 0.8;
    b.lcylinder(
        fr,
        "pot",
        p.terracotta,
        [0.0, 0.0, 0.0],
        r,
        pot_h,
        12,
        TOP,
        true,
    );
    b.lbox(
        fr,
        "plant_stem",
        p.walnut,
        [-0.02, pot_h, -0.02],
        [0.02, pot_h + 0.25, 0.02],
        BOTTOM | TOP,
    );
    let mut y = pot_h + 0.25;
    let mut rr = r * 1.6;
    let layers = ((height - y) / 0.3).round().max(1.0) as usize;
    let lh = (height - y) / layers as f64;
    for k in 0..layers {
        let m = if k % 2 == 0 { p.leaf } else { p.leaf_dark };
        let caps = if k == 0 { TOP | BOTTOM } else { TOP };
        b.lcylinder(fr, "foliage", m, [0.0, y, 0.0], rr, lh, 10, caps, true);
        y += lh;
        rr *= 0.78;
    }
}

/// A floor lamp (not a light source): base disc, pole, shade.
fn floor_lamp(b: &mut Builder, fr: &Frame, p: &Pal, shade: usize) {
    b.lcylinder(
        fr,
        "lamp_base",
        p.black,
        [0.0, 0.0, 0.0],
        0.16,
        0.03,
        32,
        TOP,
        true,
    );
    b.lcylinder(
        fr,
        "lamp_pole",
        p.steel,
        [0.0, 0.03, 0.0],
        0.015,
        1.32,
        8,
        0,
        true,
    );
    b.lcylinder(
        fr,
        "lamp_shade",
        shade,
        [0.0, 1.35, 0.0],
        0.22,
        0.3,
        32,
        TOP | BOTTOM,
        true,
    );
}

/// A small table lamp standing at local (0, 0, 0).
fn table_lamp(b: &mut Builder, fr: &Frame, p: &Pal, shade: usize, n: usize) {
    b.lcylinder(
        fr,
        "lamp_base",
        p.ceramic,
        [0.0, 0.0, 0.0],
        0.07,
        0.22,
        n * 3 / 4,
        TOP,
        true,
    );
    b.lcylinder(
        fr,
        "lamp_pole",
        p.brass,
        [0.0, 0.22, 0.0],
        0.01,
        0.1,
        6,
        0,
        true,
    );
    b.lcylinder(
        fr,
        "lamp_shade",
        shade,
        [0.0, 0.32, 0.0],
        0.15,
        0.2,
        n,
        TOP | BOTTOM,
        true,
    );
}

/// A window on a wall frame (the wall at w = 0): glass, frame, mullion, sill, curtains on a rod.
#[allow(clippy::too_many_arguments)]
fn window(
    b: &mut Builder,
    fr: &Frame,
    p: &Pal,
    w: f64,
    y0: f64,
    y1: f64,
    room_h: f64,
    curtain: usize,
) {
    let (ul, ur) = (-w / 2.0, w / 2.0);
    let f = 0.06;
    b.lrect(
        fr,
        "window_glass",
        p.glass,
        [ul, y0, 0.002],
        [ur, y1, 0.002],
        FRONT,
    );
    b.lbox(
        fr,
        "window_frame",
        p.white,
        [ul - f, y0 - f, 0.0],
        [ul, y1 + f, 0.05],
        BACK,
    );
    b.lbox(
        fr,
        "window_frame",
        p.white,
        [ur, y0 - f, 0.0],
        [ur + f, y1 + f, 0.05],
        BACK,
    );
    b.lbox(
        fr,
        "window_frame",
        p.white,
        [ul, y1, 0.0],
        [ur, y1 + f, 0.05],
        BACK | LEFT | RIGHT,
    );
    b.lbox(
        fr,
        "window_frame",
        p.white,
        [ul, y0 - f, 0.0],
        [ur, y0, 0.05],
        BACK | LEFT | RIGHT,
    );
    b.lbox(
        fr,
        "window_mullion",
        p.white,
        [-0.02, y0, 0.0],
        [0.02, y1, 0.035],
        BACK | TOP | BOTTOM,
    );
    b.lbox(
        fr,
        "window_sill",
        p.white,
        [ul - f - 0.04, y0 - f - 0.04, 0.0],
        [ur + f + 0.04, y0 - f, 0.16],
        BACK,
    );
    let rod = room_h - 0.12;
    b.lbox(
        fr,
        "curtain_rod",
        p.steel,
        [ul - 0.6, rod, 0.2],
        [ur + 0.6, rod + 0.025, 0.225],
        0,
    );
    for (a, c) in [(ul - 0.55, ul - 0.12), (ur + 0.12, ur + 0.55)] {
        b.lbox(
            fr,
            "curtain",
            curtain,
            [a, 0.03, 0.23],
            [c, rod - 0.005, 0.29],
            0,
        );
    }
}

/// A closed door on a wall frame: leaf, two raised panels, handle, architrave.
fn door(b: &mut Builder, fr: &Frame, p: &Pal, leaf: usize) {
    let (w, h) = (0.9, 2.05);
    b.lrect(
        fr,
        "door_leaf",
        leaf,
        [-w / 2.0, 0.0, 0.03],
        [w / 2.0, h, 0.03],
        FRONT,
    );
    b.lbox(
        fr,
        "door_panel",
        leaf,
        [-0.33, 1.1, 0.03],
        [0.33, 1.9, 0.045],
        BACK,
    );
    b.lbox(
        fr,
        "door_panel",
        leaf,
        [-0.33, 0.15, 0.03],
        [0.33, 0.95, 0.045],
        BACK,
    );
    b.lbox(
        fr,
        "door_handle",
        p.brass,
        [0.32, 1.0, 0.045],
        [0.42, 1.03, 0.09],
        BACK,
    );
    b.lbox(
        fr,
        "architrave",
        p.white,
        [-w / 2.0 - 0.07, 0.0, 0.0],
        [-w / 2.0, h, 0.04],
        BACK | BOTTOM | TOP,
    );
    b.lbox(
        fr,
        "architrave",
        p.white,
        [w / 2.0, 0.0, 0.0],
        [w / 2.0 + 0.07, h, 0.04],
        BACK | BOTTOM | TOP,
    );
    b.lbox(
        fr,
        "architrave",
        p.white,
        [-w / 2.0 - 0.07, h, 0.0],
        [w / 2.0 + 0.07, h + 0.07, 0.04],
        BACK,
    );
    // The wall's depth between leaf and architrave: the leaf's jambs.
    b.lrect(
        fr,
        "door_jamb",
        p.white,
        [-w / 2.0, 0.0, 0.0],
        [-w / 2.0, h, 0.03],
        RIGHT,
    );
    b.lrect(
        fr,
        "door_jamb",
        p.white,
        [w / 2.0, 0.0, 0.0],
        [w / 2.0, h, 0.03],
        LEFT,
    );
    b.lrect(
        fr,
        "door_jamb",
        p.white,
        [-w / 2.0, h, 0.0],
        [w / 2.0, h, 0.03],
        BOTTOM,
    );
}

/// A picture on a wall frame, with a fixed canvas.
#[allow(clippy::too_many_arguments)]
fn picture(b: &mut Builder, fr: &Frame, p: &Pal, v: f64, w: f64, h: f64, canvas: usize) {
    b.lbox(
        fr,
        "picture_frame",
        p.frame,
        [-w / 2.0 - 0.04, v - h / 2.0 - 0.04, 0.0],
        [w / 2.0 + 0.04, v + h / 2.0 + 0.04, 0.03],
        BACK,
    );
    b.lrect(
        fr,
        "canvas",
        canvas,
        [-w / 2.0, v - h / 2.0, 0.032],
        [w / 2.0, v + h / 2.0, 0.032],
        FRONT,
    );
}

/// A television on a wall frame's surface at height v0: screen box on a foot.
fn television(b: &mut Builder, fr: &Frame, p: &Pal, v0: f64, w: f64) {
    let h = w * 9.0 / 16.0;
    b.lbox(
        fr,
        "tv_foot",
        p.black,
        [-0.15, v0, 0.05],
        [0.15, v0 + 0.02, 0.25],
        BOTTOM,
    );
    b.lbox(
        fr,
        "tv_neck",
        p.black,
        [-0.03, v0 + 0.02, 0.12],
        [0.03, v0 + 0.08, 0.16],
        BOTTOM | TOP,
    );
    b.lbox(
        fr,
        "tv",
        p.black,
        [-w / 2.0, v0 + 0.08, 0.1],
        [w / 2.0, v0 + 0.08 + h, 0.16],
        0,
    );
    b.lrect(
        fr,
        "tv_screen",
        p.screen,
        [-w / 2.0 + 0.015, v0 + 0.095, 0.161],
        [w / 2.0 - 0.015, v0 + 0.065 + h, 0.161],
        FRONT,
    );
}

/// A computer monitor, keyboard and a mug on a desk (frame at the desk top, back at w = 0).
fn computer(b: &mut Builder, fr: &Frame, p: &Pal) {
    b.lbox(
        fr,
        "monitor_foot",
        p.black,
        [-0.11, 0.0, 0.06],
        [0.11, 0.015, 0.22],
        BOTTOM,
    );
    b.lbox(
        fr,
        "monitor_neck",
        p.black,
        [-0.025, 0.015, 0.1],
        [0.025, 0.12, 0.13],
        BOTTOM | TOP,
    );
    b.lbox(
        fr,
        "monitor",
        p.black,
        [-0.3, 0.12, 0.08],
        [0.3, 0.47, 0.13],
        0,
    );
    b.lrect(
        fr,
        "monitor_screen",
        p.screen,
        [-0.285, 0.135, 0.131],
        [0.285, 0.455, 0.131],
        FRONT,
    );
    b.lbox(
        fr,
        "keyboard",
        p.grey,
        [-0.22, 0.0, 0.3],
        [0.22, 0.02, 0.45],
        BOTTOM,
    );
    b.lcylinder(
        fr,
        "mug",
        p.ceramic,
        [0.34, 0.0, 0.38],
        0.04,
        0.1,
        12,
        TOP,
        true,
    );
}

/// A wall clock: a disc with two hands.
fn clock(b: &mut Builder, fr: &Frame, p: &Pal, v: f64, r: f64, n: usize) {
    b.vdisc(fr, "clock", p.cream, 0.0, v, 0.03, r, n);
    b.lrect(
        fr,
        "clock_hand",
        p.black,
        [-0.006, v, 0.032],
        [0.006, v + 0.7 * r, 0.032],
        FRONT,
    );
    b.lrect(
        fr,
        "clock_hand",
        p.black,
        [0.0, v - 0.006, 0.033],
        [0.5 * r, v + 0.006, 0.033],
        FRONT,
    );
}

// ---------------------------------------------------------------------------------------------
// The simple room: a study / living room, 5.4 m × 4.4 m × 2.7 m, two light panels

fn simple(b: &mut Builder, rng: &mut SplitMix) -> Plan {
    let p = palette(b);
    let h = 2.7;
    let room = RoomRect {
        name: "study",
        x0: 0.0,
        x1: 5.4,
        z0: 0.0,
        z1: 4.4,
    };
    let finish = Finish {
        wall: b.material("wall_warm", [0.82, 0.77, 0.66]),
        dado: b.material("dado_sage", [0.5, 0.6, 0.52]),
        floor: Floor::Planks {
            width: 0.18,
            length: 1.2,
            mats: p.oak.clone(),
        },
        ceiling_tile: 0.6,
        // Two 0.6 × 1.2 m panels, symmetric about the room's centre.
        lights: vec![[2, 3, 1, 2], [6, 3, 1, 2]],
    };
    shell(b, rng, &p, &room, h, &finish, &[]);

    // North wall: two bookcases, a low cabinet with a lamp, a door; a plant in the corner.
    let mut shelves = Vec::new();
    // (Their boards share corners: fewer vertices, see the module's notes.)
    b.shared = true;
    for x in [1.0, 2.06] {
        let fr = room.wall(Side::North, x, 0.01);
        shelves.extend(bookcase(b, &fr, 1.0, 2.1, 0.34, 6, p.walnut, p.wood));
    }
    b.shared = false;
    let fr = room.wall(Side::North, 3.1, 0.01);
    cabinet(
        b,
        &fr,
        0.9,
        0.8,
        0.45,
        p.white,
        p.white,
        Fronts::Doors(2),
        p.brass,
    );
    table_lamp(b, &fr.at(0.2, 0.8, 0.22), &p, p.cream, 16);
    clock(b, &room.wall(Side::North, 3.1, 0.0), &p, 1.75, 0.16, 16);
    door(b, &room.wall(Side::North, 4.25, 0.0), &p, p.wood);
    plant(b, &Frame::new(5.05, 0.0, 4.05, Facing::NegZ), &p, 0.2, 1.3);

    // West wall: a window with curtains, a desk under it with a computer and a chair, a filing
    // cabinet in the corner.
    let wf = room.wall(Side::West, 2.2, 0.0);
    window(b, &wf, &p, 1.6, 1.0, 2.2, h, p.green);
    let desk = room.wall(Side::West, 2.2, 0.02);
    table(b, &desk, "desk", 1.4, 0.7, 0.75, p.wood, p.walnut, 0.05);
    computer(b, &desk.at(0.1, 0.75, 0.1), &p);
    let papers = Papers {
        fr: desk.at(0.0, 0.75, 0.0),
        u0: -0.62,
        w: 0.33,
        material: p.paper,
    };
    chair(
        b,
        &Frame::new(1.08, 0.0, 2.2, Facing::NegX),
        p.walnut,
        p.red,
    );
    cabinet(
        b,
        &room.wall(Side::West, 0.45, 0.01),
        0.45,
        0.72,
        0.55,
        p.grey,
        p.grey,
        Fronts::Drawers(3),
        p.steel,
    );

    // East wall: a sofa under a picture (the tuned canvas), a side table with a lamp, a plant.
    let ef = room.wall(Side::East, 2.2, 0.02);
    b.shared = true;
    sofa(b, &ef, 2.1, 0.88, p.blue, p.blue, 3);
    b.shared = false;
    let canvas = Tuner {
        kind: TunerKind::Canvas {
            fr: room.wall(Side::East, 2.2, 0.0),
            v: 1.62,
            w: 0.032,
        },
        material: p.canvas,
        a: (0.7, 1.0, 1.4),
        b: (0.45, 0.7, 0.9),
    };
    let (cw, ch) = (canvas.a.2, canvas.b.2);
    b.lbox(
        &room.wall(Side::East, 2.2, 0.0),
        "picture_frame",
        p.frame,
        [-cw / 2.0 - 0.05, 1.62 - ch / 2.0 - 0.05, 0.0],
        [cw / 2.0 + 0.05, 1.62 + ch / 2.0 + 0.05, 0.03],
        BACK,
    );
    let side = room.wall(Side::East, 0.62, 0.02);
    table(
        b,
        &side,
        "side_table",
        0.45,
        0.45,
        0.55,
        p.walnut,
        p.walnut,
        0.04,
    );
    table_lamp(b, &side.at(0.0, 0.55, 0.22), &p, p.cream, 16);

    // In the middle: a coffee table on the tuned rug; the round rug by the desk.
    let coffee = Frame::new(3.95, 0.0, 2.2, Facing::NegX);
    table(
        b,
        &coffee.at(0.0, 0.0, -0.3),
        "coffee_table",
        1.1,
        0.6,
        0.42,
        p.walnut,
        p.walnut,
        0.05,
    );
    b.lbox(
        &coffee.at(-0.25, 0.42, -0.1),
        "coffee_book",
        p.books[1],
        [0.0, 0.0, 0.0],
        [0.3, 0.04, 0.22],
        BOTTOM,
    );
    let rug = Tuner {
        kind: TunerKind::Rug { x: 3.75, z: 2.2 },
        material: p.rug_red,
        a: (0.9, 1.2, 1.5),
        b: (1.4, 2.0, 2.6),
    };

    // South wall (behind the camera): a sideboard with a television.
    let sf = room.wall(Side::South, 2.7, 0.01);
    cabinet(
        b,
        &sf,
        1.6,
        0.55,
        0.45,
        p.walnut,
        p.walnut,
        Fronts::Doors(4),
        p.brass,
    );
    television(b, &sf.at(0.0, 0.55, 0.0), &p, 0.0, 1.0);

    Plan {
        shelves,
        books: p.books.clone(),
        papers,
        round_rug: RoundRug {
            x: 1.45,
            z: 2.2,
            radius: 0.72,
            material: p.rug_blue,
        },
        tuners: [rug, canvas],
    }
}

// ---------------------------------------------------------------------------------------------
// The complex room: a four-room flat (living room, kitchen-diner, bedroom, study), 11 m × 8.6 m,
// six light panels

fn complex(b: &mut Builder, rng: &mut SplitMix) -> Plan {
    let p = palette(b);
    let h = 2.7;
    let t = 0.15; // inner walls
    let living = RoomRect {
        name: "living",
        x0: 0.0,
        x1: 6.0,
        z0: 0.0,
        z1: 4.6,
    };
    let kitchen = RoomRect {
        name: "kitchen",
        x0: 6.0 + t,
        x1: 11.0,
        z0: 0.0,
        z1: 4.6,
    };
    let bedroom = RoomRect {
        name: "bedroom",
        x0: 0.0,
        x1: 4.6,
        z0: 4.6 + t,
        z1: 8.6,
    };
    let study = RoomRect {
        name: "study",
        x0: 4.6 + t,
        x1: 11.0,
        z0: 4.6 + t,
        z1: 8.6,
    };
    // Doorways: living-kitchen (wide), living-bedroom, living-study.
    let (lk, lb, ls) = ((1.2, 2.8, 2.25), (3.5, 4.35, 2.05), (5.05, 5.9, 2.05));
    doorway(
        b, p.white, p.oak[0], true, living.x1, kitchen.x0, lk.0, lk.1, lk.2,
    );
    doorway(
        b, p.white, p.oak[0], false, living.z1, bedroom.z0, lb.0, lb.1, lb.2,
    );
    doorway(
        b, p.white, p.oak[0], false, living.z1, study.z0, ls.0, ls.1, ls.2,
    );
    let planks = |p: &Pal| Floor::Planks {
        width: 0.18,
        length: 1.2,
        mats: p.oak.clone(),
    };
    let f_living = Finish {
        wall: b.material("wall_warm", [0.82, 0.77, 0.66]),
        dado: b.material("dado_sage", [0.5, 0.6, 0.52]),
        floor: planks(&p),
        ceiling_tile: 0.6,
        lights: vec![[2, 3, 1, 2], [7, 3, 1, 2]],
    };
    let f_kitchen = Finish {
        wall: b.material("wall_yellow", [0.86, 0.8, 0.56]),
        dado: b.material("dado_white", [0.8, 0.8, 0.76]),
        floor: Floor::Tiles {
            size: 0.4,
            mats: [
                b.material("tile_light", [0.78, 0.76, 0.72]),
                b.material("tile_dark", [0.3, 0.3, 0.33]),
            ],
        },
        ceiling_tile: 0.6,
        lights: vec![[2, 3, 2, 1], [5, 3, 1, 2]],
    };
    let f_bedroom = Finish {
        wall: b.material("wall_blue", [0.62, 0.7, 0.8]),
        dado: b.material("dado_blue", [0.4, 0.5, 0.64]),
        floor: planks(&p),
        ceiling_tile: 0.6,
        lights: vec![[3, 3, 2, 1]],
    };
    let f_study = Finish {
        wall: b.material("wall_green", [0.66, 0.74, 0.6]),
        dado: b.material("dado_green", [0.36, 0.46, 0.34]),
        floor: planks(&p),
        ceiling_tile: 0.6,
        lights: vec![[5, 2, 2, 1]],
    };
    let open = |side, lo, hi, height| Opening {
        side,
        lo,
        hi,
        height,
    };
    shell(
        b,
        rng,
        &p,
        &living,
        h,
        &f_living,
        &[
            open(Side::East, lk.0, lk.1, lk.2),
            open(Side::North, lb.0, lb.1, lb.2),
            open(Side::North, ls.0, ls.1, ls.2),
        ],
    );
    shell(
        b,
        rng,
        &p,
        &kitchen,
        h,
        &f_kitchen,
        &[open(Side::West, lk.0, lk.1, lk.2)],
    );
    shell(
        b,
        rng,
        &p,
        &bedroom,
        h,
        &f_bedroom,
        &[open(Side::South, lb.0, lb.1, lb.2)],
    );
    shell(
        b,
        rng,
        &p,
        &study,
        h,
        &f_study,
        &[open(Side::South, ls.0, ls.1, ls.2)],
    );

    let mut shelves = Vec::new();

    // Living room. North wall: two bookcases and a plant; west wall: sofa under the tuned canvas;
    // south wall: a window; east wall: a TV unit; in the middle a coffee table on the tuned rug.
    for x in [0.75, 1.8] {
        shelves.extend(bookcase(
            b,
            &living.wall(Side::North, x, 0.01),
            1.0,
            2.2,
            0.34,
            6,
            p.walnut,
            p.wood,
        ));
    }
    plant(b, &Frame::new(2.85, 0.0, 4.2, Facing::NegZ), &p, 0.22, 1.4);
    let wf = living.wall(Side::South, 2.6, 0.0);
    window(b, &wf, &p, 1.8, 0.95, 2.2, h, p.mustard);
    let sofa_fr = living.wall(Side::West, 2.3, 0.02);
    sofa(b, &sofa_fr, 2.3, 0.9, p.grey, p.grey, 3);
    let canvas = Tuner {
        kind: TunerKind::Canvas {
            fr: living.wall(Side::West, 2.3, 0.0),
            v: 1.65,
            w: 0.032,
        },
        material: p.canvas,
        a: (0.8, 1.2, 1.5),
        b: (0.5, 0.7, 0.9),
    };
    let (cw, ch) = (canvas.a.2, canvas.b.2);
    b.lbox(
        &living.wall(Side::West, 2.3, 0.0),
        "picture_frame",
        p.frame,
        [-cw / 2.0 - 0.05, 1.65 - ch / 2.0 - 0.05, 0.0],
        [cw / 2.0 + 0.05, 1.65 + ch / 2.0 + 0.05, 0.03],
        BACK,
    );
    for z in [0.75, 3.85] {
        let st = living.wall(Side::West, z, 0.02);
        table(
            b,
            &st,
            "side_table",
            0.45,
            0.45,
            0.55,
            p.walnut,
            p.walnut,
            0.04,
        );
        table_lamp(b, &st.at(0.0, 0.55, 0.22), &p, p.cream, 24);
    }
    let coffee = Frame::new(1.75, 0.0, 2.3, Facing::PosX);
    table(
        b,
        &coffee.at(0.0, 0.0, -0.32),
        "coffee_table",
        1.2,
        0.64,
        0.42,
        p.walnut,
        p.walnut,
        0.05,
    );
    b.lbox(
        &coffee.at(0.2, 0.42, -0.1),
        "coffee_book",
        p.books[3],
        [0.0, 0.0, 0.0],
        [0.3, 0.04, 0.22],
        BOTTOM,
    );
    let rug = Tuner {
        kind: TunerKind::Rug { x: 1.85, z: 2.3 },
        material: p.rug_red,
        a: (1.0, 1.4, 1.6),
        b: (1.6, 2.3, 2.9),
    };
    // Armchairs facing the sofa.
    for z in [1.3, 3.3] {
        sofa(
            b,
            &Frame::new(3.55, 0.0, z, Facing::NegX),
            0.85,
            0.85,
            p.mustard,
            p.mustard,
            1,
        );
    }
    let tv = living.wall(Side::East, 3.7, 0.01);
    cabinet(
        b,
        &tv,
        1.4,
        0.5,
        0.42,
        p.walnut,
        p.walnut,
        Fronts::Drawers(2),
        p.brass,
    );
    television(b, &tv.at(0.0, 0.5, 0.0), &p, 0.0, 1.1);
    floor_lamp(b, &Frame::new(5.6, 0.0, 0.4, Facing::NegX), &p, p.cream);
    clock(b, &living.wall(Side::East, 0.55, 0.0), &p, 1.9, 0.18, 64);

    // Kitchen: a counter run along the east wall (base cabinets, worktop, sink, hob, wall
    // cabinets, hood, tiled splashback), a fridge; a round dining table with four chairs.
    let run = kitchen.wall(Side::East, 2.5, 0.0);
    let (len, n_units) = (3.6, 6);
    let unit = len / n_units as f64;
    for k in 0..n_units {
        let u = -len / 2.0 + (k as f64 + 0.5) * unit;
        let fronts = if k == 1 || k == 4 {
            Fronts::Drawers(3)
        } else {
            Fronts::Doors(1)
        };
        cabinet(
            b,
            &run.at(u, 0.0, 0.0),
            unit,
            0.86,
            0.6,
            p.white,
            p.white,
            fronts,
            p.steel,
        );
    }
    let wood_top = b.material("worktop", [0.4, 0.32, 0.26]);
    b.lbox(
        &run,
        "worktop",
        wood_top,
        [-len / 2.0, 0.86, 0.0],
        [len / 2.0, 0.9, 0.63],
        BACK,
    );
    let sink_u = -len / 2.0 + 1.5 * unit;
    b.lrect(
        &run,
        "sink",
        p.steel,
        [sink_u - 0.25, 0.9005, 0.12],
        [sink_u + 0.25, 0.9005, 0.5],
        TOP,
    );
    b.lcylinder(
        &run,
        "tap",
        p.steel,
        [sink_u, 0.9, 0.06],
        0.015,
        0.3,
        8,
        TOP,
        true,
    );
    b.lbox(
        &run,
        "tap_spout",
        p.steel,
        [sink_u - 0.01, 1.17, 0.075],
        [sink_u + 0.01, 1.19, 0.2],
        BACK,
    );
    let hob_u = -len / 2.0 + 4.5 * unit;
    b.lrect(
        &run,
        "hob",
        p.black,
        [hob_u - 0.29, 0.9005, 0.08],
        [hob_u + 0.29, 0.9005, 0.56],
        TOP,
    );
    for (du, dw, r) in [
        (-0.14, 0.19, 0.09),
        (0.14, 0.19, 0.07),
        (-0.14, 0.44, 0.07),
        (0.14, 0.44, 0.09),
    ] {
        let c = run.world([hob_u + du, 0.901, dw]);
        b.hdisc("burner", p.grey, c, r, 40);
    }
    for k in 0..n_units {
        let u = -len / 2.0 + (k as f64 + 0.5) * unit;
        if k == 4 {
            b.lbox(
                &run,
                "hood",
                p.steel,
                [u - unit / 2.0 + 0.01, 1.55, 0.0],
                [u + unit / 2.0 - 0.01, 1.75, 0.5],
                BACK,
            );
            b.lbox(
                &run,
                "hood_flue",
                p.steel,
                [u - 0.12, 1.75, 0.0],
                [u + 0.12, h, 0.25],
                BACK | TOP,
            );
            continue;
        }
        let top = run.at(u, 1.45, 0.0);
        cabinet_wall(b, &top, unit, 0.75, 0.35, p.white, p.steel);
    }
    // Splashback tiles (0.15 m, 4 mm joints).
    let tile_m = b.material("splash_tile", [0.82, 0.86, 0.84]);
    let cols = (len / 0.15).floor() as usize;
    for i in 0..cols {
        for j in 0..3 {
            let u = -len / 2.0 + i as f64 * 0.15 + 0.002;
            let v = 0.902 + j as f64 * 0.15 + 0.002;
            b.lrect(
                &run,
                "splash_tile",
                tile_m,
                [u, v, 0.003],
                [u + 0.146, v + 0.146, 0.003],
                FRONT,
            );
        }
    }
    let fridge = kitchen.wall(Side::East, 0.37, 0.01);
    b.lbox(
        &fridge,
        "fridge",
        p.white,
        [-0.32, 0.0, 0.0],
        [0.32, 1.9, 0.62],
        BACK | BOTTOM,
    );
    b.lbox(
        &fridge,
        "fridge_door",
        p.white,
        [-0.315, 0.02, 0.62],
        [0.315, 0.78, 0.66],
        BACK,
    );
    b.lbox(
        &fridge,
        "fridge_door",
        p.white,
        [-0.315, 0.8, 0.62],
        [0.315, 1.88, 0.66],
        BACK,
    );
    for (v0, v1) in [(0.5, 0.74), (0.84, 1.2)] {
        b.lbox(
            &fridge,
            "handle",
            p.steel,
            [0.25, v0, 0.66],
            [0.27, v1, 0.69],
            BACK,
        );
    }
    // Round dining table.
    let (tx, tz) = (8.1, 2.1);
    b.hdisc("rug_round", p.rug_blue, [tx, RUG_Y, tz], 1.05, 64);
    b.cylinder(
        "dining_foot",
        p.walnut,
        [tx, 0.0, tz],
        0.3,
        0.03,
        32,
        TOP,
        true,
    );
    b.cylinder(
        "dining_column",
        p.walnut,
        [tx, 0.03, tz],
        0.06,
        0.69,
        12,
        0,
        true,
    );
    b.cylinder(
        "dining_top",
        p.walnut,
        [tx, 0.72, tz],
        0.6,
        0.04,
        96,
        TOP | BOTTOM,
        true,
    );
    for k in 0..4 {
        let a = std::f64::consts::FRAC_PI_2 * k as f64;
        let (dx, dz) = (0.33 * a.cos(), 0.33 * a.sin());
        b.hdisc("plate", p.ceramic, [tx + dx, 0.762, tz + dz], 0.12, 48);
        b.cylinder(
            "glass",
            p.glass,
            [tx + 0.3 * (a + 0.6).cos(), 0.76, tz + 0.3 * (a + 0.6).sin()],
            0.035,
            0.11,
            16,
            TOP,
            true,
        );
    }
    b.cylinder(
        "fruit_bowl",
        p.ceramic,
        [tx, 0.76, tz],
        0.13,
        0.07,
        48,
        TOP,
        true,
    );
    for (x, z, f) in [
        (tx + 0.92, tz, Facing::NegX),
        (tx - 0.92, tz, Facing::PosX),
        (tx, tz + 0.92, Facing::NegZ),
        (tx, tz - 0.92, Facing::PosZ),
    ] {
        chair(b, &Frame::new(x, 0.0, z, f), p.walnut, p.green);
    }
    clock(b, &kitchen.wall(Side::South, 8.1, 0.0), &p, 1.9, 0.2, 64);
    let wfk = kitchen.wall(Side::North, 8.1, 0.0);
    window(b, &wfk, &p, 1.6, 1.0, 2.2, h, p.red);
    plant(b, &Frame::new(6.55, 0.0, 0.4, Facing::PosZ), &p, 0.2, 1.3);

    // Bedroom: bed against the north wall between two night stands with lamps, a wardrobe on
    // the west wall, a chest of drawers, a window on the west wall, a rug.
    let bed_fr = bedroom.wall(Side::North, 2.3, 0.01);
    let duvet = b.material("duvet", [0.78, 0.7, 0.55]);
    bed(b, &bed_fr, 1.6, 2.0, p.walnut, p.white, duvet, p.cream);
    for x in [1.15, 3.45] {
        let ns = bedroom.wall(Side::North, x, 0.01);
        cabinet(
            b,
            &ns,
            0.5,
            0.55,
            0.4,
            p.walnut,
            p.walnut,
            Fronts::Drawers(2),
            p.brass,
        );
        table_lamp(b, &ns.at(0.0, 0.55, 0.2), &p, p.cream, 24);
    }
    picture(
        b,
        &bedroom.wall(Side::North, 2.3, 0.0),
        &p,
        1.65,
        1.2,
        0.5,
        p.rug_blue,
    );
    let wardrobe = bedroom.wall(Side::East, 6.6, 0.01);
    cabinet(
        b,
        &wardrobe,
        1.8,
        2.2,
        0.6,
        p.white,
        p.wood,
        Fronts::Doors(3),
        p.brass,
    );
    let chest = bedroom.wall(Side::South, 1.5, 0.01);
    cabinet(
        b,
        &chest,
        1.2,
        0.85,
        0.48,
        p.wood,
        p.wood,
        Fronts::Drawers(4),
        p.brass,
    );
    b.cylinder(
        "vase",
        p.rug_blue,
        chest.world([0.35, 0.85, 0.24]),
        0.06,
        0.25,
        16,
        TOP,
        true,
    );
    // A round mirror above the chest of drawers.
    let mirror = b.material("mirror", [0.7, 0.72, 0.74]);
    b.vdisc(&chest, "mirror", mirror, 0.0, 1.55, 0.02, 0.35, 64);
    let wfb = bedroom.wall(Side::West, 6.8, 0.0);
    window(b, &wfb, &p, 1.4, 1.0, 2.2, h, p.blue);
    b.hdisc("rug_round", p.rug_blue, [2.3, RUG_Y, 5.75], 0.7, 96);
    plant(b, &Frame::new(4.2, 0.0, 8.2, Facing::NegZ), &p, 0.18, 1.1);

    // Study: bookcases along the north and east walls, a desk with a computer and papers, an
    // office chair, an armchair with a floor lamp, a filing cabinet, the round rug.
    for x in [5.5, 6.55, 7.6, 8.65, 9.7] {
        shelves.extend(bookcase(
            b,
            &study.wall(Side::North, x, 0.01),
            1.0,
            2.2,
            0.34,
            6,
            p.walnut,
            p.wood,
        ));
    }
    for z in [5.9, 6.95] {
        shelves.extend(bookcase(
            b,
            &study.wall(Side::West, z, 0.01),
            1.0,
            2.2,
            0.34,
            6,
            p.walnut,
            p.wood,
        ));
    }
    let desk = study.wall(Side::South, 8.6, 0.02);
    table(b, &desk, "desk", 1.6, 0.75, 0.75, p.wood, p.walnut, 0.05);
    computer(b, &desk.at(-0.25, 0.75, 0.02), &p);
    let papers = Papers {
        fr: desk.at(0.0, 0.75, 0.0),
        u0: 0.36,
        w: 0.36,
        material: p.paper,
    };
    chair(
        b,
        &Frame::new(8.35, 0.0, 5.95, Facing::NegZ),
        p.walnut,
        p.blue,
    );
    let filing = study.wall(Side::South, 9.9, 0.01);
    cabinet(
        b,
        &filing,
        0.5,
        1.1,
        0.6,
        p.grey,
        p.grey,
        Fronts::Drawers(4),
        p.steel,
    );
    sofa(
        b,
        &study.wall(Side::South, 6.4, 0.02),
        0.9,
        0.85,
        p.red,
        p.red,
        1,
    );
    floor_lamp(b, &Frame::new(7.15, 0.0, 5.05, Facing::PosZ), &p, p.cream);
    clock(b, &study.wall(Side::South, 8.6, 0.0), &p, 1.9, 0.16, 64);
    let wfs = study.wall(Side::East, 6.7, 0.0);
    window(b, &wfs, &p, 1.2, 1.0, 2.2, h, p.green);

    Plan {
        shelves,
        books: p.books.clone(),
        papers,
        round_rug: RoundRug {
            x: 7.6,
            z: 6.9,
            radius: 0.9,
            material: p.rug_red,
        },
        tuners: [rug, canvas],
    }
}

/// A wall cabinet (carcass and one door), its frame at its bottom on the wall.
fn cabinet_wall(b: &mut Builder, fr: &Frame, w: f64, h: f64, d: f64, m: usize, handle: usize) {
    b.lbox(
        fr,
        "upper_cabinet",
        m,
        [-w / 2.0 + 0.003, 0.0, 0.0],
        [w / 2.0 - 0.003, h, d - 0.02],
        BACK,
    );
    b.lbox(
        fr,
        "cabinet_door",
        m,
        [-w / 2.0 + 0.006, 0.005, d - 0.02],
        [w / 2.0 - 0.006, h - 0.005, d],
        BACK,
    );
    b.lbox(
        fr,
        "handle",
        handle,
        [-0.06, 0.03, d],
        [0.06, 0.05, d + 0.025],
        BACK,
    );
}
