//! The progressive refinement loop of section 3.2, written once for both backends:
//!
//! ```text
//! initialise the unshot energy E of every patch (its emission)      -- GpuBackend::new, Ledger::new
//! while not converged:                                               -- Ledger::converged
//!     shooter = Find_Max_Energy()                                    -- Ledger::max_energy_polygons
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

use super::cluster_parts::{self, Part};
use super::clusters::{ClusterChoice, Clusters, Member};
use super::face_clusters::FaceClusters;
use super::find_max_energy::{self, EnergyTotals, Ledger, PassTimes, ShotBalance};
use super::overshoot::Overshoot;
use super::pass_names::{ACCUMULATION, FIND_MAX_ENERGY, READBACK, RECONSTRUCTION, VISIBILITY};
use super::{shooters, Shooter, ShotRecord, SolveError, SolveOptions, MAX_CORNERS};
use crate::patches::{Lightmap, PatchLayout};
use crate::scene::Scene;
use glam::Vec3;
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
    /// The visibility passes of one reconstruction pass's `shooters`, `shooters[k]` into slot
    /// k: one `visibility` after another, unless the backend overlaps them (beyond the paper:
    /// `VisibilityPass::run_pass`).
    fn visibility_pass(&mut self, shooters: &[Shooter]) -> Result<(), SolveError> {
        for (slot, shooter) in shooters.iter().enumerate() {
            self.visibility(shooter, slot)?;
        }
        Ok(())
    }
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
    /// Beyond the paper (clusters): zero the unshot radiance of every patch of `polygons`
    /// before a shot's passes, as their cluster's shot carries it; they count as changed.
    fn clear_unshot(&mut self, polygons: &[usize]) -> Result<(), SolveError>;
    /// Beyond the paper (face clusters): the parts the next passes' shooters point at
    /// (`Shooter::parts`, `cluster_parts.rs`).
    fn parts(&mut self, parts: &[Part]) -> Result<(), SolveError>;
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
    /// Small coplanar polygons that shoot together
    /// (`SolveOptions::cluster_cell`), and how many such shots were made.
    clusters: Clusters,
    cluster_shots: u32,
    /// Touching small polygons whose normals lie within a cone (`SolveOptions::face_clusters`),
    /// and how many steps shot one.
    face_clusters: Option<FaceClusters>,
    face_cluster_shots: u32,
    /// The most cells a polygon's shot is divided into (`shooters::max_cells`).
    max_cells: u32,
}

impl<'a, B: Backend> Solver<'a, B> {
    /// A solver on `backend`, whose lightmaps hold the emission, for the caller's `layout`.
    /// `face_clusters`: the hierarchy the solve shoots from (`clusters::face_clusters`).
    pub(super) fn start(
        scene: &'a Scene,
        layout: &'a PatchLayout,
        options: SolveOptions,
        backend: B,
        face_clusters: Option<FaceClusters>,
    ) -> Result<Self, SolveError> {
        let ledger = Ledger::new(scene, backend.unshot(), layout.patch_size)?;
        let overshoot = options
            .overshoot
            .then(|| Overshoot::new(scene, ledger.patches()));
        let clusters = Clusters::new(scene, layout, options.shooter_cell, options.cluster_cell);
        let max_cells = shooters::max_cells(scene, options.shot_triangles);
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
            clusters,
            cluster_shots: 0,
            face_clusters,
            face_cluster_shots: 0,
            max_cells,
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
        let (shooters, members) = self.next_shooters();
        if shooters.is_empty() {
            return Ok(None);
        }
        self.ledger.times.add(FIND_MAX_ENERGY, t.elapsed());
        self.shoot_step(&shooters, &members).map(Some)
    }

