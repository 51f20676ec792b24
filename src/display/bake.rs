//! The display's smooth shading (`smooth.rs`) baked into the radiance atlas, for programs that
//! only sample a texture (`--gltf`, `gltf_out.rs`): the display pass's own fragment shader run
//! over the atlas, each triangle drawn at its lightmap coordinates (`glsl/bake.vert`), so that
//! each patch texel of a smoothed polygon gets what the display shows at its centre. Polygons
//! without smooth edges keep their texels bit for bit; the gutters are dilated again from the
//! baked texels.

use super::mesh::DisplayMesh;
use super::render::{DisplayPass, Viewport};
use super::smooth::Smoothing;
use crate::gl::{Framebuffer, GlContext, GlError, Renderbuffer};
use crate::glsl;
use crate::patches::PatchLayout;
use crate::scene::Scene;
use glam::Mat4;

/// `atlas` (RGBA radiance, rows bottom to top, dilated, as the display samples it) with the
/// smooth shading of `smoothing` baked into the patch texels of the polygons it smooths.
pub fn bake_smoothing(
    ctx: &GlContext,
    scene: &Scene,
    layout: &PatchLayout,
    atlas: &[f32],
    smoothing: &Smoothing,
) -> Result<Vec<f32>, GlError> {
    let mut out = atlas.to_vec();
    if smoothing.is_empty() {
        return Ok(out);
    }
    let gl = &ctx.gl;
    let (w, h) = (layout.atlas_width, layout.atlas_height);
    let mut mesh = DisplayMesh::new(gl, scene, layout, smoothing.clone())?;
    mesh.update(atlas, w, h);
    let pass = DisplayPass::with_shaders(ctx, (w, h), glsl!("bake.vert"), glsl!("display.frag"))?;
    pass.upload(atlas);
    let color = Renderbuffer::new(gl, glow::RGBA32F, w as i32, h as i32)?;
    let fbo = Framebuffer::new(gl)?;
    fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT0, &color);
    fbo.check_complete("bake")?;
    // No depth attachment: lightmaps do not overlap, so there is nothing to hide.
    let viewport = Viewport::full(w as i32, h as i32);
    pass.run(ctx, &mesh, Mat4::IDENTITY, Some(&fbo), viewport, |_| {})?;
    let mut baked = Vec::new();
    fbo.read_f32(glow::COLOR_ATTACHMENT0, w as i32, h as i32, &mut baked);
    unsafe {
        use glow::HasContext;
        gl.bind_framebuffer(glow::FRAMEBUFFER, None)
    };
    ctx.check("bake")?;
    // Patch texels are the texels whose centres the rasteriser covers (patches/mod.rs), so each
    // was drawn; only smoothed polygons' are taken, the rest stay exactly the solver's.
    for (i, &owner) in layout.owner.iter().enumerate() {
        if owner > 0 && smoothing.is_smoothed(owner as usize - 1) {
            out[4 * i..4 * i + 3].copy_from_slice(&baked[4 * i..4 * i + 3]);
        }
    }
    layout.dilate(&mut out);
    Ok(out)
}
