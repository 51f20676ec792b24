//! The progressive refinement loop of section 3.2, on the GPU:
//!
//! ```text
//! initialise the unshot energy E of every patch (its emission)
//! while not converged:
//!     shooter = Find_Max_Energy()              -- CPU, from the unshot atlas
//!     visibility pass from the shooter         -- item buffer (texture attachment)
//!     reconstruction pass over all receivers   -- lightmap texels + ΔE, ΔE = ρ·F·E
//!                                                 (into renderbuffer attachments)
//!     copy the sums into the lightmaps         -- glCopyTexSubImage2D
//!     (the shooter's unshot energy is cleared in the same pass)
//! ```

use super::find_max_energy::EnergyTotals;
use super::reconstruction::{Lightmaps, ReconstructionPass};
use super::visibility::VisibilityPass;
use super::{mesh, shooters, Shooter, ShotRecord, SolveOptions, VisibilityKind};
use crate::gl::{GlContext, GlError, Mesh};
use crate::patches::{Lightmap, PatchLayout};
use crate::scene::Scene;
use mesh::SceneMesh;
use std::time::Instant;

#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error(transparent)]
    Gl(#[from] GlError),
    #[error(
        "the lightmap atlas needs {width}x{height} texels but this driver allows at most {max}x{max} \
         (GL_MAX_TEXTURE_SIZE / GL_MAX_RENDERBUFFER_SIZE); use a larger --patch-size (about {suggest} \
         scene units or more) or fewer --patches"
    )]
    AtlasTooLarge {
        width: u32,
        height: u32,
        max: i32,
        suggest: f32,
    },
    #[error("an atlas of {got} floats was given where the layout has {expected}")]
    AtlasSize { expected: usize, got: usize },
    #[error("--tessellate {0} must be 0 (off) or a positive number of patch sizes")]
    Tessellation(f32),
    #[error("--hemi-res {res} is outside 16..={max}")]
    HemiRes { res: u32, max: i32 },
    #[error(
        "the emitters have no patches at this patch size ({size} scene units): a light smaller \
         than a patch emits nothing; use a smaller --patch-size or more --patches"
    )]
    NoEmission { size: f32 },
}

/// Wall-clock seconds spent in each named pass (draw calls are asynchronous: a pass's GPU time
/// shows up where the next readback waits for it).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct PassTimes {
    pub find_max_energy: f64,
    pub visibility: f64,
    pub reconstruction: f64,
    pub readback: f64,
    pub accumulation: f64,
}

pub struct GpuSolver<'a> {
    ctx: &'a GlContext,
    scene: &'a Scene,
    /// The caller's layout, in which the atlases are handed out.
    layout: &'a PatchLayout,
    /// The same lightmaps without gutters, in which the passes work.
    dense: PatchLayout,
    /// The scene with the caller's lightmap coordinates, for display.
    display_mesh: Mesh,
    visibility_mesh: SceneMesh,
    pub visibility: VisibilityPass,
    pub reconstruction: ReconstructionPass,
    lightmaps: Lightmaps,
    options: SolveOptions,
    patch_area: Vec<f64>,
    emitted_power: f64,
    totals: EnergyTotals,
    /// The polygons a shot changed (the reconstruction passes' receivers and the shooter).
    changed: Vec<usize>,
    scratch: Vec<f32>,
    shots: u32,
    /// Visibility + reconstruction pass pairs run so far (one per shooter cell).
    pub passes: u32,
    started: Instant,
    pub history: Vec<ShotRecord>,
    pub times: PassTimes,
    /// Patches per polygon as the rasterizer drew them.
    pub gpu_patches: Vec<u32>,
}

