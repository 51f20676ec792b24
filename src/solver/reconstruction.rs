//! Reconstruction pass (paper 3.2.2): every receiver drawn orthographically onto its lightmap
//! texels, into an FBO whose colour attachments are *renderbuffers* the size of the atlas. The
//! fragment shader tests visibility against the item buffer and computes the form factor and the
//! received energy; the results are copied into the lightmap textures with glCopyTexSubImage2D.
//!
//! The receivers are rasterised once, at initialisation, into atlas textures holding each patch's
//! position, normal and reflectance (`glsl/patchdata.frag`); every pass then draws one quad over
//! the atlas and reads them (on llvmpipe, setting up the triangles of 1,602 small polygons cost
//! more than all of the pass's fragment work).
//!
//! Two attachments: 0 = radiosity + ΔL, 1 = unshot + ΔL (the shooter's own unshot cleared).
//! The paper adds with GL_ADD while copying; a copy cannot add, so the shader adds the old value
//! it reads from the texture, and the copy replaces the texture with the sum: same result.

use super::mesh::ATTRIBUTES;
use super::visibility::{face_rotations, VisibilityPass};
use super::{FormFactorKind, Shooter, SolveOptions, VisibilityKind};
use crate::gl::objects::Attribute;
use crate::gl::{
    Framebuffer, GlContext, GlError, Mesh, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::glsl;
use glow::HasContext;

pub const NAME: &str = "reconstruction";
pub const INIT_NAME: &str = "initialisation";
pub const COPY_NAME: &str = "accumulation";

/// The two lightmap atlases of section 3.1: accumulated and unshot radiance (RGBA32F, alpha =
/// polygon ID + 1), which the reconstruction pass reads and its copies replace.
pub struct Lightmaps {
    pub radiosity: Texture,
    pub unshot: Texture,
}

impl Lightmaps {
    pub fn new(ctx: &GlContext, width: i32, height: i32) -> Result<Self, GlError> {
        let make = || {
            Texture::new(
                &ctx.gl,
                width,
                height,
                TextureFormat::Rgba32F,
                glow::NEAREST,
            )
        };
        Ok(Lightmaps {
            radiosity: make()?,
            unshot: make()?,
        })
    }
}

/// Each patch's geometry as atlas textures (RGBA32F): position + polygon ID + 1, normal, Kd.
struct PatchData {
    program: Program,
    position: Texture,
    normal: Texture,
    reflectance: Texture,
    fbo: Framebuffer,
}

pub struct ReconstructionPass {
    program: Program,
    emission: Program,
    patches: PatchData,
    /// Two triangles covering the atlas.
    quad: Mesh,
    _radiosity_rb: Renderbuffer,
    _unshot_rb: Renderbuffer,
    fbo: Framebuffer,
    width: i32,
    height: i32,
}

impl ReconstructionPass {
    pub fn new(ctx: &GlContext, width: i32, height: i32) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let outputs = &[(0, "NewRadiosity"), (1, "NewUnshot")];
        let program = Program::new(
            gl,
            glsl!("atlas.vert"),
            glsl!("reconstruct.frag"),
            &[(0, "Corner")],
            outputs,
        )?;
        let quad = Mesh::new(
            gl,
            &[
                -1.0, -1.0, 1.0, -1.0, 1.0, 1.0, -1.0, -1.0, 1.0, 1.0, -1.0, 1.0,
            ],
            2,
            &[Attribute {
                location: 0,
                size: 2,
                offset: 0,
            }],
        )?;
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
        patches.fbo.check_complete(INIT_NAME)?;
        let emission = Program::new(
            gl,
            glsl!("lightmap.vert"),
            glsl!("emission.frag"),
            ATTRIBUTES,
            outputs,
        )?;
        let radiosity_rb = Renderbuffer::new(gl, glow::RGBA32F, width, height)?;
        let unshot_rb = Renderbuffer::new(gl, glow::RGBA32F, width, height)?;
        let fbo = Framebuffer::new(gl)?;
        fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT0, &radiosity_rb);
        fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT1, &unshot_rb);
        fbo.check_complete(NAME)?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(NAME)?;
        Ok(ReconstructionPass {
            program,
            emission,
            patches,
            quad,
            _radiosity_rb: radiosity_rb,
            _unshot_rb: unshot_rb,
            fbo,
            width,
            height,
        })
    }

    fn begin(&self, ctx: &GlContext) {
        Self::target(
            ctx,
            &self.fbo,
            &[glow::COLOR_ATTACHMENT0, glow::COLOR_ATTACHMENT1],
            self.width,
            self.height,
        );
    }

    /// Bind `fbo` for drawing flat into the atlas: its `buffers`, no depth, blending, culling
    /// or scissor, cleared to zero (texels that are no patch stay zero: alpha 0, no polygon).
    fn target(ctx: &GlContext, fbo: &Framebuffer, buffers: &[u32], width: i32, height: i32) {
        let gl = &ctx.gl;
        fbo.bind();
        unsafe {
            gl.viewport(0, 0, width, height);
            gl.draw_buffers(buffers);
            gl.disable(glow::DEPTH_TEST);
            gl.disable(glow::BLEND);
            gl.disable(glow::CULL_FACE);
            gl.disable(glow::SCISSOR_TEST);
            gl.clear_color(0.0, 0.0, 0.0, 0.0);
            gl.clear(glow::COLOR_BUFFER_BIT);
        }
    }

    /// Rasterise every patch's geometry into the patch textures, then write each patch's emitted
    /// radiance (and its polygon ID in alpha) into both attachments.
    pub fn emit(&self, ctx: &GlContext, mesh: &Mesh) -> Result<(), GlError> {
        Self::target(
            ctx,
            &self.patches.fbo,
            &[
                glow::COLOR_ATTACHMENT0,
                glow::COLOR_ATTACHMENT1,
                glow::COLOR_ATTACHMENT2,
            ],
            self.width,
            self.height,
        );
        self.patches.program.use_program();
        mesh.draw();
        ctx.check(INIT_NAME)?;
        self.begin(ctx);
        self.emission.use_program();
        mesh.draw();
        ctx.check(INIT_NAME)
    }

    /// One reconstruction: ΔL for every patch from `shooter`, added to `radiosity` and `unshot`
    /// (read as textures) into the two renderbuffers.
    pub fn run(
        &self,
        ctx: &GlContext,
        visibility: &VisibilityPass,
        lightmaps: &Lightmaps,
        shooter: &Shooter,
        options: &SolveOptions,
    ) -> Result<(), GlError> {
        self.begin(ctx);
        self.program.use_program();
        visibility.item_buffer.bind(0);
        visibility.distance.bind(3);
        lightmaps.radiosity.bind(1);
        lightmaps.unshot.bind(2);
        self.patches.position.bind(4);
        self.patches.normal.bind(5);
        self.patches.reflectance.bind(6);
        self.program.set_i32("PatchPosition", 4);
        self.program.set_i32("PatchNormal", 5);
        self.program.set_i32("PatchReflectance", 6);
        self.program.set_i32("HemiItemBuffer", 0);
        self.program.set_i32("Radiosity", 1);
        self.program.set_i32("Unshot", 2);
        self.program
            .set_mat4("ShooterView", &shooter.view().to_cols_array());
        self.program
            .set_vec3("ShootPos", shooter.position.to_array());
        self.program
            .set_vec3("ShootNormal", shooter.normal.to_array());
        self.program
            .set_vec3("ShootEnergy", shooter.energy.to_array());
        self.program.set_f32("ShooterId", shooter.polygon as f32);
        self.program
            .set_vec4("ShooterTexels", shooter.texels.map(|v| v as f32));
        let p = &self.program;
        p.set_i32(
            "FormFactorKind",
            (options.form_factor == FormFactorKind::Polygon) as i32,
        );
        let corners: Vec<f32> = shooter.corners.iter().flat_map(|c| c.to_array()).collect();
        p.set_vec3_array("ShootCorners", &corners);
        p.set_i32("ShootCornerCount", shooter.corner_count as i32);
        p.set_f32("ShootArea", shooter.area);
        p.set_i32(
            "HemiCube",
            (options.visibility == VisibilityKind::Hemicube) as i32,
        );
        let rotations: Vec<f32> = face_rotations()
            .iter()
            .flat_map(|m| m.to_cols_array())
            .collect();
        p.set_mat3_array("FaceRotation", &rotations);
        p.set_i32("Robust", options.robust_visibility as i32);
        p.set_i32("HemiDistance", 3);
        self.quad.draw();
        unsafe {
            ctx.gl.active_texture(glow::TEXTURE0);
        }
        ctx.check(NAME)
    }

    /// Read the new unshot atlas (attachment 1) for Find_Max_Energy.
    pub fn read_unshot(&self, out: &mut Vec<f32>) {
        self.fbo
            .read_f32(glow::COLOR_ATTACHMENT1, self.width, self.height, out);
    }

    /// The paper's accumulation: glCopyTexSubImage2D from the renderbuffers into the lightmaps.
    pub fn copy_into(&self, ctx: &GlContext, lightmaps: &Lightmaps) -> Result<(), GlError> {
        self.fbo
            .copy_to_texture(glow::COLOR_ATTACHMENT0, &lightmaps.radiosity);
        self.fbo
            .copy_to_texture(glow::COLOR_ATTACHMENT1, &lightmaps.unshot);
        unsafe {
            ctx.gl.read_buffer(glow::COLOR_ATTACHMENT0);
            ctx.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
        ctx.check(COPY_NAME)
    }
}