    /// The shooters of the next step: Find_Max_Energy's polygon, its shooters (`shooters_of`).
    /// Beyond the paper, with `shooters_per_pass` K > 1, the next polygons too, as long as all
    /// their shooters fit in one reconstruction pass, and no more than the shots left before
    /// `max_shots`; and a polygon of a cluster whose shot is small shoots with its cluster
    /// (`ClusterChoice::cluster_of`), whose members it returns. Empty when nothing is left to
    /// shoot.
    fn next_shooters(&self) -> (Vec<Shooter>, Vec<Member>) {
        let k = self.options.shooters_per_pass.max(1) as usize;
        let left = self.options.max_shots.saturating_sub(self.ledger.shots());
        let (mut shooters, mut members) = (Vec::new(), Vec::new());
        // The polygons this step already shoots, alone or in a cluster: none shoots twice.
        let mut taken: Vec<usize> = Vec::new();
        let mut units = 0;
        // Without clusters (`cluster_cell` 0, as in the paper) no polygon has one.
        let clustered = (self.options.cluster_cell > 0).then(|| ClusterChoice {
            scene: self.scene,
            layout: self.layout,
            options: &self.options,
            totals: self.ledger.totals(),
            emitted_power: self.ledger.emitted_power(),
            clusters: &self.clusters,
            face_clusters: self.face_clusters.as_ref(),
        });
        for p in self.next_polygons(k.min(left as usize).max(1)) {
            if taken.contains(&p) {
                continue;
            }
            let cluster = clustered.as_ref().and_then(|c| c.cluster_of(p, &taken));
            let (mut cells, cluster) = match cluster {
                Some((shooter, cluster)) => (vec![shooter], cluster),
                None => (self.shooters_of(p), Vec::new()),
            };
            // A polygon shot in a later pass of the step would have received from the earlier
            // ones and then lost it to its remainder; so either one polygon (its cells K to a
            // pass: they send each other nothing), or polygons that share one pass.
            if !shooters.is_empty() && shooters.len() + cells.len() > k {
                break;
            }
            if self.options.rotate_item_buffer {
                // Each polygon of the step its own turn, as if shot one after another.
                let turn = super::turn_of_shot(self.ledger.shots() + units);
                cells.iter_mut().for_each(|s| s.turn = turn);
            }
            units += 1;
            taken.push(p);
            for m in cluster {
                taken.push(m.polygon);
                members.push(Member {
                    shooter: shooters.len(),
                    ..m
                });
            }
            shooters.append(&mut cells);
        }
        (shooters, members)
    }

    /// One shot of the polygons of `shooters` (texels in the caller's layout): a visibility pass
    /// per shooter, and a reconstruction pass and the accumulation per `shooters_per_pass` of
    /// them (in the paper one shooter, the whole polygon: one pass of each), then one readback.
    /// The shooters of one reconstruction pass shoot simultaneously (see
    /// `SolveOptions::shooters_per_pass`). Shooters of several polygons must fit in one pass, as
    /// `step` picks them: a polygon shot in a later pass would lose what it received in an earlier
    /// one. The shot counts one per polygon.
    pub fn shoot(&mut self, shooters: &[Shooter]) -> Result<ShotRecord, SolveError> {
        self.shoot_step(shooters, &[])
    }

