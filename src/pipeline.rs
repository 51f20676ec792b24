//! The library's front door: the whole pipeline of the paper in a few calls, for the command
//! line, the viewer, the golden check and any program of yours.
//!
//! ```no_run
//! use gpu_radiosity::gl::{BackendChoice, GlContext};
//! use gpu_radiosity::pipeline::{self, Mode, SolverKind};
//!
//! # fn main() -> anyhow::Result<()> {
//! let (scene, _) = pipeline::load_scene(None)?;             // the built-in Cornell box
//! let layout = pipeline::lay_out(&scene, None, None)?;      // ~4,096 patches
//! let ctx = GlContext::headless(BackendChoice::Auto)?;      // EGL or OSMesa, no display
//! let options = Mode::Accurate.options();
//! let solution = pipeline::solve(&ctx, &scene, &layout, SolverKind::Gpu, options, 0, |_| {})?;
//! let image = pipeline::render(&ctx, &scene, &layout, &solution.display_atlas(&scene, &layout, false).0,
//!                              &scene.camera_or_default(), (512, 512))?;
//! gpu_radiosity::display::output::write_png("cornell.png".as_ref(), &image, 1.0)?;
//! # Ok(()) }
//! ```
//!
//! scene ([`load_scene`]) → patches ([`lay_out`]) → solver ([`solve`], or a
//! [`Solver`] driven shot by shot) → display ([`render`], [`write_outputs`]).

use crate::display::output::{self, Payload};
use crate::display::output_set::OutputSet;
use crate::display::{self, DisplayMesh, Image, Smoothing};
use crate::gl::{limits, GlContext, GlError, GlInfo, LimitError};
use crate::patches::{LayoutError, PatchLayout, Resolution};
use crate::scene::{bundled, Camera, Emission, LoadOptions, Scene, SceneError, SkyStats};
use crate::solver::{
    visibility, Backend, ChosenTuning, CpuSolver, GpuSolver, PassTimes, ShotRecord, SolveError,
    SolveOptions, Solver, VisibilityKind,
};
use glam::Vec3;
use std::path::{Path, PathBuf};

/// Patches when neither the caller nor the scene says otherwise, for a scene of few polygons.
pub const DEFAULT_PATCHES: u32 = 4096;

/// Scenes of more polygons than this get [`default_patches`] beyond [`DEFAULT_PATCHES`].
pub const FEW_POLYGONS: usize = DEFAULT_PATCHES as usize / 8;

/// The default patch budget: [`DEFAULT_PATCHES`], and for a scene of many polygons (more than
/// [`FEW_POLYGONS`]) two more per polygon. Every polygon gets at least one patch whatever the
/// size, so a fixed budget below the polygon count would make every face one flat texel, the
/// largest walls included (a 40,000-triangle room came out one texel per face, patch size
/// larger than the scene); two per polygon leave at least half the patches to the surfaces
/// larger than a patch, in proportion to their area.
pub fn default_patches(scene: &Scene) -> u32 {
    // The sky's quads (`--sky`) have their own patch each, outside the budget.
    let polygons = scene.own_polygons().len();
    if polygons <= FEW_POLYGONS {
        DEFAULT_PATCHES
    } else {
        let budget = DEFAULT_PATCHES as u64 + 2 * polygons as u64;
        budget.min(u32::MAX as u64) as u32
    }
}

/// Which solver computes the radiosity.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SolverKind {
    /// The paper's passes on OpenGL.
    Gpu,
    /// The same algorithm in Rust, with exact ray-cast visibility (rayon).
    Cpu,
}

/// The two sets of solver settings: the paper literally, or with the corrections of
/// paper_notes.md.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// The paper as written (`SolveOptions::paper`).
    Paper,
    /// With the corrections and speed options (`SolveOptions::accurate`): the default.
    Accurate,
}

