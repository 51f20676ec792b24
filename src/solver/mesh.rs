//! The scene as one interleaved vertex buffer, built once: every pass draws all polygons with a
//! single draw call (the paper draws polygon by polygon; same fragments, fewer calls).

use crate::gl::objects::Attribute;
use crate::gl::{GlError, Mesh};
use crate::patches::PatchLayout;
use crate::scene::{triangulate, Scene};
use glam::Vec3;

/// Attribute locations, bound before linking (paper 2.2, step 9).
pub const POSITION: u32 = 0;
/// See `POSITION`: the polygon's normal.
pub const NORMAL: u32 = 1;
/// See `POSITION`: the texel in the atlas.
pub const LIGHTMAP_UV: u32 = 2;
/// See `POSITION`: the polygon's ID (the item buffer's colour).
pub const POLYGON_ID: u32 = 3;
/// See `POSITION`: the material's Kd.
pub const REFLECTANCE: u32 = 4;
/// See `POSITION`: the material's Ke.
pub const EMISSION: u32 = 5;

/// Each location with the shaders' attribute name, for `glBindAttribLocation`.
pub const ATTRIBUTES: &[(u32, &str)] = &[
    (POSITION, "Position"),
    (NORMAL, "Normal"),
    (LIGHTMAP_UV, "LightmapUV"),
    (POLYGON_ID, "PolygonId"),
    (REFLECTANCE, "Reflectance"),
    (EMISSION, "Emission"),
];

const FLOATS: i32 = 15;
/// Where in a vertex its polygon ID is (floats from the start).
const ID_OFFSET: i32 = 8;

/// The vertex data: per triangle corner position, normal, atlas UV, polygon ID, Kd, Ke.
pub fn vertex_data(scene: &Scene, layout: &PatchLayout) -> Vec<f32> {
    let mut data = Vec::new();
    for (i, p) in scene.polygons.iter().enumerate() {
        push_polygon(&mut data, scene, layout, i, &p.vertices);
    }
    data
}

/// Append polygon `i`'s attributes on the triangles of `outline` (its own vertices, or its
/// plate's: `Plates::vertex_data`) to `data`.
pub fn push_polygon(
    data: &mut Vec<f32>,
    scene: &Scene,
    layout: &PatchLayout,
    i: usize,
    outline: &[Vec3],
) {
    let normal = scene.polygons[i].normal;
    for tri in triangulate(outline, normal) {
        for &k in &tri {
            push_vertex(data, scene, layout, i, outline[k]);
        }
    }
}

/// One vertex of polygon `i` at `v`: position, normal, atlas coordinates, ID, Kd, Ke.
fn push_vertex(data: &mut Vec<f32>, scene: &Scene, layout: &PatchLayout, i: usize, v: Vec3) {
    let p = &scene.polygons[i];
    let m = scene.material(p);
    data.extend_from_slice(&v.to_array());
    data.extend_from_slice(&p.normal.to_array());
    data.extend_from_slice(&layout.atlas_uv(i, v).to_array());
    data.push(i as f32);
    data.extend_from_slice(&m.kd.to_array());
    data.extend_from_slice(&m.ke.to_array());
}

/// The scene for the visibility pass, with every triangle cut into a grid of sub-triangles
/// whose edges are at most `max_edge` long. The hemispherical projection maps straight edges to
/// curves; the rasterizer draws straight lines between projected vertices, so large polygons
/// must be cut small for the item buffer to be right (the paper's scenes are finely meshed
/// already; the Cornell box's walls are single quads).
pub fn tessellated_data(scene: &Scene, layout: &PatchLayout, max_edge: f32) -> Vec<f32> {
    let mut data = Vec::new();
    for (i, p) in scene.polygons.iter().enumerate() {
        for tri in triangulate(&p.vertices, p.normal) {
            let [a, b, c] = tri.map(|k| p.vertices[k]);
            let longest = (b - a).length().max((c - b).length()).max((a - c).length());
            let n = ((longest / max_edge).ceil() as usize).clamp(1, 256);
            // Barycentric grid: point (r, s) = a + (b - a) r/n + (c - a) s/n.
            let at = |r: usize, s: usize| {
                a + (b - a) * (r as f32 / n as f32) + (c - a) * (s as f32 / n as f32)
            };
            let mut push = |v: Vec3| push_vertex(&mut data, scene, layout, i, v);
            for r in 0..n {
                for s in 0..n - r {
                    push(at(r, s));
                    push(at(r + 1, s));
                    push(at(r, s + 1));
                    if r + s + 2 <= n {
                        push(at(r + 1, s));
                        push(at(r + 1, s + 1));
                        push(at(r, s + 1));
                    }
                }
            }
        }
    }
    data
}

/// The scene's vertex buffer for the visibility pass, each polygon's corners stored once, and
/// its triangles as corner indices (polygon `i`: `triangles[ranges[i].0 .. ranges[i].0 +
/// ranges[i].1]`), so a pass can draw only the polygons it needs. Shared corners: llvmpipe
/// transforms each index of a draw once, a third fewer vertices for a quad than three per
/// triangle.
pub struct SceneMesh {
    /// The vertices (shared corners), uploaded.
    pub mesh: Mesh,
    /// Every polygon's triangles as corner indices, polygon after polygon.
    pub triangles: Vec<u32>,
    /// Polygon `i`'s triangles: (first index, index count) in `triangles`.
    pub ranges: Vec<(u32, u32)>,
}

/// Upload vertex data made by [`vertex_data`], `Plates::vertex_data` or [`tessellated_data`] (each
/// polygon's triangles one after another) for `polygons` polygons, merging each polygon's equal
/// corners.
pub fn upload_scene(
    gl: &crate::gl::Gl,
    data: &[f32],
    polygons: usize,
) -> Result<SceneMesh, GlError> {
    let mut ranges = vec![(0u32, 0u32); polygons];
    let mut corners = Vec::with_capacity(data.len());
    let mut triangles = Vec::with_capacity(data.len() / FLOATS as usize);
    // The current polygon's corners so far, by their exact bits.
    let mut seen = std::collections::HashMap::new();
    let mut current = None;
    for vertex in data.chunks_exact(FLOATS as usize) {
        let polygon = vertex[ID_OFFSET as usize] as usize;
        if current != Some(polygon) {
            seen.clear();
            current = Some(polygon);
        }
        let range = &mut ranges[polygon];
        if range.1 == 0 {
            range.0 = triangles.len() as u32;
        }
        range.1 += 1;
        let bits: [u32; FLOATS as usize] = std::array::from_fn(|i| vertex[i].to_bits());
        let index = *seen.entry(bits).or_insert_with(|| {
            corners.extend_from_slice(vertex);
            (corners.len() / FLOATS as usize - 1) as u32
        });
        triangles.push(index);
    }
    Ok(SceneMesh {
        mesh: upload(gl, &corners)?,
        triangles,
        ranges,
    })
}

/// Upload vertex data made by [`vertex_data`] or [`tessellated_data`].
pub fn upload(gl: &crate::gl::Gl, data: &[f32]) -> Result<Mesh, GlError> {
    let a = |location, size, offset| Attribute {
        location,
        size,
        offset,
    };
    Mesh::new(
        gl,
        data,
        FLOATS,
        &[
            a(POSITION, 3, 0),
            a(NORMAL, 3, 3),
            a(LIGHTMAP_UV, 2, 6),
            a(POLYGON_ID, 1, ID_OFFSET),
            a(REFLECTANCE, 3, 9),
            a(EMISSION, 3, 12),
        ],
    )
}
