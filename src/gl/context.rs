//! Headless OpenGL 3.0 compatibility contexts. Two backends reach Mesa without a display server:
//! EGL (through glutin, on the EGL device platform) and OSMesa (loaded at run time, so the binary
//! needs `libosmesa6` only when asked for it). `auto` tries EGL, then OSMesa.

use super::check::DebugLog;
use super::{egl, osmesa, Gl};
use glow::HasContext;
use std::rc::Rc;

/// Which headless backend to open (`--backend`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BackendChoice {
    /// EGL (surfaceless) if it works, else OSMesa.
    Auto,
    /// EGL with Mesa's surfaceless platform.
    Egl,
    /// OSMesa, Mesa's off-screen library.
    Osmesa,
}

/// The backend a context was made with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BackendKind {
    /// EGL with Mesa's surfaceless platform.
    Egl,
    /// OSMesa, Mesa's off-screen library.
    Osmesa,
    /// A context made by someone else (the interactive viewer's window).
    Window,
}

impl BackendKind {
    /// Its name in stats.json and messages (`egl`, `osmesa`, `window`).
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
    /// The backend the context came from.
    pub backend: BackendKind,
    /// GL_VENDOR.
    pub vendor: String,
    /// GL_RENDERER (llvmpipe, softpipe, zink, ...).
    pub renderer: String,
    /// GL_VERSION.
    pub version: String,
    /// GL_SHADING_LANGUAGE_VERSION.
    pub glsl_version: String,
    /// GL_MAX_TEXTURE_SIZE: the largest texture side (the atlas must fit).
    pub max_texture_size: i32,
    /// GL_MAX_RENDERBUFFER_SIZE: the largest renderbuffer side (the item buffer must fit).
    pub max_renderbuffer_size: i32,
    /// GL_MAX_VIEWPORT_DIMS: the widest and tallest viewport.
    pub max_viewport_dims: [i32; 2],
    /// Whether KHR_debug is there: driver messages turn into errors that name the pass.
    pub khr_debug: bool,
}

/// No backend gave an OpenGL 3.0 context; the message says how to install one.
#[derive(Debug, thiserror::Error)]
#[error(
    "no usable OpenGL 3.0 driver: {tried}. On Debian install Mesa's software drivers with \
     `apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri` (EGL backend) or \
     `apt-get install libosmesa6` (OSMesa backend)"
)]
pub struct NoDriver {
    /// Each backend tried and why it failed.
    pub tried: String,
}

