//! Visibility pass (paper 3.2.1): the scene drawn from the shooter, polygon IDs as colours, into
//! an FBO whose colour attachment is a *texture* (so the reconstruction pass can sample it), with
//! a depth renderbuffer for hidden-surface removal.
//!
//! Two projections: the paper's hemispherical one (`glsl/hemiproj.vert`, one render onto the
//! unit disk) and the hemicube (`glsl/hemicube.vert`, five 90° perspective renders):
//!
//! ```text
//!   hemisphere: R x R          hemicube: 5R x R, one face per R x R block
//!   +--------+                 +-------+-------+-------+-------+-------+
//!   |  disk  |                 | front |  +x   |  -x   |  +y   |  -y   |
//!   +--------+                 +-------+-------+-------+-------+-------+
//! ```

use super::mesh::ATTRIBUTES;
use super::{Shooter, VisibilityKind};
use crate::gl::{
    Framebuffer, GlContext, GlError, Mesh, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::glsl;
use glam::{Mat3, Mat4, Vec3};
use glow::HasContext;

pub struct VisibilityPass {
    program: Program,
    pub kind: VisibilityKind,
    /// The item buffer: RGBA8, ID + 1 in RGB (0 = nothing seen).
    pub item_buffer: Texture,
    /// Distance from the shooter to what each pixel shows (R32F; cleared to "infinitely far").
    pub distance: Texture,
    _depth: Renderbuffer,
    fbo: Framebuffer,
    resolution: i32,
    near_far: [f32; 2],
}

pub const NAME: &str = "visibility";

/// Hemicube faces as rotations of the shooter's eye space (which looks down -z): front, +x,
/// -x, +y, -y. The reconstruction shader uses the same matrices to find a direction's pixel.
pub fn face_rotations() -> [Mat3; 5] {
    let face = |dir: Vec3, up: Vec3| Mat3::from_mat4(Mat4::look_at_rh(Vec3::ZERO, dir, up));
    [
        face(Vec3::NEG_Z, Vec3::Y),
        face(Vec3::X, Vec3::Y),
        face(Vec3::NEG_X, Vec3::Y),
        face(Vec3::Y, Vec3::Z),
        face(Vec3::NEG_Y, Vec3::Z),
    ]
}

impl VisibilityPass {
    /// `scene_size`: the scene's bounding-box diagonal, which sets the near and far planes.
    pub fn new(
        ctx: &GlContext,
        kind: VisibilityKind,
        resolution: u32,
        scene_size: f32,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let vertex = match kind {
            VisibilityKind::Hemisphere => glsl!("hemiproj.vert"),
            VisibilityKind::Hemicube => glsl!("hemicube.vert"),
        };
        let program = Program::new(
            gl,
            vertex,
            glsl!("itembuffer.frag"),
            ATTRIBUTES,
            &[(0, "Color"), (1, "Distance")],
        )?;
        let res = resolution as i32;
        let width = if kind == VisibilityKind::Hemicube {
            5 * res
        } else {
            res
        };
        // NEAREST: an ID must never be blended with its neighbour's.
        let item_buffer = Texture::new(gl, width, res, TextureFormat::Rgba8, glow::NEAREST)?;
        let distance = Texture::new(gl, width, res, TextureFormat::R32F, glow::NEAREST)?;
        let depth = Renderbuffer::new(gl, glow::DEPTH_COMPONENT24, width, res)?;
        let fbo = Framebuffer::new(gl)?;
        fbo.attach_texture(glow::COLOR_ATTACHMENT0, &item_buffer);
        fbo.attach_texture(glow::COLOR_ATTACHMENT1, &distance);
        fbo.attach_renderbuffer(glow::DEPTH_ATTACHMENT, &depth);
        fbo.check_complete(NAME)?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(NAME)?;
        // Near plane: 1e-4 of the scene, so the shooter's own plane is clipped away but receivers
        // a hair in front of it are kept. Far plane: beyond anything in the scene.
        let near_far = [scene_size * 1e-4, scene_size * 2.0];
        Ok(VisibilityPass {
            program,
            kind,
            item_buffer,
            distance,
            _depth: depth,
            fbo,
            resolution: res,
            near_far,
        })
    }

    pub fn run(&self, ctx: &GlContext, mesh: &Mesh, shooter: &Shooter) -> Result<(), GlError> {
        let gl = &ctx.gl;
        self.fbo.bind();
        unsafe {
            gl.viewport(0, 0, self.item_buffer.width, self.item_buffer.height);
            gl.draw_buffers(&[glow::COLOR_ATTACHMENT0, glow::COLOR_ATTACHMENT1]);
            gl.disable(glow::BLEND);
            gl.disable(glow::SCISSOR_TEST);
            // Back faces occlude too: a wall seen from behind is still a wall.
            gl.disable(glow::CULL_FACE);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::LESS);
            gl.depth_mask(true);
            gl.clear_buffer_f32_slice(glow::COLOR, 0, &[0.0; 4]);
            gl.clear_buffer_f32_slice(glow::COLOR, 1, &[f32::MAX, 0.0, 0.0, 0.0]);
            gl.clear_depth_f64(1.0);
            gl.clear(glow::DEPTH_BUFFER_BIT);
        }
        self.program.use_program();
        self.program.set_f32("ShooterId", shooter.polygon as f32);
        let view = shooter.view();
        self.program.set_mat4("ShooterView", &view.to_cols_array());
        match self.kind {
            VisibilityKind::Hemisphere => {
                self.program.set_vec2("NearFar", self.near_far);
                mesh.draw();
            }
            VisibilityKind::Hemicube => {
                let [n, f] = self.near_far;
                let projection = Mat4::perspective_rh_gl(std::f32::consts::FRAC_PI_2, 1.0, n, f);
                for (k, rotation) in face_rotations().iter().enumerate() {
                    let r = self.resolution;
                    unsafe { gl.viewport(k as i32 * r, 0, r, r) };
                    let m = projection * Mat4::from_mat3(*rotation) * view;
                    self.program
                        .set_mat4("FaceViewProjection", &m.to_cols_array());
                    mesh.draw();
                }
            }
        }
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
