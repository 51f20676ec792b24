//! Overshooting (beyond the paper: Feda & Purgathofer 1992, in the form Gortler, Cohen &
//! Slusallek 1994 analyse as over-relaxation). A polygon that shoots will later receive light
//! back from the rest of the scene and have to shoot again; the big walls of a room do so dozens
//! of times. Overshooting sends that future light ahead with the shot: the shooter shoots its
//! unshot radiance plus ρ·L_amb, ρ its reflectance and L_amb the ambient estimate of the radiance
//! still to arrive, and its patches are left with −ρ·L_amb unshot radiance instead of zero. When the light does arrive it
//! cancels the negative remainder; where the estimate was too high the negative unshot energy is
//! shot like any other (Find_Max_Energy and the stopping rule count it by its magnitude). The
//! solution the loop converges to is the same; it gets there in fewer shots.
//!
//! The ambient estimate is the one of Cohen, Chen, Wallace & Greenberg (1988): the area-weighted
//! mean unshot radiance of the other polygons, times the interreflection factor 1 / (1 − ρ̄) of
//! the scene's mean reflectance ρ̄ (per colour channel).
//!
//! What a polygon is predicted to shoot later, ρ_p · A_p / ΣA / (1 − ρ̄) times what the others
//! hold, is never more than half of what they hold (`MAX_SHARE`). At a share of 1 or more (white
//! walls, each a fifth of an open box's area) every polygon can hold a remainder that the others'
//! remainders account for while the unshot power by magnitude is anything: positive walls wait for
//! negative light, negative ones for positive light, and none is picked, as its shot would move
//! nothing. The archive's white Cornell box settled there and climbed, shot by shot of 0.2 %, to
//! twice the emitted power (shot 111). Below 1 the only such state is the solution, so the
//! negative remainders are picked and shot back like any other unshot energy.

use super::find_max_energy::EnergyTotals;
use crate::scene::Scene;
use glam::{DVec3, Vec3};

/// The largest mean reflectance the ambient estimate uses (see `Overshoot::new`).
const MAX_MEAN_REFLECTANCE: f64 = 0.8;

/// The largest share of the others' unshot energy a polygon's remainder may predict it will
/// shoot (see the module's text). In rooms of ordinary reflectance no polygon comes near it (the
/// Cornell box's floor: 0.3), so their shots are unchanged.
const MAX_SHARE: f64 = 0.5;

/// What the ambient estimate needs of the scene, computed once per solve.
#[derive(Clone, Debug)]
pub struct Overshoot {
    /// Each polygon's reflectance (its material's Kd).
    reflectance: Vec<Vec3>,
    /// 1 / (1 − ρ̄) per channel, ρ̄ the area-weighted mean reflectance.
    interreflection: DVec3,
    /// Each polygon's area if it has patches (what its patches' areas add up to), else 0.
    areas: Vec<f64>,
    /// Their sum.
    area: f64,
}

impl Overshoot {
    /// `patches[p]`: polygon p's patch count (polygons without patches receive nothing and are
    /// left out of the mean).
    pub fn new(scene: &Scene, patches: &[u32]) -> Overshoot {
        let reflectance: Vec<Vec3> = scene
            .polygons
            .iter()
            .map(|p| scene.material(p).kd)
            .collect();
        let areas: Vec<f64> = (scene.polygons.iter().zip(patches))
            .map(|(polygon, &n)| if n > 0 { polygon.area as f64 } else { 0.0 })
            .collect();
        let area: f64 = areas.iter().sum();
        let weighted = (reflectance.iter().zip(&areas))
            .fold(DVec3::ZERO, |w, (rho, &a)| w + rho.as_dvec3() * a);
        let mean = if area > 0.0 {
            weighted / area
        } else {
            DVec3::ZERO
        };
        // The estimate assumes a closed room; in an open one (a Cornell box without its front,
        // a courtyard) less comes back. With white walls (Kd 1, as a published Cornell box has)
        // 1 / (1 − ρ̄) is 20 or more and each shot's overshoot swings far past the answer: the
        // unshot power by magnitude grew past twice the emitted power. At most 5 (ρ̄ ≤ 0.8) keeps
        // every scene's swings bounded and does not change rooms of ordinary reflectance.
        let interreflection = (DVec3::ONE - mean.min(DVec3::splat(MAX_MEAN_REFLECTANCE))).recip();
        Overshoot {
            reflectance,
            interreflection,
            areas,
            area,
        }
    }

