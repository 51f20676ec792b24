//! Bad input, as a new user would give it: every case ends with a non-zero exit and one message
//! that names the problem and the place, never a panic or a backtrace, and the good outputs an
//! earlier run left in the output directory are untouched.

use std::path::{Path, PathBuf};
use std::process::Command;

struct Case {
    what: &'static str,
    args: Vec<String>,
    env: Vec<(&'static str, &'static str)>,
    needles: Vec<&'static str>,
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 0 1\n";

#[test]
fn bad_input_gives_clear_errors_and_damages_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let out: PathBuf = d.join("out");
    let shadow = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/shadow/shadow.obj");
    let shadow = shadow.to_str().unwrap().to_string();
    let run = |args: &[String], env: &[(&str, &str)]| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_radiosity"));
        c.args(args).current_dir(d);
        for (k, v) in env {
            c.env(k, v);
        }
        c.output().unwrap()
    };
    // A good run first: its files must survive every bad one.
    let good = run(
        &[
            "solve".into(),
            shadow.clone(),
            "--out".into(),
            out.to_str().unwrap().into(),
            "--size".into(),
            "64x48".into(),
        ],
        &[],
    );
    assert!(
        good.status.success(),
        "{}",
        String::from_utf8_lossy(&good.stderr)
    );
    let files = ["image.png", "image.exr", "lightmap.exr", "stats.json"];
    let before: Vec<Vec<u8>> = files
        .iter()
        .map(|f| std::fs::read(out.join(f)).unwrap())
        .collect();

    std::fs::create_dir(d.join("folder.obj")).unwrap();
    let lamp_mtl = write(d, "lamp.mtl", "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n");
    let _ = lamp_mtl;
    write(d, "badkd.mtl", "newmtl lamp\nKd 0.5 x 0.5\nKe 1 1 1\n");
    write(d, "negke.mtl", "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 -1 1\n");
    let with = |mtl: &str, body: &str| format!("mtllib {mtl}\nusemtl lamp\n{body}");
    let scenes = [
        (
            "bad number",
            write(d, "num.obj", "v 0 0 0\nv 1 oops 0\nv 0 0 1\nf 1 2 3\n"),
            vec!["num.obj:2", "three numbers"],
        ),
        (
            "short vertex",
            write(d, "short.obj", "v 0 0 0\nv 1 0\nv 0 0 1\nf 1 2 3\n"),
            vec!["short.obj:2"],
        ),
        (
            "index out of range",
            write(d, "idx.obj", &format!("{TRIANGLE}f 1 2 4\n")),
            vec!["idx.obj:4", "`4`"],
        ),
        (
            "zero index",
            write(d, "zero.obj", &format!("{TRIANGLE}f 0 1 2\n")),
            vec!["zero.obj:4"],
        ),
        (
            "two-vertex face",
            write(d, "two.obj", &format!("{TRIANGLE}f 1 2\n")),
            vec!["two.obj:4", "at least three"],
        ),
        (
            "NaN coordinate",
            write(d, "nan.obj", "v 0 0 0\nv NaN 0 0\nv 0 0 1\nf 1 2 3\n"),
            vec!["nan.obj:2", "finite"],
        ),
        (
            "infinite coordinate",
            write(d, "inf.obj", "v 0 0 0\nv 1e39 0 0\nv 0 0 1\nf 1 2 3\n"),
            vec!["inf.obj:2", "finite"],
        ),
        (
            "malformed MTL",
            write(
                d,
                "m1.obj",
                &with("badkd.mtl", &format!("{TRIANGLE}f 1 2 3\n")),
            ),
            vec!["badkd.mtl:2", "Kd"],
        ),
        (
            "negative Ke",
            write(
                d,
                "m2.obj",
                &with("negke.mtl", &format!("{TRIANGLE}f 1 2 3\n")),
            ),
            vec!["negke.mtl:3", "Ke"],
        ),
        (
            "missing MTL, so no emitter",
            write(
                d,
                "m3.obj",
                &with("nowhere.mtl", &format!("{TRIANGLE}f 1 2 3\n")),
            ),
            vec!["nowhere.mtl", "no emitter"],
        ),
        (
            "no emitter",
            write(d, "dark.obj", &format!("{TRIANGLE}f 1 2 3\n")),
            vec!["dark.obj", "no emitter", "Ke"],
        ),
        (
            "only degenerate polygons",
            write(d, "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
            vec!["flat.obj", "non-zero area"],
        ),
        (
            "emitter facing away",
            {
                write(
                    d,
                    "away.mtl",
                    "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 1 1 1\n",
                );
                write(
                    d,
                    "away.obj",
                    "mtllib away.mtl\no floor\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nusemtl floor\nf 1 4 3 2\no lamp\nv 0 1 0\nv 0 1 1\nv 1 1 1\nv 1 1 0\nusemtl lamp\nf 5 6 7 8\n",
                )
            },
            vec!["away.obj", "face away", "lamp"],
        ),
    ];
    let o = out.to_str().unwrap().to_string();
    let mut cases: Vec<Case> = scenes
        .into_iter()
        .map(|(what, scene, needles)| Case {
            what,
            args: vec!["solve".into(), scene, "--out".into(), o.clone()],
            env: vec![],
            needles,
        })
        .collect();
    let solve = |extra: &[&str]| {
        let mut a: Vec<String> = vec!["solve".into(), shadow.clone(), "--out".into(), o.clone()];
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    cases.extend([
        Case {
            what: "missing scene",
            args: vec![
                "solve".into(),
                "nothere.obj".into(),
                "--out".into(),
                o.clone(),
            ],
            env: vec![],
            needles: vec!["nothere.obj", "No such file"],
        },
        Case {
            what: "a folder as scene",
            args: vec![
                "solve".into(),
                "folder.obj".into(),
                "--out".into(),
                o.clone(),
            ],
            env: vec![],
            needles: vec!["folder.obj", "directory"],
        },
        Case {
            what: "atlas too large",
            args: solve(&["--patch-size", "0.0001"]),
            env: vec![],
            needles: vec!["patch size", "fits"],
        },
        Case {
            what: "threshold out of range",
            args: solve(&["--threshold", "2"]),
            env: vec![],
            needles: vec!["--threshold"],
        },
        Case {
            what: "zero image size",
            args: solve(&["--size", "0x10"]),
            env: vec![],
            needles: vec!["--size", "0x10"],
        },
        Case {
            what: "bad camera vector",
            args: solve(&["--eye", "1,2"]),
            env: vec![],
            needles: vec!["--eye", "X,Y,Z"],
        },
        Case {
            what: "item buffer too small",
            args: solve(&["--hemi-res", "4"]),
            env: vec![],
            needles: vec!["--hemi-res"],
        },
        Case {
            what: "output is a file",
            args: vec![
                "solve".into(),
                shadow.clone(),
                "--out".into(),
                format!("{o}/stats.json/sub"),
            ],
            env: vec![],
            needles: vec!["output directory", "stats.json"],
        },
        Case {
            what: "no GL driver",
            args: solve(&[]),
            env: vec![
                ("RADIOSITY_OSMESA_LIB", "/nonexistent/libOSMesa.so"),
                ("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent.json"),
            ],
            needles: vec!["no usable OpenGL", "egl", "osmesa", "apt-get install"],
        },
        Case {
            what: "OSMesa asked for but missing",
            args: solve(&["--backend", "osmesa"]),
            env: vec![("RADIOSITY_OSMESA_LIB", "/nonexistent/libOSMesa.so")],
            needles: vec!["osmesa", "libosmesa6"],
        },
    ]);
    println!("{:<32} exit  message", "case");
    for c in &cases {
        let r = run(&c.args, &c.env);
        let err = String::from_utf8_lossy(&r.stderr);
        let message = err
            .lines()
            .filter(|l| l.starts_with("error"))
            .collect::<Vec<_>>()
            .join(" ");
        println!(
            "{:<32} {:>4}  {}",
            c.what,
            r.status.code().unwrap_or(-1),
            message
        );
        assert!(!r.status.success(), "{}: should fail", c.what);
        assert!(
            !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
            "{}: panic: {err}",
            c.what
        );
        for n in &c.needles {
            assert!(
                err.contains(n),
                "{}: the message should mention '{n}': {err}",
                c.what
            );
        }
    }
    // docs/testing.md: "23 kinds of bad input".
    assert_eq!(
        cases.len(),
        23,
        "docs/testing.md quotes the number of cases"
    );
    let after: Vec<Vec<u8>> = files
        .iter()
        .map(|f| std::fs::read(out.join(f)).unwrap())
        .collect();
    assert!(before == after, "a failed run changed the earlier outputs");
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| !files.contains(&&*e.file_name().to_string_lossy()))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
}
