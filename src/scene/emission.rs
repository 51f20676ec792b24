//! Light without editing the file: emission overrides (`--emit NAME=R,G,B`) make a material an
//! emitter after loading, and the check that the scene then emits at all, whose message lists
//! the materials by area so that the user can pick the lamps and windows.

use super::error::{EmissionError, SceneError, MAX_KE};
use super::Scene;
use glam::Vec3;

/// Make the material `material` emit `ke` (emitted radiance, linear RGB, as `Ke` in the MTL
/// file; 0,0,0 turns an emitter off).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Emission {
    /// The material's name as messages show it (control characters escaped).
    pub material: String,
    /// Emitted radiance, linear RGB.
    pub ke: [f32; 3],
}

/// What a scene loader does besides reading the files.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Emission overrides, applied in order after loading and before the check that something
    /// emits.
    pub emit: Vec<Emission>,
    /// Keep every face its own polygon (`--keep-faces`), as a scene's `# keep-faces` line does;
    /// otherwise connected coplanar faces of one material are merged (`merge.rs`).
    pub keep_faces: bool,
    /// Beyond the paper: surround the scene with a uniform sky of this radiance (`--sky`,
    /// `sky.rs`), added before the check that something emits.
    pub sky: Option<Vec3>,
}

/// Materials listed in a message at most; the rest are counted.
const LISTED: usize = 30;

impl Scene {
    /// Set the emitted radiance of every material called `name` (as messages show it) to `ke`;
    /// the number of materials changed (more than one when libraries define the name twice).
    pub fn set_emission(&mut self, name: &str, ke: Vec3) -> Result<usize, EmissionError> {
        if !ke.to_array().iter().all(|v| (0.0..=MAX_KE).contains(v)) {
            return Err(EmissionError::Radiance {
                name: name.to_string(),
                ke: ke.to_array(),
            });
        }
        let mut changed = 0;
        for m in self.materials.iter_mut().filter(|m| m.name == name) {
            m.ke = ke;
            changed += 1;
        }
        if changed == 0 {
            let mut names: Vec<&str> = self.materials.iter().map(|m| m.name.as_str()).collect();
            let more = names.len().saturating_sub(LISTED);
            names.truncate(LISTED);
            let mut materials = names.join(", ");
            if more > 0 {
                materials += &format!(" and {more} more");
            }
            return Err(EmissionError::UnknownMaterial {
                name: super::shown(name),
                materials,
            });
        }
        Ok(changed)
    }

    /// Apply `overrides` in order; the error names the file `path`.
    pub(super) fn apply_emission(
        &mut self,
        path: &str,
        overrides: &[Emission],
    ) -> Result<(), SceneError> {
        for e in overrides {
            self.set_emission(&e.material, Vec3::from(e.ke))
                .map_err(|source| SceneError::Emit {
                    path: path.to_string(),
                    source,
                })?;
        }
        Ok(())
    }

    /// Fail unless some face emits: naming the emitting materials that have no face, or listing
    /// every material with its faces and area when none emits.
    pub(super) fn check_emits(&self, path: &str) -> Result<(), SceneError> {
        if self.light_count() > 0 {
            return Ok(());
        }
        let emitting = self.emitting_materials();
        if !emitting.is_empty() {
            return Err(SceneError::EmitterZeroArea {
                path: path.to_string(),
                materials: emitting.join(", "),
                skipped: self.skipped_degenerate,
            });
        }
        Err(SceneError::NoEmitter {
            path: path.to_string(),
            materials: self.materials_by_area(),
        })
    }

