//! Golden images: small reference renders of the bundled scenes in both modes, for regression
//! testing a Mesa build (`radiosity check`, `tests/golden.rs`). The references of tests/golden/
//! and the scenes are built into the binary, so an installed `radiosity check` needs no source
//! tree; `--against DIR` compares with other references.
//!
//! Metric: the relative RMS difference (RMS of the pixel differences over the mean radiance of
//! the reference) and the fraction of pixels that differ by more than 5 % of the reference's
//! mean. On the same driver the images are bit-identical (the solve is deterministic); the
//! tolerances leave room for another Mesa's rounding, not for a changed algorithm.

use crate::display::{self, Image};
use crate::gl::GlContext;
use crate::patches::{PatchLayout, Resolution};
use crate::pipeline::{self, SolverKind};
use crate::scene::bundled;
use crate::solver::SolveOptions;
use anyhow::{bail, Context, Result};
use std::path::Path;

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

/// Where the reference images are.
pub enum References<'a> {
    /// The copies of tests/golden/ built into the binary.
    BuiltIn,
    /// `<case>.exr` files in a directory.
    Dir(&'a Path),
}

macro_rules! golden {
    ($case:literal) => {
        (
            $case,
            include_bytes!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/tests/golden/",
                $case,
                ".exr"
            ))
            .as_slice(),
        )
    };
}

/// tests/golden/ at build time, one per case.
const BUILT_IN: [(&str, &[u8]); 6] = [
    golden!("cornell-paper"),
    golden!("cornell-accurate"),
    golden!("box-paper"),
    golden!("box-accurate"),
    golden!("shadow-paper"),
    golden!("shadow-accurate"),
];

/// Solve and render a case (1,024 patches, threshold 0.01, 96x96, the scene's camera).
pub fn render(ctx: &GlContext, case: &Case) -> Result<Image> {
    let scene = bundled::find(case.scene)
        .with_context(|| format!("no built-in scene '{}'", case.scene))?
        .load()?;
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

impl References<'_> {
    fn read(&self, case: &str) -> Result<Vec<f32>> {
        let img = match self {
            References::Dir(dir) => {
                let path = dir.join(format!("{case}.exr"));
                image::open(&path)
                    .with_context(|| format!("cannot read the golden image {}", path.display()))?
            }
            References::BuiltIn => {
                let (_, bytes) = BUILT_IN
                    .iter()
                    .find(|(name, _)| *name == case)
                    .with_context(|| format!("no built-in golden image for {case}"))?;
                image::load_from_memory_with_format(bytes, image::ImageFormat::OpenExr)
                    .with_context(|| format!("cannot read the built-in golden image {case}.exr"))?
            }
        };
        Ok(img.to_rgb32f().into_raw())
    }
}

/// Render every case and compare it with its reference; on a failure write
/// `<diff_dir>/<case>-diff.png` (|difference| × 10, tone mapped). With `update`, write the
/// renders as the new references instead (into a directory: the built-in ones are fixed).
pub fn check(
    ctx: &GlContext,
    references: &References,
    diff_dir: &Path,
    update: bool,
) -> Result<Vec<Comparison>> {
    let update_dir = match (update, references) {
        (false, _) => None,
        (true, References::Dir(dir)) => Some(*dir),
        (true, References::BuiltIn) => {
            bail!("the built-in golden images cannot be updated: name a directory of references")
        }
    };
    let mut results = Vec::new();
    for case in CASES {
        let name = case.name();
        let image = render(ctx, case)?;
        if let Some(dir) = update_dir {
            std::fs::create_dir_all(dir)?;
            let path = dir.join(format!("{name}.exr"));
            display::output::write_exr(&path, image.width, image.height, &image.rgb)?;
            results.push(Comparison {
                case: name,
                rms: 0.0,
                outliers: 0.0,
                pass: true,
            });
            continue;
        }
        let reference = references.read(&name)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_case_has_a_built_in_reference_of_its_size() {
        for case in CASES {
            let rgb = References::BuiltIn.read(&case.name()).unwrap();
            assert_eq!(rgb.len(), (SIZE.0 * SIZE.1 * 3) as usize, "{}", case.name());
        }
    }
}
