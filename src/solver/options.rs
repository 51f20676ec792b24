//! The solver's settings: the paper's, the accurate mode's (the default), and the configurations
//! the benches compare; and the rules that pick a shot's item-buffer side and turn. The checks
//! both backends share are [`SolveOptions::check`].

use super::{SolveError, Tuning};

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
    /// The form factor of the reconstruction pass.
    pub form_factor: FormFactorKind,
    /// How the visibility pass sees the scene from the shooter.
    pub visibility: VisibilityKind,
    /// Robust visibility: a receiver is visible when its pixel holds its ID, or when the
    /// polygon its pixel shows does not lie between it and the shooter (the two are on the same
    /// side of that polygon's plane). The paper tests the nearest pixel's ID only, which misses
    /// receivers smaller than a pixel and darkens joints where polygons meet.
    pub robust_visibility: bool,
    /// Speed switches for llvmpipe that leave the answer as it is (`tuning.rs`); the paper's mode
    /// turns them all off, so that its passes are the paper's.
    /// (In stats.json `tuning_switches`: `tuning` names the profile.)
    #[serde(rename = "tuning_switches")]
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
    /// small shot at `small_hemi_res`; see [`item_buffer_side`](super::item_buffer_side)).
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
    /// Beyond the paper, so that no shot creates energy: a shot whose receivers got more than it
    /// carried (their gains over their reflectance, channel by channel; `ShotBalance`) is scaled
    /// back to what it carried by a second reconstruction pass. Gathering samples the form factor
    /// at patch centres, and a patch whose centre sees the shooter while most of its area does
    /// not would otherwise receive for all of it. Off in the paper's mode.
    pub conserve: bool,
    /// Beyond the paper, for fewer passes: only shots carrying at least this share of the
    /// emitted power cut their cells where a touching polygon's plane crosses them
    /// (`shooters::cuts_cells`). 0: every shot.
    pub cut_above: f32,
    /// Beyond the paper, for fewer passes: the side, in patches, of the cells of shots that
    /// carry less than `cut_above` (0, or no larger than the cell side: the same cells as every
    /// shot). Most of a large scene's passes are late shots of its largest polygons, each a
    /// fraction of a percent of the light; wider cells shoot them in a fraction of the passes.
    pub coarse_cell: u32,
    /// Beyond the paper, for fewer shots on scenes of many small polygons: small touching
    /// coplanar polygons shoot together, as one shooter, within squares of `shooter_cell`
    /// patches on their plane in any shot, and of `cluster_cell` × `cluster_cell` patches once
    /// their summed unshot power is below `cut_above` (`clusters.rs`; only in scenes whose
    /// polygons average at most `clusters::AVERAGE_PATCHES` patches). 0: every polygon shoots
    /// alone.
    pub cluster_cell: u32,
    /// Beyond the paper, for large shooters in scenes of many triangles: a polygon's shot has
    /// at most this many triangles over the scene's triangle count cells (at least
    /// `shooters::MIN_CELLS_PER_SHOT`), wider cells where its own would be more
    /// (`shooters::widened_cell`): each cell is a visibility pass of the whole scene; and the
    /// cuts where a touching polygon's plane crosses a cell add at most as many parts again
    /// (`shooters::cell_parts`); shots below `cut_above` have fewer cells in proportion to what
    /// they carry, at least `MIN_CELLS_PER_SHOT` (`shooters::shot_cap`). 0: no limit.
    pub shot_triangles: u64,
    /// Beyond the paper, for fewer shots on curved surfaces of many small faces: a small
    /// polygon shoots with the largest cluster of touching non-coplanar neighbours around it
    /// (normals within [`FACE_CONE_DEGREES`], bounds within `cluster_cell` patches) whose
    /// misdirected power stays within `cut_above` of the emitted power and whose shooting point
    /// sees little of other polygons close in front (`face_clusters.rs`, `cluster_near.rs`).
    /// Needs `shooter_cell`, `cluster_cell` and `cut_above` (so never in the paper's mode), and
    /// only in scenes whose polygons average at most `clusters::AVERAGE_PATCHES` patches.
    pub face_clusters: bool,
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
            conserve: false,
            cut_above: 0.0,
            coarse_cell: 0,
            cluster_cell: 0,
            shot_triangles: 0,
            face_clusters: false,
        }
    }

    /// The default, beyond the paper (see paper_notes.md), fast and right on any scene:
    ///
    /// - what the paper's shots miss: cells of 4×4 patches shoot (emitters patch by patch), cut
    ///   where a touching polygon's plane crosses them in the shots that carry at least
    ///   [`CUT_ABOVE`] of the emitted power; the polygon form factor; a 256² hemicube (exact for
    ///   straight edges) with the robust visibility test; no shot delivering more than it carried
    ///   (`conserve`);
    /// - fewer and cheaper shots: overshooting, the item buffer by shot (256² for the shots
    ///   carrying over [`SMALL_SHOT`], falling with the cube root of the share from 128² to 16²)
    ///   and turned shot by shot, [`MAX_SHOOTERS_PER_PASS`] shooters per reconstruction pass,
    ///   and the smaller shots from cells of [`COARSE_CELL`] patches (cut down to 4×4 at contacts);
    ///   in scenes of many small polygons, small touching coplanar neighbours shoot together,
    ///   within squares of the cell (4 patches), and of [`CLUSTER_CELL`] in small shots
    ///   (`clusters.rs`);
    /// - the stopping rule at [`DEFAULT_THRESHOLD`], where every region of the Cornell box lands
    ///   within 3 % of a path-traced reference (`tests/path_traced.rs`).
    pub fn accurate() -> Self {
        SolveOptions {
            threshold: DEFAULT_THRESHOLD,
            hemi_res: 256,
            tessellation: 0.0,
            shooter_cell: 4,
            emitter_cell: 1,
            form_factor: FormFactorKind::Polygon,
            visibility: VisibilityKind::Hemicube,
            robust_visibility: true,
            tuning: Tuning::llvmpipe(),
            overshoot: true,
            small_hemi_res: 128,
            small_shot: SMALL_SHOT,
            min_hemi_res: 16,
            rotate_item_buffer: true,
            shooters_per_pass: MAX_SHOOTERS_PER_PASS,
            conserve: true,
            cut_above: CUT_ABOVE,
            coarse_cell: COARSE_CELL,
            cluster_cell: CLUSTER_CELL,
            shot_triangles: SHOT_TRIANGLES,
            face_clusters: true,
            ..Self::paper()
        }
    }

    /// The accurate mode's corrections without its speed options: one shooter per pass, every
    /// shot at `hemi_res`, no overshooting, no turning, every shot's cells cut (the default as it
    /// was before the speed options joined it; the references of the accuracy tests).
    pub fn accurate_alone() -> Self {
        SolveOptions {
            overshoot: false,
            small_hemi_res: 0,
            small_shot: 0.0,
            min_hemi_res: 0,
            rotate_item_buffer: false,
            shooters_per_pass: 1,
            cut_above: 0.0,
            coarse_cell: 0,
            cluster_cell: 0,
            ..Self::accurate()
        }
    }

    /// Table 1's paper-faithful configuration: the paper's loop, one pass per shot with each
    /// polygon shooting whole from its centroid, but with the polygon form factor, a
    /// [`BENCH_HEMI_RES`]² hemicube with the robust test (the paper's point factor creates
    /// energy between close polygons and never converges on the rooms). No `conserve`: the paper
    /// has no scale-back pass, and it cost the row a fifth more passes (perf-log, 2026-12-07);
    /// a shot that over-delivers is reported once, as in the paper's mode. The
    /// hemicube's side was chosen by measurement on the simple room: against the CPU solver's
    /// exact ray casts the mean patch difference is 3.3 % at 64², 1.5 % at 128², 1.1 % at 192²
    /// and at 256², while the visibility pass costs about twice as much at 256² as at 128².
    pub fn paper_faithful(threshold: f32) -> Self {
        SolveOptions {
            threshold,
            max_shots: 1_000_000,
            hemi_res: BENCH_HEMI_RES,
            shooter_cell: 0,
            emitter_cell: 0,
            conserve: false,
            ..Self::accurate_alone()
        }
    }

    /// Whole polygons with every speed option (Table 1's fast row before the default took the
    /// speed options): right only where every polygon is small next to the patch size, as in the
    /// Table 1 rooms; on the Cornell box the short block's front stays black, since every whole
    /// shooter's centroid lies behind its plane.
    pub fn whole_polygons(threshold: f32) -> Self {
        SolveOptions {
            threshold,
            max_shots: 1_000_000,
            shooter_cell: 0,
            emitter_cell: 0,
            ..Self::accurate()
        }
    }

    /// The default with another stopping rule and no shot limit (the benches).
    pub fn default_with(threshold: f32) -> Self {
        SolveOptions {
            threshold,
            max_shots: 1_000_000,
            ..Self::accurate()
        }
    }

    /// Check the settings both backends need; `max_side` is the largest texture side of the
    /// GPU's driver (`None` on the CPU, which draws no item buffer).
    pub fn check(&self, max_side: Option<i32>) -> Result<(), SolveError> {
        if let Some(max) = max_side {
            // The hemicube's item buffer is five faces wide.
            let faces = super::visibility::item_buffer_size(self.visibility, 1).0 as i32;
            if self.hemi_res < 16 || self.hemi_res as i64 > (max / faces) as i64 {
                return Err(SolveError::HemiRes {
                    res: self.hemi_res,
                    max: max / faces,
                });
            }
        } else if self.hemi_res < 16 {
            return Err(SolveError::HemiRes {
                res: self.hemi_res,
                max: i32::MAX,
            });
        }
        let small = self.small_hemi_res;
        if small != 0 && !(16..=self.hemi_res).contains(&small) {
            return Err(SolveError::SmallHemiRes {
                small,
                full: self.hemi_res,
            });
        }
        let min = self.min_hemi_res;
        if min != 0 && (small == 0 || !(16..=small).contains(&min)) {
            return Err(SolveError::MinHemiRes { min, small });
        }
        let k = self.shooters_per_pass;
        if !(1..=MAX_SHOOTERS_PER_PASS).contains(&k) {
            return Err(SolveError::ShootersPerPass(k));
        }
        self.tuning.check().map_err(SolveError::Tuning)?;
        if !(self.tessellation >= 0.0 && self.tessellation.is_finite()) {
            return Err(SolveError::Tessellation(self.tessellation));
        }
        Ok(())
    }
}

