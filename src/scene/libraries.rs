//! The material libraries an OBJ names (`mtllib`), read under the path rules of
//! [`MaterialFiles`], and the materials its `usemtl` lines resolve to. A missing library is a
//! warning, not an error (the geometry still loads, grey): it says which `.mtl` files in the
//! scene's folder define the materials the scene uses, since exporters and archives often
//! rename one file and not the other.

use super::error::SceneError;
use super::files::{decode, file_name, shown, shown_path, MaterialFiles};
use super::mtl::{parse_mtl, Library};
use super::obj::ObjFile;
use super::{Material, DEFAULT_GREY, DEFAULT_MATERIAL};
use glam::Vec3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The scene's materials (the default grey last) and, for each `usemtl` name of the OBJ, the
/// index of its material.
pub(super) struct Materials {
    pub list: Vec<Material>,
    pub of_name: Vec<usize>,
}

/// Read every library `obj` names and resolve its `usemtl` names; warnings and notes go to
/// `messages`. A library that exists but is refused (outside the folder, not a regular file,
/// too large) or malformed is an error.
pub(super) fn load_libraries(
    path: &Path,
    obj: &ObjFile,
    files: &dyn MaterialFiles,
    messages: &mut Vec<String>,
) -> Result<Materials, SceneError> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut list = Vec::new();
    let mut by_name: HashMap<String, usize> = HashMap::new();
    let mut read: Vec<PathBuf> = Vec::new();
    let mut missing = Vec::new();
    for library in &obj.libraries {
        let file = dir.join(&library.name);
        if read.contains(&file) {
            continue;
        }
        let bytes = match files.read(&file) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                missing.push((library.line, file, e));
                continue;
            }
            Err(e) => {
                return Err(SceneError::Material {
                    path: shown_path(path),
                    mtl: shown_path(&file),
                    reason: shown(&e.to_string()),
                })
            }
        };
        let lib = parse_mtl(&file, &decode(&bytes))?;
        report(&file, &lib, messages);
        for (name, material) in lib.materials {
            // A name defined twice: the later definition is the one used (as tobj did).
            by_name.insert(name, list.len());
            list.push(material);
        }
        read.push(file);
    }
    let default = list.len();
    list.push(Material {
        name: DEFAULT_MATERIAL.into(),
        kd: Vec3::splat(DEFAULT_GREY),
        ke: Vec3::ZERO,
    });
    let undefined: Vec<&str> = obj
        .material_names
        .iter()
        .filter(|n| !by_name.contains_key(*n))
        .map(String::as_str)
        .collect();
    for (line, file, e) in &missing {
        let (lib, err) = (file_name(file), shown(&e.to_string()));
        let hint = where_defined(&undefined, files, &read);
        messages.push(format!(
            "warning: {}:{line}: cannot read the material library {lib} ({err}); {hint}",
            shown_path(path)
        ));
    }
    if missing.is_empty() && !undefined.is_empty() {
        messages.push(format!(
            "warning: {}: no material library defines {}, used by `usemtl`; faces with {} are grey",
            shown_path(path),
            quoted(&undefined),
            if undefined.len() == 1 { "it" } else { "them" }
        ));
    }
    let of_name = obj
        .material_names
        .iter()
        .map(|n| by_name.get(n).copied().unwrap_or(default))
        .collect();
    Ok(Materials { list, of_name })
}

/// The summary of what a library skipped, and its clamped reflectances.
fn report(file: &Path, lib: &Library, messages: &mut Vec<String>) {
    if let Some(s) = lib.skipped.summary() {
        messages.push(format!("note: {}: {s}", shown_path(file)));
    }
    for c in &lib.clamped {
        messages.push(format!("warning: {c}"));
    }
    if let Some(n) = textured_only_note(&lib.textured_only) {
        messages.push(format!("note: {}: {n}", shown_path(file)));
    }
    let more = lib.clamped_lines - lib.clamped.len();
    if more > 0 {
        messages.push(format!(
            "warning: {}: {more} more `Kd` line(s) above 1 clamped to 1",
            shown_path(file)
        ));
    }
}

/// What happened to the materials that give their colour only as a texture (`mtl.rs`).
fn textured_only_note(names: &[String]) -> Option<String> {
    let first = names.first()?;
    let which = match names.len() {
        1 => format!("material '{first}' gives"),
        2 => format!("materials '{first}' and '{}' give", names[1]),
        n => format!("{n} materials ('{first}', '{}', …) give", names[1]),
    };
    Some(format!(
        "{which} a colour only as a texture (`map_Kd`, no `Kd`): textures are not read (one \
         mean over a texture that many faces share is no face's colour), so they reflect the \
         default grey {DEFAULT_GREY}; add `Kd` lines to choose"
    ))
}

