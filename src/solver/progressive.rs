//! The progressive refinement loop of section 3.2, written once for both backends:
//!
//! ```text
//! initialise the unshot energy E of every patch (its emission)      -- Backend::new, Ledger::new
//! while not converged:                                               -- Ledger::converged
//!     shooter = Find_Max_Energy()                                    -- Ledger::find_max_energy
//!     for each cell of the shooter (the paper: the whole polygon):
//!         visibility pass from the shooter                           -- Backend::visibility
//!         reconstruction pass: every receiver's ΔE = ρ·F·E added     -- Backend::reconstruction
//!         the sums into the lightmaps (glCopyTexSubImage2D)          -- Backend::accumulate
//!     (beyond the paper, `shooters_per_pass` K > 1: the K polygons with the most unshot
//!     power; one visibility pass each, one reconstruction pass for K of them)
//!     (the shooter's unshot energy is cleared by its pass)
//!     read the unshot lightmap back, re-total the changed polygons   -- Backend::read_unshot
//! ```
//!
//! A backend ([`Backend`]) does the passes: [`GpuBackend`](super::gpu::GpuBackend) on OpenGL as the
//! paper does, [`CpuBackend`](super::cpu::CpuBackend) in Rust with exact visibility. [`Solver`]
//! runs the loop and keeps the books ([`Ledger`]); `GpuSolver` and `CpuSolver` name the two.

use super::ledger::{Ledger, PassTimes};
use super::overshoot::Overshoot;
use super::{shooters, Shooter, ShotRecord, SolveError, SolveOptions};
use crate::patches::{Lightmap, PatchLayout};
use crate::scene::Scene;
use std::time::{Duration, Instant};

/// The passes of one shot, as a backend does them. Atlases are RGBA (alpha: polygon ID + 1), in
/// the backend's own layout ([`Backend::layout`]); a shooter's texels too.
pub trait Backend {
    /// The layout the backend's atlases are in.
    fn layout(&self) -> &PatchLayout;
    /// The unshot radiance atlas as last read back (`read_unshot`).
    fn unshot(&self) -> &[f32];
    /// Visibility pass (3.2.1): what the shooter sees, kept in item-buffer slot `slot` (0 in the
    /// paper; one slot per shooter of the next reconstruction pass).
    fn visibility(&mut self, shooter: &Shooter, slot: usize) -> Result<(), SolveError>;
    /// Reconstruction pass (3.2.2, steps 1–3): every receiver's ΔL from `shooters` (one in the
    /// paper; their visibility in slots 0, 1, …) added to its lightmap values; the shooting
    /// texels' unshot radiance zero (or their remainder), plus what the others send them.
    fn reconstruction(&mut self, shooters: &[Shooter]) -> Result<(), SolveError>;
    /// Accumulation (3.2.2, step 4): the pass's sums become the lightmaps the next pass reads.
    fn accumulate(&mut self) -> Result<(), SolveError>;
    /// After a shot: read the unshot atlas back and put into `changed` (cleared first) the
    /// polygons whose lightmaps the shot's passes can have changed.
    fn read_unshot(&mut self, changed: &mut Vec<usize>) -> Result<(), SolveError>;
    /// The accumulated radiance atlas.
    fn radiosity(&self) -> Vec<f32>;
    /// Replace both lightmaps.
    fn load(&mut self, radiosity: &[f32], unshot: &[f32]) -> Result<(), SolveError>;
}

/// Progressive refinement radiosity on a backend `B`: the paper's loop and its bookkeeping.
pub struct Solver<'a, B: Backend> {
    scene: &'a Scene,
    /// The caller's layout, in which atlases and shooters are handed out.
    layout: &'a PatchLayout,
    options: SolveOptions,
    backend: B,
    ledger: Ledger,
    /// The polygons' lightmap rectangles in the backend's layout; the polygons a shot changed.
    texels: Vec<[u32; 4]>,
    changed: Vec<usize>,
    /// Whether a shot beyond the balance's bound was reported (once a solve).
    excess_reported: std::cell::Cell<bool>,
    /// The unshot power the solve started from (the emitted power, or what `load_atlases`
    /// loaded): a valid solve never goes above it.
    unshot_ceiling: f64,
    /// The ambient estimate, when overshooting (`SolveOptions::overshoot`).
    overshoot: Option<Overshoot>,
}

/// Pass names, as `PassTimes` keys them.
pub const FIND_MAX_ENERGY: &str = "find_max_energy";
pub const VISIBILITY: &str = "visibility";
pub const RECONSTRUCTION: &str = "reconstruction";
pub const ACCUMULATION: &str = "accumulation";
pub const READBACK: &str = "readback";

