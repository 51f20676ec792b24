//! What the display draws: the scene's triangles with their lightmap coordinates, polygon ID and
//! the range of their polygon's smooth edges, and the texture of those edges (`smooth.rs`,
//! `glsl/smooth.glsl`), which changes with the radiance atlas while the triangles stay.

use super::smooth::{Smoothing, EDGE_FLOATS};
use crate::gl::objects::Attribute;
use crate::gl::{Gl, GlError, Mesh, Texture, TextureFormat};
use crate::patches::PatchLayout;
use crate::scene::{triangulate, Scene};
use crate::solver::mesh::{LIGHTMAP_UV, POLYGON_ID, POSITION};
use glam::{Vec2, Vec3};

/// The smooth-edge range's attribute location (the others are the solver mesh's).
pub const SMOOTH_EDGE_RANGE: u32 = 6;

/// The display shaders' attributes, bound before linking.
pub const ATTRIBUTES: &[(u32, &str)] = &[
    (POSITION, "Position"),
    (LIGHTMAP_UV, "LightmapUV"),
    (POLYGON_ID, "PolygonId"),
    (SMOOTH_EDGE_RANGE, "SmoothEdgeRange"),
];

/// Floats per vertex: position 3, atlas UV 2, polygon ID 1, smooth edges (first, count) 2.
const FLOATS: usize = 8;
/// Smooth edges per row of the edge texture (four texels each).
const EDGES_PER_ROW: usize = 1024;

/// The scene as the display draws it, with the smooth edges it blends across.
pub struct DisplayMesh {
    mesh: Mesh,
    smoothing: Smoothing,
    /// [`Smoothing::edge_texels`] for the last atlas, four RGBA32F texels per edge.
    edges: Texture,
}

impl DisplayMesh {
    /// The triangles of every polygon of `scene` (as the solver's mesh triangulates them).
    pub fn new(
        gl: &Gl,
        scene: &Scene,
        layout: &PatchLayout,
        smoothing: Smoothing,
    ) -> Result<DisplayMesh, GlError> {
        let mut data = Vec::new();
        // The sky (`--sky`) lights the scene but is not drawn: the background shows there.
        for (i, p) in scene.own_polygons().iter().enumerate() {
            let (first, count) = smoothing.edge_range(i);
            for tri in triangulate(&p.vertices, p.normal) {
                for k in tri {
                    let v = p.vertices[k];
                    data.extend_from_slice(&v.to_array());
                    data.extend_from_slice(&layout.atlas_uv(i, v).to_array());
                    data.extend_from_slice(&[i as f32, first as f32, count as f32]);
                }
            }
        }
        Self::with_data(gl, &data, smoothing)
    }

    /// Triangles given as three corners each, with their texture coordinates, drawn without
    /// smooth edges: a mesh from elsewhere (a glTF file this program wrote, tests/gltf_export.rs)
    /// through the same pass.
    pub fn from_triangles(gl: &Gl, corners: &[Vec3], uvs: &[Vec2]) -> Result<DisplayMesh, GlError> {
        let mut data = Vec::with_capacity(corners.len() * FLOATS);
        for (v, uv) in corners.iter().zip(uvs) {
            data.extend_from_slice(&v.to_array());
            data.extend_from_slice(&uv.to_array());
            data.extend_from_slice(&[0.0, 0.0, 0.0]);
        }
        Self::with_data(gl, &data, Smoothing::none())
    }

    fn with_data(gl: &Gl, data: &[f32], smoothing: Smoothing) -> Result<DisplayMesh, GlError> {
        let a = |location, size, offset| Attribute {
            location,
            size,
            offset,
        };
        let mesh = Mesh::new(
            gl,
            data,
            FLOATS as i32,
            &[
                a(POSITION, 3, 0),
                a(LIGHTMAP_UV, 2, 3),
                a(POLYGON_ID, 1, 5),
                a(SMOOTH_EDGE_RANGE, 2, 6),
            ],
        )?;
        let n = smoothing.edge_count();
        let width = 4 * n.clamp(1, EDGES_PER_ROW);
        let height = n.div_ceil(EDGES_PER_ROW).max(1);
        let edges = Texture::new(
            gl,
            width as i32,
            height as i32,
            TextureFormat::Rgba32F,
            glow::NEAREST,
        )?;
        Ok(DisplayMesh {
            mesh,
            smoothing,
            edges,
        })
    }

    /// Evaluate the smooth edges on `atlas` (RGBA radiance, rows bottom to top, dilated: what the
    /// display samples) of `width` x `height` texels. Nothing to do without smooth edges.
    pub fn update(&mut self, atlas: &[f32], width: u32, height: u32) {
        if self.smoothing.is_empty() {
            return;
        }
        let mut texels = self.smoothing.edge_texels(atlas, width, height);
        let size = self.edges.width as usize * self.edges.height as usize * 4;
        debug_assert!(texels.len() <= size && texels.len().is_multiple_of(EDGE_FLOATS));
        texels.resize(size, 0.0);
        self.edges.upload_f32(&texels);
    }

    /// The scene's triangles as the display draws them.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The smooth edges, as a texture for `glsl/smooth.glsl`'s `SmoothEdges`.
    pub fn edges(&self) -> &Texture {
        &self.edges
    }

    /// The smoothing the edge texture was made for.
    pub fn smoothing(&self) -> &Smoothing {
        &self.smoothing
    }
}
