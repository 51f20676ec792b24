//! Beyond the paper: a uniform sky (`--sky R,G,B`), for scenes lit through their openings (a
//! courtyard, a nave's windows) whose files have no emitter.
//!
//! The sky is made of ordinary emitters, added when the scene is loaded: an open box of quads
//! around the scene's bounds, a margin ([`MARGIN`]) outside them, its top and four sides facing
//! inward (emitters shine from their front only), with no bottom: light comes from above the
//! horizon of the scene's lowest point, as from a sky over the ground. Each quad has `Ke` the
//! sky's radiance and `Kd` 0, so it shoots once and takes nothing back; both solvers shoot it
//! patch by patch like any emitter, without a pass of their own. Whatever of the scene is
//! reached through an opening receives L·F, F the configuration factor of the opening: a quad
//! seen through it delivers its radiance times its own factor, as a lamp would.
//!
//! The quads are [`DIVISIONS`] to the longer side of the top, square, one patch each whatever the
//! scene's patch size (`PatchLayout`), so that the sky does not take the scene's patch budget. A
//! quad is seen (from its centre, through the item buffer) whole or not at all, so an opening
//! gets its share to within the quads along its edge: from a point under it, the factor of the
//! opening shrunk and grown by half a quad (`tests/sky.rs` checks that band).
//!
//! The sky is not part of the picture (`DisplayMesh` leaves it out: the background shows where
//! it would be), of the default camera's framing, or of the counts of `stats.json` (`polygons`,
//! `lights` and `patches` are the scene's; `sky` has its own).

use super::error::{EmissionError, MAX_KE};
use super::{Material, Polygon, Scene};
use glam::Vec3;

/// The sky's material and object name. Loaders end the material list with
/// `DEFAULT_MATERIAL`, so a sky's material, pushed after it, is the only last material of this
/// name.
pub const SKY_MATERIAL: &str = "(sky)";

/// Quads along the longer side of the sky's top: 32 makes about 2,000 quads on an open level
/// such as zdm2 (one shot each), each about 3° wide seen from the middle of the scene.
pub const DIVISIONS: u32 = 32;

/// The sky's distance outside the scene's bounds, as a share of their diagonal: close, so that
/// most of its light falls on the scene rather than on the sky itself (which absorbs it), yet
/// clear of the outermost faces.
pub const MARGIN: f32 = 0.02;

/// What a sky adds to a scene, for the statistics.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SkyStats {
    /// Its radiance, linear RGB (as `Ke`).
    pub radiance: [f32; 3],
    /// Its quads (polygons of the solve, not of the scene's counts).
    pub polygons: usize,
    /// Their patches (one each).
    pub patches: u64,
}

impl Scene {
    /// Surround the scene with a sky of radiance `radiance` (see the module's note). Each
    /// channel from 0 to [`MAX_KE`]; at least one above 0.
    pub fn add_sky(&mut self, radiance: Vec3) -> Result<(), EmissionError> {
        let ok = radiance
            .to_array()
            .iter()
            .all(|v| (0.0..=MAX_KE).contains(v));
        if !ok || radiance.max_element() <= 0.0 {
            return Err(EmissionError::Radiance {
                name: SKY_MATERIAL.into(),
                ke: radiance.to_array(),
            });
        }
        let (lo, hi) = self.bounds();
        let material = self.materials.len();
        self.materials.push(Material {
            name: SKY_MATERIAL.into(),
            kd: Vec3::ZERO,
            ke: radiance,
        });
        for quad in quads(lo, hi) {
            if let Some(p) = Polygon::new(quad.to_vec(), material, SKY_MATERIAL.into()) {
                self.polygons.push(p);
            }
        }
        Ok(())
    }

    /// The index of the sky's first polygon (the sky's polygons are the last ones), if the
    /// scene has a sky.
    pub fn sky_start(&self) -> Option<usize> {
        let m = self.materials.len().checked_sub(1)?;
        if self.materials[m].name != SKY_MATERIAL {
            return None;
        }
        Some(self.polygons.partition_point(|p| p.material != m))
    }

    /// Whether polygon `p` belongs to the sky.
    pub fn is_sky(&self, p: usize) -> bool {
        self.sky_start().is_some_and(|k| p >= k)
    }

    /// The polygons of the scene itself, the sky's left out.
    pub fn own_polygons(&self) -> &[Polygon] {
        &self.polygons[..self.sky_start().unwrap_or(self.polygons.len())]
    }

