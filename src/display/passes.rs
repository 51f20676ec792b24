//! Pictures of the passes of single shots, for reading the paper beside the program
//! (`radiosity solve --dump-passes K[,K...] --out DIR`). For each listed shot K (three digits):
//!
//! ```text
//! shot-K-itembuffer.png     the visibility pass's item buffer from the shooter: polygon IDs in
//!                           false colour (id_colour; black = nothing seen), top row first.
//!                           Hemisphere: the unit disk, R x R. Hemicube: front, +x, -x, +y, -y.
//!                           A shot from several cells (accurate mode) shows its last cell's.
//! shot-K-delta.png          the reconstruction passes' ΔL: radiance atlas after the shot minus
//!                           before, scaled so its brightest patches are white (see shot-K.json)
//! shot-K-atlas-before.png   the radiance atlas before and after the shot, exposure 1 as image.png
//! shot-K-atlas-after.png
//! shot-K.json               shooter, powers, exposures, and the legend of the false colours
//! ```
//!
//! Atlas pictures are enlarged by a whole factor (nearest texel) to at least 512 pixels, with
//! texels that are no patch in dark blue-grey; row 0 at the top, i.e. the atlas flipped.

use super::output::{srgb_encode, Payload};
use super::output_set::OutputSet;
use crate::patches::PatchLayout;
use crate::scene::Scene;
use crate::solver::{GpuSolver, ShotRecord, VisibilityKind};
use anyhow::Result;
use std::collections::BTreeSet;

/// False colours for polygon IDs: (ID + 1) times an odd constant, modulo 2^24, as R, G, B bytes.
/// Neighbouring IDs get very different colours, and the map is a bijection of 24-bit numbers,
/// so [`colour_id`] decodes a picture back to IDs exactly. `glsl/overlay.frag` uses the same.
pub const ID_COLOUR_MULTIPLIER: u32 = 0xF9_C94F;
/// The inverse of [`ID_COLOUR_MULTIPLIER`] modulo 2^24.
pub const ID_COLOUR_INVERSE: u32 = 0x3B_ADAF;

/// The false colour of an item-buffer pixel: black where nothing is seen.
pub fn id_colour(id: Option<u32>) -> [u8; 3] {
    let n = id.map_or(0, |i| i + 1);
    let c = n.wrapping_mul(ID_COLOUR_MULTIPLIER) & 0xFF_FFFF;
    [c as u8, (c >> 8) as u8, (c >> 16) as u8]
}

/// The ID a false colour stands for (`None` for black).
pub fn colour_id(rgb: [u8; 3]) -> Option<u32> {
    let c = rgb[0] as u32 | (rgb[1] as u32) << 8 | (rgb[2] as u32) << 16;
    (c.wrapping_mul(ID_COLOUR_INVERSE) & 0xFF_FFFF).checked_sub(1)
}

/// Texels that are no patch, in the atlas pictures.
const NO_PATCH: [u8; 3] = [28, 30, 44];
/// Atlas pictures are enlarged to at least this many pixels along their longer side.
const ATLAS_MIN_SIDE: u32 = 512;

/// Which shots to dump, the output set they join, and the atlas kept from before the next one.
pub struct PassDumps<'a> {
    shots: BTreeSet<u32>,
    set: &'a OutputSet,
    before: Option<Vec<f32>>,
    /// Names of the files staged so far.
    pub written: Vec<String>,
}

impl<'a> PassDumps<'a> {
    /// Dumps for the shots listed (1-based), staged in `set`.
    pub fn new(shots: &[u32], set: &'a OutputSet) -> PassDumps<'a> {
        PassDumps {
            shots: shots.iter().copied().collect(),
            set,
            before: None,
            written: Vec::new(),
        }
    }

    /// Whether no shot is to be pictured.
    pub fn is_empty(&self) -> bool {
        self.shots.is_empty()
    }

    /// Call before each shot: keeps the radiance atlas when the coming shot is one to dump.
    pub fn before_shot(&mut self, solver: &GpuSolver) {
        self.before = (self.shots.contains(&(solver.shots() + 1)) && !solver.converged())
            .then(|| solver.radiosity_atlas());
    }

    /// Call after each shot: writes its pictures when it is one to dump.
    pub fn after_shot(
        &mut self,
        solver: &GpuSolver,
        scene: &Scene,
        layout: &PatchLayout,
        record: &ShotRecord,
    ) -> Result<()> {
        let Some(before) = self.before.take() else {
            return Ok(());
        };
        let name = |what: &str| format!("shot-{:03}-{what}", record.shot);
        let (w, h) = (layout.atlas_width, layout.atlas_height);
        let after = solver.radiosity_atlas();
        let delta: Vec<f32> = after
            .iter()
            .zip(&before)
            .enumerate()
            .map(|(i, (a, b))| if i % 4 == 3 { *a } else { a - b })
            .collect();
        let delta_exposure = auto_exposure(&delta);

        let mut files = Vec::new();
        let vis = &solver.backend().visibility;
        // Only what this shot drew (a small shot fills the lower-left corner).
        let full = vis.item_buffer().width as usize;
        let (iw, ih) = (vis.drawn().0 as u32, vis.drawn().1 as u32);
        let ids: Vec<Option<u32>> = (vis.read_ids().chunks_exact(full))
            .take(ih as usize)
            .flat_map(|row| row[..iw as usize].to_vec())
            .collect();
        let path = name("itembuffer.png");
        write_rgb(self.set, &path, iw, ih, &item_buffer_rgb(&ids, iw, ih))?;
        files.push(path);
        for (what, atlas, exposure) in [
            ("delta.png", &delta, delta_exposure),
            ("atlas-before.png", &before, 1.0),
            ("atlas-after.png", &after, 1.0),
        ] {
            let (rgb, pw, ph) = atlas_rgb(atlas, w, h, exposure);
            let path = name(what);
            write_rgb(self.set, &path, pw, ph, &rgb)?;
            files.push(path);
        }

        let mut seen: Vec<u32> = ids.iter().flatten().copied().collect();
        seen.sort_unstable();
        seen.dedup();
        let legend: Vec<serde_json::Value> = seen
            .iter()
            .map(|&id| {
                let c = id_colour(Some(id));
                serde_json::json!({
                    "id": id,
                    "object": scene.polygons.get(id as usize).map(|p| p.object.as_str()),
                    "colour": format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]),
                })
            })
            .collect();
        let shooter = &scene.polygons[record.shooter];
        let info = serde_json::json!({
            "shot": record.shot,
            "shooter": record.shooter,
            "shooter_object": shooter.object,
            "shot_power": record.shot_power,
            "reflected_power": record.reflected_power,
            "unshot_fraction_after": record.unshot_fraction,
            "visibility": match vis.kind {
                VisibilityKind::Hemisphere => "hemisphere",
                VisibilityKind::Hemicube => "hemicube",
            },
            "item_buffer_size": [iw, ih],
            "atlas_size": [w, h],
            "delta_exposure": delta_exposure,
            "atlas_exposure": 1.0,
            "item_buffer_legend": legend,
        });
        let path = format!("shot-{:03}.json", record.shot);
        self.set.write(&path, Payload::json(&info)?)?;
        files.push(path);
        self.written.extend(files);
        Ok(())
    }
}

