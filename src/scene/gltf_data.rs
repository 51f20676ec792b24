//! The bytes behind a glTF file, read by this program rather than by the `gltf` crate's importer:
//! buffers and images only from the GLB's binary chunk, `data:` URIs or files inside the scene's
//! folder (the rule `mtllib` follows), every byte range checked before it is read, so that a file
//! that lies about its sizes gets a message, not a panic or an allocation of what it claims.

use super::files::{confined_file, read_regular, shown, MAX_OBJ_BYTES};
use gltf::accessor::{DataType, Dimensions};
use gltf::Accessor;
use std::path::Path;

/// Largest texture read for its mean colour, texels per side.
const MAX_TEXTURE_SIDE: u32 = 16384;

/// Every buffer of a glTF document, in its order.
pub(super) struct Buffers(Vec<Vec<u8>>);

impl Buffers {
    /// Read the buffers of `doc`: the GLB chunk `blob`, `data:` URIs, or files beside `path`
    /// (together at most [`MAX_OBJ_BYTES`]). Each must hold at least the bytes it declares.
    pub fn read(
        doc: &gltf::Document,
        blob: Option<Vec<u8>>,
        dir: &Path,
    ) -> Result<Buffers, String> {
        let mut blob = blob;
        let mut list = Vec::new();
        let mut total = 0u64;
        for b in doc.buffers() {
            let what = format!("buffer {}", b.index());
            let data = match b.source() {
                gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                    format!("{what} is the GLB binary chunk, which the file does not have")
                })?,
                gltf::buffer::Source::Uri(uri) => {
                    read_uri(uri, dir, MAX_OBJ_BYTES - total).map_err(|e| format!("{what}: {e}"))?
                }
            };
            if data.len() < b.length() {
                return Err(format!(
                    "{what} is truncated: it declares {} bytes and holds {}",
                    b.length(),
                    data.len()
                ));
            }
            total += data.len() as u64;
            list.push(data);
        }
        Ok(Buffers(list))
    }

    /// The bytes of a buffer view, checked to lie inside its buffer.
    pub fn view(&self, view: &gltf::buffer::View) -> Result<&[u8], String> {
        let data = &self.0[view.buffer().index()];
        let (start, len) = (view.offset() as u64, view.length() as u64);
        if start + len > data.len() as u64 {
            return Err(format!(
                "bufferView {} (bytes {start} to {}) reaches past the end of buffer {} ({} bytes)",
                view.index(),
                start + len,
                view.buffer().index(),
                data.len()
            ));
        }
        Ok(&data[start as usize..(start + len) as usize])
    }

    /// Each element of `accessor` as `N` components of `ty` (little-endian), after checking that
    /// the last one ends inside its view.
    fn elements<const N: usize>(
        &self,
        accessor: &Accessor,
        expected: Dimensions,
        types: &[DataType],
    ) -> Result<Vec<[u32; N]>, String> {
        let what = format!("accessor {}", accessor.index());
        if accessor.sparse().is_some() {
            return Err(format!("{what} is sparse, which the loader does not read"));
        }
        if accessor.dimensions() != expected || !types.contains(&accessor.data_type()) {
            return Err(format!(
                "{what} is {:?} of {:?}, expected {expected:?} of {types:?}",
                accessor.dimensions(),
                accessor.data_type()
            ));
        }
        let view = accessor
            .view()
            .ok_or_else(|| format!("{what} has no bufferView"))?;
        let bytes = self.view(&view)?;
        let component = accessor.data_type().size();
        let size = component * N;
        let stride = view.stride().unwrap_or(size);
        let count = accessor.count() as u64;
        if stride < size {
            return Err(format!(
                "{what}: bufferView {} has a stride of {stride} bytes, less than an element \
                 ({size} bytes)",
                view.index()
            ));
        }
        let end = if count == 0 {
            0
        } else {
            accessor.offset() as u64 + stride as u64 * (count - 1) + size as u64
        };
        if end > bytes.len() as u64 {
            return Err(format!(
                "{what}: {count} elements from byte {} need {end} bytes of bufferView {}, which \
                 has {}",
                accessor.offset(),
                view.index(),
                bytes.len()
            ));
        }
        let read = |at: usize| -> u32 {
            match component {
                1 => bytes[at] as u32,
                2 => u16::from_le_bytes([bytes[at], bytes[at + 1]]) as u32,
                _ => u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]),
            }
        };
        Ok((0..count as usize)
            .map(|i| {
                let at = accessor.offset() + i * stride;
                std::array::from_fn(|c| read(at + c * component))
            })
            .collect())
    }

    /// A `POSITION` accessor: three floats per vertex.
    pub fn positions(&self, accessor: &Accessor) -> Result<Vec<[f32; 3]>, String> {
        let raw = self.elements::<3>(accessor, Dimensions::Vec3, &[DataType::F32])?;
        Ok(raw.into_iter().map(|v| v.map(f32::from_bits)).collect())
    }

    /// An index accessor: unsigned bytes, shorts or ints.
    pub fn indices(&self, accessor: &Accessor) -> Result<Vec<u32>, String> {
        let types = [DataType::U8, DataType::U16, DataType::U32];
        let raw = self.elements::<1>(accessor, Dimensions::Scalar, &types)?;
        Ok(raw.into_iter().map(|[i]| i).collect())
    }

    /// The mean linear RGB of an image (sRGB-decoded texels, as a viewer samples a base colour
    /// or emissive texture), alpha ignored.
    pub fn image_mean(&self, image: &gltf::Image, dir: &Path) -> Result<[f32; 3], String> {
        let what = format!("image {}", image.index());
        let bytes = match image.source() {
            gltf::image::Source::View { view, .. } => self.view(&view)?.to_vec(),
            gltf::image::Source::Uri { uri, .. } => {
                read_uri(uri, dir, MAX_OBJ_BYTES).map_err(|e| format!("{what}: {e}"))?
            }
        };
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| format!("{what}: {e}"))?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_TEXTURE_SIDE);
        limits.max_image_height = Some(MAX_TEXTURE_SIDE);
        limits.max_alloc = Some(1 << 30);
        reader.limits(limits);
        let decoded = reader
            .decode()
            .map_err(|e| format!("{what} cannot be decoded: {e}"))?
            .into_rgb32f();
        let n = (decoded.width() as f64 * decoded.height() as f64).max(1.0);
        let mut sum = [0f64; 3];
        for px in decoded.pixels() {
            for (s, &v) in sum.iter_mut().zip(&px.0) {
                *s += srgb_decode(v) as f64;
            }
        }
        Ok(sum.map(|s| (s / n) as f32))
    }
}

