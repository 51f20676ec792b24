//! The builder: named pieces (an OBJ object each) made of faces, and the primitives that emit
//! them — boxes, rectangles, vertical cylinders, flat discs — in world axes or in a local frame.

use crate::geometry::{box_face, q, q3, Frame, ALL, BOTTOM, Q3, TOP};
use std::collections::HashMap;

/// One OBJ object: its vertices and faces (indices into its own vertices).
pub struct Piece {
    pub name: String,
    pub material: usize,
    pub vertices: Vec<Q3>,
    pub faces: Vec<Vec<usize>>,
}

/// One MTL material: reflectance and emitted radiance.
pub struct Mat {
    pub name: String,
    pub kd: [f64; 3],
    pub ke: [f64; 3],
}

/// A room under construction: its pieces and materials, in the order the files list them.
#[derive(Default)]
pub struct Builder {
    pub pieces: Vec<Piece>,
    pub materials: Vec<Mat>,
    counters: HashMap<String, usize>,
    /// The rooms' empty space (boxes, min and max corners in metres), for the tests.
    pub interior: Vec<([f64; 3], [f64; 3])>,
    /// While set, boxes share their corners between their faces.
    pub shared: bool,
}

/// A vertical n-sided cylinder: its n side quads, and the caps in `caps` (TOP, BOTTOM).
pub struct Cylinder {
    /// The centre of its bottom.
    pub bottom: [f64; 3],
    pub radius: f64,
    pub height: f64,
    pub sides: usize,
    pub caps: u8,
}

impl Builder {
    pub fn material(&mut self, name: &str, kd: [f64; 3]) -> usize {
        self.emitter(name, kd, [0.0; 3])
    }

    pub fn emitter(&mut self, name: &str, kd: [f64; 3], ke: [f64; 3]) -> usize {
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

    /// Faces and vertices so far.
    pub fn counts(&self) -> (usize, usize) {
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
    pub fn polys(&mut self, base: &str, material: usize, faces: Vec<Vec<Q3>>) {
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
    pub fn cuboid(&mut self, base: &str, m: usize, lo: [f64; 3], hi: [f64; 3], omit: u8) {
        let (lo, hi) = (q3(lo), q3(hi));
        assert!((0..3).all(|i| lo[i] <= hi[i]), "{base}: an inside-out box");
        if self.shared {
            self.shared_polys(base, m, Self::box_faces(lo, hi, omit));
        } else {
            self.polys(base, m, Self::box_faces(lo, hi, omit));
        }
    }

    /// A box in a local frame.
    pub fn lbox(&mut self, fr: &Frame, base: &str, m: usize, lo: [f64; 3], hi: [f64; 3], omit: u8) {
        let (a, b) = fr.world_box(lo, hi);
        self.cuboid(base, m, a, b, fr.world_bits(omit));
    }

    /// One rectangle: the `face` side of the (flat) local box [lo, hi].
    pub fn lrect(
        &mut self,
        fr: &Frame,
        base: &str,
        m: usize,
        lo: [f64; 3],
        hi: [f64; 3],
        face: u8,
    ) {
        self.lbox(fr, base, m, lo, hi, ALL & !face);
    }

    /// One world rectangle.
    pub fn rect(&mut self, base: &str, m: usize, lo: [f64; 3], hi: [f64; 3], face: u8) {
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

    /// A vertical cylinder in world axes.
    pub fn cylinder(&mut self, base: &str, m: usize, c: Cylinder) {
        let (bottom, n) = (c.bottom, c.sides);
        let lo = Self::ring(bottom, c.radius, n);
        let hi = Self::ring([bottom[0], bottom[1] + c.height, bottom[2]], c.radius, n);
        let mut faces = Vec::new();
        for k in 0..n {
            let k1 = (k + 1) % n;
            faces.push(vec![lo[k], hi[k], hi[k1], lo[k1]]);
        }
        if c.caps & TOP != 0 {
            faces.push(hi.iter().rev().copied().collect());
        }
        if c.caps & BOTTOM != 0 {
            faces.push(lo.clone());
        }
        self.polys(base, m, faces);
    }

    /// A cylinder whose bottom is given in a local frame (its axis stays vertical).
    pub fn lcylinder(&mut self, fr: &Frame, base: &str, m: usize, c: Cylinder) {
        let bottom = fr.world(c.bottom);
        self.cylinder(base, m, Cylinder { bottom, ..c });
    }

    /// A flat horizontal n-gon facing up.
    pub fn hdisc(&mut self, base: &str, m: usize, c: [f64; 3], r: f64, n: usize) {
        let face = Self::ring(c, r, n).into_iter().rev().collect();
        self.polys(base, m, vec![face]);
    }

    /// A flat vertical n-gon in a local frame's (u, v) plane, centred at local `c` = (u, v, w),
    /// facing the front.
    pub fn vdisc(&mut self, fr: &Frame, base: &str, m: usize, c: [f64; 3], r: f64, n: usize) {
        let [u, v, w] = c;
        let face = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                q3(fr.world([u + r * a.cos(), v + r * a.sin(), w]))
            })
            .collect();
        self.polys(base, m, vec![face]);
    }
}
