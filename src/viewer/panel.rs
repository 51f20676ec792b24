//! The viewer's side panel (egui): controls, the overlays, what the solver is doing, and the
//! unshot fraction plotted against the shot. It folds and scrolls, and reports where its
//! controls went (`reach.rs`).

use super::overlays::OverlaySet;
use super::reach::Reach;
use super::ViewMode;
use crate::solver::{pass_names, PassTimes};
use egui::style::ScrollStyle;
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

/// What one frame of the panel gave: the user's actions and where its controls were laid out.
pub struct Shown {
    pub actions: Actions,
    pub reach: Reach,
}

/// The panel, top to bottom: what runs where, the run buttons, the overlays (the teaching view
/// of each pass, so near the top), the readout, the plot, the settings, the keys. Each part
/// folds, and the whole scrolls: at 720 pixels high it is taller than the window.
pub fn show(ctx: &egui::Context, c: &mut Controls, r: &Readout) -> Shown {
    let mut a = Actions::default();
    let mut reach = Reach::default();
    egui::SidePanel::right("panel")
        .exact_width(WIDTH)
        .resizable(false)
        .show(ctx, |ui| {
            // A solid bar, drawn whenever the panel overflows; egui's default floating bar
            // appears only under the mouse, so nothing told a user there was more below.
            ui.spacing_mut().scroll = ScrollStyle::solid();
            let out = egui::ScrollArea::vertical()
                .id_salt("panel")
                .auto_shrink([false, false])
                .show(ui, |ui| {
                    ui.heading("GPU radiosity");
                    ui.label(format!("scene {} · {} context", r.scene, r.window_api));
                    ui.label(format!("{} | {}", r.renderer, r.gl_version));
                    if let Some(m) = r.message {
                        ui.colored_label(egui::Color32::LIGHT_RED, m);
                    }
                    buttons(ui, c, &mut a, &mut reach);
                    section(ui, &mut reach, "overlays (keys 1-5)", |ui, reach| {
                        overlays(ui, &mut c.overlays, reach)
                    });
                    section(ui, &mut reach, "solve", |ui, _| readout(ui, r));
                    section(
                        ui,
                        &mut reach,
                        "unshot fraction against shot (log scale)",
                        |ui, _| plot(ui, r, c.threshold),
                    );
                    section(ui, &mut reach, "settings", |ui, reach| {
                        settings(ui, c, r, reach)
                    });
                    section(ui, &mut reach, "mouse and keys", |ui, _| {
                        ui.label(
                            "Left drag orbits, right drag pans, the wheel zooms (over the \
                             scene; over the panel it scrolls).\nSpace run/pause, S step, R \
                             reset, C camera, M mode, 1-5 overlays, Esc quit.",
                        );
                    });
                });
            reach.view = out.inner_rect;
            reach.content_height = out.content_size.y;
            reach.offset = out.state.offset.y;
        });
    Shown { actions: a, reach }
}

/// A part of the panel under a header that folds it (open at the start).
fn section(
    ui: &mut egui::Ui,
    reach: &mut Reach,
    title: &'static str,
    body: impl FnOnce(&mut egui::Ui, &mut Reach),
) {
    let folding = egui::CollapsingHeader::new(title)
        .default_open(true)
        .show(ui, |ui| body(ui, reach));
    reach.place(title, folding.header_response);
}

fn buttons(ui: &mut egui::Ui, c: &mut Controls, a: &mut Actions, reach: &mut Reach) {
    ui.horizontal(|ui| {
        let run = if c.running { "Pause" } else { "Run" };
        if reach.place("Run/Pause", ui.button(run)).clicked() {
            c.running ^= true;
        }
        if reach
            .place("Step one shot", ui.button("Step one shot"))
            .clicked()
        {
            a.step = true;
        }
        if reach.place("Reset", ui.button("Reset")).clicked() {
            a.reset = true;
        }
        if reach.place("Camera", ui.button("Camera")).clicked() {
            a.reset_camera = true;
        }
    });
}

/// The overlays' switches, named as `--overlays` names them.
fn overlays(ui: &mut egui::Ui, o: &mut OverlaySet, reach: &mut Reach) {
    let mut check = |on: &mut bool, name: &'static str, text: &str| {
        reach.place(name, ui.checkbox(on, text));
    };
    check(
        &mut o.shooter,
        "shooter",
        "1  shooters (last orange, next cyan)",
    );
    check(
        &mut o.item_buffer,
        "item-buffer",
        "2  item buffer from the last shooter",
    );
    check(&mut o.heat_map, "heat-map", "3  unshot energy heat map");
    check(&mut o.atlas, "atlas", "4  lightmap atlas");
    check(&mut o.borders, "borders", "5  patch borders");
}

