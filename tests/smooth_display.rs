//! Smooth display of curved surfaces (src/display/smooth.rs): a room with a tessellated sphere, a
//! column of thin facets and a box cut into coplanar tiles, solved briefly in both modes and with
//! both solvers, and rendered with and without smoothing. Across the facets' shared edges the
//! picture's jumps fall by a large factor; across the box's 90° edges they stay as they were; the
//! Cornell box, which has no smooth edge, draws exactly as before; the viewer draws the same.

mod common;

use glam::{Mat4, Vec3, Vec4};
use gpu_radiosity::display::{scene_view_projection, smooth, Image, Smoothing};
use gpu_radiosity::gl::GlContext;
use gpu_radiosity::patches::PatchLayout;
use gpu_radiosity::pipeline::{self, Mode, SolverKind};
use gpu_radiosity::scene::{Camera, Scene};
use gpu_radiosity::solver::SolveOptions;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const SIZE: (u32, u32) = (512, 512);
const SPHERE_CENTRE: Vec3 = Vec3::new(1.3, 0.75, 2.4);
const SPHERE_RADIUS: f32 = 0.7;
const COLUMN_CENTRE: Vec3 = Vec3::new(3.2, 0.0, 3.2);
const COLUMN_RADIUS: f32 = 0.45;
const COLUMN_HEIGHT: f32 = 2.2;
/// The box: [2.3, 3.1] × [0, 0.8] × [1.6, 2.4], each side cut into 3 × 3 tiles.
const BOX_LO: Vec3 = Vec3::new(2.3, 0.0, 1.6);
const BOX_SIDE: f32 = 0.8;

/// An OBJ being written: vertices (1-based in faces), faces by material and object.
#[derive(Default)]
struct Obj {
    vertices: Vec<Vec3>,
    text: String,
}

impl Obj {
    fn vertex(&mut self, v: Vec3) -> usize {
        self.vertices.push(v);
        writeln!(self.text, "v {} {} {}", v.x, v.y, v.z).unwrap();
        self.vertices.len()
    }

    fn object(&mut self, name: &str, material: &str) {
        writeln!(self.text, "o {name}\nusemtl {material}").unwrap();
    }

    fn face(&mut self, corners: &[usize]) {
        let list: Vec<String> = corners.iter().map(|c| c.to_string()).collect();
        writeln!(self.text, "f {}", list.join(" ")).unwrap();
    }

    /// A face wound so that its normal points away from `inside`.
    fn face_outward(&mut self, corners: &[usize], inside: Vec3) -> Facet {
        let p: Vec<Vec3> = corners.iter().map(|&c| self.vertices[c - 1]).collect();
        let centroid = p.iter().copied().sum::<Vec3>() / p.len() as f32;
        let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        let mut corners = corners.to_vec();
        let normal = if normal.dot(centroid - inside) < 0.0 {
            corners.reverse();
            -normal
        } else {
            normal
        };
        self.face(&corners);
        Facet {
            corners,
            centroid,
            normal,
        }
    }
}

/// One face of a curved surface, as the test wrote it.
#[derive(Clone)]
struct Facet {
    corners: Vec<usize>,
    centroid: Vec3,
    normal: Vec3,
}

/// The test scene: its OBJ folder, and the facets of the sphere, the column and the box.
struct Written {
    obj: PathBuf,
    sphere: Vec<Facet>,
    column: Vec<Facet>,
    tiles: Vec<Facet>,
    vertices: Vec<Vec3>,
}

