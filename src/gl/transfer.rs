//! Every pixel transfer between a Rust buffer and GL goes through here: `glReadPixels`,
//! `glGetTexImage`, `glTexImage2D` and `glTexSubImage2D`. GL is handed a bare pointer and
//! touches as many bytes as the format, the type, the pixel-store state (alignment, row length,
//! skips, a bound pixel buffer) and the image's size say, whatever the Rust buffer's length. So
//! these functions put that state into a known form themselves, compute the span GL will touch
//! ([`span`]) and refuse a shorter buffer before GL sees the pointer.

use glow::HasContext;

/// The pixel formats the transfers use (the `format` argument of the GL calls).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelFormat {
    /// One component per pixel (GL_RED).
    Red,
    /// Three components per pixel (GL_RGB).
    Rgb,
    /// Four components per pixel (GL_RGBA).
    Rgba,
}

/// The component types the transfers use (the `type` argument of the GL calls).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelType {
    /// One byte per component (GL_UNSIGNED_BYTE).
    UnsignedByte,
    /// A 32-bit float per component (GL_FLOAT).
    Float,
}

impl PixelFormat {
    fn components(self) -> usize {
        match self {
            PixelFormat::Red => 1,
            PixelFormat::Rgb => 3,
            PixelFormat::Rgba => 4,
        }
    }
    fn gl(self) -> u32 {
        match self {
            PixelFormat::Red => glow::RED,
            PixelFormat::Rgb => glow::RGB,
            PixelFormat::Rgba => glow::RGBA,
        }
    }
}

impl PixelType {
    fn bytes(self) -> usize {
        match self {
            PixelType::UnsignedByte => 1,
            PixelType::Float => 4,
        }
    }
    fn gl(self) -> u32 {
        match self {
            PixelType::UnsignedByte => glow::UNSIGNED_BYTE,
            PixelType::Float => glow::FLOAT,
        }
    }
}

/// The pixel-store parameters that decide where GL puts each row (`GL_PACK_*` for reads,
/// `GL_UNPACK_*` for uploads).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelStore {
    /// Rows start at multiples of this many bytes: 1, 2, 4 or 8.
    pub alignment: usize,
    /// Pixels from one row's start to the next's; 0: the image's width.
    pub row_length: usize,
    /// Pixels skipped at the start of each row.
    pub skip_pixels: usize,
    /// Rows skipped before the first.
    pub skip_rows: usize,
}

impl PixelStore {
    /// The state every transfer here sets before it runs: GL's defaults.
    pub const DEFAULT: PixelStore = PixelStore {
        alignment: 4,
        row_length: 0,
        skip_pixels: 0,
        skip_rows: 0,
    };
}

/// A transfer refused before GL saw the buffer.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TransferError {
    /// A negative width or height.
    #[error("a {width}x{height} pixel transfer has a negative size")]
    Negative {
        /// The width asked for.
        width: i32,
        /// The height asked for.
        height: i32,
    },
    /// An alignment GL does not accept.
    #[error("GL_PACK/UNPACK_ALIGNMENT {0} is not 1, 2, 4 or 8")]
    Alignment(usize),
    /// A size whose byte count overflows `usize`.
    #[error("a {width}x{height} pixel transfer needs more bytes than this machine can address")]
    Overflow {
        /// The width asked for.
        width: i32,
        /// The height asked for.
        height: i32,
    },
    /// A buffer shorter than the bytes GL would touch.
    #[error(
        "a {width}x{height} {format:?}/{ty:?} pixel transfer touches {needed} bytes, but the \
         buffer holds {len}"
    )]
    Short {
        /// The width asked for.
        width: i32,
        /// The height asked for.
        height: i32,
        /// The pixel format.
        format: PixelFormat,
        /// The component type.
        ty: PixelType,
        /// The bytes GL would touch with the pixel-store state.
        needed: usize,
        /// The bytes the buffer holds.
        len: usize,
    },
    /// GL could not make the buffer object an upload goes through.
    #[error("no buffer object for a texture upload: {0}")]
    Buffer(String),
}

