//! `radiosity solve [SCENE.obj]`: scene → patches → GPU solver → display → files.

use super::{values, UsageError};
use crate::display;
use crate::display::output_set::OutputSet;
use crate::gl::{BackendChoice, GlContext, GlInfo};
use crate::patches::PatchLayout;
use crate::pipeline::{self, SettingsError, Stats, Target};
pub use crate::pipeline::{Mode, SolverKind};
use crate::scene::{Camera, Emission, LoadOptions, Scene, SceneError};
use crate::solver::{
    ChosenTuning, FormFactorKind, GpuSolver, ShotRecord, SolveError, SolveOptions, TuningChoice,
    VisibilityKind,
};
use anyhow::{bail, Context, Result};
use clap::value_parser;
use glam::Vec3;
use std::cell::RefCell;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// `radiosity solve`'s flags (`view` shares most of them).
#[derive(clap::Args, Debug, Clone)]
pub struct SolveArgs {
    /// OBJ scene (with its MTL) or glTF scene (.glb, .gltf); default: the Cornell box built into
    /// the binary.
    pub scene: Option<PathBuf>,
    /// Output directory; default: out/SCENE_NAME/.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// OpenGL backend: auto tries EGL, then OSMesa.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// gpu: the paper's passes on OpenGL; cpu: the same algorithm in Rust with exact ray-cast
    /// visibility (the display still uses OpenGL).
    #[arg(long, value_enum, default_value_t = SolverKind::Gpu)]
    pub solver: SolverKind,
    /// Worker threads of the CPU solver (0: one per core; at most 4 per core). The result is the
    /// same for any count.
    #[arg(long, default_value_t = 0, value_parser = values::threads, allow_hyphen_values = true)]
    pub threads: usize,
    /// Stop when unshot power / emitted power ≤ this (0 < F < 1). Mode default: paper 0.01,
    /// accurate 0.003.
    #[arg(long, value_parser = values::threshold, allow_hyphen_values = true)]
    pub threshold: Option<f32>,
    /// Stop after this many shots at most (0 to 1,000,000; 0: the emitters alone). Default:
    /// 10,000, or one per polygon on scenes of more polygons.
    #[arg(
        long,
        value_parser = value_parser!(u32).range(0..=values::MAX_SHOTS as i64),
        allow_hyphen_values = true,
    )]
    pub max_shots: Option<u32>,
    /// Stop after this many seconds of solving (finite, > 0), writing the solution so far as
    /// any solve's.
    #[arg(long, value_parser = values::positive, allow_hyphen_values = true)]
    pub max_seconds: Option<f32>,
    /// Aim at about this many patches, 1 to 1,048,576 (default, unless the scene sets a patch
    /// size: 4096, plus 2 per polygon on scenes of more than 512 polygons).
    #[arg(
        long,
        conflicts_with = "patch_size",
        value_parser = value_parser!(u32).range(1..=values::MAX_PATCHES as i64),
        allow_hyphen_values = true,
    )]
    pub patches: Option<u32>,
    /// Patch side in scene units (> 0).
    #[arg(long, value_parser = values::positive, allow_hyphen_values = true)]
    pub patch_size: Option<f32>,
    /// `paper`: the paper's algorithm literally; `accurate`: with the corrections listed in
    /// paper_notes.md. The four options below override single settings of the mode.
    #[arg(long, value_enum, default_value_t = Mode::Accurate)]
    pub mode: Mode,
    /// Speed switches of the GPU passes: auto (the llvmpipe engine on Mesa's software
    /// rasterisers, the GPU profile on any other renderer; the paper's passes with --mode
    /// paper), paper (the passes as the paper draws them), llvmpipe, gpu (every item buffer
    /// drawn by the GPU). The same answers within what each switch promises.
    #[arg(long, value_enum, default_value_t = TuningChoice::Auto)]
    pub tuning: TuningChoice,
    /// Item-buffer resolution (pixels per side; per face for the hemicube). Mode default:
    /// paper 512, accurate 256.
    #[arg(long, value_parser = values::hemi_res(), allow_hyphen_values = true)]
    pub hemi_res: Option<u32>,
    /// Longest edge of the visibility pass's triangles, in patch sizes (0: whole polygons).
    /// Default 0; worth 1-2 with `--visibility hemisphere`, whose projection curves edges.
    #[arg(long, value_parser = values::tessellation, allow_hyphen_values = true)]
    pub tessellate: Option<f32>,
    /// Side, in patches, of the cells a polygon shoots from (0: the whole polygon from its
    /// centroid; at most 16384). Mode default: paper 0, accurate 4.
    #[arg(
        long,
        value_parser = value_parser!(u32).range(0..=values::MAX_CELL as i64),
        allow_hyphen_values = true,
    )]
    pub shooter_cell: Option<u32>,
    /// The same for emitters (their first shot is the direct light). Mode default: paper 0,
    /// accurate 1.
    #[arg(
        long,
        value_parser = value_parser!(u32).range(0..=values::MAX_CELL as i64),
        allow_hyphen_values = true,
    )]
    pub emitter_cell: Option<u32>,
    /// Form factor: point (paper) or polygon (exact for the shooter's cell).
    #[arg(long, value_enum)]
    pub form_factor: Option<FormFactorKind>,
    /// Visibility pass: hemisphere (paper's hemispherical projection) or hemicube.
    #[arg(long, value_enum)]
    pub visibility: Option<VisibilityKind>,
    /// Beyond the paper, for fewer shots: each shooter also shoots the ambient light it will
    /// still receive, leaving that much negative unshot energy (Feda & Purgathofer 1992).
    /// `--overshoot` or `--overshoot true|false`. Mode default: paper off, accurate on.
    #[arg(long, num_args = 0..=1, default_missing_value = "true", value_name = "BOOL")]
    pub overshoot: Option<bool>,
    /// Beyond the paper, for cheaper shots: draw the item buffer at this resolution (16 to
    /// --hemi-res; 0: off) for shots that carry less than --small-shot of the emitted power.
    /// Mode default: paper 0, accurate 128 (--hemi-res where that is smaller).
    #[arg(long, value_parser = values::hemi_res_or_off, allow_hyphen_values = true)]
    pub small_hemi_res: Option<u32>,
    /// See --small-hemi-res: a share of the emitted power (0 ≤ F < 1). Default 0.01.
    #[arg(long, value_parser = values::share, allow_hyphen_values = true)]
    pub small_shot: Option<f32>,
    /// Beyond the paper, for cheaper shots (needs --small-hemi-res): below --small-shot the
    /// item buffer's side falls with the cube root of the shot's share of the emitted power,
    /// down to N (16 to --small-hemi-res; 0: off). Mode default: paper 0, accurate 16.
    #[arg(long, value_parser = values::hemi_res_or_off, allow_hyphen_values = true)]
    pub min_hemi_res: Option<u32>,
    /// Beyond the paper, for accuracy: turn each shot's item buffer about the shooter's normal
    /// by its own angle, so that the aliasing of successive shots averages out. Mode default:
    /// paper off, accurate on.
    #[arg(long, num_args = 0..=1, default_missing_value = "true", value_name = "BOOL")]
    pub rotate_item_buffer: Option<bool>,
    /// Beyond the paper, for cheaper shots: each step shoots the K polygons with the most unshot
    /// power (1 to 8), each with its own item buffer, through one reconstruction pass. Mode
    /// default: paper 1, accurate 8 (1 with --dump-passes).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=crate::solver::MAX_SHOOTERS_PER_PASS as i64))]
    pub shooters_per_pass: Option<u32>,
    /// Beyond the paper, so that no shot creates energy: a shot whose receivers got more than
    /// it carried is scaled back to what it carried. Mode default: paper off, accurate on.
    #[arg(long, num_args = 0..=1, default_missing_value = "true", value_name = "BOOL")]
    pub conserve: Option<bool>,
    /// Beyond the paper, for fewer passes: only shots carrying at least this share of the
    /// emitted power cut their cells where a touching polygon's plane crosses them (0 ≤ F < 1;
    /// 0: every shot). Mode default: paper 0, accurate 0.003.
    #[arg(long, value_parser = values::share, allow_hyphen_values = true)]
    pub cut_above: Option<f32>,
    /// Beyond the paper, for fewer passes: shots below --cut-above shoot from cells of this side
    /// in patches (0 or no wider than the cell: the same cells as every shot; at most 16384).
    /// Mode default: paper 0, accurate 16.
    #[arg(
        long,
        value_parser = value_parser!(u32).range(0..=values::MAX_CELL as i64),
        allow_hyphen_values = true,
    )]
    pub coarse_cell: Option<u32>,
    /// Beyond the paper, for fewer shots on scenes of many small polygons (at most 4 patches
    /// each on average): small touching coplanar polygons within squares of the cell's side
    /// shoot together, as one shooter, and those within squares of this side in patches in the
    /// shots below `--cut-above` (0: never; at most 16384). Mode default: paper 0, accurate 8.
    #[arg(
        long,
        value_parser = value_parser!(u32).range(0..=values::MAX_CELL as i64),
        allow_hyphen_values = true,
    )]
    pub cluster_cell: Option<u32>,
    /// Beyond the paper, for large shooters in scenes of many triangles: a polygon's shot is
    /// divided into at most N / (the scene's triangles) cells, at least 64, each a visibility
    /// pass (0: no limit). Mode default: paper 0, accurate 50,000,000.
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub shot_triangles: Option<u64>,
    /// Beyond the paper, for fewer shots on curved surfaces of many small faces: a small
    /// polygon shoots together with touching neighbours whose normals lie within 20° of their
    /// mean, as long as the power that may go astray stays below --cut-above of the emitted
    /// power and the cluster's point sees little of other polygons close in front (needs --shooter-cell, --cluster-cell and --cut-above above 0, so nothing in
    /// --mode paper; only in scenes of polygons of at most 4 patches on average).
    /// `--face-clusters` or `--face-clusters true|false`. Default on (`--mode accurate`).
    #[arg(long, num_args = 0..=1, default_missing_value = "true", value_name = "BOOL")]
    pub face_clusters: Option<bool>,
    /// Make the material NAME emit light: emitted radiance R,G,B, as `Ke` in the MTL file (each 0
    /// to 1e15; 0,0,0 turns an emitter off). Repeatable.
    #[arg(long, value_name = "NAME=R,G,B", value_parser = values::emission, allow_hyphen_values = true)]
    pub emit: Vec<Emission>,
    /// Beyond the paper: light the scene through its openings by a uniform sky of radiance
    /// R,G,B (each 0 to 1e15), emitters around the scene's bounds (see src/scene/sky.rs).
    #[arg(long, value_name = "R,G,B", value_parser = values::sky, allow_hyphen_values = true)]
    pub sky: Option<Vec3>,
    /// Keep every face of the OBJ its own polygon (as a `# keep-faces` line in the file does);
    /// by default connected coplanar faces of one material become one polygon.
    #[arg(long)]
    pub keep_faces: bool,
    /// Camera position, X,Y,Z (default: the scene's camera).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// The point the camera looks at, X,Y,Z (default: the scene's camera).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// The camera's up direction, X,Y,Z (default: the scene's camera).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<Vec3>,
    /// Vertical field of view, degrees (1 to 179).
    #[arg(long, value_parser = values::fov, allow_hyphen_values = true)]
    pub fov: Option<f32>,
    /// Image size, WxH.
    #[arg(long, value_parser = parse_size, default_value = "512x512", allow_hyphen_values = true)]
    pub size: (u32, u32),
    /// Show an unconverged solution with Cohen et al.'s (1988) ambient term added (images only;
    /// lightmap.exr stays the solver's answer).
    #[arg(long)]
    pub ambient: bool,
    /// Beyond the paper, for the images: faces of one material meeting at less than this angle
    /// (degrees, 0 to under 90; 0: off) are shaded smooth across their shared edges, so that
    /// tessellated spheres and columns look round (lightmap.exr stays the solver's answer).
    #[arg(
        long,
        default_value_t = crate::display::smooth::DEFAULT_ANGLE,
        value_parser = values::smooth_angle,
        allow_hyphen_values = true,
    )]
    pub smooth_angle: f32,
    /// Multiplier applied to radiance before tone mapping image.png (finite, > 0).
    #[arg(long, default_value_t = 1.0, value_parser = values::positive, allow_hyphen_values = true)]
    pub exposure: f32,
    /// Write pictures of these shots' passes into the output directory (item buffer, ΔL, atlas
    /// before and after; see src/display/passes.rs), e.g. `--dump-passes 1,2,10`.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "K[,K...]",
        value_parser = value_parser!(u32).range(1..=values::MAX_SHOTS as i64),
        allow_hyphen_values = true,
    )]
    pub dump_passes: Vec<u32>,
    /// Write convergence.png: unshot fraction against shot and against time, log scale.
    #[arg(long)]
    pub plot: bool,
    /// Also write the solved scene as glTF 2.0 into the output directory: NAME.glb, or
    /// NAME.gltf with NAME.bin and NAME.png (unlit, the lightmap as its texture; docs/usage.md).
    #[arg(long, value_name = "NAME.glb|NAME.gltf", value_parser = display::gltf_out::file_name)]
    pub gltf: Option<String>,
}

