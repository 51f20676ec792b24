//! Independent CPU geometry for the GPU tests: ray casting against the scene's polygons.
#![allow(dead_code)]

use glam::{Vec2, Vec3};
use gpu_radiosity::geometry::{flatten, point_in_polygon};
use gpu_radiosity::gl::{BackendChoice, GlContext};
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::{load_obj, Polygon, Scene};
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
