//! Headless OpenGL 3.0 compatibility contexts. Two backends reach Mesa without a display server:
//! EGL (through glutin, on the EGL device platform) and OSMesa (loaded at run time, so the binary
//! needs `libosmesa6` only when asked for it). `auto` tries EGL, then OSMesa.

use super::check::DebugLog;
use super::{egl, osmesa, Gl};
use glow::HasContext;
use std::rc::Rc;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BackendChoice {
    Auto,
    Egl,
    Osmesa,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BackendKind {
    Egl,
    Osmesa,
    /// A context made by someone else (the interactive viewer's window).
    Window,
}

impl BackendKind {
    pub fn name(self) -> &'static str {
        match self {
            BackendKind::Egl => "egl",
            BackendKind::Osmesa => "osmesa",
            BackendKind::Window => "window",
        }
    }
}

/// What the driver says about itself, and the limits the solver depends on.
#[derive(Clone, Debug, serde::Serialize)]
pub struct GlInfo {
    pub backend: BackendKind,
    pub vendor: String,
    pub renderer: String,
    pub version: String,
    pub glsl_version: String,
    pub max_texture_size: i32,
    pub max_renderbuffer_size: i32,
    /// GL_MAX_VIEWPORT_DIMS: the widest and tallest viewport.
    pub max_viewport_dims: [i32; 2],
    pub khr_debug: bool,
}

#[derive(Debug, thiserror::Error)]
#[error(
    "no usable OpenGL 3.0 driver: {tried}. On Debian install Mesa's software drivers with \
     `apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri` (EGL backend) or \
     `apt-get install libosmesa6` (OSMesa backend)"
)]
pub struct NoDriver {
    pub tried: String,
}

enum Keep {
    Egl(#[allow(dead_code)] egl::EglContext),
    Osmesa(#[allow(dead_code)] osmesa::OsMesaContext),
    External(#[allow(dead_code)] Box<dyn std::any::Any>),
}

/// A current GL context. GL objects made with `gl` must be dropped before this value.
pub struct GlContext {
    pub gl: Gl,
    pub info: GlInfo,
    pub debug: Option<DebugLog>,
    _keep: Keep,
}

impl GlContext {
    pub fn headless(choice: BackendChoice) -> Result<GlContext, NoDriver> {
        let order: &[BackendKind] = match choice {
            BackendChoice::Auto => &[BackendKind::Egl, BackendKind::Osmesa],
            BackendChoice::Egl => &[BackendKind::Egl],
            BackendChoice::Osmesa => &[BackendKind::Osmesa],
        };
        let mut tried = Vec::new();
        for &kind in order {
            let made = match kind {
                BackendKind::Egl => egl::create().map(|(k, gl)| (Keep::Egl(k), gl)),
                BackendKind::Osmesa => osmesa::create().map(|(k, gl)| (Keep::Osmesa(k), gl)),
                BackendKind::Window => unreachable!("not a headless backend"),
            };
            match made {
                Ok((keep, gl)) => match Self::finish(kind, keep, gl) {
                    Ok(ctx) => return Ok(ctx),
                    Err(e) => tried.push(format!("{}: {e}", kind.name())),
                },
                Err(e) => tried.push(format!("{}: {e}", kind.name())),
            }
        }
        Err(NoDriver {
            tried: tried.join("; "),
        })
    }

    /// Wrap a context that is already current (e.g. a window's), so the same passes run on it.
    /// `keep` is held until this value is dropped (put the window's context in it).
    pub fn from_current(
        gl: glow::Context,
        keep: Box<dyn std::any::Any>,
    ) -> Result<GlContext, String> {
        Self::finish(BackendKind::Window, Keep::External(keep), gl)
    }

    fn finish(kind: BackendKind, keep: Keep, mut gl: glow::Context) -> Result<GlContext, String> {
        let version = gl.version();
        if (version.major, version.minor) < (3, 0) || version.is_embedded {
            return Err(format!(
                "the driver gives OpenGL {}.{}, 3.0 (desktop, compatibility) is needed",
                version.major, version.minor
            ));
        }
        let debug = DebugLog::install(&mut gl);
        let mut max_viewport_dims = [0; 2];
        unsafe { gl.get_parameter_i32_slice(glow::MAX_VIEWPORT_DIMS, &mut max_viewport_dims) };
        let info = unsafe {
            GlInfo {
                backend: kind,
                vendor: gl.get_parameter_string(glow::VENDOR),
                renderer: gl.get_parameter_string(glow::RENDERER),
                version: gl.get_parameter_string(glow::VERSION),
                glsl_version: gl.get_parameter_string(glow::SHADING_LANGUAGE_VERSION),
                max_texture_size: gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE),
                max_renderbuffer_size: gl.get_parameter_i32(glow::MAX_RENDERBUFFER_SIZE),
                max_viewport_dims,
                khr_debug: debug.is_some(),
            }
        };
        Ok(GlContext {
            gl: Rc::new(gl),
            info,
            debug,
            _keep: keep,
        })
    }

    /// Turn pending GL errors into an error naming `pass`.
    pub fn check(&self, pass: &str) -> Result<(), super::GlError> {
        super::check::check(&self.gl, self.debug.as_ref(), pass)
    }
}