impl SolveArgs {
    /// The solver settings: the mode's, with single settings overridden.
    pub fn options(&self) -> SolveOptions {
        let base = self.mode.options();
        // One shooter per pass when picturing the passes, unless asked for more (refused).
        let shooters_per_pass = match self.shooters_per_pass {
            Some(k) => k,
            None if !self.dump_passes.is_empty() => 1,
            None => base.shooters_per_pass,
        };
        // A mode's small-shot sides follow a smaller --hemi-res down (`--hemi-res 64` alone is
        // not refused for the default's 128² small shots); sides given explicitly are checked.
        let hemi_res = self.hemi_res.unwrap_or(base.hemi_res);
        let small_hemi_res = self
            .small_hemi_res
            .unwrap_or(base.small_hemi_res.min(hemi_res));
        let min_hemi_res = self
            .min_hemi_res
            .unwrap_or(base.min_hemi_res.min(small_hemi_res));
        SolveOptions {
            threshold: self.threshold.unwrap_or(base.threshold),
            max_shots: self.max_shots.unwrap_or(base.max_shots),
            hemi_res,
            tessellation: self.tessellate.unwrap_or(base.tessellation),
            shooter_cell: self.shooter_cell.unwrap_or(base.shooter_cell),
            emitter_cell: self.emitter_cell.unwrap_or(base.emitter_cell),
            form_factor: self.form_factor.unwrap_or(base.form_factor),
            visibility: self.visibility.unwrap_or(base.visibility),
            robust_visibility: base.robust_visibility,
            tuning: base.tuning,
            overshoot: self.overshoot.unwrap_or(base.overshoot),
            small_hemi_res,
            small_shot: self.small_shot.unwrap_or(crate::solver::SMALL_SHOT),
            min_hemi_res,
            rotate_item_buffer: self.rotate_item_buffer.unwrap_or(base.rotate_item_buffer),
            shooters_per_pass,
            conserve: self.conserve.unwrap_or(base.conserve),
            cut_above: self.cut_above.unwrap_or(base.cut_above),
            coarse_cell: self.coarse_cell.unwrap_or(base.coarse_cell),
            cluster_cell: self.cluster_cell.unwrap_or(base.cluster_cell),
            shot_triangles: self.shot_triangles.unwrap_or(base.shot_triangles),
            face_clusters: self.face_clusters.unwrap_or(base.face_clusters),
        }
    }

