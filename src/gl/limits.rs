//! Can this driver hold a render target of a given size? Checked before a solve starts, so that a
//! size the driver cannot meet is refused with the limit named, not found as an incomplete
//! framebuffer halfway through (or after) the solve.

use super::{Framebuffer, GlContext, Renderbuffer};
use glow::HasContext;

/// A render target the driver cannot hold, with the limit it runs into.
#[derive(Debug, thiserror::Error)]
pub enum LimitError {
    /// A side beyond the driver's limit.
    #[error(
        "the {what} would be {width}x{height} pixels, but this driver allows at most {max} per \
         side ({limit})"
    )]
    TooLarge {
        /// The render target ("lightmap atlas", "item buffer", "image").
        what: String,
        /// Its width, pixels.
        width: u64,
        /// Its height, pixels.
        height: u64,
        /// The largest side the limit allows.
        max: i32,
        /// The limit's GL name.
        limit: &'static str,
    },
    /// Within the limits, but the driver cannot allocate it.
    #[error(
        "this driver cannot allocate the {what}: a {width}x{height} {format} render target \
         ({mib} MiB) gives {status}: more memory than the driver gives one texture"
    )]
    Allocation {
        /// The render target ("lightmap atlas", "item buffer", "image").
        what: String,
        /// Its width, pixels.
        width: u64,
        /// Its height, pixels.
        height: u64,
        /// Its internal format's GL name.
        format: &'static str,
        /// Its size, MiB.
        mib: u64,
        /// What the probe framebuffer's status was.
        status: String,
    },
}

/// The largest side every limit allows: GL_MAX_TEXTURE_SIZE, GL_MAX_RENDERBUFFER_SIZE and
/// GL_MAX_VIEWPORT_DIMS, with the name of the one that binds.
pub fn largest_side(ctx: &GlContext) -> (i32, &'static str) {
    let info = &ctx.info;
    [
        (info.max_texture_size, "GL_MAX_TEXTURE_SIZE"),
        (info.max_renderbuffer_size, "GL_MAX_RENDERBUFFER_SIZE"),
        (
            info.max_viewport_dims[0].min(info.max_viewport_dims[1]),
            "GL_MAX_VIEWPORT_DIMS",
        ),
    ]
    .into_iter()
    .min_by_key(|&(max, _)| max)
    .expect("three limits")
}

/// Check that a `width` x `height` render target of `format` (`glow::RGBA8` or
/// `glow::RGBA32F`) fits the driver's limits, then make one and see that the framebuffer is
/// complete: llvmpipe's memory cap is only found that way. `what` names it in the message.
pub fn check_target(
    ctx: &GlContext,
    what: &str,
    width: u64,
    height: u64,
    format: u32,
) -> Result<(), LimitError> {
    let (max, limit) = largest_side(ctx);
    if width > max.max(0) as u64 || height > max.max(0) as u64 {
        return Err(LimitError::TooLarge {
            what: what.into(),
            width,
            height,
            max,
            limit,
        });
    }
    let (name, bytes) = match format {
        glow::RGBA32F => ("RGBA32F", 16),
        _ => ("RGBA8", 4),
    };
    let fail = |status: String| LimitError::Allocation {
        what: what.into(),
        width,
        height,
        format: name,
        mib: (width * height * bytes).div_ceil(1 << 20),
        status,
    };
    let gl = &ctx.gl;
    // Drain earlier errors, so that only this allocation's are read below.
    while unsafe { gl.get_error() } != glow::NO_ERROR {}
    let made = Renderbuffer::new(gl, format, width as i32, height as i32)
        .and_then(|rb| Ok((Framebuffer::new(gl)?, rb)));
    let result = match made {
        Err(e) => Err(fail(e.to_string())),
        Ok((fbo, rb)) => {
            fbo.attach_renderbuffer(glow::COLOR_ATTACHMENT0, &rb);
            let complete = fbo.check_complete("size check");
            let error = unsafe { gl.get_error() };
            match complete {
                Err(super::GlError::Framebuffer { status, .. }) => Err(fail(status)),
                Err(e) => Err(fail(e.to_string())),
                Ok(()) if error != glow::NO_ERROR => {
                    Err(fail(super::check::error_name(error).into()))
                }
                Ok(()) => Ok(()),
            }
        }
    };
    unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
    // The KHR_debug log may hold the failed allocation's message: it is this check's, not the
    // next pass's.
    let _ = ctx.check("size check");
    result
}
