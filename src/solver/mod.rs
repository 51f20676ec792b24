//! The solver: progressive refinement radiosity as in section 3.2 of the paper.
//!
//! `progressive.rs` is the loop in the paper's order, written once ([`Solver`]) over a
//! [`Backend`] that does the passes: `gpu.rs` on OpenGL as the paper does, `cpu/` in Rust with
//! exact visibility. Each step has its own file: `find_max_energy.rs` (choose the shooter, from
//! the books both backends share: unshot totals, areas, stopping rule, history, pass timers,
//! and each shot's energy balance), `shooters.rs` (the shooter's cells, beyond the paper, whose
//! whole polygon shoots from `progressive.rs`), `visibility/` (item buffer from the shooter,
//! and what it may leave out), `reconstruction/` (form factors and received energy per patch,
//! accumulation), `form_factor.rs` (the CPU twins of the
//! shader's factors). `mesh.rs` builds the vertex data the passes draw; `pass_names.rs` names
//! the steps (timers, GL errors); `tuning.rs` holds every speed trick for llvmpipe, apart from
//! the paper; `overshoot.rs` the ambient estimate of overshooting, one of the speed options
//! beyond the paper that change the answer (`SolveOptions::overshoot`, `small_hemi_res`,
//! `rotate_item_buffer`, `shooters_per_pass`).

pub mod cluster_near;
pub mod cluster_parts;
pub mod cluster_shooter;
pub mod clusters;
pub mod cpu;
pub mod engine;
pub mod face_clusters;
pub mod find_max_energy;
pub mod form_factor;
pub mod gpu;
pub mod mesh;
pub mod options;
pub mod overshoot;
pub mod pass_names;
pub mod profile;
pub mod progressive;
pub mod reconstruction;
pub mod shooters;
pub mod tuning;
pub mod visibility;

pub use cluster_parts::{Part, PartRows};
pub use clusters::Member;
pub use cpu::CpuSolver;
pub use find_max_energy::{Ledger, PassTimes};
pub use gpu::GpuSolver;
pub use options::*;
pub use profile::{ChosenTuning, Profile, TuningChoice};
pub use progressive::{Backend, Solver};
pub use tuning::{ReceiverChoice, Tuning, Walk};
pub use visibility::item_buffer_side;

use crate::gl::GlError;

/// Why a solve cannot start or go on. The messages speak of the solver's settings (patch size,
/// item-buffer resolution, tessellation); the command line adds its flags.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    /// A GL failure (names the pass).
    #[error(transparent)]
    Gl(#[from] GlError),
    /// The atlas is larger than the driver's textures.
    #[error(
        "the lightmap atlas needs {width}x{height} texels but this driver allows at most \
         {max}x{max} (GL_MAX_TEXTURE_SIZE / GL_MAX_RENDERBUFFER_SIZE); use a larger patch size \
         (about {suggest} scene units or more) or fewer patches"
    )]
    AtlasTooLarge {
        /// Atlas width, texels.
        width: u32,
        /// Atlas height, texels.
        height: u32,
        /// The driver's largest side.
        max: i32,
        /// About the smallest patch size that fits.
        suggest: f32,
    },
    /// Speed switches that cannot work together (`Tuning::check`).
    #[error("{0}")]
    Tuning(String),
    /// A negative or non-finite tessellation.
    #[error("the tessellation {0} must be 0 (off) or a positive number of patch sizes")]
    Tessellation(f32),
    /// An item-buffer resolution the driver cannot hold.
    #[error("the item-buffer resolution {res} is outside 16..={max}")]
    HemiRes {
        /// The resolution asked for.
        res: u32,
        /// The largest this driver allows.
        max: i32,
    },
    /// A small shots' resolution outside 16 to the full one.
    #[error(
        "the small shots' item-buffer resolution {small} is outside 16..={full} (the \
         item-buffer resolution)"
    )]
    SmallHemiRes {
        /// The small shots' resolution.
        small: u32,
        /// The item-buffer resolution.
        full: u32,
    },
    /// A smallest shots' resolution above the small shots' one.
    #[error(
        "the smallest shots' item-buffer resolution {min} needs a small shots' resolution at \
         least as large (now {small}; 0: none) and is at least 16"
    )]
    MinHemiRes {
        /// The smallest shots' resolution.
        min: u32,
        /// The small shots' resolution.
        small: u32,
    },
    /// No emitter has a patch.
    #[error(
        "the emitters have no patches at this patch size ({patch_size} scene units): a light \
         smaller than a patch emits nothing; use a smaller patch size or more patches"
    )]
    NoEmission {
        /// The patch size, scene units.
        patch_size: f32,
    },
    /// The CPU solver's worker threads cannot start.
    #[error("cannot start {threads} worker threads: {source}")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// Why they cannot start.
        source: rayon::ThreadPoolBuildError,
    },
    /// A shot's receivers got more than it carried (the check of `Solver::shoot`).
    #[error(
        "energy created at shot {shot}: the unshot power is now {unshot:.3}x the emitted power (or \
         the loaded one) ({shooter} shot {shot_power:.4e} and its receivers received \
         {received:.4e}, {excess:.3}x what it carried in its worst channel). Receivers that \
         gained most: {receivers}. {cause}"
    )]
    EnergyCreated {
        /// What does this, for the settings in use.
        cause: &'static str,
        /// The shot, 1-based.
        shot: u32,
        /// Unshot power after the shot over the emitted power (or over the loaded unshot power).
        unshot: f64,
        /// The shooting polygon, with its object.
        shooter: String,
        /// Power it carried.
        shot_power: f64,
        /// Power that reached the receivers (RGB mean).
        received: f64,
        /// Received over carried, in the channel where that is largest.
        excess: f64,
        /// The receivers that gained most.
        receivers: String,
    },
    /// Shooters per pass outside 1 to `MAX_SHOOTERS_PER_PASS`.
    #[error("the shooters per pass {0} are outside 1..={max}", max = MAX_SHOOTERS_PER_PASS)]
    ShootersPerPass(u32),
    /// An atlas of the wrong length given to `Solver::load_atlases`.
    #[error("an atlas of {got} floats was given where the layout has {expected}")]
    AtlasSize {
        /// Floats the layout has.
        expected: usize,
        /// Floats given.
        got: usize,
    },
}

