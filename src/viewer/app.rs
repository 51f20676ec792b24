//! The viewer's frame loop. The event loop is pumped from here (winit's pump_events), so one
//! solve (`Session`) can borrow the context, scene and layout that live in this function's
//! frames; reset ends the solve's loop and builds a new one.
//!
//! Each frame: take the window's events (panel first, then camera and keys) → at most
//! `shots_per_frame` shots within a time budget → the scene, the insets, the panel → present.

use super::camera::OrbitCamera;
use super::overlays::{Insets, OverlaySet};
use super::panel::{self, Actions, Controls, Readout};
use super::reach::Reach;
use super::session::Session;
use super::{ViewMode, ViewOptions};
use crate::display::output::{write_atomic, Payload};
use crate::display::Viewport;
use crate::gl::window::GlWindow;
use crate::gl::GlContext;
use crate::patches::{PatchLayout, Resolution};
use crate::scene::Scene;
use anyhow::{anyhow, Context as _, Result};
use std::path::Path;
use std::rc::Rc;
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::platform::pump_events::{EventLoopExtPumpEvents, PumpStatus};
use winit::window::WindowId;

/// Time the solver may take per frame before the frame is drawn (at least one shot is taken).
const SOLVE_BUDGET: Duration = Duration::from_millis(40);
/// How long to wait for events when nothing moves.
const IDLE_WAIT: Duration = Duration::from_millis(100);
/// Frames drawn after the last shot before a screenshot (egui lays some things out in two).
const SETTLE_FRAMES: u32 = 3;

/// The window's events, gathered while the loop is pumped.
#[derive(Default)]
struct Events(Vec<WindowEvent>);

impl ApplicationHandler for Events {
    fn resumed(&mut self, _: &ActiveEventLoop) {}
    fn window_event(&mut self, _: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        self.0.push(event);
    }
}

/// The panel's egui: its context, its winit input state and its GL painter.
struct Gui {
    ctx: egui::Context,
    state: egui_winit::State,
    painter: egui_glow::Painter,
}

enum Next {
    Reset,
    Quit,
}

/// What outlives a solve: the window and its input, the panel, the camera, the controls.
struct Viewer {
    event_loop: EventLoop<()>,
    window: Rc<GlWindow>,
    events: Events,
    gui: Gui,
    insets: Insets,
    camera: OrbitCamera,
    controls: Controls,
    /// Panel width in physical pixels.
    panel_px: u32,
    options: ViewOptions,
    cursor: Option<(f64, f64)>,
    dragging: Option<MouseButton>,
    pending: Actions,
    repaint: bool,
    fps: f32,
    /// Milliseconds to draw and present a frame (moving average).
    draw_ms: f32,
    last_frame: Instant,
    message: Option<String>,
    settle: u32,
    /// Where the panel's controls were in the last frame (printed with a screenshot).
    reach: Reach,
}

