//! `radiosity view [SCENE.obj]`: the interactive viewer (see src/viewer/).

use super::solve::{parse_size, Mode};
use super::values;
use crate::scene::Emission;
use crate::viewer::{self, Overlay, ViewOptions};
use anyhow::Result;
use clap::value_parser;
use std::path::PathBuf;

#[derive(clap::Args, Debug, Clone)]
pub struct ViewArgs {
    /// OBJ scene (with its MTL) or glTF scene (.glb, .gltf); default: the Cornell box built into
    /// the binary.
    pub scene: Option<PathBuf>,
    /// `paper` or `accurate`, as for `solve` (switch in the window with M).
    #[arg(long, value_enum, default_value_t = Mode::Accurate)]
    pub mode: Mode,
    /// Speed switches of the GPU passes, as for `solve`: auto, paper, llvmpipe, gpu.
    #[arg(long, value_enum, default_value_t = crate::solver::TuningChoice::Auto)]
    pub tuning: crate::solver::TuningChoice,
    /// Stop when unshot power / emitted power ≤ this (0 < F < 1). Mode default: paper 0.01,
    /// accurate 0.003.
    #[arg(long, value_parser = values::threshold, allow_hyphen_values = true)]
    pub threshold: Option<f32>,
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
    /// Make the material NAME emit light, as for `solve` (radiance R,G,B, as `Ke`). Repeatable.
    #[arg(long, value_name = "NAME=R,G,B", value_parser = values::emission, allow_hyphen_values = true)]
    pub emit: Vec<Emission>,
    /// Light the scene by a uniform sky of radiance R,G,B, as for `solve`.
    #[arg(long, value_name = "R,G,B", value_parser = values::sky, allow_hyphen_values = true)]
    pub sky: Option<glam::Vec3>,
    /// Keep every face its own polygon, as for `solve`.
    #[arg(long)]
    pub keep_faces: bool,
    /// Size of the scene view, WxH pixels (the panel is added on the right).
    #[arg(long, value_parser = parse_size, default_value = "720x720", allow_hyphen_values = true)]
    pub size: (u32, u32),
    /// Multiplier applied to radiance before tone mapping, as for `solve` (finite, > 0).
    #[arg(long, default_value_t = 1.0, value_parser = values::positive, allow_hyphen_values = true)]
    pub exposure: f32,
    /// Crease angle of the smooth shading, degrees, as for `solve` (0 to under 90; 0: off).
    #[arg(
        long,
        default_value_t = crate::display::smooth::DEFAULT_ANGLE,
        value_parser = values::smooth_angle,
        allow_hyphen_values = true,
    )]
    pub smooth_angle: f32,
    /// Most shots per frame while running, 1 to 64 (the window stays responsive).
    #[arg(
        long,
        default_value_t = 4,
        value_parser = value_parser!(u32).range(1..=64),
        allow_hyphen_values = true,
    )]
    pub shots_per_frame: u32,
    /// Overlays on at the start (keys 1-5 switch them).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "shooter")]
    pub overlays: Vec<Overlay>,
    /// Run, and after --after-shots shots save the whole window to this PNG and exit.
    #[arg(long, requires = "after_shots")]
    pub screenshot: Option<PathBuf>,
    /// Shots before the screenshot, 0 to 1,000,000 (fewer if the solve converges first).
    #[arg(
        long,
        requires = "screenshot",
        value_parser = value_parser!(u32).range(0..=values::MAX_SHOTS as i64),
        allow_hyphen_values = true,
    )]
    pub after_shots: Option<u32>,
}

pub fn run_view(args: &ViewArgs) -> Result<()> {
    let threshold = args.threshold.unwrap_or(args.mode.options().threshold);
    // The flags' ranges are checked while parsing (values.rs); this is for the library's rules.
    super::solve::check_solve_settings(threshold, args.patch_size, args.patches)?;
    viewer::run(ViewOptions {
        scene: args.scene.clone(),
        emit: args.emit.clone(),
        sky: args.sky,
        keep_faces: args.keep_faces,
        mode: args.mode,
        tuning: args.tuning,
        threshold,
        patch_size: args.patch_size,
        patches: args.patches,
        size: args.size,
        exposure: args.exposure,
        smooth_angle: args.smooth_angle,
        shots_per_frame: args.shots_per_frame,
        overlays: args.overlays.clone(),
        screenshot: args.screenshot.clone().zip(args.after_shots),
    })
}