    /// The scene without its sky (itself when it has none): what the camera frames.
    pub fn without_sky(&self) -> std::borrow::Cow<'_, Scene> {
        match self.sky_start() {
            None => std::borrow::Cow::Borrowed(self),
            Some(k) => {
                let mut own = Scene {
                    polygons: self.polygons[..k].to_vec(),
                    ..self.clone_header()
                };
                own.materials.pop();
                std::borrow::Cow::Owned(own)
            }
        }
    }

    /// Everything but the polygons.
    fn clone_header(&self) -> Scene {
        Scene {
            name: self.name.clone(),
            polygons: Vec::new(),
            materials: self.materials.clone(),
            vertex_count: self.vertex_count,
            camera: self.camera,
            patch_size: self.patch_size,
            skipped_degenerate: self.skipped_degenerate,
            faces: self.faces,
        }
    }

    /// The sky's statistics, `patches` its patch count, if the scene has one.
    pub fn sky_stats(&self, patches: u64) -> Option<SkyStats> {
        let k = self.sky_start()?;
        Some(SkyStats {
            radiance: self.materials.last()?.ke.to_array(),
            polygons: self.polygons.len() - k,
            patches,
        })
    }
}

/// The sky's quads around the box `lo`–`hi`, counter-clockwise seen from inside.
fn quads(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 4]> {
    let m = MARGIN * (hi - lo).length().max(f32::MIN_POSITIVE);
    let (a, b) = (
        Vec3::new(lo.x - m, lo.y, lo.z - m),
        Vec3::new(hi.x + m, hi.y + m, hi.z + m),
    );
    let size = b - a;
    let cell = size.x.max(size.z) / DIVISIONS as f32;
    let (x, y, z) = (Vec3::X * size.x, Vec3::Y * size.y, Vec3::Z * size.z);
    // Each face as a corner and two edges whose cross product points into the box.
    let faces = [
        (a + y, x, z), // top, facing down
        (a, y, z),     // x = a.x, facing +x
        (a + x, z, y), // x = b.x, facing −x
        (a, x, y),     // z = a.z, facing +z
        (a + z, y, x), // z = b.z, facing −z
    ];
    let mut out = Vec::new();
    for (corner, u, v) in faces {
        let (nu, nv) = (divisions(u.length(), cell), divisions(v.length(), cell));
        let (du, dv) = (u / nu as f32, v / nv as f32);
        for i in 0..nu {
            for j in 0..nv {
                let o = corner + du * i as f32 + dv * j as f32;
                out.push([o, o + du, o + du + dv, o + dv]);
            }
        }
    }
    out
}

/// Quads along an edge of `length` for quads of side about `cell`: at least one, and at most
/// four times the top's, so that a tall, narrow scene's sides stay a few thousand quads (longer
/// ones then).
fn divisions(length: f32, cell: f32) -> u32 {
    ((length / cell).round() as u32).clamp(1, 4 * DIVISIONS)
}

#[cfg(test)]
mod tests {
    use super::super::test_scene;
    use super::*;

    fn floor() -> Polygon {
        let v = [(0.0, 0.0), (0.0, 1.0), (2.0, 1.0), (2.0, 0.0)]
            .map(|(x, z)| Vec3::new(x, 0.0, z))
            .to_vec();
        Polygon::new(v, 0, "floor".into()).unwrap()
    }

    #[test]
    fn the_sky_surrounds_the_scene_facing_inward_and_is_told_apart() {
        let mut s = test_scene(vec![floor()]);
        s.materials.push(Material {
            name: super::super::DEFAULT_MATERIAL.into(),
            kd: Vec3::splat(0.5),
            ke: Vec3::ZERO,
        });
        assert_eq!(s.sky_start(), None);
        assert!(s.add_sky(Vec3::new(0.0, 0.0, 0.0)).is_err());
        assert!(s.add_sky(Vec3::new(-1.0, 1.0, 1.0)).is_err());
        s.add_sky(Vec3::new(1.0, 2.0, 3.0)).unwrap();
        assert_eq!(s.sky_start(), Some(1));
        assert!(!s.is_sky(0) && s.is_sky(1) && s.is_sky(s.polygons.len() - 1));
        assert_eq!(s.own_polygons().len(), 1);
        assert_eq!(s.without_sky().polygons.len(), 1);
        assert_eq!(s.without_sky().materials.len(), 2);
        let sky = &s.polygons[1..];
        // 32 along the 2-unit side, 16 along the other on top; sides a few rows high.
        assert!(sky.len() > 32 * 16, "{}", sky.len());
        let (lo, hi) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 1.0));
        let centre = (lo + hi) / 2.0;
        let m = MARGIN * (hi - lo).length();
        for p in sky {
            // Inward: the scene's centre is in front of every quad; none below the floor.
            assert!(p.plane().distance(centre) > 0.0, "{:?}", p.normal);
            assert!(p.vertices.iter().all(|v| v.y >= 0.0 && v.y <= m * 1.001));
            assert!(p.normal.y <= 0.0);
        }
        let area: f32 = sky.iter().map(|p| p.area).sum();
        let (w, d, h) = (2.0 + 2.0 * m, 1.0 + 2.0 * m, m);
        assert!((area - (w * d + 2.0 * (w + d) * h)).abs() < 1e-4 * area);
        assert_eq!(s.sky_stats(7).unwrap().radiance, [1.0, 2.0, 3.0]);
        assert!(s.material(&sky[0]).is_emitter() && s.material(&sky[0]).kd == Vec3::ZERO);
    }
}
