//! The solver: progressive refinement radiosity as in section 3.2 of the paper.
//!
//! `progressive.rs` is the loop in the paper's order, written once ([`Solver`]) over a
//! [`Backend`] that does the passes: `gpu.rs` on OpenGL as the paper does, `cpu/` in Rust with
//! exact visibility. `ledger.rs` keeps the books both share (unshot totals, areas, stopping rule,
//! history, pass timers). Each step has its own file: `find_max_energy.rs` (choose the shooter),
//! `shooters.rs` (the shooter's cells), `visibility/` (item buffer from the shooter, and what it
//! may leave out), `reconstruction/` (form factors and received energy per patch, accumulation),
//! `form_factor.rs` (the CPU twins of the shader's factors). `mesh.rs` builds the vertex data
//! the passes draw; `tuning.rs` holds every speed trick for llvmpipe, apart from the paper;
//! `overshoot.rs` the ambient estimate of overshooting, one of the speed options beyond the paper
//! that change the answer (`SolveOptions::overshoot`, `small_hemi_res`,
//! `rotate_item_buffer`, `shooters_per_pass`).

pub mod cpu;
pub mod find_max_energy;
pub mod form_factor;
pub mod gpu;
pub mod ledger;
pub mod mesh;
pub mod overshoot;
pub mod progressive;
pub mod reconstruction;
pub mod shooters;
pub mod tuning;
pub mod visibility;

pub use cpu::CpuSolver;
pub use gpu::GpuSolver;
pub use ledger::{Ledger, PassTimes};
pub use progressive::{Backend, Solver};
pub use tuning::Tuning;

use crate::gl::GlError;

/// Why a solve cannot start or go on. The messages speak of the solver's settings (patch size,
/// item-buffer resolution, tessellation); the command line adds its flags.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error(transparent)]
    Gl(#[from] GlError),
    #[error(
        "the lightmap atlas needs {width}x{height} texels but this driver allows at most \
         {max}x{max} (GL_MAX_TEXTURE_SIZE / GL_MAX_RENDERBUFFER_SIZE); use a larger patch size \
         (about {suggest} scene units or more) or fewer patches"
    )]
    AtlasTooLarge {
        width: u32,
        height: u32,
        max: i32,
        suggest: f32,
    },
    #[error("the tessellation {0} must be 0 (off) or a positive number of patch sizes")]
    Tessellation(f32),
    #[error("the item-buffer resolution {res} is outside 16..={max}")]
    HemiRes { res: u32, max: i32 },
    #[error(
        "the small shots' item-buffer resolution {small} is outside 16..={full} (the \
         item-buffer resolution)"
    )]
    SmallHemiRes { small: u32, full: u32 },
    #[error(
        "the smallest shots' item-buffer resolution {min} needs a small shots' resolution at \
         least as large (now {small}; 0: none) and is at least 16"
    )]
    MinHemiRes { min: u32, small: u32 },
    #[error(
        "the emitters have no patches at this patch size ({patch_size} scene units): a light \
         smaller than a patch emits nothing; use a smaller patch size or more patches"
    )]
    NoEmission { patch_size: f32 },
    #[error("cannot start {threads} worker threads: {source}")]
    Threads {
        threads: usize,
        source: rayon::ThreadPoolBuildError,
    },
    #[error(
        "energy created at shot {shot}: the unshot power is now {unshot:.3}x the emitted power (or \
         the loaded one) \
         ({shooter} shot {shot_power:.4e} and the receivers reflected {reflected:.4e}, where the \
         largest reflectance allows {bound:.4e}). Receivers that gained most: {receivers}. {cause}"
    )]
    EnergyCreated {
        /// What does this, for the settings in use.
        cause: &'static str,
        shot: u32,
        /// Unshot power after the shot over the emitted power (or over the loaded unshot power).
        unshot: f64,
        shooter: String,
        shot_power: f64,
        reflected: f64,
        bound: f64,
        receivers: String,
    },
    #[error("the shooters per pass {0} are outside 1..={max}", max = MAX_SHOOTERS_PER_PASS)]
    ShootersPerPass(u32),
    #[error("an atlas of {got} floats was given where the layout has {expected}")]
    AtlasSize { expected: usize, got: usize },
}

use glam::{Mat4, Vec3};

