//! The viewer's side panel (egui): controls, the overlays, what the solver is doing, and the
//! unshot fraction plotted against the shot.

use super::overlays::OverlaySet;
use super::ViewMode;
use crate::solver::{progressive, PassTimes};
use egui_plot::{HLine, Line, LineStyle, Plot, PlotPoints};

/// Width of the panel in points.
pub const WIDTH: f32 = 330.0;

/// What the user can change. Mode and patch size take effect on reset.
pub struct Controls {
    pub running: bool,
    pub shots_per_frame: u32,
    pub mode: ViewMode,
    pub threshold: f32,
    pub patch_size: f32,
    /// The patch sizes offered: a quarter to four times the starting one (16 times the patches
    /// at most, so a shot stays about a second on llvmpipe).
    pub patch_size_range: (f32, f32),
    pub exposure: f32,
    pub overlays: OverlaySet,
}

/// What the panel shows, read from the session each frame.
pub struct Readout<'s> {
    pub scene: &'s str,
    pub renderer: &'s str,
    pub gl_version: &'s str,
    pub window_api: &'s str,
    /// Mode and patch size of the running solve.
    pub mode: ViewMode,
    pub patch_size: f32,
    pub patches: u64,
    pub atlas: (u32, u32),
    pub shots: u32,
    pub passes: u32,
    pub unshot_fraction: f64,
    pub converged: bool,
    pub last_shooter: Option<(usize, &'s str)>,
    pub next_shooter: Option<(usize, &'s str)>,
    pub times: &'s PassTimes,
    pub solve_seconds: f64,
    pub fps: f32,
    /// Milliseconds to draw and present one frame.
    pub draw_ms: f32,
    /// (shot, unshot fraction), from shot 0.
    pub history: Vec<[f64; 2]>,
    pub message: Option<&'s str>,
}

/// What the user asked for this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Actions {
    pub step: bool,
    pub reset: bool,
    pub reset_camera: bool,
}

pub fn show(ctx: &egui::Context, c: &mut Controls, r: &Readout) -> Actions {
    let mut a = Actions::default();
    egui::SidePanel::right("panel")
        .exact_width(WIDTH)
        .resizable(false)
        .show(ctx, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.heading("GPU radiosity");
                ui.label(format!("scene {} · {} context", r.scene, r.window_api));
                ui.label(format!("{} | {}", r.renderer, r.gl_version));
                if let Some(m) = r.message {
                    ui.colored_label(egui::Color32::LIGHT_RED, m);
                }
                buttons(ui, c, &mut a);
                ui.separator();
                readout(ui, r);
                plot(ui, r, c.threshold);
                ui.separator();
                settings(ui, c, r);
                ui.separator();
                ui.label(
                    "Mouse: left drag orbit, right drag pan, wheel zoom.\nKeys: Space run/pause, \
                     S step, R reset, C camera, M mode, 1-5 overlays, Esc quit.",
                );
            });
        });
    a
}

fn buttons(ui: &mut egui::Ui, c: &mut Controls, a: &mut Actions) {
    ui.horizontal(|ui| {
        let run = if c.running { "Pause" } else { "Run" };
        if ui.button(run).clicked() {
            c.running ^= true;
        }
        if ui.button("Step one shot").clicked() {
            a.step = true;
        }
        if ui.button("Reset").clicked() {
            a.reset = true;
        }
        if ui.button("Camera").clicked() {
            a.reset_camera = true;
        }
    });
}