    /// The stopping rule's threshold in use.
    pub fn threshold(&self) -> f32 {
        self.threshold.unwrap_or(self.mode.options().threshold)
    }
}

fn rayon_threads(requested: usize) -> usize {
    if requested > 0 {
        requested
    } else {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    }
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|t| {
            t.trim()
                .parse::<f32>()
                .map_err(|_| format!("'{t}' is not a number"))
        })
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!(
            "expected X,Y,Z with three finite numbers, got '{s}'"
        )),
    }
}

pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH, got '{s}'"))?;
    let w: u32 = w.parse().map_err(|_| format!("bad width in '{s}'"))?;
    let h: u32 = h.parse().map_err(|_| format!("bad height in '{s}'"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!(
            "image size '{s}' must be between 1x1 and 16384x16384"
        ));
    }
    Ok((w, h))
}

/// The checks `solve` and `view` share (the stopping rule and the patch resolution), with the
/// flags named.
pub(crate) fn check_solve_settings(
    threshold: f32,
    patch_size: Option<f32>,
    patches: Option<u32>,
) -> Result<()> {
    pipeline::check_settings(threshold, patch_size, patches).map_err(|e| {
        let flag = match e {
            SettingsError::Threshold(_) => "--threshold",
            SettingsError::PatchSize(_) => "--patch-size",
            SettingsError::Patches => "--patches",
        };
        anyhow::anyhow!("{flag}: {e}")
    })
}

