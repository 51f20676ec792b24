//! Hostile input (issue 20): scene files built to bypass the loader's checks, create energy,
//! make it work without end, read files elsewhere, mislead its messages or lose its precision.
//! Each ends in a correct result or a clear error (exit status 1), never a panic or a hang.

mod common;

use common::*;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::{load_obj, SceneError};
use gpu_radiosity::solver::{CpuSolver, GpuSolver, SolveError, SolveOptions};
use std::path::Path;
use std::process::Command;

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

const LAMP_MTL: &str = "newmtl lamp\nKd 0 0 0\nKe 1 1 1\nnewmtl floor\nKd 0.7 0.7 0.7\n";

/// A lamp facing down over a 2x2 floor facing up, the floor's corners given `copies` times.
fn lamp_over_floor(mtllib: &str, floor_copies: usize) -> String {
    let mut s = format!(
        "{mtllib}\no lamp\nv -0.2 1 -0.2\nv 0.2 1 -0.2\nv 0.2 1 0.2\nv -0.2 1 0.2\nusemtl lamp\nf 1 2 3 4\no floor\nusemtl floor\n"
    );
    for k in 0..floor_copies {
        let b = 5 + 4 * k;
        s += "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n";
        s += &format!("f {} {} {} {}\n", b + 3, b + 2, b + 1, b);
    }
    s
}

fn run(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "{args:?}: panic: {err}"
    );
    (out.status.code().unwrap_or(-1), err)
}

fn fails_with(dir: &Path, args: &[&str], needles: &[&str]) {
    let (code, err) = run(dir, args);
    assert_eq!(code, 1, "{args:?} should fail with status 1: {err}");
    for n in needles {
        assert!(
            err.contains(n),
            "{args:?}: the message should say '{n}': {err}"
        );
    }
}

/// Class 3: `mtllib` after a tab or indented names the file tobj reads, and that file is checked.
#[test]
fn the_mtl_check_cannot_be_bypassed() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    write(d, "hot.mtl", "newmtl lamp\nKd 0 0 0\nKe 1e39 1 1\n");
    write(d, "one.mtl", "newmtl lamp\nKd 0.5\nKe 1 1 1\n");
    write(d, "ok.mtl", LAMP_MTL);
    let tab = write(d, "tab.obj", &lamp_over_floor("mtllib\thot.mtl", 1));
    let one = write(d, "one.obj", &lamp_over_floor("mtllib \t one.mtl", 1));
    let indented = write(d, "ind.obj", &lamp_over_floor("   mtllib ok.mtl", 1));
    for (scene, needles) in [
        (&tab, vec!["hot.mtl:3", "Ke"]),
        (&one, vec!["one.mtl:2", "Kd"]),
    ] {
        let e = load_obj(Path::new(scene)).unwrap_err().to_string();
        for n in needles {
            assert!(e.contains(n), "{e}");
        }
        fails_with(
            d,
            &["solve", scene, "--out", "out"],
            &["needs three numbers"],
        );
    }
    // The indented line is the library it says, not a file named "mtllib ok.mtl".
    let scene = load_obj(Path::new(&indented)).unwrap();
    assert_eq!(scene.light_count(), 1);
    assert_eq!(scene.materials[1].kd.x, 0.7);
}

/// Class 5: material libraries outside the folder, FIFOs, devices and huge files are refused
/// without reading them; the scene file itself too.
#[test]
fn material_paths_are_confined_and_only_regular_files_are_read() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::create_dir(d.join("sub")).unwrap();
    write(d, "ok.mtl", LAMP_MTL);
    let up = write(d, "sub/up.obj", &lamp_over_floor("mtllib ../ok.mtl", 1));
    let abs = write(d, "abs.obj", &lamp_over_floor("mtllib /etc/hostname", 1));
    let zero = write(d, "zero.obj", &lamp_over_floor("mtllib /dev/zero", 1));
    let fifo = d.join("fifo.mtl");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let fifo = write(d, "fifo.obj", &lamp_over_floor("mtllib fifo.mtl", 1));
    std::fs::File::create(d.join("big.mtl"))
        .unwrap()
        .set_len(gpu_radiosity::scene::MAX_MTL_BYTES + 1)
        .unwrap();
    let big = write(d, "big.obj", &lamp_over_floor("mtllib big.mtl", 1));
    for (scene, needles) in [
        (
            &up,
            vec![
                "../ok.mtl",
                "outside the scene's folder",
                "--allow-outside-materials",
            ],
        ),
        (&abs, vec!["/etc/hostname", "outside"]),
        (&zero, vec!["/dev/zero", "outside"]),
        (&fifo, vec!["fifo.mtl", "not a regular file"]),
        (&big, vec!["big.mtl", "larger than the limit"]),
    ] {
        fails_with(d, &["solve", scene, "--out", "out"], &needles);
    }
    fails_with(
        d,
        &["solve", "/dev/zero", "--out", "out"],
        &["/dev/zero", "not a regular file"],
    );
    // Allowed on request: the library one folder up is read and the scene solves.
    let (code, err) = run(
        d,
        &[
            "--allow-outside-materials",
            "solve",
            &up,
            "--out",
            "out",
            "--size",
            "32x24",
        ],
    );
    assert_eq!(code, 0, "{err}");
}

