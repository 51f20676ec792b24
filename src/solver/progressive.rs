//! The progressive refinement loop of section 3.2, on the GPU:
//!
//! ```text
//! initialise the unshot energy E of every patch (its emission)
//! while not converged:
//!     shooter = Find_Max_Energy()              -- CPU, from the unshot atlas
//!     visibility pass from the shooter         -- item buffer (texture attachment)
//!     reconstruction pass over all receivers   -- ΔE = ρ·F·E (renderbuffer attachments)
//!     copy the sums into the lightmaps         -- glCopyTexSubImage2D
//!     (the shooter's unshot energy is cleared in the same pass)
//! ```

use super::find_max_energy::EnergyTotals;
use super::reconstruction::{Lightmaps, ReconstructionPass};
use super::visibility::VisibilityPass;
use super::MAX_CORNERS;
use super::{mesh, Shooter, ShotRecord, SolveOptions};
use crate::gl::{GlContext, GlError, Mesh};
use crate::patches::PatchLayout;
use crate::patches::{clip_convex, signed_area, Lightmap};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use std::time::Instant;

/// Lightmap-space outline → world corners (padded to MAX_CORNERS), their count and world area.
fn world_outline(lm: &Lightmap, outline: &[Vec2]) -> ([Vec3; MAX_CORNERS], usize, f32) {
    let mut corners = [Vec3::ZERO; MAX_CORNERS];
    for (c, p) in corners.iter_mut().zip(outline) {
        *c = lm.world(p.x, p.y);
    }
    (
        corners,
        outline.len().min(MAX_CORNERS),
        signed_area(outline).abs() * lm.texel_area(),
    )
}