/// The bytes GL touches, from the buffer's start, to transfer a `width` x `height` image of
/// `format` and `ty` with `store` in force, by the GL specification's rules for unpacking
/// (`glPixelStore`; packing follows the same ones). Each row but the last is padded to
/// `alignment` bytes (unless a component is at least that large); the last row ends where its
/// pixels end.
pub fn span(
    width: i32,
    height: i32,
    format: PixelFormat,
    ty: PixelType,
    store: PixelStore,
) -> Result<usize, TransferError> {
    if width < 0 || height < 0 {
        return Err(TransferError::Negative { width, height });
    }
    let k = store.alignment;
    if !matches!(k, 1 | 2 | 4 | 8) {
        return Err(TransferError::Alignment(k));
    }
    if width == 0 || height == 0 {
        return Ok(0);
    }
    let overflow = TransferError::Overflow { width, height };
    let (w, h) = (width as usize, height as usize);
    let pixel = format.components() * ty.bytes();
    let row_pixels = if store.row_length > 0 {
        store.row_length
    } else {
        w
    };
    let row_bytes = row_pixels.checked_mul(pixel).ok_or(overflow.clone())?;
    let stride = if ty.bytes() >= k {
        row_bytes
    } else {
        row_bytes
            .div_ceil(k)
            .checked_mul(k)
            .ok_or(overflow.clone())?
    };
    let start = store
        .skip_rows
        .checked_mul(stride)
        .and_then(|s| s.checked_add(store.skip_pixels.checked_mul(pixel)?))
        .ok_or(overflow.clone())?;
    (h - 1)
        .checked_mul(stride)
        .and_then(|rows| rows.checked_add(w.checked_mul(pixel)?))
        .and_then(|image| image.checked_add(start))
        .ok_or(overflow)
}

/// Check that `len` bytes hold the transfer GL will make with [`PixelStore::DEFAULT`].
fn check(
    width: i32,
    height: i32,
    format: PixelFormat,
    ty: PixelType,
    len: usize,
) -> Result<(), TransferError> {
    let needed = span(width, height, format, ty, PixelStore::DEFAULT)?;
    if len < needed {
        return Err(TransferError::Short {
            width,
            height,
            format,
            ty,
            needed,
            len,
        });
    }
    Ok(())
}

/// Put the pack state into [`PixelStore::DEFAULT`] with no pixel buffer bound, so that a
/// pointer is a pointer and [`span`] is what GL writes. Set every time: other code on the same
/// context (the viewer's panel painter) changes pixel-store state.
fn pack_defaults(gl: &glow::Context) {
    let d = PixelStore::DEFAULT;
    unsafe {
        gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
        gl.pixel_store_i32(glow::PACK_ALIGNMENT, d.alignment as i32);
        gl.pixel_store_i32(glow::PACK_ROW_LENGTH, d.row_length as i32);
        gl.pixel_store_i32(glow::PACK_SKIP_PIXELS, d.skip_pixels as i32);
        gl.pixel_store_i32(glow::PACK_SKIP_ROWS, d.skip_rows as i32);
    }
}

/// The same for uploads (`GL_UNPACK_*`): GL then reads at most [`span`] bytes.
fn unpack_defaults(gl: &glow::Context) {
    let d = PixelStore::DEFAULT;
    unsafe {
        gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
        gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, d.alignment as i32);
        gl.pixel_store_i32(glow::UNPACK_ROW_LENGTH, d.row_length as i32);
        gl.pixel_store_i32(glow::UNPACK_SKIP_PIXELS, d.skip_pixels as i32);
        gl.pixel_store_i32(glow::UNPACK_SKIP_ROWS, d.skip_rows as i32);
    }
}

/// `glReadPixels` of the rectangle at (`x`, `y`), `width` x `height`, of the bound read
/// framebuffer's read buffer into `out`. GL writes at most the rectangle (less where it leaves
/// the framebuffer), so the rectangle sizes the check.
#[allow(clippy::too_many_arguments)]
pub fn read_pixels(
    gl: &glow::Context,
    x: i32,
    y: i32,
    width: i32,
    height: i32,
    format: PixelFormat,
    ty: PixelType,
    out: &mut [u8],
) -> Result<(), TransferError> {
    check(width, height, format, ty, out.len())?;
    pack_defaults(gl);
    unsafe {
        gl.read_pixels(
            x,
            y,
            width,
            height,
            format.gl(),
            ty.gl(),
            glow::PixelPackData::Slice(Some(out)),
        );
    }
    Ok(())
}

/// `glGetTexImage` of level 0 of the texture bound to `GL_TEXTURE_2D` into `out`. GL writes
/// the level's whole image, so `width` x `height` must be its real size: the caller's promise,
/// kept by [`super::Texture`], which alone specifies its images and records their size.
pub fn get_tex_image(
    gl: &glow::Context,
    width: i32,
    height: i32,
    format: PixelFormat,
    ty: PixelType,
    out: &mut [u8],
) -> Result<(), TransferError> {
    check(width, height, format, ty, out.len())?;
    pack_defaults(gl);
    unsafe {
        gl.get_tex_image(
            glow::TEXTURE_2D,
            0,
            format.gl(),
            ty.gl(),
            glow::PixelPackData::Slice(Some(out)),
        );
    }
    Ok(())
}