    /// The unshot radiance polygon `p`'s shooting patches are left with: minus its reflectance
    /// times the ambient radiance the others' unshot energy (`totals`) will still bring.
    pub fn remainder(&self, totals: &EnergyTotals, p: usize) -> Vec3 {
        self.remainder_with(sum(totals), totals, p).as_vec3()
    }

    /// [`remainder`](Self::remainder), given the sum of every polygon's unshot energy.
    fn remainder_with(&self, all: DVec3, totals: &EnergyTotals, p: usize) -> DVec3 {
        if self.area <= 0.0 {
            return DVec3::ZERO;
        }
        let others = all - DVec3::from_array(totals.energy[p]);
        -(self.gain(p) * others / self.area)
    }

    /// ρ_p / (1 − ρ̄) per channel, at most [`MAX_SHARE`] ΣA / A_p: polygon `p`'s remainder is
    /// minus this times the others' mean unshot radiance.
    fn gain(&self, p: usize) -> DVec3 {
        let gain = self.reflectance[p].as_dvec3() * self.interreflection;
        if self.areas[p] > 0.0 {
            gain.min(DVec3::splat(MAX_SHARE * self.area / self.areas[p]))
        } else {
            gain
        }
    }

    /// Find_Max_Energy when overshooting: the polygon whose shot would carry the most power,
    /// |unshot − remainder × area| (π·Σ|·| over RGB, averaged), above zero. Not the most unshot
    /// power: a polygon left with its remainder would shoot nothing, and be picked again and
    /// again. Ties go to the lower ID. The `count` such polygons, most first (one in the paper's
    /// loop). A polygon that has received nothing yet is not picked: its shot would be all
    /// prediction (a floor under a small lamp would shoot the ambient light before the lamp lit
    /// it, and a solve could start with more unshot power than the emitters give).
    pub fn max_shot_polygons(&self, totals: &EnergyTotals, count: usize) -> Vec<usize> {
        let all = sum(totals);
        let power = |p: usize| {
            let e = DVec3::from_array(totals.energy[p]);
            if e == DVec3::ZERO {
                return 0.0;
            }
            // The remainder over the patches a shot would clear (not those that have never
            // received: they do not shoot, and counting them kept a half-buried polygon of Lost
            // Empire first in line for 8,000 shots that carried nothing).
            let patches = totals.patches[p];
            let lit = if patches > 0 {
                self.areas[p] * totals.lit[p] as f64 / patches as f64
            } else {
                0.0
            };
            let shot = e - self.remainder_with(all, totals, p) * lit;
            std::f64::consts::PI * shot.abs().element_sum() / 3.0
        };
        super::find_max_energy::largest(totals.energy.len(), count, 0.0, power)
    }
}

