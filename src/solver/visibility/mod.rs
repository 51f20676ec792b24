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
//! What fills the item buffers is an [`ItemBufferFill`]: the paper's [`DrawnViews`] draw the whole
//! scene into every view. The llvmpipe engine (`solver::engine`) has its own, which leaves out
//! what cannot show or writes the item buffer on the CPU; this file does not know it. How the
//! views are drawn ([`ViewSetup`]) is data: the depth format, the part of each face drawn, and
//! the guard band around the faces (none in the paper).

use super::mesh::{SceneMesh, ATTRIBUTES};
use super::pass_names::VISIBILITY;
use super::{Shooter, SolveOptions, VisibilityKind};
use crate::gl::{
    Framebuffer, GlContext, GlError, IndexStream, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::glsl;
use crate::scene::Scene;
use glam::{Mat3, Mat4, Vec3};
use glow::HasContext;
use std::any::Any;

/// The visibility pass (3.2.1): the scene drawn from a shooter into an item buffer of polygon
/// IDs, which the reconstruction pass reads to tell whether a receiver is seen.
pub struct VisibilityPass {
    program: Program,
    /// Hemicube or hemispherical projection.
    pub kind: VisibilityKind,
    /// The item buffers, one per shooter of a reconstruction pass (`with_fill`; one in the
    /// paper), each with its depth buffer and FBO.
    slots: Vec<ItemSlot>,
    resolution: i32,
    /// Each hemicube face is drawn in a viewport `guard` times its size, centred on it (1: the
    /// paper's; see [`ViewSetup::guard_band`]).
    guard: i32,
    /// The part of each hemicube face drawn ([`FaceArea`]).
    faces: FaceArea,
    near_far: [f32; 2],
    /// The part of the item buffer the last pass drew (width, height): all of it, or the
    /// lower-left corner for a shot at a smaller resolution (`Shooter::hemi_res`).
    drawn: (i32, i32),
    /// The triangles the views of the last shot drew.
    stream: IndexStream,
    /// What fills the item buffers.
    fill: Box<dyn ItemBufferFill>,
}

/// How the views are drawn. The paper's: float depth, whole faces, no guard band
/// ([`ViewSetup::PAPER`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewSetup {
    /// The depth buffer's format.
    pub depth: DepthFormat,
    /// The part of each hemicube face drawn.
    pub faces: FaceArea,
    /// Each hemicube face drawn in a viewport this many times its size (odd; even ones round
    /// down, and the driver's largest viewport may cap it), its frustum widened to match and
    /// the scissor keeping its own pixels: llvmpipe then clips none of the triangles that
    /// cross a face's edge (`Tuning::guard_band`). 1: none, as the paper.
    pub guard_band: u32,
}

impl ViewSetup {
    /// The paper's views.
    pub const PAPER: ViewSetup = ViewSetup {
        depth: DepthFormat::Float32,
        faces: FaceArea::Whole,
        guard_band: 1,
    };
}

/// The item buffers' depth format (`Tuning::float_depth`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthFormat {
    /// 32-bit float (GL 3.0): what every profile uses.
    Float32,
    /// 24-bit integers.
    Int24,
}

/// The part of each hemicube face a shot draws (`Tuning::half_side_faces`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaceArea {
    /// Every pixel, as the paper.
    Whole,
    /// Only the pixels above the shooter's horizon, the ones the reconstruction pass looks up
    /// ([`front_half`]).
    AboveHorizon,
}

impl FaceArea {
    /// The pixels of face `k` drawn (x, y, width, height within the face) at `r` pixels a side.
    pub fn of(self, k: usize, r: i32) -> [i32; 4] {
        match self {
            FaceArea::Whole => [0, 0, r, r],
            FaceArea::AboveHorizon => front_half(k, r),
        }
    }
}

/// One view's part of a [`DrawList`]: from index `first`, `unclipped` indices, then `clipped`
/// more, drawn one after the other. The paper's lists put every triangle in `clipped`; the
/// engine puts first those wholly inside the guarded frustum, which llvmpipe draws on its fast
/// path when they come in a draw of their own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ViewDraw {
    /// The view's first index in [`DrawList::indices`].
    pub first: usize,
    /// How many indices, from `first`, need no clipping.
    pub unclipped: usize,
    /// How many indices follow those, which may need clipping.
    pub clipped: usize,
}

