//! The sky (`--sky R,G,B`, `src/scene/sky.rs`, beyond the paper): a floor under an opening gets
//! the closed-form share of a uniform sky, in both solvers; the sky stays out of the picture and
//! of the scene's counts; an open level with no emitter solves under it.

mod common;

use glam::Vec3;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::{load_obj_with, sky, LoadOptions, Scene};
use gpu_radiosity::solver::{CpuSolver, GpuSolver, SolveOptions};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Box width and height, and the half-side of the square opening centred in its ceiling.
const W: f32 = 1.0;
const H: f32 = 0.25;
const A: f32 = 0.4;

/// A closed box (1 × 0.25 × 1, +y up) with a 0.8 × 0.8 square hole in the middle of its
/// ceiling: the floor reflects 0.5, walls and ceiling nothing, so the floor's radiance is direct
/// sky light only.
fn holed_box(dir: &Path) -> PathBuf {
    let (c0, c1) = (0.5 - A, 0.5 + A);
    let mut quads: Vec<(&str, [[f32; 3]; 4])> = vec![
        (
            "floor",
            [[0., 0., 0.], [0., 0., W], [W, 0., W], [W, 0., 0.]],
        ),
        (
            "black",
            [[0., 0., 0.], [W, 0., 0.], [W, H, 0.], [0., H, 0.]],
        ),
        ("black", [[0., 0., W], [0., H, W], [W, H, W], [W, 0., W]]),
        (
            "black",
            [[0., 0., 0.], [0., H, 0.], [0., H, W], [0., 0., W]],
        ),
        ("black", [[W, 0., 0.], [W, 0., W], [W, H, W], [W, H, 0.]]),
    ];
    // The ceiling around the hole, facing down.
    for (x0, x1, z0, z1) in [
        (0.0, W, 0.0, c0),
        (0.0, W, c1, W),
        (0.0, c0, c0, c1),
        (c1, W, c0, c1),
    ] {
        quads.push((
            "black",
            [[x0, H, z0], [x1, H, z0], [x1, H, z1], [x0, H, z1]],
        ));
    }
    let mut obj = String::from("mtllib hole.mtl\n");
    for (k, (material, q)) in quads.iter().enumerate() {
        for v in q {
            obj += &format!("v {} {} {}\n", v[0], v[1], v[2]);
        }
        let i = 4 * k + 1;
        obj += &format!("usemtl {material}\nf {} {} {} {}\n", i, i + 1, i + 2, i + 3);
    }
    std::fs::write(
        dir.join("hole.mtl"),
        "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl black\nKd 0 0 0\n",
    )
    .unwrap();
    let path = dir.join("hole.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

/// The configuration factor from a point to a parallel a × b rectangle at distance c, the
/// point's normal through a corner (docs/conventions.md).
fn corner(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

/// The factor from a point to a centred square of half-side `a` at height `h`: four corners.
fn centred_square(a: f64, h: f64) -> f64 {
    4.0 * corner(a, a, h)
}

/// The floor's radiance at its centre, under the hole (RGB).
fn floor_centre(scene: &Scene, layout: &PatchLayout, atlas: &[f32]) -> Vec3 {
    let floor = (scene.polygons.iter())
        .position(|p| scene.material(p).name == "floor")
        .unwrap();
    let lm = &layout.lightmaps[floor];
    let t = lm.texel_of(Vec3::new(0.5, 0.0, 0.5));
    // The patch size makes the floor 33 × 33 patches: one is centred under the hole.
    assert_eq!((lm.w, lm.h), (33, 33));
    assert!(
        (t.x.fract() - 0.5).abs() < 1e-3 && (t.y.fract() - 0.5).abs() < 1e-3,
        "{t}"
    );
    let at = ((lm.y + t.y as u32) * layout.atlas_width + lm.x + t.x as u32) as usize * 4;
    Vec3::new(atlas[at], atlas[at + 1], atlas[at + 2])
}

#[test]
fn a_floor_under_an_opening_gets_the_closed_form_share_of_the_sky() {
    let tmp = tempfile::tempdir().unwrap();
    let sky_radiance = Vec3::new(1.0, 0.5, 2.0);
    let options = LoadOptions {
        sky: Some(sky_radiance),
        ..Default::default()
    };
    let scene = load_obj_with(&holed_box(tmp.path()), &options).unwrap();
    assert_eq!(scene.own_polygons().len(), 9);
    let layout = PatchLayout::new(&scene, Resolution::PatchSize(W / 32.9));
    // ρ·L·F: irradiance E = π·L·F on the floor, radiosity ρ·E, radiance ρ·E/π.
    let f = centred_square(A as f64, H as f64);
    // The sky's quads are seen whole or not at all (from their centres): from the floor's
    // centre the opening then counts between itself shrunk and grown by half a quad, projected
    // onto the opening's plane.
    let (lo, hi) = (Vec3::ZERO, Vec3::new(W, H, W));
    let margin = sky::MARGIN * (hi - lo).length();
    let quad = (W + 2.0 * margin) / sky::DIVISIONS as f32;
    let half = (0.5 * quad * H / (H + margin)) as f64;
    let (f_lo, f_hi) = (
        centred_square(A as f64 - half, H as f64),
        centred_square(A as f64 + half, H as f64),
    );
    println!("F = {f:.5}, band {f_lo:.5} to {f_hi:.5} (quads of {quad:.4})");
    assert!(
        f_hi / f_lo < 1.04,
        "the band is narrow enough to mean something"
    );

    let ctx = common::context();
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, SolveOptions::accurate()).unwrap();
    gpu.solve(|_| {}).unwrap();
    let mut cpu = CpuSolver::new(&scene, &layout, SolveOptions::accurate(), 0).unwrap();
    cpu.solve(|_| {}).unwrap();
    for (name, atlas) in [
        ("gpu", gpu.radiosity_atlas()),
        ("cpu", cpu.radiosity_atlas()),
    ] {
        let l = floor_centre(&scene, &layout, &atlas);
        for c in 0..3 {
            let share = (l[c] / (0.5 * sky_radiance[c])) as f64;
            println!(
                "{name} channel {c}: floor {:.5}, share {share:.5} against F {f:.5} ({:+.2} %)",
                l[c],
                100.0 * (share / f - 1.0)
            );
            // 1 % beyond the band for the item buffer's and the floats' rounding.
            assert!(
                share > 0.99 * f_lo && share < 1.01 * f_hi,
                "{name} channel {c}: {share} outside {f_lo}..{f_hi}"
            );
        }
    }
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
}

fn stats(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap()
}

#[test]
fn the_sky_is_out_of_the_picture_and_of_the_counts() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = holed_box(tmp.path());
    let out = tmp.path().join("out");
    // From above, outside the sky: the sky's top would hide the box (its back, black).
    let o = bin()
        .args([
            "solve",
            scene.to_str().unwrap(),
            "--sky",
            "1,1,1",
            "--patches",
            "2000",
        ])
        .args([
            "--eye",
            "0.5,3,0.5",
            "--target",
            "0.5,0,0.5",
            "--up",
            "0,0,1",
        ])
        .args([
            "--fov",
            "10",
            "--size",
            "64x64",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let s = stats(&out);
    assert_eq!(s["polygons"], 9, "{s}");
    assert_eq!(s["lights"], 0);
    let sky = &s["sky"];
    assert_eq!(sky["radiance"], serde_json::json!([1.0, 1.0, 1.0]));
    let quads = sky["polygons"].as_u64().unwrap();
    assert!(quads > 1000, "{sky}");
    assert_eq!(sky["patches"].as_u64(), Some(quads), "one patch each");
    // The scene's own patches are about what was asked for, whatever the sky's size.
    let patches = s["patches"].as_u64().unwrap();
    assert!((1800..=2200).contains(&patches), "{patches}");
    assert_eq!(s["stopped"], "threshold");

    let image = image::open(out.join("image.exr")).unwrap().to_rgb32f();
    let centre = image.get_pixel(32, 32).0;
    // The floor through the opening: 0.5 × F ≈ 0.38.
    assert!(centre[0] > 0.3 && centre[0] < 0.45, "{centre:?}");
}

/// A solve of `level` (as published) under `--sky 1,1,1` to the 1 %: its stats and
/// stderr, after checking that it converged and that more than `min_lit` of the picture is lit
/// (the default camera frames the level, not the sky, which the picture leaves black).
fn solve_under_the_sky(level: &Path, out: &Path, min_lit: f64) -> (serde_json::Value, String) {
    let o = bin()
        .args(["solve", level.to_str().unwrap(), "--size", "96x96"])
        .args(["--sky", "1,1,1", "--threshold", "0.01"])
        .args(["--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    let s = stats(out);
    assert_eq!(s["stopped"], "threshold", "{err}");
    assert!(s["unshot_fraction"].as_f64().unwrap() <= 0.01);
    assert_eq!(s["lights"].as_u64(), Some(0));
    assert!(s["sky"]["polygons"].as_u64().unwrap() > 1000, "{err}");
    let reflected: f64 = (s["history"].as_array().unwrap().iter())
        .map(|r| r["reflected_power"].as_f64().unwrap())
        .sum();
    assert!(reflected > 0.0, "the level reflects the sky's light");
    let image = image::open(out.join("image.exr")).unwrap().to_rgb32f();
    let lit = image.pixels().filter(|p| p.0[1] > 1e-3).count();
    let share = lit as f64 / (image.width() * image.height()) as f64;
    println!("{}: {share:.2} of the picture lit", level.display());
    assert!(share > min_lit, "{share:.3} of the picture lit");
    (s, err)
}

/// zdm2 (a Sauerbraten level open to the sky, no emitters) as published, in the OBJ of the
/// map's own export: its 84 materials give their colour only as textures, which the loader
/// does not read, so they reflect the default grey and say so.
#[test]
fn an_open_level_without_emitters_is_lit_by_the_sky() {
    let Some(level) = common::third_party("zdm2/zdm2.obj") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let o = bin()
        .args(["solve", level.to_str().unwrap(), "--max-shots", "50"])
        .args(["--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "no emitter without the sky");
    assert!(String::from_utf8_lossy(&o.stderr).contains("--sky R,G,B"));
    assert!(!out.exists(), "a failed solve writes nothing");

    // From inside a courtyard: the sky shows only above the roofs.
    let (_, err) = solve_under_the_sky(&level, &out, 0.5);
    assert!(
        err.contains("84 materials ('slot1', 'slot21', …) give a colour only as a texture")
            && err.contains("default grey 0.5"),
        "{err}"
    );
}

/// The same level as the glTF of Godot's global-illumination demo (no materials: the loader's
/// grey), as published. Its default camera looks at the whole level from above, a block on a
/// black background.
#[test]
fn the_levels_gltf_is_lit_by_the_sky_too() {
    let Some(level) = common::third_party("zdm2/zdm2.glb") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let (s, _) = solve_under_the_sky(&level, &tmp.path().join("out"), 0.25);
    assert!(
        s["polygons"].as_u64().unwrap() > 20_000,
        "{}",
        s["polygons"]
    );
}

#[test]
fn a_sky_out_of_range_is_a_usage_error() {
    for bad in ["0,0,0", "-1,1,1", "1,1", "nan,1,1", "1,1,2e15", "grey"] {
        let o = bin().args(["solve", "--sky", bad]).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("--sky") && err.contains(bad), "{bad}: {err}");
    }
}
