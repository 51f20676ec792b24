//! Visibility pass (paper 3.2.1): the scene drawn from the shooter, polygon IDs as colours, into
//! an FBO whose colour attachment is a *texture* (so the reconstruction pass can sample it), with
//! a depth renderbuffer for hidden-surface removal. The IDs are all the reconstruction pass needs:
//! its robust test looks up the shown polygon's plane by ID.
//!
//! Two projections: the paper's hemispherical one (`glsl/hemiproj.vert`, one render onto the
//! unit disk) and the hemicube (`glsl/hemicube.vert`, five 90° perspective renders):
//!
//! ```text
//!   hemisphere: R x R          hemicube: 5R x R, one face per R x R block
//!   +--------+                 +-------+-------+-------+-------+-------+
//!   |  disk  |                 | front |  +x   |  -x   |  +y   |  -y   |
//!   +--------+                 +-------+-------+-------+-------+-------+
//! ```
//!
//! The paper draws the whole scene into each view. What this pass does besides, for llvmpipe's
//! sake, is switched by [`Tuning`] (each switch documented there): what each view leaves out, in
//! `culling` (views culled by bounding spheres, draws split by whether they need clipping,
//! coplanar neighbours drawn as one plate (`plates`), the far faces of convex solids left out
//! (`solids`), polygons between the pixel centres (`samples`)), and in the draw itself a guard
//! band around each hemicube face, half side faces, float depth, and a glFlush at the end.

mod box_tree;
pub mod culling;
pub mod occlusion;
pub mod plates;
pub mod samples;
pub mod seen_receivers;
pub mod solids;