/// The sRGB transfer curve inverted: an 8-bit texel's linear value.
fn srgb_decode(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The bytes a URI names: a base64 `data:` URI, or a relative reference to a file inside `dir`
/// (percent-decoded; absolute paths, other schemes and `..` that leaves the folder refused).
fn read_uri(uri: &str, dir: &Path, limit: u64) -> Result<Vec<u8>, String> {
    let quoted = shown(&uri.chars().take(80).collect::<String>());
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or_else(|| format!("the data URI `{quoted}` is not base64"))?;
        if data.len() as u64 / 4 * 3 > limit {
            return Err(format!("the data URI is larger than {} MiB", limit >> 20));
        }
        return base64(data).ok_or_else(|| format!("the data URI `{quoted}` is not valid base64"));
    }
    let name = percent_decode(uri).ok_or_else(|| format!("`{quoted}` is not a valid URI"))?;
    let scheme = name
        .split_once(':')
        .is_some_and(|(s, _)| !s.is_empty() && !s.contains('/'));
    let up = Path::new(&name)
        .components()
        .any(|c| c == std::path::Component::ParentDir);
    if scheme || up || name.starts_with('/') || name.starts_with('\\') {
        return Err(format!(
            "`{quoted}` is not a file name relative to the scene's folder (absolute paths, `..` and \
             URLs are refused)"
        ));
    }
    let file = dir.join(&name);
    confined_file(dir, &file).map_err(|e| format!("`{quoted}`: {e}"))?;
    read_regular(&file, limit).map_err(|e| format!("cannot read `{quoted}`: {e}"))
}

/// `%XX` escapes decoded; `None` for a bad escape or bytes that are not UTF-8.
fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Standard base64 (padding optional, no whitespace), `None` when malformed.
fn base64(s: &str) -> Option<Vec<u8>> {
    let s = s.trim_end_matches('=');
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 3);
    for chunk in s.as_bytes().chunks(4) {
        if chunk.len() == 1 {
            return None;
        }
        let mut n = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            n |= value(c)? << (18 - 6 * k);
        }
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_decode_and_stay_in_the_folder() {
        assert_eq!(base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64("aGVsbG8").unwrap(), b"hello");
        assert_eq!(base64("AAEC").unwrap(), [0, 1, 2]);
        assert!(base64("a").is_none() && base64("a*bc").is_none());
        assert_eq!(percent_decode("my%20scene.bin").unwrap(), "my scene.bin");
        assert!(percent_decode("bad%2").is_none());
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join("a b.bin"), [7u8; 4]).unwrap();
        assert_eq!(read_uri("a%20b.bin", d.path(), 100).unwrap(), [7u8; 4]);
        assert_eq!(
            read_uri("data:application/octet-stream;base64,AAEC", d.path(), 100).unwrap(),
            [0, 1, 2]
        );
        for bad in [
            "/etc/passwd",
            "../x.bin",
            "file:///etc/passwd",
            "http://example.com/x.bin",
        ] {
            let e = read_uri(bad, d.path(), 100).unwrap_err();
            assert!(e.contains("refused") || e.contains("outside"), "{bad}: {e}");
        }
        assert!(read_uri("a%20b.bin", d.path(), 2)
            .unwrap_err()
            .contains("limit"));
    }
}
