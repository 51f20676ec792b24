//! The names of the solver's steps and passes, defined once: the keys of [`PassTimes`]
//! (`stats.json`'s `pass_seconds`, the viewer's timings) and the stage a GL error names.
//!
//! [`PassTimes`]: super::PassTimes

/// Choosing the shooters (the paper's Find_Max_Energy).
pub const FIND_MAX_ENERGY: &str = "find_max_energy";
/// The visibility pass (3.2.1): the item buffer drawn from the shooter.
pub const VISIBILITY: &str = "visibility";
/// The reconstruction pass (3.2.2): every receiver's ΔL.
pub const RECONSTRUCTION: &str = "reconstruction";
/// The accumulation: the renderbuffers copied into the lightmaps (glCopyTexSubImage2D).
pub const ACCUMULATION: &str = "accumulation";
/// Reading the unshot lightmap back for the next Find_Max_Energy.
pub const READBACK: &str = "readback";
/// The set-up before the first shot: patch data and the emission written into the lightmaps.
pub const INITIALISATION: &str = "initialisation";
