//! `radiosity solve --gltf FILE`: the solved scene as glTF 2.0, lit by its lightmap, so that any
//! conforming viewer shows the radiosity solution with no lights of its own.
//!
//! - **Geometry**: the polygons as solved (merged), triangulated as the display draws them, one
//!   primitive per material, each vertex with its atlas coordinates in `TEXCOORD_0` and, for
//!   engines that look for a lightmap in the second set, the same accessor as `TEXCOORD_1`.
//! - **Light**: every material is `KHR_materials_unlit` with the tone-mapped sRGB atlas as
//!   `baseColorTexture` (`image.png`'s tone mapping and `--exposure`), its smooth shading baked in
//!   (`bake.rs`) and its gutters dilated, sampled bilinearly without mipmaps (which would mix
//!   neighbouring lightmaps) and clamped. glTF's UV origin is the image's top left: `v` runs
//!   down, the atlas's GL rows up, so `v = 1 − v_atlas` and the image is written top row first.
//! - **Linear radiance**, for engines that want it: the same atlas as 32-bit floats (RGB, rows
//!   top to bottom, the texture's layout) in a buffer view that the root's `extras.radiosity`
//!   names (`linear_lightmap`), in the file itself so that it cannot be separated from it. A
//!   PNG cannot hold it, and glTF has no float image type.
//! - **Camera**: the one `image.png` was drawn from, as the scene's camera node.
//! - Materials keep their names, with their `Kd` and `Ke` in `extras`.
//!
//! `.glb` is one file; `.gltf` is FILE.gltf with FILE.bin and FILE.png beside it.

use super::output::{atlas_rgb_top_down, tone_map};
use super::Image;
use crate::patches::PatchLayout;
use crate::scene::{triangulate, Camera, Scene};
use anyhow::{bail, Context, Result};
use glam::{Mat4, Vec3};
use serde_json::{json, Value};
use std::borrow::Cow;

/// What the export needs of a solve.
pub struct Export<'a> {
    /// The scene as solved.
    pub scene: &'a Scene,
    /// Its patch layout: the atlas's texels and each polygon's lightmap coordinates.
    pub layout: &'a PatchLayout,
    /// The radiance atlas as displayed: RGBA, rows bottom to top, dilated, smooth shading baked
    /// in ([`super::bake::bake_smoothing`]).
    pub atlas: &'a [f32],
    /// The camera of `image.png`.
    pub camera: Camera,
    /// Its picture's width over height.
    pub aspect: f32,
    /// The `--exposure` of `image.png`, applied to the sRGB texture.
    pub exposure: f32,
}

/// The container a file name asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Container {
    /// `.glb`: one binary file.
    Glb,
    /// `.gltf`: JSON, with a `.bin` and a `.png` beside it.
    Gltf,
}

/// `--gltf`'s value: a plain file name ending in `.glb` or `.gltf`, written into the output
/// folder with the other outputs (so under the same whole-or-nothing rule), whose companion files
/// are not names of that set.
pub fn file_name(s: &str) -> Result<String, String> {
    let (stem, container) = split(s)
        .ok_or_else(|| format!("expected a file name ending in .glb or .gltf, got '{s}'"))?;
    if s.contains(['/', '\\']) || s.starts_with('.') || stem.is_empty() {
        return Err(format!(
            "'{s}' must be a plain file name (it is written into the output directory, --out, \
             with the other outputs)"
        ));
    }
    for name in companions(stem, container).iter().skip(1) {
        if super::output_set::is_set_member(name) {
            return Err(format!(
                "'{s}' would write {name}, a name of the other outputs"
            ));
        }
    }
    Ok(s.to_string())
}

fn split(s: &str) -> Option<(&str, Container)> {
    let (stem, ext) = s.rsplit_once('.')?;
    match ext.to_ascii_lowercase().as_str() {
        "glb" => Some((stem, Container::Glb)),
        "gltf" => Some((stem, Container::Gltf)),
        _ => None,
    }
}

/// The files a name writes: itself, then for `.gltf` its `.bin` and `.png`.
fn companions(stem: &str, container: Container) -> Vec<String> {
    match container {
        Container::Glb => vec![format!("{stem}.glb")],
        Container::Gltf => vec![
            format!("{stem}.gltf"),
            format!("{stem}.bin"),
            format!("{stem}.png"),
        ],
    }
}

