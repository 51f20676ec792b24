//! The energy balance of one shot, per colour channel: what the shooters carried against what
//! their receivers received; and the error that names a refused shot's receivers
//! ([`energy_created`]).
//!
//! A receiver's unshot energy grows by ρ × what reaches it, so what reached it is its gain over
//! its reflectance, channel by channel. Summed over the receivers this is the power the shot
//! delivered, which can never exceed the power it carried: the gathered form factors of a shot
//! add up to at most 1 (reciprocity: Σ_j A_j F_j→s = A_s Σ_j F_s→j ≤ A_s). Point samples of the
//! factor can break that (a patch centre next to a contact, a whole polygon whose centroid sees a
//! receiver that most of the polygon does not, folded faces), and a shot that delivers more than
//! it carried creates energy.

use super::find_max_energy::EnergyTotals;
use super::{Shooter, ShotRecord, SolveError};
use crate::scene::Scene;
use glam::DVec3;

/// One shot's books, in the units of [`EnergyTotals::energy`] (Σ L·A, RGB).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShotBalance {
    /// What the shooters carried, each channel by magnitude (an overshot shooter's negative
    /// energy is shot too).
    pub carried: DVec3,
    /// What reached the receivers (their gains over their reflectance), signed.
    pub received: DVec3,
    /// The float noise of the whole atlas's sums, per channel ([`EMITTED_NOISE`] of the emitted
    /// energy): a shot that carries next to nothing is judged within it.
    pub floor: f64,
}

impl ShotBalance {
    /// The books of a shot of `shooters` (energies in the units of `EnergyTotals::energy`), from
    /// each changed polygon's totals `before` the shot and `after` it. A shooter's own total
    /// fell by what it carried, so its gain is after − before + carried. `floor`: the absolute
    /// float noise per channel (see [`EMITTED_NOISE`]).
    pub fn measure(
        scene: &Scene,
        shooters: &[Shooter],
        before: &[(usize, [f64; 3])],
        after: &EnergyTotals,
        floor: f64,
    ) -> ShotBalance {
        let mut carried = DVec3::ZERO;
        for s in shooters {
            carried += s.energy.as_dvec3().abs();
        }
        let mut received = DVec3::ZERO;
        for &(p, old) in before {
            let mut gain = DVec3::from(after.energy[p]) - DVec3::from(old);
            for s in shooters.iter().filter(|s| s.polygon == p) {
                gain += s.energy.as_dvec3();
            }
            let kd = scene.material(&scene.polygons[p]).kd.as_dvec3();
            for c in 0..3 {
                // A black channel reflects nothing, so its gain says nothing of what arrived
                // (and it is exactly zero: ρ·F·E with ρ = 0).
                if kd[c] > 0.0 {
                    received[c] += gain[c] / kd[c];
                }
            }
        }
        ShotBalance {
            carried,
            received,
            floor,
        }
    }

    /// The largest ratio, over the channels that carried anything, of what was received to what
    /// was carried: at most 1 for a shot that creates no energy. What a channel received within
    /// the float noise of the shot's sums ([`NOISE`] of its fullest channel) counts as carried.
    pub fn excess(&self) -> f64 {
        (0..3)
            .filter(|&c| self.carried[c] > 0.0)
            .map(|c| self.over_noise(c) / self.carried[c])
            .fold(0.0, f64::max)
    }

    /// What channel `c` received, less the shot's float noise where it received more than it
    /// carried.
    fn over_noise(&self, c: usize) -> f64 {
        let r = self.received[c].abs();
        let slack = (NOISE * self.carried.max_element()).max(self.floor);
        if r > self.carried[c] {
            (r - slack).max(self.carried[c])
        } else {
            r
        }
    }

    /// Per channel, the factor that brings what was received down to what was carried (1 where
    /// it is within, float noise included).
    pub fn scale_to_carried(&self) -> DVec3 {
        DVec3::from_array(std::array::from_fn(|c| {
            let r = self.received[c].abs();
            if self.over_noise(c) > self.carried[c] && r > 0.0 {
                self.carried[c] / r
            } else {
                1.0
            }
        }))
    }

    /// The power that reached the receivers, π·Σ, RGB mean (as `ShotRecord` reports powers).
    pub fn received_power(&self) -> f64 {
        std::f64::consts::PI * self.received.element_sum() / 3.0
    }

    /// The power the shooters carried, by magnitude, π·Σ, RGB mean.
    pub fn carried_power(&self) -> f64 {
        std::f64::consts::PI * self.carried.element_sum() / 3.0
    }
}

/// The float noise of a shot's books, as a share of its fullest channel: the atlases hold f32
/// (7 significant digits), and a receiver's gain is the difference of two sums of them. A channel
/// that carried almost nothing (the blue of a dandelion, reflectance 0.008: 1.6e-6 of the shot)
/// can read 1.005x over on that noise alone (Lost Empire, shot 2,514: 5.73e-6 received against
/// 5.70e-6 carried, while red and green balanced to 1e-8).
pub const NOISE: f64 = 1e-6;

