//! The CPU solver: the same progressive refinement as the GPU solver — same patches, same
//! lightmap atlas layout (alpha = polygon ID + 1), same Find_Max_Energy, same shooters, same
//! form factors — in plain Rust, multi-threaded with rayon. Visibility is exact (shadow rays
//! against a BVH). Each patch's ΔL is computed independently and the sums are sequential, so
//! the result is bit-identical for every thread count.

pub mod reconstruction;

use super::progressive::{Backend, Solver};
use super::{Part, Shooter, SolveError, SolveOptions};
use crate::patches::PatchLayout;
use crate::scene::bvh::Bvh;
use crate::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;
use reconstruction::Receiver;

/// Progressive refinement on the CPU.
pub type CpuSolver<'a> = Solver<'a, CpuBackend<'a>>;

/// The CPU's lightmaps, receivers and shadow-ray BVH.
pub struct CpuBackend<'a> {
    layout: &'a PatchLayout,
    form_factor: super::FormFactorKind,
    /// `Scene::plane_slack`: within it of a plane counts as on it.
    slack: f32,
    bvh: Bvh,
    receivers: Vec<Receiver>,
    /// ΔL of every receiver from the current shooter.
    deltas: Vec<Vec3>,
    radiosity: Vec<f32>,
    unshot: Vec<f32>,
    /// Which polygons the current shot changed.
    marked: Vec<bool>,
    /// The step's face-cluster parts (`Backend::parts`).
    parts: Vec<Part>,
    pool: rayon::ThreadPool,
}

impl<'a> Solver<'a, CpuBackend<'a>> {
    /// The CPU solver for `scene` laid out as `layout`, on `threads` worker threads (0: one per
    /// core); every patch's unshot energy starts as its emission.
    pub fn new(
        scene: &'a Scene,
        layout: &'a PatchLayout,
        options: SolveOptions,
        threads: usize,
    ) -> Result<Self, SolveError> {
        let backend = CpuBackend::new(scene, layout, &options, threads)?;
        let hierarchy = super::clusters::face_clusters(scene, layout, &options);
        Solver::start(scene, layout, options, backend, hierarchy)
    }
}

impl<'a> CpuBackend<'a> {
    fn new(
        scene: &Scene,
        layout: &'a PatchLayout,
        options: &SolveOptions,
        threads: usize,
    ) -> Result<Self, SolveError> {
        options.check(None)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|source| SolveError::Threads { threads, source })?;
        let n = layout.atlas_width as usize * layout.atlas_height as usize;
        let receivers = reconstruction::receivers(scene, layout);
        let mut radiosity = vec![0f32; n * 4];
        for r in &receivers {
            let ke = scene.material(&scene.polygons[r.polygon as usize]).ke;
            let id = (r.polygon + 1) as f32;
            radiosity[r.texel * 4..r.texel * 4 + 4].copy_from_slice(&[ke.x, ke.y, ke.z, id]);
        }
        let unshot = radiosity.clone();
        Ok(CpuBackend {
            layout,
            form_factor: options.form_factor,
            slack: scene.plane_slack(),
            bvh: Bvh::new(scene),
            deltas: vec![Vec3::ZERO; receivers.len()],
            parts: Vec::new(),
            receivers,
            radiosity,
            unshot,
            marked: vec![false; scene.polygons.len()],
            pool,
        })
    }
}

impl Backend for CpuBackend<'_> {
    fn layout(&self) -> &PatchLayout {
        self.layout
    }

    fn unshot(&self) -> &[f32] {
        &self.unshot
    }

    /// Nothing to draw: visibility is a shadow ray per receiver against the BVH, cast in the
    /// reconstruction only where the form factor is not zero.
    fn visibility(&mut self, _: &Shooter, _: usize) -> Result<(), SolveError> {
        Ok(())
    }

    fn reconstruction(&mut self, shooters: &[Shooter]) -> Result<(), SolveError> {
        let (bvh, receivers, kind) = (&self.bvh, &self.receivers, self.form_factor);
        let (slack, parts) = (self.slack, &self.parts[..]);
        let deltas = &mut self.deltas;
        // Each receiver's ΔL from every shooter, summed in the shooters' order (as the shader).
        self.pool.install(|| {
            deltas
                .par_iter_mut()
                .zip(receivers.par_iter())
                .for_each(|(d, r)| {
                    *d = shooters.iter().fold(Vec3::ZERO, |sum, s| {
                        sum + reconstruction::delta(r, s, parts, kind, slack, bvh)
                    })
                });
        });
        // The sums, in receiver order (the same for any thread count); the shooting texels'
        // unshot radiance their remainder (zero in the paper) plus what the other shooters send.
        let width = self.layout.atlas_width as usize;
        for (r, d) in self.receivers.iter().zip(&self.deltas) {
            let at = r.texel * 4;
            let p = r.polygon as usize;
            let (x, y) = (r.texel % width, r.texel / width);
            let shooting = shooters.iter().find(|s| {
                let [x0, y0, x1, y1] = s.texels.map(|v| v as usize);
                s.polygon == p && (x0..x1).contains(&x) && (y0..y1).contains(&y)
            });
            if shooters.iter().any(|s| s.polygon == p) || *d != Vec3::ZERO {
                self.marked[p] = true;
            }
            if let Some(s) = shooting {
                self.unshot[at..at + 3].copy_from_slice(&s.remainder.to_array());
            }
            for c in 0..3 {
                self.radiosity[at + c] += d[c];
                self.unshot[at + c] += d[c];
            }
        }
        Ok(())
    }

    /// Nothing to copy: the reconstruction added into the lightmaps themselves.
    fn accumulate(&mut self) -> Result<(), SolveError> {
        Ok(())
    }

    fn read_unshot(&mut self, changed: &mut Vec<usize>) -> Result<(), SolveError> {
        changed.clear();
        for (p, m) in self.marked.iter_mut().enumerate() {
            if std::mem::take(m) {
                changed.push(p);
            }
        }
        Ok(())
    }

    fn radiosity(&self) -> Vec<f32> {
        self.radiosity.clone()
    }

    fn load(&mut self, radiosity: &[f32], unshot: &[f32]) -> Result<(), SolveError> {
        self.radiosity.copy_from_slice(radiosity);
        self.unshot.copy_from_slice(unshot);
        self.marked.fill(true);
        Ok(())
    }

    fn parts(&mut self, parts: &[Part]) -> Result<(), SolveError> {
        self.parts = parts.to_vec();
        Ok(())
    }

    fn clear_unshot(&mut self, polygons: &[usize]) -> Result<(), SolveError> {
        let width = self.layout.atlas_width as usize;
        for &p in polygons {
            let lm = &self.layout.lightmaps[p];
            let id = (p + 1) as f32;
            for y in lm.y as usize..(lm.y + lm.h) as usize {
                let row = (y * width + lm.x as usize) * 4..(y * width + (lm.x + lm.w) as usize) * 4;
                for texel in self.unshot[row].chunks_exact_mut(4) {
                    if texel[3] == id {
                        texel[..3].fill(0.0);
                    }
                }
            }
            self.marked[p] = true;
        }
        Ok(())
    }
}