impl Mode {
    /// Its solver settings.
    pub fn options(self) -> SolveOptions {
        match self {
            Mode::Paper => SolveOptions::paper(),
            Mode::Accurate => SolveOptions::accurate(),
        }
    }

    /// Its name on the command line and in stats.json.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Paper => "paper",
            Mode::Accurate => "accurate",
        }
    }
}

/// Settings a solve cannot run with, in the library's terms.
#[derive(Debug, thiserror::Error)]
pub enum SettingsError {
    /// A stopping threshold outside (0, 1).
    #[error("the threshold {0} must be between 0 and 1 (exclusive)")]
    Threshold(f32),
    /// A patch size that is not a positive number.
    #[error("the patch size {0} must be a positive number of scene units")]
    PatchSize(f32),
    /// A patch count of zero.
    #[error("the patch count must be at least 1")]
    Patches,
}

/// The light reached nothing that reflects it: a scene error (most often emitters wound
/// backwards), not a black picture to write.
#[derive(Debug, thiserror::Error)]
#[error("the light reaches no surface that reflects it: {cause}")]
pub struct LightReachesNothing {
    /// The emitting objects, comma-separated.
    pub lights: String,
    /// Why, as far as the geometry tells.
    pub cause: String,
}

/// Check the stopping rule's threshold (0 < t < 1) and the patch resolution the caller asks for.
pub fn check_settings(
    threshold: f32,
    patch_size: Option<f32>,
    patches: Option<u32>,
) -> Result<(), SettingsError> {
    if !(threshold > 0.0 && threshold < 1.0) {
        return Err(SettingsError::Threshold(threshold));
    }
    if let Some(s) = patch_size {
        if !(s > 0.0 && s.is_finite()) {
            return Err(SettingsError::PatchSize(s));
        }
    }
    if patches == Some(0) {
        return Err(SettingsError::Patches);
    }
    Ok(())
}

/// A render target whose size a setting decides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// The lightmap atlas (patch size or count): both solvers' display draws from it.
    Atlas,
    /// The GPU solver's item buffer (its resolution).
    ItemBuffer,
    /// The picture (its size).
    Image,
}

/// A render target this driver cannot hold, and which one.
#[derive(Debug, thiserror::Error)]
#[error("{error}")]
pub struct TargetTooLarge {
    /// The target (atlas, item buffer, image).
    pub target: Target,
    /// The limit it runs into.
    pub error: LimitError,
}

/// Refuse, before any solving, the render targets this driver cannot hold: the lightmap atlas
/// (RGBA32F), the GPU solver's item buffer (RGBA8) and the `image` (RGBA32F). Each is checked
/// against the GL size limits and made once (see [`crate::gl::limits`]).
pub fn check_limits(
    ctx: &GlContext,
    layout: &PatchLayout,
    kind: SolverKind,
    options: &SolveOptions,
    image: (u32, u32),
) -> Result<(), TargetTooLarge> {
    let at = |target| move |error| TargetTooLarge { target, error };
    let (w, h) = (layout.atlas_width as u64, layout.atlas_height as u64);
    limits::check_target(ctx, "lightmap atlas", w, h, glow::RGBA32F).map_err(at(Target::Atlas))?;
    if kind == SolverKind::Gpu {
        let (w, h) = visibility::item_buffer_size(options.visibility, options.hemi_res);
        let what = match options.visibility {
            VisibilityKind::Hemicube => "item buffer (five hemicube faces side by side)",
            VisibilityKind::Hemisphere => "item buffer",
        };
        limits::check_target(ctx, what, w, h, glow::RGBA8).map_err(at(Target::ItemBuffer))?;
    }
    let (w, h) = (image.0 as u64, image.1 as u64);
    limits::check_target(ctx, "image", w, h, glow::RGBA32F).map_err(at(Target::Image))
}