/// The float noise of the atlas's sums as a share of the emitted energy: a shot that carries
/// next to nothing (an overshooting polygon whose unshot energy is just its remainder) has books
/// of noise alone (`bench table1` on the complex room, shot 90: 1.8e-8 of power carried,
/// 1e-10 of the emitted, read 1.6x over). Within this floor a shot counts as balanced: 1e-7 of the
/// emitted energy per shot is far below anything a stopping rule can see.
pub const EMITTED_NOISE: f64 = 1e-7;

/// A shot delivering more than this times what it carried is scaled back
/// (`SolveOptions::conserve`): above the float noise of the atlas sums (a few 1e-6).
pub const CORRECT_ABOVE: f64 = 1.001;

/// The most a shot may deliver over what it carried before the solve calls it energy created:
/// 0.5 %, the tolerance; a scaled-back shot lands within float noise of 1.
pub const TOLERANCE: f64 = 1.005;

/// The shooters of the pass that scales a shot back to what it carried (`balance`): the same
/// shooters, from the same points, sending (factor − 1) times their energy, so that each
/// receiver ends with factor × what the shot gave it; they own no texels (their unshot energy was
/// already left at its remainder) and so clear nothing.
///
/// Why one factor for the whole shot: the books say how much too much arrived, not where. The
/// receivers that got too much are mostly patches whose centres see the shooter while most of
/// their area does not (a cabinet's front behind its doors, seen through the 6 mm gap between
/// them); a second gathering could not tell them apart either.
pub fn correction(shooters: &[Shooter], balance: &ShotBalance) -> Vec<Shooter> {
    let factor = balance.scale_to_carried().as_vec3();
    shooters
        .iter()
        .map(|s| Shooter {
            energy: s.energy * (factor - glam::Vec3::ONE),
            texels: [0; 4],
            remainder: glam::Vec3::ZERO,
            ..*s
        })
        .collect()
}

/// The error of a shot the solve refuses (`Solver::check_balance`): `record`'s shot, whose books
/// are `balance`, left the unshot power at `growth` times what the solve started from. It names
/// the five receivers that gained most, from their totals `before` the shot to those `after` it,
/// and the likely `cause`.
pub fn energy_created(
    scene: &Scene,
    record: &ShotRecord,
    balance: &ShotBalance,
    before: &[(usize, [f64; 3])],
    after: &EnergyTotals,
    growth: f64,
    cause: &'static str,
) -> SolveError {
    let mut gains: Vec<(f64, usize)> = before
        .iter()
        .filter(|&&(p, _)| p != record.shooter)
        .map(|&(p, old)| {
            let old = std::f64::consts::PI * (old[0] + old[1] + old[2]) / 3.0;
            (after.power(p) - old, p)
        })
        .filter(|&(g, _)| g > 0.0)
        .collect();
    gains.sort_by(|a, b| b.0.total_cmp(&a.0));
    let name = |p: usize| {
        format!(
            "polygon {p} of '{}'",
            crate::scene::shown(&scene.polygons[p].object)
        )
    };
    let receivers: Vec<String> = gains
        .iter()
        .take(5)
        .map(|&(g, p)| format!("{} (+{g:.3e})", name(p)))
        .collect();
    SolveError::EnergyCreated {
        cause,
        shot: record.shot,
        unshot: growth,
        shooter: name(record.shooter),
        shot_power: record.shot_power,
        received: record.received_power,
        excess: balance.excess(),
        receivers: receivers.join(", "),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A near-empty channel over by float noise is not energy created; over by more, it is.
    #[test]
    fn a_near_empty_channel_over_by_noise_is_within() {
        let noisy = ShotBalance {
            carried: DVec3::new(3.434346, 3.723375, 5.70285e-6),
            received: DVec3::new(3.434346, 3.723374, 5.73235e-6),
            floor: 0.0,
        };
        assert!(noisy.excess() <= 1.0 + 1e-6, "{}", noisy.excess());
        assert_eq!(noisy.scale_to_carried(), DVec3::ONE);
        let over = ShotBalance {
            carried: DVec3::new(3.4, 3.7, 5.7e-6),
            received: DVec3::new(3.4, 3.7, 2.0e-5),
            floor: 0.0,
        };
        assert!(over.excess() > TOLERANCE, "{}", over.excess());
        assert!(over.scale_to_carried().z < 1.0);
        // A full channel over by 1 % stays over.
        let full = ShotBalance {
            carried: DVec3::new(1.0, 1.0, 1.0),
            received: DVec3::new(1.01, 1.0, 1.0),
            floor: 0.0,
        };
        assert!((full.excess() - 1.01).abs() < 1e-5, "{}", full.excess());
        // A shot of noise alone (1.8e-8 carried, 1.6x over) is within the floor.
        let tiny = ShotBalance {
            carried: DVec3::splat(5.7e-9),
            received: DVec3::splat(9.2e-9),
            floor: EMITTED_NOISE * 59.0,
        };
        assert!(tiny.excess() <= 1.0, "{}", tiny.excess());
        let floored = ShotBalance {
            floor: EMITTED_NOISE * 59.0,
            ..full
        };
        assert!(floored.excess() > 1.009);
    }
}
