//! Output files: `image.exr` (linear radiance), `image.png` (tone-mapped sRGB), `lightmap.exr`
//! (the atlas, linear radiance) and `stats.json`.
//!
//! A single file ([`write_atomic`]) is encoded into a uniquely named temporary file, created
//! exclusively beside it (so a symlink planted at a temporary name is never followed and two runs
//! never share one), synced, and renamed over the target. `solve`'s outputs are a set and go
//! through [`super::output_set::OutputSet`] instead, which replaces them all together.
//!
//! Encoders write straight into the file through `Recorder`, which keeps the first I/O error:
//! a full disk is then reported as "no space left", not as whatever the encoder makes of it.

use super::Image;
use anyhow::{anyhow, Context, Result};
use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::os::unix::fs::PermissionsExt;
use std::path::Path;

/// What to write: the encoders are chosen here, not from the file name.
pub enum Payload<'a> {
    /// Linear RGB floats, rows top to bottom.
    Exr {
        /// Width, pixels.
        width: u32,
        /// Height, pixels.
        height: u32,
        /// Three floats per pixel.
        rgb: &'a [f32],
    },
    /// 8-bit sRGB, rows top to bottom.
    Png {
        /// Width, pixels.
        width: u32,
        /// Height, pixels.
        height: u32,
        /// Three bytes per pixel.
        rgb: &'a [u8],
    },
    /// UTF-8 text (JSON, reports), written as it is.
    Text(String),
    /// Bytes encoded elsewhere (`gltf_out`), written as they are.
    Bytes(&'a [u8]),
}

impl Payload<'_> {
    /// A value as pretty JSON with a final newline.
    pub fn json(value: &impl serde::Serialize) -> Result<Payload<'static>> {
        Ok(Payload::Text(serde_json::to_string_pretty(value)? + "\n"))
    }

    fn encode(&self, w: &mut (impl Write + Seek)) -> Result<()> {
        match self {
            Payload::Exr { width, height, rgb } => {
                let img = image::Rgb32FImage::from_raw(*width, *height, rgb.to_vec())
                    .context("image size does not match its data")?;
                img.write_to(w, image::ImageFormat::OpenExr)
                    .context("EXR encoder failed")
            }
            Payload::Png { width, height, rgb } => {
                let img = image::RgbImage::from_raw(*width, *height, rgb.to_vec())
                    .context("image size does not match its data")?;
                img.write_to(w, image::ImageFormat::Png)
                    .context("PNG encoder failed")
            }
            Payload::Text(text) => Ok(w.write_all(text.as_bytes())?),
            Payload::Bytes(bytes) => Ok(w.write_all(bytes)?),
        }
    }
}

/// A writer that remembers the first I/O error it passed on.
struct Recorder<W> {
    inner: W,
    error: Option<(io::ErrorKind, String)>,
}

impl<W> Recorder<W> {
    fn keep<T>(&mut self, r: io::Result<T>) -> io::Result<T> {
        if let Err(e) = &r {
            if self.error.is_none() {
                self.error = Some((e.kind(), e.to_string()));
            }
        }
        r
    }
}

impl<W: Write> Write for Recorder<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let r = self.inner.write(buf);
        self.keep(r)
    }
    fn flush(&mut self) -> io::Result<()> {
        let r = self.inner.flush();
        self.keep(r)
    }
}

impl<W: Seek> Seek for Recorder<W> {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        let r = self.inner.seek(pos);
        self.keep(r)
    }
}

/// An I/O failure on `path`, named by its cause: ENOSPC and EDQUOT say the disk (or the quota) is
/// full.
pub(crate) fn io_error(kind: io::ErrorKind, message: &str, path: &Path) -> anyhow::Error {
    if matches!(
        kind,
        io::ErrorKind::StorageFull | io::ErrorKind::QuotaExceeded
    ) {
        anyhow!(
            "no space left on the device while writing {} (ENOSPC: {message})",
            path.display()
        )
    } else {
        anyhow!("cannot write {}: {message}", path.display())
    }
}

/// Encode `payload` into `file` and sync it to the disk; `path` names the file in messages.
pub(crate) fn fill(file: &mut File, payload: &Payload, path: &Path) -> Result<()> {
    let mut w = Recorder {
        inner: BufWriter::new(&mut *file),
        error: None,
    };
    let encoded = payload.encode(&mut w).and_then(|()| Ok(w.flush()?));
    // The I/O error, when there was one, is the cause; the encoder's message may hide it.
    if let Some((kind, message)) = &w.error {
        return Err(io_error(*kind, message, path));
    }
    encoded.with_context(|| format!("cannot write {}", path.display()))?;
    drop(w);
    file.sync_all()
        .map_err(|e| io_error(e.kind(), &e.to_string(), path))
}

