//! EGL on the device platform (EGL_EXT_platform_device): no window system, no environment
//! variables. Mesa lists its software rasterizer as a device (EGL_MESA_device_software).

use glutin::api::egl::{context::PossiblyCurrentContext, device::Device, display::Display};
use glutin::config::{Api, ConfigSurfaceTypes, ConfigTemplateBuilder};
use glutin::context::{ContextApi, ContextAttributesBuilder, GlProfile, Version};
use glutin::prelude::*;

pub struct EglContext {
    _context: PossiblyCurrentContext,
    _display: Display,
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
            _context: context,
            _display: display,
        },
        gl,
    ))
}
