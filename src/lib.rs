//! gpu-radiosity: progressive refinement radiosity computed on the GPU through OpenGL 3.0
//! (compatibility profile) and GLSL 1.30, after Yu Ping, *Research and application on radiosity
//! illumination based on GPU hardware acceleration*.
//!
//! The pipeline, one module per stage: [`scene`] (OBJ + MTL) → [`patches`] (lightmaps and the
//! atlas) → [`solver`] (Find_Max_Energy, visibility pass, reconstruction pass) → [`display`]
//! (the lit scene from a camera, images). [`pipeline`] runs them all in a few calls (see its
//! example, and `examples/solve_cornell.rs`); [`gl`] holds the contexts and GL object wrappers;
//! [`cli`] the command line.

#![warn(missing_docs)]

pub mod cli;
pub mod display;
pub mod geometry;
pub mod gl;
pub mod golden;
pub mod patches;
pub mod pipeline;
pub mod random;
pub mod scene;
pub mod solver;
pub mod validate;
pub mod viewer;