/// The triangles (vertex indices of the [`SceneMesh`]) each view of one shot draws: views one
/// after another in `indices`, each view's part in `views` (the hemisphere uses the first).
pub struct DrawList<'a> {
    /// The triangles' corners.
    pub indices: &'a [u32],
    /// Where each view's triangles are in `indices`.
    pub views: [ViewDraw; 5],
}

impl<'a> DrawList<'a> {
    /// Every view draws all of `triangles` (the scene's, in its order), as the paper does.
    pub fn whole(triangles: &'a [u32]) -> Self {
        let all = ViewDraw {
            first: 0,
            unclipped: 0,
            clipped: triangles.len(),
        };
        DrawList {
            indices: triangles,
            views: [all; 5],
        }
    }
}

/// One shot of a pass: the shooter, its view matrix, and its item buffer's side in pixels.
pub struct Shot<'a> {
    /// The shooter.
    pub shooter: &'a Shooter,
    /// World to the shooter's eye space (`Shooter::view`).
    pub view: Mat4,
    /// Pixels per side (per hemicube face) this shot fills.
    pub r: i32,
}

/// What fills one item buffer.
pub enum Filled<'a> {
    /// The views draw `list`; the shooter's own polygon is drawn under ID `shooter_id`.
    Drawn {
        /// The triangles each view draws.
        list: DrawList<'a>,
        /// The ID the item buffer shows for the shooter's polygon (its own in the paper).
        shooter_id: usize,
    },
    /// The item buffer is already written: RGBA8 bytes (ID + 1 in RGB) of the lower-left
    /// 5r × r pixels, rows bottom to top, to upload where the views would have drawn.
    Written(&'a [u8]),
}

/// What fills a pass's item buffers: the views drawn whole ([`DrawnViews`], the paper's), or
/// the llvmpipe engine's culled views and hidden-polygon walk.
pub trait ItemBufferFill: Any {
    /// What fills slot `slot`'s item buffer for `shot`, in `mesh` (the visibility mesh).
    fn shot<'a>(&'a mut self, mesh: &'a SceneMesh, shot: &Shot, slot: usize) -> Filled<'a>;