use super::mesh::{SceneMesh, ATTRIBUTES};
use super::pass_names::VISIBILITY;
use super::{Shooter, Tuning, VisibilityKind};
use crate::gl::{
    Framebuffer, GlContext, GlError, IndexStream, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::glsl;
use crate::scene::Scene;
use culling::{Culling, DrawList, Lists, Triangles, ViewDraw};
use glam::{Mat3, Mat4, Vec3};
use glow::HasContext;
use plates::Plates;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The visibility pass (3.2.1): the scene drawn from a shooter into an item buffer of polygon
/// IDs, which the reconstruction pass reads to tell whether a receiver is seen.
pub struct VisibilityPass {
    program: Program,
    /// Hemicube or hemispherical projection.
    pub kind: VisibilityKind,
    /// The item buffers, one per shooter of a reconstruction pass (`with_slots`; one in the
    /// paper), each with its depth buffer and FBO.
    slots: Vec<ItemSlot>,
    resolution: i32,
    /// The speed switches this pass reads (see [`Tuning`]).
    tuning: Tuning,
    /// Each hemicube face is drawn in a viewport `guard` times its size, centred on it
    /// (`Tuning::guard_band`, made odd so that the face stays on whole pixels, and no wider than
    /// the driver's viewport; 1 on the hemisphere).
    guard: i32,
    near_far: [f32; 2],
    /// The part of the item buffer the last pass drew (width, height): all of it, or the
    /// lower-left corner for a shot at a smaller resolution (`Shooter::hemi_res`).
    drawn: (i32, i32),
    /// Coplanar polygons drawn as one (`merge_plates`; at first every polygon alone).
    plates: Plates,
    /// What each view may leave out, and its buffers.
    culling: Culling,
    /// Whether the tuning asks for culling at all (`Culling::asked`); if not, every view draws
    /// the whole scene.
    culls: bool,
    /// The triangles the views of the last shot drew.
    stream: IndexStream,
    /// The draw lists of `run_pass`, one per shooter of a pass, kept for the next.
    pass_lists: Vec<Lists>,
    /// Per slot, the polygons that may receive from its shot, when the walk wrote its item
    /// buffer (`Tuning::walk_receivers`).
    receivers: Vec<Option<seen_receivers::Reach>>,
}

/// One item buffer (RGBA8, ID + 1 in RGB, 0 = nothing seen) with its depth buffer and FBO.
struct ItemSlot {
    item_buffer: Texture,
    _depth: Renderbuffer,
    fbo: Framebuffer,
}

impl ItemSlot {
    fn new(
        gl: &std::rc::Rc<glow::Context>,
        width: i32,
        height: i32,
        float_depth: bool,
    ) -> Result<Self, GlError> {
        // NEAREST: an ID must never be blended with its neighbour's.
        let item_buffer = Texture::new(gl, width, height, TextureFormat::Rgba8, glow::NEAREST)?;
        // Float depth (GL 3.0) or 24-bit integers: `Tuning::float_depth`.
        let depth_format = if float_depth {
            glow::DEPTH_COMPONENT32F
        } else {
            glow::DEPTH_COMPONENT24
        };
        let depth = Renderbuffer::new(gl, depth_format, width, height)?;
        let fbo = Framebuffer::new(gl)?;
        fbo.attach_texture(glow::COLOR_ATTACHMENT0, &item_buffer);
        fbo.attach_renderbuffer(glow::DEPTH_ATTACHMENT, &depth);
        fbo.check_complete(VISIBILITY)?;
        Ok(ItemSlot {
            item_buffer,
            _depth: depth,
            fbo,
        })
    }
}

/// Keep `receivers` in `kept` (reusing its allocation).
fn keep(kept: &mut Option<seen_receivers::Reach>, receivers: Option<&seen_receivers::Reach>) {
    match receivers {
        Some(r) => kept.get_or_insert_with(Default::default).clone_from(r),
        None => *kept = None,
    }
}

/// Put the item buffer the walk wrote (`Tuning::walk_item_buffers`; RGBA8 `bytes` of the
/// lower-left 5r × r pixels) into `slot`'s texture, where the views would have drawn it.
fn write_item_buffer(
    ctx: &GlContext,
    slot: &ItemSlot,
    r: i32,
    bytes: &[u8],
) -> Result<(), GlError> {
    slot.item_buffer.upload_u8_region(5 * r, r, bytes);
    ctx.check(VISIBILITY)
}

/// The pixels of hemicube face `k` (x, y, width, height within the face) that look above the
/// shooter's horizon: all of the front face, half of each side face (see `face_rotations`:
/// +x and -x put the shooter's normal at their left and right, +y and -y at their bottom).
pub fn front_half(k: usize, r: i32) -> [i32; 4] {
    let h = (r + 1) / 2;
    match k {
        1 => [0, 0, h, r],
        2 => [r - h, 0, h, r],
        3 | 4 => [0, 0, r, h],
        _ => [0, 0, r, r],
    }
}

/// Threads that build a pass's draw lists besides the one that draws (`VisibilityPass::run_pass`).
const BUILDERS: usize = 2;

/// Hemicube faces as rotations of the shooter's eye space (which looks down -z): front, +x,
/// -x, +y, -y. The reconstruction shader uses the same matrices to find a direction's pixel.
pub fn face_rotations() -> [Mat3; 5] {
    let face = |dir: Vec3, up: Vec3| Mat3::from_mat4(Mat4::look_at_rh(Vec3::ZERO, dir, up));
    [
        face(Vec3::NEG_Z, Vec3::Y),
        face(Vec3::X, Vec3::Y),
        face(Vec3::NEG_X, Vec3::Y),
        face(Vec3::Y, Vec3::Z),
        face(Vec3::NEG_Y, Vec3::Z),
    ]
}

/// The item buffer's width and height at resolution `res`: the hemicube's five faces side by
/// side, or the hemisphere's one square.
pub fn item_buffer_size(kind: VisibilityKind, res: u32) -> (u64, u64) {
    let faces = match kind {
        VisibilityKind::Hemicube => 5,
        VisibilityKind::Hemisphere => 1,
    };
    (faces * res as u64, res as u64)
}

impl VisibilityPass {
    /// A pass with one item buffer (the paper's: one shooter per pass).
    pub fn new(
        ctx: &GlContext,
        kind: VisibilityKind,
        resolution: u32,
        tuning: Tuning,
        scene: &Scene,
    ) -> Result<Self, GlError> {
        Self::with_slots(ctx, kind, resolution, tuning, scene, 1)
    }

    /// A pass with `slots` item buffers, one for each shooter of one reconstruction pass
    /// (`SolveOptions::shooters_per_pass`; `run_in_slot`).
    pub fn with_slots(
        ctx: &GlContext,
        kind: VisibilityKind,
        resolution: u32,
        tuning: Tuning,
        scene: &Scene,
        slots: u32,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
        let scene_size = scene.size();
        // Passes of several shooters walk every side (`Tuning::walk_up_to`): the reach the walk
        // finds lets their reconstruction skip most of the atlas, which a drawn slot forfeits
        // for the whole pass.
        let tuning = if slots > 1 {
            Tuning {
                walk_up_to: 0,
                ..tuning
            }
        } else {
            tuning
        };
        let vertex = match kind {
            VisibilityKind::Hemisphere => glsl!("hemiproj.vert"),
            VisibilityKind::Hemicube => glsl!("hemicube.vert"),
        }
        .insert(&crate::gl::faults::item_id_source(
            &glsl!("item_id.glsl").text,
        ));
        let program = Program::new(
            gl,
            vertex,
            glsl!("itembuffer.frag"),
            ATTRIBUTES,
            &[(0, "Color")],
        )?;
        let res = resolution as i32;
        let width = item_buffer_size(kind, resolution).0 as i32;
        // NEAREST: an ID must never be blended with its neighbour's.
        let slots = (0..slots.max(1))
            .map(|_| ItemSlot::new(gl, width, res, tuning.float_depth))
            .collect::<Result<Vec<_>, GlError>>()?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(VISIBILITY)?;
        // Near plane: 1e-4 of the scene, so the shooter's own plane is clipped away but receivers
        // a hair in front of it are kept. Far plane: beyond anything in the scene.
        let near_far = [scene_size * 1e-4, scene_size * 2.0];
        let mut dims = [0; 2];
        unsafe { gl.get_parameter_i32_slice(glow::MAX_VIEWPORT_DIMS, &mut dims) };
        let fits = (dims[0].min(dims[1]) / res.max(1)).max(1);
        let wanted = tuning.guard_band.clamp(1, i32::MAX as u32) as i32;
        let guard = if kind == VisibilityKind::Hemicube {
            (fits.min(wanted) - 1) / 2 * 2 + 1
        } else {
            1
        };
        Ok(VisibilityPass {
            program,
            kind,
            receivers: vec![None; slots.len()],
            slots,
            resolution: res,
            tuning,
            guard,
            near_far,
            drawn: (width, res),
            plates: Plates::none(scene.polygons.len()),
            culling: Culling::new(scene, kind, tuning, near_far, guard),
            culls: Culling::asked(&tuning, kind),
            stream: IndexStream::new(gl)?,
            pass_lists: Vec::new(),
        })
    }

    /// Merge coplanar polygons outside the solids into plates (`Tuning::plates`; hemicube only:
    /// the hemispherical projection needs small polygons, and bigger ones would curve more). The
    /// caller then draws a mesh made by `Plates::vertex_data` from the plates returned; the item
    /// buffer shows each plate under its representative's ID. Only for the robust visibility
    /// test, which reads the shown polygon's plane, not its ID alone. With the switch off every
    /// polygon stays alone, and `Plates::vertex_data` gives the scene's own mesh.
    pub fn merge_plates(&mut self, scene: &Scene) -> &Plates {
        if self.kind == VisibilityKind::Hemicube && self.tuning.plates {
            let solids = &self.culling.solids;
            self.plates = Plates::find(scene, |p| solids.solid_of[p].is_none());
            self.culling.use_plates(scene, &self.plates);
        }
        &self.plates
    }

    /// The polygon whose ID the item buffer shows where polygon `p` is seen.
    pub fn shown_as(&self, p: usize) -> usize {
        self.plates.representative[p]
    }

    /// Draw the item buffer from `shooter` into the first slot, the paper's one (`run_in_slot`).
    pub fn run(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shooter: &Shooter,
    ) -> Result<(), GlError> {
        self.run_in_slot(ctx, mesh, shooter, 0)
    }

    /// `run` into item buffer `slot` (`with_slots`; `slot_texture`): the paper's "render the
    /// scene from the shooter", polygon IDs as colours, each view drawing what culling left
    /// (`culling`; the whole scene with `Tuning::none`).
    pub fn run_in_slot(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shooter: &Shooter,
        slot: usize,
    ) -> Result<(), GlError> {
        if slot >= self.slots.len() {
            return Err(GlError::Limit(format!(
                "item-buffer slot {slot} of a pass set up for {}",
                self.slots.len()
            )));
        }
        let view = shooter.view();
        let r = self.resolution_of(shooter);
        let views = self.upload_draw_list(mesh, shooter, view, r);
        keep(&mut self.receivers[slot], self.culling.receivers());
        if let Some(bytes) = self.culling.written_item_buffer() {
            write_item_buffer(ctx, &self.slots[slot], r, bytes)?;
            self.drawn = (5 * r, r);
            return Ok(());
        }
        let id = self.shown_as(shooter.polygon) as f32;
        self.draw(ctx, mesh, slot, id, view, r, views)
    }

    /// This shot's resolution (`SolveOptions::small_hemi_res`): the views fill the item
    /// buffer's lower-left corner, and the reconstruction pass looks up only that.
    fn resolution_of(&self, shooter: &Shooter) -> i32 {
        (shooter.hemi_res as i32).clamp(1, self.resolution)
    }

    /// Draw the views (`views`, in the uploaded draw list) from a shooter shown as `id`, with
    /// view matrix `view`, at `r` pixels per side, into slot `slot`.
    #[allow(clippy::too_many_arguments)]
    fn draw(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        slot: usize,
        id: f32,
        view: Mat4,
        r: i32,
        views: [ViewDraw; 5],
    ) -> Result<(), GlError> {
        self.clear_slot(ctx, slot, r);
        self.program.use_program();
        // The shooter's plate lies in the shooter's plane, which the near plane clips away;
        // the shaders put it beyond the far plane.
        self.program.set_f32("ShooterId", id);
        self.program.set_mat4("ShooterView", &view.to_cols_array());
        match self.kind {
            VisibilityKind::Hemisphere => self.draw_hemisphere(mesh, views[0]),
            VisibilityKind::Hemicube => self.draw_hemicube(ctx, mesh, &views, view, r),
        }
        self.finish(ctx)
    }

    /// The visibility passes of one reconstruction pass: `shooters[k]` into slot k, as
    /// `run_in_slot` draws them one by one, but the next shots' draw lists are built on two
    /// other threads (`BUILDERS`) while this one's draws are issued, and this one builds the
    /// next unclaimed list itself whenever the one it must draw next is not ready. On llvmpipe
    /// the thread that issues the draws also transforms and sets up every triangle, and is the
    /// one the visibility pass waits for; building the lists (`Culling::build`) was a sixth of
    /// its time on Lost Empire, and more than drawing them once hidden polygons were left out;
    /// waiting for the builders left it idle a third of the pass (docs/perf-log.md). The same
    /// lists, so the same item buffers.
    pub fn run_pass(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shooters: &[Shooter],
    ) -> Result<(), GlError> {
        if !self.culls || shooters.len() < 2 || shooters.len() > self.slots.len() {
            for (slot, shooter) in shooters.iter().enumerate() {
                self.run_in_slot(ctx, mesh, shooter, slot)?;
            }
            return Ok(());
        }
        let shots: Vec<(Mat4, i32, f32)> = (shooters.iter())
            .map(|s| {
                (
                    s.view(),
                    self.resolution_of(s),
                    self.shown_as(s.polygon) as f32,
                )
            })
            .collect();
        let culling = self.culling.take();
        let plates = std::mem::take(&mut self.plates);
        let mut lists = std::mem::take(&mut self.pass_lists);
        lists.resize_with(shooters.len(), Lists::default);
        let triangles = Triangles::of(mesh);
        // Each shot's list in a cell of its own; the next shot without a list is claimed by
        // whichever thread is free first: the builders, or this one when the list it must draw
        // next is not ready (waiting for a builder left it idle a third of the pass).
        let cells: Vec<Mutex<Lists>> = lists.into_iter().map(Mutex::new).collect();
        let unclaimed = AtomicUsize::new(0);
        let claim = || {
            let k = unclaimed.fetch_add(1, Ordering::Relaxed);
            (k < cells.len()).then(|| {
                let mut built = cells[k].lock().expect("a builder does not panic");
                let (view, r, _) = shots[k];
                culling.build(&mut built, triangles, &shooters[k], view, &plates, r);
                k
            })
        };
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
            for (slot, &(view, r, id)) in shots.iter().enumerate() {
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
                keep(&mut self.receivers[slot], built.receivers());
                if let Some(bytes) = built.written_item_buffer() {
                    drawn = write_item_buffer(ctx, &self.slots[slot], r, bytes);
                    self.drawn = (5 * r, r);
                } else {
                    let list = built.draw_list();
                    self.stream.upload(list.indices);
                    drawn = self.draw(ctx, mesh, slot, id, view, r, list.views);
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

    /// Upload the triangles each view draws from `shooter` (view matrix `view`, `r` pixels per
    /// side): what culling leaves if the tuning asks for it, else the whole scene; where each
    /// view's triangles are in the upload.
    fn upload_draw_list(
        &mut self,
        mesh: &SceneMesh,
        shooter: &Shooter,
        view: Mat4,
        r: i32,
    ) -> [ViewDraw; 5] {
        let list = if self.culls {
            self.culling.draw_list(mesh, shooter, view, &self.plates, r)
        } else {
            DrawList::whole(&mesh.triangles)
        };
        self.stream.upload(list.indices);
        list.views
    }

    /// Bind slot `slot`'s FBO for a depth-tested draw of IDs and clear the part a shot at `r`
    /// pixels per side draws (the lower-left corner; `drawn`).
    fn clear_slot(&mut self, ctx: &GlContext, slot: usize, r: i32) {
        let gl = &ctx.gl;
        let target = &self.slots[slot];
        let (width, height) = (target.item_buffer.width / self.resolution * r, r);
        self.drawn = (width, height);
        target.fbo.bind();
        unsafe {
            gl.viewport(0, 0, width, height);
            gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]);
            gl.disable(glow::BLEND);
            // The clears too cover only this shot's pixels.
            gl.enable(glow::SCISSOR_TEST);
            gl.scissor(0, 0, width, height);
            // Back faces occlude too: a wall seen from behind is still a wall.
            gl.disable(glow::CULL_FACE);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::LESS);
            gl.depth_mask(true);
            gl.clear_buffer_f32_slice(glow::COLOR, 0, &[0.0; 4]);
            gl.clear_depth_f64(1.0);
            gl.clear(glow::DEPTH_BUFFER_BIT);
            gl.disable(glow::SCISSOR_TEST);
        }
    }

    /// The paper's projection: one draw onto the unit disk (`glsl/hemiproj.vert`).
    fn draw_hemisphere(&self, mesh: &SceneMesh, draw: ViewDraw) {
        self.program.set_vec2("NearFar", self.near_far);
        let count = draw.unclipped + draw.clipped;
        mesh.mesh.draw_indexed(&self.stream, draw.first, count);
    }

    /// The hemicube: five 90° perspective views of `view` side by side, `r` pixels each, each
    /// in its guard band, the side faces only above the horizon (`Tuning::half_side_faces`).
    fn draw_hemicube(
        &self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        draws: &[ViewDraw; 5],
        view: Mat4,
        r: i32,
    ) {
        let gl = &ctx.gl;
        let [n, f] = self.near_far;
        let g = self.guard;
        let widen = Mat4::from_scale(Vec3::new(1.0 / g as f32, 1.0 / g as f32, 1.0));
        let projection = widen * Mat4::perspective_rh_gl(std::f32::consts::FRAC_PI_2, 1.0, n, f);
        let margin = (g - 1) / 2 * r;
        unsafe { gl.enable(glow::SCISSOR_TEST) };
        for (k, rotation) in face_rotations().iter().enumerate() {
            let x = k as i32 * r;
            unsafe {
                gl.viewport(x - margin, -margin, g * r, g * r);
                let [sx, sy, sw, sh] = if self.tuning.half_side_faces {
                    front_half(k, r)
                } else {
                    [0, 0, r, r]
                };
                gl.scissor(x + sx, sy, sw, sh);
            }
            let m = projection * Mat4::from_mat3(*rotation) * view;
            self.program
                .set_mat4("FaceViewProjection", &m.to_cols_array());
            // Two draws (`split_unclipped`): llvmpipe takes its fast path for a draw with
            // nothing to clip.
            let d = draws[k];
            for (first, count) in [(d.first, d.unclipped), (d.first + d.unclipped, d.clipped)] {
                if count > 0 {
                    mesh.mesh.draw_indexed(&self.stream, first, count);
                }
            }
        }
        unsafe { gl.disable(glow::SCISSOR_TEST) };
    }

    /// Leave the FBO, and (`Tuning::flush_visibility`) have the pass rasterised now:
    /// llvmpipe queues it and returns, so the CPU picks the receivers meanwhile.
    fn finish(&self, ctx: &GlContext) -> Result<(), GlError> {
        let gl = &ctx.gl;
        unsafe {
            gl.disable(glow::DEPTH_TEST);
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            if self.tuning.flush_visibility {
                gl.flush();
            }
        }
        ctx.check(VISIBILITY)
    }

    /// How many times a view left a polygon out as falling between the pixel centres, over all
    /// passes (`Tuning::cull_between_samples`).
    pub fn missed(&self) -> u64 {
        self.culling.missed
    }

    /// How many polygons in front of a shooter were left out as hidden, over all passes
    /// (`Tuning::cull_hidden`), where the views were drawn: a walk that writes the item buffer
    /// (`Tuning::walk_item_buffers`) does not list the polygons in front of the shooter, so it
    /// counts none.
    pub fn hidden(&self) -> u64 {
        self.culling.hidden
    }

    /// Find the receivers of every shot whose item buffer the walk writes from now on
    /// (`Tuning::walk_receivers`; `receivers_seen`).
    pub fn use_seen_receivers(&mut self, seen: seen_receivers::SeenReceivers) {
        self.culling.use_seen_receivers(seen);
    }

    /// What the last shot in slot `slot` may reach, when the walk wrote its item buffer and
    /// `use_seen_receivers` set up the test (`Tuning::walk_receivers`); `None` if not known.
    pub fn receivers_seen(&self, slot: usize) -> Option<&seen_receivers::Reach> {
        self.receivers.get(slot)?.as_ref()
    }

    /// The item buffer of slot `slot` (`run_in_slot`).
    pub fn slot_texture(&self, slot: usize) -> &Texture {
        &self.slots[slot].item_buffer
    }

    /// The item buffer of the first slot: the paper's one.
    pub fn item_buffer(&self) -> &Texture {
        self.slot_texture(0)
    }

    /// The part of the item buffer the last pass drew (width, height), from its lower-left
    /// corner; the rest holds what earlier passes left.
    pub fn drawn(&self) -> (i32, i32) {
        self.drawn
    }

    /// The (first slot's) item buffer as polygon IDs (`None` where no polygon is seen), rows
    /// bottom to top.
    pub fn read_ids(&self) -> Vec<Option<u32>> {
        self.read_slot_ids(0)
    }

    /// Slot `slot`'s item buffer as [`read_ids`](Self::read_ids) gives the first.
    pub fn read_slot_ids(&self, slot: usize) -> Vec<Option<u32>> {
        self.slot_texture(slot)
            .read_u8()
            .chunks_exact(4)
            .map(|c| {
                let n = c[0] as u32 | (c[1] as u32) << 8 | (c[2] as u32) << 16;
                n.checked_sub(1)
            })
            .collect()
    }
}
