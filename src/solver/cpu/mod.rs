//! The CPU solver: the same progressive refinement as the GPU solver — same patches, same
//! lightmap atlas layout (alpha = polygon ID + 1), same Find_Max_Energy, same shooters, same
//! form factors — in plain Rust, multi-threaded with rayon. Visibility is exact (shadow rays
//! against a BVH). Each patch's ΔL is computed independently and the sums are sequential, so
//! the result is bit-identical for every thread count.

pub mod reconstruction;
pub mod visibility;

use super::find_max_energy::EnergyTotals;
use super::{shooters, Shooter, ShotRecord, SolveOptions};
use crate::patches::PatchLayout;
use crate::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;
use reconstruction::Receiver;
use std::time::Instant;
use visibility::Bvh;

#[derive(Debug, thiserror::Error)]
pub enum CpuError {
    #[error("cannot start {threads} worker threads: {source}")]
    Threads {
        threads: usize,
        source: rayon::ThreadPoolBuildError,
    },
    #[error(
        "the emitters have no patches at this patch size ({size} scene units): a light smaller \\
         than a patch emits nothing; use a smaller --patch-size or more --patches"
    )]
    NoEmission { size: f32 },
}

pub struct CpuSolver<'a> {
    scene: &'a Scene,
    layout: &'a PatchLayout,
    options: SolveOptions,
    bvh: Bvh,
    receivers: Vec<Receiver>,
    deltas: Vec<Vec3>,
    radiosity: Vec<f32>,
    unshot: Vec<f32>,
    patch_area: Vec<f64>,
    totals: EnergyTotals,
    /// Lightmap rectangles [x0, y0, x1, y1) per polygon; which polygons a shot changed.
    texels: Vec<[u32; 4]>,
    marked: Vec<bool>,
    changed: Vec<usize>,
    emitted_power: f64,
    shots: u32,
    pub passes: u32,
    started: Instant,
    pub history: Vec<ShotRecord>,
    pool: rayon::ThreadPool,
}

