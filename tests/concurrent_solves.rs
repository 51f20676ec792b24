//! GPU solves in several threads at once, each on a context of its own made and dropped in a
//! short-lived thread, as parallel tests and `bench` children use GL: each must give, bit for
//! bit, the answer the same solve gives alone. Contexts of one process share Mesa's screen (and,
//! on EGL, one display), so a context that disturbed another's state, or was torn down while
//! another drew, would show here as a different atlas or a crash.
mod common;
use common::*;
use gpu_radiosity::gl::{BackendChoice, GlContext};
use gpu_radiosity::patches::PatchLayout;
use gpu_radiosity::scene::Scene;
use gpu_radiosity::solver::{GpuSolver, SolveOptions};

const THREADS: usize = 4;
const ROUNDS: usize = 2;

/// The radiosity atlas of a short accurate-mode solve on a new context of `backend`, made and
/// dropped on the calling thread.
fn solve(backend: BackendChoice, scene: &Scene, layout: &PatchLayout) -> Vec<f32> {
    let ctx = GlContext::headless(backend).unwrap();
    let options = SolveOptions {
        threshold: 0.3,
        ..SolveOptions::accurate()
    };
    let mut solver = GpuSolver::new(&ctx, scene, layout, options).unwrap();
    solver.solve(|_| {}).unwrap();
    let atlas = solver.radiosity_atlas();
    ctx.check("concurrent solve").unwrap();
    atlas
}

#[test]
fn solves_in_several_threads_at_once_match_a_solve_alone() {
    let scene = load("box");
    let layout = layout(&scene, 1.0 / 8.0);
    let backends: Vec<_> = [BackendChoice::Egl, BackendChoice::Osmesa]
        .into_iter()
        .filter(|&b| GlContext::headless(b).is_ok())
        .collect();
    assert!(!backends.is_empty(), "no GL backend");
    for backend in backends {
        let alone = solve(backend, &scene, &layout);
        assert!(alone.iter().any(|&v| v > 0.0), "{backend:?}: a dark atlas");
        std::thread::scope(|s| {
            for t in 0..THREADS {
                let (scene, layout, alone) = (&scene, &layout, &alone);
                s.spawn(move || {
                    for round in 0..ROUNDS {
                        // A fresh thread per round: its context is its first and last.
                        let atlas = std::thread::scope(|inner| {
                            inner
                                .spawn(|| solve(backend, scene, layout))
                                .join()
                                .unwrap()
                        });
                        assert!(
                            atlas == *alone,
                            "{backend:?}, thread {t}, round {round}: not the atlas of a solve alone"
                        );
                    }
                });
            }
        });
    }
}
