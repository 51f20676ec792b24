//! How a render is held against its reference.
//!
//! Drivers may decide differently which of two polygons owns a pixel whose centre lies exactly
//! on their shared edge (GL leaves the tie-break to the implementation, and softpipe's differs
//! from llvmpipe's: the closed box's diagonal corner edges run through pixel centres). So a
//! pixel is compared with the closest value among the reference's 3x3 neighbourhood: a pixel
//! that took the other side of an edge matches that side, while any change over a region (a
//! wrong shot, a lost copy, a scrambled ID) still shows in full. The plain difference is
//! reported too (`differing`), and the diff pictures show every pixel that is not identical.

/// Relative RMS difference allowed (radiance pictures).
pub const RMS_TOLERANCE: f64 = 0.01;
/// Fraction of pixels allowed to differ by more than 5 % of the mean (radiance pictures).
pub const OUTLIER_TOLERANCE: f64 = 0.005;

/// What a picture's values are, which decides how it is compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    /// Linear radiance: relative RMS and outliers, within [`RMS_TOLERANCE`] and
    /// [`OUTLIER_TOLERANCE`].
    Radiance,
    /// Polygon IDs (ID + 1, 0 for nothing): exact, up to an edge. No pixel may hold an ID that
    /// its reference's 3x3 neighbourhood lacks.
    Ids,
}

/// A case compared with its reference: the figures and the verdict.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Comparison {
    /// The case's name.
    pub case: String,
    /// How it was compared.
    pub metric: Metric,
    /// Radiance: RMS of the edge-tolerant differences over the reference's mean. IDs: 0.
    pub rms: f64,
    /// Radiance: fraction of pixels off by more than 5 % of the mean, edge-tolerant. IDs:
    /// fraction of pixels whose ID is not in the reference's 3x3 neighbourhood.
    pub outliers: f64,
    /// Fraction of pixels that are not bit-identical to the reference.
    pub differing: f64,
    /// Radiance: the plain RMS difference (pixel against pixel) over the mean; IDs: 0. What
    /// the edge tolerance forgives is the gap between this and `rms`.
    pub rms_plain: f64,
    /// Whether every figure is within its tolerance.
    pub pass: bool,
    /// Why it failed, with the figures (empty when it passed).
    pub message: String,
}

