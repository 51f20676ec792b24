//! `radiosity solve [SCENE.obj]`: scene → patches → GPU solver → display → files.

use crate::display::{self, output};
use crate::gl::{BackendChoice, GlContext, GlInfo};
use crate::patches::{PatchLayout, Resolution};
use crate::scene::{bundled, Camera};
use crate::solver::cpu::CpuSolver;
use crate::solver::{FormFactorKind, GpuSolver, ShotRecord, SolveOptions, VisibilityKind};
use anyhow::{bail, Context, Result};
use glam::Vec3;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Patches when neither --patches nor --patch-size nor the scene says otherwise.
pub const DEFAULT_PATCHES: u32 = 4096;

#[derive(clap::Args, Debug, Clone)]
pub struct SolveArgs {
    /// OBJ scene (with its MTL); default: the Cornell box built into the binary.
    pub scene: Option<PathBuf>,
    /// Output directory; default: out/<scene name>/.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// OpenGL backend: auto tries EGL, then OSMesa.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// gpu: the paper's passes on OpenGL; cpu: the same algorithm in Rust with exact ray-cast
    /// visibility (the display still uses OpenGL).
    #[arg(long, value_enum, default_value_t = SolverKind::Gpu)]
    pub solver: SolverKind,
    /// Worker threads of the CPU solver (0: one per core). The result is the same for any count.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Stop when unshot power / emitted power ≤ this.
    #[arg(long, default_value_t = 0.01)]
    pub threshold: f32,
    /// Stop after this many shots at most.
    #[arg(long, default_value_t = 10_000)]
    pub max_shots: u32,
    /// Aim at about this many patches (default 4096 unless the scene sets a patch size).
    #[arg(long, conflicts_with = "patch_size")]
    pub patches: Option<u32>,
    /// Patch side in scene units.
    #[arg(long)]
    pub patch_size: Option<f32>,
    /// `paper`: the paper's algorithm literally; `accurate`: with the corrections listed in
    /// paper_notes.md. The four options below override single settings of the mode.
    #[arg(long, value_enum, default_value_t = Mode::Accurate)]
    pub mode: Mode,
    /// Item-buffer resolution (pixels per side; per face for the hemicube). Mode default:
    /// paper 512, accurate 256.
    #[arg(long)]
    pub hemi_res: Option<u32>,
    /// Longest edge of the visibility pass's triangles, in patch sizes (0: whole polygons).
    /// Default 0; worth 1-2 with `--visibility hemisphere`, whose projection curves edges.
    #[arg(long)]
    pub tessellate: Option<f32>,
    /// Side, in patches, of the cells a polygon shoots from (0: the whole polygon from its
    /// centroid). Mode default: paper 0, accurate 4.
    #[arg(long)]
    pub shooter_cell: Option<u32>,
    /// The same for emitters (their first shot is the direct light). Mode default: paper 0,
    /// accurate 1.
    #[arg(long)]
    pub emitter_cell: Option<u32>,
    /// Form factor: point (paper) or polygon (exact for the shooter's cell).
    #[arg(long, value_enum)]
    pub form_factor: Option<FormFactorKind>,
    /// Visibility pass: hemisphere (paper's hemispherical projection) or hemicube.
    #[arg(long, value_enum)]
    pub visibility: Option<VisibilityKind>,
    /// Camera position, X,Y,Z (default: the scene's camera).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<Vec3>,
    /// Vertical field of view, degrees.
    #[arg(long)]
    pub fov: Option<f32>,
    /// Image size, WxH.
    #[arg(long, value_parser = parse_size, default_value = "512x512")]
    pub size: (u32, u32),
    /// Show an unconverged solution with Cohen et al.'s (1988) ambient term added (images only;
    /// lightmap.exr stays the solver's answer).
    #[arg(long)]
    pub ambient: bool,
    /// Multiplier applied to radiance before tone mapping image.png.
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
    /// Write pictures of these shots' passes into the output directory (item buffer, ΔL, atlas
    /// before and after; see src/display/passes.rs), e.g. `--dump-passes 1,2,10`.
    #[arg(long, value_delimiter = ',', value_name = "K[,K...]")]
    pub dump_passes: Vec<u32>,
    /// Write convergence.png: unshot fraction against shot and against time, log scale.
    #[arg(long)]
    pub plot: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    Paper,
    Accurate,
}

