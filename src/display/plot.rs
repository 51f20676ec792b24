//! `convergence.png` (`radiosity solve --plot`): the unshot fraction (unshot power / emitted power)
//! against the shot and against the solve time, on a log scale, with the stopping threshold.
//! Drawn with plotters into a pixel buffer; text uses a font compiled into the binary (Ubuntu
//! Light, from egui's fonts), so no system font library is needed.

use super::output::Payload;
use super::output_set::OutputSet;
use crate::solver::ShotRecord;
use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::sync::Once;

const SIZE: (u32, u32) = (1200, 480);

pub(super) fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font; a failure would only lose the labels.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

/// Stage `convergence.png`: the two convergence plots side by side. `title` names the run
/// (scene, mode).
pub fn write_convergence(
    set: &OutputSet,
    history: &[ShotRecord],
    threshold: f32,
    title: &str,
) -> Result<()> {
    let rgb = draw_convergence(history, threshold, title)?;
    let (width, height) = SIZE;
    set.write(
        "convergence.png",
        Payload::Png {
            width,
            height,
            rgb: &rgb,
        },
    )
}

/// The plots as RGB pixels, rows top to bottom, `SIZE`.
pub fn draw_convergence(history: &[ShotRecord], threshold: f32, title: &str) -> Result<Vec<u8>> {
    register_font();
    let mut rgb = vec![255u8; SIZE.0 as usize * SIZE.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(plot_error)?;
        let (left, right) = root.split_horizontally(SIZE.0 / 2);
        // Shot 0 is the start: everything is unshot.
        let by_shot: Vec<(f64, f64)> = std::iter::once((0.0, 1.0))
            .chain(history.iter().map(|r| (r.shot as f64, r.unshot_fraction)))
            .collect();
        let by_time: Vec<(f64, f64)> = std::iter::once((0.0, 1.0))
            .chain(history.iter().map(|r| (r.seconds, r.unshot_fraction)))
            .collect();
        panel(&left, &by_shot, threshold, "shot", 0)?;
        panel(&right, &by_time, threshold, "solve time (s)", 2)?;
        root.present().map_err(plot_error)?;
    }
    Ok(rgb)
}

fn panel(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    points: &[(f64, f64)],
    threshold: f32,
    x_label: &str,
    x_decimals: usize,
) -> Result<()> {
    let label = format!("threshold {threshold}");
    let threshold = threshold as f64;
    let x_max = points.iter().map(|p| p.0).fold(0.0, f64::max).max(1e-3) * 1.02;
    let y_min = points
        .iter()
        .map(|p| p.1)
        .filter(|&y| y > 0.0)
        .fold(threshold, f64::min)
        .max(1e-9)
        * 0.5;
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..x_max, (y_min..1.2).log_scale())
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .x_label_formatter(&|x| format!("{x:.x_decimals$}"))
        .y_desc("unshot fraction (log)")
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .draw()
        .map_err(plot_error)?;
    let grey = RGBColor(150, 150, 150);
    chart
        .draw_series(DashedLineSeries::new(
            [(0.0, threshold), (x_max, threshold)],
            6,
            4,
            grey.stroke_width(1),
        ))
        .map_err(plot_error)?
        .label(label)
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], grey));
    let blue = RGBColor(31, 94, 170);
    chart
        .draw_series(LineSeries::new(
            points.iter().map(|&(x, y)| (x, y.max(y_min))),
            blue.stroke_width(2),
        ))
        .map_err(plot_error)?
        .label("unshot power / emitted power")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], blue.stroke_width(2)));
    chart
        .configure_series_labels()
        .label_font(("sans-serif", 15))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(plot_error)?;
    Ok(())
}

fn plot_error(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("cannot draw the convergence plot: {e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_a_curve_and_labels() {
        let history: Vec<ShotRecord> = (1..=20)
            .map(|k| ShotRecord {
                shot: k,
                shooter: 0,
                seconds: k as f64 * 0.1,
                unshot_fraction: 0.7f64.powi(k as i32),
                shot_power: 1.0,
                reflected_power: 0.5,
                carried_power: 1.0,
                received_power: 0.7,
            })
            .collect();
        let rgb = draw_convergence(&history, 0.01, "test").unwrap();
        let blue = rgb
            .chunks_exact(3)
            .filter(|p| p[2] > 150 && p[0] < 80)
            .count();
        let dark = rgb
            .chunks_exact(3)
            .filter(|p| p[0] < 60 && p[1] < 60)
            .count();
        assert!(blue > 500, "curve pixels: {blue}");
        assert!(dark > 2000, "text and axes pixels: {dark}");
    }
}
