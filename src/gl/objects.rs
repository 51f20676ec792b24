//! Owning wrappers for the GL objects the passes use. Each owns its id and deletes it in `Drop`.

use super::check::{framebuffer_status_name, GlError};
use super::transfer::{self, PixelFormat, PixelStore, PixelType};
use super::Gl;
use glow::HasContext;

/// The internal formats the solver and display use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureFormat {
    /// Energy and radiance: 32-bit float per channel (the paper's RGBA8 cannot hold energy).
    Rgba32F,
    /// The item buffer: polygon IDs as 8-bit colours, exactly as in the paper.
    Rgba8,
}

impl TextureFormat {
    fn internal(self) -> u32 {
        match self {
            TextureFormat::Rgba32F => glow::RGBA32F,
            TextureFormat::Rgba8 => glow::RGBA8,
        }
    }
    /// The component type its uploads use (and its zero fill).
    fn pixel_type(self) -> PixelType {
        match self {
            TextureFormat::Rgba32F => PixelType::Float,
            TextureFormat::Rgba8 => PixelType::UnsignedByte,
        }
    }
}

/// A 2D texture (lightmaps, item buffers, pictures), deleted when dropped.
pub struct Texture {
    gl: Gl,
    raw: glow::Texture,
    /// Width, texels.
    pub width: i32,
    /// Height, texels.
    pub height: i32,
    /// Its internal format.
    pub format: TextureFormat,
    /// The size GL allocated for level 0: what `glGetTexImage` writes. Private, so that no
    /// change to the public fields can make a readback buffer smaller than what GL writes; no
    /// code outside this type can respecify the image (`raw` is private too).
    allocated: (i32, i32),
}

impl Texture {
    /// A 2D texture, zero-filled, with the given filter for both minification and magnification.
    pub fn new(
        gl: &Gl,
        width: i32,
        height: i32,
        format: TextureFormat,
        filter: u32,
    ) -> Result<Texture, GlError> {
        // Refused before anything is made, so a bad size never reaches the transfers.
        let bytes = transfer::span(
            width,
            height,
            PixelFormat::Rgba,
            format.pixel_type(),
            PixelStore::DEFAULT,
        )
        .map_err(|e| GlError::Limit(format!("texture of {width}x{height}: {e}")))?;
        unsafe {
            let raw = gl.create_texture().map_err(GlError::Limit)?;
            gl.bind_texture(glow::TEXTURE_2D, Some(raw));
            gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MIN_FILTER, filter as i32);
            gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAG_FILTER, filter as i32);
            gl.tex_parameter_i32(
                glow::TEXTURE_2D,
                glow::TEXTURE_WRAP_S,
                glow::CLAMP_TO_EDGE as i32,
            );
            gl.tex_parameter_i32(
                glow::TEXTURE_2D,
                glow::TEXTURE_WRAP_T,
                glow::CLAMP_TO_EDGE as i32,
            );
            gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAX_LEVEL, 0);
            let zeros = vec![0u8; bytes];
            let uploaded = transfer::tex_image_2d(
                gl,
                format.internal(),
                width,
                height,
                PixelFormat::Rgba,
                format.pixel_type(),
                &zeros,
            );
            gl.bind_texture(glow::TEXTURE_2D, None);
            if let Err(e) = uploaded {
                gl.delete_texture(raw);
                return Err(GlError::Limit(e.to_string()));
            }
            Ok(Texture {
                gl: gl.clone(),
                raw,
                width,
                height,
                format,
                allocated: (width, height),
            })
        }
    }

    /// Replace the whole image with RGBA float data (rows bottom to top, as GL stores them).
    pub fn upload_f32(&self, rgba: &[f32]) {
        assert_eq!(self.format, TextureFormat::Rgba32F);
        let (w, h) = self.allocated;
        assert_eq!(rgba.len(), w as usize * h as usize * 4);
        unsafe { self.gl.bind_texture(glow::TEXTURE_2D, Some(self.raw)) };
        let uploaded = transfer::tex_sub_image_2d(
            &self.gl,
            w,
            h,
            PixelFormat::Rgba,
            PixelType::Float,
            transfer::f32_bytes(rgba),
        );
        unsafe { self.gl.bind_texture(glow::TEXTURE_2D, None) };
        uploaded.expect("the slice holds the whole image (asserted above)");
    }

    /// Replace the lower-left `width` × `height` texels of an RGBA8 texture with `rgba` (rows
    /// bottom to top).
    pub fn upload_u8_region(&self, width: i32, height: i32, rgba: &[u8]) {
        assert_eq!(self.format, TextureFormat::Rgba8);
        let (w, h) = self.allocated;
        assert!(
            width <= w && height <= h,
            "{width}x{height} in a {w}x{h} texture"
        );
        unsafe { self.gl.bind_texture(glow::TEXTURE_2D, Some(self.raw)) };
        let uploaded = transfer::tex_sub_image_2d(
            &self.gl,
            width,
            height,
            PixelFormat::Rgba,
            PixelType::UnsignedByte,
            rgba,
        );
        unsafe { self.gl.bind_texture(glow::TEXTURE_2D, None) };
        uploaded.expect("the bytes hold the whole region");
    }

    /// Read the whole image back as RGBA floats (rows bottom to top).
    pub fn read_f32(&self, out: &mut Vec<f32>) {
        out.resize(self.texels() * 4, 0.0);
        self.read(PixelType::Float, transfer::f32_bytes_mut(out));
    }

    /// Read the whole image back as RGBA bytes (rows bottom to top).
    pub fn read_u8(&self) -> Vec<u8> {
        let mut out = vec![0u8; self.texels() * 4];
        self.read(PixelType::UnsignedByte, &mut out);
        out
    }

    fn texels(&self) -> usize {
        self.allocated.0 as usize * self.allocated.1 as usize
    }

    /// `glGetTexImage` of the whole image into `out`, checked against the allocated size.
    fn read(&self, ty: PixelType, out: &mut [u8]) {
        let (w, h) = self.allocated;
        unsafe { self.gl.bind_texture(glow::TEXTURE_2D, Some(self.raw)) };
        let read = transfer::get_tex_image(&self.gl, w, h, PixelFormat::Rgba, ty, out);
        unsafe { self.gl.bind_texture(glow::TEXTURE_2D, None) };
        read.expect("the buffer was sized from the allocated image");
    }

    /// Bind to texture unit `unit` (made active).
    pub fn bind(&self, unit: u32) {
        unsafe {
            self.gl.active_texture(glow::TEXTURE0 + unit);
            self.gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
        }
    }
}

