//! Visibility pass (paper 3.2.1): the scene drawn from the shooter through the hemispherical
//! projection, polygon IDs as colours, into an FBO whose colour attachment is a *texture* (so the
//! reconstruction pass can sample it) with a depth renderbuffer for hidden-surface removal.

use super::mesh::ATTRIBUTES;
use super::Shooter;
use crate::gl::{
    Framebuffer, GlContext, GlError, Mesh, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::glsl;
use glow::HasContext;

pub struct VisibilityPass {
    program: Program,
    /// The item buffer: RGBA8, ID + 1 in RGB (0 = nothing seen).
    pub item_buffer: Texture,
    _depth: Renderbuffer,
    fbo: Framebuffer,
    near_far: [f32; 2],
}

pub const NAME: &str = "visibility";

impl VisibilityPass {
    /// `scene_size`: the scene's bounding-box diagonal, which sets the near and far planes.
    pub fn new(ctx: &GlContext, resolution: u32, scene_size: f32) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let program = Program::new(
            gl,
            glsl!("hemiproj.vert"),
            glsl!("itembuffer.frag"),
            ATTRIBUTES,
            &[(0, "Color")],
        )?;
        let res = resolution as i32;
        // NEAREST: an ID must never be blended with its neighbour's.
        let item_buffer = Texture::new(gl, res, res, TextureFormat::Rgba8, glow::NEAREST)?;
        let depth = Renderbuffer::new(gl, glow::DEPTH_COMPONENT24, res, res)?;
        let fbo = Framebuffer::new(gl)?;
        fbo.attach_texture(glow::COLOR_ATTACHMENT0, &item_buffer);
        fbo.attach_renderbuffer(glow::DEPTH_ATTACHMENT, &depth);
        fbo.check_complete(NAME)?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(NAME)?;
        // Near plane: 1e-4 of the scene, so the shooter's own plane is clipped away but
        // receivers a hair in front of it are kept. Far plane: beyond anything in the scene.
        let near_far = [scene_size * 1e-4, scene_size * 2.0];
        Ok(VisibilityPass {
            program,
            item_buffer,
            _depth: depth,
            fbo,
            near_far,
        })
    }

    pub fn run(&self, ctx: &GlContext, mesh: &Mesh, shooter: &Shooter) -> Result<(), GlError> {
        let gl = &ctx.gl;
        self.fbo.bind();
        unsafe {
            gl.viewport(0, 0, self.item_buffer.width, self.item_buffer.height);
            gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]);
            gl.disable(glow::BLEND);
            gl.disable(glow::SCISSOR_TEST);
            // Back faces occlude too: a wall seen from behind is still a wall.
            gl.disable(glow::CULL_FACE);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::LESS);
            gl.depth_mask(true);
            gl.clear_color(0.0, 0.0, 0.0, 0.0);
            gl.clear_depth_f64(1.0);
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
        }
        self.program.use_program();
        self.program
            .set_mat4("ShooterView", &shooter.view().to_cols_array());
        self.program.set_vec2("NearFar", self.near_far);
        self.program.set_f32("ShooterId", shooter.polygon as f32);
        mesh.draw();
        unsafe {
            gl.disable(glow::DEPTH_TEST);
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
        ctx.check(NAME)
    }

    /// The item buffer as polygon IDs (`None` where no polygon is seen), rows bottom to top.
    pub fn read_ids(&self) -> Vec<Option<u32>> {
        self.item_buffer
            .read_u8()
            .chunks_exact(4)
            .map(|c| {
                let n = c[0] as u32 | (c[1] as u32) << 8 | (c[2] as u32) << 16;
                n.checked_sub(1)
            })
            .collect()
    }
}
