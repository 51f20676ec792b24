//! Display (paper 3.2.2, end of step 5): the whole scene drawn from a camera with the packed
//! lightmap atlas (curved surfaces shaded smooth, beyond the paper: `smooth.rs`), and the result
//! written as images.

pub mod ambient;
pub mod bake;
pub mod gltf_out;
pub mod mesh;
pub mod output;
pub mod output_set;
pub mod passes;
pub mod plot;
mod render;
pub mod scaling_plot;
pub mod smooth;

pub use mesh::DisplayMesh;
pub use render::{render, scene_view_projection, DisplayPass, Image, Viewport};
pub use smooth::Smoothing;

use crate::scene::Camera;
use glam::Mat4;

/// View-projection of a standard right-handed look-at camera (world +x appears on the left when
/// looking down +z, as docs/conventions.md says of the Cornell box).
pub fn view_projection(camera: &Camera, aspect: f32, near: f32, far: f32) -> Mat4 {
    let view = Mat4::look_at_rh(camera.eye, camera.target, camera.up);
    let projection = Mat4::perspective_rh_gl(camera.fov_y.to_radians(), aspect, near, far);
    projection * view
}
