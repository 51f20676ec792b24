//! Writes a cathedral-type test scene (not a test): `cathedral OUT_DIR [DETAIL]` writes
//! `OUT_DIR/cathedral.obj` and `.mtl`. A nave under a barrel vault, two arcades of faceted columns
//! and arches, side aisles under curved vaults, 32 window panes (material `window`, lit with
//! `--emit window=8,8,8`). At DETAIL 1.42 (the default) it has 70,122 triangles, which merge into
//! 19,131 polygons and get 42,308 patches by default: the size of the classic cathedral scenes of
//! radiosity papers (issue 58's target names one of 73,000 triangles), built here because such
//! scenes may not be committed (docs/perf-log.md has its runs). Every face is wound to face the
//! room's inside; columns and arches face out of their axes.
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::Path;

type P = [f64; 3];

/// Which way a face must point: towards `toward` (or away from it when `away`).
type Facing = Box<dyn Fn(P) -> (P, bool)>;

#[derive(Default)]
struct Obj {
    vertices: Vec<P>,
    text: String,
    triangles: usize,
}

impl Obj {
    fn vertex(&mut self, p: P) -> usize {
        self.vertices.push(p);
        self.vertices.len()
    }

    fn material(&mut self, name: &str) {
        writeln!(self.text, "usemtl {name}").unwrap();
    }

    /// A triangle, wound so that its normal points as `facing` asks at its centre.
    fn triangle(&mut self, [a, b, c]: [usize; 3], facing: &Facing) {
        let [pa, pb, pc] = [a, b, c].map(|i| self.vertices[i - 1]);
        let e1 = sub(pb, pa);
        let e2 = sub(pc, pa);
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let centre = [0, 1, 2].map(|i| (pa[i] + pb[i] + pc[i]) / 3.0);
        let (toward, away) = facing(centre);
        let d = sub(toward, centre);
        let towards = n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > 0.0;
        let (b, c) = if towards != away { (b, c) } else { (c, b) };
        writeln!(self.text, "f {a} {b} {c}").unwrap();
        self.triangles += 1;
    }

    fn quad(&mut self, corners: [P; 4], material: &str, facing: &Facing) {
        self.material(material);
        let [a, b, c, d] = corners.map(|p| self.vertex(p));
        self.triangle([a, b, c], facing);
        self.triangle([a, c, d], facing);
    }

    /// A surface `f(u, v)` over the unit square, `nu` × `nv` quads of two triangles.
    fn grid(
        &mut self,
        f: impl Fn(f64, f64) -> P,
        nu: usize,
        nv: usize,
        material: &str,
        facing: &Facing,
    ) {
        self.material(material);
        let ids: Vec<Vec<usize>> = (0..=nu)
            .map(|i| {
                (0..=nv)
                    .map(|j| self.vertex(f(i as f64 / nu as f64, j as f64 / nv as f64)))
                    .collect()
            })
            .collect();
        for i in 0..nu {
            for j in 0..nv {
                let [a, b, c, d] = [ids[i][j], ids[i + 1][j], ids[i + 1][j + 1], ids[i][j + 1]];
                self.triangle([a, b, c], facing);
                self.triangle([a, c, d], facing);
            }
        }
    }
}

fn sub(p: P, q: P) -> P {
    [p[0] - q[0], p[1] - q[1], p[2] - q[2]]
}

