//! The paper's two virtual rooms (`roomgen simple|complex`, tools/roomgen/):
//! the committed files are exactly what the generator writes, they have exactly Table 1's
//! counts, and they are well-formed rooms (planar convex polygons; walls, floors and ceilings
//! facing the inside; lights facing down; furniture facing outward; nothing outside the rooms).

use glam::Vec3;
use gpu_radiosity::patches::{PatchLayout, Resolution};
use gpu_radiosity::scene::{load_obj, Polygon, Scene};
use roomgen::{generate, GeneratedScene, Room};
use std::collections::BTreeMap;
use std::path::PathBuf;

const ROOMS: [Room; 2] = [Room::Simple, Room::Complex];

fn path(room: Room, ext: &str) -> PathBuf {
    let name = room.name();
    // The rooms are committed with the solver's other scenes, two levels up.
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
        .join(format!("{name}.{ext}"))
}

fn load(room: Room) -> Scene {
    load_obj(&path(room, "obj")).expect("the committed scene loads")
}

fn generated(room: Room) -> GeneratedScene {
    generate(room, &format!("{}.mtl", room.name()))
}

fn patches(scene: &Scene, size: f32) -> u64 {
    PatchLayout::new(scene, Resolution::PatchSize(size)).patch_count()
}

/// Shell polygons: the rooms' own surfaces, as named by the generator.
fn is_shell(object: &str) -> bool {
    ["floor_", "ceiling_", "wall_", "light_", "doorway_"]
        .iter()
        .any(|p| object.starts_with(p))
}

fn inside(boxes: &[(Vec3, Vec3)], p: Vec3, tolerance: f32) -> bool {
    boxes.iter().any(|(lo, hi)| {
        p.cmpge(*lo - Vec3::splat(tolerance)).all() && p.cmple(*hi + Vec3::splat(tolerance)).all()
    })
}

#[test]
fn the_generator_reproduces_the_committed_files() {
    for room in ROOMS {
        let g = generated(room);
        for (ext, text) in [("obj", &g.obj), ("mtl", &g.mtl)] {
            let file = path(room, ext);
            let committed = std::fs::read_to_string(&file).expect("the committed file exists");
            if committed != *text {
                let line = committed
                    .lines()
                    .zip(text.lines())
                    .position(|(a, b)| a != b)
                    .map(|n| n + 1)
                    .unwrap_or(committed.lines().count().min(text.lines().count()) + 1);
                panic!(
                    "{} differs from the generator's output from line {line} on; \
                     regenerate it with `cargo run --release -p roomgen -- {}`",
                    file.display(),
                    room.name()
                );
            }
        }
    }
}

#[test]
fn the_committed_rooms_have_the_papers_counts() {
    // Table 1 of the paper (docs/conventions.md).
    for (room, faces, vertices, lights, patch_count) in [
        (Room::Simple, 1_602, 6_431, 2, 14_445),
        (Room::Complex, 8_549, 35_785, 6, 86_077),
    ] {
        let scene = load(room);
        let size = scene.patch_size.expect("a `# patch-size` line");
        let name = room.name();
        assert_eq!(scene.polygons.len(), faces, "{name}: faces");
        assert_eq!(scene.vertex_count, vertices, "{name}: vertices");
        assert_eq!(scene.light_count(), lights, "{name}: lights");
        assert_eq!(patches(&scene, size), patch_count, "{name}: patches");
        assert_eq!(scene.skipped_degenerate, 0, "{name}: degenerate polygons");
        // The count does not hang on a rounding: no lightmap side sits on a multiple of the
        // patch size.
        for f in [1.0 - 1e-4, 1.0 + 1e-4] {
            assert_eq!(
                patches(&scene, size * f),
                patch_count,
                "{name}: at {f} × {size}"
            );
        }
    }
}