impl<'a, B: Backend> Solver<'a, B> {
    /// A solver on `backend`, whose lightmaps hold the emission, for the caller's `layout`.
    pub(super) fn start(
        scene: &'a Scene,
        layout: &'a PatchLayout,
        options: SolveOptions,
        backend: B,
    ) -> Result<Self, SolveError> {
        let ledger = Ledger::new(scene, backend.unshot(), layout.patch_size)?;
        let overshoot = options
            .overshoot
            .then(|| Overshoot::new(scene, ledger.patches()));
        Ok(Solver {
            scene,
            layout,
            options,
            texels: backend.layout().texel_rects(),
            backend,
            changed: Vec::new(),
            excess_reported: std::cell::Cell::new(false),
            unshot_ceiling: 0.0,
            overshoot,
            ledger,
        })
    }

    /// One shot; `None` once the stopping rule holds (or nothing is left to shoot).
    pub fn step(&mut self) -> Result<Option<ShotRecord>, SolveError> {
        if self.converged() {
            return Ok(None);
        }
        // Find_Max_Energy (3.2.2, step 5): the polygon with the most unshot power shoots next.
        let t = Instant::now();
        let shooters = self.next_shooters();
        if shooters.is_empty() {
            return Ok(None);
        }
        self.ledger.times.add(FIND_MAX_ENERGY, t.elapsed());
        self.shoot(&shooters).map(Some)
    }

    /// The shooters of the next step: Find_Max_Energy's polygon, its shooters (`shooters_of`).
    /// Beyond the paper, with `shooters_per_pass` K > 1, the next polygons too, as long as all
    /// their shooters fit in one reconstruction pass, and no more than the shots left before
    /// `max_shots`. Empty when nothing is left to shoot.
    fn next_shooters(&self) -> Vec<Shooter> {
        let k = self.options.shooters_per_pass.max(1) as usize;
        let left = self.options.max_shots.saturating_sub(self.ledger.shots());
        let mut shooters = Vec::new();
        for (i, p) in self
            .next_polygons(k.min(left as usize).max(1))
            .into_iter()
            .enumerate()
        {
            let mut cells = self.shooters_of(p);
            // A polygon shot in a later pass of the step would have received from the earlier
            // ones and then lost it to its remainder; so either one polygon (its cells K to a
            // pass: they send each other nothing), or polygons that share one pass.
            if i > 0 && shooters.len() + cells.len() > k {
                break;
            }
            if self.options.rotate_item_buffer {
                // Each polygon of the step its own turn, as if shot one after another.
                let turn = super::turn_of_shot(self.ledger.shots() + i as u32);
                cells.iter_mut().for_each(|s| s.turn = turn);
            }
            shooters.append(&mut cells);
        }
        shooters
    }

    /// One shot of the polygons of `shooters` (texels in the caller's layout): a visibility pass
    /// per shooter, and a reconstruction pass and the accumulation per `shooters_per_pass` of
    /// them (in the paper one shooter, the whole polygon: one pass of each), then one readback.
    /// The shooters of one reconstruction pass shoot simultaneously (see
    /// `SolveOptions::shooters_per_pass`). Shooters of several polygons must fit in one pass, as
    /// `step` picks them: a polygon shot in a later pass would lose what it received in an earlier
    /// one. The shot counts one per polygon.
    pub fn shoot(&mut self, shooters: &[Shooter]) -> Result<ShotRecord, SolveError> {
        let polygon = shooters.first().map(|s| s.polygon).unwrap_or(0);
        let mut polygons: Vec<usize> = shooters.iter().map(|s| s.polygon).collect();
        polygons.dedup();
        let before = self.ledger.unshot_power();
        let shot_power: f64 = shooters.iter().map(|s| s.power()).sum();
        let bound = self.reflection_bound(shooters);
        let powers_before: Vec<f64> = (0..self.scene.polygons.len())
            .map(|p| self.ledger.totals().power(p))
            .collect();
        let own: Vec<Shooter> = shooters
            .iter()
            .map(|s| Shooter {
                texels: move_rect(
                    s.texels,
                    &self.layout.lightmaps[s.polygon],
                    &self.backend.layout().lightmaps[s.polygon],
                ),
                ..*s
            })
            .collect();
        for pass in own.chunks(self.options.shooters_per_pass.max(1) as usize) {
            let (backend, times) = (&mut self.backend, &mut self.ledger.times);
            for (slot, shooter) in pass.iter().enumerate() {
                times.time(VISIBILITY, || backend.visibility(shooter, slot))?;
            }
            times.time(RECONSTRUCTION, || backend.reconstruction(pass))?;
            times.time(ACCUMULATION, || backend.accumulate())?;
            self.ledger.count_pass();
        }
        let (backend, times) = (&mut self.backend, &mut self.ledger.times);
        times.time(READBACK, || backend.read_unshot(&mut self.changed))?;
        let t = Instant::now();
        let width = self.backend.layout().atlas_width as usize;
        self.ledger
            .update(self.backend.unshot(), width, &self.texels, &self.changed);
        self.ledger.times.add(FIND_MAX_ENERGY, t.elapsed());
        let record = self
            .ledger
            .record_shot(polygon, polygons.len() as u32, before, shot_power);
        self.check_balance(&record, bound, &powers_before)?;
        Ok(record)
    }

