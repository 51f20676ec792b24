//! Named GL error checks: every pass ends with `check(gl, "pass name")`, which turns `glGetError`
//! codes and any KHR_debug error messages into an error that says which pass failed.

use glow::HasContext;
use std::sync::{Arc, Mutex};

/// A GL failure, named by the pass or shader it happened in.
#[derive(Debug, thiserror::Error)]
pub enum GlError {
    /// `glGetError` or a KHR_debug error after a pass.
    #[error("OpenGL error in the {pass} pass: {what}")]
    Pass {
        /// The pass that was running.
        pass: String,
        /// The error codes' names or the driver's messages.
        what: String,
    },
    /// A framebuffer GL cannot draw into.
    #[error("framebuffer for the {pass} pass is incomplete: {status}")]
    Framebuffer {
        /// The pass that set it up.
        pass: String,
        /// `glCheckFramebufferStatus`'s answer, named.
        status: String,
    },
    /// A shader that does not compile.
    #[error("shader {file} failed to compile:\n{log}")]
    Compile {
        /// The shader's file under glsl/.
        file: String,
        /// The compiler's log.
        log: String,
    },
    /// Shaders that do not link into a program.
    #[error("shader program ({files}) failed to link:\n{log}")]
    Link {
        /// The program's shader files.
        files: String,
        /// The linker's log.
        log: String,
    },
    /// A GL object the driver cannot create, or a size beyond a limit.
    #[error("{0}")]
    Limit(String),
}

/// Messages of severity HIGH or type ERROR gathered from KHR_debug between two checks.
#[derive(Clone, Default)]
pub struct DebugLog(Arc<Mutex<Vec<String>>>);

impl DebugLog {
    /// Turn on synchronous debug output when the context has KHR_debug (Mesa does, even
    /// without a debug context); otherwise `glGetError` alone is used.
    pub fn install(gl: &mut glow::Context) -> Option<DebugLog> {
        if !gl.supported_extensions().contains("GL_KHR_debug") {
            return None;
        }
        let log = DebugLog::default();
        let sink = log.0.clone();
        unsafe {
            gl.enable(glow::DEBUG_OUTPUT);
            gl.enable(glow::DEBUG_OUTPUT_SYNCHRONOUS);
            gl.debug_message_callback(move |_source, ty, _id, severity, msg| {
                if ty == glow::DEBUG_TYPE_ERROR || severity == glow::DEBUG_SEVERITY_HIGH {
                    if let Ok(mut v) = sink.lock() {
                        v.push(msg.to_string());
                    }
                }
            });
        }
        Some(log)
    }

    fn drain(&self) -> Vec<String> {
        self.0
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default()
    }
}

/// The name of a `glGetError` code (`GL_INVALID_ENUM`, ...).
pub fn error_name(code: u32) -> &'static str {
    match code {
        glow::INVALID_ENUM => "GL_INVALID_ENUM",
        glow::INVALID_VALUE => "GL_INVALID_VALUE",
        glow::INVALID_OPERATION => "GL_INVALID_OPERATION",
        glow::INVALID_FRAMEBUFFER_OPERATION => "GL_INVALID_FRAMEBUFFER_OPERATION",
        glow::OUT_OF_MEMORY => "GL_OUT_OF_MEMORY",
        glow::STACK_OVERFLOW => "GL_STACK_OVERFLOW",
        glow::STACK_UNDERFLOW => "GL_STACK_UNDERFLOW",
        _ => "unknown GL error",
    }
}

/// Collect every pending GL error (and debug message) and name the pass they belong to.
pub fn check(gl: &glow::Context, debug: Option<&DebugLog>, pass: &str) -> Result<(), GlError> {
    let mut what = Vec::new();
    loop {
        let code = unsafe { gl.get_error() };
        if code == glow::NO_ERROR {
            break;
        }
        what.push(format!("{} (0x{code:04X})", error_name(code)));
        if what.len() > 8 {
            break;
        }
    }
    if let Some(d) = debug {
        what.extend(d.drain());
    }
    if what.is_empty() {
        Ok(())
    } else {
        Err(GlError::Pass {
            pass: pass.to_string(),
            what: what.join("; "),
        })
    }
}

/// The name of a `glCheckFramebufferStatus` answer, or its number if unknown.
pub fn framebuffer_status_name(status: u32) -> String {
    match status {
        glow::FRAMEBUFFER_UNDEFINED => "GL_FRAMEBUFFER_UNDEFINED".into(),
        glow::FRAMEBUFFER_INCOMPLETE_ATTACHMENT => "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT".into(),
        glow::FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT => {
            "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT".into()
        }
        glow::FRAMEBUFFER_UNSUPPORTED => {
            "GL_FRAMEBUFFER_UNSUPPORTED (the driver cannot render to this format)".into()
        }
        glow::FRAMEBUFFER_INCOMPLETE_MULTISAMPLE => "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE".into(),
        other => format!("status 0x{other:04X}"),
    }
}