/// The share of the emitted power below which a shot counts as small
/// (`SolveOptions::small_shot`), as measured against the accuracy guard (docs/accuracy.md).
pub const SMALL_SHOT: f32 = 0.01;

/// Most shooters one reconstruction pass serves (`SolveOptions::shooters_per_pass`; the shader
/// is compiled for that many). Eight item buffers take texture units 0 and 7 to 13 of the 16
/// GL 3.0 promises, and the shooters' uniforms under 900 of its 1,024 fragment components,
/// each array element counted as a whole vec4.
pub const MAX_SHOOTERS_PER_PASS: u32 = 8;

/// Which form factor the reconstruction pass evaluates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FormFactorKind {
    /// The paper's point factor cos·cos/(π r²) times the shooter's area (blows up near it).
    Point,
    /// The exact differential-area-to-polygon factor of the shooter's cell (finite everywhere).
    Polygon,
}

/// How the visibility pass sees the scene from the shooter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum VisibilityKind {
    /// The paper's hemispherical projection: one render, curved edges drawn straight.
    Hemisphere,
    /// Five perspective renders (Cohen & Greenberg 1985): exact for straight edges.
    Hemicube,
}

/// Stopping rule and pass parameters.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SolveOptions {
    /// Stop when unshot power / emitted power falls to this. Range (0, 1); typical 0.01.
    pub threshold: f32,
    /// Stop after this many shots whatever the unshot fraction. Typical 10 000.
    pub max_shots: u32,
    /// Item-buffer side in pixels. Range 16..=max texture size; typical 512.
    pub hemi_res: u32,
    /// Longest triangle edge drawn by the visibility pass, in patch sizes; 0 draws the polygons
    /// whole, as the paper does. Typical 2.
    pub tessellation: f32,
    /// Side, in patches, of the cells a polygon shoots from; 0 shoots the whole polygon from its
    /// centroid, as the paper does. Typical 8.
    pub shooter_cell: u32,
    /// The same for emitters, whose first shot is the direct light (the sharpest shadows):
    /// smaller cells there cost a few passes and fix partly shadowed receivers. Typical 1.
    pub emitter_cell: u32,
    pub form_factor: FormFactorKind,
    pub visibility: VisibilityKind,
    /// Robust visibility: a receiver is visible when its pixel holds its ID, or when the
    /// polygon its pixel shows does not lie between it and the shooter (the two are on the same
    /// side of that polygon's plane). The paper tests the nearest pixel's ID only, which misses
    /// receivers smaller than a pixel and darkens joints where polygons meet.
    pub robust_visibility: bool,
    /// Speed switches for llvmpipe that leave the answer as it is (`tuning.rs`); the paper's mode
    /// turns them all off, so that its passes are the paper's.
    pub tuning: Tuning,
    /// Beyond the paper, for fewer shots: each shooter also shoots the ambient light it will
    /// still receive, and is left with that much negative unshot energy (`overshoot.rs`).
    pub overshoot: bool,
    /// Beyond the paper, for cheaper shots: a shot that carries less than `small_shot` of the
    /// emitted power draws its item buffer at `small_hemi_res` per side instead of `hemi_res`
    /// (0: every shot at `hemi_res`). Such shots carry little of the light, and the item
    /// buffer's sampling errors of many small shots average out.
    pub small_hemi_res: u32,
    /// See `small_hemi_res`: a share of the emitted power, 0 to 1.
    pub small_shot: f32,
    /// Beyond the paper, for cheaper shots: with `small_hemi_res`, the small shots' side falls
    /// further with the cube root of their share of the emitted power, down to this (0: every
    /// small shot at `small_hemi_res`; see [`item_buffer_side`]).
    pub min_hemi_res: u32,
    /// Beyond the paper, for accuracy: each shot turns its item buffer about the shooter's
    /// normal by its own angle ([`turn_of_shot`]), so that the pixel grids of successive shots do
    /// not line up with the scene's edges, nor with one another: their aliasing averages out
    /// instead of adding up. The paper (and every shot with this off) orients the item buffer by
    /// the normal alone.
    pub rotate_item_buffer: bool,
    /// Beyond the paper, for cheaper shots: how many shooters one reconstruction pass serves.
    /// Each step of the loop then takes the polygons with the most unshot power, up to
    /// `shooters_per_pass` of them as long as all their shooters fit in one pass; each shooter
    /// draws its own item buffer, and one reconstruction pass adds what all of them send. They
    /// shoot simultaneously: each shoots the unshot energy it had when the step began, and keeps
    /// what the others send it this pass as unshot energy. A polygon with more cells than that
    /// shoots alone, its cells `shooters_per_pass` to a pass (they send each other nothing).
    /// 1: one shooter per pass, as the paper.
    pub shooters_per_pass: u32,
}

