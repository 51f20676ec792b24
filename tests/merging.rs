//! Surfaces, not triangles: connected coplanar faces of one material become one polygon
//! (`scene::merge`), the run says `N faces → M polygons`, `--keep-faces` and `# keep-faces` keep
//! them apart, and the Table 1 rooms keep their exact counts.

use gpu_radiosity::scene::{load_obj, load_obj_with, LoadOptions};
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

/// A 4 m × 3 m × 2.5 m room, every wall a grid of `n`×`n` quads cut into triangles, the ceiling
/// with a lamp (its own material) in its middle cell, and a box on the floor (its own faces).
fn tessellated_room(n: usize) -> String {
    let mut obj = String::from("mtllib room.mtl\n");
    let mut vertices = 0;
    let mut quad = |obj: &mut String, corners: [[f32; 3]; 4], material: &str, split: bool| {
        let _ = writeln!(obj, "usemtl {material}");
        for c in corners {
            let _ = writeln!(obj, "v {} {} {}", c[0], c[1], c[2]);
        }
        let b = vertices + 1;
        if split {
            let _ = writeln!(
                obj,
                "f {} {} {}\nf {} {} {}",
                b,
                b + 1,
                b + 2,
                b,
                b + 2,
                b + 3
            );
        } else {
            let _ = writeln!(obj, "f {} {} {} {}", b, b + 1, b + 2, b + 3);
        }
        vertices += 4;
    };
    let (w, h, d) = (4.0f32, 2.5f32, 3.0f32);
    // Each wall: origin, two edge vectors (u × v points into the room), material.
    type Wall = ([f32; 3], [f32; 3], [f32; 3], &'static str);
    let walls: [Wall; 6] = [
        ([0.0, 0.0, 0.0], [0.0, 0.0, d], [w, 0.0, 0.0], "floor"),
        ([0.0, h, 0.0], [w, 0.0, 0.0], [0.0, 0.0, d], "ceiling"),
        ([0.0, 0.0, 0.0], [w, 0.0, 0.0], [0.0, h, 0.0], "wall"),
        ([0.0, 0.0, d], [0.0, h, 0.0], [w, 0.0, 0.0], "wall"),
        ([0.0, 0.0, 0.0], [0.0, h, 0.0], [0.0, 0.0, d], "wall"),
        ([w, 0.0, 0.0], [0.0, 0.0, d], [0.0, h, 0.0], "wall"),
    ];
    for (o, u, v, material) in walls {
        for i in 0..n {
            for j in 0..n {
                let at = |a: f32, b: f32| {
                    [0, 1, 2].map(|k| o[k] + u[k] * a / n as f32 + v[k] * b / n as f32)
                };
                let (a, b) = (i as f32, j as f32);
                let lamp = material == "ceiling" && i == n / 2 && j == n / 2;
                let corners = [
                    at(a, b),
                    at(a + 1.0, b),
                    at(a + 1.0, b + 1.0),
                    at(a, b + 1.0),
                ];
                quad(
                    &mut obj,
                    corners,
                    if lamp { "lamp" } else { material },
                    true,
                );
            }
        }
    }
    obj
}

const ROOM_MTL: &str = "newmtl floor\nKd 0.6 0.6 0.6\nnewmtl ceiling\nKd 0.8 0.8 0.8\n\
                        newmtl wall\nKd 0.7 0.5 0.4\nnewmtl lamp\nKd 0.8 0.8 0.8\nKe 10 10 10\n";

fn write_room(dir: &Path, n: usize, header: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("room.mtl"), ROOM_MTL).unwrap();
    let path = dir.join("room.obj");
    std::fs::write(&path, format!("{header}{}", tessellated_room(n))).unwrap();
    path
}

/// A room of 6 × 2 × 10² triangles: the floor and the walls are one polygon each, the ceiling
/// (a lamp cut out of its middle) a few around the hole, and the merged polygons cover exactly
/// the faces' area.
#[test]
fn a_tessellated_room_becomes_its_walls() {
    let tmp = tempfile::tempdir().unwrap();
    let path = write_room(tmp.path(), 10, "");
    let merged = load_obj(&path).unwrap();
    let kept = load_obj_with(
        &path,
        &LoadOptions {
            keep_faces: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(kept.faces, 1200);
    assert_eq!(kept.polygons.len(), 1200);
    assert_eq!(merged.faces, 1200);
    // Floor and 4 walls: one each. Ceiling: a ring around the lamp cannot be one outline, so at
    // least two; the lamp's two triangles: one.
    let n = merged.polygons.len();
    assert!((1 + 4 + 2 + 1..=1 + 4 + 4 + 1).contains(&n), "{n} polygons");
    let area = |s: &gpu_radiosity::scene::Scene, material: &str| -> f64 {
        (s.polygons.iter())
            .filter(|p| s.material(p).name == material)
            .map(|p| p.area as f64)
            .sum()
    };
    for material in ["floor", "ceiling", "wall", "lamp"] {
        let (a, b) = (area(&merged, material), area(&kept, material));
        assert!((a - b).abs() < 1e-4 * b, "{material}: {a} against {b}");
    }
    let count = |material: &str| {
        (merged.polygons.iter())
            .filter(|p| merged.material(p).name == material)
            .count()
    };
    assert_eq!(count("floor"), 1);
    assert_eq!(count("wall"), 4);
    assert_eq!(count("lamp"), 1);
}

/// The command line says what merging did and records it; `--keep-faces` and the header line
/// `# keep-faces` keep every face its own polygon.
#[test]
fn the_run_says_faces_to_polygons_and_keep_faces_keeps_them() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    write_room(d, 6, "");
    let run = |extra: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_radiosity"))
            .current_dir(d)
            .args(["solve", "room.obj", "--max-shots", "2", "--size", "32x32"])
            .args(extra)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr).to_string();
        assert!(o.status.success(), "{stderr}");
        let stats: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("out/room/stats.json")).unwrap()).unwrap();
        (stderr, stats)
    };
    let (stderr, stats) = run(&[]);
    let polygons = stats["polygons"].as_u64().unwrap();
    assert_eq!(stats["faces"], 432);
    assert!(polygons < 20, "{polygons} polygons");
    assert!(
        stderr.contains(&format!("432 faces → {polygons} polygons")),
        "{stderr}"
    );
    let (stderr, stats) = run(&["--keep-faces"]);
    assert_eq!(
        (stats["faces"].as_u64(), stats["polygons"].as_u64()),
        (Some(432), Some(432))
    );
    assert!(!stderr.contains('→'), "{stderr}");
    write_room(d, 6, "# keep-faces\n");
    let (_, stats) = run(&[]);
    assert_eq!(stats["polygons"], 432);
}

/// Table 1 counts faces: the rooms carry `# keep-faces`, and load with their exact counts.
#[test]
fn the_table_1_rooms_keep_their_faces() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (room, faces) in [("simple", 1602), ("complex", 8549)] {
        let scene = load_obj(&root.join(format!("scenes/{room}/{room}.obj"))).unwrap();
        assert_eq!(
            (scene.faces, scene.polygons.len()),
            (faces, faces),
            "{room}"
        );
    }
}