impl Drop for Texture {
    fn drop(&mut self) {
        unsafe { self.gl.delete_texture(self.raw) }
    }
}

/// A renderbuffer (depth for the item buffer and the marking pass), deleted when dropped.
pub struct Renderbuffer {
    gl: Gl,
    raw: glow::Renderbuffer,
    /// Width, pixels.
    pub width: i32,
    /// Height, pixels.
    pub height: i32,
}

impl Renderbuffer {
    /// A renderbuffer of `internal_format` (e.g. `glow::DEPTH_COMPONENT24`), `width` x `height`.
    pub fn new(gl: &Gl, internal_format: u32, width: i32, height: i32) -> Result<Self, GlError> {
        unsafe {
            let raw = gl.create_renderbuffer().map_err(GlError::Limit)?;
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(raw));
            gl.renderbuffer_storage(glow::RENDERBUFFER, internal_format, width, height);
            gl.bind_renderbuffer(glow::RENDERBUFFER, None);
            Ok(Renderbuffer {
                gl: gl.clone(),
                raw,
                width,
                height,
            })
        }
    }
}

impl Drop for Renderbuffer {
    fn drop(&mut self) {
        unsafe { self.gl.delete_renderbuffer(self.raw) }
    }
}

/// A framebuffer object: the passes draw into its attached textures, never a window.
pub struct Framebuffer {
    gl: Gl,
    raw: glow::Framebuffer,
}

impl Framebuffer {
    /// An empty framebuffer; attach before drawing.
    pub fn new(gl: &Gl) -> Result<Self, GlError> {
        let raw = unsafe { gl.create_framebuffer() }.map_err(GlError::Limit)?;
        Ok(Framebuffer {
            gl: gl.clone(),
            raw,
        })
    }