/// Which of the `.mtl` files beside the scene (those not already `read`) define the `used`
/// materials that no library read defines, and what to do about it.
fn where_defined(used: &[&str], files: &dyn MaterialFiles, read: &[PathBuf]) -> String {
    let grey = "until then faces with those materials are grey";
    if used.is_empty() {
        return "the materials the scene uses are defined in its other libraries".into();
    }
    let all = if used.len() == 1 {
        format!("the material {} used", quoted(used))
    } else {
        format!("all {} materials used", used.len())
    };
    // Each candidate that parses, with how many of the used materials it defines.
    let mut found: Vec<(String, Vec<&str>)> = files
        .beside()
        .iter()
        .filter(|f| !read.contains(f))
        .filter_map(|f| {
            // One file in memory at a time; what does not read or parse is not suggested.
            let lib = parse_mtl(f, &decode(&files.read(f).ok()?)).ok()?;
            let defines: Vec<&str> = used
                .iter()
                .copied()
                .filter(|u| lib.materials.iter().any(|(n, _)| n == u))
                .collect();
            (!defines.is_empty()).then(|| (file_name(f), defines))
        })
        .collect();
    found.sort_by(|a, b| b.1.len().cmp(&a.1.len()).then(a.0.cmp(&b.0)));
    let complete: Vec<&str> = found
        .iter()
        .filter(|(_, d)| d.len() == used.len())
        .map(|(f, _)| f.as_str())
        .collect();
    match (complete.as_slice(), found.first()) {
        ([one], _) => format!(
            "{one} in the same folder defines {all}: change the `mtllib` line to name it; {grey}"
        ),
        ([_, _, ..], _) => format!(
            "{} in the same folder each define {all}: change the `mtllib` line to name one; {grey}",
            complete.join(", ")
        ),
        ([], Some((f, d))) => format!(
            "{f} in the same folder defines {} of the {} materials used ({}); {grey}",
            d.len(),
            used.len(),
            quoted(d)
        ),
        ([], None) => format!(
            "no .mtl file in the same folder defines the materials used ({}); {grey}",
            quoted(used)
        ),
    }
}

/// `'a', 'b', 'c'` (at most ten, then a count), names escaped.
fn quoted(names: &[&str]) -> String {
    let mut parts: Vec<String> = names
        .iter()
        .take(10)
        .map(|n| format!("'{}'", shown(n)))
        .collect();
    if names.len() > 10 {
        parts.push(format!("{} more", names.len() - 10));
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Files in memory.
    struct Files(Vec<(&'static str, &'static str)>);

    impl MaterialFiles for Files {
        fn read(&self, file: &Path) -> std::io::Result<Vec<u8>> {
            let (_, text) = self.0.iter().find(|(n, _)| Path::new(n) == file).unwrap();
            Ok(text.as_bytes().to_vec())
        }

        fn beside(&self) -> Vec<PathBuf> {
            self.0.iter().map(|(n, _)| PathBuf::from(n)).collect()
        }
    }

    #[test]
    fn the_hint_names_the_file_that_defines_the_materials() {
        let files = Files(vec![
            ("other.mtl", "newmtl floor\nKd 1 1 1\n"),
            (
                "CornellBox-Original.mtl",
                "newmtl floor\nnewmtl light\nKe 1 1 1\n",
            ),
            ("broken.mtl", "newmtl floor\nnewmtl light\nKd x\n"),
        ]);
        let hint = where_defined(&["floor", "light"], &files, &[]);
        assert!(
            hint.starts_with(
                "CornellBox-Original.mtl in the same folder defines all 2 materials used: change \
                 the `mtllib` line to name it"
            ),
            "{hint}"
        );
        let hint = where_defined(&["floor", "light"], &Files(files.0[..1].to_vec()), &[]);
        assert!(
            hint.starts_with(
                "other.mtl in the same folder defines 1 of the 2 materials used ('floor')"
            ),
            "{hint}"
        );
        let hint = where_defined(&["floor"], &Files(vec![]), &[]);
        assert!(
            hint.starts_with(
                "no .mtl file in the same folder defines the materials used ('floor')"
            ),
            "{hint}"
        );
        assert!(hint.ends_with("grey"), "{hint}");
    }
}
