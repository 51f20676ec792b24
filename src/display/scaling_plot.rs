//! `docs/scaling.png` and `docs/scaling-fast.png` (`radiosity bench scaling --plot`): loop
//! seconds against patches, log-log, one line per room and solver, the configuration in the
//! caption; extrapolated points hollow. Drawn like `plot.rs`.

use anyhow::{anyhow, Result};
use plotters::prelude::*;

/// Width and height of the plot in pixels.
pub const SIZE: (u32, u32) = (900, 600);

/// One point of the plot: a room solved by one solver at one patch count. (The bench's runs
/// carry more; it hands over only this, so the library does not depend on the command line.)
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// The room; the lines join the points of one room and solver.
    pub room: String,
    /// The solver (`gpu`, `cpu`).
    pub solver: String,
    /// The patches of the run (the x axis).
    pub patches: u64,
    /// Loop seconds to the stopping rule, measured or extrapolated.
    pub loop_s: f64,
    /// Measured to the stopping rule (a filled dot), or extrapolated from a run the time
    /// budget stopped (a hollow one).
    pub measured: bool,
}

/// The plot as RGB pixels, rows top to bottom, [`SIZE`]. `exponents`: (room, solver, slope);
/// `configuration`: the configuration timed (`paper-faithful` or `fast`), named in the caption.
pub fn draw(
    points: &[Point],
    exponents: &[(String, String, f64)],
    configuration: &str,
) -> Result<Vec<u8>> {
    super::plot::register_font();
    let error = |e: &dyn std::fmt::Display| anyhow!("cannot draw the scaling plot: {e}");
    let mut rgb = vec![255u8; SIZE.0 as usize * SIZE.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| error(&e))?;
        let xs = points.iter().map(|p| p.patches as f64);
        let ys = points.iter().map(|p| p.loop_s.max(1e-3));
        let (x0, x1) = xs.fold((f64::MAX, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
        let (y0, y1) = ys.fold((f64::MAX, 0.0f64), |(a, b), y| (a.min(y), b.max(y)));
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("Loop time against patches (log-log), {configuration} configuration"),
                ("sans-serif", 22),
            )
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (x0 / 1.5..x1 * 1.5).log_scale(),
                (y0 / 2.0..y1 * 2.0).log_scale(),
            )
            .map_err(|e| error(&e))?;
        chart
            .configure_mesh()
            .x_desc("patches (filled: measured to the stopping rule; hollow: extrapolated from a budgeted run)")
            .y_desc("loop seconds to the stopping rule")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| {
                if *y >= 1.0 {
                    format!("{y:.0}")
                } else {
                    format!("{y:.2}")
                }
            })
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .draw()
            .map_err(|e| error(&e))?;
        let colours = [
            RGBColor(31, 94, 170),
            RGBColor(200, 80, 40),
            RGBColor(60, 150, 70),
            RGBColor(140, 70, 160),
        ];
        for (k, (room, solver, slope)) in exponents.iter().enumerate() {
            let colour = colours[k % colours.len()];
            let points: Vec<(f64, f64, bool)> = points
                .iter()
                .filter(|p| &p.room == room && &p.solver == solver)
                .map(|p| (p.patches as f64, p.loop_s, p.measured))
                .collect();
            chart
                .draw_series(LineSeries::new(
                    points.iter().map(|p| (p.0, p.1)),
                    colour.stroke_width(2),
                ))
                .map_err(|e| error(&e))?
                .label(format!("{room}, {solver}: exponent {slope:.2}"))
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(points.iter().map(|&(x, y, complete)| {
                    let style = if complete {
                        colour.filled()
                    } else {
                        colour.stroke_width(2)
                    };
                    Circle::new((x, y), 5, style)
                }))
                .map_err(|e| error(&e))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(("sans-serif", 15))
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| error(&e))?;
        root.present().map_err(|e| error(&e))?;
    }
    Ok(rgb)
}