    /// Every shot of one reconstruction pass, `shots[k]` into slot k, each handed to `put` in
    /// slot order as soon as it is filled (and `after_draw` called after those drawn). By
    /// default one after the other; a fill may prepare the next ones meanwhile.
    fn pass(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shots: &[Shot],
        put: &mut dyn FnMut(usize, Filled<'_>) -> Result<(), GlError>,
    ) -> Result<(), GlError> {
        one_by_one(self, ctx, mesh, shots, put)
    }

    /// Called after the views of a shot are drawn (and the FBO left); the paper does nothing.
    fn after_draw(&self, _ctx: &GlContext) {}

    /// This fill as `Any`, for the engine to find its own.
    fn as_any(&self) -> &dyn Any;

    /// This fill as `Any`, to change.
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

/// [`ItemBufferFill::pass`] one shot after the other: the default, and the engine's way when
/// there is nothing to prepare beside the draws.
pub fn one_by_one<F: ItemBufferFill + ?Sized>(
    fill: &mut F,
    ctx: &GlContext,
    mesh: &SceneMesh,
    shots: &[Shot],
    put: &mut dyn FnMut(usize, Filled<'_>) -> Result<(), GlError>,
) -> Result<(), GlError> {
    for (slot, shot) in shots.iter().enumerate() {
        let filled = fill.shot(mesh, shot, slot);
        let drawn = matches!(filled, Filled::Drawn { .. });
        put(slot, filled)?;
        if drawn {
            fill.after_draw(ctx);
        }
    }
    Ok(())
}

/// The paper's fill: every view draws the whole scene.
pub struct DrawnViews;

impl ItemBufferFill for DrawnViews {
    fn shot<'a>(&'a mut self, mesh: &'a SceneMesh, shot: &Shot, _slot: usize) -> Filled<'a> {
        Filled::Drawn {
            list: DrawList::whole(&mesh.triangles),
            shooter_id: shot.shooter.polygon,
        }
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
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
        depth: DepthFormat,
    ) -> Result<Self, GlError> {
        // NEAREST: an ID must never be blended with its neighbour's.
        let item_buffer = Texture::new(gl, width, height, TextureFormat::Rgba8, glow::NEAREST)?;
        let depth_format = match depth {
            DepthFormat::Float32 => glow::DEPTH_COMPONENT32F,
            DepthFormat::Int24 => glow::DEPTH_COMPONENT24,
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

impl Shooter {
    /// World -> shooter eye space, which the item buffer is drawn in: eye at the shooter,
    /// looking down -z along its normal (turned by `turn` about it, beyond the paper).
    pub fn view(&self) -> Mat4 {
        let up = glam::Quat::from_axis_angle(self.normal, self.turn)
            * self.normal.any_orthonormal_vector();
        Mat4::look_at_rh(self.position, self.position + self.normal, up)
    }
}

/// The item buffer's side for a shot that carries `share` of the emitted power (by magnitude:
/// an overshot shooter's negative energy too): `hemi_res`, or `small_hemi_res` below
/// `small_shot`; with `min_hemi_res`, below `small_shot` the side falls with the cube root of
/// the share, to `min_hemi_res` at the least. Why the cube root: a shot's aliasing error grows
/// with its power over its side, its cost with the side squared, and Σ error + λ Σ cost is
/// least where side³ ∝ power.
pub fn item_buffer_side(options: &SolveOptions, share: f64) -> u32 {
    let o = options;
    let small = share.abs() < o.small_shot as f64;
    if o.small_hemi_res == 0 || !small {
        o.hemi_res
    } else if o.min_hemi_res == 0 {
        o.small_hemi_res
    } else {
        let side = o.small_hemi_res as f64 * (share.abs() / o.small_shot as f64).cbrt();
        (side.round() as u32).clamp(o.min_hemi_res, o.small_hemi_res)
    }
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

/// The views' near and far planes for `scene`. Near: 1e-4 of the scene, so the shooter's own
/// plane is clipped away but receivers a hair in front of it are kept. Far: beyond anything.
pub fn near_far(scene: &Scene) -> [f32; 2] {
    let size = scene.size();
    [size * 1e-4, size * 2.0]
}

/// The guard band a pass of `kind` at `resolution` draws with when `wanted` (odd, at most what
/// the driver's viewport holds; 1 on the hemisphere, which has no faces).
pub fn guard_band(ctx: &GlContext, kind: VisibilityKind, resolution: u32, wanted: u32) -> i32 {
    let mut dims = [0; 2];
    unsafe {
        ctx.gl
            .get_parameter_i32_slice(glow::MAX_VIEWPORT_DIMS, &mut dims)
    };
    let fits = (dims[0].min(dims[1]) / (resolution as i32).max(1)).max(1);
    let wanted = wanted.clamp(1, i32::MAX as u32) as i32;
    match kind {
        VisibilityKind::Hemicube => (fits.min(wanted) - 1) / 2 * 2 + 1,
        VisibilityKind::Hemisphere => 1,
    }
}

impl VisibilityPass {
    /// The paper's pass: one item buffer, every view drawing the whole scene.
    pub fn paper(
        ctx: &GlContext,
        kind: VisibilityKind,
        resolution: u32,
        scene: &Scene,
    ) -> Result<Self, GlError> {
        let fill = Box::new(DrawnViews);
        Self::with_fill(ctx, kind, resolution, ViewSetup::PAPER, scene, 1, fill)
    }

    /// A pass with `slots` item buffers, one for each shooter of one reconstruction pass
    /// (`SolveOptions::shooters_per_pass`; `run_in_slot`), drawn as `setup` says, filled by
    /// `fill`.
    pub fn with_fill(
        ctx: &GlContext,
        kind: VisibilityKind,
        resolution: u32,
        setup: ViewSetup,
        scene: &Scene,
        slots: u32,
        fill: Box<dyn ItemBufferFill>,
    ) -> Result<Self, GlError> {
        let gl = &ctx.gl;
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
        let slots = (0..slots.max(1))
            .map(|_| ItemSlot::new(gl, width, res, setup.depth))
            .collect::<Result<Vec<_>, GlError>>()?;
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
        ctx.check(VISIBILITY)?;
        Ok(VisibilityPass {
            program,
            kind,
            slots,
            resolution: res,
            guard: guard_band(ctx, kind, resolution, setup.guard_band),
            faces: setup.faces,
            near_far: near_far(scene),
            drawn: (width, res),
            stream: IndexStream::new(gl)?,
            fill,
        })
    }

    /// What fills this pass's item buffers.
    pub fn fill(&self) -> &dyn ItemBufferFill {
        &*self.fill
    }

    /// What fills this pass's item buffers, to change.
    pub fn fill_mut(&mut self) -> &mut dyn ItemBufferFill {
        &mut *self.fill
    }

    /// Fill the item buffer from `shooter` into the first slot, the paper's one (`run_in_slot`).
    pub fn run(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shooter: &Shooter,
    ) -> Result<(), GlError> {
        self.run_in_slot(ctx, mesh, shooter, 0)
    }

    /// `run` into item buffer `slot` (`with_fill`; `slot_texture`): the paper's "render the
    /// scene from the shooter", polygon IDs as colours.
    pub fn run_in_slot(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shooter: &Shooter,
        slot: usize,
    ) -> Result<(), GlError> {
        self.check_slots(slot + 1)?;
        let shot = self.shot(shooter);
        let mut fill = self.take_fill();
        let filled = fill.shot(mesh, &shot, slot);
        let drawn = matches!(filled, Filled::Drawn { .. });
        let put = self.put(ctx, mesh, &shot, slot, filled);
        if drawn && put.is_ok() {
            fill.after_draw(ctx);
        }
        self.fill = fill;
        put
    }

    /// The visibility passes of one reconstruction pass: `shooters[k]` into slot k, as
    /// `run_in_slot` fills them one by one (a fill may prepare the next while one is drawn).
    pub fn run_pass(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shooters: &[Shooter],
    ) -> Result<(), GlError> {
        self.check_slots(shooters.len())?;
        let shots: Vec<Shot> = shooters.iter().map(|s| self.shot(s)).collect();
        let mut fill = self.take_fill();
        let done = fill.pass(ctx, mesh, &shots, &mut |slot, filled| {
            self.put(ctx, mesh, &shots[slot], slot, filled)
        });
        self.fill = fill;
        done
    }

    /// Refuse more shots than the pass has item buffers.
    fn check_slots(&self, shots: usize) -> Result<(), GlError> {
        if shots > self.slots.len() {
            return Err(GlError::Limit(format!(
                "item-buffer slot {} of a pass set up for {}",
                shots - 1,
                self.slots.len()
            )));
        }
        Ok(())
    }

    /// The fill, out of the pass while it runs (so that it can hand its results to `put`).
    fn take_fill(&mut self) -> Box<dyn ItemBufferFill> {
        std::mem::replace(&mut self.fill, Box::new(DrawnViews))
    }

    /// `shooter`'s shot: its view and this shot's resolution (`SolveOptions::small_hemi_res`:
    /// the views fill the item buffer's lower-left corner, and the reconstruction pass looks up
    /// only that).
    fn shot<'a>(&self, shooter: &'a Shooter) -> Shot<'a> {
        Shot {
            shooter,
            view: shooter.view(),
            r: (shooter.hemi_res as i32).clamp(1, self.resolution),
        }
    }

    /// Put what the fill gave for `shot` into slot `slot`: draw its views, or upload the item
    /// buffer it wrote (RGBA8 bytes of the lower-left 5r × r pixels).
    fn put(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shot: &Shot,
        slot: usize,
        filled: Filled<'_>,
    ) -> Result<(), GlError> {
        let r = shot.r;
        match filled {
            Filled::Written(bytes) => {
                self.slots[slot]
                    .item_buffer
                    .upload_u8_region(5 * r, r, bytes);
                self.drawn = (5 * r, r);
                ctx.check(VISIBILITY)
            }
            Filled::Drawn { list, shooter_id } => {
                self.stream.upload(list.indices);
                self.draw(ctx, mesh, slot, shooter_id as f32, shot, list.views)
            }
        }
    }

    /// Draw the views (`views`, in the uploaded draw list) of `shot`, its shooter's polygon
    /// shown as `id`, into slot `slot`.
    fn draw(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        slot: usize,
        id: f32,
        shot: &Shot,
        views: [ViewDraw; 5],
    ) -> Result<(), GlError> {
        self.clear_slot(ctx, slot, shot.r);
        self.program.use_program();
        // The shooter's polygon lies in the shooter's plane, which the near plane clips away;
        // the shaders put it beyond the far plane.
        self.program.set_f32("ShooterId", id);
        self.program
            .set_mat4("ShooterView", &shot.view.to_cols_array());
        match self.kind {
            VisibilityKind::Hemisphere => self.draw_hemisphere(mesh, views[0]),
            VisibilityKind::Hemicube => self.draw_hemicube(ctx, mesh, &views, shot),
        }
        self.finish(ctx)
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

    /// The hemicube: five 90° perspective views of the shot side by side, `r` pixels each, each
    /// in its guard band (none in the paper), each drawing the part `faces` says.
    fn draw_hemicube(&self, ctx: &GlContext, mesh: &SceneMesh, draws: &[ViewDraw; 5], shot: &Shot) {
        let gl = &ctx.gl;
        let [n, f] = self.near_far;
        let (g, r) = (self.guard, shot.r);
        let widen = Mat4::from_scale(Vec3::new(1.0 / g as f32, 1.0 / g as f32, 1.0));
        let projection = widen * Mat4::perspective_rh_gl(std::f32::consts::FRAC_PI_2, 1.0, n, f);
        let margin = (g - 1) / 2 * r;
        unsafe { gl.enable(glow::SCISSOR_TEST) };
        for (k, rotation) in face_rotations().iter().enumerate() {
            let x = k as i32 * r;
            let [sx, sy, sw, sh] = self.faces.of(k, r);
            unsafe {
                gl.viewport(x - margin, -margin, g * r, g * r);
                gl.scissor(x + sx, sy, sw, sh);
            }
            let m = projection * Mat4::from_mat3(*rotation) * shot.view;
            self.program
                .set_mat4("FaceViewProjection", &m.to_cols_array());
            // A view's list comes in two parts (`ViewDraw`), drawn one after the other.
            let d = draws[k];
            for (first, count) in [(d.first, d.unclipped), (d.first + d.unclipped, d.clipped)] {
                if count > 0 {
                    mesh.mesh.draw_indexed(&self.stream, first, count);
                }
            }
        }
        unsafe { gl.disable(glow::SCISSOR_TEST) };
    }

    /// Leave the FBO.
    fn finish(&self, ctx: &GlContext) -> Result<(), GlError> {
        let gl = &ctx.gl;
        unsafe {
            gl.disable(glow::DEPTH_TEST);
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
        ctx.check(VISIBILITY)
    }

    /// The item buffer of slot `slot` (`run_in_slot`).
    pub fn slot_texture(&self, slot: usize) -> &Texture {
        &self.slots[slot].item_buffer
    }

    /// The item buffer of the first slot: the paper's one.
    pub fn item_buffer(&self) -> &Texture {
        self.slot_texture(0)
    }

    /// How many item buffers the pass has.
    pub fn slots(&self) -> usize {
        self.slots.len()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_smallest_shots_get_sides_in_proportion_to_the_cube_root_of_their_power() {
        let o = SolveOptions {
            hemi_res: 256,
            small_hemi_res: 128,
            small_shot: 0.01,
            min_hemi_res: 16,
            ..SolveOptions::accurate()
        };
        // At and above the small shots' share: the full side.
        assert_eq!(item_buffer_side(&o, 0.01), 256);
        assert_eq!(item_buffer_side(&o, -0.5), 256);
        // Just below: the small shots' side; an eighth of the share, half of it; by magnitude.
        assert_eq!(item_buffer_side(&o, 0.009_999), 128);
        assert_eq!(item_buffer_side(&o, 0.01 / 8.0), 64);
        assert_eq!(item_buffer_side(&o, -0.01 / 64.0), 32);
        // Never below the least, nor for a shot of nothing.
        assert_eq!(item_buffer_side(&o, 1e-9), 16);
        assert_eq!(item_buffer_side(&o, 0.0), 16);
        // Falling with the share all the way.
        let sides: Vec<u32> = (0..60)
            .map(|k| item_buffer_side(&o, 0.0099 * 0.9f64.powi(k)))
            .collect();
        assert!(sides.windows(2).all(|w| w[1] <= w[0]), "{sides:?}");
        // Without `min_hemi_res`, two sides only (the option as it was).
        let two = SolveOptions {
            min_hemi_res: 0,
            ..o.clone()
        };
        assert_eq!(item_buffer_side(&two, 1e-9), 128);
        assert_eq!(item_buffer_side(&two, 0.02), 256);
        // Without `small_hemi_res`, one.
        let one = SolveOptions {
            small_hemi_res: 0,
            ..o
        };
        assert_eq!(item_buffer_side(&one, 1e-9), 256);
    }
}
