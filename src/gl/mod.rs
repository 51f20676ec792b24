//! The OpenGL layer: contexts (headless EGL and OSMesa), small owning wrappers for GL objects,
//! shader programs, named error checks, and the checked pixel transfers (`transfer`) every
//! readback and upload goes through. No raw GL id leaves this module tree.

pub mod check;
pub mod context;
mod egl;
pub mod faults;
pub mod limits;
pub mod objects;
mod osmesa;
pub mod program;
pub mod transfer;
pub mod window;

pub use check::GlError;
pub use context::{BackendChoice, BackendKind, GlContext, GlInfo};
pub use limits::LimitError;
pub use objects::{Framebuffer, IndexStream, Mesh, Renderbuffer, Texture, TextureFormat};
pub use program::Program;

/// The GL handle every wrapper shares; it lives as long as the last object made with it.
pub type Gl = std::rc::Rc<glow::Context>;