/// A 4 × 3 × 4 room lit by a ceiling panel, with a UV sphere of 16 × 12 quads cut into triangles
/// (352 triangles), a 20-sided column (quads of about 1 × 8 patches) and a box of 54 tiles.
fn write_scene(dir: &Path) -> Written {
    let mut o = Obj::default();
    writeln!(
        o.text,
        "# camera eye 2.1 1.7 0.25 target 2.0 0.8 2.5 up 0 1 0 fov 62\nmtllib room.mtl"
    )
    .unwrap();
    let quad = |o: &mut Obj, name: &str, material: &str, c: [Vec3; 4], inside: Vec3| {
        o.object(name, material);
        let ids: Vec<usize> = c.iter().map(|&v| o.vertex(v)).collect();
        o.face_outward(&ids, inside);
    };
    let v = Vec3::new;
    // The room's walls face inward: "outward" from a point outside each.
    for (name, c, outside) in [
        (
            "floor",
            [v(0., 0., 0.), v(4., 0., 0.), v(4., 0., 4.), v(0., 0., 4.)],
            v(2., 9., 2.),
        ),
        (
            "ceiling",
            [v(0., 3., 0.), v(4., 3., 0.), v(4., 3., 4.), v(0., 3., 4.)],
            v(2., -9., 2.),
        ),
        (
            "left",
            [v(0., 0., 0.), v(0., 3., 0.), v(0., 3., 4.), v(0., 0., 4.)],
            v(9., 1., 2.),
        ),
        (
            "right",
            [v(4., 0., 0.), v(4., 3., 0.), v(4., 3., 4.), v(4., 0., 4.)],
            v(-9., 1., 2.),
        ),
        (
            "back",
            [v(0., 0., 4.), v(4., 0., 4.), v(4., 3., 4.), v(0., 3., 4.)],
            v(2., 1., -9.),
        ),
        (
            "front",
            [v(0., 0., 0.), v(4., 0., 0.), v(4., 3., 0.), v(0., 3., 0.)],
            v(2., 1., 9.),
        ),
    ] {
        quad(&mut o, name, "wall", c, outside);
    }
    let l = [
        v(1.5, 2.98, 1.2),
        v(2.5, 2.98, 1.2),
        v(2.5, 2.98, 2.2),
        v(1.5, 2.98, 2.2),
    ];
    quad(&mut o, "light", "light", l, v(2.0, 9.0, 1.7));

    // The sphere: rings of 16 vertices between the poles, quads split along a diagonal.
    let (segments, rings) = (16, 12);
    o.object("sphere", "white");
    let at = |j: usize, i: usize| {
        let (theta, phi) = (
            std::f32::consts::PI * j as f32 / rings as f32,
            std::f32::consts::TAU * i as f32 / segments as f32,
        );
        SPHERE_CENTRE
            + SPHERE_RADIUS
                * v(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                )
    };
    let top = o.vertex(at(0, 0));
    let mut ring_ids = Vec::new();
    for j in 1..rings {
        ring_ids.push(
            (0..segments)
                .map(|i| o.vertex(at(j, i)))
                .collect::<Vec<_>>(),
        );
    }
    let bottom = o.vertex(at(rings, 0));
    let mut sphere = Vec::new();
    for i in 0..segments {
        let n = (i + 1) % segments;
        sphere.push(o.face_outward(&[top, ring_ids[0][i], ring_ids[0][n]], SPHERE_CENTRE));
        let last = &ring_ids[rings - 2];
        sphere.push(o.face_outward(&[bottom, last[n], last[i]], SPHERE_CENTRE));
        for j in 0..rings - 2 {
            let (a, b) = (&ring_ids[j], &ring_ids[j + 1]);
            sphere.push(o.face_outward(&[a[i], b[i], b[n]], SPHERE_CENTRE));
            sphere.push(o.face_outward(&[a[i], b[n], a[n]], SPHERE_CENTRE));
        }
    }

    // The column: 20 side quads; its caps meet them at 90°.
    let sides = 20;
    o.object("column", "white");
    let around = |i: usize, y: f32| {
        let phi = std::f32::consts::TAU * i as f32 / sides as f32;
        COLUMN_CENTRE + v(COLUMN_RADIUS * phi.cos(), y, COLUMN_RADIUS * phi.sin())
    };
    let low: Vec<usize> = (0..sides).map(|i| o.vertex(around(i, 0.0))).collect();
    let high: Vec<usize> = (0..sides)
        .map(|i| o.vertex(around(i, COLUMN_HEIGHT)))
        .collect();
    let axis = COLUMN_CENTRE + v(0.0, 0.5 * COLUMN_HEIGHT, 0.0);
    let mut column = Vec::new();
    for i in 0..sides {
        let n = (i + 1) % sides;
        let inside = COLUMN_CENTRE + v(0.0, 0.5 * COLUMN_HEIGHT, 0.0);
        column.push(o.face_outward(&[low[i], low[n], high[n], high[i]], inside));
    }
    o.face_outward(&high, axis);

    // The box, each side 3 × 3 coplanar tiles of one material.
    o.object("box", "white");
    let centre = BOX_LO + Vec3::splat(0.5 * BOX_SIDE);
    let mut tiles = Vec::new();
    for axis in 0..3 {
        for side in [0.0, 1.0] {
            if axis == 1 && side == 0.0 {
                continue; // the bottom, on the floor
            }
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |a: usize, b: usize| {
                let mut p = [0.0; 3];
                p[axis] = side * BOX_SIDE;
                p[u] = a as f32 * BOX_SIDE / 3.0;
                p[w] = b as f32 * BOX_SIDE / 3.0;
                BOX_LO + Vec3::from_array(p)
            };
            let mut grid = HashMap::new();
            for a in 0..4 {
                for b in 0..4 {
                    grid.insert((a, b), o.vertex(corner(a, b)));
                }
            }
            for a in 0..3 {
                for b in 0..3 {
                    let c = [
                        grid[&(a, b)],
                        grid[&(a + 1, b)],
                        grid[&(a + 1, b + 1)],
                        grid[&(a, b + 1)],
                    ];
                    tiles.push(o.face_outward(&c, centre));
                }
            }
        }
    }
    let obj = dir.join("room.obj");
    std::fs::write(&obj, &o.text).unwrap();
    std::fs::write(
        dir.join("room.mtl"),
        "newmtl wall\nKd 0.6 0.6 0.6\nnewmtl white\nKd 0.75 0.75 0.75\n\
         newmtl light\nKd 0 0 0\nKe 12 12 12\n",
    )
    .unwrap();
    Written {
        obj,
        sphere,
        column,
        tiles,
        vertices: o.vertices,
    }
}

