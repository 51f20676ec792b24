//! Independent CPU geometry for the GPU tests: ray casting against the scene's polygons.
#![allow(dead_code)]

pub mod gltf_room;

use glam::{Vec2, Vec3};
use gpu_radiosity::geometry::{flatten, point_in_polygon};
use gpu_radiosity::gl::{BackendChoice, GlContext};
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::{load_obj, Material, Polygon, Scene};
use std::path::PathBuf;

pub fn scene_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .join(format!("{name}.obj"))
}

pub fn load(name: &str) -> Scene {
    load_obj(&scene_path(name)).expect("bundled scene loads")
}

pub fn layout(scene: &Scene, patch_size: f32) -> PatchLayout {
    PatchLayout::new(scene, Resolution::PatchSize(patch_size))
}

pub fn context() -> GlContext {
    GlContext::headless(BackendChoice::Auto).expect("a GL 3.0 context (Mesa llvmpipe)")
}

/// Distance along the ray to the polygon (either side), if it is hit in front of the origin.
pub fn hit(polygon: &Polygon, origin: Vec3, dir: Vec3) -> Option<f32> {
    let denom = dir.dot(polygon.normal);
    if denom.abs() < 1e-9 {
        return None;
    }
    let t = (polygon.vertices[0] - origin).dot(polygon.normal) / denom;
    if t <= 0.0 {
        return None;
    }
    let p = origin + dir * t;
    let u = (polygon.vertices[1] - polygon.vertices[0]).normalize();
    let v = polygon.normal.cross(u);
    let flat: Vec<Vec2> = flatten(&polygon.vertices, u, v).collect();
    point_in_polygon(&flat, Vec2::new(p.dot(u), p.dot(v))).then_some(t)
}

/// The nearest polygon along a ray, skipping `skip`.
pub fn first_hit(scene: &Scene, origin: Vec3, dir: Vec3, skip: usize) -> Option<(usize, f32)> {
    scene
        .polygons
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != skip)
        .filter_map(|(i, p)| hit(p, origin, dir).map(|t| (i, t)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// Is the segment from `a` to `b` free of every polygon except `skip_a` and `skip_b`?
pub fn unoccluded(scene: &Scene, a: Vec3, b: Vec3, skip_a: usize, skip_b: usize) -> bool {
    let d = b - a;
    let len = d.length();
    let dir = d / len;
    scene.polygons.iter().enumerate().all(|(i, p)| {
        i == skip_a || i == skip_b || hit(p, a, dir).is_none_or(|t| t >= len * (1.0 - 1e-5))
    })
}

/// The centres of polygon `p`'s patches: (atlas texel index, world position). Not every test
/// binary uses it.
#[allow(unused_imports)]
pub use gpu_radiosity::validate::path_traced::patch_centres;

/// Assert that `value` reads as `quoted`, the figure README.md or paper_notes.md prints for it,
/// when written with the quoted text's precision: as many decimals, or for a quote such as
/// `4.6e-7` as many significant digits. So a test's measured number and the docs' cannot drift
/// apart silently: change one, and this names the other. `what` names the figure.
pub fn assert_quoted(what: &str, value: f64, quoted: &str) {
    // A quoted sign: "+0.81" reads as "0.81" (and a value that is negative must be quoted so).
    let quoted = quoted.strip_prefix('+').unwrap_or(quoted);
    let decimals = |t: &str| t.split_once('.').map_or(0, |(_, d)| d.len());
    let shown = match quoted.split_once('e') {
        Some((mantissa, _)) => format!("{value:.*e}", decimals(mantissa)),
        None => format!("{value:.*}", decimals(quoted)),
    };
    assert_eq!(
        shown, quoted,
        "{what}: measured {value:e}, which reads {shown} at the docs' precision; they quote {quoted}"
    );
}

/// Run `radiosity` with `args`, require that it fails, and return its exit code and stderr.
pub fn run_refused(args: &[&str]) -> (i32, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "accepted: {stderr}");
    (out.status.code().unwrap_or(-1), stderr)
}

/// Run `radiosity` with `args`, require success, and return (and print) its stdout.
pub fn run_ok<'a>(args: impl IntoIterator<Item = &'a std::ffi::OsStr>) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    println!("{stdout}");
    stdout
}