pub fn run(options: ViewOptions) -> Result<()> {
    let load = crate::scene::LoadOptions {
        emit: options.emit.clone(),
        keep_faces: options.keep_faces,
        sky: options.sky,
    };
    let (scene, _) = crate::pipeline::load_scene_with(options.scene.as_deref(), &load)?;
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow!(
            "cannot open a window: no display ({e}). Run it on a desktop, or headless under \
             Xvfb: `xvfb-run -a radiosity view ...` (Debian: apt-get install xvfb xauth)"
        )
    })?;
    let title = format!("radiosity view: {}", scene.name);
    let panel_guess = panel::WIDTH.ceil() as u32;
    let (w, h) = options.size;
    let window = Rc::new(
        GlWindow::new(&event_loop, &title, (w + panel_guess, h))
            .map_err(|e| anyhow!("cannot open the viewer's window: {e}"))?,
    );
    let scale = window.window.scale_factor() as f32;
    let panel_px = (panel::WIDTH * scale).ceil() as u32;
    if panel_px != panel_guess {
        let _ = window
            .window
            .request_inner_size(winit::dpi::PhysicalSize::new(w + panel_px, h));
    }
    let ctx = GlContext::from_current(window.load_gl(), Box::new(window.clone()))
        .map_err(|e| anyhow!("the window's OpenGL context cannot run the solver: {e}"))?;
    eprintln!(
        "window ({}): {} | {} | {}",
        window.api_name(),
        ctx.info.vendor,
        ctx.info.renderer,
        ctx.info.version
    );
    let painter = egui_glow::Painter::new(Arc::new(window.load_gl()), "", None, false)
        .map_err(|e| anyhow!("cannot draw the panel: {e}"))?;
    let egui_ctx = egui::Context::default();
    let state = egui_winit::State::new(
        egui_ctx.clone(),
        egui::ViewportId::ROOT,
        &event_loop,
        Some(scale),
        None,
        Some(painter.max_texture_side()),
    );
    let resolution = crate::pipeline::resolution(&scene, options.patch_size, options.patches);
    let patch_size = match resolution {
        Resolution::PatchSize(s) => s,
        Resolution::Patches(_) => PatchLayout::try_new(&scene, resolution)?.patch_size,
    };
    let controls = Controls {
        running: options.screenshot.is_some(),
        shots_per_frame: options.shots_per_frame,
        mode: options.mode,
        threshold: options.threshold,
        patch_size,
        patch_size_range: (0.25 * patch_size, 4.0 * patch_size),
        exposure: options.exposure,
        overlays: OverlaySet::from_list(&options.overlays),
    };
    let mut viewer = Viewer {
        event_loop,
        window,
        events: Events::default(),
        gui: Gui {
            ctx: egui_ctx,
            state,
            painter,
        },
        insets: Insets::new(&ctx)?,
        camera: OrbitCamera::new(scene.camera_or_default()),
        controls,
        panel_px,
        options,
        cursor: None,
        dragging: None,
        pending: Actions::default(),
        repaint: true,
        fps: 0.0,
        draw_ms: 0.0,
        last_frame: Instant::now(),
        message: None,
        settle: 0,
        reach: Reach::default(),
    };
    let result = solves(&mut viewer, &ctx, &scene);
    viewer.gui.painter.destroy();
    result
}

/// One solve after another until the window closes; a reset starts the next.
fn solves(v: &mut Viewer, ctx: &GlContext, scene: &Scene) -> Result<()> {
    let mut good: Option<(ViewMode, f32)> = None;
    loop {
        let c = &v.controls;
        let layout = match PatchLayout::try_new(scene, Resolution::PatchSize(c.patch_size)) {
            Ok(layout) => layout,
            Err(e) => match good {
                None => return Err(e.into()),
                Some((mode, size)) => {
                    v.message = Some(format!("{e}"));
                    (v.controls.mode, v.controls.patch_size) = (mode, size);
                    continue;
                }
            },
        };
        let c = &v.controls;
        let smooth = v.options.smooth_angle;
        let tuning = v.options.tuning;
        let session = Session::new(ctx, scene, &layout, (c.mode, tuning), c.threshold, smooth);
        let mut session = match (session, good) {
            (Ok(s), _) => s,
            (Err(e), None) => return Err(e.into()),
            // A setting that does not work: say why and go back to the last one that did.
            (Err(e), Some((mode, size))) => {
                v.message = Some(format!("{e}"));
                (v.controls.mode, v.controls.patch_size) = (mode, size);
                continue;
            }
        };
        good = Some((v.controls.mode, v.controls.patch_size));
        v.settle = 0;
        match frames(v, ctx, scene, &mut session)? {
            Next::Reset => v.message = None,
            Next::Quit => return Ok(()),
        }
    }
}