    /// The most a shot of `shooters` can reflect: per colour channel, what it shoots times the
    /// largest reflectance any polygon has (as `Shooter::power` averages, over RGB).
    fn reflection_bound(&self, shooters: &[Shooter]) -> f64 {
        let kd = self
            .scene
            .materials
            .iter()
            .fold(glam::Vec3::ZERO, |m, material| m.max(material.kd));
        // By magnitude: an overshot shooter's negative unshot energy shoots negative light.
        let energy = shooters
            .iter()
            .fold(glam::DVec3::ZERO, |e, s| e + s.energy.as_dvec3().abs());
        std::f64::consts::PI * energy.dot(kd.as_dvec3()) / 3.0
    }

    /// Energy balance. A shot that reflected more than `bound` (beyond float noise) broke it
    /// locally: the receivers' patch centres sample the form factor, which near a contact (a
    /// lamp base on a cabinet) overestimates what a coarse patch receives. Whole polygons shooting
    /// in the Table 1 rooms do that on a few shots (up to 1.5x in the simple room, 2.5x in the
    /// complex one) and still converge, so such a shot is reported once as a warning. Energy is
    /// created at the scale of the scene when the unshot power passes the emitted power (or what
    /// `load_atlases` started from), or stops being a number: overlapping receivers, folded
    /// faces, or the point form factor running away. Going on would make every later shot and the
    /// picture wrong, so the solve stops there and names the polygons.
    fn check_balance(
        &self,
        record: &ShotRecord,
        bound: f64,
        powers_before: &[f64],
    ) -> Result<(), SolveError> {
        // Float noise of the f32 atlas sums; a few 1e-3 also covers the hemicube's per-pixel
        // delta form factors, which add up to 1 only within their discretisation.
        let slack = 5e-3 * bound + 1e-9 * self.ledger.emitted_power();
        let over = record.reflected_power.abs() > bound + slack || record.reflected_power.is_nan();
        let ceiling = self.unshot_ceiling.max(self.ledger.emitted_power());
        let growth = self.ledger.unshot_power() / ceiling;
        // Overshooting leaves negative unshot energy behind, so the magnitude may pass the
        // ceiling a little (the signed total may not); twice over is a runaway all the same.
        let magnitude = self.ledger.unshot_fraction() * self.ledger.emitted_power() / ceiling;
        let runaway =
            growth > 1.0 + 5e-3 || !growth.is_finite() || !magnitude.is_finite() || magnitude > 2.0;
        if !runaway {
            if over && !self.excess_reported.replace(true) {
                eprintln!(
                    "warning: shot {} reflected {:.3}x the most its power allows ({}); the \
                     patches near the shooter sample its form factor coarsely. The solve goes on \
                     while the unshot power stays below the emitted power",
                    record.shot,
                    record.reflected_power / bound,
                    crate::scene::shown(&self.scene.polygons[record.shooter].object)
                );
            }
            return Ok(());
        }
        let totals = self.ledger.totals();
        let mut gains: Vec<(f64, usize)> = (0..self.scene.polygons.len())
            .filter(|&p| p != record.shooter)
            .map(|p| (totals.power(p) - powers_before[p], p))
            .filter(|&(g, _)| g > 0.0)
            .collect();
        gains.sort_by(|a, b| b.0.total_cmp(&a.0));
        let name = |p: usize| {
            format!(
                "polygon {p} of '{}'",
                crate::scene::shown(&self.scene.polygons[p].object)
            )
        };
        let receivers: Vec<String> = gains
            .iter()
            .take(5)
            .map(|&(g, p)| format!("{} (+{g:.3e})", name(p)))
            .collect();
        // The paper's point form factor has no bound near the shooter (in the simple room a sofa
        // 2 cm from a wall receives 2.8x what the wall shot, and the solve runs away to NaN),
        // so in the paper's mode the excess is the algorithm's own; still the answer would be
        // wrong, so it stops too, and says so.
        let cause = if self.options.form_factor == super::FormFactorKind::Point {
            "The point form factor (--form-factor point, as in --mode paper) has no bound for \
             receivers close to the shooter; the polygon form factor (--form-factor polygon, \
             --mode accurate) keeps the balance"
        } else {
            "Overlapping faces in one plane (a face given twice) or intersecting faces do this; \
             remove the duplicates"
        };
        Err(SolveError::EnergyCreated {
            cause,
            shot: record.shot,
            unshot: growth,
            shooter: name(record.shooter),
            shot_power: record.shot_power,
            reflected: record.reflected_power,
            bound,
            receivers: receivers.join(", "),
        })
    }

