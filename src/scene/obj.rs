//! Wavefront OBJ: the statements the solver uses, read by the program itself so that every
//! error names its line. Used: `v` (position), `f` (face; `v`, `v/vt`, `v//vn`, `v/vt/vn`,
//! negative indices counting back), `usemtl`, `mtllib`, and `o`/`g` for the object names in
//! messages; `vt` and `vn` are counted so that a face's indices can be checked. Everything else
//! (`s`, `l`, `p`, `vp`, `usemap`, `mg`, `cstype`, ...) is skipped and counted.

use super::error::SceneError;
use super::files::{excerpt, shown_path};
use super::statements::{statements, Skipped, Statement};
use glam::Vec3;
use std::collections::HashMap;
use std::path::Path;

/// The object name of faces before any `o` or `g` line (and of an `o` without a name).
pub(super) const UNNAMED: &str = "unnamed_object";

/// One `f` line.
#[derive(Clone, Copy, Debug)]
pub(super) struct Face {
    /// Its corners are `ObjFile::corners[start..start + len]`.
    pub start: u32,
    pub len: u32,
    /// Index into `ObjFile::material_names` of the `usemtl` in effect, if any.
    pub material: Option<u32>,
    /// Index into `ObjFile::object_names`.
    pub object: u32,
}

/// An `mtllib` line: the file it names and where.
#[derive(Clone, Debug)]
pub(super) struct LibraryLine {
    pub line: usize,
    pub name: String,
}

/// What an OBJ file says, faces in file order.
#[derive(Debug, Default)]
pub(super) struct ObjFile {
    pub positions: Vec<Vec3>,
    /// Position indices (0-based) of every face's corners, face after face.
    pub corners: Vec<u32>,
    pub faces: Vec<Face>,
    pub libraries: Vec<LibraryLine>,
    /// The names `usemtl` lines give, as written, each once in order of first use.
    pub material_names: Vec<String>,
    /// The names of `o` and `g` lines, as written.
    pub object_names: Vec<String>,
    pub skipped: Skipped,
}

impl ObjFile {
    pub fn corners_of(&self, face: &Face) -> &[u32] {
        &self.corners[face.start as usize..(face.start + face.len) as usize]
    }
}

/// Read an OBJ text; `path` names it in messages.
pub(super) fn parse_obj(path: &Path, text: &str) -> Result<ObjFile, SceneError> {
    let mut obj = ObjFile {
        object_names: vec![UNNAMED.to_string()],
        ..Default::default()
    };
    let mut materials: HashMap<String, u32> = HashMap::new();
    let (mut texcoords, mut normals) = (0usize, 0usize);
    let mut material = None;
    let mut object = 0u32;
    for s in statements(text) {
        let bad = |what: String| SceneError::Parse {
            path: shown_path(path),
            line: format!(":{}", s.line),
            what,
        };
        match s.keyword {
            "v" => obj.positions.push(position(&s).map_err(bad)?),
            "vt" => texcoords += 1,
            "vn" => normals += 1,
            "f" => {
                let start = obj.corners.len() as u32;
                for corner in s.tokens() {
                    let v = corner_index(corner, obj.positions.len(), texcoords, normals)
                        .map_err(bad)?;
                    obj.corners.push(v);
                }
                let len = obj.corners.len() as u32 - start;
                if len < 3 {
                    return Err(bad(format!(
                        "a face needs at least three vertices, got {len} (`f {}`)",
                        excerpt(s.rest)
                    )));
                }
                obj.faces.push(Face {
                    start,
                    len,
                    material,
                    object,
                });
            }
            // An empty `usemtl` (some exporters write one for "no material") means grey.
            "usemtl" if s.rest.is_empty() => material = None,
            "usemtl" => {
                let next = materials.len() as u32;
                let id = *materials.entry(s.rest.to_string()).or_insert(next);
                if id == next {
                    obj.material_names.push(s.rest.to_string());
                }
                material = Some(id);
            }
            // The name is the rest of the line: file names may hold spaces.
            "mtllib" if s.rest.is_empty() => {
                return Err(bad("`mtllib` needs a file name".into()));
            }
            "mtllib" => obj.libraries.push(LibraryLine {
                line: s.line,
                name: s.rest.to_string(),
            }),
            "o" | "g" => {
                let name = if s.rest.is_empty() { UNNAMED } else { s.rest };
                obj.object_names.push(name.to_string());
                object = obj.object_names.len() as u32 - 1;
            }
            other => obj.skipped.add(other),
        }
    }
    Ok(obj)
}

/// `v x y z [w | r g b]`: three finite coordinates; the weight or colour that may follow is
/// checked to be numbers and otherwise unused.
fn position(s: &Statement) -> Result<Vec3, String> {
    let mut count = 0;
    let mut xyz = [0.0f32; 3];
    for t in s.tokens() {
        let Ok(v) = t.parse::<f32>() else {
            count = 0;
            break;
        };
        if count < 3 {
            xyz[count] = v;
        }
        count += 1;
    }
    let line = || format!("v {}", excerpt(s.rest));
    if count < 3 {
        return Err(format!("a vertex needs three numbers, got `{}`", line()));
    }
    if xyz.iter().any(|v| !v.is_finite()) {
        return Err(format!(
            "vertex coordinates must be finite, got `{}`",
            line()
        ));
    }
    Ok(Vec3::from(xyz))
}