/// What keeps a context alive, and its teardown.
enum Backend {
    Egl(egl::EglContext),
    Osmesa(osmesa::OsMesaContext),
    External(#[allow(dead_code)] Box<dyn std::any::Any>),
}

/// Held by every thread that has a context on one of Mesa's software rasterisers (or is making
/// a context): llvmpipe of Mesa 22.3 (Debian 12), which all contexts of a process share, crashes
/// when contexts of two threads draw at once (SIGSEGV inside `glCopyTexSubImage2D` and
/// `glDrawArrays`, with the other thread in the same driver function; docs/perf-log.md,
/// 2026-12-04). Reentrant, so one thread may hold several contexts; another thread's
/// [`GlContext::headless`] waits until this one has dropped all of them. Contexts on a hardware
/// driver let it go once they know their renderer.
static SOFTWARE_RASTERISER: parking_lot::ReentrantMutex<()> =
    parking_lot::const_reentrant_mutex(());

/// Whether `renderer` (GL_RENDERER) is one of Mesa's software rasterisers, directly or under
/// zink over lavapipe (`zink Vulkan 1.3(llvmpipe (LLVM 15.0.6, 256 bits) (MESA_LLVMPIPE))`),
/// including classic swrast, which calls itself `Mesa X11` or `Mesa OffScreen`.
pub fn is_software_rasteriser(renderer: &str) -> bool {
    let r = renderer.to_ascii_lowercase();
    ["llvmpipe", "lavapipe", "softpipe", "swrast"]
        .iter()
        .any(|name| r.contains(name))
        || r.starts_with("mesa x11")
        || r.starts_with("mesa offscreen")
}

/// A context's backend, destroyed in `drop` with no context current; then the thread's newest
/// remaining context is made current again. The software rasteriser's lock goes last (a field
/// after `drop`'s body).
struct Keep {
    backend: Option<Backend>,
    _serial: Option<parking_lot::ReentrantMutexGuard<'static, ()>>,
}

impl Keep {
    /// Make this context current on the calling thread. A window's context is made current by
    /// its window, and is the only one on the viewer's thread.
    fn make_current(&self) {
        match &self.backend {
            Some(Backend::Egl(c)) => {
                c.make_current();
            }
            Some(Backend::Osmesa(c)) => {
                c.make_current();
            }
            _ => {}
        }
    }
}

impl Drop for Keep {
    fn drop(&mut self) {
        let backend = self.backend.take();
        let egl = matches!(backend, Some(Backend::Egl(_)));
        // EglContext and OsMesaContext release the context, then destroy it.
        drop(backend);
        let (newest, egl_left) = LIVE
            .try_with(|live| {
                let mut live = live.borrow_mut();
                live.retain(|k| k.strong_count() > 0);
                // A window's context may be EGL too.
                let egl_left = live
                    .iter()
                    .filter_map(std::rc::Weak::upgrade)
                    .any(|k| matches!(k.backend, Some(Backend::Egl(_) | Backend::External(_))));
                (live.last().and_then(std::rc::Weak::upgrade), egl_left)
            })
            .unwrap_or((None, true));
        if let Some(k) = newest {
            k.make_current();
        }
        if egl && !egl_left {
            // The thread's last EGL context is gone: free its EGL state now, not at its end.
            egl::release_thread();
        }
    }
}

thread_local! {
    /// This thread's live contexts, oldest first. A new context is made current when it is
    /// created, so GL calls go to the newest; `drop` keeps it so.
    static LIVE: std::cell::RefCell<Vec<std::rc::Weak<Keep>>> = const {
        std::cell::RefCell::new(Vec::new())
    };
}

/// A current GL context. GL objects made with `gl` must be dropped before this value.
///
/// Several may live in one thread (each call goes to the newest; use the objects of one only
/// while it is the newest), and in several threads, though on Mesa's software rasterisers one
/// thread at a time: another thread's `headless` waits until this thread has dropped all of its
/// contexts (see [`is_software_rasteriser`]; those drivers crash otherwise). A `GlContext` cannot move to
/// another thread (it is neither `Send` nor `Sync`), so it is always dropped on the thread it
/// is current on. Dropping one, in any order, tears it down with this context current (the
/// glow handle removes its KHR_debug callback from this context, not another), destroys it
/// with no context current, and makes the thread's newest remaining context current again.
pub struct GlContext {
    /// The GL functions of this context.
    pub gl: Gl,
    /// What the driver says about itself.
    pub info: GlInfo,
    /// The KHR_debug messages, when the driver has the extension.
    pub debug: Option<DebugLog>,
    _keep: Rc<Keep>,
}

impl Drop for GlContext {
    fn drop(&mut self) {
        let newest = LIVE
            .try_with(|live| {
                live.borrow()
                    .last()
                    .is_some_and(|k| std::ptr::eq(k.as_ptr(), Rc::as_ptr(&self._keep)))
            })
            .unwrap_or(true);
        if !newest {
            self._keep.make_current();
        }
        // Then the fields go in order: `gl` (with the debug callback, if this is the last
        // handle), then `_keep` (release, destroy, restore the newest).
    }
}

impl GlContext {
    /// A context without a window, from `choice` (`Auto`: EGL, then OSMesa), current on this thread.
    pub fn headless(choice: BackendChoice) -> Result<GlContext, NoDriver> {
        let order: &[BackendKind] = match choice {
            BackendChoice::Auto => &[BackendKind::Egl, BackendKind::Osmesa],
            BackendChoice::Egl => &[BackendKind::Egl],
            BackendChoice::Osmesa => &[BackendKind::Osmesa],
        };
        let mut tried = Vec::new();
        // Before the driver is known, every thread waits its turn (`finish` lets go on hardware).
        let serial = SOFTWARE_RASTERISER.lock();
        for &kind in order {
            let made = match kind {
                BackendKind::Egl => egl::create().map(|(k, gl)| (Backend::Egl(k), gl)),
                BackendKind::Osmesa => osmesa::create().map(|(k, gl)| (Backend::Osmesa(k), gl)),
                BackendKind::Window => unreachable!("not a headless backend"),
            };
            match made {
                Ok((keep, gl)) => match Self::finish(kind, keep, gl, SOFTWARE_RASTERISER.lock()) {
                    Ok(ctx) => return Ok(ctx),
                    Err(e) => tried.push(format!("{}: {e}", kind.name())),
                },
                Err(e) => tried.push(format!("{}: {e}", kind.name())),
            }
        }
        drop(serial);
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
        Self::finish(
            BackendKind::Window,
            Backend::External(keep),
            gl,
            SOFTWARE_RASTERISER.lock(),
        )
    }

