//! Wavefront OBJ + MTL loading through `tobj`, keeping polygons as polygons (no triangulation:
//! a quad is one face with one lightmap, as in the paper). Two comment lines are understood:
//! `# camera eye X Y Z target X Y Z up X Y Z fov DEG` and `# patch-size S`.

use super::{Camera, Material, Polygon, Scene};
use glam::Vec3;
use std::cell::RefCell;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("cannot read scene file {path}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}{line}: {what}")]
    Parse {
        path: String,
        line: String,
        what: String,
    },
    #[error("{path}: object '{object}' has a vertex that is not a finite number ({vertex})")]
    NotFinite {
        path: String,
        object: String,
        vertex: String,
    },
    #[error(
        "{path}: the scene has no emitter: no material has a positive Ke (materials: {materials}). \
         Give the lights a material with `Ke r g b` (emitted radiance)"
    )]
    NoEmitter { path: String, materials: String },
    #[error("{path}: cannot use the material library {mtl}: {reason}")]
    Material {
        path: String,
        mtl: String,
        reason: String,
    },
    #[error(
        "{path}: the scene is {size:e} units across (bounding-box diagonal); scenes from \
         {MIN_SCENE_SIZE:e} to {MAX_SCENE_SIZE:e} units are solved accurately (f32 positions, \
         areas and form factors). Scale the scene into that range"
    )]
    Scale { path: String, size: f32 },
    #[error(
        "{path}: the emitting material(s) {materials} have no face with a non-zero area, so \
         nothing emits: no face uses them, or theirs have zero area ({skipped} zero-area face(s) \
         skipped in the scene)"
    )]
    EmitterZeroArea {
        path: String,
        materials: String,
        skipped: usize,
    },
    #[error("{path}: the scene has no polygons with a non-zero area")]
    Empty { path: String },
}

/// Largest OBJ file read (bytes): beyond it a file is refused rather than read until memory
/// runs out (`/dev/zero` was read until the allocator aborted).
pub const MAX_OBJ_BYTES: u64 = 1 << 30;
/// Largest MTL file read (bytes): a material library is a few lines per material.
pub const MAX_MTL_BYTES: u64 = 16 << 20;

static ALLOW_OUTSIDE_MATERIALS: AtomicBool = AtomicBool::new(false);

/// Let `mtllib` name files outside the scene's folder (absolute paths, `../`); off by default,
/// so that a scene file cannot make the program read any file it can reach.
pub fn allow_outside_materials(allow: bool) {
    ALLOW_OUTSIDE_MATERIALS.store(allow, Ordering::Relaxed);
}

pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    let bytes = read_regular(path, MAX_OBJ_BYTES).map_err(|source| SceneError::Read {
        path: shown_path(path),
        source,
    })?;
    let text = String::from_utf8(bytes).map_err(|_| SceneError::Read {
        path: shown_path(path),
        source: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        ),
    })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    parse_obj(path, &text, |file| {
        if !ALLOW_OUTSIDE_MATERIALS.load(Ordering::Relaxed) {
            confined(dir, file)?;
        }
        read_regular(file, MAX_MTL_BYTES)
    })
}

/// Refuse `file` unless it resolves (symbolic links followed) inside `dir`.
fn confined(dir: &Path, file: &Path) -> std::io::Result<()> {
    let (d, f) = (dir.canonicalize()?, file.canonicalize()?);
    if f.starts_with(&d) {
        Ok(())
    } else {
        Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            format!(
                "it is outside the scene's folder {}; pass --allow-outside-materials to read it",
                shown_path(&d)
            ),
        ))
    }
}

/// The bytes of `path` if it is a regular file of at most `limit` bytes: a FIFO would block
/// forever and a device (`/dev/zero`) never ends.
fn read_regular(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let meta = std::fs::metadata(path)?;
    if meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "it is a directory",
        ));
    }
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a device, FIFO or socket)",
        ));
    }
    if meta.len() > limit {
        return Err(too_large(limit));
    }
    let mut bytes = Vec::new();
    // The file may grow between the check and the read: read at most one byte past the limit.
    std::fs::File::open(path)?
        .take(limit + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit));
    }
    Ok(bytes)
}