/// What `solve` made: its statistics (as written to stats.json) and where the files went.
pub struct SolveOutcome {
    /// The run's statistics, as written to stats.json.
    pub stats: Stats,
    /// The folder the outputs were published in.
    pub out_dir: PathBuf,
}

/// `radiosity solve`: load the scene, lay out the patches, solve, render and publish the outputs
/// together (or none of them).
pub fn run_solve(args: &SolveArgs) -> Result<SolveOutcome> {
    // First: a signal from here on removes what this run staged and exits 1.
    display::output_set::exit_on_signals()?;
    check_solve_settings(args.threshold(), args.patch_size, args.patches)?;
    let (scene, scene_path) =
        load_scene(args.scene.as_deref(), &args.emit, args.keep_faces, args.sky)?;
    let scene_name = scene_path.display().to_string();
    // Without a `# camera` line, chosen by casting rays into the scene: once.
    let camera = camera_from(args, scene.camera_or_default());
    check_camera(args, &scene, &camera)?;
    let out_dir = output_dir(args, &scene)?;
    check_dump_passes(args)?;
    // Before the solve: an unwritable folder fails now, not after it. Every file goes in here and
    // is published together at the end.
    let set = OutputSet::begin(&out_dir)?;

    let layout = lay_out(args, &scene)?;
    let ctx = GlContext::headless(args.backend)?;
    report_setup(&ctx.info, &scene, &layout);
    let mut options = args.options();
    let tuning = chosen_tuning(args, &ctx);
    eprintln!("{}", tuning.line());
    options.tuning = tuning.tuning();
    if args.max_shots.is_none() {
        options.max_shots = crate::solver::default_max_shots(scene.polygons.len());
        if options.max_shots > SolveOptions::paper().max_shots {
            eprintln!(
                "shot limit: {} (one per polygon; --max-shots sets it)",
                options.max_shots
            );
        }
    }
    check_limits(args, &ctx, &layout, &options)?;
    let limits = super::stopping::Limits::begin(args.max_seconds.map(f64::from));
    let solution = solve(args, &ctx, &scene, &layout, &options, &set, &limits)?;
    let stopped = limits.end();
    solution
        .check_light_reaches(&scene)
        .with_context(|| scene_name.clone())?;
    eprintln!(
        "solved: {} shots ({} passes), unshot fraction {:.5}, {:.3} s",
        solution.shots,
        solution.passes,
        solution.unshot_fraction,
        solution.solve_seconds()
    );

    let (atlas, ambient) = solution.display_atlas(&scene, &layout, args.ambient);
    if let Some(l) = ambient {
        eprintln!("ambient term: {:.5} {:.5} {:.5}", l.x, l.y, l.z);
    }
    let smoothing = smoothing(args, &scene, &layout);
    let image = pipeline::render_smoothed(
        &ctx, &scene, &layout, &atlas, &smoothing, &camera, args.size,
    )?;
    let run = pipeline::Run {
        scene_name,
        scene: &scene,
        layout: &layout,
        solver: args.solver,
        mode: args.mode,
        options,
        tuning: &tuning,
        emit: &args.emit,
        gl: &ctx.info,
        threads: (args.solver == SolverKind::Cpu).then(|| rayon_threads(args.threads)),
        smoothing: &smoothing,
    };
    let mut stats = Stats::new(run, &solution, ambient);
    if let Some(why) = stopped {
        (stats.stopped, stats.interrupted) = (why, why == pipeline::Stopped::Interrupted);
    }
    stats.max_seconds = args.max_seconds.map(f64::from);
    pipeline::write_outputs(&set, &image, args.exposure, &layout, &solution, &stats)?;
    if let Some(name) = &args.gltf {
        write_gltf(
            &set, name, &ctx, &scene, &layout, &atlas, &smoothing, args, camera,
        )?;
    }
    if args.plot {
        let title = format!("{} ({:?} mode)", scene.name, args.mode).to_lowercase();
        display::plot::write_convergence(&set, &stats.history, args.threshold(), &title)?;
    }
    set.publish()?;
    eprintln!("wrote {}", out_dir.display());
    if let Some(why) = stopped {
        eprintln!("{}", super::stopping::said(why, &solution));
    }
    Ok(SolveOutcome { stats, out_dir })
}

