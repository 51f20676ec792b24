//! `Find_Max_Energy` (paper 3.2.2, step 5), on the CPU: total the unshot energy of each
//! polygon's lightmap and pick the polygon with the most unshot power as the next shooter; and
//! the books both backends keep around it ([`Ledger`]): those totals, the patch areas that turn
//! radiance into power, the emitted power the stopping rule compares against, the shot history
//! and the time spent in each named pass.
//!
//! The unshot atlas comes back from the GPU as RGBA floats: RGB is the unshot radiance of the
//! patch, alpha the polygon ID + 1 (0 where a texel is not a patch). Every patch of a polygon
//! has the same area (polygon area / patch count), so the totals are exact in power.

use super::{ShotRecord, SolveError};
use crate::scene::Scene;
use glam::Vec3;
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
}
