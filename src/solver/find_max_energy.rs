//! `Find_Max_Energy` (paper 3.2.2, step 5), on the CPU: total the unshot energy of each
//! polygon's lightmap and pick the polygon with the most unshot power as the next shooter; and
//! the books both backends keep around it ([`Ledger`]): those totals, the patch areas that turn
//! radiance into power, the emitted power the stopping rule compares against, the shot history
//! and the time spent in each named pass.
//!
//! Each shot's books are judged here too ([`ShotBalance`]): what the shooters carried against
//! what their receivers received, per colour channel; and the error that names a refused shot's
//! receivers ([`energy_created`]).
//!
//! A receiver's unshot energy grows by ρ × what reaches it, so what reached it is its gain over
//! its reflectance, channel by channel. Summed over the receivers this is the power the shot
//! delivered, which can never exceed the power it carried: the gathered form factors of a shot
//! add up to at most 1 (reciprocity: Σ_j A_j F_j→s = A_s Σ_j F_s→j ≤ A_s). Point samples of the
//! factor can break that (a patch centre next to a contact, a whole polygon whose centroid sees a
//! receiver that most of the polygon does not, folded faces), and a shot that delivers more than
//! it carried creates energy.
//!
//! The unshot atlas comes back from the GPU as RGBA floats: RGB is the unshot radiance of the
//! patch, alpha the polygon ID + 1 (0 where a texel is not a patch). Every patch of a polygon
//! has the same area (polygon area / patch count), so the totals are exact in power.

use super::{Shooter, ShotRecord, SolveError};
use crate::scene::Scene;
use glam::{DVec3, Vec3};
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

/// Unshot energy per polygon, summed from an unshot atlas.
#[derive(Clone, Debug, Default)]
pub struct EnergyTotals {
    /// Per polygon: Σ unshot radiance × patch area, RGB (f64 so long sums stay exact enough).
    pub energy: Vec<[f64; 3]>,
    /// Per polygon: patches seen in the atlas.
    pub patches: Vec<u32>,
    /// Per polygon: patches whose unshot radiance is not zero (RGB sum): those a shot of the
    /// polygon would clear. A patch that has never received (buried under a block) and all its
    /// cell with it shoots nothing (`shooters::cell_parts`), so overshooting must not count it as
    /// able to shoot its remainder (`Overshoot::max_shot_polygons`).
    pub lit: Vec<u32>,
}

impl EnergyTotals {
    /// Sum an RGBA atlas. `patch_area[p]` is the area of one patch of polygon p, or `None` to
    /// count patches only (the first call, before the areas are known).
    pub fn sum(rgba: &[f32], polygon_count: usize, patch_area: Option<&[f64]>) -> EnergyTotals {
        let mut totals = EnergyTotals {
            energy: vec![[0.0; 3]; polygon_count],
            patches: vec![0; polygon_count],
            lit: vec![0; polygon_count],
        };
        for texel in rgba.chunks_exact(4) {
            let id = texel[3] as usize;
            if id == 0 || id > polygon_count {
                continue;
            }
            let p = id - 1;
            totals.patches[p] += 1;
            totals.lit[p] += (texel[0] + texel[1] + texel[2] != 0.0) as u32;
            let e = &mut totals.energy[p];
            for c in 0..3 {
                e[c] += texel[c] as f64;
            }
        }
        if let Some(area) = patch_area {
            for (e, &a) in totals.energy.iter_mut().zip(area) {
                *e = e.map(|v| v * a);
            }
        }
        totals
    }

    /// Re-total only the polygons in `changed` (a shot changes its receivers' and shooter's
    /// texels, no others), each read from its lightmap rectangle `texels[p]` = [x0, y0, x1, y1)
    /// of an atlas `width` texels wide: the same texels in the same order as `sum`, so the same
    /// totals, without scanning the whole atlas every shot.
    pub fn update(
        &mut self,
        rgba: &[f32],
        width: usize,
        texels: &[[u32; 4]],
        changed: &[usize],
        patch_area: &[f64],
    ) {
        for &p in changed {
            let [x0, y0, x1, y1] = texels[p].map(|v| v as usize);
            let id = (p + 1) as f32;
            let (mut e, mut lit) = ([0.0f64; 3], 0);
            for y in y0..y1 {
                for texel in rgba[(y * width + x0) * 4..(y * width + x1) * 4].chunks_exact(4) {
                    if texel[3] == id {
                        for c in 0..3 {
                            e[c] += texel[c] as f64;
                        }
                        lit += (texel[0] + texel[1] + texel[2] != 0.0) as u32;
                    }
                }
            }
            self.energy[p] = e.map(|v| v * patch_area[p]);
            self.lit[p] = lit;
        }
    }

