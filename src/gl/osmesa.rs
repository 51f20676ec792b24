//! OSMesa, Mesa's off-screen interface, loaded at run time with libloading so that the binary
//! links nothing from it. `RADIOSITY_OSMESA_LIB` overrides the library path.

use std::ffi::{c_char, c_int, c_void, CString};

const OSMESA_FORMAT: c_int = 0x22;
const OSMESA_RGBA: c_int = 0x1908;
const OSMESA_DEPTH_BITS: c_int = 0x30;
const OSMESA_PROFILE: c_int = 0x33;
const OSMESA_COMPAT_PROFILE: c_int = 0x35;
const OSMESA_CONTEXT_MAJOR_VERSION: c_int = 0x36;
const OSMESA_CONTEXT_MINOR_VERSION: c_int = 0x37;
const GL_UNSIGNED_BYTE: u32 = 0x1401;

type CreateContextAttribs = unsafe extern "C" fn(*const c_int, *mut c_void) -> *mut c_void;
type MakeCurrent = unsafe extern "C" fn(*mut c_void, *mut c_void, u32, c_int, c_int) -> u8;
type DestroyContext = unsafe extern "C" fn(*mut c_void);
type GetProcAddress = unsafe extern "C" fn(*const c_char) -> *const c_void;

pub struct OsMesaContext {
    context: *mut c_void,
    destroy: DestroyContext,
    // The default framebuffer OSMesa needs; we render to FBOs, so one pixel is enough.
    _buffer: Box<[u8; 4]>,
    _lib: libloading::Library,
}

impl Drop for OsMesaContext {
    fn drop(&mut self) {
        unsafe { (self.destroy)(self.context) }
    }
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

pub fn create() -> Result<(OsMesaContext, glow::Context), String> {
    let names = library_names();
    let lib = names
        .iter()
        .find_map(|n| unsafe { libloading::Library::new(n) }.ok())
        .ok_or_else(|| format!("cannot load {}", names.join(" or ")))?;
    unsafe {
        let create: CreateContextAttribs = *lib
            .get::<CreateContextAttribs>(b"OSMesaCreateContextAttribs\0")
            .map_err(|e| e.to_string())?;
        let make_current: MakeCurrent = *lib
            .get::<MakeCurrent>(b"OSMesaMakeCurrent\0")
            .map_err(|e| e.to_string())?;
        let destroy: DestroyContext = *lib
            .get::<DestroyContext>(b"OSMesaDestroyContext\0")
            .map_err(|e| e.to_string())?;
        let get_proc: GetProcAddress = *lib
            .get::<GetProcAddress>(b"OSMesaGetProcAddress\0")
            .map_err(|e| e.to_string())?;
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
        let context = create(attribs.as_ptr(), std::ptr::null_mut());
        if context.is_null() {
            return Err("OSMesaCreateContextAttribs refused a 3.0 compatibility context".into());
        }
        let mut buffer = Box::new([0u8; 4]);
        if make_current(context, buffer.as_mut_ptr().cast(), GL_UNSIGNED_BYTE, 1, 1) == 0 {
            destroy(context);
            return Err("OSMesaMakeCurrent failed".into());
        }
        let gl = glow::Context::from_loader_function(|name| {
            let c = CString::new(name).expect("GL names have no NUL");
            get_proc(c.as_ptr())
        });
        Ok((
            OsMesaContext {
                context,
                destroy,
                _buffer: buffer,
                _lib: lib,
            },
            gl,
        ))
    }
}