fn settings(ui: &mut egui::Ui, c: &mut Controls, r: &Readout) {
    ui.add(egui::Slider::new(&mut c.shots_per_frame, 1..=32).text("shots per frame (max)"));
    ui.add(
        egui::Slider::new(&mut c.threshold, 1e-4..=0.5)
            .logarithmic(true)
            .text("threshold"),
    );
    ui.add(
        egui::Slider::new(&mut c.exposure, 0.05..=20.0)
            .logarithmic(true)
            .text("exposure"),
    );
    ui.horizontal(|ui| {
        ui.label("mode");
        ui.radio_value(&mut c.mode, ViewMode::Paper, "paper");
        ui.radio_value(&mut c.mode, ViewMode::Accurate, "accurate");
    });
    ui.horizontal(|ui| {
        ui.label("patch size");
        let step = (r.patch_size * 0.01).max(1e-6) as f64;
        ui.add(
            egui::DragValue::new(&mut c.patch_size)
                .speed(step)
                .range(c.patch_size_range.0..=c.patch_size_range.1),
        );
    });
    if c.mode != r.mode || c.patch_size != r.patch_size {
        ui.colored_label(egui::Color32::YELLOW, "mode / patch size apply on Reset");
    }
    ui.label("overlays");
    let o = &mut c.overlays;
    ui.checkbox(&mut o.shooter, "1  shooters (last orange, next cyan)");
    ui.checkbox(&mut o.item_buffer, "2  item buffer from the last shooter");
    ui.checkbox(&mut o.heat_map, "3  unshot energy heat map");
    ui.checkbox(&mut o.atlas, "4  lightmap atlas");
    ui.checkbox(&mut o.borders, "5  patch borders");
}

fn readout(ui: &mut egui::Ui, r: &Readout) {
    // Passes run once per shooter cell, the readback and Find_Max_Energy once per shot.
    let ms = |s: f64, n: u32| format!("{:.2} ms", 1e3 * s / n.max(1) as f64);
    let t = r.times;
    egui::Grid::new("readout").num_columns(2).show(ui, |ui| {
        let mut row = |k: &str, v: String| {
            ui.label(k);
            ui.label(v);
            ui.end_row();
        };
        row("mode", r.mode.name().into());
        row(
            "patches",
            format!("{} (size {:.4})", r.patches, r.patch_size),
        );
        row("atlas", format!("{} x {} texels", r.atlas.0, r.atlas.1));
        let done = if r.converged { ", converged" } else { "" };
        row("shots", format!("{} ({} passes){done}", r.shots, r.passes));
        row("unshot fraction", format!("{:.5}", r.unshot_fraction));
        let name =
            |s: Option<(usize, &str)>| s.map_or("none".to_string(), |(id, o)| format!("#{id} {o}"));
        row("last shooter", name(r.last_shooter));
        row("next shooter", name(r.next_shooter));
        row("solve time", format!("{:.2} s", r.solve_seconds));
        row(
            "visibility pass",
            ms(t.get(progressive::VISIBILITY), r.passes),
        );
        row(
            "reconstruction pass",
            ms(t.get(progressive::RECONSTRUCTION), r.passes),
        );
        row(
            "accumulation copy",
            ms(t.get(progressive::ACCUMULATION), r.passes),
        );
        row(
            "readback + max energy",
            ms(
                t.get(progressive::READBACK) + t.get(progressive::FIND_MAX_ENERGY),
                r.shots,
            ),
        );
        row("frames per second", format!("{:.1}", r.fps));
        row("frame draw time", format!("{:.1} ms", r.draw_ms));
    });
}

fn plot(ui: &mut egui::Ui, r: &Readout, threshold: f32) {
    ui.label("unshot fraction against shot (log scale)");
    let log: Vec<[f64; 2]> = r
        .history
        .iter()
        .map(|&[x, y]| [x, y.max(1e-12).log10()])
        .collect();
    Plot::new("convergence")
        .height(170.0)
        .allow_zoom(false)
        .allow_drag(false)
        .allow_scroll(false)
        .include_y(0.0)
        .include_y((threshold as f64).log10() - 0.2)
        .y_axis_formatter(|m, _| {
            // Label whole decades only.
            let d = m.value.round();
            if (m.value - d).abs() < 1e-6 {
                format!("1e{d:.0}")
            } else {
                String::new()
            }
        })
        .show(ui, |p| {
            p.hline(
                HLine::new("threshold", (threshold as f64).log10())
                    .color(egui::Color32::GRAY)
                    .style(LineStyle::dashed_loose()),
            );
            p.line(
                Line::new("unshot fraction", PlotPoints::from(log))
                    .color(egui::Color32::from_rgb(90, 170, 255))
                    .width(2.0),
            );
        });
}