    /// [`shoot`](Self::shoot), with the members of the clusters among `shooters` (see
    /// [`Member`]): their unshot energy is cleared before the passes, and the shot's books count
    /// each member's energy as carried (so a cluster's shot is judged as its members' shots
    /// would be). A cluster counts as one shot.
    fn shoot_step(
        &mut self,
        shooters: &[Shooter],
        members: &[Member],
    ) -> Result<ShotRecord, SolveError> {
        let polygon = shooters.first().map(|s| s.polygon).unwrap_or(0);
        let mut polygons: Vec<usize> = shooters.iter().map(|s| s.polygon).collect();
        polygons.dedup();
        let before = self.ledger.unshot_power();
        let shot_power: f64 = shooters.iter().map(|s| s.power()).sum();
        let mut own: Vec<Shooter> = shooters
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
        if !members.is_empty() {
            // Cleared before the passes, so that the members keep what the pass's other
            // shooters send them, as a shooting texel does.
            let cleared: Vec<usize> = members.iter().map(|m| m.polygon).collect();
            let (backend, times) = (&mut self.backend, &mut self.ledger.times);
            times.time(RECONSTRUCTION, || backend.clear_unshot(&cleared))?;
            self.cluster_shots += 1;
            if members.iter().any(|m| m.face) {
                self.face_cluster_shots += 1;
                let parts = cluster_parts::parts_of(self.scene, self.layout, &mut own, members);
                let (backend, times) = (&mut self.backend, &mut self.ledger.times);
                times.time(RECONSTRUCTION, || backend.parts(&parts))?;
            }
        }
        self.run_passes(&own, true)?;
        let mut totals_before = self.read_back()?;
        let books = books_of(&own, members);
        let mut balance = self.balance_of(&books, &totals_before);
        // Beyond the paper: a shot whose receivers got more than it carried is scaled back.
        if self.options.conserve && balance.excess() > find_max_energy::CORRECT_ABOVE {
            let correction = find_max_energy::correction(&own, &balance);
            // The item buffers of a single pass are still in their slots; several passes drew
            // over each other's.
            let redraw = own.len() > self.options.shooters_per_pass.max(1) as usize;
            self.run_passes(&correction, redraw)?;
            // A flag per polygon: a search of the list per polygon took Lost Empire's solve
            // O(changed²), tens of thousands of receivers, 59 % of its time.
            let mut known = vec![false; self.scene.polygons.len()];
            totals_before.iter().for_each(|&(q, _)| known[q] = true);
            for (p, old) in self.read_back()? {
                if !known[p] {
                    totals_before.push((p, old));
                }
            }
            balance = self.balance_of(&books, &totals_before);
            self.ledger.count_correction();
        }
        let (carried, received) = (balance.carried_power(), balance.received_power());
        let count = polygons.len() as u32;
        let record = self
            .ledger
            .record_shot(polygon, count, before, shot_power, carried, received);
        self.check_balance(&record, &balance, &totals_before)?;
        Ok(record)
    }

    /// The books of a shot of `shooters` from the changed polygons' totals `before` it, judged
    /// with the float noise of the atlas's sums: [`find_max_energy::EMITTED_NOISE`] of the
    /// emitted energy per channel, in the ledger's energy units (Σ L·A).
    fn balance_of(&self, shooters: &[Shooter], before: &[(usize, [f64; 3])]) -> ShotBalance {
        let floor =
            find_max_energy::EMITTED_NOISE * self.ledger.emitted_power() / std::f64::consts::PI;
        ShotBalance::measure(self.scene, shooters, before, self.ledger.totals(), floor)
    }

    /// The passes of one shot: for each `shooters_per_pass` of `shooters`, a visibility pass per
    /// shooter (unless `draw_visibility` is off: their item buffers are already in their slots),
    /// a reconstruction pass and the accumulation.
    fn run_passes(
        &mut self,
        shooters: &[Shooter],
        draw_visibility: bool,
    ) -> Result<(), SolveError> {
        for pass in shooters.chunks(self.options.shooters_per_pass.max(1) as usize) {
            let (backend, times) = (&mut self.backend, &mut self.ledger.times);
            if draw_visibility {
                times.time(VISIBILITY, || backend.visibility_pass(pass))?;
            }
            times.time(RECONSTRUCTION, || backend.reconstruction(pass))?;
            times.time(ACCUMULATION, || backend.accumulate())?;
            self.ledger.count_pass();
        }
        Ok(())
    }

    /// Read the unshot atlas back and re-total the polygons the passes changed (the end of
    /// step 5, before Find_Max_Energy); their totals before, for the shot's books.
    fn read_back(&mut self) -> Result<Vec<(usize, [f64; 3])>, SolveError> {
        let (backend, times) = (&mut self.backend, &mut self.ledger.times);
        times.time(READBACK, || backend.read_unshot(&mut self.changed))?;
        let t = Instant::now();
        let before = self
            .changed
            .iter()
            .map(|&p| (p, self.ledger.totals().energy[p]))
            .collect();
        let width = self.backend.layout().atlas_width as usize;
        self.ledger
            .update(self.backend.unshot(), width, &self.texels, &self.changed);
        self.ledger.times.add(FIND_MAX_ENERGY, t.elapsed());
        Ok(before)
    }

