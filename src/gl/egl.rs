//! EGL on the device platform (EGL_EXT_platform_device): no window system, no environment
//! variables. Mesa lists its software rasterizer as a device (EGL_MESA_device_software).
//!
//! Every context of a process made on one device shares one `EGLDisplay` (EGL returns the same
//! handle for the same platform and device). glutin's `Display` never calls `eglTerminate` on
//! it unless EGL_KHR_display_reference counts its users (Mesa 22.3 does not offer it), so
//! dropping one context's display never pulls the display from under another's.

use glutin::api::egl::{context::PossiblyCurrentContext, device::Device, display::Display};
use glutin::config::{Api, ConfigSurfaceTypes, ConfigTemplateBuilder};
use glutin::context::{ContextApi, ContextAttributesBuilder, GlProfile, Version};
use glutin::prelude::*;
use std::sync::OnceLock;

pub struct EglContext {
    /// `None` once destroyed (in `drop`).
    context: Option<PossiblyCurrentContext>,
    _display: Display,
}

impl EglContext {
    /// Make this context current on the calling thread (surfaceless: we draw to FBOs only).
    pub fn make_current(&self) -> bool {
        self.context
            .as_ref()
            .is_some_and(|c| c.make_current_surfaceless().is_ok())
    }
}

impl Drop for EglContext {
    fn drop(&mut self) {
        if let Some(context) = self.context.take() {
            // eglDestroyContext on a context that is current only marks it for deletion: it
            // would stay current on this thread (and alive, with its rasteriser threads) until
            // the thread ends. Released first, it is destroyed at once, with no context current.
            if context.is_current() {
                let _ = context.make_not_current_in_place();
            }
            drop(context);
        }
    }
}

/// libEGL, for the two entry points glutin does not wrap: the library glutin loaded, loaded
/// again here and never unloaded.
fn libegl() -> Option<&'static libloading::Library> {
    static LIB: OnceLock<Option<libloading::Library>> = OnceLock::new();
    LIB.get_or_init(|| {
        ["libEGL.so.1", "libEGL.so"]
            .iter()
            .find_map(|n| unsafe { libloading::Library::new(n) }.ok())
    })
    .as_ref()
}

/// `eglReleaseThread`: return the calling thread to EGL's initial state, freeing its per-thread
/// state now. Called after the thread's last context is destroyed, as its last EGL call. Left to
/// the thread's end, libglvnd 1.6 frees that state in a thread-exit destructor, which races with
/// its exit-time teardown (`__eglFini` frees every thread's state) when the process ends as the
/// thread does, as a test binary does after its last test: a double free (docs/perf-log.md,
/// 2026-12-03).
pub fn release_thread() {
    type ReleaseThread = unsafe extern "C" fn() -> u32;
    if let Some(lib) = libegl() {
        if let Ok(f) = unsafe { lib.get::<ReleaseThread>(b"eglReleaseThread\0") } {
            unsafe { f() };
        }
    }
}

/// `eglGetCurrentContext`: the calling thread's current EGL context, null if none.
#[cfg(test)]
pub fn current_context() -> *mut std::ffi::c_void {
    type GetCurrentContext = unsafe extern "C" fn() -> *mut std::ffi::c_void;
    let f = libegl()
        .and_then(|lib| unsafe { lib.get::<GetCurrentContext>(b"eglGetCurrentContext\0") }.ok())
        .expect("libEGL has eglGetCurrentContext");
    unsafe { f() }
}

/// Hardware devices first (a real GPU where there is one), then Mesa's software device.
fn rank(device: &Device) -> u8 {
    if device.extensions().contains("EGL_MESA_device_software") {
        1
    } else {
        0
    }
}

pub fn create() -> Result<(EglContext, glow::Context), String> {
    let mut devices: Vec<Device> = Device::query_devices()
        .map_err(|e| format!("cannot list EGL devices ({e})"))?
        .collect();
    devices.sort_by_key(rank);
    if devices.is_empty() {
        return Err("EGL lists no devices".into());
    }
    let mut errors = Vec::new();
    for device in &devices {
        match create_on(device) {
            Ok(made) => return Ok(made),
            Err(e) => errors.push(format!(
                "device {}: {e}",
                device.name().or(device.vendor()).unwrap_or("?")
            )),
        }
    }
    Err(errors.join(", "))
}

fn create_on(device: &Device) -> Result<(EglContext, glow::Context), String> {
    let display = unsafe { Display::with_device(device, None) }.map_err(|e| e.to_string())?;
    // An empty surface type: we never draw to a window surface, only to framebuffer objects.
    let template = ConfigTemplateBuilder::new()
        .with_surface_type(ConfigSurfaceTypes::empty())
        .with_api(Api::OPENGL)
        .build();
    let config = unsafe { display.find_configs(template) }
        .map_err(|e| e.to_string())?
        .next()
        .ok_or("no EGL config for desktop OpenGL")?;
    let attributes = ContextAttributesBuilder::new()
        .with_context_api(ContextApi::OpenGl(Some(Version::new(3, 0))))
        .with_profile(GlProfile::Compatibility)
        .build(None);
    let context = unsafe { display.create_context(&config, &attributes) }
        .map_err(|e| format!("cannot create a GL 3.0 compatibility context ({e})"))?;
    let context = context
        .make_current_surfaceless()
        .map_err(|e| format!("cannot make the context current ({e})"))?;
    let gl = unsafe { glow::Context::from_loader_function_cstr(|s| display.get_proc_address(s)) };
    Ok((
        EglContext {
            context: Some(context),
            _display: display,
        },
        gl,
    ))
}
