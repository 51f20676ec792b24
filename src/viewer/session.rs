//! One solve in the viewer: the `GpuSolver` (the same one `radiosity solve` runs), and the
//! textures each frame draws from, refreshed after every batch of shots. Rebuilt on reset, so
//! it borrows the context, scene and layout of the frame loop.

use super::camera::OrbitCamera;
use super::overlays::{inset_rect, Inset, Insets, OverlaySet, HEAT_DECADES};
use super::ViewMode;
use crate::display::{scene_view_projection, DisplayMesh, DisplayPass, Smoothing, Viewport};
use crate::gl::{GlContext, GlError, Texture, TextureFormat};
use crate::glsl;
use crate::patches::PatchLayout;
use crate::scene::Scene;
use crate::solver::{GpuSolver, SolveError, SolveOptions, TuningChoice};
use std::time::{Duration, Instant};

pub struct Session<'a> {
    pub solver: GpuSolver<'a>,
    pub mode: ViewMode,
    pub layout: &'a PatchLayout,
    /// The display pass with the viewer's shaders; its lightmap is the dilated radiance atlas.
    display: DisplayPass,
    /// The scene with the layout's lightmap coordinates and its smooth edges.
    mesh: DisplayMesh,
    /// The radiance atlas as solved (not dilated), for the atlas inset.
    atlas: Texture,
    /// The unshot atlas, for the heat map.
    unshot: Texture,
    /// log10 of the largest unshot radiance of a patch (the heat map's white).
    pub heat_log_max: f32,
    /// When the last batch of shots ended: the time until the next is kept off the solver's clock.
    idle_since: Instant,
}

impl<'a> Session<'a> {
    pub fn new(
        ctx: &'a GlContext,
        scene: &'a Scene,
        layout: &'a PatchLayout,
        (mode, tuning): (ViewMode, TuningChoice),
        threshold: f32,
        smooth_angle: f32,
    ) -> Result<Session<'a>, SolveError> {
        // Resolved on the window's renderer, per session: switching to the paper's mode (M)
        // takes the paper's passes unless --tuning names a profile.
        let chosen = tuning.resolve(mode == ViewMode::Paper, Some(&ctx.info.renderer));
        eprintln!("{}", chosen.line());
        let options = SolveOptions {
            threshold,
            tuning: chosen.tuning(),
            ..mode.options()
        };
        let mut solver = GpuSolver::new(ctx, scene, layout, options)?;
        let size = (layout.atlas_width, layout.atlas_height);
        let display =
            DisplayPass::with_shaders(ctx, size, glsl!("viewer.vert"), glsl!("viewer.frag"))?;
        let texture = || {
            Texture::new(
                &ctx.gl,
                size.0 as i32,
                size.1 as i32,
                TextureFormat::Rgba32F,
                glow::NEAREST,
            )
        };
        let (atlas, unshot) = (texture()?, texture()?);
        let smoothing = Smoothing::new(scene, layout, smooth_angle);
        let mesh = DisplayMesh::new(&ctx.gl, scene, layout, smoothing)?;
        solver.restart_clock();
        let mut session = Session {
            solver,
            mode,
            layout,
            display,
            mesh,
            atlas,
            unshot,
            heat_log_max: 0.0,
            idle_since: Instant::now(),
        };
        session.refresh();
        Ok(session)
    }

    /// Up to `max_shots` shots, fewer if `budget` runs out first (at least one unless
    /// converged). Returns the number taken; the textures are refreshed when it is not 0.
    pub fn advance(&mut self, max_shots: u32, budget: Duration) -> Result<u32, SolveError> {
        self.solver.exclude_time(self.idle_since.elapsed());
        let start = Instant::now();
        let mut taken = 0;
        while taken < max_shots && (taken == 0 || start.elapsed() < budget) {
            if self.solver.step()?.is_none() {
                break;
            }
            taken += 1;
        }
        // From here on (reading the atlases back too) the time is the viewer's, not the solver's.
        self.idle_since = Instant::now();
        if taken > 0 {
            self.refresh();
        }
        Ok(taken)
    }

    /// Read the atlases back and upload them for display (dilated, as `solve` renders them).
    fn refresh(&mut self) {
        let mut radiance = self.solver.radiosity_atlas();
        self.atlas.upload_f32(&radiance);
        self.layout.dilate(&mut radiance);
        self.display.upload(&radiance);
        let (w, h) = (self.layout.atlas_width, self.layout.atlas_height);
        self.mesh.update(&radiance, w, h);
        let unshot = self.solver.unshot_atlas();
        self.unshot.upload_f32(&unshot);
        let max = unshot
            .chunks_exact(4)
            .filter(|t| t[3] > 0.0)
            .map(|t| (t[0] + t[1] + t[2]) / 3.0)
            .fold(0.0f32, f32::max);
        self.heat_log_max = if max > 0.0 { max.log10() } else { 0.0 };
    }

    /// The polygon whose item buffer is shown: the last shot's shooter.
    pub fn last_shooter(&self) -> Option<usize> {
        self.solver.history().last().map(|r| r.shooter)
    }

    /// The polygon Find_Max_Energy picks for the next shot (none once converged).
    pub fn next_shooter(&self) -> Option<usize> {
        (!self.solver.converged())
            .then(|| self.solver.next_polygon())
            .flatten()
    }

    /// The lit scene (with the in-scene overlays) into `view` of the window.
    pub fn draw_scene(
        &self,
        ctx: &GlContext,
        scene: &Scene,
        camera: &OrbitCamera,
        view: Viewport,
        overlays: OverlaySet,
        exposure: f32,
    ) -> Result<(), GlError> {
        let vp = scene_view_projection(scene, &camera.camera, view.aspect());
        let id = |p: Option<usize>| match p {
            Some(p) if overlays.shooter => p as f32,
            _ => -1.0,
        };
        let (last, next) = (id(self.last_shooter()), id(self.next_shooter()));
        let (w, h) = (self.layout.atlas_width, self.layout.atlas_height);
        self.display.run(ctx, &self.mesh, vp, None, view, |p| {
            self.unshot.bind(1);
            p.set_i32("Unshot", 1);
            p.set_vec2("AtlasSize", [w as f32, h as f32]);
            p.set_f32("Exposure", exposure);
            p.set_i32("HeatMap", overlays.heat_map as i32);
            p.set_f32("HeatMax", self.heat_log_max);
            p.set_f32("HeatDecades", HEAT_DECADES);
            p.set_i32("Borders", overlays.borders as i32);
            p.set_f32("LastShooter", last);
            p.set_f32("NextShooter", next);
        })
    }

    /// The item-buffer and atlas insets that are on, in the corners of `view`.
    pub fn draw_insets(
        &self,
        ctx: &GlContext,
        insets: &Insets,
        view: Viewport,
        overlays: OverlaySet,
        exposure: f32,
    ) -> Result<(), GlError> {
        if overlays.item_buffer && self.last_shooter().is_some() {
            let item = &self.solver.backend().visibility.item_buffer();
            if let Some(rect) = inset_rect(view, (item.width, item.height), true) {
                insets.draw(ctx, item, Inset::ItemBuffer, rect)?;
            }
        }
        if overlays.atlas {
            let (texture, what) = if overlays.heat_map {
                let log_max = self.heat_log_max;
                (&self.unshot, Inset::Heat { log_max })
            } else {
                (&self.atlas, Inset::Radiance { exposure })
            };
            let size = (texture.width, texture.height);
            if let Some(rect) = inset_rect(view, size, false) {
                insets.draw(ctx, texture, what, rect)?;
            }
        }
        Ok(())
    }
}
