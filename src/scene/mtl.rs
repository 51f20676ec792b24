//! Material libraries (MTL). The solver uses three statements: `newmtl`, `Kd` (diffuse
//! reflectance) and `Ke` (emitted radiance). Those are checked, since a typo in them would
//! silently change the light; every other statement (`Ka`, `Ks`, `Ns`, `illum`, `map_Kd`, ...)
//! is skipped whatever its values and counted for one summary line. A material without `Kd`
//! reflects nothing, unless it has a texture (`map_Kd`): then the file does give it a colour,
//! only not one the solver reads, and it reflects the default grey (a game level whose
//! materials are all textures would otherwise be black under any light).

use super::error::{SceneError, MAX_KE};
use super::files::{excerpt, shown};
use super::statements::{statements, three_numbers, Skipped, Statement};
use super::{Material, DEFAULT_GREY};
use glam::Vec3;
use std::path::Path;

/// `Kd` lines above 1 reported one by one; beyond, only counted.
const CLAMPS_SHOWN: usize = 5;

/// What an MTL file defines.
#[derive(Debug, Default)]
pub(super) struct Library {
    /// In file order: the name as written (what `usemtl` names) and the material, whose own
    /// name is escaped for messages.
    pub materials: Vec<(String, Material)>,
    pub skipped: Skipped,
    /// `Kd` lines clamped to 1, as messages (at most [`CLAMPS_SHOWN`]), and how many there were.
    pub clamped: Vec<String>,
    pub clamped_lines: usize,
    /// The materials (escaped names) with `map_Kd` and no `Kd`, given [`DEFAULT_GREY`].
    pub textured_only: Vec<String>,
}

/// Read an MTL text; `path` names it in messages.
pub(super) fn parse_mtl(path: &Path, text: &str) -> Result<Library, SceneError> {
    let mut library = Library::default();
    // Per material: whether it has a `Kd` line and whether it has a `map_Kd` one.
    let mut colour: Vec<(bool, bool)> = Vec::new();
    for s in statements(text) {
        let bad = |what: String| SceneError::Parse {
            path: super::shown_path(path),
            line: format!(":{}", s.line),
            what,
        };
        match s.keyword {
            "newmtl" => {
                if s.rest.is_empty() {
                    return Err(bad("`newmtl` needs a material name".into()));
                }
                // A material without `Kd` reflects nothing (but see `map_Kd`), one without
                // `Ke` emits nothing.
                colour.push((false, false));
                library.materials.push((
                    s.rest.to_string(),
                    Material {
                        name: shown(s.rest),
                        kd: Vec3::ZERO,
                        ke: Vec3::ZERO,
                    },
                ));
            }
            "Kd" | "Ke" => {
                let Some((_, material)) = library.materials.last_mut() else {
                    return Err(bad(format!(
                        "`{}` comes before any `newmtl`, so it belongs to no material",
                        s.keyword
                    )));
                };
                if s.keyword == "Ke" {
                    material.ke = emission(&s).map_err(bad)?;
                } else {
                    let kd = reflectance(&s).map_err(bad)?;
                    if let Some(c) = colour.last_mut() {
                        c.0 = true;
                    }
                    if kd.max_element() > 1.0 {
                        library.clamped_lines += 1;
                        if library.clamped.len() < CLAMPS_SHOWN {
                            library
                                .clamped
                                .push(clamp_message(path, &s, &material.name, kd));
                        }
                    }
                    material.kd = kd.min(Vec3::ONE);
                }
            }
            other => {
                if other == "map_Kd" {
                    if let Some(c) = colour.last_mut() {
                        c.1 = true;
                    }
                }
                library.skipped.add(other)
            }
        }
    }
    for ((_, material), _) in library
        .materials
        .iter_mut()
        .zip(&colour)
        .filter(|(_, &(kd, map))| map && !kd)
    {
        material.kd = Vec3::splat(DEFAULT_GREY);
        library.textured_only.push(material.name.clone());
    }
    Ok(library)
}

/// `Kd`: three finite numbers from 0 up. Above 1 is accepted here and clamped by the caller: a
/// reflectance above 1 creates energy, but exporters write it (a colour scaled by a factor).
fn reflectance(s: &Statement) -> Result<Vec3, String> {
    match three_numbers(s) {
        Some(v) if v.iter().all(|x| x.is_finite() && *x >= 0.0) => Ok(Vec3::from(v)),
        _ => Err(format!(
            "`Kd` needs three numbers, each 0 or more (above 1 is clamped to 1), got `Kd {}`",
            excerpt(s.rest)
        )),
    }
}

/// `Ke`: three numbers in [0, MAX_KE].
fn emission(s: &Statement) -> Result<Vec3, String> {
    match three_numbers(s) {
        Some(v) if v.iter().all(|x| (0.0..=MAX_KE).contains(x)) => Ok(Vec3::from(v)),
        _ => Err(format!(
            "`Ke` needs three numbers in [0, {MAX_KE:e}], got `Ke {}`",
            excerpt(s.rest)
        )),
    }
}