fn frames(v: &mut Viewer, ctx: &GlContext, scene: &Scene, s: &mut Session) -> Result<Next> {
    // The solver took no shot when asked: nothing is left to shoot (its shot limit, or no
    // shooter with power), so a screenshot waiting for more shots is taken now.
    let mut stopped = false;
    loop {
        let target = v.options.screenshot.as_ref().map(|(_, n)| *n);
        let reached =
            target.is_some_and(|n| s.solver.shots() >= n || s.solver.converged() || stopped);
        if target.is_some() {
            v.controls.running = !reached;
        }
        let busy = (v.controls.running && !s.solver.converged()) || target.is_some();
        let wait = if busy || v.repaint {
            Duration::ZERO
        } else {
            IDLE_WAIT
        };
        if let PumpStatus::Exit(_) = v.event_loop.pump_app_events(Some(wait), &mut v.events) {
            return Ok(Next::Quit);
        }
        let events = std::mem::take(&mut v.events.0);
        let mut redraw = busy || v.repaint || !events.is_empty();
        for event in &events {
            if let Some(next) = handle_event(v, event) {
                return Ok(next);
            }
        }
        let actions = std::mem::take(&mut v.pending);
        if actions.reset {
            return Ok(Next::Reset);
        }
        if actions.reset_camera {
            v.camera.reset();
        }
        s.solver.set_threshold(v.controls.threshold);
        let mut shots = if actions.step {
            1
        } else if v.controls.running {
            v.controls.shots_per_frame.max(1)
        } else {
            0
        };
        if let Some(n) = target {
            shots = shots.min(n.saturating_sub(s.solver.shots()));
        }
        if shots > 0 {
            if s.advance(shots, SOLVE_BUDGET)? > 0 {
                redraw = true;
                if s.solver.converged() && target.is_none() {
                    v.controls.running = false;
                }
            } else if !stopped {
                stopped = true;
                redraw = true;
                v.controls.running = false;
                eprintln!("the solve stopped after {} shots", s.solver.shots());
            }
        }
        if !redraw {
            continue;
        }
        let started = Instant::now();
        draw(v, ctx, scene, s)?;
        if reached {
            v.settle += 1;
            if v.settle >= SETTLE_FRAMES {
                let (path, _) = v.options.screenshot.clone().expect("a screenshot target");
                let (w, h) = v.window.size();
                let rgb = GlWindow::read_back_buffer(&ctx.gl, w, h);
                write_png(&path, w, h, rgb)?;
                eprintln!(
                    "wrote {} after {} shots ({}x{})",
                    path.display(),
                    s.solver.shots(),
                    w,
                    h
                );
                eprintln!("{}", v.reach);
                return Ok(Next::Quit);
            }
        }
        v.window.swap_buffers().map_err(|e| anyhow!(e))?;
        let ms = 1e3 * started.elapsed().as_secs_f32();
        v.draw_ms = if v.draw_ms == 0.0 {
            ms
        } else {
            0.9 * v.draw_ms + 0.1 * ms
        };
    }
}

/// The panel sees every event first; what it does not take moves the camera or is a key.
fn handle_event(v: &mut Viewer, event: &WindowEvent) -> Option<Next> {
    let consumed = v
        .gui
        .state
        .on_window_event(&v.window.window, event)
        .consumed;
    let scene_width = v.window.size().0.saturating_sub(v.panel_px) as f64;
    let view_height = v.window.size().1 as f32;
    match event {
        WindowEvent::CloseRequested | WindowEvent::Destroyed => return Some(Next::Quit),
        WindowEvent::Resized(size) => v.window.resize(size.width, size.height),
        WindowEvent::CursorMoved { position, .. } => {
            let (x, y) = (position.x, position.y);
            if let (Some((x0, y0)), Some(button)) = (v.cursor, v.dragging) {
                let (dx, dy) = ((x - x0) as f32, (y - y0) as f32);
                match button {
                    MouseButton::Left => v.camera.orbit(-dx * 0.006, dy * 0.006),
                    _ => v.camera.pan(dx / view_height, -dy / view_height),
                }
            }
            v.cursor = Some((x, y));
        }
        WindowEvent::MouseInput { state, button, .. } => {
            let in_scene = v.cursor.is_some_and(|(x, _)| x < scene_width);
            v.dragging = match state {
                ElementState::Pressed if in_scene && !consumed => Some(*button),
                _ => None,
            };
        }
        WindowEvent::MouseWheel { delta, .. }
            if !consumed && v.cursor.is_some_and(|(x, _)| x < scene_width) =>
        {
            v.camera.zoom(match delta {
                MouseScrollDelta::LineDelta(_, y) => *y,
                MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
            });
        }
        WindowEvent::KeyboardInput { event, .. }
            if event.state == ElementState::Pressed
                && !consumed
                && !v.gui.ctx.wants_keyboard_input() =>
        {
            return key(v, &event.logical_key);
        }
        _ => {}
    }
    None
}