impl SolveOptions {
    /// The paper, literally: the whole polygon shoots from its centroid with the point form
    /// factor, whole polygons drawn through the hemispherical projection, nearest-pixel IDs.
    pub fn paper() -> Self {
        SolveOptions {
            threshold: 0.01,
            max_shots: 10_000,
            hemi_res: 512,
            tessellation: 0.0,
            shooter_cell: 0,
            emitter_cell: 0,
            form_factor: FormFactorKind::Point,
            visibility: VisibilityKind::Hemisphere,
            robust_visibility: false,
            tuning: Tuning::none(),
            overshoot: false,
            small_hemi_res: 0,
            small_shot: 0.0,
            min_hemi_res: 0,
            rotate_item_buffer: false,
            shooters_per_pass: 1,
        }
    }

    /// Beyond the paper (see paper_notes.md): cells of 4x4 patches shoot (cut finer where a
    /// nearby polygon's plane crosses them), with the polygon form factor; a 256² hemicube (exact
    /// for straight edges, so nothing to tessellate) with the robust visibility test.
    pub fn accurate() -> Self {
        SolveOptions {
            hemi_res: 256,
            tessellation: 0.0,
            shooter_cell: 4,
            emitter_cell: 1,
            form_factor: FormFactorKind::Polygon,
            visibility: VisibilityKind::Hemicube,
            robust_visibility: true,
            tuning: Tuning::llvmpipe(),
            ..Self::paper()
        }
    }
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self::accurate()
    }
}

/// The item buffer's side for a shot that carries `share` of the emitted power (by magnitude:
/// an overshot shooter's negative energy too): `hemi_res`, or `small_hemi_res` below
/// `small_shot`; with `min_hemi_res`, below `small_shot` the side falls with the cube root of
/// the share, to `min_hemi_res` at the least. Why the cube root: a shot's aliasing error grows
/// with its power over its side, its cost with the side squared, and Σ error + λ Σ cost is
/// least where side³ ∝ power.
pub fn item_buffer_side(options: &SolveOptions, share: f64) -> u32 {
    let o = options;
    let small = share.abs() < o.small_shot as f64;
    if o.small_hemi_res == 0 || !small {
        o.hemi_res
    } else if o.min_hemi_res == 0 {
        o.small_hemi_res
    } else {
        let side = o.small_hemi_res as f64 * (share.abs() / o.small_shot as f64).cbrt();
        (side.round() as u32).clamp(o.min_hemi_res, o.small_hemi_res)
    }
}

/// The item buffer's turn for shot `shot` (0-based) when `SolveOptions::rotate_item_buffer` is
/// on: the golden-ratio sequence of angles, which spreads any run of successive shots evenly
/// around the circle, the same in every run (so that solves stay reproducible).
pub fn turn_of_shot(shot: u32) -> f32 {
    const GOLDEN: f64 = 0.618_033_988_749_894_8;
    ((shot as f64 * GOLDEN).fract() * std::f64::consts::TAU) as f32
}

/// Most corners a shooter's outline may have (a cell clipped to its polygon, or a whole polygon);
/// a shooter with more uses its bounding rectangle instead.
pub const MAX_CORNERS: usize = 12;

/// A shooter: a polygon, or one cell of its lightmap, shooting its unshot energy from one point
/// (the paper: the whole polygon from its centre).
#[derive(Clone, Copy, Debug)]
pub struct Shooter {
    pub polygon: usize,
    /// The atlas texels whose unshot energy this shot carries (and clears): [x0, y0, x1, y1).
    pub texels: [u32; 4],
    pub position: Vec3,
    pub normal: Vec3,
    /// Unshot radiance times area, RGB (what the shader calls ShootEnergy).
    pub energy: Vec3,
    /// The shooter's outline (counter-clockwise seen from its front), for the polygon form
    /// factor: `corners[..corner_count]`.
    pub corners: [Vec3; MAX_CORNERS],
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
}