/// OBJ lines of a deeply non-planar face: a zigzag crown of `corners` corners on the unit circle
/// (heights 0 and 0.5 in turn), material `floor`, facing up, its vertices numbered after the
/// file's first `before` ones (tests/hostile.rs, tests/shot_balance.rs).
pub fn zigzag_crown(before: usize, corners: usize) -> String {
    let mut s = String::from("o crown\nusemtl floor\n");
    for k in 0..corners {
        let a = std::f64::consts::TAU * k as f64 / corners as f64;
        s += &format!("v {} {} {}\n", a.cos(), 0.5 * (k % 2) as f64, a.sin());
    }
    s += "f";
    for k in 0..corners {
        s += &format!(" {}", before + corners - k);
    }
    s + "\n"
}

/// Write a closed room of `tiles` × 12 × `tiles` units into `dir` (room.obj, room.mtl; patch
/// size 1): its floor unit tiles in a checkerboard of two greys (so that merging leaves them
/// apart, as a voxel world's faces), walls and ceiling one polygon each, a 4×4 light in the middle
/// of the ceiling. Returns the OBJ's path. Polygons: the tiles, then the ceiling, the walls (the
/// third red, the fifth green) and the lamp.
pub fn write_tiled_room(dir: &std::path::Path, tiles: usize) -> PathBuf {
    let n = tiles as f32;
    let mut obj = String::from("# patch-size 1\nmtllib room.mtl\n");
    let mut quads: Vec<([[f32; 3]; 4], &str)> = Vec::new();
    for z in 0..tiles {
        for x in 0..tiles {
            let (x, z) = (x as f32, z as f32);
            let m = if ((x + z) as usize).is_multiple_of(2) {
                "dark"
            } else {
                "light_grey"
            };
            quads.push((
                [
                    [x, 0.0, z],
                    [x, 0.0, z + 1.0],
                    [x + 1.0, 0.0, z + 1.0],
                    [x + 1.0, 0.0, z],
                ],
                m,
            ));
        }
    }
    let h = 12.0;
    quads.extend([
        // Ceiling (facing down), walls facing in.
        ([[0.0, h, 0.0], [n, h, 0.0], [n, h, n], [0.0, h, n]], "wall"),
        (
            [[0.0, 0.0, 0.0], [n, 0.0, 0.0], [n, h, 0.0], [0.0, h, 0.0]],
            "wall",
        ),
        ([[0.0, 0.0, n], [0.0, h, n], [n, h, n], [n, 0.0, n]], "red"),
        (
            [[0.0, 0.0, 0.0], [0.0, h, 0.0], [0.0, h, n], [0.0, 0.0, n]],
            "wall",
        ),
        (
            [[n, 0.0, 0.0], [n, 0.0, n], [n, h, n], [n, h, 0.0]],
            "green",
        ),
    ]);
    let (a, b) = (n / 2.0 - 2.0, n / 2.0 + 2.0);
    let y = h - 0.01;
    quads.push(([[a, y, a], [b, y, a], [b, y, b], [a, y, b]], "lamp"));
    let mut v = 1;
    for (corners, material) in &quads {
        for [x, y, z] in corners {
            obj += &format!("v {x} {y} {z}\n");
        }
        obj += &format!("usemtl {material}\nf {} {} {} {}\n", v, v + 1, v + 2, v + 3);
        v += 4;
    }
    let mtl = "newmtl dark\nKd 0.3 0.3 0.3\nnewmtl light_grey\nKd 0.6 0.6 0.6\n\
               newmtl wall\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.6 0.1 0.1\n\
               newmtl green\nKd 0.1 0.6 0.1\nnewmtl lamp\nKd 0 0 0\nKe 10 10 10\n";
    std::fs::write(dir.join("room.obj"), obj).unwrap();
    std::fs::write(dir.join("room.mtl"), mtl).unwrap();
    dir.join("room.obj")
}

