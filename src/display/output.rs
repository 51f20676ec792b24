//! Output files: `image.exr` (linear radiance), `image.png` (tone-mapped sRGB), `lightmap.exr`
//! (the atlas, linear radiance) and `stats.json`. Each is written to a temporary file in the same
//! directory and renamed, so a failed run never leaves half a file over a good one.

use super::Image;
use anyhow::{Context, Result};
use std::path::Path;

/// Write `bytes` through a temporary file and an atomic rename.
pub fn write_atomic(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    // Keep the extension last: the image encoders choose the format from it.
    let tmp = path.with_file_name(format!(".{name}.partial.{ext}"));
    let result = write(&tmp);
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(e.context(format!("cannot write {}", path.display())));
    }
    std::fs::rename(&tmp, path).with_context(|| format!("cannot write {}", path.display()))
}

pub fn write_exr(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<()> {
    write_atomic(path, |tmp| {
        let img = image::Rgb32FImage::from_raw(width, height, rgb.to_vec())
            .context("image size does not match its data")?;
        img.save(tmp).context("EXR encoder failed")?;
        Ok(())
    })
}

/// Linear radiance → display: scale by `exposure`, clamp, sRGB transfer curve, 8 bits.
pub fn tone_map(image: &Image, exposure: f32) -> Vec<u8> {
    image
        .rgb
        .iter()
        .map(|&v| (srgb_encode((v * exposure).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8)
        .collect()
}

pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

pub fn write_png(path: &Path, image: &Image, exposure: f32) -> Result<()> {
    write_atomic(path, |tmp| {
        let img = image::RgbImage::from_raw(image.width, image.height, tone_map(image, exposure))
            .context("image size does not match its data")?;
        img.save(tmp).context("PNG encoder failed")?;
        Ok(())
    })
}

/// The atlas as an EXR: RGB radiance, row 0 at the top (GL's rows flipped).
pub fn write_atlas_exr(path: &Path, width: u32, height: u32, rgba_bottom_up: &[f32]) -> Result<()> {
    let mut rgb = Vec::with_capacity(width as usize * height as usize * 3);
    for row in (0..height as usize).rev() {
        for px in
            rgba_bottom_up[row * width as usize * 4..(row + 1) * width as usize * 4].chunks_exact(4)
        {
            rgb.extend_from_slice(&px[..3]);
        }
    }
    write_exr(path, width, height, &rgb)
}

pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    write_atomic(path, |tmp| {
        let text = serde_json::to_string_pretty(value)?;
        std::fs::write(tmp, text + "\n")?;
        Ok(())
    })
}