use glam::Vec3;

/// Most corners a shooter's outline may have (a cell clipped to its polygon, or a whole polygon);
/// a shooter with more uses its bounding rectangle instead.
pub const MAX_CORNERS: usize = 12;

/// A shooter: a polygon, or one cell of its lightmap, shooting its unshot energy from one point
/// (the paper: the whole polygon from its centre).
#[derive(Clone, Copy, Debug)]
pub struct Shooter {
    /// Its polygon.
    pub polygon: usize,
    /// The atlas texels whose unshot energy this shot carries (and clears): [x0, y0, x1, y1).
    /// Parts of one cell share it (their patches are told apart by side, `shooters.rs`).
    pub texels: [u32; 4],
    /// How many patches' unshot energy it carries.
    pub patches: u32,
    /// The point it shoots from (the paper: the polygon's centroid).
    pub position: Vec3,
    /// Its polygon's unit normal (the item buffer looks along it).
    pub normal: Vec3,
    /// Unshot radiance times area, RGB (what the shader calls ShootEnergy).
    pub energy: Vec3,
    /// The shooter's outline (counter-clockwise seen from its front), for the polygon form
    /// factor: `corners[..corner_count]`.
    pub corners: [Vec3; MAX_CORNERS],
    /// Corners of the outline in `corners`.
    pub corner_count: usize,
    /// Area of that outline.
    pub area: f32,
    /// The unshot radiance the shooting patches are left with: zero in the paper; minus the
    /// overshoot when overshooting (`overshoot.rs`), which `energy` then includes.
    pub remainder: Vec3,
    /// Item-buffer side for this shot's visibility pass (per hemicube face).
    pub hemi_res: u32,
    /// Turn of the item buffer about the normal, radians (`SolveOptions::rotate_item_buffer`;
    /// 0 in the paper).
    pub turn: f32,
    /// Beyond the paper: a face cluster's members, shot with their own outlines at receivers
    /// near it (`cluster_parts.rs`); none for every other shooter.
    pub parts: PartRows,
}

/// One shot, as reported in `stats.json`'s history.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ShotRecord {
    /// The shot, 1-based.
    pub shot: u32,
    /// The polygon that shot (the first, when several shot in one pass).
    pub shooter: usize,
    /// Seconds since the solve started, at the end of this shot.
    pub seconds: f64,
    /// Unshot power / emitted power after this shot.
    pub unshot_fraction: f64,
    /// Power the shooter shot (π·ΔL·A, RGB mean).
    pub shot_power: f64,
    /// Power the receivers reflect from it (added to their unshot energy).
    pub reflected_power: f64,
    /// Power the shooters carried, each colour channel by magnitude (RGB mean): `shot_power`,
    /// unless overshooting shot negative energy too.
    pub carried_power: f64,
    /// Power that reached the receivers (what they reflect over their reflectance, channel by
    /// channel, RGB mean): at most `carried_power` in a shot that creates no energy.
    pub received_power: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shooter(turn: f32) -> Shooter {
        Shooter {
            polygon: 0,
            texels: [0; 4],
            patches: 1,
            position: Vec3::new(1.0, 2.0, 3.0),
            normal: Vec3::new(0.0, 1.0, 0.0),
            energy: Vec3::ONE,
            corners: [Vec3::ZERO; MAX_CORNERS],
            corner_count: 0,
            area: 1.0,
            remainder: Vec3::ZERO,
            hemi_res: 64,
            turn,
            parts: PartRows::default(),
        }
    }

    #[test]
    fn a_turned_item_buffer_still_looks_along_the_normal_and_turns_by_the_angle() {
        let (plain, turned) = (shooter(0.0).view(), shooter(0.7).view());
        let ahead = Vec3::new(1.0, 3.0, 3.0);
        // Straight ahead is straight ahead either way.
        for view in [plain, turned] {
            let d = view.transform_point3(ahead);
            assert!(d.x.abs() < 1e-6 && d.y.abs() < 1e-6 && (d.z + 1.0).abs() < 1e-6);
        }
        // A direction across the normal turns about the view axis by the angle.
        let side = plain.transform_vector3(Vec3::X);
        let side_turned = turned.transform_vector3(Vec3::X);
        let angle = side.truncate().angle_to(side_turned.truncate()).abs();
        assert!((angle - 0.7).abs() < 1e-5, "{angle}");
    }
}