/// A third-party scene file (`path` below the folder of `gpu_radiosity::scene::third_party`), or
/// `None` when it is absent: the test that needs it then says which file and where it is
/// published, and returns (skips). With `RADIOSITY_REQUIRE_SCENES` set (`.ci/run` sets it) an
/// absent scene fails the test instead, so that CI never skips one silently.
pub fn third_party(path: &str) -> Option<PathBuf> {
    match gpu_radiosity::scene::third_party::find(path) {
        Ok(found) => Some(found),
        Err(message) if std::env::var_os("RADIOSITY_REQUIRE_SCENES").is_some() => {
            panic!("{message}")
        }
        Err(message) => {
            eprintln!("SKIPPED: {message}");
            None
        }
    }
}

/// The variants of the archive's Cornell box family, each in
/// `cornell-box-family/CornellBox-VARIANT/CornellBox-VARIANT.obj` (the Original is in `cornell-box/`).
pub const CORNELL_FAMILY: [&str; 8] = [
    "Empty-White",
    "Empty-RG",
    "Empty-CO",
    "Empty-Squashed",
    "Sphere",
    "Water",
    "Glossy",
    "Mirror",
];

/// Where the family's `variant` lies below the third-party folder.
pub fn cornell_family_path(variant: &str) -> String {
    format!("cornell-box-family/CornellBox-{variant}/CornellBox-{variant}.obj")
}

/// The family's `variant` file, or `None` when it is absent (see [`third_party`]).
pub fn cornell_family_box(variant: &str) -> Option<PathBuf> {
    third_party(&cornell_family_path(variant))
}

/// A third-party scene with `material` made an emitter of radiance `ke` (`--emit`), or `None`
/// when the file is absent (see [`third_party`]).
pub fn third_party_lit(path: &str, material: &str, ke: [f32; 3]) -> Option<Scene> {
    let emit = vec![gpu_radiosity::scene::Emission {
        material: material.into(),
        ke,
    }];
    let scene = gpu_radiosity::scene::load_obj_with(
        &third_party(path)?,
        &gpu_radiosity::scene::LoadOptions {
            emit,
            ..Default::default()
        },
    )
    .unwrap();
    Some(scene)
}

/// Shooting points spread over `scene`: every `n / count`-th polygon, from the centres of its first
/// and last triangles (points on the polygon, as its patches are; a concave outline's centroid may
/// lie off it): (polygon, position), about `2 count` of them.
pub fn shooting_points(scene: &Scene, count: usize) -> Vec<(usize, Vec3)> {
    let n = scene.polygons.len();
    let mut points = Vec::new();
    for p in (0..n).step_by(n / count + 1) {
        let polygon = &scene.polygons[p];
        let triangles = gpu_radiosity::scene::triangulate(&polygon.vertices, polygon.normal);
        for t in [triangles[0], triangles[triangles.len() - 1]] {
            points.push((
                p,
                t.iter().map(|&k| polygon.vertices[k]).sum::<Vec3>() / 3.0,
            ));
        }
    }
    points
}

/// Every entry of `dir` with the contents of its files (empty for a folder): what an output set
/// holds, to compare before and after a run.
pub fn snapshot(dir: &std::path::Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let name = e.file_name().to_string_lossy().into_owned();
            (name, std::fs::read(e.path()).unwrap_or_default())
        })
        .collect()
}

/// A scene of `polygons` with one material, `lamp` (reflects 0.5, emits 1): the property and
/// fuzz-regression tests' scenes.
pub fn scene_of(polygons: Vec<Polygon>) -> Scene {
    Scene {
        name: "prop".into(),
        polygons,
        materials: vec![Material {
            name: "lamp".into(),
            kd: Vec3::splat(0.5),
            ke: Vec3::ONE,
        }],
        vertex_count: 0,
        camera: None,
        patch_size: None,
        skipped_degenerate: 0,
        faces: 0,
    }
}

/// The MTL of [`load_text`]'s scenes: `lamp`, as [`scene_of`]'s material.
pub const LAMP_MTL: &str = "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n";

/// Writes an OBJ (and MTL) into a temporary directory and loads it.
pub fn load_text(
    obj: impl AsRef<[u8]>,
    mtl: impl AsRef<[u8]>,
) -> (
    tempfile::TempDir,
    Result<Scene, gpu_radiosity::scene::SceneError>,
) {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("s.obj"), obj).unwrap();
    std::fs::write(dir.path().join("m.mtl"), mtl).unwrap();
    let scene = load_obj(&dir.path().join("s.obj"));
    (dir, scene)
}