    /// Energy balance. With `SolveOptions::conserve` no shot may deliver more than it carried
    /// (0.5 % for float noise), since over-delivering shots were scaled back; one that does is an
    /// error. Without it (the paper's mode), such a shot is reported once as a warning: the
    /// receivers' patch centres sample the form factor, and the paper's point factor has no bound
    /// near the shooter. Either way energy is created at the scale of the scene when the unshot
    /// power passes the emitted power (or what `load_atlases` started from), or stops being a
    /// number; going on would make every later shot and the picture wrong, so the solve stops
    /// there and names the polygons.
    fn check_balance(
        &self,
        record: &ShotRecord,
        balance: &ShotBalance,
        totals_before: &[(usize, [f64; 3])],
    ) -> Result<(), SolveError> {
        let over = balance.excess() > find_max_energy::TOLERANCE || balance.excess().is_nan();
        let ceiling = self.unshot_ceiling.max(self.ledger.emitted_power());
        let growth = self.ledger.unshot_power() / ceiling;
        // Overshooting leaves negative unshot energy behind, so the magnitude may pass the
        // ceiling a little (the signed total may not); twice over is a runaway all the same.
        let magnitude = self.ledger.unshot_fraction() * self.ledger.emitted_power() / ceiling;
        let runaway =
            growth > 1.0 + 5e-3 || !growth.is_finite() || !magnitude.is_finite() || magnitude > 2.0;
        let refused = runaway || (over && self.options.conserve);
        if !refused {
            if over && !self.excess_reported.replace(true) {
                eprintln!(
                    "warning: shot {} delivered {:.3}x the power it carried ({}); the patches near \
                     the shooter sample its form factor coarsely. The solve goes on while the \
                     unshot power stays below the emitted power",
                    record.shot,
                    balance.excess(),
                    crate::scene::shown(&self.scene.polygons[record.shooter].object)
                );
            }
            return Ok(());
        }
        // The paper's point form factor has no bound near the shooter (in the simple room a sofa
        // 2 cm from a wall receives 2.8x what the wall shot, and the solve runs away to NaN),
        // so in the paper's mode the excess is the algorithm's own; still the answer would be
        // wrong, so it stops too, and says so.
        let cause = if self.options.form_factor == super::FormFactorKind::Point {
            "The point form factor (--form-factor point, as in --mode paper) has no bound for \
             receivers close to the shooter; the polygon form factor (--form-factor polygon, \
             --mode accurate) keeps the balance"
        } else if !runaway {
            "A shot delivered more than it carried after it was scaled back: this is a bug; \
             please report it with the scene"
        } else {
            "Overlapping faces in one plane (a face given twice) or intersecting faces do this; \
             remove the duplicates"
        };
        let (scene, after) = (self.scene, self.ledger.totals());
        let error = find_max_energy::energy_created(
            scene,
            record,
            balance,
            totals_before,
            after,
            growth,
            cause,
        );
        Err(error)
    }

    /// Run to the stopping rule; `progress` sees every shot.
    pub fn solve(&mut self, progress: impl FnMut(&ShotRecord)) -> Result<(), SolveError> {
        self.solve_until(progress, || false)
    }

    /// [`solve`](Self::solve), also stopped, between shots, when `stop` says so (an interrupt, a
    /// time limit): the solution so far is then as good as any shot's.
    pub fn solve_until(
        &mut self,
        mut progress: impl FnMut(&ShotRecord),
        stop: impl FnMut() -> bool,
    ) -> Result<(), SolveError> {
        self.solve_with_until(
            |_| {},
            |_, record| {
                progress(record);
                Ok::<(), SolveError>(())
            },
            stop,
        )
    }

    /// Run to the stopping rule, calling `before` ahead of every shot and `after` once it is
    /// taken (to picture the passes, say); the time they take is kept out of the solver's clock
    /// (the history's seconds). An error from `after` stops the solve.
    pub fn solve_with<E: From<SolveError>>(
        &mut self,
        before: impl FnMut(&Self),
        after: impl FnMut(&Self, &ShotRecord) -> Result<(), E>,
    ) -> Result<(), E> {
        self.solve_with_until(before, after, || false)
    }