    /// Run to the stopping rule; `progress` sees every shot.
    pub fn solve(&mut self, mut progress: impl FnMut(&ShotRecord)) -> Result<(), SolveError> {
        self.solve_with(
            |_| {},
            |_, record| {
                progress(record);
                Ok::<(), SolveError>(())
            },
        )
    }

    /// Run to the stopping rule, calling `before` ahead of every shot and `after` once it is
    /// taken (to picture the passes, say); the time they take is kept out of the solver's clock
    /// (the history's seconds). An error from `after` stops the solve.
    pub fn solve_with<E: From<SolveError>>(
        &mut self,
        mut before: impl FnMut(&Self),
        mut after: impl FnMut(&Self, &ShotRecord) -> Result<(), E>,
    ) -> Result<(), E> {
        self.ledger.restart_clock();
        loop {
            let t = Instant::now();
            before(self);
            self.ledger.exclude_time(t.elapsed());
            let Some(record) = self.step()? else {
                return Ok(());
            };
            let t = Instant::now();
            after(self, &record)?;
            self.ledger.exclude_time(t.elapsed());
        }
    }

    /// Find_Max_Energy: the polygon with the most unshot power (when overshooting, whose shot
    /// would carry the most: `Overshoot::find_max_energy`).
    pub fn next_polygon(&self) -> Option<usize> {
        self.next_polygons(1).first().copied()
    }

    /// Find_Max_Energy for `count` shooters at once: the `count` polygons that would carry the
    /// most, most first (fewer when fewer have anything to shoot).
    pub fn next_polygons(&self, count: usize) -> Vec<usize> {
        match &self.overshoot {
            Some(o) => o.find_max_energy(self.ledger.totals(), count),
            None => self.ledger.find_max_energy(count),
        }
    }

    /// The shooters that carry polygon `p`'s unshot energy (see `shooters::shooters_of`), their
    /// texels in the caller's layout; with their overshoot, item-buffer resolution and turn when
    /// the options go beyond the paper there.
    pub fn shooters_of(&self, p: usize) -> Vec<Shooter> {
        let own = self.backend.layout();
        let mut shooters = shooters::shooters_of(
            self.scene,
            own,
            &self.options,
            self.backend.unshot(),
            self.ledger.patch_areas(),
            self.ledger.totals(),
            p,
        );
        let remainder = self
            .overshoot
            .as_ref()
            .map(|o| o.remainder(self.ledger.totals(), p));
        for s in &mut shooters {
            if let Some(remainder) = remainder {
                // Each of the shooter's patches shoots −remainder more radiance.
                let area = patches_in(own, self.backend.unshot(), s.texels, p) as f64
                    * self.ledger.patch_area(p);
                s.energy -= remainder * area as f32;
                s.remainder = remainder;
            }
            s.hemi_res = self.item_buffer_resolution(s);
            if self.options.rotate_item_buffer {
                s.turn = super::turn_of_shot(self.ledger.shots());
            }
            s.texels = move_rect(s.texels, &own.lightmaps[p], &self.layout.lightmaps[p]);
        }
        shooters
    }

    /// The item-buffer resolution for shooter `s` ([`super::item_buffer_side`]).
    fn item_buffer_resolution(&self, s: &Shooter) -> u32 {
        super::item_buffer_side(&self.options, s.power() / self.ledger.emitted_power())
    }

    pub fn converged(&self) -> bool {
        self.ledger
            .converged(self.options.threshold, self.options.max_shots)
    }

    pub fn unshot_fraction(&self) -> f64 {
        self.ledger.unshot_fraction()
    }

    pub fn emitted_power(&self) -> f64 {
        self.ledger.emitted_power()
    }

    pub fn shots(&self) -> u32 {
        self.ledger.shots()
    }