/// The default stopping rule (unshot power / emitted power) of the accurate mode: the default
/// command on the Cornell box lands within 3 % of a path-traced reference in every region there
/// (1.8 % measured; at 0.01 the worst region was 2.9 %, too close to call).
pub const DEFAULT_THRESHOLD: f32 = 0.003;

/// The shot limit of `radiosity solve` when `--max-shots` is not given: the modes' 10,000, or one
/// per polygon on scenes of more polygons (at most 1,000,000). A scene of many small polygons
/// needs a shot for every few polygons: Lost Empire (48,596 polygons) reaches 1 % unshot at shot
/// 14,937 (33,875 while shots created energy, stopping at the 10,000 limit with 5.4 % left).
pub fn default_max_shots(polygons: usize) -> u32 {
    (polygons.min(1_000_000) as u32).max(SolveOptions::paper().max_shots)
}

/// The share of the emitted power from which a shot cuts its cells along touching polygons'
/// planes (`SolveOptions::cut_above`): on the Cornell box every region stays within 2 % of the
/// path-traced reference, and on the simple room a third of the passes of cutting every shot
/// are left (1,399 against 4,146).
pub const CUT_ABOVE: f32 = 0.003;

/// The cell side of shots below [`CUT_ABOVE`] (`SolveOptions::coarse_cell`): 16 patches, four
/// times the default cell's side, a sixteenth of its cells.
pub const COARSE_CELL: u32 = 16;

