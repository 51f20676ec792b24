//! The display pass: rasterise the scene from the camera into a float framebuffer, sampling the
//! (dilated) radiance atlas bilinearly, and read the linear radiance image back.

use crate::gl::{
    Framebuffer, GlContext, GlError, Mesh, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::glsl;
use crate::scene::{Camera, Scene};
use crate::solver::mesh::ATTRIBUTES;
use glow::HasContext;

pub const NAME: &str = "display";

/// A linear RGB radiance image, row 0 at the top.
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<f32>,
}

/// Draw `mesh` from `camera` with `atlas` (RGBA radiance, rows bottom to top, already dilated).
pub fn render(
    ctx: &GlContext,
    scene: &Scene,
    mesh: &Mesh,
    atlas: &[f32],
    atlas_size: (u32, u32),
    camera: &Camera,
    (width, height): (u32, u32),
) -> Result<Image, GlError> {
    let gl = &ctx.gl;
    let (w, h) = (width as i32, height as i32);
    let program = Program::new(
        gl,
        glsl!("display.vert"),
        glsl!("display.frag"),
        ATTRIBUTES,
        &[(0, "Color")],
    )?;
    let lightmap = Texture::new(
        gl,
        atlas_size.0 as i32,
        atlas_size.1 as i32,
        TextureFormat::Rgba32F,
        glow::LINEAR,
    )?;
    lightmap.upload_f32(atlas);
    let color = Renderbuffer::new(gl, glow::RGBA32F, w, h)?;
    let depth = Renderbuffer::new(gl, glow::DEPTH_COMPONENT24, w, h)?;
    let fbo = Framebuffer::new(gl)?;
    fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT0, &color);
    fbo.attach_renderbuffer(glow::DEPTH_ATTACHMENT, &depth);
    fbo.check_complete(NAME)?;

    let (lo, hi) = scene.bounds();
    let reach = (hi - lo).length() + (camera.eye - 0.5 * (lo + hi)).length();
    let vp = super::view_projection(
        camera,
        width as f32 / height as f32,
        reach * 1e-4,
        reach * 2.0,
    );
    fbo.bind();
    unsafe {
        gl.viewport(0, 0, w, h);
        gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]);
        gl.disable(glow::BLEND);
        gl.disable(glow::SCISSOR_TEST);
        // One-sided surfaces: a polygon seen from behind shows its (unlit) back as black.
        gl.disable(glow::CULL_FACE);
        gl.enable(glow::DEPTH_TEST);
        gl.depth_func(glow::LESS);
        gl.depth_mask(true);
        gl.clear_color(0.0, 0.0, 0.0, 1.0);
        gl.clear_depth_f64(1.0);
        gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
    }
    program.use_program();
    lightmap.bind(0);
    program.set_i32("Lightmap", 0);
    program.set_mat4("ViewProjection", &vp.to_cols_array());
    mesh.draw();
    unsafe { gl.disable(glow::DEPTH_TEST) };
    let mut rgba = Vec::new();
    fbo.read_f32(glow::COLOR_ATTACHMENT0, w, h, &mut rgba);
    unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
    ctx.check(NAME)?;

    // GL rows run bottom to top; images run top to bottom.
    let mut rgb = Vec::with_capacity(width as usize * height as usize * 3);
    for row in (0..height as usize).rev() {
        for px in rgba[row * width as usize * 4..(row + 1) * width as usize * 4].chunks_exact(4) {
            rgb.extend_from_slice(&px[..3]);
        }
    }
    Ok(Image { width, height, rgb })
}
