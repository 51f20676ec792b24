//! A window with an OpenGL 3.0 compatibility context, for the interactive viewer: winit makes the
//! X11 window, glutin (through glutin-winit) the context on EGL, or GLX when EGL has no config.
//! The solver's passes run on it through `GlContext::from_current`, exactly as headless.

use super::transfer::{self, PixelFormat, PixelType};
use glow::HasContext;
use glutin::config::{Config, ConfigTemplateBuilder, GlConfig};
use glutin::context::{
    ContextApi, ContextAttributesBuilder, GlProfile, NotCurrentGlContext, PossiblyCurrentContext,
    Version,
};
use glutin::display::{Display, GetGlDisplay, GlDisplay};
use glutin::surface::{GlSurface, Surface, SurfaceAttributesBuilder, SwapInterval, WindowSurface};
use glutin_winit::{ApiPreference, DisplayBuilder, GlWindow as _};
use std::ffi::CStr;
use std::num::NonZeroU32;
use winit::dpi::PhysicalSize;
use winit::event_loop::EventLoop;
use winit::raw_window_handle::HasWindowHandle;
use winit::window::{Window, WindowAttributes};

/// The window, its surface and its current context. Keep it alive (e.g. in an `Rc` shared with
/// the `GlContext`) until every GL object made on it is dropped.
pub struct GlWindow {
    // Field order is drop order: the surface and context go before the window they draw to.
    surface: Surface<WindowSurface>,
    context: PossiblyCurrentContext,
    display: Display,
    /// The X11 window (size, redraw requests, cursor).
    pub window: Window,
}

impl GlWindow {
    /// Open a window whose drawable area is `size` physical pixels, and make its context current.
    pub fn new(
        event_loop: &EventLoop<()>,
        title: &str,
        size: (u32, u32),
    ) -> Result<GlWindow, String> {
        let attributes = WindowAttributes::default()
            .with_title(title)
            .with_inner_size(PhysicalSize::new(size.0, size.1));
        // A depth buffer for the scene; no multisampling, so the window shows exactly the
        // pixels the headless display pass renders.
        let template = ConfigTemplateBuilder::new()
            .with_depth_size(24)
            .with_transparency(false);
        let (window, config) = DisplayBuilder::new()
            .with_preference(ApiPreference::PreferEgl)
            .with_window_attributes(Some(attributes.clone()))
            .build(event_loop, template, pick_config)
            .map_err(|e| format!("no OpenGL configuration for a window ({e})"))?;
        let display = config.display();
        let window = match window {
            Some(w) => w,
            None => glutin_winit::finalize_window(event_loop, attributes, &config)
                .map_err(|e| format!("cannot open a window ({e})"))?,
        };
        let handle = window
            .window_handle()
            .map_err(|e| format!("no window handle ({e})"))?
            .as_raw();
        let context_attributes = ContextAttributesBuilder::new()
            .with_context_api(ContextApi::OpenGl(Some(Version::new(3, 0))))
            .with_profile(GlProfile::Compatibility)
            .build(Some(handle));
        let context = unsafe { display.create_context(&config, &context_attributes) }
            .map_err(|e| format!("cannot create a GL 3.0 compatibility context ({e})"))?;
        let surface_attributes = window
            .build_surface_attributes(SurfaceAttributesBuilder::new())
            .map_err(|e| format!("no window handle ({e})"))?;
        let surface = unsafe { display.create_window_surface(&config, &surface_attributes) }
            .map_err(|e| format!("cannot create the window's GL surface ({e})"))?;
        let context = context
            .make_current(&surface)
            .map_err(|e| format!("cannot make the window's context current ({e})"))?;
        // Frames are paced by the viewer, not by vertical sync (there is none under Xvfb).
        let _ = surface.set_swap_interval(&context, SwapInterval::DontWait);
        Ok(GlWindow {
            surface,
            context,
            display,
            window,
        })
    }

    /// A glow handle on this window's context (one for the passes, one for the panel's painter).
    pub fn load_gl(&self) -> glow::Context {
        unsafe {
            glow::Context::from_loader_function_cstr(|s: &CStr| self.display.get_proc_address(s))
        }
    }

    /// "EGL" or "GLX": how the context was made.
    pub fn api_name(&self) -> &'static str {
        match &self.display {
            Display::Egl(_) => "EGL",
            #[allow(unreachable_patterns)]
            _ => "GLX",
        }
    }

    /// The drawable size in physical pixels.
    pub fn size(&self) -> (u32, u32) {
        let s = self.window.inner_size();
        (s.width.max(1), s.height.max(1))
    }

    /// Follow a resize of the window.
    pub fn resize(&self, width: u32, height: u32) {
        if let (Some(w), Some(h)) = (NonZeroU32::new(width), NonZeroU32::new(height)) {
            self.surface.resize(&self.context, w, h);
        }
    }

    /// Show the frame drawn (swap the surface's buffers).
    pub fn swap_buffers(&self) -> Result<(), String> {
        self.surface
            .swap_buffers(&self.context)
            .map_err(|e| format!("cannot present the frame ({e})"))
    }

    /// The back buffer (what the next swap shows) as RGB bytes, rows top to bottom.
    pub fn read_back_buffer(gl: &glow::Context, width: u32, height: u32) -> Vec<u8> {
        let (w, h) = (width as usize, height as usize);
        let mut rgba = vec![0u8; w * h * 4];
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            gl.read_buffer(glow::BACK);
        }
        transfer::read_pixels(
            gl,
            0,
            0,
            width as i32,
            height as i32,
            PixelFormat::Rgba,
            PixelType::UnsignedByte,
            &mut rgba,
        )
        .expect("the buffer was sized for the rectangle");
        let mut rgb = Vec::with_capacity(w * h * 3);
        for row in (0..h).rev() {
            for px in rgba[row * w * 4..(row + 1) * w * 4].chunks_exact(4) {
                rgb.extend_from_slice(&px[..3]);
            }
        }
        rgb
    }
}

/// A single-sampled config with a depth buffer, RGBA8 when there is one.
fn pick_config(configs: Box<dyn Iterator<Item = Config> + '_>) -> Config {
    let mut configs: Vec<Config> = configs.collect();
    configs.sort_by_key(|c| {
        (
            c.num_samples() != 0,
            c.depth_size() < 24,
            c.color_buffer_type()
                != Some(glutin::config::ColorBufferType::Rgb {
                    r_size: 8,
                    g_size: 8,
                    b_size: 8,
                }),
            c.alpha_size() != 8,
        )
    });
    configs.swap_remove(0)
}