/// `glTexImage2D` of level 0 of the texture bound to `GL_TEXTURE_2D`: `width` x `height`
/// texels of `internal_format`, from `data` (GL reads [`span`] bytes of it).
pub fn tex_image_2d(
    gl: &glow::Context,
    internal_format: u32,
    width: i32,
    height: i32,
    format: PixelFormat,
    ty: PixelType,
    data: &[u8],
) -> Result<(), TransferError> {
    check(width, height, format, ty, data.len())?;
    unpack_defaults(gl);
    unsafe {
        gl.tex_image_2d(
            glow::TEXTURE_2D,
            0,
            internal_format as i32,
            width,
            height,
            0,
            format.gl(),
            ty.gl(),
            glow::PixelUnpackData::Slice(Some(data)),
        );
    }
    Ok(())
}

/// `glTexSubImage2D` of level 0 of the texture bound to `GL_TEXTURE_2D`, from its origin.
pub fn tex_sub_image_2d(
    gl: &glow::Context,
    width: i32,
    height: i32,
    format: PixelFormat,
    ty: PixelType,
    data: &[u8],
) -> Result<(), TransferError> {
    check(width, height, format, ty, data.len())?;
    if super::faults::drops_upload() {
        return Ok(());
    }
    unpack_defaults(gl);
    // From a pixel unpack buffer, not client memory: Mesa 24+'s threaded context may write a
    // client-memory upload straight into the texture from the calling thread when it judges the
    // texture idle, and it judges a texture that queued draws still sample (bound in an earlier
    // batch) idle. Zink over lavapipe then let the last reconstruction pass's draws read the
    // next shot's item buffer (issue 60, docs/drivers.md). An upload from a buffer object is
    // queued behind those draws, as GL orders it.
    unsafe {
        let buffer = gl.create_buffer().map_err(TransferError::Buffer)?;
        gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, Some(buffer));
        gl.buffer_data_u8_slice(glow::PIXEL_UNPACK_BUFFER, data, glow::STREAM_DRAW);
        gl.tex_sub_image_2d(
            glow::TEXTURE_2D,
            0,
            0,
            0,
            width,
            height,
            format.gl(),
            ty.gl(),
            glow::PixelUnpackData::BufferOffset(0),
        );
        gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
        gl.delete_buffer(buffer);
    }
    Ok(())
}

/// A float slice as the bytes GL reads.
pub fn f32_bytes(v: &[f32]) -> &[u8] {
    // f32 has no padding and any bit pattern is a valid u8 sequence.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast(), std::mem::size_of_val(v)) }
}

/// A float slice as the bytes GL writes (any bytes GL writes are a valid f32).
pub fn f32_bytes_mut(v: &mut [f32]) -> &mut [u8] {
    unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast(), std::mem::size_of_val(v)) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use PixelFormat::*;
    use PixelType::*;

    const D: PixelStore = PixelStore::DEFAULT;

    #[test]
    fn tight_rgba_images_are_width_times_height_pixels() {
        assert_eq!(span(7, 5, Rgba, UnsignedByte, D), Ok(7 * 5 * 4));
        assert_eq!(span(7, 5, Rgba, Float, D), Ok(7 * 5 * 16));
        assert_eq!(span(1, 1, Rgba, UnsignedByte, D), Ok(4));
    }

    #[test]
    fn rows_are_padded_to_the_alignment_except_the_last() {
        // RGB bytes, 5 pixels: 15 bytes a row, padded to 16 at alignment 4.
        assert_eq!(span(5, 3, Rgb, UnsignedByte, D), Ok(2 * 16 + 15));
        let one = PixelStore { alignment: 1, ..D };
        assert_eq!(span(5, 3, Rgb, UnsignedByte, one), Ok(3 * 15));
        let eight = PixelStore { alignment: 8, ..D };
        assert_eq!(span(5, 3, Rgb, UnsignedByte, eight), Ok(2 * 16 + 15));
        // A single red byte per pixel, 3 wide: rows of 4 bytes at alignment 4.
        assert_eq!(span(3, 2, Red, UnsignedByte, D), Ok(4 + 3));
        // Components as large as the alignment are never padded.
        assert_eq!(span(3, 2, Rgb, Float, D), Ok(2 * 36));
        // Floats at alignment 8: 12-byte rows padded to 16.
        assert_eq!(span(1, 2, Rgb, Float, eight), Ok(16 + 12));
    }

    #[test]
    fn row_length_and_skips_move_the_rows() {
        let long = PixelStore {
            row_length: 10,
            ..D
        };
        assert_eq!(span(4, 3, Rgba, UnsignedByte, long), Ok(2 * 40 + 16));
        let skipped = PixelStore {
            row_length: 10,
            skip_pixels: 2,
            skip_rows: 1,
            ..D
        };
        assert_eq!(
            span(4, 3, Rgba, UnsignedByte, skipped),
            Ok(40 + 8 + 2 * 40 + 16)
        );
    }

    #[test]
    fn empty_negative_and_absurd_sizes() {
        assert_eq!(span(0, 9, Rgba, Float, D), Ok(0));
        assert_eq!(span(9, 0, Rgba, Float, D), Ok(0));
        assert!(matches!(
            span(-1, 2, Rgba, Float, D),
            Err(TransferError::Negative { .. })
        ));
        let odd = PixelStore { alignment: 3, ..D };
        assert_eq!(
            span(1, 1, Rgba, Float, odd),
            Err(TransferError::Alignment(3))
        );
        let huge = PixelStore {
            row_length: usize::MAX / 2,
            ..D
        };
        assert!(matches!(
            span(2, 2, Rgba, Float, huge),
            Err(TransferError::Overflow { .. })
        ));
    }

    #[test]
    fn a_short_buffer_is_refused_with_both_sizes() {
        assert_eq!(check(4, 4, Rgba, Float, 256), Ok(()));
        let short = check(4, 4, Rgba, Float, 255).unwrap_err();
        assert!(matches!(
            short,
            TransferError::Short {
                needed: 256,
                len: 255,
                ..
            }
        ));
        assert!(short.to_string().contains("256") && short.to_string().contains("255"));
    }
}