    /// Power of polygon p: π·Σ L·A, RGB mean (the paper's `Intensity`).
    pub fn power(&self, p: usize) -> f64 {
        let e = self.energy[p];
        std::f64::consts::PI * (e[0] + e[1] + e[2]) / 3.0
    }

    /// Σ of every polygon's `power` (negative channels count against it).
    pub fn total_power(&self) -> f64 {
        (0..self.energy.len()).map(|p| self.power(p)).sum()
    }

    /// How much polygon p has left to shoot: π·Σ|L·A| over RGB, averaged; its power when no
    /// channel is negative (always, unless overshooting leaves negative unshot energy behind,
    /// which must be shot as well).
    pub fn magnitude(&self, p: usize) -> f64 {
        let e = self.energy[p];
        std::f64::consts::PI * (e[0].abs() + e[1].abs() + e[2].abs()) / 3.0
    }

    /// Σ of every polygon's [`magnitude`](Self::magnitude): what the stopping rule compares.
    pub fn total_magnitude(&self) -> f64 {
        (0..self.energy.len()).map(|p| self.magnitude(p)).sum()
    }

    /// The paper's `Find_Max_Energy_lm`: the `count` polygons (the paper: one) with the most
    /// unshot power (the largest [`magnitude`](Self::magnitude)) above `floor`, most first;
    /// fewer, or none, when fewer have more than `floor`. Ties go to the lower ID, so the choice
    /// is deterministic.
    pub fn max_energy_polygons(&self, floor: f64, count: usize) -> Vec<usize> {
        largest(self.energy.len(), count, floor, |p| self.magnitude(p))
    }

    /// Polygon `p`'s unshot energy, radiance × area per RGB channel.
    pub fn energy_rgb(&self, p: usize) -> Vec3 {
        let e = self.energy[p];
        Vec3::new(e[0] as f32, e[1] as f32, e[2] as f32)
    }
}

/// The `count` indices below `n` with the largest `score` above `floor`, largest first; ties go
/// to the lower index. One scan, each score computed once (the complex room has 8,549 polygons,
/// and the loop waits for this between shots), keeping the best `count` in order.
pub fn largest(n: usize, count: usize, floor: f64, score: impl Fn(usize) -> f64) -> Vec<usize> {
    if count == 0 {
        return Vec::new();
    }
    let mut best: Vec<(f64, usize)> = Vec::with_capacity(count + 1);
    for p in 0..n {
        let f = score(p);
        // `>`: a NaN is never picked, and a later index never passes an equal score.
        let above = f > floor && (best.len() < count || f > best[count - 1].0);
        if !above {
            continue;
        }
        let at = best.partition_point(|&(g, _)| g >= f);
        best.insert(at, (f, p));
        best.truncate(count);
    }
    best.into_iter().map(|(_, p)| p).collect()
}

/// Wall-clock seconds spent in each named pass, keyed by the pass's name (`visibility`,
/// `reconstruction`, `accumulation`, `readback`, `find_max_energy`). On the GPU draw calls are
/// asynchronous: a pass's time shows up where the next readback waits for it.
#[derive(Clone, Debug, Default, serde::Serialize)]
#[serde(transparent)]
pub struct PassTimes(BTreeMap<&'static str, f64>);

impl PassTimes {
    /// Seconds spent in `pass` so far (0 if it never ran).
    pub fn get(&self, pass: &str) -> f64 {
        self.0.get(pass).copied().unwrap_or(0.0)
    }

    /// Add `elapsed` to `pass`.
    pub fn add(&mut self, pass: &'static str, elapsed: Duration) {
        *self.0.entry(pass).or_default() += elapsed.as_secs_f64();
    }

    /// Run `f`, adding its wall-clock time to `pass`.
    pub fn time<T>(&mut self, pass: &'static str, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let out = f();
        self.add(pass, t.elapsed());
        out
    }

    /// Every pass that ran, with its seconds, in name order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        self.0.iter().map(|(&k, &v)| (k, v))
    }
}

/// Totals, areas, the stopping rule's reference, the history and the timers of one solve.
#[derive(Clone, Debug)]
pub struct Ledger {
    totals: EnergyTotals,
    /// Area of one patch of each polygon: equal shares of the polygon's area, so that the patch
    /// areas of a polygon add up to its area exactly.
    patch_area: Vec<f64>,
    /// Patches of each polygon, as counted in the initial atlas.
    patches: Vec<u32>,
    emitted_power: f64,
    shots: u32,
    passes: u32,
    corrections: u32,
    started: Instant,
    history: Vec<ShotRecord>,
    /// Seconds per named pass.
    pub times: PassTimes,
}