/// A world point on the image, in pixels (x right, y down), if in front of the camera.
struct Projector {
    view_projection: Mat4,
}

impl Projector {
    fn new(scene: &Scene, camera: &Camera) -> Projector {
        Projector {
            view_projection: scene_view_projection(scene, camera, SIZE.0 as f32 / SIZE.1 as f32),
        }
    }

    fn pixel(&self, p: Vec3) -> glam::Vec2 {
        let c: Vec4 = self.view_projection * p.extend(1.0);
        let ndc = c.truncate() / c.w;
        glam::Vec2::new(
            (ndc.x + 1.0) * 0.5 * SIZE.0 as f32,
            (1.0 - ndc.y) * 0.5 * SIZE.1 as f32,
        )
    }
}

/// The mean of R, G and B of the pixel holding the point `p` (pixels, y down).
fn luminance(image: &Image, p: glam::Vec2) -> f32 {
    let (x, y) = (p.x.floor() as usize, p.y.floor() as usize);
    let at = (y * image.width as usize + x) * 3;
    (image.rgb[at] + image.rgb[at + 1] + image.rgb[at + 2]) / 3.0
}

/// Pairs of image points on either side of the shared edges of `facets` (between facets that
/// turn more than 5° from each other), 2 pixels from the edge, and the same pairs inside one
/// facet: from 2 to 6 pixels into it. The points lie square to the edge, at a quarter, half and
/// three quarters of it; only points inside their facet that the camera sees (ray cast) count.
struct EdgePairs {
    across: Vec<(glam::Vec2, glam::Vec2)>,
    inside: Vec<(glam::Vec2, glam::Vec2)>,
}