/// The files of the export named `name` (checked by [`file_name`]): (file name, bytes), the named
/// file first.
pub fn encode(export: &Export, name: &str) -> Result<Vec<(String, Vec<u8>)>> {
    let (stem, container) = split(name).context("not a .glb or .gltf name")?;
    let names = companions(stem, container);
    let layout = export.layout;
    let (w, h) = (layout.atlas_width, layout.atlas_height);
    if export.atlas.len() != 4 * w as usize * h as usize {
        bail!("the atlas does not match its layout");
    }
    let linear = atlas_rgb_top_down(w, h, export.atlas);
    let image = Image {
        width: w,
        height: h,
        rgb: linear,
    };
    let png = encode_png(w, h, &tone_map(&image, export.exposure))?;
    let linear = image.rgb;
    let mut bin = Bin::default();
    let mesh = geometry(export, &mut bin);
    let image = match container {
        Container::Glb => json!({"bufferView": bin.push(&png, None), "mimeType": "image/png"}),
        Container::Gltf => json!({"uri": uri(&names[2])}),
    };
    let floats: Vec<u8> = linear.iter().flat_map(|v| v.to_le_bytes()).collect();
    let linear_view = bin.push(&floats, None);
    let mut root = document(export, mesh, image, linear_view, w, h);
    let buffer = match container {
        Container::Glb => json!({"byteLength": bin.bytes.len()}),
        Container::Gltf => json!({"byteLength": bin.bytes.len(), "uri": uri(&names[1])}),
    };
    root["buffers"] = json!([buffer]);
    root["bufferViews"] = Value::Array(std::mem::take(&mut bin.views));
    // Through gltf-json's types: what is written is what the `gltf` crate reads back.
    let root: gltf::json::Root =
        serde_json::from_value(root).context("the glTF document does not fit gltf-json")?;
    let json_bytes = serde_json::to_vec(&root)?;
    Ok(match container {
        Container::Glb => {
            let glb = gltf::binary::Glb {
                header: gltf::binary::Header {
                    magic: *b"glTF",
                    version: 2,
                    length: 0, // computed by to_vec
                },
                json: Cow::Owned(json_bytes),
                bin: Some(Cow::Owned(bin.bytes)),
            };
            vec![(
                names[0].clone(),
                glb.to_vec().context("GLB encoding failed")?,
            )]
        }
        Container::Gltf => {
            let mut names = names.into_iter();
            let mut next = || names.next().unwrap_or_default();
            vec![(next(), json_bytes), (next(), bin.bytes), (next(), png)]
        }
    })
}

/// The binary buffer and its views, each 4-byte aligned (as accessors of floats and ints must be).
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
}

impl Bin {
    /// Append `data` as a new buffer view (with `target`: 34962 vertices, 34963 indices); its
    /// index.
    fn push(&mut self, data: &[u8], target: Option<u32>) -> usize {
        self.bytes.resize(self.bytes.len().next_multiple_of(4), 0);
        let mut view =
            json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bytes.extend_from_slice(data);
        self.views.push(view);
        self.views.len() - 1
    }
}

/// The mesh: a primitive per material with polygons, its accessors and views in `bin`.
/// Returns (accessors, primitives).
fn geometry(export: &Export, bin: &mut Bin) -> (Vec<Value>, Vec<Value>) {
    let (scene, layout) = (export.scene, export.layout);
    let (mut positions, mut uvs, mut indices) =
        (Vec::<u8>::new(), Vec::<u8>::new(), Vec::<u8>::new());
    // Per material: (first vertex, vertex count, first index, index count, min, max).
    let mut ranges = Vec::new();
    for m in 0..scene.materials.len() {
        let (first_vertex, first_index) = (positions.len() / 12, indices.len() / 4);
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for (i, p) in scene
            .polygons
            .iter()
            .enumerate()
            .filter(|(_, p)| p.material == m)
        {
            let base = (positions.len() / 12 - first_vertex) as u32;
            for &v in &p.vertices {
                let uv = layout.atlas_uv(i, v);
                positions.extend(v.to_array().iter().flat_map(|c| c.to_le_bytes()));
                uvs.extend([uv.x, 1.0 - uv.y].iter().flat_map(|c| c.to_le_bytes()));
                (lo, hi) = (lo.min(v), hi.max(v));
            }
            for t in triangulate(&p.vertices, p.normal) {
                indices.extend(t.iter().flat_map(|&k| (base + k as u32).to_le_bytes()));
            }
        }
        let count = positions.len() / 12 - first_vertex;
        if count > 0 {
            let index_count = indices.len() / 4 - first_index;
            ranges.push((m, first_vertex, count, first_index, index_count, lo, hi));
        }
    }
    // Each material's primitive has its accessors in these shared views: the stride is then
    // required.
    let position_view = bin.push(&positions, Some(34962));
    bin.views[position_view]["byteStride"] = json!(12);
    let uv_view = bin.push(&uvs, Some(34962));
    bin.views[uv_view]["byteStride"] = json!(8);
    let index_view = bin.push(&indices, Some(34963));
    let (mut accessors, mut primitives) = (Vec::new(), Vec::new());
    for (m, first_vertex, count, first_index, index_count, lo, hi) in ranges {
        let at = accessors.len();
        accessors.push(json!({
            "bufferView": position_view, "byteOffset": 12 * first_vertex, "componentType": 5126,
            "count": count, "type": "VEC3", "min": lo.to_array(), "max": hi.to_array()
        }));
        accessors.push(json!({
            "bufferView": uv_view, "byteOffset": 8 * first_vertex, "componentType": 5126,
            "count": count, "type": "VEC2"
        }));
        accessors.push(json!({
            "bufferView": index_view, "byteOffset": 4 * first_index, "componentType": 5125,
            "count": index_count, "type": "SCALAR"
        }));
        primitives.push(json!({
            "attributes": {"POSITION": at, "TEXCOORD_0": at + 1, "TEXCOORD_1": at + 1},
            "indices": at + 2,
            "material": m,
            "mode": 4
        }));
    }
    (accessors, primitives)
}