impl Ledger {
    /// Start from the initial unshot atlas (every patch's emission; RGBA, alpha = polygon ID +
    /// 1). Fails when nothing is emitted at this patch size (`patch_size`, scene units).
    pub fn new(scene: &Scene, emission: &[f32], patch_size: f32) -> Result<Ledger, SolveError> {
        let n = scene.polygons.len();
        let counted = EnergyTotals::sum(emission, n, None);
        let patch_area: Vec<f64> = scene
            .polygons
            .iter()
            .zip(&counted.patches)
            .map(|(p, &k)| if k > 0 { p.area as f64 / k as f64 } else { 0.0 })
            .collect();
        let totals = EnergyTotals::sum(emission, n, Some(&patch_area));
        let emitted_power = totals.total_power();
        if emitted_power <= 0.0 {
            return Err(SolveError::NoEmission { patch_size });
        }
        Ok(Ledger {
            totals,
            patch_area,
            patches: counted.patches,
            emitted_power,
            shots: 0,
            passes: 0,
            corrections: 0,
            started: Instant::now(),
            history: Vec::new(),
            times: PassTimes::default(),
        })
    }

    /// Find_Max_Energy: the `count` polygons with the most unshot power (the paper: one), most
    /// first, of those that have some ([`EnergyTotals::max_energy_polygons`]).
    pub fn max_energy_polygons(&self, count: usize) -> Vec<usize> {
        self.totals.max_energy_polygons(0.0, count)
    }

    /// Unshot power / emitted power, counting negative unshot energy (left by overshooting) as
    /// unshot too ([`EnergyTotals::total_magnitude`]).
    pub fn unshot_fraction(&self) -> f64 {
        self.totals.total_magnitude() / self.emitted_power
    }

    /// The stopping rule: the unshot fraction at or below `threshold`, or `max_shots` taken.
    pub fn converged(&self, threshold: f32, max_shots: u32) -> bool {
        self.unshot_fraction() <= threshold as f64 || self.shots >= max_shots
    }

    /// Every polygon's unshot energy, as last read back.
    pub fn totals(&self) -> &EnergyTotals {
        &self.totals
    }

    /// Re-total the polygons `changed` from the unshot atlas `unshot` (`width` texels wide,
    /// lightmap rectangles `texels`), after a shot.
    pub fn update(&mut self, unshot: &[f32], width: usize, texels: &[[u32; 4]], changed: &[usize]) {
        self.totals
            .update(unshot, width, texels, changed, &self.patch_area);
    }

    /// Re-total every polygon from `unshot` (after the lightmaps were replaced from outside).
    pub fn retotal(&mut self, unshot: &[f32]) {
        self.totals = EnergyTotals::sum(unshot, self.patch_area.len(), Some(&self.patch_area));
    }

    /// Total unshot power now, signed (negative unshot energy left by overshooting takes away).
    pub fn unshot_power(&self) -> f64 {
        self.totals.total_power()
    }

    /// Count one visibility + reconstruction pass pair.
    pub fn count_pass(&mut self) {
        self.passes += 1;
    }

    /// Count a shot scaled back to what it carried (`SolveOptions::conserve`).
    pub fn count_correction(&mut self) {
        self.corrections += 1;
    }

    /// Shots scaled back to what they carried so far.
    pub fn corrections(&self) -> u32 {
        self.corrections
    }

    /// Close a shot of `polygons` polygons (the first of them `polygon`; one in the paper) that
    /// shot `shot_power`, carried `carried_power` and delivered `received_power` to its receivers
    /// (the shot's `ShotBalance`), the unshot power having been `before` when it started; the
    /// record is kept in the history and returned. Every polygon counts as a shot.
    pub fn record_shot(
        &mut self,
        polygon: usize,
        polygons: u32,
        before: f64,
        shot_power: f64,
        carried_power: f64,
        received_power: f64,
    ) -> ShotRecord {
        self.shots += polygons.max(1);
        let record = ShotRecord {
            shot: self.shots,
            shooter: polygon,
            seconds: self.started.elapsed().as_secs_f64(),
            unshot_fraction: self.unshot_fraction(),
            shot_power,
            // What the receivers gained: the new total, less what was left unshot.
            reflected_power: self.unshot_power() - (before - shot_power),
            carried_power,
            received_power,
        };
        self.history.push(record.clone());
        record
    }

    /// Shots so far.
    pub fn shots(&self) -> u32 {
        self.shots
    }

    /// Visibility + reconstruction pass pairs so far (one per shooter cell of each shot).
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// The scene's emitted power (radiance × area × π, RGB mean): the stopping rule's denominator.
    pub fn emitted_power(&self) -> f64 {
        self.emitted_power
    }