/// The side, in patches, of the squares in which small coplanar polygons shoot together
/// (`SolveOptions::cluster_cell`): half the coarse cells' side, so that a cluster's one shot
/// stands for at most 64 patches.
pub const CLUSTER_CELL: u32 = 8;

/// The triangles the visibility passes of one polygon's shot may draw together
/// (`SolveOptions::shot_triangles`): 50 million, 150 cells on the conference room's 331,179
/// triangles (a quarter of a second a pass there on llvmpipe), thousands on the Table 1 rooms,
/// whose shots it leaves as they were.
pub const SHOT_TRIANGLES: u64 = 50_000_000;

/// The widest cone (half-angle, degrees) of a face cluster's normals
/// (`SolveOptions::face_clusters`): at most sin 20° = 34 % of a cluster's power may leave in
/// other directions than its members' own, and the error bound allows a cluster's shot only
/// while that is within `cut_above` of the emitted power.
pub const FACE_CONE_DEGREES: f32 = 20.0;

/// The configurations `bench guard` compares: the paper-faithful one, each speed option alone
/// on it, whole polygons with all of them, and the default.
pub fn configurations(threshold: f32) -> Vec<(&'static str, SolveOptions)> {
    let base = SolveOptions::paper_faithful(threshold);
    let all = SolveOptions::accurate();
    vec![
        ("paper-faithful", base.clone()),
        (
            "overshoot",
            SolveOptions {
                overshoot: true,
                ..base.clone()
            },
        ),
        (
            "item buffer by shot",
            SolveOptions {
                hemi_res: all.hemi_res,
                small_hemi_res: all.small_hemi_res,
                small_shot: all.small_shot,
                min_hemi_res: all.min_hemi_res,
                ..base.clone()
            },
        ),
        (
            "item buffer turned",
            SolveOptions {
                rotate_item_buffer: true,
                ..base.clone()
            },
        ),
        (
            "shooters per pass",
            SolveOptions {
                shooters_per_pass: MAX_SHOOTERS_PER_PASS,
                ..base
            },
        ),
        ("whole polygons", SolveOptions::whole_polygons(threshold)),
        ("default", SolveOptions::default_with(threshold)),
    ]
}

/// Item-buffer side of [`SolveOptions::paper_faithful`].
pub const BENCH_HEMI_RES: u32 = 128;

impl Default for SolveOptions {
    fn default() -> Self {
        Self::accurate()
    }
}

/// The item buffer's turn for shot `shot` (0-based) when `SolveOptions::rotate_item_buffer` is
/// on: the golden-ratio sequence of angles, which spreads any run of successive shots evenly
/// around the circle, the same in every run (so that solves stay reproducible).
pub fn turn_of_shot(shot: u32) -> f32 {
    const GOLDEN: f64 = 0.618_033_988_749_894_8;
    ((shot as f64 * GOLDEN).fract() * std::f64::consts::TAU) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn the_default_shot_limit_is_one_per_polygon_past_ten_thousand() {
        assert_eq!(default_max_shots(0), 10_000);
        assert_eq!(default_max_shots(8_549), 10_000);
        assert_eq!(default_max_shots(48_596), 48_596);
        assert_eq!(default_max_shots(usize::MAX), 1_000_000);
    }
}