fn too_large(limit: u64) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::InvalidData,
        format!("larger than the limit of {} MiB", limit >> 20),
    )
}

/// `s` with control characters escaped (`\u{1b}`, `\n`), for echoing names read from a file:
/// a raw escape sequence in an object name would drive the user's terminal.
pub fn shown(s: &str) -> String {
    if !s.chars().any(char::is_control) {
        return s.to_string();
    }
    s.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// A path for messages, control characters escaped.
pub fn shown_path(path: &Path) -> String {
    shown(&path.display().to_string())
}

/// The scene in an OBJ text. `path` names it in messages and locates the MTL files it names,
/// which `read` fetches (from disk, or from the copies built into the binary): files and
/// built-in scenes go through the same checks.
pub(super) fn parse_obj(
    path: &Path,
    text: &str,
    read: impl Fn(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<Scene, SceneError> {
    let header = parse_comments(path, text)?;
    check_lines(path, text)?;
    // tobj takes an `mtllib` line's file name from after the line's first space: an indented
    // line names "mtllib x.mtl", a tab after the keyword names nothing. Give it lines that say
    // what they mean (keyword, one space, the name), so that the file it asks for is the one
    // the line names.
    let text = normalise(text);
    let mut warnings = Vec::new();
    // The one path to the materials: tobj asks for each library through `load_mtl`, which reads
    // it, checks it with `parse_mtl` and hands tobj the checked values, re-written, so what is
    // checked is what is used. tobj's loader cannot fail with our error: keep the first.
    let mtl_error: RefCell<Option<SceneError>> = RefCell::new(None);
    let mtl_warnings: RefCell<Vec<String>> = RefCell::new(Vec::new());
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ..Default::default()
    };
    let load_mtl = |name: &Path| {
        let file = match path.parent() {
            Some(dir) => dir.join(name),
            None => name.to_path_buf(),
        };
        let bytes = match read(&file) {
            Ok(bytes) => bytes,
            // A missing MTL is a warning: the geometry still loads (and with no emitter the
            // scene then stops with its own clear error). One refused (outside the folder, not
            // a regular file, too large) is an error that says why.
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                mtl_error.borrow_mut().get_or_insert(SceneError::Material {
                    path: shown_path(path),
                    mtl: shown_path(&file),
                    reason: shown(&e.to_string()),
                });
                return Err(tobj::LoadError::OpenFileFailed);
            }
            Err(e) => {
                mtl_warnings.borrow_mut().push(format!(
                    "cannot read the material library {} ({}); its faces are grey",
                    shown_path(&file),
                    shown(&e.to_string())
                ));
                return Err(tobj::LoadError::OpenFileFailed);
            }
        };
        // A malformed one is an error: a typo in Kd or Ke would otherwise silently change the
        // light. Bytes that are not UTF-8 must not hide a bad line.
        match parse_mtl(&file, &String::from_utf8_lossy(&bytes)) {
            Ok(clean) => tobj::load_mtl_buf(&mut clean.as_bytes()),
            Err(e) => {
                mtl_error.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::MaterialParseError)
            }
        }
    };
    let loaded = tobj::load_obj_buf(&mut text.as_bytes(), &options, load_mtl);
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    warnings.extend(mtl_warnings.into_inner());
    let (models, materials) = loaded.map_err(|e| SceneError::Parse {
        path: shown_path(path),
        line: first_bad_line(&text, &e)
            .map(|n| format!(":{n}"))
            .unwrap_or_default(),
        what: format!("malformed OBJ ({e})"),
    })?;
    let mut materials: Vec<Material> = match materials {
        Ok(m) => m.into_iter().map(to_material).collect(),
        // Already reported (the library could not be read).
        Err(_) if !warnings.is_empty() => Vec::new(),
        Err(e) => {
            warnings.push(format!(
                "materials could not be read ({e}); every face is grey"
            ));
            Vec::new()
        }
    };
    // Faces without a material get a neutral grey that does not emit.
    let default_material = materials.len();
    materials.push(Material {
        name: "(default)".into(),
        kd: Vec3::splat(0.5),
        ke: Vec3::ZERO,
    });

    // Outside this range f32 loses the scene: at 1e-18 areas underflow to zero, at 1e±9 a shot
    // reflected 3e-6 % or 11.8 % of its power instead of 7.1 %. tests/hostile.rs solves the
    // shadow scene scaled to both ends of the range and finds its first shot unchanged.
    let (lo, hi) = models
        .iter()
        .flat_map(|m| m.mesh.positions.chunks_exact(3))
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            let p = Vec3::from_slice(p);
            (lo.min(p), hi.max(p))
        });
    let size = (hi.as_dvec3() - lo.as_dvec3()).length() as f32;
    if lo.x <= hi.x && !(MIN_SCENE_SIZE..=MAX_SCENE_SIZE).contains(&size) {
        return Err(SceneError::Scale {
            path: shown_path(path),
            size,
        });
    }
    let mut polygons = Vec::new();
    let mut skipped = 0;
    let mut split = 0;
    for model in &models {
        let mesh = &model.mesh;
        let position = |i: u32| {
            let i = i as usize * 3;
            Vec3::new(
                mesh.positions[i],
                mesh.positions[i + 1],
                mesh.positions[i + 2],
            )
        };
        if let Some(bad) = mesh.positions.iter().position(|v| !v.is_finite()) {
            let i = bad / 3 * 3;
            return Err(SceneError::NotFinite {
                path: shown_path(path),
                object: shown(&model.name),
                vertex: format!("{:?}", &mesh.positions[i..i + 3]),
            });
        }
        let arities: Vec<u32> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.clone()
        };
        let material = mesh
            .material_id
            .filter(|&m| m < default_material)
            .unwrap_or(default_material);
        let mut start = 0usize;
        for arity in arities {
            let idx = &mesh.indices[start..start + arity as usize];
            start += arity as usize;
            let vertices: Vec<Vec3> = idx.iter().map(|&i| position(i)).collect();
            match Polygon::new(vertices.clone(), material, shown(&model.name)) {
                // A badly non-planar polygon has no one plane for its lightmap: split it into
                // triangles, each planar. Ear clipping on its mean plane, not a fan: a fan of a
                // non-convex outline folds over itself, and triangles that overlap each
                // receive the same light (a 10,000-corner zigzag reflected 12.5x its light).
                Some(p) if vertices.len() > 3 && !p.is_planar(0.01) => {
                    split += 1;
                    for t in super::triangulate(&p.vertices, p.normal) {
                        let tri = t.map(|k| p.vertices[k]).to_vec();
                        match Polygon::new(tri, material, shown(&model.name)) {
                            Some(t) => polygons.push(t),
                            None => skipped += 1,
                        }
                    }
                }
                Some(p) => polygons.push(p),
                None => skipped += 1,
            }
        }
    }
    for w in &warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    if split > 0 {
        eprintln!(
            "warning: {}: split {split} non-planar polygon(s) (off their plane by more than 1 % of their size) into triangles",
            path.display()
        );
    }
    if skipped > 0 {
        eprintln!(
            "warning: {}: skipped {skipped} polygon(s) with zero area",
            path.display()
        );
    }
    let (dropped, names) = super::overlap::drop_duplicates(&mut polygons);
    if dropped > 0 {
        eprintln!(
            "warning: {}: dropped {dropped} face(s) given twice (same corners; each copy would \
             receive the same light and create energy): {}",
            shown_path(path),
            names.join(", ")
        );
    }
    if let Some((lo, hi)) = crate::geometry::bounds(
        &polygons
            .iter()
            .flat_map(|p| p.vertices.iter().copied())
            .collect::<Vec<_>>(),
    ) {
        let slack = 1e-5 * (hi - lo).length();
        // A warning, not an error: the paper's rooms have such faces (a door jamb inside its
        // architrave's side), where the excess is far below the solver's balance check's
        // tolerance. Where it is not, that check stops the solve and names the receivers.
        if let Some(o) = super::overlap::find_overlap(&polygons, slack) {
            eprintln!(
                "warning: {}: faces overlap in one plane, facing the same way: {} and {}. Both \
                 receive the light that falls on their common part, which creates energy; if a \
                 shot reflects more than it received the solve stops",
                shown_path(path),
                super::overlap::describe(&polygons[o.a]),
                super::overlap::describe(&polygons[o.b]),
            );
        }
    }
    if polygons.is_empty() {
        return Err(SceneError::Empty {
            path: shown_path(path),
        });
    }
    let scene = Scene {
        name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        polygons,
        materials,
        vertex_count: header.vertex_count,
        camera: header.camera,
        patch_size: header.patch_size,
        skipped_degenerate: skipped,
    };
    if scene.light_count() == 0 && scene.materials.iter().any(|m| m.is_emitter()) {
        let names: Vec<&str> = scene
            .materials
            .iter()
            .filter(|m| m.is_emitter())
            .map(|m| m.name.as_str())
            .collect();
        return Err(SceneError::EmitterZeroArea {
            path: shown_path(path),
            materials: names.join(", "),
            skipped,
        });
    }
    if scene.light_count() == 0 {
        let names: Vec<&str> = scene.materials[..default_material]
            .iter()
            .map(|m| m.name.as_str())
            .collect();
        return Err(SceneError::NoEmitter {
            path: shown_path(path),
            materials: if names.is_empty() {
                "none".into()
            } else {
                names.join(", ")
            },
        });
    }
    Ok(scene)
}

