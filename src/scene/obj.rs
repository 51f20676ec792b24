//! Wavefront OBJ + MTL loading through `tobj`, keeping polygons as polygons (no triangulation:
//! a quad is one face with one lightmap, as in the paper). Two comment lines are understood:
//! `# camera eye X Y Z target X Y Z up X Y Z fov DEG` and `# patch-size S`.

use super::{Camera, Material, Polygon, Scene};
use glam::Vec3;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("cannot read scene file {path}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}{line}: {what}")]
    Parse {
        path: PathBuf,
        line: String,
        what: String,
    },
    #[error("{path}: object '{object}' has a vertex that is not a finite number ({vertex})")]
    NotFinite {
        path: PathBuf,
        object: String,
        vertex: String,
    },
    #[error(
        "{path}: the scene has no emitter: no material has a positive Ke (materials: {materials}). \
         Give the lights a material with `Ke r g b` (emitted radiance)"
    )]
    NoEmitter { path: PathBuf, materials: String },
    #[error("{path}: the scene has no polygons with a non-zero area")]
    Empty { path: PathBuf },
}

pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse_obj(path, &text, |file| std::fs::read(file))
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
    let mut warnings = Vec::new();
    for lib in text
        .lines()
        .filter_map(|l| l.trim().strip_prefix("mtllib "))
    {
        let mtl = path.parent().unwrap_or(Path::new(".")).join(lib.trim());
        match read(&mtl) {
            // A missing MTL is a warning: the geometry still loads (and with no emitter the
            // scene then stops with its own clear error). A malformed one is an error: a typo in
            // Kd or Ke would otherwise silently change the light. Bytes that are not UTF-8 must
            // not hide a bad line from the check (tobj would still reach it).
            Err(e) => warnings.push(format!(
                "cannot read the material library {} ({e}); its faces are grey",
                mtl.display()
            )),
            Ok(bytes) => check_mtl(&mtl, &String::from_utf8_lossy(&bytes))?,
        }
    }

    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ..Default::default()
    };
    // What tobj::load_obj does with a file, on the text already read: MTL files next to the OBJ.
    let load_mtl = |name: &Path| {
        let file = match path.parent() {
            Some(dir) => dir.join(name),
            None => name.to_path_buf(),
        };
        match read(&file) {
            Ok(bytes) => tobj::load_mtl_buf(&mut bytes.as_slice()),
            Err(_) => Err(tobj::LoadError::OpenFileFailed),
        }
    };
    let loaded = tobj::load_obj_buf(&mut text.as_bytes(), &options, load_mtl);
    let (models, materials) = loaded.map_err(|e| SceneError::Parse {
        path: path.to_path_buf(),
        line: first_bad_line(text, &e)
            .map(|n| format!(":{n}"))
            .unwrap_or_default(),
        what: format!("malformed OBJ ({e})"),
    })?;
    let mut materials: Vec<Material> = match materials {
        Ok(m) => m.into_iter().map(to_material).collect(),
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
                path: path.to_path_buf(),
                object: model.name.clone(),
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
            match Polygon::new(vertices.clone(), material, model.name.clone()) {
                // A badly non-planar polygon has no one plane for its lightmap: split it into
                // the triangles of a fan, each planar.
                Some(p) if vertices.len() > 3 && !p.is_planar(0.01) => {
                    split += 1;
                    for k in 1..vertices.len() - 1 {
                        let tri = vec![vertices[0], vertices[k], vertices[k + 1]];
                        match Polygon::new(tri, material, model.name.clone()) {
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
    if polygons.is_empty() {
        return Err(SceneError::Empty {
            path: path.to_path_buf(),
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
    if scene.light_count() == 0 {
        let names: Vec<&str> = scene.materials[..default_material]
            .iter()
            .map(|m| m.name.as_str())
            .collect();
        return Err(SceneError::NoEmitter {
            path: path.to_path_buf(),
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
        name: m.name,
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
            path: path.to_path_buf(),
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
            path: path.to_path_buf(),
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

/// Check the colour lines of an MTL file (Ka, Kd, Ks, Ke: three numbers in range).
fn check_mtl(path: &Path, text: &str) -> Result<(), SceneError> {
    for (n, line) in text.lines().enumerate() {
        let mut tokens = line.split_whitespace();
        let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = tokens.next() else {
            continue;
        };
        let values: Vec<&str> = tokens.collect();
        let numbers: Vec<f32> = values.iter().filter_map(|t| t.parse().ok()).collect();
        let fine = values.len() == 3
            && numbers.len() == 3
            && numbers.iter().all(|v| v.is_finite() && *v >= 0.0)
            && (key == "Ke" || numbers.iter().all(|v| *v <= 1.0));
        if !fine {
            let range = if key == "Ke" {
                "finite, ≥ 0"
            } else {
                "in [0, 1]"
            };
            return Err(SceneError::Parse {
                path: path.to_path_buf(),
                line: format!(":{}", n + 1),
                what: format!("`{key}` needs three numbers {range}, got `{}`", line.trim()),
            });
        }
    }
    Ok(())
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
