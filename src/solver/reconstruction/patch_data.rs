//! What the reconstruction shader reads about the receivers besides the lightmaps: each patch's
//! position, normal and reflectance, rasterised once into atlas textures
//! (`glsl/patchdata.frag`), and each polygon's plane, for the robust visibility test.

use super::draw_flat;
use crate::gl::{Framebuffer, Gl, GlContext, GlError, Mesh, Program, Texture, TextureFormat};
use crate::glsl;
use crate::scene::Scene;
use crate::solver::mesh::ATTRIBUTES;
use crate::solver::pass_names::INITIALISATION;

/// Each patch's geometry as atlas textures (RGBA32F): position + polygon ID + 1, normal, Kd.
pub(crate) struct PatchData {
    program: Program,
    pub(crate) position: Texture,
    normal: Texture,
    reflectance: Texture,
    fbo: Framebuffer,
}

impl PatchData {
    pub(crate) fn new(gl: &Gl, width: i32, height: i32) -> Result<Self, GlError> {
        let make = || Texture::new(gl, width, height, TextureFormat::Rgba32F, glow::NEAREST);
        let patches = PatchData {
            program: Program::new(
                gl,
                glsl!("lightmap.vert"),
                glsl!("patchdata.frag"),
                ATTRIBUTES,
                &[
                    (0, "PatchPosition"),
                    (1, "PatchNormal"),
                    (2, "PatchReflectance"),
                ],
            )?,
            position: make()?,
            normal: make()?,
            reflectance: make()?,
            fbo: Framebuffer::new(gl)?,
        };
        patches
            .fbo
            .attach_texture(glow::COLOR_ATTACHMENT0, &patches.position);
        patches
            .fbo
            .attach_texture(glow::COLOR_ATTACHMENT1, &patches.normal);
        patches
            .fbo
            .attach_texture(glow::COLOR_ATTACHMENT2, &patches.reflectance);
        patches.fbo.check_complete(INITIALISATION)?;
        Ok(patches)
    }

    /// Rasterise every patch of `mesh` (the scene in the atlas) into the textures.
    pub(crate) fn rasterise(&self, ctx: &GlContext, mesh: &Mesh) -> Result<(), GlError> {
        draw_flat(
            ctx,
            &self.fbo,
            &[
                glow::COLOR_ATTACHMENT0,
                glow::COLOR_ATTACHMENT1,
                glow::COLOR_ATTACHMENT2,
            ],
            self.position.width,
            self.position.height,
            true,
        );
        self.program.use_program();
        mesh.draw();
        ctx.check(INITIALISATION)
    }

    /// Bind position, normal and reflectance to texture units `position`, `normal`,
    /// `reflectance`.
    pub(crate) fn bind(&self, position: u32, normal: u32, reflectance: u32) {
        self.position.bind(position);
        self.normal.bind(normal);
        self.reflectance.bind(reflectance);
    }
}

/// Each polygon's plane (unit normal n, n·x of its points) as an RGBA32F texture, texel ID at
/// (ID % width, ID / width): the robust visibility test asks whether the polygon a pixel shows
/// lies between the shooter and the receiver.
pub(crate) struct PolygonPlanes {
    pub(crate) texture: Texture,
    /// World units a point must lie beyond a plane to count as behind it (`Scene::plane_slack`).
    pub(crate) slack: f32,
}

impl PolygonPlanes {
    pub(crate) fn new(ctx: &GlContext, scene: &Scene) -> Result<Self, GlError> {
        let n = scene.polygons.len().max(1);
        let largest = 1usize << (ctx.info.max_texture_size.max(1) as u32).ilog2();
        let width = n.next_power_of_two().min(largest);
        let height = n.div_ceil(width);
        let mut data = vec![0.0f32; width * height * 4];
        for (texel, p) in data.chunks_exact_mut(4).zip(&scene.polygons) {
            let plane = p.plane();
            texel.copy_from_slice(&[plane.normal.x, plane.normal.y, plane.normal.z, plane.offset]);
        }
        let texture = Texture::new(
            &ctx.gl,
            width as i32,
            height as i32,
            TextureFormat::Rgba32F,
            glow::NEAREST,
        )?;
        texture.upload_f32(&data);
        Ok(PolygonPlanes {
            texture,
            slack: scene.plane_slack(),
        })
    }
}