fn settings(ui: &mut egui::Ui, c: &mut Controls, r: &Readout, reach: &mut Reach) {
    let shots = egui::Slider::new(&mut c.shots_per_frame, 1..=32).text("shots per frame (max)");
    reach.place("shots per frame", ui.add(shots));
    let threshold = egui::Slider::new(&mut c.threshold, 1e-4..=0.5)
        .logarithmic(true)
        .text("threshold");
    reach.place("threshold", ui.add(threshold));
    let exposure = egui::Slider::new(&mut c.exposure, 0.05..=20.0)
        .logarithmic(true)
        .text("exposure");
    reach.place("exposure", ui.add(exposure));
    ui.horizontal(|ui| {
        ui.label("mode");
        reach.place(
            "paper",
            ui.radio_value(&mut c.mode, ViewMode::Paper, "paper"),
        );
        let accurate = ui.radio_value(&mut c.mode, ViewMode::Accurate, "accurate");
        reach.place("accurate", accurate);
    });
    ui.horizontal(|ui| {
        ui.label("patch size");
        let step = (r.patch_size * 0.01).max(1e-6) as f64;
        let size = egui::DragValue::new(&mut c.patch_size)
            .speed(step)
            .range(c.patch_size_range.0..=c.patch_size_range.1);
        reach.place("patch size", ui.add(size));
    });
    if c.mode != r.mode || c.patch_size != r.patch_size {
        ui.colored_label(egui::Color32::YELLOW, "mode / patch size apply on Reset");
    }
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
            ms(t.get(pass_names::VISIBILITY), r.passes),
        );
        row(
            "reconstruction pass",
            ms(t.get(pass_names::RECONSTRUCTION), r.passes),
        );
        row(
            "accumulation copy",
            ms(t.get(pass_names::ACCUMULATION), r.passes),
        );
        row(
            "readback + max energy",
            ms(
                t.get(pass_names::READBACK) + t.get(pass_names::FIND_MAX_ENERGY),
                r.shots,
            ),
        );
        row("frames per second", format!("{:.1}", r.fps));
        row("frame draw time", format!("{:.1} ms", r.draw_ms));
    });
}