/// Every polygon's unshot energy, summed per channel.
fn sum(totals: &EnergyTotals) -> DVec3 {
    (totals.energy.iter()).fold(DVec3::ZERO, |s, e| s + DVec3::from_array(*e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cornell() -> Scene {
        crate::scene::bundled::find("cornell")
            .unwrap()
            .load()
            .unwrap()
    }

    /// No unshot energy anywhere yet, `patches` per polygon.
    fn no_energy(n: usize, patches: u32) -> EnergyTotals {
        EnergyTotals {
            energy: vec![[0.0; 3]; n],
            patches: vec![patches; n],
            lit: vec![patches; n],
        }
    }

    #[test]
    fn the_remainder_is_minus_reflectance_times_the_others_ambient() {
        let scene = cornell();
        let n = scene.polygons.len();
        let overshoot = Overshoot::new(&scene, &vec![1; n]);
        let mut totals = no_energy(n, 1);
        // Only polygon 0 has unshot energy: it overshoots nothing of its own.
        totals.energy[0] = [2.0, 2.0, 2.0];
        assert_eq!(overshoot.remainder(&totals, 0), Vec3::ZERO);
        let r = overshoot.remainder(&totals, 1);
        let rho = scene.material(&scene.polygons[1]).kd;
        // No polygon of the Cornell box comes near the cap.
        for (p, polygon) in scene.polygons.iter().enumerate() {
            let uncapped = scene.material(polygon).kd.as_dvec3() * overshoot.interreflection;
            assert_eq!(overshoot.gain(p), uncapped, "polygon {p}");
        }
        let area: f64 = scene.polygons.iter().map(|p| p.area as f64).sum();
        for c in 0..3 {
            let expected = -(rho[c] as f64) * overshoot.interreflection[c] * 2.0 / area;
            assert!(
                (r[c] as f64 - expected).abs() < 1e-6 * expected.abs(),
                "{r} {expected}"
            );
            assert!(overshoot.interreflection[c] > 1.0);
        }
    }

    /// The archive's white Cornell box (five walls of Kd 1 and about equal area, interreflection
    /// 5): uncapped, each wall would be predicted to shoot all that the others hold, and walls
    /// holding +1, +1, −1, −1 and 0 would each sit at their remainder, shooting nothing, forever.
    /// Capped at half, each shoots half of what it holds back, the negative ones included.
    #[test]
    fn negative_remainders_are_shot_back_where_the_prediction_would_hold_them() {
        let n = 5;
        let white = Overshoot {
            reflectance: vec![Vec3::ONE; n],
            interreflection: DVec3::splat(5.0),
            areas: vec![1.0; n],
            area: n as f64,
        };
        let mut totals = no_energy(n, 1);
        for (p, e) in [1.0, 1.0, -1.0, -1.0].into_iter().enumerate() {
            totals.energy[p] = [e; 3];
        }
        for p in 0..4 {
            // Half of what the polygon holds stays as its remainder; the other half is shot.
            let r = white.remainder(&totals, p);
            assert!((r - Vec3::splat(0.5 * totals.energy[p][0] as f32)).length() < 1e-6);
        }
        assert_eq!(white.max_shot_polygons(&totals, n), vec![0, 1, 2, 3]);
    }

    /// White walls (Kd 1, as a published Cornell box has) would make the closed-room estimate
    /// infinite; it stays at most 1 / (1 − 0.8).
    #[test]
    fn the_ambient_estimate_stays_bounded_with_white_walls() {
        let mut scene = cornell();
        for m in &mut scene.materials {
            m.kd = Vec3::ONE;
        }
        let overshoot = Overshoot::new(&scene, &vec![1; scene.polygons.len()]);
        assert!(
            (overshoot.interreflection - DVec3::splat(5.0))
                .abs()
                .max_element()
                < 1e-9,
            "{}",
            overshoot.interreflection
        );
    }

    /// Before the light has shot, only the light may: a polygon that has received nothing would
    /// shoot predicted ambient light alone (a floor far larger than its lamp would go first).
    #[test]
    fn a_polygon_that_received_nothing_is_not_picked() {
        let scene = cornell();
        let n = scene.polygons.len();
        // Every polygon's area huge next to the light's patch: its prediction outweighs the light.
        let overshoot = Overshoot::new(&scene, &vec![1; n]);
        let mut totals = no_energy(n, 1_000);
        let light = scene
            .polygons
            .iter()
            .position(|p| scene.material(p).is_emitter())
            .unwrap();
        totals.energy[light] = [1e-3; 3];
        let big = Overshoot {
            areas: vec![1e6; n],
            ..overshoot
        };
        assert_eq!(big.max_shot_polygons(&totals, n), vec![light]);
        // Once a wall has received, it competes by its shot (unshot plus predicted ambient).
        let wall = (light + 1) % n;
        totals.energy[wall] = [1e-6; 3];
        assert_eq!(big.max_shot_polygons(&totals, n).len(), 2);
    }

    /// A polygon whose lit patches hold exactly their remainder has nothing to shoot, however
    /// many of its patches have never received (they shoot nothing): it is not picked. Before,
    /// its whole area counted, and Lost Empire's half-buried grass was picked for 8,000 shots.
    #[test]
    fn patches_that_never_received_add_no_remainder_to_shoot() {
        let scene = cornell();
        let n = scene.polygons.len();
        let overshoot = Overshoot::new(&scene, &vec![4; n]);
        let mut totals = no_energy(n, 4);
        let (a, b) = (1, 2);
        totals.energy[a] = [1.0; 3];
        // b: 1 of its 4 patches lit, holding the remainder; the other 3 at zero.
        totals.lit[b] = 1;
        let remainder = overshoot.remainder_with(sum(&totals), &totals, b);
        totals.energy[b] = (remainder * overshoot.areas[b] / 4.0).to_array();
        // The remainder depends on the others' energy, b's own excluded: unchanged by b's.
        assert_eq!(
            overshoot.remainder_with(sum(&totals), &totals, b),
            remainder
        );
        assert!(remainder.length() > 0.0);
        assert_eq!(overshoot.max_shot_polygons(&totals, n), vec![a]);
        // Counting all 4 patches, b would shoot 3/4 of its area's remainder, again and again.
        totals.lit[b] = 4;
        assert_eq!(overshoot.max_shot_polygons(&totals, n).len(), 2);
    }
}
