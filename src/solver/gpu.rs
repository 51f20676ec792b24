//! The GPU backend: the paper's passes on OpenGL 3.0. The visibility pass draws the item buffer
//! from the shooter (`visibility/`); the reconstruction pass draws every receiver's lightmap
//! into renderbuffers, adding ΔL to the values it reads from the lightmap textures
//! (`reconstruction/`); `glCopyTexSubImage2D` copies the sums back into the textures, and the
//! unshot texture is read back for Find_Max_Energy after each shot.

use super::progressive::{Backend, Solver};
use super::reconstruction::{Lightmaps, ReconstructionPass};
use super::visibility::VisibilityPass;
use super::{engine, mesh, Part, Shooter, SolveError, SolveOptions, VisibilityKind};
use crate::gl::GlContext;
use crate::patches::PatchLayout;
use crate::scene::Scene;
use mesh::SceneMesh;

/// Progressive refinement on the GPU.
pub type GpuSolver<'a> = Solver<'a, GpuBackend<'a>>;

/// The GL objects and passes of a GPU solve.
pub struct GpuBackend<'a> {
    ctx: &'a GlContext,
    /// The caller's lightmaps without gutters, in which the passes work (the gutters are for
    /// display filtering only).
    dense: PatchLayout,
    visibility_mesh: SceneMesh,
    /// The visibility pass (item buffers from each shooter).
    pub visibility: VisibilityPass,
    /// The reconstruction pass (form factors and received energy per patch).
    pub reconstruction: ReconstructionPass,
    lightmaps: Lightmaps,
    options: SolveOptions,
    /// The unshot atlas as last read back from its texture.
    unshot: Vec<f32>,
    /// The polygons the passes of the current shot drew (receivers and shooters).
    touched: Vec<usize>,
}

impl<'a> Solver<'a, GpuBackend<'a>> {
    /// Set up the passes on `ctx` for `scene` laid out as `layout`, and initialise every patch's
    /// unshot energy with its emission.
    pub fn new(
        ctx: &'a GlContext,
        scene: &'a Scene,
        layout: &'a PatchLayout,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        // The reconstruction shader holds the near field's code only where face clusters shoot.
        let hierarchy = super::clusters::face_clusters(scene, layout, &options);
        let compiled = SolveOptions {
            face_clusters: hierarchy.is_some(),
            ..options.clone()
        };
        let backend = GpuBackend::new(ctx, scene, layout, compiled)?;
        Solver::start(scene, layout, options, backend, hierarchy)
    }
}

impl<'a> GpuBackend<'a> {
    fn new(
        ctx: &'a GlContext,
        scene: &Scene,
        layout: &PatchLayout,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let max = ctx
            .info
            .max_texture_size
            .min(ctx.info.max_renderbuffer_size);
        let dense = layout.without_gutters();
        let layout = &dense;
        let (w, h) = (layout.atlas_width, layout.atlas_height);
        if w as i64 > max as i64 || h as i64 > max as i64 {
            let scale = (w.max(h) as f32 / max as f32) * 1.05;
            return Err(SolveError::AtlasTooLarge {
                width: w,
                height: h,
                max,
                suggest: crate::patches::three_digits_up(layout.patch_size * scale),
            });
        }
        options.check(Some(max))?;
        let gl = &ctx.gl;
        let mesh = mesh::upload(gl, &mesh::vertex_data(scene, layout))?;
        let n = scene.polygons.len();
        // One item buffer per shooter of a reconstruction pass.
        let mut visibility = VisibilityPass::with_slots(
            ctx,
            options.visibility,
            options.hemi_res,
            options.tuning,
            scene,
            options.shooters_per_pass,
        )?;
        let data = if options.tessellation > 0.0 {
            let size = options.tessellation * layout.patch_size;
            mesh::tessellated_data(scene, layout, size)
        } else if options.visibility == VisibilityKind::Hemicube && options.robust_visibility {
            // Plates: the robust test reads the shown polygon's plane, which a plate shares.
            match visibility.merge_plates(scene) {
                Some(plates) => plates.vertex_data(scene, layout),
                None => mesh::vertex_data(scene, layout),
            }
        } else {
            mesh::vertex_data(scene, layout)
        };
        let visibility_mesh = mesh::upload_scene(gl, &data, n)?;
        let mut reconstruction = ReconstructionPass::new(ctx, scene, layout, &options)?;
        let lightmaps = Lightmaps::new(ctx, w as i32, h as i32)?;

        // Initialise: every patch's unshot energy is its emission (3.2: "initialise E").
        reconstruction.emit(ctx, &mesh)?;
        reconstruction.copy_into(ctx, &lightmaps)?;
        // The llvmpipe engine's receivers' test reads the patch positions just rasterised.
        engine::after_emission(
            &mut visibility,
            &reconstruction,
            scene,
            &options,
            w as usize,
        );
        let mut unshot = Vec::new();
        lightmaps.unshot.read_f32(&mut unshot);
        reconstruction.observe(&unshot);
        Ok(GpuBackend {
            ctx,
            dense,
            visibility_mesh,
            visibility,
            reconstruction,
            lightmaps,
            options,
            unshot,
            touched: Vec::new(),
        })
    }
}

