//! The display pass: rasterise the scene from the camera, sampling the (dilated) radiance atlas
//! bilinearly and adding the smooth-shading corrections of the vertices (`smooth.rs`).
//! `DisplayPass` is built once and run per frame (the viewer draws it into its window); `render`
//! runs it once into a float framebuffer and reads the linear radiance image back (what
//! `radiosity solve` writes).

use super::mesh::{DisplayMesh, ATTRIBUTES};
use super::smooth::{FADE_TEXELS, FULL_TEXELS};
use crate::gl::program::Source;
use crate::gl::{Framebuffer, GlContext, GlError, Program, Renderbuffer, Texture, TextureFormat};
use crate::glsl;
use crate::scene::{Camera, Scene};
use glam::Mat4;
use glow::HasContext;

pub const NAME: &str = "display";
/// The texture unit of the smooth edges (`glsl/smooth.glsl`).
const SMOOTH_EDGES_UNIT: u32 = 2;

/// A linear RGB radiance image, row 0 at the top.
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB, three floats per pixel.
    pub rgb: Vec<f32>,
}

/// A rectangle of a framebuffer in pixels, GL's way: origin at the bottom left.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Viewport {
    /// Left edge, pixels.
    pub x: i32,
    /// Bottom edge, pixels.
    pub y: i32,
    /// Width, pixels.
    pub width: i32,
    /// Height, pixels.
    pub height: i32,
}

impl Viewport {
    /// The whole of a `width` x `height` target.
    pub fn full(width: i32, height: i32) -> Viewport {
        Viewport {
            x: 0,
            y: 0,
            width,
            height,
        }
    }

    /// Width over height (a zero height counts as 1).
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height.max(1) as f32
    }
}

/// The camera's view-projection for `scene`, with near and far planes that hold the whole scene
/// wherever the camera is.
pub fn scene_view_projection(scene: &Scene, camera: &Camera, aspect: f32) -> Mat4 {
    let (lo, hi) = scene.bounds();
    let reach = (hi - lo).length() + (camera.eye - 0.5 * (lo + hi)).length();
    super::view_projection(camera, aspect, reach * 1e-4, reach * 2.0)
}

/// The scene drawn from a camera with a lightmap atlas: one program and the atlas texture.
pub struct DisplayPass {
    program: Program,
    /// The atlas the pass samples (RGBA32F radiance, bilinear), texture unit 0, `Lightmap`.
    pub lightmap: Texture,
}

impl DisplayPass {
    /// Linear radiance out (`glsl/display.vert`, `glsl/display.frag`).
    pub fn new(ctx: &GlContext, atlas_size: (u32, u32)) -> Result<Self, GlError> {
        Self::with_shaders(
            ctx,
            atlas_size,
            glsl!("display.vert"),
            glsl!("display.frag"),
        )
    }

    /// The same pass with other shaders (the viewer's tone mapping and overlays). They get the
    /// display mesh's attributes (`mesh::ATTRIBUTES`), `ViewProjection`, `Lightmap` on unit 0,
    /// the mesh's smooth edges on unit 2 and `glsl/smooth.glsl`'s `smoothRadiance` (inserted
    /// into the fragment shader), and write `Color`. Units 1 and 3 up are the caller's.
    pub fn with_shaders(
        ctx: &GlContext,
        atlas_size: (u32, u32),
        vertex: Source,
        fragment: Source,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let smooth = format!(
            "#define SMOOTH_FULL {FULL_TEXELS:?}\n#define SMOOTH_FADE {FADE_TEXELS:?}\n{}",
            glsl!("smooth.glsl").text
        );
        let fragment = fragment.insert(&smooth);
        let program = Program::new(gl, vertex, fragment, ATTRIBUTES, &[(0, "Color")])?;
        let lightmap = Texture::new(
            gl,
            atlas_size.0 as i32,
            atlas_size.1 as i32,
            TextureFormat::Rgba32F,
            glow::LINEAR,
        )?;
        Ok(DisplayPass { program, lightmap })
    }

    /// Replace the atlas (RGBA radiance, rows bottom to top, already dilated).
    pub fn upload(&self, atlas: &[f32]) {
        self.lightmap.upload_f32(atlas);
    }

    /// Draw `mesh` with `view_projection` into `viewport` of `framebuffer` (`None`: the default
    /// framebuffer, i.e. the window), after clearing that viewport to black. `uniforms` sets any
    /// further uniforms of the bound program (textures on units 1 and up).
    pub fn run(
        &self,
        ctx: &GlContext,
        mesh: &DisplayMesh,
        view_projection: Mat4,
        framebuffer: Option<&Framebuffer>,
        viewport: Viewport,
        uniforms: impl FnOnce(&Program),
    ) -> Result<(), GlError> {
        let gl = &ctx.gl;
        let Viewport {
            x,
            y,
            width,
            height,
        } = viewport;
        unsafe {
            match framebuffer {
                Some(fbo) => {
                    fbo.bind();
                    gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]);
                }
                None => {
                    gl.bind_framebuffer(glow::FRAMEBUFFER, None);
                    gl.draw_buffer(glow::BACK);
                }
            }
            gl.viewport(x, y, width, height);
            gl.disable(glow::BLEND);
            // One-sided surfaces: a polygon seen from behind shows its (unlit) back as black.
            gl.disable(glow::CULL_FACE);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::LESS);
            gl.depth_mask(true);
            gl.color_mask(true, true, true, true);
            // Clear the viewport only (the window has a panel beside it).
            gl.enable(glow::SCISSOR_TEST);
            gl.scissor(x, y, width, height);
            gl.clear_color(0.0, 0.0, 0.0, 1.0);
            gl.clear_depth_f64(1.0);
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
            gl.disable(glow::SCISSOR_TEST);
        }
        self.program.use_program();
        self.lightmap.bind(0);
        self.program.set_i32("Lightmap", 0);
        mesh.edges().bind(SMOOTH_EDGES_UNIT);
        self.program
            .set_i32("SmoothEdges", SMOOTH_EDGES_UNIT as i32);
        self.program
            .set_mat4("ViewProjection", &view_projection.to_cols_array());
        uniforms(&self.program);
        mesh.mesh().draw();
        unsafe {
            gl.disable(glow::DEPTH_TEST);
            gl.active_texture(glow::TEXTURE0);
        }
        ctx.check(NAME)
    }
}

/// Draw `mesh` from `camera` with `atlas` (RGBA radiance, rows bottom to top, already dilated;
/// the mesh's corrections made for it with [`DisplayMesh::update`]) into a `width` x `height`
/// float image.
pub fn render(
    ctx: &GlContext,
    scene: &Scene,
    mesh: &DisplayMesh,
    atlas: &[f32],
    atlas_size: (u32, u32),
    camera: &Camera,
    (width, height): (u32, u32),
) -> Result<Image, GlError> {
    let gl = &ctx.gl;
    let (w, h) = (width as i32, height as i32);
    let pass = DisplayPass::new(ctx, atlas_size)?;
    pass.upload(atlas);
    let color = Renderbuffer::new(gl, glow::RGBA32F, w, h)?;
    let depth = Renderbuffer::new(gl, glow::DEPTH_COMPONENT24, w, h)?;
    let fbo = Framebuffer::new(gl)?;
    fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT0, &color);
    fbo.attach_renderbuffer(glow::DEPTH_ATTACHMENT, &depth);
    fbo.check_complete(NAME)?;

    let vp = scene_view_projection(scene, camera, width as f32 / height as f32);
    pass.run(ctx, mesh, vp, Some(&fbo), Viewport::full(w, h), |_| {})?;
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