    /// Visibility + reconstruction pass pairs run so far (one per shooter cell of each shot).
    pub fn passes(&self) -> u32 {
        self.ledger.passes()
    }

    pub fn history(&self) -> &[ShotRecord] {
        self.ledger.history()
    }

    /// Seconds per named pass.
    pub fn times(&self) -> &PassTimes {
        &self.ledger.times
    }

    /// The books: totals, areas, emitted power, history, timers.
    pub fn ledger(&self) -> &Ledger {
        &self.ledger
    }

    /// Area of one patch of `polygon`.
    pub fn patch_area(&self, polygon: usize) -> f64 {
        self.ledger.patch_area(polygon)
    }

    pub fn patch_areas(&self) -> &[f64] {
        self.ledger.patch_areas()
    }

    pub fn options(&self) -> &SolveOptions {
        &self.options
    }

    pub fn backend(&self) -> &B {
        &self.backend
    }

    pub fn backend_mut(&mut self) -> &mut B {
        &mut self.backend
    }

    /// The accumulated radiance atlas in the caller's layout, RGBA (alpha: polygon ID + 1),
    /// rows bottom to top.
    pub fn radiosity_atlas(&self) -> Vec<f32> {
        self.to_caller(&self.backend.radiosity())
    }

    /// The unshot radiance atlas as last read back, in the caller's layout (RGBA, alpha:
    /// polygon ID + 1).
    pub fn unshot_atlas(&self) -> Vec<f32> {
        self.to_caller(self.backend.unshot())
    }

    /// Replace both lightmaps with atlases in the caller's layout (RGBA as `radiosity_atlas` and
    /// `unshot_atlas` give them, alpha the polygon ID + 1), e.g. to resume a saved solve; the
    /// unshot totals are read back from the backend, so Find_Max_Energy picks from them.
    pub fn load_atlases(&mut self, radiosity: &[f32], unshot: &[f32]) -> Result<(), SolveError> {
        let texels = self.layout.atlas_width as usize * self.layout.atlas_height as usize * 4;
        if radiosity.len() != texels || unshot.len() != texels {
            return Err(SolveError::AtlasSize {
                expected: texels,
                got: radiosity.len().max(unshot.len()),
            });
        }
        let own = self.backend.layout();
        let (r, u) = (
            self.layout.move_atlas(radiosity, 4, own),
            self.layout.move_atlas(unshot, 4, own),
        );
        self.backend.load(&r, &u)?;
        self.backend.read_unshot(&mut self.changed)?;
        self.ledger.retotal(self.backend.unshot());
        self.unshot_ceiling = self.ledger.unshot_power().max(self.ledger.emitted_power());
        Ok(())
    }

    /// Restart the clock of the history's `seconds`, as `solve` does (for callers that drive
    /// `step` themselves: the pass pictures, the viewer).
    pub fn restart_clock(&mut self) {
        self.ledger.restart_clock();
    }

    /// Keep `elapsed` (time spent between shots on something else: writing pictures, drawing
    /// the viewer's frames) out of the history's `seconds`.
    pub fn exclude_time(&mut self, elapsed: Duration) {
        self.ledger.exclude_time(elapsed);
    }

    /// Change the stopping rule's threshold (unshot power / emitted power) between shots.
    pub fn set_threshold(&mut self, threshold: f32) {
        self.options.threshold = threshold;
    }

    fn to_caller(&self, atlas: &[f32]) -> Vec<f32> {
        self.backend.layout().move_atlas(atlas, 4, self.layout)
    }
}

/// The patches of polygon `p` in the texel rectangle `[x0, y0, x1, y1)` of `layout`'s atlas
/// (`atlas`: RGBA, alpha the polygon ID + 1).
fn patches_in(layout: &PatchLayout, atlas: &[f32], [x0, y0, x1, y1]: [u32; 4], p: usize) -> u32 {
    let width = layout.atlas_width as usize;
    let id = (p + 1) as f32;
    let mut n = 0;
    for y in y0 as usize..y1 as usize {
        let row = &atlas[(y * width + x0 as usize) * 4..(y * width + x1 as usize) * 4];
        n += row.chunks_exact(4).filter(|t| t[3] == id).count() as u32;
    }
    n
}

/// A texel rectangle of lightmap `from` at the same place in `to` (the same lightmap elsewhere).
fn move_rect(r: [u32; 4], from: &Lightmap, to: &Lightmap) -> [u32; 4] {
    let (x, y) = (|t: u32| t - from.x + to.x, |t: u32| t - from.y + to.y);
    [x(r[0]), y(r[1]), x(r[2]), y(r[3])]
}