/// Load an OBJ scene (with its MTL), or the Cornell box built into the library for `None`;
/// also the path that names it (`<built-in>/cornell/cornell.obj` for the built-in one).
pub fn load_scene(path: Option<&Path>) -> Result<(Scene, PathBuf), SceneError> {
    load_scene_with(path, &LoadOptions::default())
}

/// [`load_scene`] with `options` applied before the check that the scene emits light: emission
/// overrides make materials emitters (`--emit NAME=R,G,B`).
pub fn load_scene_with(
    path: Option<&Path>,
    options: &LoadOptions,
) -> Result<(Scene, PathBuf), SceneError> {
    bundled::load_or_default(path, options)
}

/// The patch resolution: a patch size, else a patch count, else the scene's `# patch-size`,
/// else the default budget ([`default_patches`]).
pub fn resolution(scene: &Scene, patch_size: Option<f32>, patches: Option<u32>) -> Resolution {
    resolution_and_reason(scene, patch_size, patches).0
}

/// [`resolution`], and why, in words for the run's output.
pub fn resolution_and_reason(
    scene: &Scene,
    patch_size: Option<f32>,
    patches: Option<u32>,
) -> (Resolution, String) {
    match (patch_size, patches, scene.patch_size) {
        (Some(s), _, _) => (Resolution::PatchSize(s), "--patch-size".into()),
        (None, Some(n), _) => (Resolution::Patches(n), format!("--patches {n}")),
        (None, None, Some(s)) => (Resolution::PatchSize(s), "the scene's # patch-size".into()),
        (None, None, None) if scene.own_polygons().len() <= FEW_POLYGONS => (
            Resolution::Patches(DEFAULT_PATCHES),
            format!("the default budget of {DEFAULT_PATCHES} patches"),
        ),
        (None, None, None) => (
            Resolution::Patches(default_patches(scene)),
            format!(
                "the default budget for {} polygons: {DEFAULT_PATCHES} + 2 per polygon = {} \
                 patches, so that surfaces larger than a patch keep at least half of them",
                scene.own_polygons().len(),
                default_patches(scene)
            ),
        ),
    }
}

/// Lay out every polygon's lightmap and pack the atlas (see [`resolution`]).
pub fn lay_out(
    scene: &Scene,
    patch_size: Option<f32>,
    patches: Option<u32>,
) -> Result<PatchLayout, LayoutError> {
    PatchLayout::try_new(scene, resolution(scene, patch_size, patches))
}

/// What a solve leaves for display and stats, whichever solver computed it.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Accumulated radiance atlas (RGBA, alpha: polygon ID + 1, rows bottom to top).
    pub radiosity: Vec<f32>,
    /// Unshot radiance atlas, the same way.
    pub unshot: Vec<f32>,
    /// Area of one patch of each polygon.
    pub patch_area: Vec<f64>,
    /// Shots made.
    pub shots: u32,
    /// Visibility + reconstruction pass pairs.
    pub passes: u32,
    /// Unshot power over emitted power at the end.
    pub unshot_fraction: f64,
    /// Emitted power of the scene (radiance × area × π, summed over RGB).
    pub emitted_power: f64,
    /// Seconds per named pass.
    pub pass_seconds: PassTimes,
    /// Each shot's record, in order.
    pub history: Vec<ShotRecord>,
    /// Shots that reflected more than they carried and were scaled back (`SolveOptions::conserve`).
    pub corrections: u32,
    /// Coarse clusters of small coplanar polygons (`SolveOptions::cluster_cell`; each holds
    /// fine ones of the shooter cell's side).
    pub clusters: usize,
    /// Polygons in those clusters.
    pub clustered_polygons: usize,
    /// Shots in which a cluster shot (each one shot).
    pub cluster_shots: u32,
    /// Of those, the shots in which a face cluster shot (`SolveOptions::face_clusters`).
    pub face_cluster_shots: u32,
}