#[test]
fn polygons_are_planar_convex_and_not_degenerate() {
    for room in ROOMS {
        let scene = load(room);
        for p in &scene.polygons {
            let what = format!("{}: {}", room.name(), p.object);
            assert!(p.vertices.len() >= 3, "{what}");
            assert!(p.area > 1e-5, "{what}: area {} m²", p.area);
            for v in &p.vertices {
                let off = (*v - p.centroid).dot(p.normal).abs();
                assert!(off < 1e-5, "{what}: a vertex {off} m off the plane");
            }
            let n = p.vertices.len();
            for i in 0..n {
                let (a, b, c) = (
                    p.vertices[i],
                    p.vertices[(i + 1) % n],
                    p.vertices[(i + 2) % n],
                );
                let turn = (b - a).cross(c - b).dot(p.normal);
                assert!(
                    turn > 0.0,
                    "{what}: not strictly convex at vertex {}",
                    i + 1
                );
            }
        }
    }
}

#[test]
fn rooms_face_their_inside_and_lights_face_down() {
    for room in ROOMS {
        let scene = load(room);
        let g = generated(room);
        let name = room.name();
        let ceiling = g.interior.iter().map(|b| b.1.y).fold(0.0, f32::max);
        let mut shell = 0;
        for p in scene.polygons.iter().filter(|p| is_shell(&p.object)) {
            shell += 1;
            let front = p.centroid + 0.05 * p.normal;
            let back = p.centroid - 0.05 * p.normal;
            assert!(
                inside(&g.interior, front, -1e-3),
                "{name}: {} does not face the inside",
                p.object
            );
            assert!(
                !inside(&g.interior, back, -1e-3),
                "{name}: {} has the inside behind it",
                p.object
            );
        }
        assert!(shell > 100, "{name}: only {shell} shell polygons");
        let mut lights = 0;
        for p in &scene.polygons {
            let m = scene.material(p);
            if m.is_emitter() {
                lights += 1;
                assert!(p.object.starts_with("light_"), "{name}: {} emits", p.object);
                assert!(
                    p.normal.dot(Vec3::NEG_Y) > 0.9999,
                    "{name}: a light faces down"
                );
                assert!(
                    p.vertices.iter().all(|v| (v.y - ceiling).abs() < 1e-6),
                    "{name}: a light sits in the ceiling's plane"
                );
                assert!(m.ke.min_element() >= 10.0 && m.ke.max_element() <= 20.0);
                assert!((m.kd - Vec3::splat(0.78)).abs().max_element() < 1e-6);
            }
        }
        assert_eq!(lights, scene.light_count());
        // Every vertex, of furniture too, is inside the rooms (nothing goes through a wall).
        for p in &scene.polygons {
            for v in &p.vertices {
                assert!(
                    inside(&g.interior, *v, 1e-6),
                    "{name}: {} has a vertex {v} outside the rooms",
                    p.object
                );
            }
        }
        // And so is the camera.
        let camera = scene.camera.expect("a `# camera` line");
        assert!(inside(&g.interior, camera.eye, -0.05), "{name}: camera");
        assert!(
            inside(&g.interior, camera.target, 0.0),
            "{name}: camera target"
        );
    }
}

#[test]
fn furniture_faces_outward() {
    for room in ROOMS {
        let scene = load(room);
        let mut pieces: BTreeMap<&str, Vec<&Polygon>> = BTreeMap::new();
        for p in scene.polygons.iter().filter(|p| !is_shell(&p.object)) {
            pieces.entry(p.object.as_str()).or_default().push(p);
        }
        let mut solids = 0;
        for (object, faces) in pieces {
            if faces.len() < 2 {
                continue; // flat things: rugs, papers, canvases, glass
            }
            solids += 1;
            // Every piece is a convex solid (a box or a cylinder, some faces left out where
            // they rest on something): the mean of its vertices lies behind each of its faces.
            let all: Vec<Vec3> = faces
                .iter()
                .flat_map(|p| p.vertices.iter().copied())
                .collect();
            let mean = all.iter().sum::<Vec3>() / all.len() as f32;
            for p in faces {
                assert!(
                    (p.centroid - mean).dot(p.normal) > 0.0,
                    "{}: a face of {object} faces inward",
                    room.name()
                );
            }
        }
        assert!(solids > 200, "{}: only {solids} solid pieces", room.name());
    }
}
