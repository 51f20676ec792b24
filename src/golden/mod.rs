//! Golden pictures: small reference renders of the bundled scenes and probes of single GL paths,
//! for regression testing a Mesa build (`radiosity check`, `tests/golden.rs`). The references
//! of tests/golden/ and the scenes are built into the binary, so an installed `radiosity check`
//! needs no source tree; `--against DIR` compares with other references. `drivers.rs` runs the
//! check on each of Mesa's software drivers, `report.rs` writes the results for CI systems.
//!
//! On one driver the pictures are bit-identical run after run (the solve is deterministic); the
//! tolerances (`compare.rs`) leave room for another driver's rounding and edge rules, not for a
//! changed algorithm. The driver matrix renders each case twice and requires the two renders to
//! be bit-identical ([`check_twice`]).

pub mod cases;
pub mod compare;
pub mod drivers;
pub mod report;
pub mod upload_order;

pub use cases::{Case, Picture, CASES, SIZE};
pub use compare::{compare, Comparison, Metric, OUTLIER_TOLERANCE, RMS_TOLERANCE};

use crate::display::{self, Image};
use crate::gl::{faults, GlContext};
use anyhow::{bail, Context, Result};
use std::path::Path;
use std::time::Instant;

/// Where the reference pictures are.
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
const BUILT_IN: [(&str, &[u8]); 11] = [
    golden!("cornell-paper"),
    golden!("cornell-accurate"),
    golden!("cornell-accurate-walked"),
    golden!("box-paper"),
    golden!("box-accurate"),
    golden!("shadow-paper"),
    golden!("shadow-accurate"),
    golden!("ids-hemicube"),
    golden!("ids-hemisphere"),
    golden!("shot-float-copy"),
    golden!("shots-accumulate"),
];

impl References<'_> {
    fn read(&self, case: &str) -> Result<Vec<f32>> {
        // Known without a driver: GL orders the uploads and the draws.
        if case == upload_order::NAME {
            return Ok(upload_order::expected());
        }
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

/// The cases named in `names` (all of them when it is empty), in the order of [`CASES`].
pub fn select(names: &[String]) -> Result<Vec<&'static Case>> {
    for name in names {
        if !CASES.iter().any(|c| c.name == name) {
            let known: Vec<&str> = CASES.iter().map(|c| c.name).collect();
            bail!("no golden case '{name}' (cases: {})", known.join(", "));
        }
    }
    Ok(CASES
        .iter()
        .filter(|c| names.is_empty() || names.iter().any(|n| n == c.name))
        .collect())
}

/// One case's outcome and how long it took.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Outcome {
    /// The case compared with its reference (the first render, when it ran twice).
    #[serde(flatten)]
    pub comparison: Comparison,
    /// Seconds the case took (the first render).
    pub seconds: f64,
    /// The second render, when the case ran twice ([`check_twice`]).
    #[serde(default)]
    pub rerun: Option<Rerun>,
}

/// A case rendered a second time in the same process, against its first render.
///
/// "Differ" is bitwise: the two renders make the same GL calls on the same driver from the
/// same inputs, so every value must have the same bits (as it has on every driver here, run
/// after run). A driver may differ from the references within the tolerances, but never from
/// itself: a difference means the answer depends on timing (a race in the driver, or the
/// program relying on something GL does not promise), which the tolerances could hide.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Rerun {
    /// Fraction of the picture's values (pixels' channels) whose bits differ from the first
    /// render's.
    pub differing: f64,
    /// The largest absolute difference between the two (infinite where one is not a number).
    pub largest: f64,
    /// Seconds the second render took.
    pub seconds: f64,
}

impl Rerun {
    /// `second` against `first`, rendered in `seconds`.
    pub fn of(first: &[f32], second: &[f32], seconds: f64) -> Rerun {
        if first.len() != second.len() {
            return Rerun {
                differing: 1.0,
                largest: f64::INFINITY,
                seconds,
            };
        }
        let (mut differing, mut largest) = (0usize, 0.0f64);
        for (&a, &b) in first.iter().zip(second) {
            if a.to_bits() != b.to_bits() {
                differing += 1;
                let d = (a as f64 - b as f64).abs();
                largest = largest.max(if d.is_nan() { f64::INFINITY } else { d });
            }
        }
        Rerun {
            differing: differing as f64 / first.len().max(1) as f64,
            largest,
            seconds,
        }
    }
}

/// Run each case and compare it with its reference. Where a picture is not bit-identical, write
/// `<diff_dir>/<case>-diff.png` (radiance: |difference| x 10; IDs: white where they differ)
/// and `<case>-got.png`. With `update`, write the renders as the new references instead (into
/// a directory: the built-in ones are fixed).
pub fn check(
    ctx: &GlContext,
    cases: &[&Case],
    references: &References,
    diff_dir: &Path,
    update: bool,
) -> Result<Vec<Outcome>> {
    check_runs(ctx, cases, references, diff_dir, update, false)
}