impl<'a> GpuSolver<'a> {
    pub fn new(
        ctx: &'a GlContext,
        scene: &'a Scene,
        layout: &'a PatchLayout,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let max = ctx
            .info
            .max_texture_size
            .min(ctx.info.max_renderbuffer_size);
        let public = layout;
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
        if options.hemi_res < 16 || options.hemi_res as i64 > max as i64 {
            return Err(SolveError::HemiRes {
                res: options.hemi_res,
                max,
            });
        }
        if !(options.tessellation >= 0.0 && options.tessellation.is_finite()) {
            return Err(SolveError::Tessellation(options.tessellation));
        }
        let gl = &ctx.gl;
        let mesh = mesh::upload(gl, &mesh::vertex_data(scene, layout))?;
        let display_mesh = mesh::upload(gl, &mesh::vertex_data(scene, public))?;
        let n = scene.polygons.len();
        let mut visibility = VisibilityPass::new(
            ctx,
            options.visibility,
            options.hemi_res,
            options.tuning,
            scene,
        )?;
        let data = if options.tessellation > 0.0 {
            let size = options.tessellation * layout.patch_size;
            mesh::tessellated_data(scene, layout, size)
        } else if options.visibility == VisibilityKind::Hemicube && options.robust_visibility {
            // Plates: the robust test reads the shown polygon's plane, which a plate shares.
            mesh::plate_data(scene, layout, visibility.merge_plates(scene))
        } else {
            mesh::vertex_data(scene, layout)
        };
        let visibility_mesh = mesh::upload_scene(gl, &data, n)?;
        let reconstruction = ReconstructionPass::new(ctx, scene, layout)?;
        let lightmaps = Lightmaps::new(ctx, w as i32, h as i32)?;

        // Initialise: every patch's unshot energy is its emission.
        reconstruction.emit(ctx, &mesh)?;
        reconstruction.copy_into(ctx, &lightmaps)?;
        let mut scratch = Vec::new();
        lightmaps.unshot.read_f32(&mut scratch);
        let counted = EnergyTotals::sum(&scratch, n, None);
        // Equal shares of the polygon's area, so that Σ patch areas = polygon area exactly.
        let patch_area: Vec<f64> = scene
            .polygons
            .iter()
            .zip(&counted.patches)
            .map(|(p, &k)| if k > 0 { p.area as f64 / k as f64 } else { 0.0 })
            .collect();
        let totals = EnergyTotals::sum(&scratch, n, Some(&patch_area));
        let emitted_power = totals.total_power();
        if emitted_power <= 0.0 {
            return Err(SolveError::NoEmission {
                size: layout.patch_size,
            });
        }
        Ok(GpuSolver {
            ctx,
            scene,
            layout: public,
            dense,
            display_mesh,
            visibility_mesh,
            visibility,
            reconstruction,
            lightmaps,
            options,
            patch_area,
            emitted_power,
            totals,
            changed: Vec::new(),
            scratch,
            shots: 0,
            passes: 0,
            started: Instant::now(),
            history: Vec::new(),
            times: PassTimes::default(),
            gpu_patches: counted.patches,
        })
    }

    pub fn shots(&self) -> u32 {
        self.shots
    }

    pub fn emitted_power(&self) -> f64 {
        self.emitted_power
    }

    pub fn unshot_fraction(&self) -> f64 {
        self.totals.total_power() / self.emitted_power
    }

    pub fn converged(&self) -> bool {
        self.unshot_fraction() <= self.options.threshold as f64
            || self.shots >= self.options.max_shots
    }

    /// Find_Max_Energy: the polygon with the most unshot power.
    pub fn next_polygon(&self) -> Option<usize> {
        self.totals.find_max_energy(0.0)
    }

    /// The shooters that carry polygon `p`'s unshot energy (see `shooters::shooters_of`), their
    /// texels in the caller's layout (as a `CpuSolver` on that layout takes them).
    pub fn shooters_of(&self, p: usize) -> Vec<Shooter> {
        let mut shooters = shooters::shooters_of(
            self.scene,
            &self.dense,
            &self.options,
            &self.scratch,
            &self.patch_area,
            &self.totals,
            p,
        );
        for s in &mut shooters {
            s.texels = move_rect(
                s.texels,
                &self.dense.lightmaps[p],
                &self.layout.lightmaps[p],
            );
        }
        shooters
    }

    /// One shot; `None` once the stopping rule holds (or nothing is left to shoot).
    pub fn step(&mut self) -> Result<Option<ShotRecord>, SolveError> {
        if self.converged() {
            return Ok(None);
        }
        let t = Instant::now();
        let Some(p) = self.next_polygon() else {
            return Ok(None);
        };
        let shooters = self.shooters_of(p);
        self.times.find_max_energy += t.elapsed().as_secs_f64();
        self.shoot(&shooters).map(Some)
    }