impl Backend for GpuBackend<'_> {
    fn layout(&self) -> &PatchLayout {
        &self.dense
    }

    fn unshot(&self) -> &[f32] {
        &self.unshot
    }

    fn visibility(&mut self, shooter: &Shooter, slot: usize) -> Result<(), SolveError> {
        Ok(self
            .visibility
            .run_in_slot(self.ctx, &self.visibility_mesh, shooter, slot)?)
    }

    fn visibility_pass(&mut self, shooters: &[Shooter]) -> Result<(), SolveError> {
        Ok(self
            .visibility
            .run_pass(self.ctx, &self.visibility_mesh, shooters)?)
    }

    fn reconstruction(&mut self, shooters: &[Shooter]) -> Result<(), SolveError> {
        self.reconstruction.run(
            self.ctx,
            &self.visibility,
            &self.lightmaps,
            shooters,
            &self.options,
        )?;
        self.touched.extend_from_slice(&self.reconstruction.touched);
        Ok(())
    }

    fn accumulate(&mut self) -> Result<(), SolveError> {
        Ok(self.reconstruction.copy_into(self.ctx, &self.lightmaps)?)
    }

    fn read_unshot(&mut self, changed: &mut Vec<usize>) -> Result<(), SolveError> {
        // Find_Max_Energy reads what the copies put into the unshot lightmap texture.
        self.lightmaps.unshot.read_f32(&mut self.unshot);
        self.reconstruction.observe(&self.unshot);
        changed.clear();
        changed.append(&mut self.touched);
        changed.sort_unstable();
        changed.dedup();
        Ok(())
    }

    fn radiosity(&self) -> Vec<f32> {
        let mut out = Vec::new();
        self.lightmaps.radiosity.read_f32(&mut out);
        out
    }

    fn load(&mut self, radiosity: &[f32], unshot: &[f32]) -> Result<(), SolveError> {
        self.lightmaps.radiosity.upload_f32(radiosity);
        self.lightmaps.unshot.upload_f32(unshot);
        self.reconstruction.load_from(self.ctx, &self.lightmaps)?;
        // Every polygon may have changed.
        self.touched.extend(0..self.reconstruction.texels().len());
        Ok(())
    }

    fn parts(&mut self, parts: &[Part]) -> Result<(), SolveError> {
        Ok(self.reconstruction.set_parts(self.ctx, parts)?)
    }

    fn clear_unshot(&mut self, polygons: &[usize]) -> Result<(), SolveError> {
        let rects: Vec<[u32; 4]> = polygons
            .iter()
            .map(|&p| {
                let lm = &self.dense.lightmaps[p];
                [lm.x, lm.y, lm.x + lm.w, lm.y + lm.h]
            })
            .collect();
        self.reconstruction
            .clear_unshot(self.ctx, &self.lightmaps, &rects)?;
        self.touched.extend_from_slice(polygons);
        Ok(())
    }
}