/// `--gltf NAME`: the solved scene as glTF, staged with the other outputs.
#[allow(clippy::too_many_arguments)]
fn write_gltf(
    set: &OutputSet,
    name: &str,
    ctx: &GlContext,
    scene: &Scene,
    layout: &PatchLayout,
    atlas: &[f32],
    smoothing: &display::Smoothing,
    args: &SolveArgs,
    camera: Camera,
) -> Result<()> {
    let baked = display::bake::bake_smoothing(ctx, scene, layout, atlas, smoothing)?;
    let export = display::gltf_out::Export {
        scene,
        layout,
        atlas: &baked,
        camera,
        aspect: args.size.0 as f32 / args.size.1 as f32,
        exposure: args.exposure,
    };
    for (file, bytes) in display::gltf_out::encode(&export, name)? {
        set.write(&file, display::output::Payload::Bytes(&bytes))?;
    }
    Ok(())
}

/// `--tuning` resolved on `ctx`'s renderer (the GPU solver's; the CPU solver has none).
fn chosen_tuning(args: &SolveArgs, ctx: &GlContext) -> ChosenTuning {
    let renderer = (args.solver == SolverKind::Gpu).then_some(ctx.info.renderer.as_str());
    args.tuning.resolve(args.mode == Mode::Paper, renderer)
}