fn clamp_message(path: &Path, s: &Statement, material: &str, kd: Vec3) -> String {
    let k = kd.min(Vec3::ONE);
    format!(
        "{}:{}: material '{material}' has Kd {} {} {}, above 1: a surface would reflect more \
         light than it receives, so it is clamped to {} {} {}",
        super::shown_path(path),
        s.line,
        kd.x,
        kd.y,
        kd.z,
        k.x,
        k.y,
        k.z
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Library, SceneError> {
        parse_mtl(Path::new("m.mtl"), text)
    }

    #[test]
    fn what_exporters_write_loads() {
        let text = "# Blender MTL File\r\nnewmtl leftWall\r\n\tNs 10.0000\r\n\tNi 1.5000\r\n\
                    \tillum 2\r\n\tKa 0.63 0.065 0.05 # Red\r\n\tKd 0.63 0.065 0.05 # Red\r\n\
                    \tKs 0   0   0\r\n\tKe 0 0 0\r\n\tmap_Kd -bm 2 wall.png\r\n\
                    newmtl light\r\nKa 20 20 20\r\nKd 0.78 0.78 0.78\r\nKe 17 12 4\r\nTf 1 1 1\r\n\
                    d 1\r\nTr 0\r\nbump\r\nrefl -type sphere x.png\r\nPr nan\r\n";
        let lib = parse(text).unwrap();
        let names: Vec<&str> = lib.materials.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["leftWall", "light"]);
        assert_eq!(lib.materials[0].1.kd, Vec3::new(0.63, 0.065, 0.05));
        assert_eq!(lib.materials[1].1.ke, Vec3::new(17.0, 12.0, 4.0));
        assert_eq!(lib.skipped.total(), 13);
        assert_eq!(
            lib.skipped.summary().unwrap(),
            "skipped 13 statements the solver does not use (Ka ×2, Ks ×1, Ni ×1, Ns ×1, Pr ×1, \
             Tf ×1, Tr ×1, bump ×1, d ×1, illum ×1, 2 others)"
        );
        assert!(lib.clamped.is_empty());
    }

    #[test]
    fn a_colour_given_only_as_a_texture_reflects_the_default_grey() {
        let text = "newmtl tiles\nmap_Kd t.png\nnewmtl both\nmap_Kd t.png\nKd 0.2 0.3 0.4\n\
                    newmtl lamp\nKe 1 1 1\nnewmtl late\nKd 0.1 0.1 0.1\nmap_Kd t.png\n";
        let lib = parse(text).unwrap();
        let kd: Vec<Vec3> = lib.materials.iter().map(|(_, m)| m.kd).collect();
        assert_eq!(
            kd,
            [
                Vec3::splat(DEFAULT_GREY),
                Vec3::new(0.2, 0.3, 0.4),
                Vec3::ZERO, // no texture, no `Kd`: reflects nothing, as before
                Vec3::splat(0.1),
            ]
        );
        assert_eq!(lib.textured_only, ["tiles"]);
    }

    #[test]
    fn kd_above_one_is_clamped_with_its_line_and_material() {
        let lib = parse("newmtl glow\nKd 1.2 0.5 3\n").unwrap();
        assert_eq!(lib.materials[0].1.kd, Vec3::new(1.0, 0.5, 1.0));
        assert_eq!(lib.clamped_lines, 1);
        let m = &lib.clamped[0];
        assert!(
            m.starts_with("m.mtl:2: material 'glow' has Kd 1.2 0.5 3"),
            "{m}"
        );
        assert!(m.ends_with("clamped to 1 0.5 1"), "{m}");
        let many = "newmtl a\nKd 2 2 2\n".repeat(9);
        let lib = parse(&many).unwrap();
        assert_eq!((lib.clamped.len(), lib.clamped_lines), (CLAMPS_SHOWN, 9));
    }

    #[test]
    fn what_the_solver_uses_is_checked_with_the_line() {
        for (text, line, needle) in [
            ("newmtl a\nKd 0.5\n", 2, "`Kd` needs three numbers"),
            ("newmtl a\nKd 0.5 0.5 0.5 0.5\n", 2, "`Kd` needs"),
            ("newmtl a\n\nKd -0.1 0 0\n", 3, "0 or more"),
            ("newmtl a\nKd nan 0 0\n", 2, "`Kd`"),
            ("newmtl a\nKd inf 0 0\n", 2, "`Kd`"),
            (
                "newmtl a\nKe 1e39 1 1\n",
                2,
                "`Ke` needs three numbers in [0, 1e15]",
            ),
            ("newmtl a\nKe 1 -1 1 # comment\n", 2, "got `Ke 1 -1 1`"),
            ("Kd 0.5 0.5 0.5\n", 1, "before any `newmtl`"),
            ("newmtl\t\n", 1, "material name"),
        ] {
            let e = parse(text).unwrap_err().to_string();
            assert!(e.starts_with(&format!("m.mtl:{line}: ")), "{text:?}: {e}");
            assert!(e.contains(needle), "{text:?}: {e}");
        }
        let e = parse("newmtl a\nKd \x1b[2J 0 0\n").unwrap_err().to_string();
        assert!(e.contains("\\u{1b}[2J") && !e.contains('\x1b'), "{e}");
    }
}
