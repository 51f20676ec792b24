//! Scenes as exporters write them (issue 35): CRLF line ends, tabs, trailing comments,
//! statements and values the solver has no use for, reflectances above 1, a library under
//! another name, no emitter; lit with `--emit` and seen from the default camera.

use gpu_radiosity::scene::{load_obj, load_obj_with, Emission, LoadOptions, SceneError};
use std::path::Path;
use std::process::{Command, Output};

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

fn radiosity(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// Lines joined with CRLF, as Windows exporters write them.
fn crlf(lines: &[&str]) -> String {
    lines.iter().map(|l| format!("{l}\r\n")).collect()
}

/// The materials of the room: every statement an MTL may hold, most with values the solver
/// could not use (an ambient of 20, NaN specular), indented with tabs, commented at the end.
fn room_mtl() -> String {
    crlf(&[
        "# Exported by SomeTool 3.1 -- materials",
        "newmtl white",
        "\tNs 96.078431",
        "\tKa 20 20 20 # the ambient term, as a popular OBJ library's test box has it",
        "\tKd 0.7 0.7 0.7 # White",
        "\tKs nan nan nan",
        "\tKe 0 0 0",
        "\tNi 1.000000",
        "\td 0.5",
        "\tTr -3",
        "\tTf 1 1 1",
        "\tillum 99",
        "\tmap_Kd -s 1 1 1 my texture.png",
        "\tmap_Bump -bm 0.5 normal.png",
        "\tbump bump.png",
        "\tdisp disp.png",
        "\trefl -type sphere sky.png",
        "\tPr 0.5",
        "\tPm 1",
        "\tPs 0 0 0",
        "\tPc 0",
        "\tPcr 0",
        "\taniso 0",
        "\tanisor 0",
        "\tnorm normal.png",
        "newmtl red",
        "\tKa 0.63 0.065 0.05 # Red",
        "\tKd 0.63 0.065 0.05",
        "newmtl green",
        "\tKd\t0.14\t0.45\t0.091",
        "newmtl blue",
        "\tKd 0.1 0.1 0.7",
        "newmtl lamp",
        "\tKd 0.78 0.78 0.78",
        "newmtl glow",
        "\tKd 1.2 0.5 1.2 # brighter than white",
    ])
}

/// A closed room 4 wide (x), 3 high, 6 long (z), walls facing in: floor, ceiling and the near
/// wall white, the left wall (x = 0) red, the right one green, the far one (z = 6) blue, a lamp
/// under the ceiling facing down. Faces in every form of `f`, and the OBJ statements the solver
/// does not use. No `# camera` line.
fn room_obj() -> String {
    crlf(&[
        "# Exported by SomeTool 3.1",
        "mtllib room.mtl # materials",
        "o Room # the walls",
        "v\t0 0 0",
        "v 4 0 0",
        "  v 4 0 6",
        "v 0 0 6 # corner",
        "v 0 3 0",
        "v 4 3 0 1.0",
        "v 4 3 6 0.5 0.5 0.5",
        "v 0 3 6",
        "vt 0 0",
        "vt 1 0",
        "vt 1 1",
        "vn 0 1 0",
        "vp 0.5 0.5",
        "s off",
        "g floor",
        "usemtl white",
        "f 1/1/1 4/2/1 3/3/1 2/1/1",
        "g ceiling",
        "f 5//1 6//1 7//1 8//1",
        "g near",
        "f 1/1 2/2 6/3 5/1",
        "s 1",
        "g left",
        "usemtl red",
        "f\t1\t5\t8\t4",
        "g right",
        "usemtl green",
        "f 2 3 7 6 # right wall",
        "g far",
        "usemtl blue",
        "f 4 8 7 3",
        "l 1 2 3",
        "p 1",
        "usemap none",
        "mg 1 0.5",
        "cstype bspline",
        "deg 3",
        "shadow_obj shadow.obj",
        "trace_obj trace.obj",
        "maplib lib.mpc",
        "o Lamp",
        "v 1.5 2.95 2.5",
        "v 2.5 2.95 2.5",
        "v 2.5 2.95 3.5",
        "v 1.5 2.95 3.5",
        "usemtl lamp",
        "f -4 -3 -2 -1",
    ])
}

fn room(dir: &Path) {
    write(dir, "room.obj", &room_obj());
    write(dir, "room.mtl", &room_mtl());
}

fn lamp(ke: [f32; 3]) -> LoadOptions {
    LoadOptions {
        emit: vec![Emission {
            material: "lamp".into(),
            ke,
        }],
        ..Default::default()
    }
}

#[test]
fn what_exporters_write_loads_as_written() {
    let tmp = tempfile::tempdir().unwrap();
    room(tmp.path());
    let path = tmp.path().join("room.obj");
    // Nothing in the files emits.
    let e = load_obj(&path).unwrap_err();
    assert!(matches!(e, SceneError::NoEmitter { .. }), "{e}");
    let scene = load_obj_with(&path, &lamp([10.0, 10.0, 10.0])).unwrap();
    assert_eq!(scene.polygons.len(), 7);
    assert_eq!(scene.vertex_count, 12);
    assert_eq!(scene.light_count(), 1);
    let m = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap();
    assert_eq!(m("white").kd.to_array(), [0.7; 3]);
    assert_eq!(m("green").kd.to_array(), [0.14, 0.45, 0.091]);
    assert_eq!(m("glow").kd.to_array(), [1.0, 0.5, 1.0], "clamped to 1");
    assert_eq!(m("lamp").ke.to_array(), [10.0; 3]);
    let objects: Vec<&str> = scene.polygons.iter().map(|p| p.object.as_str()).collect();
    assert_eq!(
        objects,
        ["floor", "ceiling", "near", "left", "right", "far", "Lamp"]
    );
    // Every wall faces the inside; the polylines and points made no faces.
    let centre = glam::Vec3::new(2.0, 1.5, 3.0);
    for p in &scene.polygons {
        assert!(p.normal.dot(centre - p.centroid) > 0.0, "{}", p.object);
    }
}

#[test]
fn the_command_line_says_what_it_skipped_and_clamped() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    room(d);
    let o = radiosity(
        d,
        &[
            "solve",
            "room.obj",
            "--emit",
            "lamp=10,10,10",
            "--patches",
            "300",
            "--max-shots",
            "2",
            "--size",
            "16x16",
        ],
    );
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    for expected in [
        "note: room.obj: skipped 12 statements the solver does not use (s ×2, cstype ×1, deg ×1, \
         l ×1, maplib ×1, mg ×1, p ×1, shadow_obj ×1, trace_obj ×1, usemap ×1, 1 other)",
        "note: room.mtl: skipped 22 statements the solver does not use (Ka ×2, Ks ×1, Ni ×1, \
         Ns ×1, Pc ×1, Pcr ×1, Pm ×1, Pr ×1, Ps ×1, Tf ×1, 11 others)",
        "warning: room.mtl:36: material 'glow' has Kd 1.2 0.5 1.2, above 1: a surface would \
         reflect more light than it receives, so it is clamped to 1 0.5 1",
    ] {
        assert!(lines.contains(&expected), "expected\n{expected}\nin\n{err}");
    }
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("out/room/stats.json")).unwrap())
            .unwrap();
    assert_eq!(
        stats["emit"],
        serde_json::json!([{"material": "lamp", "ke": [10.0, 10.0, 10.0]}])
    );
    assert_eq!(stats["lights"], 1);
}