impl SolveArgs {
    /// The solver settings: the mode's, with single settings overridden.
    pub fn options(&self) -> SolveOptions {
        let base = match self.mode {
            Mode::Paper => SolveOptions::paper(),
            Mode::Accurate => SolveOptions::accurate(),
        };
        SolveOptions {
            threshold: self.threshold,
            max_shots: self.max_shots,
            hemi_res: self.hemi_res.unwrap_or(base.hemi_res),
            tessellation: self.tessellate.unwrap_or(base.tessellation),
            shooter_cell: self.shooter_cell.unwrap_or(base.shooter_cell),
            emitter_cell: self.emitter_cell.unwrap_or(base.emitter_cell),
            form_factor: self.form_factor.unwrap_or(base.form_factor),
            visibility: self.visibility.unwrap_or(base.visibility),
            robust_visibility: base.robust_visibility,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SolverKind {
    Gpu,
    Cpu,
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

/// What either solver leaves for display and stats.
struct Solved {
    atlas: Vec<f32>,
    unshot: Vec<f32>,
    patch_area: Vec<f64>,
    shots: u32,
    passes: u32,
    unshot_fraction: f64,
    emitted_power: f64,
    pass_seconds: Option<crate::solver::progressive::PassTimes>,
    history: Vec<ShotRecord>,
}

impl Solved {
    fn from_gpu(s: &GpuSolver) -> Solved {
        Solved {
            atlas: s.radiosity_atlas(),
            unshot: s.unshot_atlas().to_vec(),
            patch_area: (0..s.gpu_patches.len()).map(|p| s.patch_area(p)).collect(),
            shots: s.shots(),
            passes: s.passes,
            unshot_fraction: s.unshot_fraction(),
            emitted_power: s.emitted_power(),
            pass_seconds: Some(s.times.clone()),
            history: s.history.clone(),
        }
    }

    fn from_cpu(s: &CpuSolver) -> Solved {
        Solved {
            atlas: s.radiosity_atlas(),
            unshot: s.unshot_atlas().to_vec(),
            patch_area: s.patch_areas().to_vec(),
            shots: s.shots(),
            passes: s.passes,
            unshot_fraction: s.unshot_fraction(),
            emitted_power: s.emitted_power(),
            pass_seconds: None,
            history: s.history.clone(),
        }
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

/// Everything `stats.json` holds (the contract in CONVENTIONS.md, plus timings and settings).
#[derive(serde::Serialize)]
pub struct Stats {
    pub scene: String,
    pub faces: usize,
    pub vertices: usize,
    pub lights: usize,
    pub patches: u64,
    pub patch_size: f32,
    pub atlas: [u32; 2],
    pub solver: SolverKind,
    pub mode: Mode,
    pub backend: &'static str,
    pub gl_vendor: String,
    pub gl_renderer: String,
    pub gl_version: String,
    /// threshold, max_shots and the pass settings.
    #[serde(flatten)]
    pub options: SolveOptions,
    pub shots: u32,
    /// Visibility + reconstruction pass pairs (one per shooter cell of each shot).
    pub passes: u32,
    pub solve_seconds: f64,
    /// Worker threads of the CPU solver.
    pub threads: Option<usize>,
    pub unshot_fraction: f64,
    pub emitted_power: f64,
    /// The ambient radiance added to the images (with --ambient), RGB.
    pub ambient: Option<[f32; 3]>,
    /// Seconds per GPU pass (the GPU solver only).
    pub pass_seconds: Option<crate::solver::progressive::PassTimes>,
    pub history: Vec<ShotRecord>,
}

/// The checks `solve` and `view` share: the stopping rule and the patch resolution.
pub(crate) fn check_solve_settings(
    threshold: f32,
    patch_size: Option<f32>,
    patches: Option<u32>,
) -> Result<()> {
    if !(threshold > 0.0 && threshold < 1.0) {
        bail!("--threshold {threshold} must be between 0 and 1 (exclusive)");
    }
    if let Some(s) = patch_size {
        if !(s > 0.0 && s.is_finite()) {
            bail!("--patch-size {s} must be a positive number of scene units");
        }
    }
    if patches == Some(0) {
        bail!("--patches must be at least 1");
    }
    Ok(())
}

pub struct SolveOutcome {
    pub stats: Stats,
    pub out_dir: PathBuf,
}

pub fn run_solve(args: &SolveArgs) -> Result<SolveOutcome> {
    check_solve_settings(args.threshold, args.patch_size, args.patches)?;
    let (scene, scene_path) = bundled::load_or_default(args.scene.as_deref())?;
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("out").join(&scene.name));
    std::fs::create_dir_all(&out_dir)
        .with_context(|| format!("cannot create the output directory {}", out_dir.display()))?;

    let resolution = match (args.patch_size, args.patches, scene.patch_size) {
        (Some(s), _, _) => Resolution::PatchSize(s),
        (None, Some(n), _) => Resolution::Patches(n),
        (None, None, Some(s)) => Resolution::PatchSize(s),
        (None, None, None) => Resolution::Patches(DEFAULT_PATCHES),
    };
    let layout = PatchLayout::try_new(&scene, resolution)?;
    let ctx = GlContext::headless(args.backend)?;
    let info: &GlInfo = &ctx.info;
    eprintln!(
        "backend {}: {} | {} | {}",
        info.backend.name(),
        info.vendor,
        info.renderer,
        info.version
    );
    eprintln!(
        "scene {}: {} faces, {} vertices, {} lights, {} patches (patch size {:.4}, atlas {}x{})",
        scene.name,
        scene.polygons.len(),
        scene.vertex_count,
        scene.light_count(),
        layout.patch_count(),
        layout.patch_size,
        layout.atlas_width,
        layout.atlas_height
    );

    let options = args.options();
    let bar = progress_bar(args.threshold);
    let progress = |r: &ShotRecord| {
        bar.set_position(progress_position(r.unshot_fraction, args.threshold));
        bar.set_message(format!("shot {} unshot {:.4}", r.shot, r.unshot_fraction));
    };
    let solver = match args.solver {
        SolverKind::Gpu => {
            let mut solver = GpuSolver::new(&ctx, &scene, &layout, options.clone())?;
            let mut dumps = display::passes::PassDumps::new(&args.dump_passes, &out_dir);
            display::passes::solve_dumping(&mut solver, &scene, &layout, &mut dumps, progress)?;
            Solved::from_gpu(&solver)
        }
        SolverKind::Cpu => {
            if !args.dump_passes.is_empty() {
                bail!("--dump-passes pictures the GPU passes: use it with --solver gpu");
            }
            let mut solver = CpuSolver::new(&scene, &layout, options.clone(), args.threads)?;
            solver.solve(progress);
            Solved::from_cpu(&solver)
        }
    };
    bar.finish_and_clear();
    // Light that reaches nothing means a scene error (most often emitters wound backwards), not
    // a black picture to write.
    if !solver.history.is_empty() && solver.history.iter().all(|r| r.reflected_power <= 0.0) {
        let lights: Vec<&str> = scene
            .polygons
            .iter()
            .filter(|p| scene.material(p).is_emitter())
            .map(|p| p.object.as_str())
            .collect();
        bail!(
            "{}: the light reaches no surface that reflects it: the emitters ({}) face away from \
             everything, or nothing in front of them has a reflectance (Kd) above 0. Emitters \
             shine from their front face: counter-clockwise vertex order seen from the front",
            scene_path.display(),
            lights.join(", ")
        );
    }
    let solve_seconds = solver.history.last().map(|r| r.seconds).unwrap_or(0.0);
    eprintln!(
        "solved: {} shots ({} passes), unshot fraction {:.5}, {:.3} s",
        solver.shots, solver.passes, solver.unshot_fraction, solve_seconds
    );

    let mut atlas = solver.atlas.clone();
    let camera = camera_from(args, scene.camera_or_default());
    let raw_atlas = atlas.clone();
    let ambient = if args.ambient {
        let l = display::ambient::ambient(&scene, &solver.unshot, &solver.patch_area);
        display::ambient::add_ambient(&scene, &mut atlas, l);
        eprintln!("ambient term: {:.5} {:.5} {:.5}", l.x, l.y, l.z);
        Some(l.to_array())
    } else {
        None
    };
    layout.dilate(&mut atlas);
    let mesh =
        crate::solver::mesh::upload(&ctx.gl, &crate::solver::mesh::vertex_data(&scene, &layout))?;
    let image = display::render(
        &ctx,
        &scene,
        &mesh,
        &atlas,
        (layout.atlas_width, layout.atlas_height),
        &camera,
        args.size,
    )?;

    output::write_exr(
        &out_dir.join("image.exr"),
        image.width,
        image.height,
        &image.rgb,
    )?;
    output::write_png(&out_dir.join("image.png"), &image, args.exposure)?;
    output::write_atlas_exr(
        &out_dir.join("lightmap.exr"),
        layout.atlas_width,
        layout.atlas_height,
        &raw_atlas,
    )?;
    let stats = Stats {
        scene: scene_path.display().to_string(),
        faces: scene.polygons.len(),
        vertices: scene.vertex_count,
        lights: scene.light_count(),
        patches: layout.patch_count(),
        patch_size: layout.patch_size,
        atlas: [layout.atlas_width, layout.atlas_height],
        solver: args.solver,
        mode: args.mode,
        backend: info.backend.name(),
        gl_vendor: info.vendor.clone(),
        gl_renderer: info.renderer.clone(),
        gl_version: info.version.clone(),
        options,
        shots: solver.shots,
        passes: solver.passes,
        solve_seconds,
        threads: (args.solver == SolverKind::Cpu).then(|| rayon_threads(args.threads)),
        unshot_fraction: solver.unshot_fraction,
        emitted_power: solver.emitted_power,
        ambient,
        pass_seconds: solver.pass_seconds,
        history: solver.history,
    };
    output::write_json(&out_dir.join("stats.json"), &stats)?;
    if args.plot {
        let title = format!("{} ({:?} mode)", scene.name, args.mode).to_lowercase();
        let path = out_dir.join("convergence.png");
        display::plot::write_convergence(&path, &stats.history, args.threshold, &title)?;
    }
    eprintln!("wrote {}", out_dir.display());
    Ok(SolveOutcome { stats, out_dir })
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