impl<'a> CpuSolver<'a> {
    /// `threads`: worker threads (0: one per core).
    pub fn new(
        scene: &'a Scene,
        layout: &'a PatchLayout,
        options: SolveOptions,
        threads: usize,
    ) -> Result<Self, CpuError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|source| CpuError::Threads { threads, source })?;
        let n = layout.atlas_width as usize * layout.atlas_height as usize;
        let (mut radiosity, mut receivers) = (vec![0f32; n * 4], Vec::new());
        for (texel, &owner) in layout.owner.iter().enumerate() {
            if owner == 0 {
                continue;
            }
            let p = owner as usize - 1;
            let polygon = &scene.polygons[p];
            let material = scene.material(polygon);
            let lm = &layout.lightmaps[p];
            let (x, y) = (
                texel % layout.atlas_width as usize,
                texel / layout.atlas_width as usize,
            );
            let centre = lm.world(
                (x - lm.x as usize) as f32 + 0.5,
                (y - lm.y as usize) as f32 + 0.5,
            );
            receivers.push(Receiver {
                texel,
                polygon: p as u32,
                centre,
                normal: polygon.normal,
                rho: material.kd,
            });
            radiosity[texel * 4..texel * 4 + 4].copy_from_slice(&[
                material.ke.x,
                material.ke.y,
                material.ke.z,
                owner as f32,
            ]);
        }
        let unshot = radiosity.clone();
        let patch_area: Vec<f64> = scene
            .polygons
            .iter()
            .zip(&layout.patches_per_polygon)
            .map(|(p, &k)| if k > 0 { p.area as f64 / k as f64 } else { 0.0 })
            .collect();
        let totals = EnergyTotals::sum(&unshot, scene.polygons.len(), Some(&patch_area));
        let emitted_power = totals.total_power();
        if emitted_power <= 0.0 {
            return Err(CpuError::NoEmission {
                size: layout.patch_size,
            });
        }
        Ok(CpuSolver {
            scene,
            layout,
            options,
            bvh: Bvh::new(scene),
            deltas: vec![Vec3::ZERO; receivers.len()],
            receivers,
            radiosity,
            unshot,
            patch_area,
            totals,
            texels: layout.texel_rects(),
            marked: vec![false; scene.polygons.len()],
            changed: Vec::new(),
            emitted_power,
            shots: 0,
            passes: 0,
            started: Instant::now(),
            history: Vec::new(),
            pool,
        })
    }

    pub fn shots(&self) -> u32 {
        self.shots
    }

    pub fn emitted_power(&self) -> f64 {
        self.emitted_power
    }

    pub fn unshot_fraction(&self) -> f64 {
        self.totals.total_power() / self.emitted_power
    }

    pub fn converged(&self) -> bool {
        self.unshot_fraction() <= self.options.threshold as f64
            || self.shots >= self.options.max_shots
    }

    pub fn next_polygon(&self) -> Option<usize> {
        self.totals.find_max_energy(0.0)
    }

    pub fn shooters_of(&self, p: usize) -> Vec<Shooter> {
        shooters::shooters_of(
            self.scene,
            self.layout,
            &self.options,
            &self.unshot,
            &self.patch_area,
            &self.totals,
            p,
        )
    }

    pub fn step(&mut self) -> Option<ShotRecord> {
        if self.converged() {
            return None;
        }
        let p = self.next_polygon()?;
        let shooters = self.shooters_of(p);
        Some(self.shoot(&shooters))
    }

    /// One shot of one polygon from each of `shooters` in turn.
    pub fn shoot(&mut self, shooters: &[Shooter]) -> ShotRecord {
        let polygon = shooters.first().map(|s| s.polygon).unwrap_or(0);
        let before = self.totals.total_power();
        let shot_power: f64 = shooters.iter().map(|s| s.power()).sum();
        let kind = self.options.form_factor;
        for shooter in shooters {
            let (bvh, receivers) = (&self.bvh, &self.receivers);
            self.pool.install(|| {
                self.deltas
                    .par_iter_mut()
                    .zip(receivers.par_iter())
                    .for_each(|(d, r)| *d = reconstruction::delta(r, shooter, kind, bvh));
            });
            let [x0, y0, x1, y1] = shooter.texels.map(|v| v as usize);
            let width = self.layout.atlas_width as usize;
            for (r, d) in self.receivers.iter().zip(&self.deltas) {
                let at = r.texel * 4;
                if r.polygon as usize == shooter.polygon || *d != Vec3::ZERO {
                    self.marked[r.polygon as usize] = true;
                }
                if r.polygon as usize == shooter.polygon {
                    let (x, y) = (r.texel % width, r.texel / width);
                    if (x0..x1).contains(&x) && (y0..y1).contains(&y) {
                        self.unshot[at..at + 3].fill(0.0);
                    }
                    continue;
                }
                for c in 0..3 {
                    self.radiosity[at + c] += d[c];
                    self.unshot[at + c] += d[c];
                }
            }
            self.passes += 1;
        }
        // Re-total only the polygons the shot changed (as the GPU solver does).
        self.changed.clear();
        for (p, m) in self.marked.iter_mut().enumerate() {
            if std::mem::take(m) {
                self.changed.push(p);
            }
        }
        self.totals.update(
            &self.unshot,
            self.layout.atlas_width as usize,
            &self.texels,
            &self.changed,
            &self.patch_area,
        );
        self.shots += 1;
        let record = ShotRecord {
            shot: self.shots,
            shooter: polygon,
            seconds: self.started.elapsed().as_secs_f64(),
            unshot_fraction: self.unshot_fraction(),
            shot_power,
            reflected_power: self.totals.total_power() - (before - shot_power),
        };
        self.history.push(record.clone());
        record
    }

    pub fn solve(&mut self, mut progress: impl FnMut(&ShotRecord)) {
        self.started = Instant::now();
        while let Some(record) = self.step() {
            progress(&record);
        }
    }

    /// The accumulated radiance atlas, RGBA (alpha: polygon ID + 1), rows bottom to top.
    pub fn radiosity_atlas(&self) -> Vec<f32> {
        self.radiosity.clone()
    }

    pub fn unshot_atlas(&self) -> &[f32] {
        &self.unshot
    }

    pub fn patch_area(&self, polygon: usize) -> f64 {
        self.patch_area[polygon]
    }

    pub fn patch_areas(&self) -> &[f64] {
        &self.patch_area
    }
}
