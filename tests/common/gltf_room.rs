//! A small glTF scene written by the tests themselves (tests/gltf.rs, tests/gltf_export.rs): a
//! closed room (a unit cube, faces inward) scaled by 2 in a node under a node translated by
//! (10, 0, 0), with a lamp under the ceiling (emissive, with KHR_materials_emissive_strength), a
//! twelve-sided column (a curved surface the display smooths) and a camera. The walls' base colour
//! is 0.7 times a 2x1 texture of one white and one black texel (mean 0.5): Kd 0.35.

use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The JSON document (without `buffers`) and its binary buffer.
pub struct Room {
    pub json: Value,
    pub bin: Vec<u8>,
}

#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn view(&mut self, data: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": data.len()}));
        self.bin.extend_from_slice(data);
        self.views.len() - 1
    }

    fn positions(&mut self, v: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in v {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        self.accessors.push(
            json!({"bufferView": view, "componentType": 5126, "count": v.len(),
            "type": "VEC3", "min": lo, "max": hi}),
        );
        self.accessors.len() - 1
    }

    fn indices(&mut self, i: &[u16]) -> usize {
        let bytes: Vec<u8> = i.iter().flat_map(|c| c.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors.push(
            json!({"bufferView": view, "componentType": 5123, "count": i.len(), "type": "SCALAR"}),
        );
        self.accessors.len() - 1
    }

    /// A primitive of quads or polygons (fans), each turned to face along its wanted normal.
    fn primitive(&mut self, faces: &[(Vec<[f32; 3]>, [f32; 3])], material: usize) -> Value {
        let (mut v, mut idx) = (Vec::new(), Vec::new());
        for (corners, normal) in faces {
            let mut c = corners.clone();
            if dot(cross(sub(c[1], c[0]), sub(c[2], c[0])), *normal) < 0.0 {
                c.reverse();
            }
            let base = v.len() as u16;
            for k in 1..c.len() as u16 - 1 {
                idx.extend([base, base + k, base + k + 1]);
            }
            v.extend(c);
        }
        let (p, i) = (self.positions(&v), self.indices(&idx));
        json!({"attributes": {"POSITION": p}, "indices": i, "material": material})
    }
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Twelve sides of the column and its sides' count.
pub const COLUMN_SIDES: usize = 12;

pub fn room() -> Room {
    let mut b = Builder::default();
    // The cube's six faces, facing in.
    let mut walls = Vec::new();
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
                .map(|(a, c)| {
                    let mut p = [0.0; 3];
                    (p[axis], p[u], p[w]) = (side, a, c);
                    p
                })
                .to_vec();
            let mut n = [0.0; 3];
            n[axis] = 1.0 - 2.0 * side;
            walls.push((corners, n));
        }
    }
    let lamp = vec![(
        vec![
            [0.4, 0.95, 0.4],
            [0.6, 0.95, 0.4],
            [0.6, 0.95, 0.6],
            [0.4, 0.95, 0.6],
        ],
        [0.0, -1.0, 0.0],
    )];
    let mut column = Vec::new();
    let (cx, cz, r, top) = (0.3f32, 0.3f32, 0.1f32, 0.5f32);
    let at = |k: usize| {
        let a = k as f32 * std::f32::consts::TAU / COLUMN_SIDES as f32;
        (cx + r * a.cos(), cz + r * a.sin())
    };
    for k in 0..COLUMN_SIDES {
        let ((x0, z0), (x1, z1)) = (at(k), at(k + 1));
        let mid = (k as f32 + 0.5) * std::f32::consts::TAU / COLUMN_SIDES as f32;
        column.push((
            vec![[x0, 0.0, z0], [x1, 0.0, z1], [x1, top, z1], [x0, top, z0]],
            [mid.cos(), 0.0, mid.sin()],
        ));
    }
    column.push((
        (0..COLUMN_SIDES).map(|k| [at(k).0, top, at(k).1]).collect(),
        [0.0, 1.0, 0.0],
    ));
    let room_mesh = b.primitive(&walls, 0);
    let lamp_mesh = b.primitive(&lamp, 1);
    let column_mesh = b.primitive(&column, 2);
    let png = {
        let img = image::RgbImage::from_raw(2, 1, vec![255, 255, 255, 0, 0, 0]).unwrap();
        let mut out = std::io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png).unwrap();
        out.into_inner()
    };
    let png_view = b.view(&png);
    let json = json!({
        "asset": {"version": "2.0", "generator": "tests/common/gltf_room.rs"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "house", "translation": [10.0, 0.0, 0.0], "children": [1, 4]},
            {"name": "room", "mesh": 0, "scale": [2.0, 2.0, 2.0], "children": [2, 3]},
            {"name": "lamp", "mesh": 1},
            {"name": "column", "mesh": 2},
            {"name": "eye", "camera": 0, "translation": [1.0, 1.0, 1.9]}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.2, "znear": 0.01}}],
        "meshes": [
            {"name": "room", "primitives": [room_mesh]},
            {"name": "lamp", "primitives": [lamp_mesh]},
            {"name": "column", "primitives": [column_mesh]}
        ],
        "materials": [
            {"name": "wall", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0],
                "baseColorTexture": {"index": 0}}},
            {"name": "lamp", "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0]},
                "emissiveFactor": [1.0, 0.9, 0.8],
                "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 10.0}}},
            {"name": "column", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.2, 1.0]}}
        ],
        "textures": [{"source": 0}],
        "images": [{"bufferView": png_view, "mimeType": "image/png"}],
        "accessors": b.accessors,
        "bufferViews": b.views,
    });
    Room { json, bin: b.bin }
}

impl Room {
    /// As a `.glb`: the JSON chunk and the binary chunk.
    pub fn glb(&self) -> Vec<u8> {
        let mut json = self.json.clone();
        json["buffers"] = json!([{"byteLength": self.bin.len()}]);
        glb_of(&serde_json::to_vec(&json).unwrap(), &self.bin)
    }

    pub fn write_glb(&self, dir: &Path, name: &str) -> PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, self.glb()).unwrap();
        path
    }

    /// As a `.gltf` with its buffer in `NAME.bin` beside it.
    pub fn write_gltf(&self, dir: &Path, stem: &str) -> PathBuf {
        let mut json = self.json.clone();
        json["buffers"] = json!([{"byteLength": self.bin.len(), "uri": format!("{stem}.bin")}]);
        std::fs::write(dir.join(format!("{stem}.bin")), &self.bin).unwrap();
        let path = dir.join(format!("{stem}.gltf"));
        std::fs::write(&path, serde_json::to_vec_pretty(&json).unwrap()).unwrap();
        path
    }
}

/// A GLB container of `json` and `bin`, chunks padded as the spec says.
pub fn glb_of(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut j = json.to_vec();
    j.resize(j.len().next_multiple_of(4), b' ');
    let mut b = bin.to_vec();
    b.resize(b.len().next_multiple_of(4), 0);
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}