/// The transfers on a real context: they hold whatever pixel-store state other code left.
#[cfg(test)]
mod on_gl {
    use crate::gl::{BackendChoice, Framebuffer, GlContext, Texture, TextureFormat};
    use glow::HasContext;

    /// A pattern no two texels share, RGBA floats.
    fn pattern(w: i32, h: i32) -> Vec<f32> {
        (0..w * h * 4).map(|i| i as f32 * 0.25 + 1.0).collect()
    }

    /// Pixel-store state as careless code would leave it: rows twice as long, skips, and a
    /// wide alignment, for both directions.
    fn disturb(gl: &glow::Context, w: i32) {
        unsafe {
            for (row, skip_p, skip_r, align) in [
                (
                    glow::PACK_ROW_LENGTH,
                    glow::PACK_SKIP_PIXELS,
                    glow::PACK_SKIP_ROWS,
                    glow::PACK_ALIGNMENT,
                ),
                (
                    glow::UNPACK_ROW_LENGTH,
                    glow::UNPACK_SKIP_PIXELS,
                    glow::UNPACK_SKIP_ROWS,
                    glow::UNPACK_ALIGNMENT,
                ),
            ] {
                gl.pixel_store_i32(row, 2 * w + 3);
                gl.pixel_store_i32(skip_p, 5);
                gl.pixel_store_i32(skip_r, 7);
                gl.pixel_store_i32(align, 8);
            }
        }
    }

    #[test]
    fn readbacks_and_uploads_ignore_the_pixel_store_state_they_find() {
        let ctx = GlContext::headless(BackendChoice::Auto).expect("a GL 3.0 context");
        // Odd sizes: no row is a multiple of 8 bytes for RGBA8.
        let (w, h) = (37, 13);
        let data = pattern(w, h);
        let texture = Texture::new(&ctx.gl, w, h, TextureFormat::Rgba32F, glow::NEAREST).unwrap();
        disturb(&ctx.gl, w);
        texture.upload_f32(&data);
        disturb(&ctx.gl, w);
        let mut back = Vec::new();
        texture.read_f32(&mut back);
        assert_eq!(
            back, data,
            "glGetTexImage after disturbed pixel-store state"
        );

        let fbo = Framebuffer::new(&ctx.gl).unwrap();
        fbo.attach_texture(glow::COLOR_ATTACHMENT0, &texture);
        fbo.check_complete("transfer test").unwrap();
        disturb(&ctx.gl, w);
        let mut read = Vec::new();
        fbo.read_f32(glow::COLOR_ATTACHMENT0, w, h, &mut read);
        assert_eq!(read, data, "glReadPixels after disturbed pixel-store state");

        let bytes = Texture::new(&ctx.gl, w, h, TextureFormat::Rgba8, glow::NEAREST).unwrap();
        disturb(&ctx.gl, w);
        let zeros = bytes.read_u8();
        assert_eq!(zeros.len(), (w * h * 4) as usize);
        assert!(
            zeros.iter().all(|&b| b == 0),
            "a new texture reads back as zeros"
        );
        unsafe { ctx.gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check("transfer test").unwrap();
    }

    #[test]
    fn a_negative_texture_size_is_refused_before_gl_sees_it() {
        let ctx = GlContext::headless(BackendChoice::Auto).expect("a GL 3.0 context");
        let refused = Texture::new(&ctx.gl, -4, 4, TextureFormat::Rgba32F, glow::NEAREST);
        let message = refused.err().expect("refused").to_string();
        assert!(message.contains("-4x4"), "{message}");
    }
}