fn key(v: &mut Viewer, key: &Key) -> Option<Next> {
    let c = &mut v.controls;
    match key {
        Key::Named(NamedKey::Escape) => return Some(Next::Quit),
        Key::Named(NamedKey::Space) => c.running ^= true,
        Key::Named(NamedKey::ArrowRight) => v.pending.step = true,
        Key::Character(s) => match s.to_lowercase().as_str() {
            "q" => return Some(Next::Quit),
            "s" | "n" => v.pending.step = true,
            "r" => v.pending.reset = true,
            "c" => v.pending.reset_camera = true,
            "m" => {
                c.mode = match c.mode {
                    ViewMode::Paper => ViewMode::Accurate,
                    ViewMode::Accurate => ViewMode::Paper,
                };
                v.pending.reset = true;
            }
            k => {
                if let Ok(n) = k.parse::<u32>() {
                    c.overlays.toggle(n);
                }
            }
        },
        _ => {}
    }
    None
}

/// One frame into the back buffer: the scene and its insets on the left, the panel on the right.
fn draw(v: &mut Viewer, ctx: &GlContext, scene: &Scene, s: &Session) -> Result<()> {
    let now = Instant::now();
    let dt = now.duration_since(v.last_frame).as_secs_f32().max(1e-4);
    v.last_frame = now;
    v.fps = if v.fps == 0.0 {
        1.0 / dt
    } else {
        0.9 * v.fps + 0.1 / dt
    };
    let (w, h) = v.window.size();
    let view = Viewport {
        x: 0,
        y: 0,
        width: w.saturating_sub(v.panel_px).max(1) as i32,
        height: h as i32,
    };
    let c = &v.controls;
    s.draw_scene(ctx, scene, &v.camera, view, c.overlays, c.exposure)?;
    s.draw_insets(ctx, &v.insets, view, c.overlays, c.exposure)?;

    let solver = &s.solver;
    let named = |p: Option<usize>| p.map(|p| (p, scene.polygons[p].object.as_str()));
    let history = std::iter::once([0.0, 1.0])
        .chain(
            solver
                .history()
                .iter()
                .map(|r| [r.shot as f64, r.unshot_fraction]),
        )
        .collect();
    let readout = Readout {
        scene: &scene.name,
        renderer: &ctx.info.renderer,
        gl_version: &ctx.info.version,
        window_api: v.window.api_name(),
        mode: s.mode,
        patch_size: s.layout.patch_size,
        patches: solver.ledger().patches().iter().map(|&n| n as u64).sum(),
        atlas: (s.layout.atlas_width, s.layout.atlas_height),
        shots: solver.shots(),
        passes: solver.passes(),
        unshot_fraction: solver.unshot_fraction(),
        converged: solver.converged(),
        last_shooter: named(s.last_shooter()),
        next_shooter: named(s.next_shooter()),
        times: solver.times(),
        solve_seconds: solver.history().last().map_or(0.0, |r| r.seconds),
        fps: v.fps,
        draw_ms: v.draw_ms,
        history,
        message: v.message.as_deref(),
    };
    let gui = &mut v.gui;
    let controls = &mut v.controls;
    let mut actions = Actions::default();
    let reach = &mut v.reach;
    let input = gui.state.take_egui_input(&v.window.window);
    let out = gui.ctx.run(input, |ui| {
        let shown = panel::show(ui, controls, &readout);
        actions = shown.actions;
        *reach = shown.reach;
    });
    gui.state
        .handle_platform_output(&v.window.window, out.platform_output);
    let primitives = gui.ctx.tessellate(out.shapes, out.pixels_per_point);
    gui.painter.paint_and_update_textures(
        [w, h],
        out.pixels_per_point,
        &primitives,
        &out.textures_delta,
    );
    v.repaint = out
        .viewport_output
        .get(&egui::ViewportId::ROOT)
        .is_some_and(|o| o.repaint_delay.is_zero());
    v.pending = Actions {
        step: v.pending.step || actions.step,
        reset: v.pending.reset || actions.reset,
        reset_camera: v.pending.reset_camera || actions.reset_camera,
    };
    ctx.check("viewer panel")?;
    Ok(())
}

fn write_png(path: &Path, width: u32, height: u32, rgb: Vec<u8>) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the directory {}", dir.display()))?;
    }
    write_atomic(
        path,
        Payload::Png {
            width,
            height,
            rgb: &rgb,
        },
    )
}