/// The 0-based position index of a face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`. Each index
/// must name an element defined before the face; a negative one counts back from the last.
fn corner_index(
    corner: &str,
    positions: usize,
    texcoords: usize,
    normals: usize,
) -> Result<u32, String> {
    let mut parts = corner.split('/');
    let v = parts
        .next()
        .and_then(|t| resolve(t, positions))
        .ok_or_else(|| {
            format!(
                "face vertex `{}` does not name one of the {positions} vertices defined before it",
                excerpt(corner)
            )
        })?;
    let optional = |part: Option<&str>, count| match part {
        None | Some("") => true,
        Some(t) => resolve(t, count).is_some(),
    };
    if !optional(parts.next(), texcoords) || !optional(parts.next(), normals) {
        return Err(format!(
            "face vertex `{}` names a texture coordinate or normal that is not defined before \
             it ({texcoords} vt, {normals} vn)",
            excerpt(corner)
        ));
    }
    Ok(v)
}

/// An OBJ index among `count` elements: 1..=count, or -count..=-1 counting back.
fn resolve(token: &str, count: usize) -> Option<u32> {
    let i: i64 = token.parse().ok()?;
    let count = count as i64;
    let zero_based = match i {
        1.. if i <= count => i - 1,
        ..=-1 if i >= -count => count + i,
        _ => return None,
    };
    u32::try_from(zero_based).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ObjFile, SceneError> {
        parse_obj(Path::new("s.obj"), text)
    }

    #[test]
    fn faces_with_texture_and_normal_indices_and_relative_ones() {
        let obj = parse(
            "v 0 0 0\r\nv 1 0 0\r\n\tv 1 1 0 # corner\r\nv\t0 1 0 1\r\nvt 0 0\r\nvn 0 0 1\r\n\
             f 1/1/1 2/1/1 3/1/1\r\nf 1//1 3//1 4//1\r\nf -4 -2 -1\r\nf 1/1 2/1 3/1 4/1\r\n",
        )
        .unwrap();
        let corners: Vec<&[u32]> = obj.faces.iter().map(|f| obj.corners_of(f)).collect();
        assert_eq!(
            corners,
            [&[0, 1, 2][..], &[0, 2, 3], &[0, 2, 3], &[0, 1, 2, 3]]
        );
        assert_eq!(obj.positions[2], Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(obj.positions.len(), 4);
    }

    #[test]
    fn objects_materials_and_skipped_statements() {
        let obj = parse(
            "mtllib my scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no box # the box\n\
             s off\ns 1\nusemtl red\nf 1 2 3\ng\nl 1 2\np 1\nvp 0.5\nusemap tex\nmg 1\n\
             usemtl blue\nf 1 2 3\nusemtl red\nf 1 2 3\nusemtl\nf 1 2 3\ncstype bspline\n",
        )
        .unwrap();
        assert_eq!(obj.libraries[0].name, "my scene.mtl");
        assert_eq!(obj.libraries[0].line, 1);
        assert_eq!(obj.material_names, ["red", "blue"]);
        let of = |f: &Face| (obj.object_names[f.object as usize].as_str(), f.material);
        let faces: Vec<_> = obj.faces.iter().map(of).collect();
        assert_eq!(
            faces,
            [
                (UNNAMED, None),
                ("box", Some(0)),
                (UNNAMED, Some(1)),
                (UNNAMED, Some(0)),
                (UNNAMED, None)
            ]
        );
        assert_eq!(
            obj.skipped.summary().unwrap(),
            "skipped 8 statements the solver does not use (s ×2, cstype ×1, l ×1, mg ×1, p ×1, \
             usemap ×1, vp ×1)"
        );
    }

    #[test]
    fn bad_lines_are_named() {
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        for (text, line, needle) in [
            ("v 0 0 0\nv 1 oops 0\n".to_string(), 2, "three numbers"),
            ("v 0 0\n".into(), 1, "three numbers"),
            ("v 0 0 1e39\n".into(), 1, "finite"),
            ("v 0 0 nan\n".into(), 1, "finite"),
            (format!("{tri}f 1 2 4\n"), 4, "`4`"),
            (format!("{tri}f 0 1 2\n"), 4, "`0`"),
            (format!("{tri}f -4 1 2\n"), 4, "`-4`"),
            (format!("{tri}f -9223372036854775808 1 2\n"), 4, "vertices"),
            (format!("{tri}f 1 2\n"), 4, "at least three"),
            (
                format!("{tri}vt 0 0\nf 1/2 2/1 3/1\n"),
                5,
                "texture coordinate",
            ),
            (format!("{tri}vn 0 0 1\nf 1//-5 2//1 3//1\n"), 5, "normal"),
            (format!("{tri}mtllib\n"), 4, "file name"),
        ] {
            let e = parse(&text).unwrap_err().to_string();
            assert!(e.starts_with(&format!("s.obj:{line}: ")), "{text:?}: {e}");
            assert!(e.contains(needle), "{text:?}: {e}");
        }
        // A long line is quoted in part.
        let e = parse(&format!("v 0 0 {}x\n", "1".repeat(100_000)))
            .unwrap_err()
            .to_string();
        assert!(e.len() < 200 && e.contains("11…`"), "{e}");
    }
}
