//! The bookkeeping both backends share: how much unshot energy each polygon holds (what
//! Find_Max_Energy reads), the patch areas that turn radiance into power, the emitted power the
//! stopping rule compares against, the shot history and the time spent in each named pass.

use super::find_max_energy::EnergyTotals;
use super::{ShotRecord, SolveError};
use crate::scene::Scene;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

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
    /// shot `shot_power` (`balance`: what it carried and what reached the receivers), the unshot power
    /// having been `before` when it started; the record is
    /// kept in the history and returned. Every polygon counts as a shot.
    pub fn record_shot(
        &mut self,
        polygon: usize,
        polygons: u32,
        before: f64,
        shot_power: f64,
        balance: &super::balance::ShotBalance,
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
            carried_power: balance.carried_power(),
            received_power: balance.received_power(),
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