#[test]
fn no_emitter_lists_the_materials_by_area_and_emit_errors_name_them() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    room(d);
    let o = radiosity(d, &["solve", "room.obj"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let expected = "error: room.obj: the scene has no emitter: no material has a positive Ke. \
                    Its materials, largest area first: white (3 faces, area 60.0), red (1 face, \
                    area 18.0), green (1 face, area 18.0), blue (1 face, area 12.0), lamp (1 \
                    face, area 1.00), glow (0 faces, area 0). Make one emit light with \
                    `--emit NAME=R,G,B` (emitted radiance, as `Ke R G B` in the MTL file), or \
                    light a scene open to the sky with `--sky R,G,B`";
    assert!(err.lines().any(|l| l == expected), "{err}");

    // A name the scene does not have: the error lists the materials (exit 1, both commands;
    // `view` stops before it opens a window).
    for command in ["solve", "view"] {
        let o = radiosity(d, &[command, "room.obj", "--emit", "Lamp=1,1,1"]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{command}: {err}");
        assert!(
            err.contains(
                "room.obj: cannot make the material 'Lamp' emit: the scene has no material of \
                 that name. Its materials: white, red, green, blue, lamp, glow, (default)"
            ),
            "{command}: {err}"
        );
    }
    // Malformed values are usage errors (exit 2) with the form expected.
    for (value, needle) in [
        ("lamp=1,1", "expected NAME=R,G,B"),
        ("lamp", "expected NAME=R,G,B"),
        ("=1,1,1", "expected NAME=R,G,B"),
        ("lamp=-1,0,0", "from 0 to 1e15"),
        ("lamp=nan,0,0", "from 0 to 1e15"),
    ] {
        for command in ["solve", "view"] {
            let o = radiosity(d, &[command, "room.obj", "--emit", value]);
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{command} {value}: {err}");
            assert!(err.contains("--emit") && err.contains(needle), "{err}");
        }
    }
    // An emitter turned off: the scene has none left.
    let o = radiosity(
        d,
        &[
            "solve",
            "room.obj",
            "--emit",
            "lamp=1,1,1",
            "--emit",
            "lamp=0,0,0",
        ],
    );
    assert!(stderr(&o).contains("has no emitter"), "{}", stderr(&o));
}

#[test]
fn a_missing_library_names_the_file_that_defines_its_materials() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let obj = room_obj().replace("mtllib room.mtl", "mtllib cornell.mtl");
    write(d, "cornell.obj", &obj);
    write(d, "CornellBox-Original.mtl", &room_mtl());
    write(d, "other.mtl", "newmtl white\nKd 1 1 1\n");
    let o = radiosity(d, &["solve", "cornell.obj"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(
            "warning: cornell.obj:2: cannot read the material library cornell.mtl (No such file \
             or directory (os error 2)); CornellBox-Original.mtl in the same folder defines all \
             5 materials used: change the `mtllib` line to name it; until then faces with those \
             materials are grey"
        ),
        "{err}"
    );
    // The geometry loaded, grey: the error lists it under the default material.
    assert!(
        err.contains("largest area first: (default) (7 faces, area 109)"),
        "{err}"
    );
    // Nothing in the folder defines them.
    std::fs::remove_file(d.join("CornellBox-Original.mtl")).unwrap();
    std::fs::remove_file(d.join("other.mtl")).unwrap();
    let err = stderr(&radiosity(d, &["solve", "cornell.obj"]));
    assert!(
        err.contains(
            "no .mtl file in the same folder defines the materials used ('white', 'red', \
             'green', 'blue', 'lamp')"
        ),
        "{err}"
    );
}

/// The hostile-input rules hold whatever the spacing: a library out of the folder after a tab
/// and before a comment is refused; a hot `Ke` behind a comment is an error with its line.
#[test]
fn exporter_spacing_does_not_open_the_hostile_input_checks() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::create_dir(d.join("sub")).unwrap();
    write(d, "up.mtl", &room_mtl());
    let up = room_obj().replace("mtllib room.mtl # materials", "mtllib\t../up.mtl\t# up");
    write(d, "sub/up.obj", &up);
    let e = load_obj(&d.join("sub/up.obj")).unwrap_err().to_string();
    assert!(
        e.contains("../up.mtl") && e.contains("outside the scene's folder"),
        "{e}"
    );
    write(d, "room.obj", &room_obj());
    write(
        d,
        "room.mtl",
        &room_mtl().replace("\tKe 0 0 0\r\n", "\tKe 1e39 1 1 # hot\r\n"),
    );
    let e = load_obj(&d.join("room.obj")).unwrap_err().to_string();
    assert!(
        e.contains("room.mtl:7: `Ke` needs three numbers in [0, 1e15], got `Ke 1e39 1 1`"),
        "{e}"
    );
}

/// Pixels of an sRGB PNG.
fn pixels(path: &Path) -> Vec<[u8; 3]> {
    let image = image::open(path).unwrap().to_rgb8();
    image.pixels().map(|p| p.0).collect()
}

/// The default camera shows a closed room from inside: most of the picture is lit surface,
/// and the walls of four colours are all in it.
#[test]
fn the_default_camera_shows_a_closed_room_from_inside() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    room(d);
    let o = radiosity(
        d,
        &[
            "solve",
            "room.obj",
            "--emit",
            "lamp=20,20,20",
            "--patches",
            "600",
            "--max-shots",
            "12",
            "--size",
            "64x64",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let px = pixels(&d.join("out/room/image.png"));
    let share =
        |f: &dyn Fn(&[u8; 3]) -> bool| px.iter().filter(|p| f(p)).count() as f32 / px.len() as f32;
    let lit = share(&|p| p.iter().any(|&c| c > 8));
    assert!(lit > 0.95, "only {lit} of the picture is lit");
    let dominant = |k: usize| {
        move |p: &[u8; 3]| (0..3).all(|j| j == k || p[k] as f32 > 1.3 * p[j] as f32 + 4.0)
    };
    let grey = share(&|p| {
        let (lo, hi) = (p.iter().min().unwrap(), p.iter().max().unwrap());
        *hi > 40 && (*hi as f32) < 1.2 * *lo as f32 + 4.0
    });
    let (red, green, blue) = (
        share(&dominant(0)),
        share(&dominant(1)),
        share(&dominant(2)),
    );
    println!("lit {lit}, red {red}, green {green}, blue {blue}, grey {grey}");
    for (what, s) in [
        ("red", red),
        ("green", green),
        ("blue", blue),
        ("white", grey),
    ] {
        assert!(s > 0.03, "the {what} surfaces cover {s} of the picture");
    }
}

/// An open scene (a block on a floor under a lamp) is seen whole: nothing touches the border
/// of the picture, and the scene spans most of it.
#[test]
fn the_default_camera_shows_an_open_scene_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    write(
        d,
        "open.mtl",
        "newmtl floor\nKd 0.7 0.7 0.7\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n",
    );
    write(
        d,
        "open.obj",
        &[
            "mtllib open.mtl",
            "usemtl floor",
            "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nf 1 4 3 2",
            // A cube, faces out.
            "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5",
            "v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5",
            "f 9 12 11 10\nf 5 9 10 6\nf 6 10 11 7\nf 8 7 11 12\nf 5 8 12 9",
            "usemtl lamp",
            "v -0.5 2 -0.5\nv 0.5 2 -0.5\nv 0.5 2 0.5\nv -0.5 2 0.5\nf 13 14 15 16",
        ]
        .join("\n"),
    );
    let o = radiosity(
        d,
        &[
            "solve",
            "open.obj",
            "--patches",
            "400",
            "--max-shots",
            "6",
            "--size",
            "64x64",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let px = pixels(&d.join("out/open/image.png"));
    let n = 64;
    let lit = |p: &[u8; 3]| p.iter().any(|&c| c > 8);
    let border = (0..px.len())
        .filter(|i| i % n == 0 || i % n == n - 1 || i / n == 0 || i / n == n - 1)
        .filter(|&i| lit(&px[i]))
        .count();
    assert_eq!(border, 0, "the scene reaches the border of the picture");
    let (xs, ys): (Vec<usize>, Vec<usize>) = (0..px.len())
        .filter(|&i| lit(&px[i]))
        .map(|i| (i % n, i / n))
        .unzip();
    let span = |v: &[usize]| v.iter().max().unwrap() - v.iter().min().unwrap();
    assert!(
        span(&xs) > n / 2 && span(&ys) > n / 2,
        "the scene spans only {}x{} of {n}x{n} pixels",
        span(&xs),
        span(&ys)
    );
}