/// The output folder (`--out`, or out/SCENE), created.
fn output_dir(args: &SolveArgs, scene: &Scene) -> Result<PathBuf> {
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("out").join(&scene.name));
    std::fs::create_dir_all(&out_dir)
        .with_context(|| format!("cannot create the output directory {}", out_dir.display()))?;
    Ok(out_dir)
}

/// `--dump-passes` pictures one GPU shooter's passes per shot: refused with the CPU solver or
/// with several shooters per pass.
fn check_dump_passes(args: &SolveArgs) -> Result<()> {
    if args.solver == SolverKind::Cpu && !args.dump_passes.is_empty() {
        bail!("--dump-passes pictures the GPU passes: use it with --solver gpu");
    }
    if args.options().shooters_per_pass > 1 && !args.dump_passes.is_empty() {
        bail!(
            "--dump-passes pictures one shooter's passes per shot: use it with \
             --shooters-per-pass 1"
        );
    }
    Ok(())
}

/// The patch layout the flags or the scene ask for, reported on stderr with its reason.
fn lay_out(args: &SolveArgs, scene: &Scene) -> Result<PatchLayout> {
    let layout = pipeline::lay_out(scene, args.patch_size, args.patches)?;
    let sky = (scene.polygons.len() - scene.own_polygons().len()) as u64;
    eprintln!(
        "patches: {} at patch size {:.4}, from {}",
        layout.patch_count() - sky,
        layout.patch_size,
        pipeline::resolution_and_reason(scene, args.patch_size, args.patches).1
    );
    // A patch size (from the flag or the scene) can ask for more patches than --patches may.
    if layout.patch_count() > values::MAX_PATCHES as u64 {
        bail!(
            "the patch size {} gives {} patches, more than {} (the most --patches allows): use \
             a larger --patch-size",
            layout.patch_size,
            layout.patch_count(),
            values::MAX_PATCHES
        );
    }
    Ok(layout)
}

