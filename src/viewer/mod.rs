//! `radiosity view`: the scene lit shot by shot in a window, for seeing the paper's algorithm
//! work. It runs the same `GpuSolver` and passes as `radiosity solve`, on the window's GL 3.0
//! compatibility context (`gl::window`), and shows what each shot does.
//!
//! `app.rs` is the frame loop (events → a bounded number of shots → draw → panel → present);
//! `session.rs` one solve (layout, solver, the textures the frame draws from; rebuilt on reset);
//! `camera.rs` the orbit camera; `overlays.rs` the overlays and insets; `panel.rs` the egui side
//! panel; `reach.rs` which of the panel's controls a user can reach (in view, or by scrolling).

mod app;
pub mod camera;
pub mod overlays;
mod panel;
mod reach;
mod session;

pub use overlays::Overlay;

use std::path::PathBuf;

/// The solver settings the viewer runs: the same two modes as `radiosity solve`.
pub use crate::pipeline::Mode as ViewMode;

/// Everything `radiosity view` is asked for, validated.
#[derive(Clone, Debug)]
pub struct ViewOptions {
    /// The OBJ file; `None`: the Cornell box built into the binary.
    pub scene: Option<PathBuf>,
    /// Emission overrides applied after loading (`--emit NAME=R,G,B`).
    pub emit: Vec<crate::scene::Emission>,
    /// A uniform sky's radiance (`--sky R,G,B`).
    pub sky: Option<glam::Vec3>,
    /// Keep every face its own polygon (`--keep-faces`).
    pub keep_faces: bool,
    /// The solver settings, as `solve --mode`.
    pub mode: ViewMode,
    /// The speed switches, as `solve --tuning` (resolved on the window's renderer).
    pub tuning: crate::solver::TuningChoice,
    /// Stop when unshot power / emitted power ≤ this. Range (0, 1); typical 0.01.
    pub threshold: f32,
    /// Patch side in scene units; `None`: the scene's `# patch-size`, else about `patches`.
    pub patch_size: Option<f32>,
    /// Patches in all when no patch size is given; `None`: the default budget
    /// (`pipeline::default_patches`).
    pub patches: Option<u32>,
    /// The scene view in pixels (the panel is added beside it). Typical 720x720.
    pub size: (u32, u32),
    /// Radiance multiplier before tone mapping, as `solve --exposure`. Typical 1.
    pub exposure: f32,
    /// Crease angle of the smooth shading, degrees, as `solve --smooth-angle` (0: off). Range
    /// [0, 90); typical `display::smooth::DEFAULT_ANGLE`.
    pub smooth_angle: f32,
    /// Most shots per frame while running. Range 1..=64; typical 4.
    pub shots_per_frame: u32,
    /// The overlays on at the start (`--overlays`).
    pub overlays: Vec<Overlay>,
    /// Run from the start, and after this many shots (or convergence) save the window as a PNG
    /// and exit.
    pub screenshot: Option<(PathBuf, u32)>,
}

/// Open the window and run until it is closed (or the screenshot is written).
pub fn run(options: ViewOptions) -> anyhow::Result<()> {
    app::run(options)
}