fn edge_pairs(w: &Written, facets: &[Facet], scene: &Scene, camera: &Camera) -> EdgePairs {
    let at = Projector::new(scene, camera);
    // Edges by their ends' positions: the box's sides meet without sharing vertices.
    let key = |c: usize| {
        (w.vertices[c - 1] * 1e4)
            .round()
            .to_array()
            .map(|x| x as i64)
    };
    type Ends = ([i64; 3], [i64; 3]);
    // The facets having each edge, and its two ends.
    let mut edges: HashMap<Ends, (Vec<usize>, Vec3, Vec3)> = HashMap::new();
    for (f, facet) in facets.iter().enumerate() {
        let n = facet.corners.len();
        for k in 0..n {
            let (a, b) = (facet.corners[k], facet.corners[(k + 1) % n]);
            let (ka, kb) = (key(a), key(b));
            let (pa, pb) = (w.vertices[a - 1], w.vertices[b - 1]);
            let e = edges
                .entry((ka.min(kb), ka.max(kb)))
                .or_insert((Vec::new(), pa, pb));
            e.0.push(f);
        }
    }
    let seen = |p: Vec3| {
        let d = p - camera.eye;
        common::first_hit(scene, camera.eye, d.normalize(), usize::MAX)
            .is_some_and(|(_, t)| (t - d.length()).abs() < 1e-3 * d.length())
    };
    let (mut across, mut inside) = (Vec::new(), Vec::new());
    let mut keys: Vec<_> = edges.keys().copied().collect();
    keys.sort_unstable();
    for key in keys {
        let (sharing, a, b) = &edges[&key];
        let [f, g] = sharing[..] else { continue };
        let (f, g) = (&facets[f], &facets[g]);
        if f.normal.dot(g.normal) > 5f32.to_radians().cos() {
            continue;
        }
        for s in [0.25, 0.5, 0.75] {
            let p = a.lerp(*b, s);
            // A world point `px` pixels from p into the facet, square to the edge, if it is
            // inside the facet.
            let into = |facet: &Facet, px: f32| {
                let mut dir = facet.normal.cross(*b - *a).normalize();
                if dir.dot(facet.centroid - p) < 0.0 {
                    dir = -dir;
                }
                let step = 1e-3;
                let per_unit = at.pixel(p).distance(at.pixel(p + dir * step)) / step;
                let q = p + dir * (px / per_unit);
                within(w, facet, q).then_some(q)
            };
            let points = [into(f, 2.0), into(g, 2.0), into(f, 6.0)];
            let [Some(pf), Some(pg), Some(deep)] = points else {
                continue;
            };
            if [pf, pg, deep].into_iter().all(seen) {
                across.push((at.pixel(pf), at.pixel(pg)));
                inside.push((at.pixel(pf), at.pixel(deep)));
            }
        }
    }
    EdgePairs { across, inside }
}

/// Is `q` (on the facet's plane) inside the facet?
fn within(w: &Written, facet: &Facet, q: Vec3) -> bool {
    let u = facet.normal.any_orthonormal_vector();
    let v = facet.normal.cross(u);
    let corners: Vec<Vec3> = facet.corners.iter().map(|&c| w.vertices[c - 1]).collect();
    let outline: Vec<glam::Vec2> = gpu_radiosity::geometry::flatten(&corners, u, v).collect();
    gpu_radiosity::geometry::point_in_polygon(&outline, glam::Vec2::new(q.dot(u), q.dot(v)))
}

/// The mean absolute difference of the pairs' luminances.
fn mean_jump(image: &Image, pairs: &[(glam::Vec2, glam::Vec2)]) -> f32 {
    let sum: f32 = pairs
        .iter()
        .map(|&(a, b)| (luminance(image, a) - luminance(image, b)).abs())
        .sum();
    sum / pairs.len() as f32
}

