//! Golden images: small reference renders of the bundled scenes in both modes, for regression
//! testing a Mesa build (`radiosity check --against tests/golden`, `tests/golden.rs`).
//!
//! Metric: the relative RMS difference (RMS of the pixel differences over the mean radiance of
//! the reference) and the fraction of pixels that differ by more than 5 % of the reference's
//! mean. On the same driver the images are bit-identical (the solve is deterministic); the
//! tolerances leave room for another Mesa's rounding, not for a changed algorithm.

use crate::display::{self, Image};
use crate::gl::GlContext;
use crate::patches::{PatchLayout, Resolution};
use crate::pipeline::{self, SolverKind};
use crate::solver::SolveOptions;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// Relative RMS difference allowed.
pub const RMS_TOLERANCE: f64 = 0.01;
/// Fraction of pixels allowed to differ by more than 5 % of the mean.
pub const OUTLIER_TOLERANCE: f64 = 0.005;

pub struct Case {
    pub scene: &'static str,
    pub mode: &'static str,
}

impl Case {
    pub fn name(&self) -> String {
        format!("{}-{}", self.scene, self.mode)
    }

    fn options(&self) -> SolveOptions {
        match self.mode {
            "paper" => SolveOptions::paper(),
            _ => SolveOptions::accurate(),
        }
    }
}

pub const CASES: &[Case] = &[
    Case {
        scene: "cornell",
        mode: "paper",
    },
    Case {
        scene: "cornell",
        mode: "accurate",
    },
    Case {
        scene: "box",
        mode: "paper",
    },
    Case {
        scene: "box",
        mode: "accurate",
    },
    Case {
        scene: "shadow",
        mode: "paper",
    },
    Case {
        scene: "shadow",
        mode: "accurate",
    },
];

pub const SIZE: (u32, u32) = (96, 96);
const PATCHES: u32 = 1024;

fn scene_path(scene: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(scene)
        .join(format!("{scene}.obj"))
}

/// Solve and render a case (1,024 patches, threshold 0.01, 96x96, the scene's camera).
pub fn render(ctx: &GlContext, case: &Case) -> Result<Image> {
    let scene = pipeline::load_scene(Some(&scene_path(case.scene)))?;
    let layout = PatchLayout::try_new(&scene, Resolution::Patches(PATCHES))?;
    let solution = pipeline::solve(
        ctx,
        &scene,
        &layout,
        SolverKind::Gpu,
        case.options(),
        0,
        |_| {},
    )?;
    let (atlas, _) = solution.display_atlas(&scene, &layout, false);
    let camera = scene.camera_or_default();
    Ok(pipeline::render(
        ctx, &scene, &layout, &atlas, &camera, SIZE,
    )?)
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct Comparison {
    pub case: String,
    pub rms: f64,
    pub outliers: f64,
    pub pass: bool,
}

pub fn compare(name: &str, got: &[f32], reference: &[f32]) -> Comparison {
    let mean = reference.iter().map(|&v| v as f64).sum::<f64>() / reference.len().max(1) as f64;
    let scale = mean.max(1e-12);
    let (mut sq, mut outliers) = (0.0, 0usize);
    for (px_got, px_ref) in got.chunks_exact(3).zip(reference.chunks_exact(3)) {
        let mut worst = 0f64;
        for (a, b) in px_got.iter().zip(px_ref) {
            let d = (*a as f64 - *b as f64).abs();
            sq += d * d;
            worst = worst.max(d);
        }
        outliers += (worst > 0.05 * scale) as usize;
    }
    let rms = (sq / reference.len().max(1) as f64).sqrt() / scale;
    let outliers = outliers as f64 / (reference.len() / 3).max(1) as f64;
    Comparison {
        case: name.to_string(),
        rms,
        outliers,
        pass: got.len() == reference.len() && rms <= RMS_TOLERANCE && outliers <= OUTLIER_TOLERANCE,
    }
}

fn read_exr(path: &Path) -> Result<Vec<f32>> {
    let img = image::open(path)
        .with_context(|| format!("cannot read the golden image {}", path.display()))?;
    Ok(img.to_rgb32f().into_raw())
}

/// Render every case and compare it with `dir/<case>.exr`; on a failure write
/// `<diff_dir>/<case>-diff.png` (|difference| × 10, tone mapped). With `update`, write the
/// renders as the new references instead.
pub fn check(
    ctx: &GlContext,
    dir: &Path,
    diff_dir: &Path,
    update: bool,
) -> Result<Vec<Comparison>> {
    let mut results = Vec::new();
    for case in CASES {
        let name = case.name();
        let image = render(ctx, case)?;
        let path = dir.join(format!("{name}.exr"));
        if update {
            std::fs::create_dir_all(dir)?;
            display::output::write_exr(&path, image.width, image.height, &image.rgb)?;
            results.push(Comparison {
                case: name,
                rms: 0.0,
                outliers: 0.0,
                pass: true,
            });
            continue;
        }
        let reference = read_exr(&path)?;
        let c = compare(&name, &image.rgb, &reference);
        if !c.pass {
            std::fs::create_dir_all(diff_dir)?;
            let diff: Vec<f32> = image
                .rgb
                .iter()
                .zip(&reference)
                .map(|(a, b)| 10.0 * (a - b).abs())
                .collect();
            let diff = Image {
                width: image.width,
                height: image.height,
                rgb: diff,
            };
            display::output::write_png(&diff_dir.join(format!("{name}-diff.png")), &diff, 1.0)?;
            display::output::write_png(&diff_dir.join(format!("{name}-got.png")), &image, 1.0)?;
        }
        results.push(c);
    }
    Ok(results)
}