impl Solution {
    /// What `solver` holds now.
    pub fn of<B: Backend>(solver: &Solver<B>) -> Solution {
        Solution {
            radiosity: solver.radiosity_atlas(),
            unshot: solver.unshot_atlas(),
            patch_area: solver.patch_areas().to_vec(),
            shots: solver.shots(),
            passes: solver.passes(),
            corrections: solver.ledger().corrections(),
            clusters: solver.clusters().count(),
            clustered_polygons: solver.clusters().clustered_polygons(),
            cluster_shots: solver.cluster_shots(),
            face_cluster_shots: solver.face_cluster_shots(),
            unshot_fraction: solver.unshot_fraction(),
            emitted_power: solver.emitted_power(),
            pass_seconds: solver.times().clone(),
            history: solver.history().to_vec(),
        }
    }

    /// Seconds the solve took (the last shot's time).
    pub fn solve_seconds(&self) -> f64 {
        self.history.last().map_or(0.0, |r| r.seconds)
    }

    /// Fails if shots were taken and none reflected anything.
    pub fn check_light_reaches(&self, scene: &Scene) -> Result<(), LightReachesNothing> {
        if self.history.is_empty() || self.history.iter().any(|r| r.reflected_power > 0.0) {
            return Ok(());
        }
        let lights: Vec<&str> = scene
            .polygons
            .iter()
            .filter(|p| scene.material(p).is_emitter())
            .map(|p| p.object.as_str())
            .collect();
        let lights = lights.join(", ");
        // Something that reflects, with a corner in front of an emitter: the light does face it,
        // and the receivers' patches were too coarse to catch any (a face smaller than a patch
        // has none). Otherwise the emitters face away, or nothing reflects.
        let slack = scene.plane_slack();
        let faced = scene.polygons.iter().any(|e| {
            scene.material(e).is_emitter()
                && scene.polygons.iter().any(|r| {
                    scene.material(r).kd.max_element() > 0.0
                        && r.vertices.iter().any(|&v| e.plane().distance(v) > slack)
                })
        });
        let cause = if faced {
            format!(
                "surfaces with a reflectance lie in front of the emitters ({lights}) but none of \
                 their patches received light: the patches are too coarse for those surfaces \
                 (a face smaller than a patch has none); use a smaller patch size or more patches"
            )
        } else {
            format!(
                "the emitters ({lights}) face away from everything, or nothing in front of them \
                 has a reflectance (Kd) above 0. Emitters shine from their front face: \
                 counter-clockwise vertex order seen from the front"
            )
        };
        Err(LightReachesNothing { lights, cause })
    }

    /// The atlas to display: the radiance, with Cohen et al.'s (1988) ambient term added if
    /// `ambient` (then also returned), dilated into the gutters for bilinear filtering.
    pub fn display_atlas(
        &self,
        scene: &Scene,
        layout: &PatchLayout,
        ambient: bool,
    ) -> (Vec<f32>, Option<Vec3>) {
        let mut atlas = self.radiosity.clone();
        let term = ambient.then(|| {
            let l = display::ambient::ambient(scene, &self.unshot, &self.patch_area);
            display::ambient::add_ambient(scene, &mut atlas, l);
            l
        });
        layout.dilate(&mut atlas);
        (atlas, term)
    }
}

/// Solve `scene` laid out as `layout` to the stopping rule of `options`, with the GPU solver on
/// `ctx` or the CPU solver on `threads` worker threads (0: one per core); `progress` sees every
/// shot.
pub fn solve(
    ctx: &GlContext,
    scene: &Scene,
    layout: &PatchLayout,
    kind: SolverKind,
    options: SolveOptions,
    threads: usize,
    progress: impl FnMut(&ShotRecord),
) -> Result<Solution, SolveError> {
    solve_until(ctx, scene, layout, kind, options, threads, progress, || {
        false
    })
}