    fn finish(
        kind: BackendKind,
        backend: Backend,
        mut gl: glow::Context,
        serial: parking_lot::ReentrantMutexGuard<'static, ()>,
    ) -> Result<GlContext, String> {
        // Registered first, so that a refusal below tears it down like any other.
        let mut keep = Keep {
            backend: Some(backend),
            _serial: Some(serial),
        };
        let renderer = unsafe { gl.get_parameter_string(glow::RENDERER) };
        if !is_software_rasteriser(&renderer) {
            keep._serial = None;
        }
        let keep = Rc::new(keep);
        LIVE.with(|live| live.borrow_mut().push(Rc::downgrade(&keep)));
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
                renderer,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gl::{Texture, TextureFormat};

    /// Upload a pattern particular to `seed` into a new texture on `ctx` and read it back.
    fn round_trip(ctx: &GlContext, seed: u32) -> bool {
        let (w, h) = (29 + seed as i32 % 7, 11);
        let data: Vec<f32> = (0..w * h * 4).map(|i| (i as u32 ^ seed) as f32).collect();
        let texture = Texture::new(&ctx.gl, w, h, TextureFormat::Rgba32F, glow::NEAREST).unwrap();
        texture.upload_f32(&data);
        let mut back = Vec::new();
        texture.read_f32(&mut back);
        back == data && ctx.check("round trip").is_ok()
    }

    /// A deliberate GL error, as `check` reports it on `ctx`.
    fn provoked_error(ctx: &GlContext) -> String {
        unsafe { ctx.gl.enable(0xFFFF) };
        ctx.check("provoked").unwrap_err().to_string()
    }

    fn backends() -> Vec<BackendChoice> {
        // Each backend this machine has (CI installs both).
        [BackendChoice::Egl, BackendChoice::Osmesa]
            .into_iter()
            .filter(|&b| GlContext::headless(b).is_ok())
            .collect()
    }

    #[test]
    fn contexts_made_and_dropped_in_several_threads_at_once() {
        let backends = backends();
        assert!(!backends.is_empty(), "no GL backend");
        std::thread::scope(|s| {
            for t in 0..4u32 {
                let backends = &backends;
                s.spawn(move || {
                    for round in 0..6u32 {
                        let backend = backends[(t + round) as usize % backends.len()];
                        let ctx = GlContext::headless(backend).unwrap();
                        assert!(round_trip(&ctx, t * 100 + round), "{backend:?}");
                    }
                });
            }
        });
    }

    /// Threads that make and drop a context (EGL where there is one) and end as the test ends:
    /// run alone (`--exact`), the binary exits while they finish, which is when libglvnd 1.6's
    /// exit-time teardown raced their thread-exit destructors (a double free; docs/perf-log.md,
    /// 2026-12-03). One run catches that rarely (about one in a hundred before the fix);
    /// tools/asan-stress.sh runs it alone `EXIT_RUNS` times.
    #[test]
    fn threads_that_end_as_the_process_ends() {
        const THREADS: u32 = 32;
        let (tx, rx) = std::sync::mpsc::channel();
        for t in 0..THREADS {
            let tx = tx.clone();
            // Not joined, as libtest does not join its test threads.
            std::thread::spawn(move || {
                let ok =
                    GlContext::headless(BackendChoice::Auto).is_ok_and(|ctx| round_trip(&ctx, t));
                tx.send(ok).unwrap();
            });
        }
        for _ in 0..THREADS {
            assert!(rx.recv().unwrap());
        }
    }

    /// On a software rasteriser a second thread gets its context only once the first thread
    /// has dropped its own: the flag is set just before the drop, so a second thread that got
    /// its context while the first still held one would see it unset.
    #[test]
    fn software_contexts_of_two_threads_do_not_overlap() {
        use std::sync::atomic::{AtomicBool, Ordering};
        let first = GlContext::headless(BackendChoice::Auto).expect("a GL backend");
        let software = is_software_rasteriser(&first.info.renderer);
        let dropped = AtomicBool::new(false);
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::scope(|s| {
            let dropped = &dropped;
            let second = s.spawn(move || {
                rx.recv().unwrap();
                let ctx = GlContext::headless(BackendChoice::Auto).unwrap();
                let overlapped = !dropped.load(Ordering::SeqCst);
                assert!(round_trip(&ctx, 7));
                overlapped
            });
            tx.send(()).unwrap();
            std::thread::sleep(std::time::Duration::from_millis(300));
            assert!(round_trip(&first, 6));
            dropped.store(true, Ordering::SeqCst);
            drop(first);
            let overlapped = second.join().unwrap();
            // On a hardware driver the contexts may overlap (nothing asserts that they do).
            assert!(
                !(software && overlapped),
                "{}",
                "the second context came while the first lived"
            );
        });
    }

    #[test]
    fn software_rasterisers_are_recognised() {
        for r in [
            "llvmpipe (LLVM 15.0.6, 256 bits)",
            "softpipe",
            "zink (llvmpipe (LLVM 15.0.6, 256 bits))",
        ] {
            assert!(is_software_rasteriser(r), "{r}");
        }
        assert!(!is_software_rasteriser(
            "AMD Radeon RX 6600 (radeonsi, navi23, LLVM 15.0.6)"
        ));
    }

    /// Whether `backend` has a context current on this thread.
    fn something_current(backend: BackendChoice) -> bool {
        match backend {
            BackendChoice::Osmesa => !osmesa::current_context().is_null(),
            _ => !egl::current_context().is_null(),
        }
    }

    #[test]
    fn a_dropped_context_is_destroyed_not_left_current() {
        // eglDestroyContext on a current context only marks it: it would stay current (and
        // alive) on this thread until the thread ends.
        for backend in backends() {
            let ctx = GlContext::headless(backend).unwrap();
            assert!(something_current(backend), "{backend:?}");
            drop(ctx);
            assert!(
                !something_current(backend),
                "{backend:?}: still current after drop"
            );
        }
    }

    #[test]
    fn two_contexts_in_one_thread_tear_down_in_either_order() {
        for backend in backends() {
            // The older dropped first: the newer must keep its debug callback and stay current.
            let older = GlContext::headless(backend).unwrap();
            let newer = GlContext::headless(backend).unwrap();
            assert!(round_trip(&newer, 1));
            drop(older);
            assert!(
                round_trip(&newer, 2),
                "{backend:?}: the newer after the older's drop"
            );
            if newer.info.khr_debug {
                // Two parts: the glGetError code and the KHR_debug message, which only a
                // callback still installed on this context delivers.
                let error = provoked_error(&newer);
                assert_eq!(error.matches("; ").count(), 1, "{backend:?}: {error}");
            }
            drop(newer);

            // The newer dropped first: the older is current again.
            let older = GlContext::headless(backend).unwrap();
            let newer = GlContext::headless(backend).unwrap();
            drop(newer);
            assert!(
                round_trip(&older, 3),
                "{backend:?}: the older after the newer's drop"
            );
        }
    }
}
