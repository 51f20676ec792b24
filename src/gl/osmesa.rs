//! OSMesa, Mesa's off-screen interface, loaded at run time with libloading so that the binary
//! links nothing from it. `RADIOSITY_OSMESA_LIB` overrides the library path.
//!
//! The library is loaded once and stays loaded for the rest of the process: unloading it
//! (`dlclose` after the last context) runs its exit handler, which destroys the screen every
//! OSMesa context of the process shares, and a later context would load Mesa and LLVM afresh
//! into a process that still holds their state.

use super::transfer::{self, PixelFormat, PixelStore, PixelType};
use std::ffi::{c_char, c_int, c_void, CString};
use std::sync::OnceLock;

const OSMESA_FORMAT: c_int = 0x22;
const OSMESA_RGBA: c_int = 0x1908;
const OSMESA_DEPTH_BITS: c_int = 0x30;
const OSMESA_PROFILE: c_int = 0x33;
const OSMESA_COMPAT_PROFILE: c_int = 0x35;
const OSMESA_CONTEXT_MAJOR_VERSION: c_int = 0x36;
const OSMESA_CONTEXT_MINOR_VERSION: c_int = 0x37;
const GL_UNSIGNED_BYTE: u32 = 0x1401;

/// The default framebuffer OSMesa needs, in pixels; we render to FBOs, so one is enough.
const BUFFER_SIZE: (i32, i32) = (1, 1);

type CreateContextAttribs = unsafe extern "C" fn(*const c_int, *mut c_void) -> *mut c_void;
type MakeCurrent = unsafe extern "C" fn(*mut c_void, *mut c_void, u32, c_int, c_int) -> u8;
type DestroyContext = unsafe extern "C" fn(*mut c_void);
type GetCurrentContext = unsafe extern "C" fn() -> *mut c_void;
type GetProcAddress = unsafe extern "C" fn(*const c_char) -> *const c_void;

/// The loaded library and the entry points we call.
struct Library {
    create: CreateContextAttribs,
    make_current: MakeCurrent,
    destroy: DestroyContext,
    get_current: GetCurrentContext,
    get_proc: GetProcAddress,
    _lib: libloading::Library,
}

fn library_names() -> Vec<String> {
    match std::env::var("RADIOSITY_OSMESA_LIB") {
        Ok(path) => vec![path],
        Err(_) => vec![
            "libOSMesa.so.8".into(),
            "libOSMesa.so.6".into(),
            "libOSMesa.so".into(),
        ],
    }
}

fn load() -> Result<Library, String> {
    let names = library_names();
    let lib = names
        .iter()
        .find_map(|n| unsafe { libloading::Library::new(n) }.ok())
        .ok_or_else(|| format!("cannot load {}", names.join(" or ")))?;
    unsafe {
        Ok(Library {
            create: *lib
                .get::<CreateContextAttribs>(b"OSMesaCreateContextAttribs\0")
                .map_err(|e| e.to_string())?,
            make_current: *lib
                .get::<MakeCurrent>(b"OSMesaMakeCurrent\0")
                .map_err(|e| e.to_string())?,
            destroy: *lib
                .get::<DestroyContext>(b"OSMesaDestroyContext\0")
                .map_err(|e| e.to_string())?,
            get_current: *lib
                .get::<GetCurrentContext>(b"OSMesaGetCurrentContext\0")
                .map_err(|e| e.to_string())?,
            get_proc: *lib
                .get::<GetProcAddress>(b"OSMesaGetProcAddress\0")
                .map_err(|e| e.to_string())?,
            _lib: lib,
        })
    }
}

/// The process's one copy of the library (see the module's note).
fn library() -> Result<&'static Library, String> {
    static LIBRARY: OnceLock<Result<Library, String>> = OnceLock::new();
    LIBRARY.get_or_init(load).as_ref().map_err(Clone::clone)
}

pub struct OsMesaContext {
    context: *mut c_void,
    lib: &'static Library,
    /// The colour buffer OSMesa writes the default framebuffer into (at glFlush/glFinish),
    /// sized by the same rule as every other transfer; owned here (from `Box::into_raw`) and
    /// freed only after the context is destroyed.
    buffer: *mut [u8],
}

impl OsMesaContext {
    /// Make this context current on the calling thread, on its own colour buffer.
    pub fn make_current(&self) -> bool {
        let (w, h) = BUFFER_SIZE;
        let buffer = self.buffer.cast::<c_void>();
        unsafe { (self.lib.make_current)(self.context, buffer, GL_UNSIGNED_BYTE, w, h) != 0 }
    }
}

impl Drop for OsMesaContext {
    fn drop(&mut self) {
        unsafe {
            // Released first, as for EGL: OSMesaDestroyContext does not unbind a current
            // context, and this thread would keep a dangling current context.
            if (self.lib.get_current)() == self.context {
                (self.lib.make_current)(std::ptr::null_mut(), std::ptr::null_mut(), 0, 0, 0);
            }
            (self.lib.destroy)(self.context);
            drop(Box::from_raw(self.buffer));
        }
    }
}

/// `OSMesaGetCurrentContext`: the calling thread's current OSMesa context, null if none.
#[cfg(test)]
pub fn current_context() -> *mut c_void {
    library().map_or(std::ptr::null_mut(), |lib| unsafe { (lib.get_current)() })
}

pub fn create() -> Result<(OsMesaContext, glow::Context), String> {
    let lib = library()?;
    let attribs = [
        OSMESA_FORMAT,
        OSMESA_RGBA,
        OSMESA_DEPTH_BITS,
        24,
        OSMESA_PROFILE,
        OSMESA_COMPAT_PROFILE,
        OSMESA_CONTEXT_MAJOR_VERSION,
        3,
        OSMESA_CONTEXT_MINOR_VERSION,
        0,
        0,
    ];
    let context = unsafe { (lib.create)(attribs.as_ptr(), std::ptr::null_mut()) };
    if context.is_null() {
        return Err("OSMesaCreateContextAttribs refused a 3.0 compatibility context".into());
    }
    // OSMesa writes whole rows of RGBA bytes, no padding (OSMESA_ROW_LENGTH left at 0).
    let (w, h) = BUFFER_SIZE;
    let tight = PixelStore {
        alignment: 1,
        ..PixelStore::DEFAULT
    };
    let bytes = transfer::span(w, h, PixelFormat::Rgba, PixelType::UnsignedByte, tight)
        .map_err(|e| e.to_string())?;
    let made = OsMesaContext {
        context,
        lib,
        buffer: Box::into_raw(vec![0u8; bytes].into_boxed_slice()),
    };
    if !made.make_current() {
        return Err("OSMesaMakeCurrent failed".into());
    }
    let gl = unsafe {
        glow::Context::from_loader_function(|name| {
            let c = CString::new(name).expect("GL names have no NUL");
            (lib.get_proc)(c.as_ptr())
        })
    };
    Ok((made, gl))
}