/// The JSON document without its buffers.
fn document(
    export: &Export,
    (accessors, primitives): (Vec<Value>, Vec<Value>),
    image: Value,
    linear_view: usize,
    w: u32,
    h: u32,
) -> Value {
    let scene = export.scene;
    let materials: Vec<Value> = scene
        .materials
        .iter()
        .map(|m| {
            json!({
                "name": m.name,
                "pbrMetallicRoughness": {
                    "baseColorTexture": {"index": 0, "texCoord": 0},
                    "metallicFactor": 0.0,
                    "roughnessFactor": 1.0
                },
                "extensions": {"KHR_materials_unlit": {}},
                "extras": {"kd": m.kd.to_array(), "ke": m.ke.to_array()}
            })
        })
        .collect();
    let c = &export.camera;
    // The camera node's transform: the inverse of the view (glTF cameras look down −Z, +Y up).
    let (_, rotation, translation) = Mat4::look_at_rh(c.eye, c.target, c.up)
        .inverse()
        .to_scale_rotation_translation();
    let (lo, hi) = scene.bounds();
    let reach = (hi - lo).length() + (c.eye - 0.5 * (lo + hi)).length();
    json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("gpu-radiosity ", env!("CARGO_PKG_VERSION"), " (radiosity solve --gltf)")
        },
        "extensionsUsed": ["KHR_materials_unlit"],
        "scene": 0,
        "scenes": [{"name": scene.name, "nodes": [0, 1]}],
        "nodes": [
            {"name": scene.name, "mesh": 0},
            {"name": "camera", "camera": 0, "translation": translation.to_array(),
             "rotation": rotation.normalize().to_array()}
        ],
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": c.fov_y.to_radians(), "aspectRatio": export.aspect,
            "znear": reach * 1e-4, "zfar": reach * 2.0
        }}],
        "meshes": [{"name": scene.name, "primitives": primitives}],
        "materials": materials,
        "accessors": accessors,
        "textures": [{"sampler": 0, "source": 0, "name": "lightmap"}],
        // Bilinear, no mipmaps (they would blend neighbouring lightmaps), clamped.
        "samplers": [{"magFilter": 9729, "minFilter": 9729, "wrapS": 33071, "wrapT": 33071}],
        "images": [image],
        "extras": {"radiosity": {
            "linear_lightmap": {
                "bufferView": linear_view,
                "width": w,
                "height": h,
                "format": "RGB 32-bit float, little-endian, rows top to bottom (the texture's layout)",
                "unit": "radiance, in the units of the scene's emitted radiance (Ke)"
            },
            "tone_mapping": "baseColorTexture = sRGB(clamp(exposure × linear_lightmap, 0, 1))",
            "exposure": export.exposure
        }}
    })
}

fn encode_png(w: u32, h: u32, rgb: &[u8]) -> Result<Vec<u8>> {
    let img = image::RgbImage::from_raw(w, h, rgb.to_vec()).context("atlas size")?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .context("PNG encoder failed")?;
    Ok(out.into_inner())
}

/// A file name as a relative URI: every byte but RFC 3986's unreserved ones percent-encoded.
fn uri(name: &str) -> String {
    name.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'~' => {
                (b as char).to_string()
            }
            _ => format!("%{b:02X}"),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_plain_and_do_not_clash_with_the_outputs() {
        assert_eq!(file_name("room.glb").unwrap(), "room.glb");
        assert!(file_name("Room.GLTF").is_ok());
        for bad in [
            "room.obj",
            "room",
            "../room.glb",
            "a/room.glb",
            ".glb",
            ".x.glb",
            "image.gltf",
        ] {
            assert!(file_name(bad).is_err(), "{bad}");
        }
        assert_eq!(uri("my room.bin"), "my%20room.bin");
    }
}