struct Solved {
    scene: Scene,
    layout: PatchLayout,
    atlas: Vec<f32>,
}

fn solve(ctx: &GlContext, obj: &Path, mode: Mode, kind: SolverKind, shots: u32) -> Solved {
    let (scene, _) = pipeline::load_scene(Some(obj)).unwrap();
    let layout = pipeline::lay_out(&scene, None, None).unwrap();
    let options = SolveOptions {
        max_shots: shots,
        ..mode.options()
    };
    let solution = pipeline::solve(ctx, &scene, &layout, kind, options, 0, |_| {}).unwrap();
    let (atlas, _) = solution.display_atlas(&scene, &layout, true);
    Solved {
        scene,
        layout,
        atlas,
    }
}

fn render(ctx: &GlContext, s: &Solved, angle: f32) -> Image {
    let smoothing = Smoothing::new(&s.scene, &s.layout, angle);
    let camera = s.scene.camera_or_default();
    pipeline::render_smoothed(
        ctx, &s.scene, &s.layout, &s.atlas, &smoothing, &camera, SIZE,
    )
    .unwrap()
}

/// Solve the room briefly, render it with and without smoothing, and hold the jumps across
/// the curved surfaces' edges and the box's to what smoothing must do.
fn check_mode(mode: Mode, kind: SolverKind, shots: u32) {
    let dir = tempfile::tempdir().unwrap();
    let w = write_scene(dir.path());
    let ctx = common::context();
    let s = solve(&ctx, &w.obj, mode, kind, shots);
    let camera = s.scene.camera_or_default();
    let (flat, smooth) = (render(&ctx, &s, 0.0), render(&ctx, &s, 40.0));
    if let (Ok(path), Mode::Accurate, SolverKind::Gpu) =
        (std::env::var("SMOOTH_PICTURE"), mode, kind)
    {
        write_side_by_side(Path::new(&path), &flat, &smooth);
    }
    let smoothing = Smoothing::new(&s.scene, &s.layout, 40.0);
    // The sphere's triangles and the column's sides; not the column's cap, the box's coplanar
    // tiles, the walls or the light.
    assert_eq!(
        smoothing.smoothed_polygons(),
        w.sphere.len() + w.column.len()
    );
    for (what, facets) in [
        ("sphere", &w.sphere),
        ("column", &w.column),
        ("box", &w.tiles),
    ] {
        let pairs = edge_pairs(&w, facets, &s.scene, &camera);
        let before = mean_jump(&flat, &pairs.across);
        let after = mean_jump(&smooth, &pairs.across);
        let inside = mean_jump(&smooth, &pairs.inside);
        eprintln!(
            "{mode:?} {kind:?} {what}: {} pairs; across edges {before:.5} -> {after:.5} (/{:.1}); \
             inside facets {:.5} -> {inside:.5}",
            pairs.across.len(),
            before / after,
            mean_jump(&flat, &pairs.inside),
        );
        assert!(pairs.across.len() >= 15, "{what}: too few edges seen");
        if what == "box" {
            // 90° edges: the same contrast as without smoothing.
            assert!(before > 0.1, "the box's edges show no contrast: {before}");
            assert!(
                (after - before).abs() < 0.01 * before,
                "the box's edges changed: {before} -> {after}"
            );
        } else {
            // Faceted before: the edges stand out against the facets' insides...
            assert!(before > 0.02, "{what}: no facets to smooth ({before})");
            // ...and smooth after: the jumps fall by a large factor, below the shading's own
            // change over the same distance inside a facet.
            assert!(
                after < before / 5.0,
                "{what}: edges still jump: {before} -> {after}"
            );
            assert!(
                after < inside,
                "{what}: edges jump {after}, more than inside facets ({inside})"
            );
        }
    }
}