/// [`solve`], also stopped between shots when `stop` says so (an interrupt, a time limit).
#[allow(clippy::too_many_arguments)]
pub fn solve_until(
    ctx: &GlContext,
    scene: &Scene,
    layout: &PatchLayout,
    kind: SolverKind,
    options: SolveOptions,
    threads: usize,
    progress: impl FnMut(&ShotRecord),
    stop: impl FnMut() -> bool,
) -> Result<Solution, SolveError> {
    Ok(match kind {
        SolverKind::Gpu => {
            let mut solver = GpuSolver::new(ctx, scene, layout, options)?;
            solver.solve_until(progress, stop)?;
            Solution::of(&solver)
        }
        SolverKind::Cpu => {
            let mut solver = CpuSolver::new(scene, layout, options, threads)?;
            solver.solve_until(progress, stop)?;
            Solution::of(&solver)
        }
    })
}

/// Draw the lit scene from `camera` into a `size` float image (linear radiance, rows top to
/// bottom), with `atlas` as [`Solution::display_atlas`] gives it, curved surfaces shaded smooth
/// at the default crease angle ([`display::smooth::DEFAULT_ANGLE`]).
pub fn render(
    ctx: &GlContext,
    scene: &Scene,
    layout: &PatchLayout,
    atlas: &[f32],
    camera: &Camera,
    size: (u32, u32),
) -> Result<Image, GlError> {
    let smoothing = Smoothing::new(scene, layout, display::smooth::DEFAULT_ANGLE);
    render_smoothed(ctx, scene, layout, atlas, &smoothing, camera, size)
}

/// [`render`] with the smooth edges of `smoothing` (`Smoothing::new(scene, layout, 0.0)`: none,
/// each polygon its lightmap alone).
pub fn render_smoothed(
    ctx: &GlContext,
    scene: &Scene,
    layout: &PatchLayout,
    atlas: &[f32],
    smoothing: &Smoothing,
    camera: &Camera,
    size: (u32, u32),
) -> Result<Image, GlError> {
    let mut mesh = DisplayMesh::new(&ctx.gl, scene, layout, smoothing.clone())?;
    let atlas_size = (layout.atlas_width, layout.atlas_height);
    mesh.update(atlas, atlas_size.0, atlas_size.1);
    display::render(ctx, scene, &mesh, atlas, atlas_size, camera, size)
}