/// Compare an RGB picture (`width` pixels a row) with its reference.
pub fn compare(
    name: &str,
    metric: Metric,
    width: usize,
    got: &[f32],
    reference: &[f32],
) -> Comparison {
    let pixels = reference.len() / 3;
    if got.len() != reference.len() || width == 0 || !pixels.is_multiple_of(width) {
        return Comparison {
            case: name.to_string(),
            metric,
            rms: f64::INFINITY,
            outliers: 1.0,
            differing: 1.0,
            rms_plain: f64::INFINITY,
            pass: false,
            message: format!(
                "the render has {} values where the reference has {}",
                got.len(),
                reference.len()
            ),
        };
    }
    let height = pixels / width;
    let px = |data: &[f32], x: usize, y: usize| -> [f32; 3] {
        let i = 3 * (y * width + x);
        [data[i], data[i + 1], data[i + 2]]
    };
    // got(x, y) against the closest reference pixel around it: (sum of squared channel
    // differences, largest channel difference) of that pixel. NaN counts as far off.
    let nearest = |x: usize, y: usize| -> (f64, f64) {
        let g = px(got, x, y);
        let mut best = (f64::INFINITY, f64::INFINITY);
        for ny in y.saturating_sub(1)..=(y + 1).min(height - 1) {
            for nx in x.saturating_sub(1)..=(x + 1).min(width - 1) {
                let r = px(reference, nx, ny);
                let d = (0..3).map(|c| (g[c] as f64 - r[c] as f64).abs());
                let sq: f64 = d.clone().map(|v| v * v).sum();
                let worst = d.fold(0.0, f64::max);
                if sq < best.0 {
                    best = (sq, worst);
                }
            }
        }
        best
    };
    let differing = got
        .chunks_exact(3)
        .zip(reference.chunks_exact(3))
        .filter(|(a, b)| a != b)
        .count() as f64
        / pixels.max(1) as f64;
    let case = name.to_string();
    match metric {
        Metric::Radiance => {
            let mean =
                reference.iter().map(|&v| v as f64).sum::<f64>() / reference.len().max(1) as f64;
            let scale = mean.max(1e-12);
            let plain = got
                .iter()
                .zip(reference)
                .map(|(&a, &b)| (a as f64 - b as f64).powi(2))
                .sum::<f64>();
            let rms_plain = (plain / reference.len().max(1) as f64).sqrt() / scale;
            let (mut sq, mut outliers) = (0.0, 0usize);
            for y in 0..height {
                for x in 0..width {
                    let (d2, worst) = nearest(x, y);
                    sq += d2;
                    outliers += (worst > 0.05 * scale) as usize;
                }
            }
            let rms = (sq / reference.len().max(1) as f64).sqrt() / scale;
            let outliers = outliers as f64 / pixels.max(1) as f64;
            let pass = rms <= RMS_TOLERANCE && outliers <= OUTLIER_TOLERANCE;
            let message = if pass {
                String::new()
            } else {
                format!(
                    "RMS {:.4} % of the mean (allowed {} %), {:.3} % of pixels off by more than \
                     5 % of the mean (allowed {} %)",
                    100.0 * rms,
                    100.0 * RMS_TOLERANCE,
                    100.0 * outliers,
                    100.0 * OUTLIER_TOLERANCE
                )
            };
            Comparison {
                case,
                metric,
                rms,
                outliers,
                differing,
                rms_plain,
                pass,
                message,
            }
        }
        Metric::Ids => {
            let mut wrong = 0usize;
            for y in 0..height {
                for x in 0..width {
                    wrong += (nearest(x, y).0 != 0.0) as usize;
                }
            }
            let outliers = wrong as f64 / pixels.max(1) as f64;
            let pass = wrong == 0;
            let message = if pass {
                String::new()
            } else {
                format!(
                    "{wrong} pixel(s) ({:.3} %) hold an ID that the reference has nowhere near \
                     them; none is allowed",
                    100.0 * outliers
                )
            };
            Comparison {
                case,
                metric,
                rms: 0.0,
                outliers,
                differing,
                rms_plain: 0.0,
                pass,
                message,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 16x16 picture: left half 0.2, right half 1.0 (an edge between columns 7 and 8).
    fn halves(edge: usize) -> Vec<f32> {
        (0..16 * 16)
            .flat_map(|i| {
                let v = if i % 16 < edge { 0.2 } else { 1.0 };
                [v, v, v]
            })
            .collect()
    }

    #[test]
    fn an_edge_one_pixel_over_passes_but_a_changed_region_fails() {
        let reference = halves(8);
        let shifted = compare("shifted", Metric::Radiance, 16, &halves(9), &reference);
        assert!(shifted.pass && shifted.rms == 0.0, "{shifted:?}");
        assert!(
            shifted.rms_plain > 0.1 && shifted.differing > 0.06,
            "{shifted:?}"
        );
        let darker: Vec<f32> = reference.iter().map(|v| v * 0.97).collect();
        let c = compare("darker", Metric::Radiance, 16, &darker, &reference);
        assert!(!c.pass && c.rms <= c.rms_plain, "{c:?}");
        let mut nan = reference.clone();
        nan[40] = f32::NAN;
        assert!(!compare("nan", Metric::Radiance, 16, &nan, &reference).pass);
    }

    #[test]
    fn ids_must_match_up_to_an_edge() {
        let reference = halves(8);
        assert!(compare("shifted", Metric::Ids, 16, &halves(9), &reference).pass);
        let mut stray = reference.clone();
        stray[3 * 20..3 * 21].copy_from_slice(&[7.0, 7.0, 7.0]);
        let c = compare("stray", Metric::Ids, 16, &stray, &reference);
        assert!(!c.pass && c.outliers > 0.0, "{c:?}");
    }
}