#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error(transparent)]
    Gl(#[from] GlError),
    #[error(
        "the lightmap atlas needs {width}x{height} texels but this driver allows at most {max}x{max} \
         (GL_MAX_TEXTURE_SIZE / GL_MAX_RENDERBUFFER_SIZE); use a larger --patch-size (about {suggest:.4} \
         scene units or more) or fewer --patches"
    )]
    AtlasTooLarge {
        width: u32,
        height: u32,
        max: i32,
        suggest: f32,
    },
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
    layout: &'a PatchLayout,
    mesh: Mesh,
    visibility_mesh: Mesh,
    pub visibility: VisibilityPass,
    reconstruction: ReconstructionPass,
    lightmaps: Lightmaps,
    options: SolveOptions,
    patch_area: Vec<f64>,
    emitted_power: f64,
    totals: EnergyTotals,
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
        let (w, h) = (layout.atlas_width, layout.atlas_height);
        if w as i64 > max as i64 || h as i64 > max as i64 {
            let scale = (w.max(h) as f32 / max as f32) * 1.05;
            return Err(SolveError::AtlasTooLarge {
                width: w,
                height: h,
                max,
                suggest: layout.patch_size * scale,
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
        let (lo, hi) = scene.bounds();
        let mesh = mesh::upload(gl, &mesh::vertex_data(scene, layout))?;
        let visibility_mesh = if options.tessellation > 0.0 {
            mesh::upload(
                gl,
                &mesh::tessellated_data(scene, layout, options.tessellation * layout.patch_size),
            )?
        } else {
            mesh::upload(gl, &mesh::vertex_data(scene, layout))?
        };
        let visibility = VisibilityPass::new(
            ctx,
            options.visibility,
            options.hemi_res,
            (hi - lo).length(),
        )?;
        let reconstruction = ReconstructionPass::new(ctx, w as i32, h as i32)?;
        let lightmaps = Lightmaps::new(ctx, w as i32, h as i32)?;

        // Initialise: every patch's unshot energy is its emission.
        reconstruction.emit(ctx, &mesh)?;
        let mut scratch = Vec::new();
        reconstruction.read_unshot(&mut scratch);
        reconstruction.copy_into(ctx, &lightmaps)?;
        let n = scene.polygons.len();
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
            layout,
            mesh,
            visibility_mesh,
            visibility,
            reconstruction,
            lightmaps,
            options,
            patch_area,
            emitted_power,
            totals,
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

    /// The shooters that carry polygon `p`'s unshot energy: the whole polygon from its centroid
    /// (the paper), or one shooter per cell of `shooter_cell`² patches, each at the mean position
    /// of its patches with the cell's own unshot energy.
    pub fn shooters_of(&self, p: usize) -> Vec<Shooter> {
        let polygon = &self.scene.polygons[p];
        let lm = &self.layout.lightmaps[p];
        let cell = self.options.shooter_cell;
        let outline: Vec<Vec2> = polygon.vertices.iter().map(|&v| lm.texel_of(v)).collect();
        if cell == 0 {
            let rect = [
                Vec2::ZERO,
                Vec2::new(lm.w as f32, 0.0),
                Vec2::new(lm.w as f32, lm.h as f32),
                Vec2::new(0.0, lm.h as f32),
            ];
            let corners = if outline.len() <= MAX_CORNERS {
                &outline[..]
            } else {
                &rect[..]
            };
            let (corners, corner_count, area) = world_outline(lm, corners);
            return vec![Shooter {
                polygon: p,
                texels: [lm.x, lm.y, lm.x + lm.w, lm.y + lm.h],
                position: polygon.centroid,
                normal: polygon.normal,
                energy: self.totals.energy_rgb(p),
                corners,
                corner_count,
                area,
            }];
        }
        let width = self.layout.atlas_width as usize;
        let patch_area = self.patch_area[p];
        let mut shooters = Vec::new();
        for y0 in (0..lm.h).step_by(cell as usize) {
            for x0 in (0..lm.w).step_by(cell as usize) {
                let (x1, y1) = ((x0 + cell).min(lm.w), (y0 + cell).min(lm.h));
                // Shoot from the cell's energy-weighted centre: patches with nothing to shoot (e.g.
                // buried under a block standing on the floor) do not move the shooter under it.
                let (mut energy, mut position, mut weight) = ([0f64; 3], Vec3::ZERO, 0f32);
                for t in y0..y1 {
                    for s in x0..x1 {
                        let at = ((lm.y + t) as usize * width + (lm.x + s) as usize) * 4;
                        let texel = &self.scratch[at..at + 4];
                        if texel[3] as usize != p + 1 {
                            continue;
                        }
                        for c in 0..3 {
                            energy[c] += texel[c] as f64 * patch_area;
                        }
                        let w = texel[0] + texel[1] + texel[2];
                        position += w * lm.world(s as f32 + 0.5, t as f32 + 0.5);
                        weight += w;
                    }
                }
                if weight <= 0.0 {
                    continue;
                }
                // The cell's outline: its rectangle clipped to the polygon (the rectangle itself
                // where the polygon is not convex or the clip has too many corners).
                let (fx0, fy0, fx1, fy1) = (x0 as f32, y0 as f32, x1 as f32, y1 as f32);
                let rect = [
                    Vec2::new(fx0, fy0),
                    Vec2::new(fx1, fy0),
                    Vec2::new(fx1, fy1),
                    Vec2::new(fx0, fy1),
                ];
                let clipped = clip_convex(&rect, &outline)
                    .filter(|c| c.len() >= 3 && c.len() <= MAX_CORNERS && signed_area(c) > 0.0);
                let (corners, corner_count, area) =
                    world_outline(lm, clipped.as_deref().unwrap_or(&rect));
                shooters.push(Shooter {
                    polygon: p,
                    texels: [lm.x + x0, lm.y + y0, lm.x + x1, lm.y + y1],
                    position: position / weight,
                    normal: polygon.normal,
                    energy: Vec3::new(energy[0] as f32, energy[1] as f32, energy[2] as f32),
                    corners,
                    corner_count,
                    area,
                });
            }
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
        for shooter in shooters {
            let t = Instant::now();
            self.visibility.run(ctx, &self.visibility_mesh, shooter)?;
            let t1 = Instant::now();
            self.reconstruction.run(
                ctx,
                &self.mesh,
                &self.visibility,
                &self.lightmaps,
                shooter,
                &self.options,
            )?;
            let t2 = Instant::now();
            self.reconstruction.copy_into(ctx, &self.lightmaps)?;
            self.times.visibility += (t1 - t).as_secs_f64();
            self.times.reconstruction += (t2 - t1).as_secs_f64();
            self.times.accumulation += t2.elapsed().as_secs_f64();
            self.passes += 1;
        }
        let t = Instant::now();
        self.reconstruction.read_unshot(&mut self.scratch);
        let t1 = Instant::now();
        self.totals = EnergyTotals::sum(
            &self.scratch,
            self.scene.polygons.len(),
            Some(&self.patch_area),
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

    /// The accumulated radiance atlas, RGBA (alpha: polygon ID + 1), rows bottom to top.
    pub fn radiosity_atlas(&self) -> Vec<f32> {
        let mut out = Vec::new();
        self.lightmaps.radiosity.read_f32(&mut out);
        out
    }

    /// The unshot radiance atlas as last read back (RGBA, alpha: polygon ID + 1).
    pub fn unshot_atlas(&self) -> &[f32] {
        &self.scratch
    }

    pub fn patch_area(&self, polygon: usize) -> f64 {
        self.patch_area[polygon]
    }

    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }
}