    /// [`solve_with`](Self::solve_with), also stopped between shots when `stop` says so.
    pub fn solve_with_until<E: From<SolveError>>(
        &mut self,
        mut before: impl FnMut(&Self),
        mut after: impl FnMut(&Self, &ShotRecord) -> Result<(), E>,
        mut stop: impl FnMut() -> bool,
    ) -> Result<(), E> {
        self.ledger.restart_clock();
        loop {
            if stop() {
                return Ok(());
            }
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
    /// would carry the most: `Overshoot::max_shot_polygons`).
    pub fn next_polygon(&self) -> Option<usize> {
        self.next_polygons(1).first().copied()
    }

    /// Find_Max_Energy for `count` shooters at once: the `count` polygons that would carry the
    /// most, most first (fewer when fewer have anything to shoot).
    pub fn next_polygons(&self, count: usize) -> Vec<usize> {
        match &self.overshoot {
            Some(o) => o.max_shot_polygons(self.ledger.totals(), count),
            None => self.ledger.max_energy_polygons(count),
        }
    }

    /// The shooters that carry polygon `p`'s unshot energy (see `shooters::shooters_of`), their
    /// texels in the caller's layout; with their overshoot, item-buffer resolution and turn when
    /// the options go beyond the paper there.
    pub fn shooters_of(&self, p: usize) -> Vec<Shooter> {
        let own = self.backend.layout();
        let remainder = self
            .overshoot
            .as_ref()
            .map(|o| o.remainder(self.ledger.totals(), p));
        let emitter = self.scene.material(&self.scene.polygons[p]).is_emitter();
        let options = &self.options;
        let cell = if emitter {
            options.emitter_cell
        } else {
            options.shooter_cell
        };
        let mut shooters = if cell == 0 {
            let totals = self.ledger.totals();
            vec![whole_polygon(self.scene, own, totals, p, options.hemi_res)]
        } else {
            self.cells_of(p, cell, remainder.unwrap_or(Vec3::ZERO))
        };
        for s in &mut shooters {
            if let Some(remainder) = remainder {
                // Each of the shooter's patches shoots −remainder more radiance.
                let area = s.patches as f64 * self.ledger.patch_area(p);
                s.energy -= remainder * area as f32;
                s.remainder = remainder;
            }
            s.hemi_res = self.item_buffer_resolution(s);
            if self.options.rotate_item_buffer {
                s.turn = super::turn_of_shot(self.ledger.shots());
            }
            s.texels = move_rect(s.texels, &own.lightmaps[p], &self.layout.lightmaps[p]);
        }
        // A part with nothing to shoot (and no overshoot to add) costs a pass for nothing. A
        // whole polygon stays (Find_Max_Energy never picks one with nothing; callers that ask
        // for a given polygon's shooter, as the item-buffer tests do, get it).
        if cell != 0 {
            shooters.retain(|s| s.energy != glam::Vec3::ZERO);
        }
        shooters
    }

    /// Beyond the paper: polygon `p`'s cells of `cell` patches a side (`shooters::shooters_of`),
    /// as many and as finely cut as what the shot moves patch by patch asks for (with
    /// overshooting's `remainder` taken back, `shot_magnitude`), not what the polygon holds.
    fn cells_of(&self, p: usize, cell: u32, remainder: Vec3) -> Vec<Shooter> {
        let own = self.backend.layout();
        let patch_area = self.ledger.patch_area(p);
        let unshot = self.backend.unshot();
        let power = shooters::shot_magnitude(own, unshot, p, remainder, patch_area);
        let share = power / self.ledger.emitted_power();
        shooters::shooters_of(
            self.scene,
            own,
            &self.options,
            unshot,
            self.ledger.patch_areas(),
            p,
            shooters::cells_of_shot(&self.options, cell, share),
            shooters::shot_cap(self.max_cells, share, self.options.cut_above),
        )
    }

    /// The item-buffer resolution for shooter `s` ([`super::item_buffer_side`]).
    fn item_buffer_resolution(&self, s: &Shooter) -> u32 {
        super::item_buffer_side(&self.options, s.power() / self.ledger.emitted_power())
    }

    /// Whether the stopping rule holds: unshot fraction below the threshold, or `max_shots` made.
    pub fn converged(&self) -> bool {
        self.ledger
            .converged(self.options.threshold, self.options.max_shots)
    }

    /// Unshot power over emitted power, as last read back.
    pub fn unshot_fraction(&self) -> f64 {
        self.ledger.unshot_fraction()
    }

    /// The scene's emitted power (radiance × area × π, RGB mean).
    pub fn emitted_power(&self) -> f64 {
        self.ledger.emitted_power()
    }

    /// Shots so far.
    pub fn shots(&self) -> u32 {
        self.ledger.shots()
    }

    /// Visibility + reconstruction pass pairs run so far (one per shooter cell of each shot).
    pub fn passes(&self) -> u32 {
        self.ledger.passes()
    }

    /// The scene's clusters of small coplanar polygons (none unless `cluster_cell` is set and
    /// the scene's polygons are small; `clusters.rs`).
    pub fn clusters(&self) -> &Clusters {
        &self.clusters
    }

    /// Shots so far in which a cluster shot (each counts as one shot).
    pub fn cluster_shots(&self) -> u32 {
        self.cluster_shots
    }

    /// The hierarchy of face clusters (`SolveOptions::face_clusters`), if the solve uses one.
    pub fn face_clusters(&self) -> Option<&FaceClusters> {
        self.face_clusters.as_ref()
    }

    /// Of [`cluster_shots`](Self::cluster_shots), the steps in which a face cluster shot.
    pub fn face_cluster_shots(&self) -> u32 {
        self.face_cluster_shots
    }

    /// Every shot so far, in order.
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

    /// Area of one patch of each polygon.
    pub fn patch_areas(&self) -> &[f64] {
        self.ledger.patch_areas()
    }

    /// The settings it solves with.
    pub fn options(&self) -> &SolveOptions {
        &self.options
    }

    /// The backend doing the passes (the tests read its passes' counters).
    pub fn backend(&self) -> &B {
        &self.backend
    }

    /// The backend, to change (tests that plant a state).
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

/// The shooters as a shot's books count them: a cluster's shooter (`members`' `shooter`) as one
/// shooter per member, with the member's polygon and energy, so that each member's fall in
/// unshot energy counts as carried, not as a loss.
fn books_of(shooters: &[Shooter], members: &[Member]) -> Vec<Shooter> {
    if members.is_empty() {
        return shooters.to_vec();
    }
    let mut books: Vec<Shooter> = (shooters.iter().enumerate())
        .filter(|&(i, _)| !members.iter().any(|m| m.shooter == i))
        .map(|(_, s)| *s)
        .collect();
    books.extend(members.iter().map(|m| Shooter {
        polygon: m.polygon,
        energy: m.energy,
        ..shooters[m.shooter]
    }));
    books
}

/// A texel rectangle of lightmap `from` at the same place in `to` (the same lightmap elsewhere);
/// a shooter that owns no texels (`[0; 4]`: a cluster's) owns none there either.
/// The paper's shooter: polygon `p` shoots its whole unshot energy from its centroid, with its
/// own outline for the polygon form factor (its lightmap's rectangle where it has more corners
/// than a shooter holds).
fn whole_polygon(
    scene: &Scene,
    layout: &PatchLayout,
    totals: &EnergyTotals,
    p: usize,
    hemi_res: u32,
) -> Shooter {
    let polygon = &scene.polygons[p];
    let lm = &layout.lightmaps[p];
    let (corners, corner_count, area) = lm.polygon_outline::<MAX_CORNERS>(&polygon.vertices);
    Shooter {
        polygon: p,
        texels: lm.texels(),
        patches: layout.patches_per_polygon[p],
        position: polygon.centroid,
        normal: polygon.normal,
        energy: totals.energy_rgb(p),
        corners,
        corner_count,
        area,
        remainder: Vec3::ZERO,
        hemi_res,
        turn: 0.0,
        parts: Default::default(),
    }
}

fn move_rect(r: [u32; 4], from: &Lightmap, to: &Lightmap) -> [u32; 4] {
    if r == [0; 4] {
        return r;
    }
    let (x, y) = (|t: u32| t - from.x + to.x, |t: u32| t - from.y + to.y);
    [x(r[0]), y(r[1]), x(r[2]), y(r[3])]
}