// Nave length, width, wall height; aisle width and height.
const L: f64 = 48.0;
const W: f64 = 12.0;
const H: f64 = 18.0;
const AW: f64 = 6.0;
const AH: f64 = 10.0;
const WINDOWS: usize = 8;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = Path::new(args.get(1).expect("usage: cathedral OUT_DIR [DETAIL]"));
    let s: f64 = args
        .get(2)
        .map_or(1.42, |d| d.parse().expect("DETAIL: a number"));
    let n = |k: f64| (k * s) as usize;
    let mut obj = Obj::default();
    let inside: Facing = Box::new(|c| ([0.0, c[1], L / 2.0], false));

    let up: Facing = Box::new(|c| ([c[0], 5.0, c[2]], false));
    obj.quad(
        [
            [-W / 2.0 - AW, 0.0, 0.0],
            [-W / 2.0 - AW, 0.0, L],
            [W / 2.0 + AW, 0.0, L],
            [W / 2.0 + AW, 0.0, 0.0],
        ],
        "floor",
        &up,
    );
    for z in [0.0, L] {
        let (x0, x1) = (-W / 2.0 - AW, W / 2.0 + AW);
        obj.quad(
            [[x0, 0.0, z], [x1, 0.0, z], [x1, AH, z], [x0, AH, z]],
            "stone",
            &inside,
        );
        let (x0, x1) = (-W / 2.0, W / 2.0);
        obj.quad(
            [
                [x0, AH, z],
                [x1, AH, z],
                [x1, H + W / 2.0, z],
                [x0, H + W / 2.0, z],
            ],
            "stone",
            &inside,
        );
    }
    let seg = L / WINDOWS as f64;
    for side in [-1.0, 1.0] {
        // The aisle's outer wall, windows between heights 3 and 7; the clerestory above the
        // arcade, windows between 12 and 16.
        for (x, (y0, y1), (w0, w1), top) in [
            (side * (W / 2.0 + AW), (3.0, 7.0), (0.3, 0.7), AH),
            (side * W / 2.0, (12.0, 16.0), (0.35, 0.65), H),
        ] {
            let mut wall = |z0: f64, z1: f64, ya: f64, yb: f64, m: &str| {
                obj.quad(
                    [[x, ya, z0], [x, ya, z1], [x, yb, z1], [x, yb, z0]],
                    m,
                    &inside,
                )
            };
            let bottom = if top == AH { 0.0 } else { AH };
            wall(0.0, L, bottom, y0, "stone");
            wall(0.0, L, y1, top, "stone");
            for k in 0..WINDOWS {
                let z0 = k as f64 * seg;
                wall(z0, z0 + seg * w0, y0, y1, "stone");
                wall(z0 + seg * w1, z0 + seg, y0, y1, "stone");
                wall(z0 + seg * w0, z0 + seg * w1, y0, y1, "window");
            }
        }
        let cx = side * W / 2.0;
        let below: Facing = Box::new(move |c| ([side * (W / 2.0 + AW * 0.5), 0.0, c[2]], false));
        let aisle_vault = |u: f64, t: f64| {
            [
                cx + side * AW * (t * PI / 2.0).sin(),
                AH - 2.0 + 2.0 * (t * PI / 2.0).cos(),
                u * L,
            ]
        };
        obj.grid(aisle_vault, n(24.0), n(8.0), "plaster", &below);
    }
    let axis: Facing = Box::new(|c| ([0.0, H, c[2]], false));
    let nave_vault = |u: f64, t: f64| {
        [
            -W / 2.0 * (t * PI).cos(),
            H + W / 2.0 * (t * PI).sin(),
            u * L,
        ]
    };
    obj.grid(nave_vault, n(48.0), n(40.0), "plaster", &axis);

    let columns: Vec<f64> = (0..8).map(|k| 3.0 + 6.0 * k as f64).collect();
    for side in [-1.0, 1.0] {
        let cx = side * W / 2.0;
        for &cz in &columns {
            column(&mut obj, cx, cz, &n);
        }
        for pair in columns.windows(2) {
            arch(&mut obj, cx, pair[0], pair[1], &n);
        }
    }

    std::fs::create_dir_all(out).unwrap();
    let mut text = String::from(
        "# A cathedral-type test scene written by examples/cathedral.rs\nmtllib cathedral.mtl\n",
    );
    for p in &obj.vertices {
        writeln!(text, "v {:.5} {:.5} {:.5}", p[0], p[1], p[2]).unwrap();
    }
    text.push_str(&obj.text);
    std::fs::write(out.join("cathedral.obj"), text).unwrap();
    let materials = [
        ("floor", "0.5 0.45 0.4"),
        ("stone", "0.7 0.68 0.62"),
        ("plaster", "0.8 0.78 0.74"),
        ("window", "0.1 0.1 0.1"),
    ];
    let mtl: String = materials
        .iter()
        .map(|(m, kd)| format!("newmtl {m}\nKd {kd}\n\n"))
        .collect();
    std::fs::write(out.join("cathedral.mtl"), mtl).unwrap();
    println!(
        "{} vertices, {} triangles in {}",
        obj.vertices.len(),
        obj.triangles,
        out.display()
    );
}

/// A faceted column with a flaring capital and a rounded base, facing out of its axis.
fn column(obj: &mut Obj, cx: f64, cz: f64, n: &impl Fn(f64) -> usize) {
    let (r, h) = (0.6, AH - 3.5);
    let out: Facing = Box::new(move |c| ([cx, c[1], cz], true));
    let ring = move |radius: f64, t: f64, y: f64| {
        [
            cx + radius * (2.0 * PI * t).cos(),
            y,
            cz + radius * (2.0 * PI * t).sin(),
        ]
    };
    obj.grid(|t, u| ring(r, t, u * h), n(24.0), n(16.0), "stone", &out);
    obj.grid(
        |t, u| ring(r + 0.5 * u * u, t, h + u * 0.8),
        n(24.0),
        n(8.0),
        "stone",
        &out,
    );
    obj.grid(
        |t, u| ring(r + 0.25 * (PI * u).sin(), t, 0.5 * u),
        n(24.0),
        n(6.0),
        "stone",
        &out,
    );
}

/// An arch between two columns: a tube of varying radius along a half circle.
fn arch(obj: &mut Obj, cx: f64, z0: f64, z1: f64, n: &impl Fn(f64) -> usize) {
    let (r, zc, y0) = ((z1 - z0) / 2.0, (z0 + z1) / 2.0, AH - 2.7);
    let out: Facing = Box::new(move |c| {
        let a = (c[1] - y0).atan2(-(c[2] - zc));
        ([cx, y0 + r * a.sin(), zc - r * a.cos()], true)
    });
    let tube = |t: f64, phi: f64| {
        let (a, rr) = (PI * t, r + 0.3 * (2.0 * PI * phi).cos());
        [
            cx + 0.6 * (2.0 * PI * phi).sin(),
            y0 + rr * a.sin(),
            zc - rr * a.cos(),
        ]
    };
    obj.grid(tube, n(24.0), n(12.0), "stone", &out);
}