    /// `white (9 faces, area 1.05e6), red (1 face, area 3.07e5), ...`: every material, largest
    /// total area first; the default grey only when faces use it.
    pub fn materials_by_area(&self) -> String {
        let mut faces = vec![0usize; self.materials.len()];
        let mut area = vec![0f64; self.materials.len()];
        for p in &self.polygons {
            faces[p.material] += 1;
            area[p.material] += p.area as f64;
        }
        let mut order: Vec<usize> = (0..self.materials.len())
            .filter(|&m| faces[m] > 0 || self.materials[m].name != super::DEFAULT_MATERIAL)
            .collect();
        order.sort_by(|&a, &b| area[b].total_cmp(&area[a]).then(a.cmp(&b)));
        if order.is_empty() {
            return "none".into();
        }
        let mut parts: Vec<String> = order
            .iter()
            .take(LISTED)
            .map(|&m| {
                let s = if faces[m] == 1 { "" } else { "s" };
                format!(
                    "{} ({} face{s}, area {})",
                    self.materials[m].name,
                    faces[m],
                    three_digits(area[m])
                )
            })
            .collect();
        if order.len() > LISTED {
            parts.push(format!("and {} more", order.len() - LISTED));
        }
        parts.join(", ")
    }
}

/// `x` to three significant digits, in plain notation from 0.001 to a million.
fn three_digits(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let e = x.abs().log10().floor() as i32;
    if (-3..6).contains(&e) {
        format!("{:.*}", (2 - e).max(0) as usize, x)
    } else {
        format!("{x:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::super::{test_scene, Material, Polygon};
    use super::*;

    fn square(size: f32, material: usize) -> Polygon {
        let v = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(x, y)| Vec3::new(x * size, y * size, 0.0))
            .to_vec();
        Polygon::new(v, material, "o".into()).unwrap()
    }

    fn scene() -> Scene {
        let mut s = test_scene(vec![square(1.0, 0), square(2.0, 1), square(2.0, 1)]);
        s.materials.push(Material {
            name: "Glass".into(),
            kd: Vec3::ZERO,
            ke: Vec3::ZERO,
        });
        s.materials.push(Material {
            name: "unused".into(),
            kd: Vec3::ZERO,
            ke: Vec3::ZERO,
        });
        s
    }

    #[test]
    fn no_emitter_lists_materials_by_area_and_suggests_emit() {
        let e = scene().check_emits("s.obj").unwrap_err().to_string();
        assert!(
            e.contains(
                "Its materials, largest area first: Glass (2 faces, area 8.00), m (1 face, area \
                 1.00), unused (0 faces, area 0)."
            ),
            "{e}"
        );
        assert!(
            e.starts_with("s.obj: the scene has no emitter") && e.contains("--emit NAME=R,G,B")
        );
    }

    #[test]
    fn an_override_lights_the_scene_and_an_unknown_name_lists_the_materials() {
        let mut s = scene();
        assert_eq!(s.set_emission("Glass", Vec3::new(5.0, 5.0, 4.0)), Ok(1));
        assert_eq!(s.light_count(), 2);
        assert!(s.check_emits("s.obj").is_ok());
        let e = s.set_emission("Lamp", Vec3::ONE).unwrap_err().to_string();
        assert!(
            e.contains("'Lamp'") && e.contains("Its materials: m, Glass, unused"),
            "{e}"
        );
        for bad in [
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::splat(f32::NAN),
            Vec3::splat(1e16),
        ] {
            assert!(matches!(
                s.set_emission("Glass", bad),
                Err(EmissionError::Radiance { .. })
            ));
        }
        // Lit through a material no face uses: said so, not "no emitter".
        let mut s = scene();
        s.set_emission("unused", Vec3::ONE).unwrap();
        let e = s.check_emits("s.obj").unwrap_err();
        assert!(matches!(e, SceneError::EmitterZeroArea { .. }), "{e}");
    }

    #[test]
    fn areas_read_well() {
        assert_eq!(three_digits(3.2), "3.20");
        assert_eq!(three_digits(1234.6), "1235");
        assert_eq!(three_digits(0.012345), "0.0123");
        assert_eq!(three_digits(3.07e5), "307000");
        assert_eq!(three_digits(1.05e6), "1.05e6");
    }
}
