//! The llvmpipe engine's [`ItemBufferFill`]: each view draws what [`Culling`] leaves (or, with
//! the hidden-polygon walk, the item buffer is written on the CPU and uploaded), coplanar
//! neighbours drawn as plates, and the next shots' lists built on other threads while one is
//! drawn. Every switch it reads is documented in [`Tuning`].

use super::culling::{Culling, Lists, Triangles};
use super::plates::Plates;
use super::seen_receivers::{Reach, SeenReceivers};
use crate::gl::{GlContext, GlError};
use crate::scene::Scene;
use crate::solver::mesh::SceneMesh;
use crate::solver::visibility::{self, one_by_one, DrawList, Filled, ItemBufferFill, Shot};
use crate::solver::{Tuning, VisibilityKind};
use glow::HasContext;
use std::any::Any;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Threads that build a pass's draw lists besides the one that draws (`CulledViews::pass`).
const BUILDERS: usize = 2;

/// The engine's fill of a visibility pass's item buffers.
pub struct CulledViews {
    kind: VisibilityKind,
    tuning: Tuning,
    /// Coplanar polygons drawn as one (`merge_plates`; at first every polygon alone).
    pub(super) plates: Plates,
    /// What each view may leave out, and its buffers.
    pub(super) culling: Culling,
    /// Whether the tuning asks for culling at all (`Culling::asked`); if not, every view draws
    /// the whole scene.
    culls: bool,
    /// The draw lists of `pass`, one per shooter of a pass, kept for the next.
    pass_lists: Vec<Lists>,
    /// Per slot, the polygons that may receive from its shot, when the walk wrote its item
    /// buffer (`Tuning::walk_receivers`).
    pub(super) receivers: Vec<Option<Reach>>,
}

/// Keep `receivers` in `kept` (reusing its allocation).
fn keep(kept: &mut Option<Reach>, receivers: Option<&Reach>) {
    match receivers {
        Some(r) => kept.get_or_insert_with(Default::default).clone_from(r),
        None => *kept = None,
    }
}

impl CulledViews {
    /// Whether `tuning` asks a pass of `kind` for anything the paper's drawn views do not do:
    /// culling, plates, or a flush after each draw.
    pub fn wanted(tuning: &Tuning, kind: VisibilityKind) -> bool {
        Culling::asked(tuning, kind)
            || kind == VisibilityKind::Hemicube && tuning.plates
            || tuning.flush_visibility
    }

    /// The fill of a pass of `kind` at `resolution` with `slots` item buffers over `scene`.
    pub fn new(
        ctx: &GlContext,
        scene: &Scene,
        kind: VisibilityKind,
        resolution: u32,
        tuning: Tuning,
        slots: u32,
    ) -> Self {
        let near_far = visibility::near_far(scene);
        let guard = visibility::guard_band(ctx, kind, resolution, tuning.guard_band);
        CulledViews {
            kind,
            tuning,
            plates: Plates::none(scene.polygons.len()),
            culling: Culling::new(scene, kind, tuning, near_far, guard),
            culls: Culling::asked(&tuning, kind),
            pass_lists: Vec::new(),
            receivers: vec![None; slots.max(1) as usize],
        }
    }

    /// Merge coplanar polygons outside the solids into plates (`Tuning::plates`; hemicube
    /// only). See `VisibilityPass::merge_plates`.
    pub fn merge_plates(&mut self, scene: &Scene) -> &Plates {
        if self.kind == VisibilityKind::Hemicube && self.tuning.plates {
            let solids = &self.culling.solids;
            self.plates = Plates::find(scene, |p| solids.solid_of[p].is_none());
            self.culling.use_plates(scene, &self.plates);
        }
        &self.plates
    }
}

impl ItemBufferFill for CulledViews {
    fn shot<'a>(&'a mut self, mesh: &'a SceneMesh, shot: &Shot, slot: usize) -> Filled<'a> {
        let shooter_id = self.plates.representative[shot.shooter.polygon];
        if !self.culls {
            keep(&mut self.receivers[slot], None);
            let list = DrawList::whole(&mesh.triangles);
            return Filled::Drawn { list, shooter_id };
        }
        let (shooter, view, r) = (shot.shooter, shot.view, shot.r);
        self.culling.draw_list(mesh, shooter, view, &self.plates, r);
        keep(&mut self.receivers[slot], self.culling.receivers());
        let culling = &self.culling;
        match culling.written_item_buffer() {
            Some(bytes) => Filled::Written(bytes),
            None => Filled::Drawn {
                list: culling.last_list(),
                shooter_id,
            },
        }
    }