/// [`check`], each case rendered twice: the first render is compared with the reference, the
/// second with the first, bit for bit ([`Rerun`]); a case whose renders differ fails.
pub fn check_twice(
    ctx: &GlContext,
    cases: &[&Case],
    references: &References,
    diff_dir: &Path,
) -> Result<Vec<Outcome>> {
    check_runs(ctx, cases, references, diff_dir, false, true)
}

fn check_runs(
    ctx: &GlContext,
    cases: &[&Case],
    references: &References,
    diff_dir: &Path,
    update: bool,
    twice: bool,
) -> Result<Vec<Outcome>> {
    let update_dir = match (update, references) {
        (false, _) => None,
        (true, References::Dir(dir)) => Some(*dir),
        (true, References::BuiltIn) => {
            bail!("the built-in golden images cannot be updated: name a directory of references")
        }
    };
    let mut results = Vec::new();
    for case in cases {
        let t = Instant::now();
        let picture =
            cases::render(ctx, case).with_context(|| format!("golden case {}", case.name))?;
        let seconds = t.elapsed().as_secs_f64();
        // upload-order's reference is computed, never written.
        let comparison = if let Some(dir) = update_dir.filter(|_| case.name != upload_order::NAME) {
            std::fs::create_dir_all(dir)?;
            let path = dir.join(format!("{}.exr", case.name));
            display::output::write_exr(&path, picture.width, picture.height, &picture.rgb)?;
            compare(
                case.name,
                picture.metric,
                picture.width as usize,
                &picture.rgb,
                &picture.rgb,
            )
        } else {
            let reference = references.read(case.name)?;
            let c = compare(
                case.name,
                picture.metric,
                picture.width as usize,
                &picture.rgb,
                &reference,
            );
            if c.differing > 0.0 && picture.rgb.len() == reference.len() {
                write_diff(diff_dir, case.name, &picture, &reference)?;
            }
            c
        };
        let rerun = if twice {
            let t = Instant::now();
            faults::rerun(true);
            let second = cases::render(ctx, case);
            faults::rerun(false);
            let second = second.with_context(|| format!("golden case {}, again", case.name))?;
            Some(Rerun::of(
                &picture.rgb,
                &second.rgb,
                t.elapsed().as_secs_f64(),
            ))
        } else {
            None
        };
        let mut comparison = comparison;
        if let Some(r) = rerun.as_ref().filter(|r| r.differing > 0.0) {
            comparison.pass = false;
            let why = format!(
                "the second render differs from the first in {:.3} % of its values (largest \
                 difference {:.3e})",
                100.0 * r.differing,
                r.largest
            );
            comparison.message = match comparison.message.is_empty() {
                true => why,
                false => format!("{}; {why}", comparison.message),
            };
        }
        results.push(Outcome {
            comparison,
            seconds,
            rerun,
        });
    }
    Ok(results)
}

fn write_diff(dir: &Path, name: &str, picture: &Picture, reference: &[f32]) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    let image = |rgb: Vec<f32>| Image {
        width: picture.width,
        height: picture.height,
        rgb,
    };
    let (diff, got) = match picture.metric {
        Metric::Radiance => (
            picture
                .rgb
                .iter()
                .zip(reference)
                .map(|(a, b)| 10.0 * (a - b).abs())
                .collect(),
            picture.rgb.clone(),
        ),
        Metric::Ids => {
            let top = picture.rgb.iter().copied().fold(1.0, f32::max);
            (
                picture
                    .rgb
                    .iter()
                    .zip(reference)
                    .map(|(a, b)| if a != b { 1.0 } else { 0.0 })
                    .collect(),
                picture.rgb.iter().map(|v| v / top).collect(),
            )
        }
    };
    display::output::write_png(&dir.join(format!("{name}-diff.png")), &image(diff), 1.0)?;
    display::output::write_png(&dir.join(format!("{name}-got.png")), &image(got), 1.0)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_case_has_a_built_in_reference() {
        for case in CASES {
            let rgb = References::BuiltIn.read(case.name).unwrap();
            if let cases::Probe::Render { .. } = case.probe {
                assert_eq!(rgb.len(), (SIZE.0 * SIZE.1 * 3) as usize, "{}", case.name);
            }
            assert!(!rgb.is_empty(), "{}", case.name);
        }
        // Every case but upload-order, whose reference is computed.
        assert_eq!(BUILT_IN.len() + 1, CASES.len());
    }

    #[test]
    fn a_rerun_differs_by_any_bit() {
        let first = [0.25f32, 0.0, 1.0, f32::NAN];
        let same = Rerun::of(&first, &first, 0.0);
        assert_eq!(
            (same.differing, same.largest),
            (0.0, 0.0),
            "NaN bits equal NaN bits"
        );
        // One ulp, and zero's sign: within any tolerance, still not the same answer.
        let nudged = [f32::from_bits(0.25f32.to_bits() + 1), -0.0, 1.0, f32::NAN];
        let r = Rerun::of(&first, &nudged, 0.0);
        assert_eq!(r.differing, 0.5);
        assert!(r.largest > 0.0 && r.largest < 1e-7, "{}", r.largest);
        assert_eq!(Rerun::of(&first, &first[..3], 0.0).differing, 1.0);
    }
}