/// Replace the file at `path` whole: through a uniquely named temporary file created exclusively
/// in the same folder (never following a symlink), synced, then renamed over `path`. A failure
/// removes the temporary file and leaves `path` as it was.
pub fn write_atomic(path: &Path, payload: Payload) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| anyhow!("{} is not a file name", path.display()))?
        .to_string_lossy();
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".partial")
        // As a plain create would (less the umask), not tempfile's private 0600.
        .permissions(std::fs::Permissions::from_mode(0o666))
        .tempfile_in(dir)
        .map_err(|e| io_error(e.kind(), &e.to_string(), path))?;
    fill(tmp.as_file_mut(), &payload, path)?;
    tmp.persist(path)
        .map_err(|e| io_error(e.error.kind(), &e.error.to_string(), path))?;
    Ok(())
}

/// Write linear RGB floats (rows top to bottom) as an OpenEXR file, atomically.
pub fn write_exr(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<()> {
    write_atomic(path, Payload::Exr { width, height, rgb })
}

/// Linear radiance → display: scale by `exposure`, clamp, sRGB transfer curve, 8 bits.
pub fn tone_map(image: &Image, exposure: f32) -> Vec<u8> {
    image
        .rgb
        .iter()
        .map(|&v| (srgb_encode((v * exposure).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8)
        .collect()
}

/// The sRGB transfer curve of a linear value in [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// Write `image` tone-mapped (`tone_map`) as an 8-bit sRGB PNG, atomically.
pub fn write_png(path: &Path, image: &Image, exposure: f32) -> Result<()> {
    let rgb = tone_map(image, exposure);
    write_atomic(
        path,
        Payload::Png {
            width: image.width,
            height: image.height,
            rgb: &rgb,
        },
    )
}

/// The atlas as RGB radiance, row 0 at the top (GL's rows flipped).
pub fn atlas_rgb_top_down(width: u32, height: u32, rgba_bottom_up: &[f32]) -> Vec<f32> {
    let mut rgb = Vec::with_capacity(width as usize * height as usize * 3);
    for row in (0..height as usize).rev() {
        for px in
            rgba_bottom_up[row * width as usize * 4..(row + 1) * width as usize * 4].chunks_exact(4)
        {
            rgb.extend_from_slice(&px[..3]);
        }
    }
    rgb
}

/// The atlas as an EXR: RGB radiance, row 0 at the top (GL's rows flipped).
pub fn write_atlas_exr(path: &Path, width: u32, height: u32, rgba_bottom_up: &[f32]) -> Result<()> {
    let rgb = atlas_rgb_top_down(width, height, rgba_bottom_up);
    write_exr(path, width, height, &rgb)
}

/// Write `value` as pretty JSON, atomically.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    write_atomic(path, Payload::json(value)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_symlink_at_the_old_temporary_name_is_not_followed() {
        let d = tempfile::tempdir().unwrap();
        let victim = d.path().join("victim");
        std::fs::write(&victim, "keep").unwrap();
        let out = d.path().join("stats.json");
        // The fixed name earlier versions used.
        std::os::unix::fs::symlink(&victim, d.path().join(".stats.json.partial.json")).unwrap();
        write_json(&out, &serde_json::json!({"a": 1})).unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "{\n  \"a\": 1\n}\n");
        let names: Vec<String> = std::fs::read_dir(d.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 3, "no temporary file left: {names:?}");
    }

    #[test]
    fn a_full_disk_is_named_as_such() {
        // /dev/full fails every write with ENOSPC, as a full disk does.
        let Ok(mut full) = File::options().write(true).open("/dev/full") else {
            return;
        };
        let rgb = vec![0.5f32; 64 * 64 * 3];
        let payload = Payload::Exr {
            width: 64,
            height: 64,
            rgb: &rgb,
        };
        let e = fill(&mut full, &payload, Path::new("out/image.exr")).unwrap_err();
        let message = format!("{e:#}");
        assert!(message.contains("no space left"), "{message}");
        assert!(message.contains("out/image.exr"), "{message}");
        assert!(!message.contains("ecod"), "{message}");
    }
}