    /// The shots of a pass, as `shot` fills them one by one, but the next shots' draw lists
    /// are built on two other threads (`BUILDERS`) while this one's are put, and this one
    /// builds the next unclaimed list itself whenever the one it must put next is not ready.
    /// On llvmpipe the thread that issues the draws also transforms and sets up every
    /// triangle, and is the one the visibility pass waits for; building the lists
    /// (`Culling::build`) was a sixth of its time on Lost Empire, and more than drawing them
    /// once hidden polygons were left out; waiting for the builders left it idle a third of
    /// the pass (docs/perf-log.md). The same lists, so the same item buffers.
    fn pass(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shots: &[Shot],
        put: &mut dyn FnMut(usize, Filled<'_>) -> Result<(), GlError>,
    ) -> Result<(), GlError> {
        if !self.culls || shots.len() < 2 {
            return one_by_one(self, ctx, mesh, shots, put);
        }
        let ids: Vec<usize> = (shots.iter())
            .map(|s| self.plates.representative[s.shooter.polygon])
            .collect();
        let culling = self.culling.take();
        let plates = std::mem::take(&mut self.plates);
        let mut lists = std::mem::take(&mut self.pass_lists);
        lists.resize_with(shots.len(), Lists::default);
        let triangles = Triangles::of(mesh);
        // Each shot's list in a cell of its own; the next shot without a list is claimed by
        // whichever thread is free first: the builders, or this one when the list it must put
        // next is not ready (waiting for a builder left it idle a third of the pass).
        let cells: Vec<Mutex<Lists>> = lists.into_iter().map(Mutex::new).collect();
        let unclaimed = AtomicUsize::new(0);
        let claim = || {
            let k = unclaimed.fetch_add(1, Ordering::Relaxed);
            (k < cells.len()).then(|| {
                let mut built = cells[k].lock().expect("a builder does not panic");
                let s = &shots[k];
                culling.build(&mut built, triangles, s.shooter, s.view, &plates, s.r);
                k
            })
        };
        let flush = self.tuning.flush_visibility;
        let receivers = &mut self.receivers;
        let drawn = std::thread::scope(|scope| {
            let (done, arrivals) = std::sync::mpsc::channel();
            for _ in 0..BUILDERS {
                let done = done.clone();
                scope.spawn(move || {
                    while let Some(k) = claim() {
                        if done.send(k).is_err() {
                            break;
                        }
                    }
                });
            }
            drop(done);
            let mut ready = vec![false; shots.len()];
            let mut drawn = Ok(());
            for slot in 0..shots.len() {
                while !ready[slot] {
                    let k = match arrivals.try_recv() {
                        Ok(k) => k,
                        Err(_) => match claim() {
                            Some(k) => k,
                            None => arrivals.recv().expect("the builders send every list"),
                        },
                    };
                    ready[k] = true;
                }
                let built = cells[slot].lock().expect("a builder does not panic");
                keep(&mut receivers[slot], built.receivers());
                if let Some(bytes) = built.written_item_buffer() {
                    drawn = put(slot, Filled::Written(bytes));
                } else {
                    let list = built.draw_list();
                    drawn = put(
                        slot,
                        Filled::Drawn {
                            list,
                            shooter_id: ids[slot],
                        },
                    );
                    if drawn.is_ok() && flush {
                        unsafe { ctx.gl.flush() };
                    }
                }
                if drawn.is_err() {
                    // No more claims: the builders finish what they hold and stop.
                    unclaimed.store(shots.len(), Ordering::Relaxed);
                    break;
                }
            }
            drawn
        });
        let mut lists: Vec<Lists> = (cells.into_iter())
            .map(|c| c.into_inner().expect("a builder does not panic"))
            .collect();
        self.culling = culling;
        for l in &mut lists {
            self.culling.missed += std::mem::take(&mut l.missed);
            self.culling.hidden += std::mem::take(&mut l.hidden);
        }
        self.plates = plates;
        self.pass_lists = lists;
        drawn
    }

    /// A glFlush (`Tuning::flush_visibility`), so that llvmpipe rasterises the item buffer
    /// while the CPU goes on (it queues the draws and returns).
    fn after_draw(&self, ctx: &GlContext) {
        if self.tuning.flush_visibility {
            unsafe { ctx.gl.flush() };
        }
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// The receivers' test the walk runs from now on (`Tuning::walk_receivers`).
impl CulledViews {
    /// Find the receivers of every shot whose item buffer the walk writes from now on.
    pub fn use_seen_receivers(&mut self, seen: SeenReceivers) {
        self.culling.use_seen_receivers(seen);
    }
}
