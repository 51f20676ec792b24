//! The `upload-order` probe: host uploads into a texture that queued draws sample. The accurate
//! mode uploads each shot's item buffer, written by the walk (`Tuning::walk_item_buffers`), into
//! one texture between the passes of a shot, with a read-back after each shot. GL orders the
//! commands, so a draw samples what the upload before it wrote; Mesa 25.0.7's threaded context let
//! zink's queued draws sample a later upload (issue 60, docs/drivers.md). This case repeats that
//! pattern through the solver's own upload path (`Texture::upload_u8_region`); its reference is
//! known without a driver: step k sees k.

use super::{Metric, Picture};
use crate::gl::objects::Attribute;
use crate::gl::{Framebuffer, GlContext, Mesh, Program, Renderbuffer, Texture, TextureFormat};
use crate::glsl;
use anyhow::Result;
use glow::HasContext;

/// The case's name.
pub const NAME: &str = "upload-order";
/// Uploads, each followed by draws that sample it.
const STEPS: i32 = 64;
/// The texture's side: an upload of 256 KB, past the size Mesa's threaded context queues whole.
const SIDE: i32 = 256;
/// Rows of the longer draw after each upload, above the row of records.
const ROWS: i32 = 64;
/// The texture unit the draws sample: another than the one uploads use, so the texture stays
/// bound there throughout, as the item buffer did.
const UNIT: u32 = 1;

/// Step k uploads the texture filled with k, draws the rows above the records sampling it, then
/// pixel (k, 0) recording what it samples; every fourth step starts with the driver idle
/// (glFinish, as after a shot's read-back). The picture is the row of records.
pub fn render(ctx: &GlContext) -> Result<Picture> {
    let gl = &ctx.gl;
    let texture = Texture::new(gl, SIDE, SIDE, TextureFormat::Rgba8, glow::NEAREST)?;
    let target = Renderbuffer::new(gl, glow::RGBA32F, STEPS, ROWS + 1)?;
    let fbo = Framebuffer::new(gl)?;
    fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT0, &target);
    fbo.check_complete(NAME)?;
    let program = Program::new(
        gl,
        glsl!("atlas.vert"),
        glsl!("upload_order.frag"),
        &[(0, "Corner"), (1, "Size")],
        &[(0, "Seen")],
    )?;
    // One triangle over the whole viewport; the scissor picks the rows or the record.
    let layout = [(0, 2, 0), (1, 1, 2)].map(|(location, size, offset)| Attribute {
        location,
        size,
        offset,
    });
    let cover = Mesh::new(
        gl,
        &[-1.0, -1.0, 0.0, 3.0, -1.0, 0.0, -1.0, 3.0, 0.0],
        3,
        &layout,
    )?;
    texture.bind(UNIT);
    program.use_program();
    program.set_i32("Uploaded", UNIT as i32);
    unsafe {
        gl.viewport(0, 0, STEPS, ROWS + 1);
        gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]);
        gl.disable(glow::DEPTH_TEST);
        gl.disable(glow::BLEND);
        gl.enable(glow::SCISSOR_TEST);
        gl.active_texture(glow::TEXTURE0);
    }
    let mut texels = vec![0u8; (SIDE * SIDE * 4) as usize];
    for k in 0..STEPS {
        if k % 4 == 0 {
            unsafe { gl.finish() };
        }
        texels.fill(k as u8);
        texture.upload_u8_region(SIDE, SIDE, &texels);
        fbo.bind();
        program.set_f32("Step", k as f32);
        for [x, y, w, h] in [[0, 1, STEPS, ROWS], [k, 0, 1, 1]] {
            unsafe { gl.scissor(x, y, w, h) };
            cover.draw_arrays(glow::TRIANGLES, 0, 3);
        }
    }
    unsafe { gl.disable(glow::SCISSOR_TEST) };
    let mut seen = Vec::new();
    fbo.read_f32(glow::COLOR_ATTACHMENT0, STEPS, 1, &mut seen);
    unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
    ctx.check(NAME)?;
    Ok(Picture {
        width: STEPS as u32,
        height: 1,
        rgb: seen
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect(),
        metric: Metric::Radiance,
    })
}

/// The picture GL promises: step k saw k (red), its own step (green 1).
pub fn expected() -> Vec<f32> {
    (0..STEPS).flat_map(|k| [k as f32, 1.0, 0.0]).collect()
}