    /// Bind for drawing and reading.
    pub fn bind(&self) {
        unsafe { self.gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.raw)) }
    }

    /// Attach level 0 of `texture` at `attachment` (e.g. `glow::COLOR_ATTACHMENT0`); leaves it bound.
    pub fn attach_texture(&self, attachment: u32, texture: &Texture) {
        self.bind();
        unsafe {
            self.gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                attachment,
                glow::TEXTURE_2D,
                Some(texture.raw),
                0,
            );
        }
    }

    /// Attach `rb` at `attachment` (e.g. `glow::DEPTH_ATTACHMENT`); leaves it bound.
    pub fn attach_renderbuffer(&self, attachment: u32, rb: &Renderbuffer) {
        self.bind();
        unsafe {
            self.gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                attachment,
                glow::RENDERBUFFER,
                Some(rb.raw),
            );
        }
    }

    /// Check completeness once after attaching; the error names the pass.
    pub fn check_complete(&self, pass: &str) -> Result<(), GlError> {
        self.bind();
        let status = unsafe { self.gl.check_framebuffer_status(glow::FRAMEBUFFER) };
        if status == glow::FRAMEBUFFER_COMPLETE {
            Ok(())
        } else {
            Err(GlError::Framebuffer {
                pass: pass.into(),
                status: framebuffer_status_name(status),
            })
        }
    }

    /// Read the `width` x `height` rectangle at the origin of an RGBA float attachment of
    /// this framebuffer (rows bottom to top). A negative size reads nothing.
    pub fn read_f32(&self, attachment: u32, width: i32, height: i32, out: &mut Vec<f32>) {
        let (width, height) = (width.max(0), height.max(0));
        out.resize(width as usize * height as usize * 4, 0.0);
        self.bind();
        unsafe { self.gl.read_buffer(attachment) };
        transfer::read_pixels(
            &self.gl,
            0,
            0,
            width,
            height,
            PixelFormat::Rgba,
            PixelType::Float,
            transfer::f32_bytes_mut(out),
        )
        .expect("the buffer was sized for the rectangle");
    }

    /// The paper's accumulation step: `glCopyTexSubImage2D` from one colour attachment of this
    /// framebuffer into a texture of the same size.
    pub fn copy_to_texture(&self, attachment: u32, texture: &Texture) {
        self.bind();
        unsafe {
            self.gl.read_buffer(attachment);
            self.gl.bind_texture(glow::TEXTURE_2D, Some(texture.raw));
            self.gl.copy_tex_sub_image_2d(
                glow::TEXTURE_2D,
                0,
                0,
                0,
                0,
                0,
                texture.width,
                texture.height,
            );
            self.gl.bind_texture(glow::TEXTURE_2D, None);
        }
    }

    /// Copy the texels `[x0, y0, x1, y1)` of colour attachment `attachment` of this framebuffer
    /// into the same texels of `texture` (glCopyTexSubImage2D); the rectangle must lie in both.
    pub fn copy_rect_to_texture(&self, attachment: u32, texture: &Texture, rect: [u32; 4]) {
        let [x0, y0, x1, y1] = rect.map(|v| v as i32);
        assert!(
            0 <= x0
                && x0 <= x1
                && x1 <= texture.width
                && 0 <= y0
                && y0 <= y1
                && y1 <= texture.height,
            "{rect:?} outside a {}x{} texture",
            texture.width,
            texture.height
        );
        self.bind();
        unsafe {
            self.gl.read_buffer(attachment);
            self.gl.bind_texture(glow::TEXTURE_2D, Some(texture.raw));
            self.gl
                .copy_tex_sub_image_2d(glow::TEXTURE_2D, 0, x0, y0, x0, y0, x1 - x0, y1 - y0);
            self.gl.bind_texture(glow::TEXTURE_2D, None);
        }
    }

    /// Copy colour attachment 0 of this framebuffer into colour attachment `attachment` of
    /// `target`, `width` × `height` texels from the origin, unfiltered.
    pub fn blit_to(&self, target: &Framebuffer, attachment: u32, width: i32, height: i32) {
        unsafe {
            self.gl
                .bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.raw));
            self.gl.read_buffer(glow::COLOR_ATTACHMENT0);
            self.gl
                .bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(target.raw));
            self.gl.draw_buffers(&[attachment]);
            self.gl.disable(glow::SCISSOR_TEST);
            self.gl.blit_framebuffer(
                0,
                0,
                width,
                height,
                0,
                0,
                width,
                height,
                glow::COLOR_BUFFER_BIT,
                glow::NEAREST,
            );
            self.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
    }
}

impl Drop for Framebuffer {
    fn drop(&mut self) {
        unsafe { self.gl.delete_framebuffer(self.raw) }
    }
}

/// One vertex attribute of an interleaved float buffer.
pub struct Attribute {
    /// The shader's attribute location (`layout` numbers, see `solver::mesh`).
    pub location: u32,
    /// Floats per vertex in this attribute.
    pub size: i32,
    /// Offset in floats from the start of the vertex.
    pub offset: i32,
}

/// An interleaved float vertex buffer with its vertex array object; drawn as triangles (or
/// points).
pub struct Mesh {
    gl: Gl,
    vao: glow::VertexArray,
    vbo: glow::Buffer,
    /// Vertices in the buffer.
    pub vertex_count: i32,
}