/// The GL driver and the scene's sizes, on stderr.
fn report_setup(info: &GlInfo, scene: &Scene, layout: &PatchLayout) {
    eprintln!(
        "backend {}: {} | {} | {}",
        info.backend.name(),
        info.vendor,
        info.renderer,
        info.version
    );
    // The sky's quads are counted apart (one patch each).
    let sky = scene.polygons.len() - scene.own_polygons().len();
    eprintln!(
        "scene {}: {}, {} vertices, {} lights, {} patches (patch size {:.4}, atlas {}x{})",
        scene.name,
        faces_and_polygons(scene),
        scene.vertex_count,
        scene.light_count() - sky,
        layout.patch_count() - sky as u64,
        layout.patch_size,
        layout.atlas_width,
        layout.atlas_height
    );
    if let Some(sky) = scene.sky_stats(sky as u64) {
        let [r, g, b] = sky.radiance;
        eprintln!(
            "sky: radiance {r},{g},{b} from {} emitting quads around the scene (one patch each)",
            sky.polygons
        );
    }
}

/// The driver's limits against the atlas, the item buffer and the image, naming the flags.
fn check_limits(
    args: &SolveArgs,
    ctx: &GlContext,
    layout: &PatchLayout,
    options: &SolveOptions,
) -> Result<()> {
    pipeline::check_limits(ctx, layout, args.solver, options, args.size).map_err(|e| {
        let flags = match e.target {
            Target::Atlas => "--patch-size / --patches",
            Target::ItemBuffer => "--hemi-res",
            Target::Image => "--size",
        };
        anyhow::anyhow!("{e} (set with {flags})")
    })
}

/// The solve with a progress bar; with `--dump-passes`, the GPU solve with the pictures of the
/// listed shots written into `set` on the way.
fn solve(
    args: &SolveArgs,
    ctx: &GlContext,
    scene: &Scene,
    layout: &PatchLayout,
    options: &SolveOptions,
    set: &OutputSet,
    limits: &super::stopping::Limits,
) -> Result<pipeline::Solution> {
    let bar = progress_bar(args.threshold());
    let progress = |r: &ShotRecord| {
        limits.see(r);
        bar.set_position(progress_position(r.unshot_fraction, args.threshold()));
        bar.set_message(format!("shot {} unshot {:.4}", r.shot, r.unshot_fraction));
    };
    let solution = if args.dump_passes.is_empty() {
        let (kind, threads) = (args.solver, args.threads);
        let stop = || limits.stop();
        pipeline::solve_until(
            ctx,
            scene,
            layout,
            kind,
            options.clone(),
            threads,
            progress,
            stop,
        )
        .map_err(with_flags)?
    } else {
        let mut solver = GpuSolver::new(ctx, scene, layout, options.clone()).map_err(with_flags)?;
        // Both hooks use the dumps, one after the other.
        let dumps = RefCell::new(display::passes::PassDumps::new(&args.dump_passes, set));
        solver.solve_with_until(
            |s| dumps.borrow_mut().before_shot(s),
            |s, record| -> Result<()> {
                dumps
                    .borrow_mut()
                    .after_shot(s, scene, layout, record)
                    .with_context(|| {
                        format!("while writing the pictures of shot {}", record.shot)
                    })?;
                progress(record);
                Ok(())
            },
            || limits.stop(),
        )?;
        pipeline::Solution::of(&solver)
    };
    bar.finish_and_clear();
    Ok(solution)
}