    /// One shot of one polygon, from each of `shooters` in turn (all of the same polygon): a
    /// visibility pass, a reconstruction pass and the copies per shooter, then one readback.
    pub fn shoot(&mut self, shooters: &[Shooter]) -> Result<ShotRecord, SolveError> {
        let ctx = self.ctx;
        let polygon = shooters.first().map(|s| s.polygon).unwrap_or(0);
        let before = self.totals.total_power();
        let shot_power: f64 = shooters.iter().map(|s| s.power()).sum();
        self.changed.clear();
        for shooter in shooters {
            let p = shooter.polygon;
            let shooter = &Shooter {
                texels: move_rect(
                    shooter.texels,
                    &self.layout.lightmaps[p],
                    &self.dense.lightmaps[p],
                ),
                ..*shooter
            };
            let t = Instant::now();
            self.visibility.run(ctx, &self.visibility_mesh, shooter)?;
            let t1 = Instant::now();
            self.reconstruction.run(
                ctx,
                &self.visibility,
                &self.lightmaps,
                shooter,
                &self.options,
            )?;
            let t2 = Instant::now();
            self.changed.extend_from_slice(&self.reconstruction.touched);
            self.reconstruction.copy_into(ctx, &self.lightmaps)?;
            self.times.visibility += (t1 - t).as_secs_f64();
            self.times.reconstruction += (t2 - t1).as_secs_f64();
            self.times.accumulation += t2.elapsed().as_secs_f64();
            self.passes += 1;
        }
        let t = Instant::now();
        // Find_Max_Energy reads what the copies put into the unshot lightmap texture.
        self.lightmaps.unshot.read_f32(&mut self.scratch);
        let t1 = Instant::now();
        self.changed.sort_unstable();
        self.changed.dedup();
        self.totals.update(
            &self.scratch,
            self.dense.atlas_width as usize,
            self.reconstruction.texels(),
            &self.changed,
            &self.patch_area,
        );
        self.times.readback += (t1 - t).as_secs_f64();
        self.times.find_max_energy += t1.elapsed().as_secs_f64();

        self.shots += 1;
        let record = ShotRecord {
            shot: self.shots,
            shooter: polygon,
            seconds: self.started.elapsed().as_secs_f64(),
            unshot_fraction: self.unshot_fraction(),
            shot_power,
            // What the receivers gained: the new total, less what was left unshot.
            reflected_power: self.totals.total_power() - (before - shot_power),
        };
        self.history.push(record.clone());
        Ok(record)
    }

    /// Run to the stopping rule; `progress` sees every shot.
    pub fn solve(&mut self, mut progress: impl FnMut(&ShotRecord)) -> Result<(), SolveError> {
        self.started = Instant::now();
        while let Some(record) = self.step()? {
            progress(&record);
        }
        Ok(())
    }

    /// The accumulated radiance atlas in the caller's layout, RGBA (alpha: polygon ID + 1),
    /// rows bottom to top.
    pub fn radiosity_atlas(&self) -> Vec<f32> {
        let mut out = Vec::new();
        self.lightmaps.radiosity.read_f32(&mut out);
        self.dense.move_atlas(&out, 4, self.layout)
    }

    /// Replace both lightmaps with atlases in the caller's layout (RGBA as `radiosity_atlas` and
    /// `unshot_atlas` give them, alpha the polygon ID + 1), e.g. to resume a saved solve; the
    /// unshot totals are read back from the new texture, so Find_Max_Energy picks from them.
    pub fn load_atlases(&mut self, radiosity: &[f32], unshot: &[f32]) -> Result<(), SolveError> {
        let texels = self.layout.atlas_width as usize * self.layout.atlas_height as usize * 4;
        if radiosity.len() != texels || unshot.len() != texels {
            return Err(SolveError::AtlasSize {
                expected: texels,
                got: radiosity.len().max(unshot.len()),
            });
        }
        self.lightmaps
            .radiosity
            .upload_f32(&self.layout.move_atlas(radiosity, 4, &self.dense));
        self.lightmaps
            .unshot
            .upload_f32(&self.layout.move_atlas(unshot, 4, &self.dense));
        self.reconstruction.load_from(self.ctx, &self.lightmaps)?;
        self.lightmaps.unshot.read_f32(&mut self.scratch);
        self.totals = EnergyTotals::sum(
            &self.scratch,
            self.scene.polygons.len(),
            Some(&self.patch_area),
        );
        Ok(())
    }

    /// The unshot radiance atlas as last read back, in the caller's layout (RGBA, alpha:
    /// polygon ID + 1).
    pub fn unshot_atlas(&self) -> Vec<f32> {
        self.dense.move_atlas(&self.scratch, 4, self.layout)
    }

    pub fn patch_area(&self, polygon: usize) -> f64 {
        self.patch_area[polygon]
    }

    /// The scene for displaying `radiosity_atlas` (the caller's layout).
    pub fn mesh(&self) -> &Mesh {
        &self.display_mesh
    }

    /// Restart the clock of the history's `seconds`, as `solve` does (for callers that drive
    /// `step` themselves: the pass pictures, the viewer).
    pub fn restart_clock(&mut self) {
        self.started = Instant::now();
    }

    /// Keep `elapsed` (time spent between shots on something else: writing pictures, drawing
    /// the viewer's frames) out of the history's `seconds`.
    pub fn exclude_time(&mut self, elapsed: std::time::Duration) {
        self.started += elapsed;
    }

    /// Change the stopping rule's threshold (unshot power / emitted power) between shots.
    pub fn set_threshold(&mut self, threshold: f32) {
        self.options.threshold = threshold;
    }
}

/// A texel rectangle of lightmap `from` at the same place in `to` (the same lightmap elsewhere).
fn move_rect(r: [u32; 4], from: &Lightmap, to: &Lightmap) -> [u32; 4] {
    let (x, y) = (|t: u32| t - from.x + to.x, |t: u32| t - from.y + to.y);
    [x(r[0]), y(r[1]), x(r[2]), y(r[3])]
}
