//! Count fitting: the part that makes a room's faces, vertices, lights and patches hit Table 1
//! exactly. The room's layout leaves a plan of free places (shelves, a desk, a round rug, two
//! tuning rectangles); filling them, in this order, makes each count exact in turn:
//! 1. **faces**: books on the shelves (5 faces each) and 0–4 sheets of paper on a desk (1 each);
//! 2. **vertices**: the number of sides of the round rug;
//! 3. **patches**: the patch size, and the sides (in whole patches) of a rug and a canvas.

use crate::builder::Builder;
use crate::geometry::{decimal, q, Frame, BOTTOM, FRONT, PY, TOP};
use crate::random::SplitMix;
use crate::{Counts, Room};
use glam::Vec3;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::{Material, Polygon, Scene};

/// What the fitting chose, for the file's header.
pub struct Fitted {
    pub counts: Counts,
    pub patch_size: f32,
    /// The patch size as written in `# patch-size` (an exact decimal).
    pub patch_size_text: String,
    /// How the counts were hit, in words.
    pub tuning: String,
}

/// Fill the plan's free places so that `b` has exactly the room's Table 1 counts.
pub fn fit(room: Room, b: &mut Builder, rng: &mut SplitMix, plan: &Plan) -> Fitted {
    let target = room.targets();

    // 1. Faces: books (5 faces) and sheets of paper (1 face); 3 faces are kept for the round rug
    //    and the two tuning rectangles.
    let (faces, _) = b.counts();
    let spare = target
        .faces
        .checked_sub(faces + 3)
        .expect("the fixed content has more faces than the target");
    fill_books(b, rng, &plan.shelves, &plan.books, spare / 5);
    plan.papers.place(b, spare % 5);

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
    let fixed = as_loaded(b, 1.0);
    let [t0, t1] = &plan.tuners;
    let start = q(room.patch_size());
    let (patch_size_text, patch_size, (a, bb, c, d)) = (0..400i64)
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
    t0.place(b, patch_size as f64, a, bb);
    t1.place(b, patch_size as f64, c, d);

    let scene = as_loaded(b, patch_size);
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
    Fitted {
        counts,
        patch_size,
        patch_size_text,
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

/// The scene `load_obj` would read from the builder's text (same decimals, same f32 parsing),
/// for counting.
fn as_loaded(b: &Builder, patch_size: f32) -> Scene {
    let coord = |v: i64| -> f32 { decimal(v).parse().expect("a decimal") };
    let materials = b
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
    for p in &b.pieces {
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
        faces: polygons.len(),
        polygons,
        materials,
        vertex_count,
        camera: None,
        patch_size: Some(patch_size),
        skipped_degenerate: 0,
    }
}

// ---------------------------------------------------------------------------------------------
// The free places a room's layout leaves

/// Height of rugs above the floor.
pub const RUG_Y: f64 = 0.004;

/// A shelf's free space, in its bookcase's frame.
#[derive(Clone, Copy)]
pub struct Shelf {
    pub fr: Frame,
    pub u0: f64,
    pub u1: f64,
    pub v0: f64,
    pub clearance: f64,
    pub w_back: f64,
    pub w_front: f64,
}

/// Where sheets of paper go: a loose stack on a desk top (frame at the top's height), its first
/// sheet's corner at (u0, w).
pub struct Papers {
    pub fr: Frame,
    pub u0: f64,
    pub w: f64,
    pub material: usize,
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

/// The round rug, whose number of sides makes the vertex count exact.
pub struct RoundRug {
    pub x: f64,
    pub z: f64,
    pub radius: f64,
    pub material: usize,
}

/// A rectangle of (a − ½) × (b − ½) patch sizes, so exactly a·b patches. (min, preferred, max)
/// for each side in metres.
pub struct Tuner {
    pub kind: TunerKind,
    pub material: usize,
    pub a: (f64, f64, f64),
    pub b: (f64, f64, f64),
}

pub enum TunerKind {
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

/// What a room's layout leaves for the fitting: its shelves and the book materials, the desk
/// for papers, the round rug and the two tuning rectangles.
pub struct Plan {
    pub shelves: Vec<Shelf>,
    pub books: Vec<usize>,
    pub papers: Papers,
    pub round_rug: RoundRug,
    pub tuners: [Tuner; 2],
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