/// Everything `stats.json` holds (docs/conventions.md's contract, plus timings and settings).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Stats {
    /// The scene's file, as the user named it (or the bundled scene's name).
    pub scene: String,
    /// Faces of the file...
    pub faces: usize,
    /// ...and the polygons they became (connected coplanar faces of one material merged).
    pub polygons: usize,
    /// Vertices of the file.
    pub vertices: usize,
    /// Polygons of emitting materials.
    pub lights: usize,
    /// Patches of the layout.
    pub patches: u64,
    /// Patch size, scene units.
    pub patch_size: f32,
    /// The atlas's width and height, texels.
    pub atlas: [u32; 2],
    /// Which solver ran.
    pub solver: SolverKind,
    /// The mode's settings the run started from.
    pub mode: Mode,
    /// The GL backend (`egl`, `osmesa`).
    pub backend: &'static str,
    /// GL_VENDOR.
    pub gl_vendor: String,
    /// GL_RENDERER.
    pub gl_renderer: String,
    /// GL_VERSION.
    pub gl_version: String,
    /// The tuning profile that ran (`paper`, `llvmpipe`, `gpu`; `none` for the CPU solver):
    /// `--tuning`, resolved by renderer (`solver::profile`). Its switches are in
    /// `tuning_switches`.
    pub tuning: &'static str,
    /// Why that profile (e.g. `auto: renderer '…' is Mesa's software rasteriser`).
    pub tuning_reason: String,
    /// threshold, max_shots and the pass settings.
    #[serde(flatten)]
    pub options: SolveOptions,
    /// Emission overrides applied after loading (`--emit`), in order.
    pub emit: Vec<Emission>,
    /// Beyond the paper, the sky (`--sky`): its radiance, quads and patches, which `polygons`,
    /// `lights` and `patches` leave out.
    pub sky: Option<SkyStats>,
    /// Shots made.
    pub shots: u32,
    /// Visibility + reconstruction pass pairs (one per shooter cell of each shot).
    pub passes: u32,
    /// Shots scaled back because they reflected more than they carried (`SolveOptions::conserve`).
    pub corrections: u32,
    /// Clusters of small coplanar polygons that shoot their small shots together
    /// (`SolveOptions::cluster_cell`; 0 in scenes of large polygons).
    pub clusters: usize,
    /// Polygons in those clusters.
    pub clustered_polygons: usize,
    /// Shots in which a cluster shot (each one shot).
    pub cluster_shots: u32,
    /// Of those, the shots in which a face cluster shot (`SolveOptions::face_clusters`).
    pub face_cluster_shots: u32,
    /// Seconds of the solve loop (loading, layout and images not counted).
    pub solve_seconds: f64,
    /// Peak resident memory of the process when the statistics were made, MiB (0 where the
    /// system does not say).
    pub peak_memory_mib: f64,
    /// Worker threads of the CPU solver.
    pub threads: Option<usize>,
    /// Unshot power over emitted power at the end.
    pub unshot_fraction: f64,
    /// Why the solve stopped.
    pub stopped: Stopped,
    /// Whether a signal stopped it (`stopped` is then `interrupted`): the solution is the one
    /// of its last shot, `unshot_fraction` what was left.
    pub interrupted: bool,
    /// The solve's time limit (`--max-seconds`), if any.
    pub max_seconds: Option<f64>,
    /// Emitted power of the scene (radiance × area × π, summed over RGB).
    pub emitted_power: f64,
    /// The ambient radiance added to the images (with the ambient term), RGB.
    pub ambient: Option<[f32; 3]>,
    /// The images' smooth shading: its crease angle in degrees (0: off)...
    pub smooth_angle: f32,
    /// ...and the polygons it smooths (those with a smooth edge).
    pub smoothed_polygons: usize,
    /// Seconds per pass, by name.
    pub pass_seconds: PassTimes,
    /// Each shot's record, in order.
    pub history: Vec<ShotRecord>,
}

/// Why a solve stopped (`stats.json`'s `stopped`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stopped {
    /// The unshot fraction reached the threshold.
    Threshold,
    /// `max_shots` shots were made.
    MaxShots,
    /// Nothing was left that Find_Max_Energy would shoot.
    NothingToShoot,
    /// The time limit (`--max-seconds`) was reached.
    MaxSeconds,
    /// A signal (SIGINT, SIGTERM, SIGHUP) asked it to stop.
    Interrupted,
}

impl Stopped {
    /// Why a solve that ran to the end of its loop stopped, from where it ended.
    pub fn of(solution: &Solution, options: &SolveOptions) -> Stopped {
        if solution.unshot_fraction <= options.threshold as f64 {
            Stopped::Threshold
        } else if solution.shots >= options.max_shots {
            Stopped::MaxShots
        } else {
            Stopped::NothingToShoot
        }
    }
}

/// Where and how a solve ran, for [`Stats::new`].
pub struct Run<'a> {
    /// The scene's file, as the user named it (or the bundled scene's name).
    pub scene_name: String,
    /// The scene solved.
    pub scene: &'a Scene,
    /// Its patch layout.
    pub layout: &'a PatchLayout,
    /// Which solver ran.
    pub solver: SolverKind,
    /// The mode the settings came from.
    pub mode: Mode,
    /// The settings the solve used.
    pub options: SolveOptions,
    /// The tuning profile they carry, and why (`--tuning`).
    pub tuning: &'a ChosenTuning,
    /// The emission overrides the scene was loaded with.
    pub emit: &'a [Emission],
    /// The GL driver (also for the CPU solver, which renders the images on it).
    pub gl: &'a GlInfo,
    /// CPU worker threads, for the CPU solver.
    pub threads: Option<usize>,
    /// The smooth edges the images were shaded with.
    pub smoothing: &'a Smoothing,
}