/// Class 4: a floor given three times is dropped to one (with a warning) and the solve keeps
/// the balance; built into a scene by hand, such receivers stop both solvers with the balance
/// check, naming them.
#[test]
fn duplicate_faces_create_no_energy() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    write(d, "ok.mtl", LAMP_MTL);
    let triple = write(d, "triple.obj", &lamp_over_floor("mtllib ok.mtl", 3));
    let scene = load_obj(Path::new(&triple)).unwrap();
    assert_eq!(scene.polygons.len(), 2, "the copies are dropped");
    let (code, err) = run(d, &["solve", &triple, "--out", "out", "--size", "32x24"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("dropped 2 face(s) given twice"), "{err}");

    // Past the loader (a scene built in code): the check in the shared loop stops the solve.
    let mut scene = scene;
    scene.polygons.push(scene.polygons[1].clone());
    scene.polygons.push(scene.polygons[1].clone());
    let layout = PatchLayout::new(&scene, Resolution::Patches(2000));
    let ctx = context();
    let check = |e: SolveError| {
        let m = e.to_string();
        assert!(matches!(e, SolveError::EnergyCreated { .. }), "{m}");
        assert!(m.contains("'lamp'") && m.contains("'floor'"), "{m}");
    };
    // Without scaling back, the check stops both solvers.
    let options = SolveOptions {
        conserve: false,
        ..SolveOptions::accurate()
    };
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    check(gpu.step().unwrap_err());
    let mut cpu = CpuSolver::new(&scene, &layout, options, 1).unwrap();
    check(cpu.step().unwrap_err());
    // The default scales the shot back: the copies share what one floor receives.
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, SolveOptions::accurate()).unwrap();
    let r = gpu.step().unwrap().unwrap();
    assert!(r.received_power <= r.carried_power * 1.005, "{r:?}");
    assert_eq!(gpu.ledger().corrections(), 1);
}

/// Class 4: the paper's point form factor is unbounded near the shooter. In the simple room in
/// the paper's mode a sofa 2 cm from a wall receives more than the wall shot, and the unshot power
/// passes the emitted power at shot 474; without the check the solve ran 10,000 shots to a NaN
/// unshot fraction and exited 0. Both solvers stop there, naming the factor.
#[test]
fn the_point_form_factor_stops_where_it_creates_energy() {
    let scene = load("simple");
    let layout = PatchLayout::new(&scene, Resolution::Patches(14_445));
    let ctx = context();
    let check = |e: SolveError| {
        let m = e.to_string();
        assert!(matches!(e, SolveError::EnergyCreated { .. }), "{m}");
        assert!(
            m.contains("point form factor") && m.contains("--form-factor polygon"),
            "{m}"
        );
    };
    let options = SolveOptions::paper();
    let mut gpu = GpuSolver::new(&ctx, &scene, &layout, options.clone()).unwrap();
    check(gpu.solve(|_| {}).unwrap_err());
    assert!(gpu.shots() < 1000, "stopped after {} shots", gpu.shots());
    let mut cpu = CpuSolver::new(&scene, &layout, options, 0).unwrap();
    check(cpu.solve(|_| {}).unwrap_err());
    assert!(cpu.shots() < 1000, "stopped after {} shots", cpu.shots());
}

/// Class 4: a deeply non-planar 10,000-corner face (a zigzag crown) is split into triangles
/// that do not fold over each other: no shot reflects more than Kd times its power.
#[test]
fn a_non_planar_face_is_split_without_creating_energy() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    write(d, "ok.mtl", LAMP_MTL);
    let n = 10_000;
    let s = lamp_over_floor("mtllib ok.mtl", 0) + &zigzag_crown(4, n);
    let crown = write(d, "crown.obj", &s);
    let scene = load_obj(Path::new(&crown)).unwrap();
    assert!(scene.polygons.len() > 1000);
    assert!(scene.polygons.iter().all(|p| p.is_planar(1e-3)));
    let layout = PatchLayout::new(&scene, Resolution::Patches(4000));
    let ctx = context();
    let mut gpu = GpuSolver::new(
        &ctx,
        &scene,
        &layout,
        SolveOptions {
            max_shots: 20,
            ..SolveOptions::accurate()
        },
    )
    .unwrap();
    gpu.solve(|_| {}).unwrap();
    for r in gpu.history() {
        // By magnitude: overshooting shoots negative energy too.
        assert!(
            r.received_power <= r.carried_power * 1.005,
            "shot {}: received {} of {}",
            r.shot,
            r.received_power,
            r.carried_power
        );
    }
}