    /// Every shot so far, in order.
    pub fn history(&self) -> &[ShotRecord] {
        &self.history
    }

    /// Area of one patch of `polygon`.
    pub fn patch_area(&self, polygon: usize) -> f64 {
        self.patch_area[polygon]
    }

    /// Area of one patch of each polygon.
    pub fn patch_areas(&self) -> &[f64] {
        &self.patch_area
    }

    /// Patches per polygon, as counted in the initial atlas (on the GPU: as the rasteriser drew
    /// them).
    pub fn patches(&self) -> &[u32] {
        &self.patches
    }

    /// Restart the clock of the history's `seconds`.
    pub fn restart_clock(&mut self) {
        self.started = Instant::now();
    }

    /// Keep `elapsed` (time spent between shots on something else) out of the history's
    /// `seconds`.
    pub fn exclude_time(&mut self, elapsed: Duration) {
        self.started += elapsed;
    }
}

impl Shooter {
    /// Power it shoots, π·L·A, averaged over RGB (negative for negative unshot energy).
    pub fn power(&self) -> f64 {
        std::f64::consts::PI * (self.energy.x as f64 + self.energy.y as f64 + self.energy.z as f64)
            / 3.0
    }
}

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

    #[test]
    fn picks_the_polygon_with_most_power_not_most_radiance() {
        // Polygon 0: one bright patch of area 1; polygon 1: four dimmer patches of area 1.
        let rgba = [
            3.0, 3.0, 3.0, 1.0, //
            1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 2.0, //
            9.0, 9.0, 9.0, 0.0, // not a patch
        ];
        let t = EnergyTotals::sum(&rgba, 2, Some(&[1.0, 1.0]));
        assert_eq!(t.patches, vec![1, 4]);
        assert_eq!(t.max_energy_polygons(0.0, 1), vec![1]);
        assert!((t.total_power() - std::f64::consts::PI * 7.0).abs() < 1e-9);
        assert_eq!(t.max_energy_polygons(100.0, 1), Vec::<usize>::new());
    }

    #[test]
    fn the_best_few_are_what_picking_the_best_again_and_again_gives() {
        // The rule `largest` keeps: pick the highest score above the floor (ties: the lower
        // index), leave it out, pick again.
        let naive = |scores: &[f64], count: usize, floor: f64| {
            let mut picked: Vec<usize> = Vec::new();
            while picked.len() < count {
                let mut best = None;
                let mut most = floor;
                for (p, &f) in scores.iter().enumerate() {
                    if f > most && !picked.contains(&p) {
                        most = f;
                        best = Some(p);
                    }
                }
                match best {
                    Some(p) => picked.push(p),
                    None => break,
                }
            }
            picked
        };
        // Ties, NaN, scores at the floor and below it, in a scrambled order.
        let scores: Vec<f64> = (0..200u64)
            .map(|i| match (i * 7919) % 13 {
                0 => f64::NAN,
                1 => 0.0,
                2 => -1.0,
                k => ((i * 104_729) % 17) as f64 + k as f64 / 4.0,
            })
            .collect();
        for count in [0, 1, 2, 3, 4, 10, 300] {
            for floor in [0.0, 3.0, 100.0] {
                let got = largest(scores.len(), count, floor, |p| scores[p]);
                assert_eq!(
                    got,
                    naive(&scores, count, floor),
                    "count {count}, floor {floor}"
                );
            }
        }
    }

    #[test]
    fn updating_the_changed_polygons_gives_the_full_sum() {
        // A 4x2 atlas: polygon 0 at [0,0,2,2), polygon 1 at [2,0,4,1) (its second row empty).
        let mut rgba = vec![0.0f32; 4 * 2 * 4];
        let mut put = |x: usize, y: usize, v: f32, id: f32| {
            rgba[(y * 4 + x) * 4..(y * 4 + x) * 4 + 4].copy_from_slice(&[v, v, v, id])
        };
        for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            put(x, y, 1.0, 1.0);
        }
        put(2, 0, 2.0, 2.0);
        put(3, 0, 3.0, 2.0);
        let areas = [0.5, 2.0];
        let mut t = EnergyTotals::sum(&rgba, 2, Some(&areas));
        rgba[4 * 3] = 7.0; // polygon 1's second texel changes
        rgba[4 * 2..4 * 2 + 3].fill(0.0); // and its first is cleared: 1 patch lit, not 2
        t.update(&rgba, 4, &[[0, 0, 2, 2], [2, 0, 4, 1]], &[1], &areas);
        let full = EnergyTotals::sum(&rgba, 2, Some(&areas));
        assert_eq!(t.energy, full.energy);
        assert_eq!(t.lit, full.lit);
        assert_eq!(t.lit, [4, 1]);
    }

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