impl Stats {
    /// The statistics of `solution` solved as `run` says, with the images' ambient term.
    pub fn new(run: Run, solution: &Solution, ambient: Option<Vec3>) -> Stats {
        let (scene, layout) = (run.scene, run.layout);
        let own = scene.own_polygons().len();
        let sky_patches = layout.patches_per_polygon[own..].iter().map(|&n| n as u64);
        let sky = scene.sky_stats(sky_patches.sum());
        let sky_patches = sky.as_ref().map_or(0, |s| s.patches);
        let stopped = Stopped::of(solution, &run.options);
        Stats {
            scene: run.scene_name,
            faces: scene.faces,
            polygons: own,
            vertices: scene.vertex_count,
            lights: scene.light_count() - sky.as_ref().map_or(0, |s| s.polygons),
            patches: layout.patch_count() - sky_patches,
            patch_size: layout.patch_size,
            atlas: [layout.atlas_width, layout.atlas_height],
            solver: run.solver,
            mode: run.mode,
            backend: run.gl.backend.name(),
            gl_vendor: run.gl.vendor.clone(),
            gl_renderer: run.gl.renderer.clone(),
            gl_version: run.gl.version.clone(),
            tuning: run.tuning.name(),
            tuning_reason: run.tuning.reason.clone(),
            options: run.options,
            emit: run.emit.to_vec(),
            sky,
            shots: solution.shots,
            passes: solution.passes,
            corrections: solution.corrections,
            clusters: solution.clusters,
            clustered_polygons: solution.clustered_polygons,
            cluster_shots: solution.cluster_shots,
            face_cluster_shots: solution.face_cluster_shots,
            solve_seconds: solution.solve_seconds(),
            peak_memory_mib: peak_memory_mib(),
            threads: run.threads,
            unshot_fraction: solution.unshot_fraction,
            stopped,
            interrupted: false,
            max_seconds: None,
            emitted_power: solution.emitted_power,
            ambient: ambient.map(|l| l.to_array()),
            smooth_angle: run.smoothing.angle(),
            smoothed_polygons: run.smoothing.smoothed_polygons(),
            pass_seconds: solution.pass_seconds.clone(),
            history: solution.history.clone(),
        }
    }
}

/// Peak resident memory of this process (VmHWM of /proc/self/status), MiB; 0 where there is no
/// such file.
pub fn peak_memory_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("VmHWM"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map(|kib| kib / 1024.0)
        .unwrap_or(0.0)
}

/// Stage `image.exr` (linear), `image.png` (tone-mapped with `exposure`), `lightmap.exr` (the
/// solver's radiance atlas) and `stats.json` in `set`; [`OutputSet::publish`] puts them in place.
pub fn write_outputs(
    set: &OutputSet,
    image: &Image,
    exposure: f32,
    layout: &PatchLayout,
    solution: &Solution,
    stats: &Stats,
) -> anyhow::Result<()> {
    let (width, height) = (image.width, image.height);
    set.write(
        "image.exr",
        Payload::Exr {
            width,
            height,
            rgb: &image.rgb,
        },
    )?;
    let rgb = output::tone_map(image, exposure);
    set.write(
        "image.png",
        Payload::Png {
            width,
            height,
            rgb: &rgb,
        },
    )?;
    let (width, height) = (layout.atlas_width, layout.atlas_height);
    let rgb = output::atlas_rgb_top_down(width, height, &solution.radiosity);
    set.write(
        "lightmap.exr",
        Payload::Exr {
            width,
            height,
            rgb: &rgb,
        },
    )?;
    set.write("stats.json", Payload::json(stats)?)
}