/// The unshot fraction against the shot, log scale, with the threshold dashed.
fn plot(ui: &mut egui::Ui, r: &Readout, threshold: f32) {
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

/// The panel in a 1280×720 window, driven headless through egui's input as a user would: the
/// mouse wheel over the panel, clicks on controls.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::viewer::reach::Reachable;
    use egui::{pos2, vec2, Event, Modifiers, MouseWheelUnit, PointerButton, Pos2, RawInput, Rect};

    /// A laptop's window: the panel gets its full height.
    const WINDOW: egui::Vec2 = vec2(1280.0, 720.0);

    struct Window {
        ctx: egui::Context,
        controls: Controls,
        times: PassTimes,
        time: f64,
    }

    impl Window {
        fn new() -> Window {
            Window {
                ctx: egui::Context::default(),
                controls: Controls {
                    running: false,
                    shots_per_frame: 4,
                    mode: ViewMode::Accurate,
                    threshold: 0.01,
                    patch_size: 22.0,
                    patch_size_range: (5.5, 88.0),
                    exposure: 1.0,
                    overlays: OverlaySet::from_list(&[]),
                },
                times: PassTimes::default(),
                time: 0.0,
            }
        }

        /// One frame with these events, a tenth of a second after the last.
        fn frame(&mut self, events: Vec<Event>) -> Shown {
            self.time += 0.1;
            let input = RawInput {
                screen_rect: Some(Rect::from_min_size(Pos2::ZERO, WINDOW)),
                time: Some(self.time),
                events,
                ..Default::default()
            };
            let readout = Readout {
                scene: "cornell",
                renderer: "llvmpipe (LLVM 15.0.6, 256 bits)",
                gl_version: "4.5 (Compatibility Profile) Mesa 22.3.6",
                window_api: "EGL",
                mode: ViewMode::Accurate,
                patch_size: 22.0,
                patches: 4051,
                atlas: (76, 92),
                shots: 10,
                passes: 819,
                unshot_fraction: 0.154,
                converged: false,
                last_shooter: Some((2, "ceiling")),
                next_shooter: Some((0, "floor")),
                times: &self.times,
                solve_seconds: 2.85,
                fps: 6.3,
                draw_ms: 362.5,
                history: (0..=10).map(|s| [s as f64, 0.8f64.powi(s)]).collect(),
                message: None,
            };
            let mut shown = None;
            // Nothing is painted: the tests read the layout and the controls.
            let _shapes = self.ctx.run(input, |ctx| {
                shown = Some(show(ctx, &mut self.controls, &readout));
            });
            shown.expect("the panel ran")
        }

        /// Frames with no input until the layout and any scrolling have settled.
        fn settle(&mut self) -> Shown {
            for _ in 0..10 {
                self.frame(vec![]);
            }
            self.frame(vec![])
        }

        /// Move the mouse to `at` and turn the wheel by `lines` (negative: scroll down).
        fn wheel(&mut self, at: Pos2, lines: f32) -> Shown {
            self.frame(vec![
                Event::PointerMoved(at),
                Event::MouseWheel {
                    unit: MouseWheelUnit::Line,
                    delta: vec2(0.0, lines),
                    modifiers: Modifiers::NONE,
                },
            ]);
            self.settle()
        }

        /// Click the control named `name`, which must be in view.
        fn click(&mut self, shown: &Shown, name: &str) {
            let &(_, rect) = shown
                .reach
                .controls
                .iter()
                .find(|(n, _)| *n == name)
                .unwrap_or_else(|| panic!("no control {name}"));
            assert_eq!(shown.reach.of(rect), Reachable::InView, "{name}");
            let at = rect.center();
            let button = |pressed| Event::PointerButton {
                pos: at,
                button: PointerButton::Primary,
                pressed,
                modifiers: Modifiers::NONE,
            };
            // The move in a frame of its own: moved and pressed at once, egui would take the
            // move for a drag of the panel's content, and scroll.
            self.frame(vec![Event::PointerMoved(at)]);
            self.frame(vec![button(true)]);
            self.frame(vec![button(false)]);
        }
    }

    fn names(shown: &Shown) -> Vec<&'static str> {
        shown.reach.controls.iter().map(|&(n, _)| n).collect()
    }

    #[test]
    fn at_1280_by_720_the_panel_overflows_and_every_control_is_reachable() {
        let mut w = Window::new();
        let top = w.settle();
        let all = names(&top);
        assert_eq!(all.len(), 20, "controls: {all:?}");
        let r = &top.reach;
        assert!(
            r.view.bottom() > WINDOW.y - 8.0,
            "the scroll view ends at {}",
            r.view.bottom()
        );
        assert!(
            r.content_height > r.view.height(),
            "the panel fits at 720 points ({} of {}): this test no longer tests scrolling",
            r.content_height,
            r.view.height()
        );
        assert!(r.named(Reachable::OutOfReach).is_empty(), "{r}");
        assert!(!r.named(Reachable::ByScrolling).is_empty(), "{r}");
        // The overlays, the teaching view of each pass, show without scrolling.
        for name in ["shooter", "item-buffer", "heat-map", "atlas", "borders"] {
            assert!(r.named(Reachable::InView).contains(&name), "{name}: {r}");
        }
    }

    #[test]
    fn the_wheel_over_the_panel_brings_every_control_into_view_and_they_work() {
        let mut w = Window::new();
        let mut shown = w.settle();
        let all = names(&shown);
        let mut seen: Vec<&str> = shown.reach.named(Reachable::InView);
        let over_panel = pos2(WINDOW.x - WIDTH / 2.0, WINDOW.y / 2.0);
        // A line at a time, down to the bottom (egui scrolls 50 points a line).
        for _ in 0..40 {
            let before = shown.reach.offset;
            shown = w.wheel(over_panel, -1.0);
            seen.extend(shown.reach.named(Reachable::InView));
            if shown.reach.offset == before {
                break;
            }
        }
        let bottom = shown.reach.content_height - shown.reach.view.height();
        assert!(
            (shown.reach.offset - bottom).abs() < 1.0,
            "the wheel stopped at {} of {bottom}",
            shown.reach.offset
        );
        let unseen: Vec<_> = all.iter().filter(|n| !seen.contains(n)).collect();
        assert!(unseen.is_empty(), "never in view: {unseen:?}");

        // At the bottom, the last controls work: a click switches the mode.
        w.click(&shown, "paper");
        assert_eq!(w.controls.mode, ViewMode::Paper);
        // And back at the top, the overlays' switches.
        let shown = w.wheel(over_panel, 40.0);
        assert_eq!(shown.reach.offset, 0.0);
        w.click(&shown, "heat-map");
        assert!(w.controls.overlays.heat_map && !w.controls.overlays.atlas);
        let shown = w.settle();
        w.click(&shown, "Run/Pause");
        assert!(w.controls.running);
    }

    #[test]
    fn a_folded_section_hides_its_controls_and_unfolds_again() {
        let mut w = Window::new();
        let shown = w.settle();
        w.click(&shown, "overlays (keys 1-5)");
        let folded = w.settle();
        assert!(!names(&folded).contains(&"heat-map"));
        assert!(
            folded.reach.content_height < shown.reach.content_height - 80.0,
            "folding the overlays saves their five rows"
        );
        w.click(&folded, "overlays (keys 1-5)");
        assert!(names(&w.settle()).contains(&"heat-map"));
    }
}