/// Item-buffer IDs (rows bottom to top) → false-colour RGB, rows top to bottom.
pub fn item_buffer_rgb(ids: &[Option<u32>], width: u32, height: u32) -> Vec<u8> {
    let w = width as usize;
    let mut rgb = Vec::with_capacity(ids.len() * 3);
    for row in (0..height as usize).rev() {
        for &id in &ids[row * w..(row + 1) * w] {
            rgb.extend_from_slice(&id_colour(id));
        }
    }
    rgb
}

/// An exposure that maps the 99th percentile of the largest channel over the patches to 1 (the
/// few hottest texels clip, the rest stay readable); 1 when nothing is lit.
pub fn auto_exposure(rgba: &[f32]) -> f32 {
    let mut peaks: Vec<f32> = rgba
        .chunks_exact(4)
        .filter(|t| t[3] > 0.0)
        .map(|t| t[0].max(t[1]).max(t[2]))
        .filter(|&v| v > 0.0)
        .collect();
    if peaks.is_empty() {
        return 1.0;
    }
    let k = ((peaks.len() - 1) as f32 * 0.99) as usize;
    let (_, p, _) = peaks.select_nth_unstable_by(k, f32::total_cmp);
    1.0 / *p
}

/// An atlas (RGBA radiance, alpha = polygon ID + 1, rows bottom to top) → tone-mapped sRGB, rows
/// top to bottom, enlarged by a whole factor; returns the pixels and their size.
pub fn atlas_rgb(rgba: &[f32], width: u32, height: u32, exposure: f32) -> (Vec<u8>, u32, u32) {
    let scale = ATLAS_MIN_SIDE.div_ceil(width.max(height).max(1)).max(1);
    let (pw, ph) = (width * scale, height * scale);
    let mut rgb = Vec::with_capacity(pw as usize * ph as usize * 3);
    for y in 0..ph {
        let row = (height - 1 - y / scale) as usize;
        for x in 0..pw {
            let t = &rgba[(row * width as usize + (x / scale) as usize) * 4..][..4];
            if t[3] > 0.0 {
                for &v in &t[..3] {
                    let v = srgb_encode((v * exposure).clamp(0.0, 1.0));
                    rgb.push((v * 255.0 + 0.5) as u8);
                }
            } else {
                rgb.extend_from_slice(&NO_PATCH);
            }
        }
    }
    (rgb, pw, ph)
}

fn write_rgb(set: &OutputSet, name: &str, width: u32, height: u32, rgb: &[u8]) -> Result<()> {
    set.write(name, Payload::Png { width, height, rgb })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn false_colours_decode_to_their_ids() {
        assert_eq!(id_colour(None), [0, 0, 0]);
        assert_eq!(colour_id([0, 0, 0]), None);
        for id in (0..5000).chain([1 << 20, (1 << 24) - 2]) {
            assert_eq!(colour_id(id_colour(Some(id))), Some(id));
        }
        assert_eq!(
            ID_COLOUR_MULTIPLIER.wrapping_mul(ID_COLOUR_INVERSE) & 0xFF_FFFF,
            1
        );
    }

    #[test]
    fn neighbouring_ids_look_different() {
        for id in 0..40 {
            let (a, b) = (id_colour(Some(id)), id_colour(Some(id + 1)));
            let d: i32 = a
                .iter()
                .zip(&b)
                .map(|(&x, &y)| (x as i32 - y as i32).abs())
                .sum();
            assert!(d > 60, "ids {id} and {} too alike: {a:?} {b:?}", id + 1);
            assert!(a.iter().any(|&c| c > 70), "id {id} too dark: {a:?}");
        }
    }

    #[test]
    fn atlas_pictures_flip_rows_and_enlarge() {
        // 2 x 1 atlas: a lit patch on the left, no patch on the right.
        let atlas = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0];
        let (rgb, w, h) = atlas_rgb(&atlas, 2, 1, 1.0);
        assert_eq!((w, h), (512, 256));
        assert_eq!(&rgb[..3], &[255, 0, 0]);
        assert_eq!(&rgb[rgb.len() - 3..], &NO_PATCH);
    }
}
