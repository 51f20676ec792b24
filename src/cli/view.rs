//! `radiosity view [SCENE.obj]`: the interactive viewer (see src/viewer/).

use super::solve::{parse_size, Mode};
use crate::pipeline::DEFAULT_PATCHES;
use crate::viewer::{self, Overlay, ViewOptions};
use anyhow::{bail, Result};
use std::path::PathBuf;

#[derive(clap::Args, Debug, Clone)]
pub struct ViewArgs {
    /// OBJ scene (with its MTL); default: the Cornell box built into the binary.
    pub scene: Option<PathBuf>,
    /// `paper` or `accurate`, as for `solve` (switch in the window with M).
    #[arg(long, value_enum, default_value_t = Mode::Accurate)]
    pub mode: Mode,
    /// Stop when unshot power / emitted power ≤ this.
    #[arg(long, default_value_t = 0.01)]
    pub threshold: f32,
    /// Aim at about this many patches (default 4096 unless the scene sets a patch size).
    #[arg(long, conflicts_with = "patch_size")]
    pub patches: Option<u32>,
    /// Patch side in scene units.
    #[arg(long)]
    pub patch_size: Option<f32>,
    /// Size of the scene view, WxH pixels (the panel is added on the right).
    #[arg(long, value_parser = parse_size, default_value = "720x720")]
    pub size: (u32, u32),
    /// Multiplier applied to radiance before tone mapping, as for `solve`.
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
    /// Most shots per frame while running (the window stays responsive).
    #[arg(long, default_value_t = 4)]
    pub shots_per_frame: u32,
    /// Overlays on at the start (keys 1-5 switch them).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "shooter")]
    pub overlays: Vec<Overlay>,
    /// Run, and after --after-shots shots save the whole window to this PNG and exit.
    #[arg(long, requires = "after_shots")]
    pub screenshot: Option<PathBuf>,
    /// Shots before the screenshot (fewer if the solve converges first).
    #[arg(long, requires = "screenshot")]
    pub after_shots: Option<u32>,
}

pub fn run_view(args: &ViewArgs) -> Result<()> {
    super::solve::check_solve_settings(args.threshold, args.patch_size, args.patches)?;
    if !(1..=64).contains(&args.shots_per_frame) {
        bail!("--shots-per-frame must be between 1 and 64");
    }
    if !(args.exposure > 0.0 && args.exposure.is_finite()) {
        bail!("--exposure must be a positive number");
    }
    viewer::run(ViewOptions {
        scene: args.scene.clone(),
        mode: args.mode,
        threshold: args.threshold,
        patch_size: args.patch_size,
        patches: args.patches.unwrap_or(DEFAULT_PATCHES),
        size: args.size,
        exposure: args.exposure,
        shots_per_frame: args.shots_per_frame,
        overlays: args.overlays.clone(),
        screenshot: args.screenshot.clone().zip(args.after_shots),
    })
}