/// Smooth shading's normals (`--smooth-angle`), reported when some polygons have them.
fn smoothing(args: &SolveArgs, scene: &Scene, layout: &PatchLayout) -> display::Smoothing {
    let smoothing = display::Smoothing::new(scene, layout, args.smooth_angle);
    if smoothing.smoothed_polygons() > 0 {
        eprintln!(
            "smooth shading: {} polygons of curved surfaces (faces of one material meeting at \
             less than {}°, --smooth-angle)",
            smoothing.smoothed_polygons(),
            smoothing.angle()
        );
    }
    smoothing
}

/// The scene with the `--emit` overrides applied (`solve` and `view`); an override the scene
/// cannot take names the flag.
pub(crate) fn load_scene(
    path: Option<&Path>,
    emit: &[Emission],
    keep_faces: bool,
    sky: Option<Vec3>,
) -> Result<(Scene, PathBuf)> {
    let options = LoadOptions {
        emit: emit.to_vec(),
        keep_faces,
        sky,
    };
    pipeline::load_scene_with(path, &options).map_err(|e| match e {
        SceneError::Emit { .. } => anyhow::anyhow!("{e} (set with --emit)"),
        e => e.into(),
    })
}

/// A solver error with the command-line flags that set what it speaks of.
pub(crate) fn with_flags(e: SolveError) -> anyhow::Error {
    let flags = match &e {
        SolveError::AtlasTooLarge { .. } | SolveError::NoEmission { .. } => {
            Some("--patch-size / --patches")
        }
        SolveError::HemiRes { .. } => Some("--hemi-res"),
        SolveError::SmallHemiRes { .. } => Some("--small-hemi-res"),
        SolveError::MinHemiRes { .. } => Some("--min-hemi-res / --small-hemi-res"),
        SolveError::Tessellation(_) => Some("--tessellate"),
        SolveError::ShootersPerPass(_) => Some("--shooters-per-pass / --hemi-res"),
        SolveError::Threads { .. } => Some("--threads"),
        _ => None,
    };
    match flags {
        Some(flags) => anyhow::anyhow!("{e} (set with {flags})"),
        None => e.into(),
    }
}

/// Check the camera the picture will be taken with (the flags' values over the scene's camera)
/// before solving. A usage error when flags set part of it; the scene's own camera line was
/// checked when the scene loaded.
fn check_camera(args: &SolveArgs, scene: &Scene, camera: &Camera) -> Result<()> {
    let Err(e) = camera.validate() else {
        return Ok(());
    };
    let given: Vec<&str> = [
        ("--eye", args.eye.is_some()),
        ("--target", args.target.is_some()),
        ("--up", args.up.is_some()),
        ("--fov", args.fov.is_some()),
    ]
    .into_iter()
    .filter_map(|(flag, set)| set.then_some(flag))
    .collect();
    let rest = if scene.camera.is_some() {
        "the scene's `# camera` line"
    } else {
        "the default view of the scene"
    };
    if given.is_empty() {
        bail!("the camera from {rest}: {e}");
    }
    Err(UsageError(format!(
        "the camera set with {} (the rest from {rest}): {e}",
        given.join(", ")
    ))
    .into())
}

fn camera_from(args: &SolveArgs, base: Camera) -> Camera {
    Camera {
        eye: args.eye.unwrap_or(base.eye),
        target: args.target.unwrap_or(base.target),
        up: args.up.unwrap_or(base.up),
        fov_y: args.fov.unwrap_or(base.fov_y),
    }
}

const BAR_STEPS: u64 = 1000;

/// Progress on a log scale: from unshot fraction 1 (start) to the threshold (done).
fn progress_position(fraction: f64, threshold: f32) -> u64 {
    let p = fraction.max(1e-30).ln() / (threshold as f64).ln();
    (p.clamp(0.0, 1.0) * BAR_STEPS as f64) as u64
}

fn progress_bar(_threshold: f32) -> indicatif::ProgressBar {
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(BAR_STEPS);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

/// `N faces`, or `N faces → M polygons` when the reader merged coplanar faces.
fn faces_and_polygons(scene: &Scene) -> String {
    let polygons = scene.own_polygons().len();
    if scene.faces == polygons {
        format!("{} faces", scene.faces)
    } else {
        format!("{} faces → {polygons} polygons", scene.faces)
    }
}