/// `SMOOTH_PICTURE=docs/smooth.png cargo test --release --test smooth_display accurate` draws
/// paper_notes.md's picture: without smoothing on the left, with it on the right.
fn write_side_by_side(path: &Path, left: &Image, right: &Image) {
    let (w, h) = (left.width as usize, left.height as usize);
    let mut rgb = Vec::with_capacity(2 * w * h * 3);
    for y in 0..h {
        rgb.extend_from_slice(&left.rgb[y * w * 3..(y + 1) * w * 3]);
        rgb.extend_from_slice(&right.rgb[y * w * 3..(y + 1) * w * 3]);
    }
    let both = Image {
        width: 2 * w as u32,
        height: h as u32,
        rgb,
    };
    gpu_radiosity::display::output::write_png(path, &both, 1.5).unwrap();
}

#[test]
fn curved_surfaces_are_smooth_in_accurate_mode() {
    check_mode(Mode::Accurate, SolverKind::Gpu, 3);
}

#[test]
fn curved_surfaces_are_smooth_in_paper_mode() {
    check_mode(Mode::Paper, SolverKind::Gpu, 20);
}

#[test]
fn curved_surfaces_are_smooth_with_the_cpu_solver() {
    check_mode(Mode::Accurate, SolverKind::Cpu, 3);
}

/// The Cornell box has no smooth edge (its faces meet at right angles or not at all), so the
/// default display draws it bit for bit as without smoothing.
#[test]
fn the_cornell_box_draws_exactly_as_before() {
    let ctx = common::context();
    let (scene, _) = pipeline::load_scene(None).unwrap();
    let layout = pipeline::lay_out(&scene, None, None).unwrap();
    let smoothing = Smoothing::new(&scene, &layout, smooth::DEFAULT_ANGLE);
    assert!(smoothing.is_empty() && smoothing.smoothed_polygons() == 0);
    let options = SolveOptions {
        max_shots: 4,
        ..Mode::Accurate.options()
    };
    let solution =
        pipeline::solve(&ctx, &scene, &layout, SolverKind::Gpu, options, 0, |_| {}).unwrap();
    let (atlas, _) = solution.display_atlas(&scene, &layout, false);
    let camera = scene.camera_or_default();
    let size = (128, 128);
    let default = pipeline::render(&ctx, &scene, &layout, &atlas, &camera, size).unwrap();
    let off = Smoothing::new(&scene, &layout, 0.0);
    let plain =
        pipeline::render_smoothed(&ctx, &scene, &layout, &atlas, &off, &camera, size).unwrap();
    assert!(default.rgb.iter().any(|&v| v > 0.0));
    let same = default
        .rgb
        .iter()
        .zip(&plain.rgb)
        .all(|(a, b)| a.to_bits() == b.to_bits());
    assert!(same, "smoothing changed the Cornell box");
}

const BIN: &str = env!("CARGO_BIN_EXE_radiosity");

fn run(args: &[&str]) -> std::process::Output {
    let out = std::process::Command::new(BIN).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn stats(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("stats.json")).unwrap()).unwrap()
}

fn exr(path: &Path) -> Vec<f32> {
    image::open(path).unwrap().to_rgb32f().into_raw()
}