impl Mesh {
    /// Upload `data`, `floats_per_vertex` floats per vertex, with `attributes` as its layout.
    pub fn new(
        gl: &Gl,
        data: &[f32],
        floats_per_vertex: i32,
        attributes: &[Attribute],
    ) -> Result<Self, GlError> {
        unsafe {
            let vao = gl.create_vertex_array().map_err(GlError::Limit)?;
            let vbo = gl.create_buffer().map_err(GlError::Limit)?;
            gl.bind_vertex_array(Some(vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo));
            gl.buffer_data_u8_slice(
                glow::ARRAY_BUFFER,
                transfer::f32_bytes(data),
                glow::STATIC_DRAW,
            );
            for a in attributes {
                gl.enable_vertex_attrib_array(a.location);
                gl.vertex_attrib_pointer_f32(
                    a.location,
                    a.size,
                    glow::FLOAT,
                    false,
                    floats_per_vertex * 4,
                    a.offset * 4,
                );
            }
            gl.bind_vertex_array(None);
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
            let vertex_count = data.len() as i32 / floats_per_vertex;
            Ok(Mesh {
                gl: gl.clone(),
                vao,
                vbo,
                vertex_count,
            })
        }
    }

    /// Draw every vertex as triangles.
    pub fn draw(&self) {
        self.draw_range(0, self.vertex_count);
    }

    /// Replace the vertices (same layout) with new storage ("orphaning": draws still queued
    /// with the old ones never make this wait for them).
    pub fn replace(&mut self, data: &[f32], floats_per_vertex: i32) {
        unsafe {
            self.gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.vbo));
            self.gl.buffer_data_u8_slice(
                glow::ARRAY_BUFFER,
                transfer::f32_bytes(data),
                glow::STREAM_DRAW,
            );
            self.gl.bind_buffer(glow::ARRAY_BUFFER, None);
        }
        self.vertex_count = data.len() as i32 / floats_per_vertex;
    }

    /// Draw `count` vertices from `first` as triangles.
    pub fn draw_range(&self, first: i32, count: i32) {
        self.draw_arrays(glow::TRIANGLES, first, count);
    }

    /// Vertices `first..first + count` as `mode` primitives (`glow::POINTS`, `glow::TRIANGLES`).
    pub fn draw_arrays(&self, mode: u32, first: i32, count: i32) {
        if count == 0 {
            return;
        }
        unsafe {
            self.gl.bind_vertex_array(Some(self.vao));
            self.gl.draw_arrays(mode, first, count);
            self.gl.bind_vertex_array(None);
        }
    }

    /// Draw the triangles whose vertex numbers are `indices.data[first..first + count]` (as
    /// last uploaded with [`IndexStream::upload`]).
    pub fn draw_indexed(&self, indices: &IndexStream, first: usize, count: usize) {
        if count == 0 {
            return;
        }
        unsafe {
            self.gl.bind_vertex_array(Some(self.vao));
            self.gl
                .bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(indices.ebo));
            self.gl.draw_elements(
                glow::TRIANGLES,
                count as i32,
                glow::UNSIGNED_INT,
                (first * 4) as i32,
            );
            self.gl.bind_vertex_array(None);
            self.gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, None);
        }
    }
}

/// A list of vertex numbers that changes from draw to draw (e.g. the triangles left after
/// culling), in one element buffer.
pub struct IndexStream {
    gl: Gl,
    ebo: glow::Buffer,
}

impl IndexStream {
    /// An empty element buffer.
    pub fn new(gl: &Gl) -> Result<Self, GlError> {
        let ebo = unsafe { gl.create_buffer().map_err(GlError::Limit)? };
        Ok(IndexStream {
            gl: gl.clone(),
            ebo,
        })
    }

    /// Replace the list. glBufferData gives the buffer new storage ("orphaning"), so draws
    /// still queued with the old list never make this wait for them.
    pub fn upload(&self, indices: &[u32]) {
        // u32 has no padding and any bit pattern is a valid u8 sequence.
        let bytes = unsafe {
            std::slice::from_raw_parts(
                indices.as_ptr().cast::<u8>(),
                std::mem::size_of_val(indices),
            )
        };
        unsafe {
            self.gl
                .bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(self.ebo));
            self.gl
                .buffer_data_u8_slice(glow::ELEMENT_ARRAY_BUFFER, bytes, glow::STREAM_DRAW);
            self.gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, None);
        }
    }
}

impl Drop for IndexStream {
    fn drop(&mut self) {
        unsafe { self.gl.delete_buffer(self.ebo) };
    }
}

impl Drop for Mesh {
    fn drop(&mut self) {
        unsafe {
            self.gl.delete_vertex_array(self.vao);
            self.gl.delete_buffer(self.vbo);
        }
    }
}