fn to_material(m: tobj::Material) -> Material {
    let v = |c: Option<[f32; 3]>| c.map(Vec3::from).unwrap_or(Vec3::ZERO);
    Material {
        kd: v(m.diffuse).clamp(Vec3::ZERO, Vec3::ONE),
        ke: v(m.emissive).max(Vec3::ZERO),
        // Escaped once here: every message that names a material or object echoes it.
        name: shown(&m.name),
    }
}

struct Header {
    vertex_count: usize,
    camera: Option<Camera>,
    patch_size: Option<f32>,
}

fn parse_comments(path: &Path, text: &str) -> Result<Header, SceneError> {
    let mut header = Header {
        vertex_count: 0,
        camera: None,
        patch_size: None,
    };
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        let bad = |what: &str| SceneError::Parse {
            path: shown_path(path),
            line: format!(":{}", n + 1),
            what: what.to_string(),
        };
        if line.starts_with("v ") || line.starts_with("v\t") {
            header.vertex_count += 1;
        } else if let Some(rest) = line.strip_prefix("# camera") {
            let camera = parse_camera(rest).ok_or_else(|| {
                bad("expected `# camera eye X Y Z target X Y Z up X Y Z fov DEG`")
            })?;
            camera
                .validate()
                .map_err(|e| bad(&format!("bad `# camera` line: {e}")))?;
            header.camera = Some(camera);
        } else if let Some(rest) = line.strip_prefix("# patch-size") {
            let s: f32 = rest
                .trim()
                .parse()
                .map_err(|_| bad("expected `# patch-size S`"))?;
            if !(s > 0.0 && s.is_finite()) {
                return Err(bad("the patch size must be a positive number"));
            }
            header.patch_size = Some(s);
        }
    }
    Ok(header)
}