/// `solve --smooth-angle`: the images change, `lightmap.exr` (the solver's answer) does not, and
/// stats.json says what was smoothed; a bad angle is a usage error.
#[test]
fn the_command_line_option() {
    let dir = tempfile::tempdir().unwrap();
    let w = write_scene(dir.path());
    let obj = w.obj.to_str().unwrap();
    let out = |name: &str| dir.path().join(name);
    let common = [
        "solve",
        obj,
        "--solver",
        "cpu",
        "--max-shots",
        "2",
        "--size",
        "160x160",
    ];
    let smooth = out("smooth");
    let flat = out("flat");
    let log = run(&[&common[..], &["--out", smooth.to_str().unwrap()]].concat());
    assert!(
        String::from_utf8_lossy(&log.stderr).contains("smooth shading: 372 polygons"),
        "{}",
        String::from_utf8_lossy(&log.stderr)
    );
    run(&[
        &common[..],
        &["--smooth-angle", "0", "--out", flat.to_str().unwrap()],
    ]
    .concat());
    let (a, b) = (stats(&smooth), stats(&flat));
    assert_eq!(a["smooth_angle"], 40.0);
    assert_eq!(a["smoothed_polygons"], 372);
    assert_eq!(b["smooth_angle"], 0.0);
    assert_eq!(b["smoothed_polygons"], 0);
    assert_eq!(
        std::fs::read(smooth.join("lightmap.exr")).unwrap(),
        std::fs::read(flat.join("lightmap.exr")).unwrap(),
        "lightmap.exr is the solver's answer, whatever the display does"
    );
    let (ia, ib) = (exr(&smooth.join("image.exr")), exr(&flat.join("image.exr")));
    let changed = ia.iter().zip(&ib).filter(|(x, y)| x != y).count();
    assert!(
        changed > 300,
        "smoothing changed {changed} values of the image"
    );

    for bad in ["90", "-1", "nan", "x"] {
        let o = std::process::Command::new(BIN)
            .args(["solve", obj, "--smooth-angle", bad])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("--smooth-angle"), "{bad}: {err}");
    }
}

/// `radiosity view ARGS` in a fresh Xvfb server (as tests/viewer.rs runs it).
fn view(args: &[&str]) {
    let out = std::process::Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x1024x24", BIN, "view"])
        .args(args)
        .env("WINIT_X11_SCALE_FACTOR", "1")
        .output()
        .expect("xvfb-run is installed (apt-get install xvfb xauth)");
    assert!(
        out.status.success(),
        "view {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The viewer draws the smoothing too: its window shows what `solve` writes after as many
/// shots, and without smoothing something else.
#[test]
fn the_viewer_draws_the_same_smooth_picture() {
    let dir = tempfile::tempdir().unwrap();
    let w = write_scene(dir.path());
    let obj = w.obj.to_str().unwrap();
    let path = |name: &str| dir.path().join(name);
    let (smooth, flat, headless) = (path("smooth.png"), path("flat.png"), path("headless"));
    let base = [
        obj,
        "--after-shots",
        "3",
        "--size",
        "200x200",
        "--overlays",
        "none",
    ];
    view(&[&base[..], &["--screenshot", smooth.to_str().unwrap()]].concat());
    let flat_args = [
        "--smooth-angle",
        "0",
        "--screenshot",
        flat.to_str().unwrap(),
    ];
    view(&[&base[..], &flat_args[..]].concat());
    let out = headless.to_str().unwrap();
    run(&[
        "solve",
        obj,
        "--max-shots",
        "3",
        "--size",
        "200x200",
        "--out",
        out,
    ]);

    let load = |p: &Path| image::open(p).unwrap().to_rgb8();
    let (smooth, flat, image) = (
        load(&smooth),
        load(&flat),
        load(&headless.join("image.png")),
    );
    // Away from the image's border: there the walls around the camera cross its near plane, and
    // one pixel at the left border differed between window and image with smoothing off too.
    let differences = |a: &image::RgbImage| -> Vec<u8> {
        (8..192)
            .flat_map(|y| (8..192).map(move |x| (x, y)))
            .flat_map(|(x, y)| {
                let (p, q) = (a.get_pixel(x, y), image.get_pixel(x, y));
                (0..3).map(move |c| p[c].abs_diff(q[c]))
            })
            .collect()
    };
    let d = differences(&smooth);
    let worst = *d.iter().max().unwrap();
    assert!(
        worst <= 1,
        "the window differs from solve's image by {worst} levels"
    );
    let d = differences(&flat);
    let changed = d
        .chunks_exact(3)
        .filter(|p| p.iter().any(|&v| v > 2))
        .count();
    assert!(
        changed > 300,
        "without smoothing the window should differ on the curved surfaces: {changed} pixels"
    );
}