/// Class 7: messages name the real cause; names from the file are escaped.
#[test]
fn messages_name_the_real_cause() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    write(d, "ok.mtl", LAMP_MTL);
    // A zero-area lamp: the material emits, its face does not exist.
    let flat_lamp = lamp_over_floor("mtllib ok.mtl", 1).replace(
        "v -0.2 1 -0.2\nv 0.2 1 -0.2\nv 0.2 1 0.2\nv -0.2 1 0.2\n",
        "v 0 1 0\nv 0.2 1 0\nv 0.4 1 0\nv 0.6 1 0\n",
    );
    let zero = write(d, "zero.obj", &flat_lamp);
    let e = load_obj(Path::new(&zero)).unwrap_err();
    assert!(matches!(e, SceneError::EmitterZeroArea { .. }), "{e}");
    assert!(e.to_string().contains("lamp"), "{e}");
    // An object name with a terminal escape sequence is echoed escaped.
    let evil = lamp_over_floor("mtllib ok.mtl", 1).replace("o lamp", "o lamp\x1b[2J\x07");
    let evil = write(d, "evil.obj", &evil);
    let scene = load_obj(Path::new(&evil)).unwrap();
    assert_eq!(scene.polygons[0].object, "lamp\\u{1b}[2J\\u{7}");
}

/// Class 8: the shadow scene scaled to both ends of the accepted range gives the same first shot
/// (share of the power reflected) as at its own scale, in both solvers; beyond it, a clear error.
#[test]
fn extreme_scales_are_exact_or_refused() {
    use gpu_radiosity::scene::{MAX_SCENE_SIZE, MIN_SCENE_SIZE};
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/shadow");
    let obj = std::fs::read_to_string(dir.join("shadow.obj")).unwrap();
    std::fs::copy(dir.join("shadow.mtl"), d.join("shadow.mtl")).unwrap();
    let size = load("shadow").size();
    let scaled = |factor: f64| {
        let text: String = obj
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| match l.strip_prefix("v ") {
                Some(rest) => {
                    let v: Vec<f64> = rest
                        .split_whitespace()
                        .map(|t| t.parse().unwrap())
                        .collect();
                    format!(
                        "v {:e} {:e} {:e}\n",
                        v[0] * factor,
                        v[1] * factor,
                        v[2] * factor
                    )
                }
                None => format!("{l}\n"),
            })
            .collect();
        let name = format!("s{factor:e}.obj");
        write(d, &name, &text);
        load_obj(&d.join(name))
    };
    let ctx = context();
    let first_shot = |scene: &gpu_radiosity::scene::Scene| {
        let layout = PatchLayout::new(scene, Resolution::Patches(3000));
        let options = SolveOptions::accurate();
        let mut gpu = GpuSolver::new(&ctx, scene, &layout, options.clone()).unwrap();
        let g = gpu.step().unwrap().unwrap();
        let mut cpu = CpuSolver::new(scene, &layout, options, 0).unwrap();
        let c = cpu.step().unwrap().unwrap();
        [g, c].map(|r| r.reflected_power / r.shot_power)
    };
    let reference = first_shot(&scaled(1.0).unwrap());
    // The ends of the range, with 1 % to spare.
    for factor in [
        1.01 * MIN_SCENE_SIZE as f64 / size as f64,
        0.99 * MAX_SCENE_SIZE as f64 / size as f64,
    ] {
        let got = first_shot(&scaled(factor).unwrap());
        println!("scale {factor:e}: reflected/shot {got:?} (at 1: {reference:?})");
        for (g, r) in got.iter().zip(&reference) {
            assert!(
                (g / r - 1.0).abs() < 1e-3,
                "scale {factor:e}: {got:?} vs {reference:?}"
            );
        }
    }
    for factor in [1e-9, 1e9, 1e-18, 1e18] {
        let e = scaled(factor).unwrap_err();
        assert!(
            matches!(e, SceneError::Scale { .. }),
            "scale {factor:e}: {e}"
        );
        assert!(
            e.to_string().contains("1e-5") && e.to_string().contains("1e6"),
            "{e}"
        );
    }
}