fn parse_camera(rest: &str) -> Option<Camera> {
    let tokens: Vec<&str> = rest.split_whitespace().collect();
    let mut camera = Camera {
        eye: Vec3::ZERO,
        target: Vec3::Z,
        up: Vec3::Y,
        fov_y: 40.0,
    };
    let mut seen = 0;
    let mut i = 0;
    let num = |s: &str| s.parse::<f32>().ok().filter(|v| v.is_finite());
    while i < tokens.len() {
        let vec = |i: usize| -> Option<Vec3> {
            Some(Vec3::new(
                num(tokens.get(i + 1)?)?,
                num(tokens.get(i + 2)?)?,
                num(tokens.get(i + 3)?)?,
            ))
        };
        match tokens[i] {
            "eye" => camera.eye = vec(i)?,
            "target" => camera.target = vec(i)?,
            "up" => camera.up = vec(i)?,
            "fov" => {
                camera.fov_y = num(tokens.get(i + 1)?)?;
                seen |= 8;
                i += 2;
                continue;
            }
            _ => return None,
        }
        seen |= match tokens[i] {
            "eye" => 1,
            "target" => 2,
            _ => 4,
        };
        i += 4;
    }
    (seen & 3 == 3).then_some(camera)
}

/// Check every `v` and `f` line before tobj sees the file, so an error names its line: vertices
/// need three finite numbers, faces at least three vertices whose indices exist.
fn check_lines(path: &Path, text: &str) -> Result<(), SceneError> {
    let (mut vertices, mut texcoords, mut normals): (i64, i64, i64) = (0, 0, 0);
    for (n, line) in text.lines().enumerate() {
        let bad = |what: String| SceneError::Parse {
            path: shown_path(path),
            line: format!(":{}", n + 1),
            what,
        };
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let values: Vec<&str> = tokens.collect();
                let numbers: Vec<f32> = values.iter().filter_map(|t| t.parse().ok()).collect();
                if values.len() < 3 || numbers.len() != values.len() {
                    return Err(bad(format!(
                        "a vertex needs three numbers, got `{}`",
                        line.trim()
                    )));
                }
                if numbers.iter().take(3).any(|v| !v.is_finite()) {
                    return Err(bad(format!(
                        "vertex coordinates must be finite, got `{}`",
                        line.trim()
                    )));
                }
                vertices += 1;
            }
            Some("vt") => texcoords += 1,
            Some("vn") => normals += 1,
            Some("f") => {
                let corners: Vec<&str> = tokens.collect();
                if corners.len() < 3 {
                    return Err(bad(format!(
                        "a face needs at least three vertices, got {} (`{}`)",
                        corners.len(),
                        line.trim()
                    )));
                }
                // v/vt/vn: each index must name an element defined before the face (relative
                // ones too: tobj overflows on those that reach before the first).
                let valid = |part: Option<&str>, count: i64, required: bool| match part {
                    None | Some("") => !required,
                    Some(t) => match t.parse::<i64>() {
                        Ok(i) if i > 0 => i <= count,
                        Ok(i) if i < 0 => i.unsigned_abs() <= count as u64,
                        _ => false,
                    },
                };
                for c in corners {
                    let mut parts = c.split('/');
                    if !valid(parts.next(), vertices, true) {
                        return Err(bad(format!(
                            "face vertex `{c}` does not name one of the {vertices} vertices defined before it"
                        )));
                    }
                    if !valid(parts.next(), texcoords, false)
                        || !valid(parts.next(), normals, false)
                    {
                        return Err(bad(format!(
                            "face vertex `{c}` names a texture coordinate or normal that is not defined before it ({texcoords} vt, {normals} vn)"
                        )));
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Smallest and largest scene (bounding-box diagonal, scene units) solved accurately.
pub const MIN_SCENE_SIZE: f32 = 1e-5;
pub const MAX_SCENE_SIZE: f32 = 1e6;

/// Largest emitted radiance accepted: beyond it power sums (radiance × area × π, summed over
/// a scene) approach the f32 range and the picture turns to NaN.
pub const MAX_KE: f32 = 1e15;

/// Check an MTL text and write it out again with only what the solver uses (`newmtl`, `Kd`,
/// `Ke`), one canonical line each, for tobj to read. Colour lines (Ka, Kd, Ks, Ke) need three
/// numbers in range; other lines are ignored, as tobj's values for them are unused.
fn parse_mtl(path: &Path, text: &str) -> Result<String, SceneError> {
    let mut clean = String::new();
    for (n, line) in text.lines().enumerate() {
        let bad = |what: String| SceneError::Parse {
            path: shown_path(path),
            line: format!(":{}", n + 1),
            what,
        };
        let mut tokens = line.split_whitespace();
        let key = tokens.next().unwrap_or("");
        if key == "newmtl" {
            let name = line.trim_start()["newmtl".len()..].trim();
            if name.is_empty() {
                return Err(bad("`newmtl` needs a material name".into()));
            }
            clean.push_str(&format!("newmtl {name}\n"));
            continue;
        }
        if !matches!(key, "Ka" | "Kd" | "Ks" | "Ke") {
            continue;
        }
        let values: Vec<&str> = tokens.collect();
        let numbers: Vec<f32> = values.iter().filter_map(|t| t.parse().ok()).collect();
        let fine = values.len() == 3
            && numbers.len() == 3
            && numbers.iter().all(|v| v.is_finite() && *v >= 0.0)
            && if key == "Ke" {
                numbers.iter().all(|v| *v <= MAX_KE)
            } else {
                numbers.iter().all(|v| *v <= 1.0)
            };
        if !fine {
            let range = if key == "Ke" {
                format!("in [0, {MAX_KE:e}]")
            } else {
                "in [0, 1]".to_string()
            };
            return Err(bad(format!(
                "`{key}` needs three numbers {range}, got `{}`",
                shown(line.trim())
            )));
        }
        if key == "Kd" || key == "Ke" {
            // Debug formatting keeps every digit of the f32 parsed here.
            let [r, g, b] = [numbers[0], numbers[1], numbers[2]];
            clean.push_str(&format!("{key} {r:?} {g:?} {b:?}\n"));
        }
    }
    Ok(clean)
}

/// Every line with its leading blanks removed; `mtllib` lines as `mtllib NAME`.
fn normalise(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let line = line.trim_start();
        let mut tokens = line.split_whitespace();
        if tokens.next() == Some("mtllib") {
            out.push_str("mtllib ");
            out.push_str(line["mtllib".len()..].trim());
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// tobj reports what went wrong but not where: find the first line of that kind that does not
/// parse, so the message can name it.
fn first_bad_line(text: &str, error: &tobj::LoadError) -> Option<usize> {
    let positions = text
        .lines()
        .filter(|l| l.trim_start().starts_with("v "))
        .count() as i64;
    for (n, line) in text.lines().enumerate() {
        let mut tokens = line.split_whitespace();
        let keyword = tokens.next().unwrap_or("");
        let bad = match (keyword, error) {
            ("v", tobj::LoadError::PositionParseError) => {
                let values: Vec<_> = tokens.collect();
                values.len() < 3 || values.iter().any(|t| t.parse::<f32>().is_err())
            }
            ("f", tobj::LoadError::FaceParseError | tobj::LoadError::InvalidPolygon)
            | ("f", tobj::LoadError::FaceVertexOutOfBounds) => {
                let values: Vec<_> = tokens.collect();
                values.len() < 3
                    || values.iter().any(|t| {
                        match t.split('/').next().and_then(|i| i.parse::<i64>().ok()) {
                            Some(i) => {
                                i == 0
                                    || i > positions
                                    || i.unsigned_abs() > positions.unsigned_abs()
                            }
                            None => true,
                        }
                    })
            }
            _ => false,
        };
        if bad {
            return Some(n + 1);
        }
    }
    None
}