impl Shooter {
    /// World -> shooter eye space: eye at the shooter, looking down -z along its normal.
    pub fn view(&self) -> Mat4 {
        let up = glam::Quat::from_axis_angle(self.normal, self.turn)
            * self.normal.any_orthonormal_vector();
        Mat4::look_at_rh(self.position, self.position + self.normal, up)
    }

    /// Power it shoots, π·L·A, averaged over RGB (negative for negative unshot energy).
    pub fn power(&self) -> f64 {
        std::f64::consts::PI * (self.energy.x as f64 + self.energy.y as f64 + self.energy.z as f64)
            / 3.0
    }
}

/// One shot, as reported in `stats.json`'s history.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ShotRecord {
    pub shot: u32,
    pub shooter: usize,
    /// Seconds since the solve started, at the end of this shot.
    pub seconds: f64,
    /// Unshot power / emitted power after this shot.
    pub unshot_fraction: f64,
    /// Power the shooter shot (π·ΔL·A, RGB mean).
    pub shot_power: f64,
    /// Power the receivers reflect from it (added to their unshot energy).
    pub reflected_power: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shooter(turn: f32) -> Shooter {
        Shooter {
            polygon: 0,
            texels: [0; 4],
            position: Vec3::new(1.0, 2.0, 3.0),
            normal: Vec3::new(0.0, 1.0, 0.0),
            energy: Vec3::ONE,
            corners: [Vec3::ZERO; MAX_CORNERS],
            corner_count: 0,
            area: 1.0,
            remainder: Vec3::ZERO,
            hemi_res: 64,
            turn,
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

    #[test]
    fn successive_shots_turn_by_well_spread_angles_the_same_every_run() {
        assert_eq!(turn_of_shot(0), 0.0);
        assert_eq!(turn_of_shot(17), turn_of_shot(17));
        // Any 10 successive shots leave no gap wider than about 2.4 × the even spacing.
        for start in [0, 100, 5000] {
            let mut angles: Vec<f32> = (start..start + 10).map(turn_of_shot).collect();
            angles.sort_by(f32::total_cmp);
            angles.push(angles[0] + std::f32::consts::TAU);
            let widest = angles.windows(2).map(|w| w[1] - w[0]).fold(0.0, f32::max);
            assert!(widest < 2.4 * std::f32::consts::TAU / 10.0, "{widest}");
            assert!(angles
                .iter()
                .all(|a| (0.0..=2.0 * std::f32::consts::TAU).contains(a)));
        }
    }

    #[test]
    fn the_smallest_shots_get_sides_in_proportion_to_the_cube_root_of_their_power() {
        let o = SolveOptions {
            hemi_res: 256,
            small_hemi_res: 128,
            small_shot: 0.01,
            min_hemi_res: 16,
            ..SolveOptions::accurate()
        };
        // At and above the small shots' share: the full side.
        assert_eq!(item_buffer_side(&o, 0.01), 256);
        assert_eq!(item_buffer_side(&o, -0.5), 256);
        // Just below: the small shots' side; an eighth of the share, half of it; by magnitude.
        assert_eq!(item_buffer_side(&o, 0.009_999), 128);
        assert_eq!(item_buffer_side(&o, 0.01 / 8.0), 64);
        assert_eq!(item_buffer_side(&o, -0.01 / 64.0), 32);
        // Never below the least, nor for a shot of nothing.
        assert_eq!(item_buffer_side(&o, 1e-9), 16);
        assert_eq!(item_buffer_side(&o, 0.0), 16);
        // Falling with the share all the way.
        let sides: Vec<u32> = (0..60)
            .map(|k| item_buffer_side(&o, 0.0099 * 0.9f64.powi(k)))
            .collect();
        assert!(sides.windows(2).all(|w| w[1] <= w[0]), "{sides:?}");
        // Without `min_hemi_res`, two sides only (the option as it was).
        let two = SolveOptions {
            min_hemi_res: 0,
            ..o.clone()
        };
        assert_eq!(item_buffer_side(&two, 1e-9), 128);
        assert_eq!(item_buffer_side(&two, 0.02), 256);
        // Without `small_hemi_res`, one.
        let one = SolveOptions {
            small_hemi_res: 0,
            ..o
        };
        assert_eq!(item_buffer_side(&one, 1e-9), 256);
    }
}
