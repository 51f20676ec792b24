//! From an OBJ file (and its MTL libraries) to a [`Scene`], keeping polygons as polygons (no
//! triangulation: a quad is one face with one lightmap, as in the paper).

use super::emission::LoadOptions;
use super::error::{SceneError, MAX_SCENE_SIZE, MIN_SCENE_SIZE};
use super::files::{decode, read_regular, shown, shown_path, Folder, MaterialFiles, MAX_OBJ_BYTES};
use super::header::parse_header;
use super::libraries::{load_libraries, Materials};
use super::obj::{parse_obj, ObjFile};
use super::{Camera, Polygon, Scene};
use glam::Vec3;
use std::path::Path;

/// The scene in the OBJ file `path`, with its MTL libraries from the same folder.
pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    load_obj_with(path, &LoadOptions::default())
}

/// [`load_obj`] with `options` applied (emission overrides) before the check that the scene
/// emits light.
pub fn load_obj_with(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
    let (bytes, dir) = read_scene_file(path)?;
    parse_scene(path, &decode(&bytes), &Folder(dir), options)
}

/// The scene file at `path` (within the size limit of every scene file), and the folder its
/// relative references are read from (`.` for a bare file name).
pub(super) fn read_scene_file(path: &Path) -> Result<(Vec<u8>, &Path), SceneError> {
    let bytes = read_regular(path, MAX_OBJ_BYTES).map_err(|source| SceneError::Read {
        path: shown_path(path),
        source,
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Ok((bytes, dir))
}

/// The scene in an OBJ text. `path` names it in messages and locates the MTL files it names,
/// which `files` fetches (from disk, or from the copies built into the binary): files and
/// built-in scenes go through the same checks.
pub(super) fn parse_scene(
    path: &Path,
    text: &str,
    files: &dyn MaterialFiles,
    options: &LoadOptions,
) -> Result<Scene, SceneError> {
    let header = parse_header(path, text)?;
    let obj = parse_obj(path, text)?;
    let mut messages = Vec::new();
    if let Some(s) = obj.skipped.summary() {
        messages.push(format!("note: {}: {s}", shown_path(path)));
    }
    let materials = load_libraries(path, &obj, files, &mut messages)?;
    let parsed = Parsed {
        obj,
        materials,
        camera: header.camera,
        patch_size: header.patch_size,
        keep_faces: header.keep_faces,
        messages,
    };
    build_scene(path, parsed, files.built_in(), options)
}

/// What a reader (OBJ here, glTF in `gltf.rs`) hands on to [`build_scene`]: faces indexing
/// positions, with their material and object, and what the file says besides.
pub(super) struct Parsed {
    pub obj: ObjFile,
    pub materials: Materials,
    pub camera: Option<Camera>,
    pub patch_size: Option<f32>,
    pub keep_faces: bool,
    /// Warnings and notes so far, printed with the builder's own.
    pub messages: Vec<String>,
}

/// The scene of `parsed`, whichever format it was read from: polygons built (non-planar ones
/// split, zero-area ones skipped), duplicates dropped, coplanar faces merged, and the same
/// checks (scale, emission). `built_in`: notes are not repeated for the scenes built in.
pub(super) fn build_scene(
    path: &Path,
    parsed: Parsed,
    built_in: bool,
    options: &LoadOptions,
) -> Result<Scene, SceneError> {
    let shown_name = shown_path(path);
    let Parsed {
        obj,
        materials,
        camera,
        patch_size,
        keep_faces,
        mut messages,
    } = parsed;
    check_scale(&shown_name, &obj)?;
    let default = materials.list.len() - 1;
    let built = build_polygons(&obj, |m| {
        m.map_or(default, |m| materials.of_name[m as usize])
    });
    let mut polygons = built.polygons;
    if built.split > 0 {
        messages.push(format!(
            "warning: {shown_name}: split {} non-planar polygon(s) (off their plane by more than \
             1 % of their size) into triangles",
            built.split
        ));
    }
    if built.skipped > 0 {
        messages.push(format!(
            "warning: {shown_name}: skipped {} polygon(s) with zero area",
            built.skipped
        ));
    }
    let (dropped, names) = super::overlap::drop_duplicates(&mut polygons);
    if dropped > 0 {
        messages.push(format!(
            "warning: {shown_name}: dropped {dropped} face(s) given twice (same corners; each \
             copy would receive the same light and create energy): {}",
            names.join(", ")
        ));
    }
    let faces = polygons.len();
    if !(options.keep_faces || keep_faces) {
        let size = scene_size(&polygons);
        let report = super::merge::merge_coplanar(&mut polygons, size);
        if report.polygons < report.faces {
            messages.push(format!(
                "note: {shown_name}: {} faces → {} polygons (connected coplanar faces of one \
                 material merged; --keep-faces keeps them apart)",
                report.faces, report.polygons
            ));
        }
    }
    if let Some(m) = overlap_warning(&shown_name, &polygons) {
        messages.push(m);
    }
    for m in &messages {
        if !(built_in && m.starts_with("note:")) {
            eprintln!("{m}");
        }
    }
    if polygons.is_empty() {
        return Err(SceneError::Empty { path: shown_name });
    }
    let mut scene = Scene {
        name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        polygons,
        materials: materials.list,
        vertex_count: obj.positions.len(),
        camera,
        patch_size,
        skipped_degenerate: built.skipped,
        faces,
    };
    scene.apply_emission(&shown_name, &options.emit)?;
    if let Some(radiance) = options.sky {
        (scene.add_sky(radiance)).map_err(|source| SceneError::Emit {
            path: shown_name.clone(),
            source,
        })?;
    }
    scene.check_emits(&shown_name)?;
    Ok(scene)
}

/// The diagonal of the polygons' bounding box.
fn scene_size(polygons: &[Polygon]) -> f32 {
    let all: Vec<Vec3> = polygons
        .iter()
        .flat_map(|p| p.vertices.iter().copied())
        .collect();
    crate::geometry::bounds(&all).map_or(0.0, |(lo, hi)| (hi - lo).length())
}

/// Outside this range f32 loses the scene: at 1e-18 areas underflow to zero, at 1e±9 a shot
/// reflected 3e-6 % or 11.8 % of its power instead of 7.1 %. tests/hostile.rs solves the
/// shadow scene scaled to both ends of the range and finds its first shot unchanged.
fn check_scale(path: &str, obj: &ObjFile) -> Result<(), SceneError> {
    let (lo, hi) = obj
        .corners
        .iter()
        .map(|&i| obj.positions[i as usize])
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
    let size = (hi.as_dvec3() - lo.as_dvec3()).length() as f32;
    if lo.x <= hi.x && !(MIN_SCENE_SIZE..=MAX_SCENE_SIZE).contains(&size) {
        return Err(SceneError::Scale {
            path: path.to_string(),
            size,
        });
    }
    Ok(())
}

struct Built {
    polygons: Vec<Polygon>,
    /// Faces dropped for (near) zero area.
    skipped: usize,
    /// Non-planar faces split into triangles.
    split: usize,
}

/// A polygon per face, in file order, with the material `material` gives for the face's
/// `usemtl` name.
fn build_polygons(obj: &ObjFile, material: impl Fn(Option<u32>) -> usize) -> Built {
    // Escaped once here: every message that names an object echoes it.
    let objects: Vec<String> = obj.object_names.iter().map(|n| shown(n)).collect();
    let mut built = Built {
        polygons: Vec::with_capacity(obj.faces.len()),
        skipped: 0,
        split: 0,
    };
    for face in &obj.faces {
        let vertices: Vec<Vec3> = obj
            .corners_of(face)
            .iter()
            .map(|&i| obj.positions[i as usize])
            .collect();
        let (material, object) = (material(face.material), &objects[face.object as usize]);
        match Polygon::new(vertices, material, object.clone()) {
            // A badly non-planar polygon has no one plane for its lightmap: split it into
            // triangles, each planar. Ear clipping on its mean plane, not a fan: a fan of a
            // non-convex outline folds over itself, and triangles that overlap each receive
            // the same light (a 10,000-corner zigzag reflected 12.5x its light).
            Some(p) if p.vertices.len() > 3 && !p.is_planar(0.01) => {
                built.split += 1;
                for t in super::triangulate(&p.vertices, p.normal) {
                    let tri = t.map(|k| p.vertices[k]).to_vec();
                    match Polygon::new(tri, material, object.clone()) {
                        Some(t) => built.polygons.push(t),
                        None => built.skipped += 1,
                    }
                }
            }
            Some(p) => built.polygons.push(p),
            None => built.skipped += 1,
        }
    }
    built
}

/// A warning, not an error: the paper's rooms have such faces (a door jamb inside its
/// architrave's side), where the excess is far below the solver's balance check's tolerance.
/// Where it is not, that check stops the solve and names the receivers.
fn overlap_warning(path: &str, polygons: &[Polygon]) -> Option<String> {
    let all: Vec<Vec3> = polygons
        .iter()
        .flat_map(|p| p.vertices.iter().copied())
        .collect();
    let (lo, hi) = crate::geometry::bounds(&all)?;
    let slack = 1e-5 * (hi - lo).length();
    let o = super::overlap::find_overlap(polygons, slack)?;
    Some(format!(
        "warning: {path}: faces overlap in one plane, facing the same way: {} and {}. Both \
         receive the light that falls on their common part, which creates energy; if a shot \
         reflects more than it received the solve stops",
        super::overlap::describe(&polygons[o.a]),
        super::overlap::describe(&polygons[o.b]),
    ))
}
