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
//! sake, is switched by [`Tuning`] (each switch documented there): views culled by bounding
//! spheres, a guard band around each hemicube face, draws split by whether they need clipping,
//! half side faces, coplanar neighbours drawn as one plate (`plates`), the far faces of convex
//! solids left out (`solids`), float depth, and a glFlush at the end.

pub mod plates;
pub mod samples;
pub mod solids;

use super::mesh::{SceneMesh, ATTRIBUTES};
use super::{Shooter, Tuning, VisibilityKind};
use crate::geometry::{mean, sphere_around, Plane};
use crate::gl::{
    Framebuffer, GlContext, GlError, IndexStream, Program, Renderbuffer, Texture, TextureFormat,
};
use crate::glsl;
use crate::scene::Scene;
use glam::{Mat3, Mat4, Vec3};
use glow::HasContext;
use plates::Plates;
use samples::Outlines;
use solids::Solids;

pub struct VisibilityPass {
    program: Program,
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
    /// Each polygon's bounding sphere (centre, radius), for culling.
    spheres: Vec<(Vec3, f32)>,
    /// The polygons in front of the shooter: (polygon, sphere centre in eye space, radius) (reused).
    in_front: Vec<(usize, Vec3, f32)>,
    /// The triangles each view draws after culling, views one after another, each view's
    /// unclipped polygons first (reused).
    indices: Vec<u32>,
    /// One view's polygons that may need clipping, gathered to follow its others (reused).
    clipped: Vec<u32>,
    stream: IndexStream,
    /// The scene's convex solids, whose faces turned away from the shooter are left out (see
    /// `solids`: the item buffer stays the same).
    solids: Solids,
    /// Each polygon's plane.
    planes: Vec<Plane>,
    /// Per solid, whether the current shooter is clear of it (reused).
    outside: Vec<bool>,
    /// Coplanar polygons drawn as one (`merge_plates`; at first every polygon alone).
    plates: Plates,
    /// Each drawn polygon's corners, for `Tuning::cull_between_samples`.
    outlines: Outlines,
    /// How many times a view left a polygon out as falling between the pixel centres, over all
    /// passes (`Tuning::cull_between_samples`).
    pub missed: u64,
}

pub const NAME: &str = "visibility";

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
        fbo.check_complete(NAME)?;
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
        let spheres = scene.polygons.iter().map(|p| p.bounding_sphere()).collect();
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
        ctx.check(NAME)?;
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
        let plates = Plates::none(scene.polygons.len());
        Ok(VisibilityPass {
            program,
            kind,
            slots,
            resolution: res,
            tuning,
            guard,
            near_far,
            drawn: (width, res),
            spheres,
            in_front: Vec::new(),
            indices: Vec::new(),
            clipped: Vec::new(),
            stream: IndexStream::new(gl)?,
            solids: Solids::find(scene),
            planes: scene.polygons.iter().map(|p| p.plane()).collect(),
            outside: Vec::new(),
            outlines: Outlines::new(scene, &plates),
            plates,
            missed: 0,
        })
    }

    /// Merge coplanar polygons outside the solids into plates (`Tuning::plates`; hemicube only:
    /// the hemispherical projection needs small polygons, and bigger ones would curve more). The
    /// caller then draws a mesh made by `mesh::plate_data` from the plates returned; the item
    /// buffer shows each plate under its representative's ID. Only for the robust visibility
    /// test, which reads the shown polygon's plane, not its ID alone. With the switch off every
    /// polygon stays alone, and `plate_data` gives the scene's own mesh.
    pub fn merge_plates(&mut self, scene: &Scene) -> &Plates {
        if self.kind == VisibilityKind::Hemicube && self.tuning.plates {
            let solids = &self.solids;
            self.plates = Plates::find(scene, |p| solids.solid_of[p].is_none());
            for (&p, outline) in &self.plates.outlines {
                self.spheres[p] = sphere_around(mean(outline), outline);
            }
            self.outlines = Outlines::new(scene, &self.plates);
        }
        &self.plates
    }

    /// The polygon whose ID the item buffer shows where polygon `p` is seen.
    pub fn shown_as(&self, p: usize) -> usize {
        self.plates.representative[p]
    }

    /// Draw the item buffer from `shooter` (into the first slot). With `Tuning::cull_views` each view draws only the
    /// polygons whose bounding sphere reaches into it and in front of the shooter, and with
    /// `Tuning::half_side_faces` the hemicube's side faces fill only their upper halves, the
    /// part above the shooter's horizon that the reconstruction pass looks up.
    pub fn run(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shooter: &Shooter,
    ) -> Result<(), GlError> {
        self.run_in_slot(ctx, mesh, shooter, 0)
    }

    /// `run` into item buffer `slot` (`with_slots`; `slot_texture`).
    pub fn run_in_slot(
        &mut self,
        ctx: &GlContext,
        mesh: &SceneMesh,
        shooter: &Shooter,
        slot: usize,
    ) -> Result<(), GlError> {
        let gl = &ctx.gl;
        let Some(target) = self.slots.get(slot) else {
            return Err(GlError::Limit(format!(
                "item-buffer slot {slot} of a pass set up for {}",
                self.slots.len()
            )));
        };
        let view = shooter.view();
        let views = match self.kind {
            VisibilityKind::Hemisphere => 1,
            VisibilityKind::Hemicube => 5,
        };
        let rotations = face_rotations();
        // Wholly behind the shooter's plane: nothing it could hide is looked up. The rest, with
        // their spheres' centres in the shooter's eye space, once for all the views.
        let s = shooter.position;
        let solids = &self.solids;
        self.outside.clear();
        // Clear of the near plane too: geometry nearer than it is clipped away, and a clipped
        // near face would show the far face behind it. On a face axis, depth ≥ distance / √3.
        let margin = self.near_far[0] * 3f32.sqrt();
        let tuning = self.tuning;
        self.outside.extend(
            // Only where projected straight edges are exact (the hemicube): the hemispherical
            // projection drawn with straight edges lets a far face peek past the near ones.
            (0..solids.count()).map(|k| {
                tuning.cull_solids
                    && self.kind == VisibilityKind::Hemicube
                    && solids.clear_of(k, s, margin)
            }),
        );
        self.in_front.clear();
        // The shooter's plate lies in the shooter's plane, which the near plane clips away (and
        // the shaders put it beyond the far plane).
        let shooter_plate = self.plates.representative[shooter.polygon];
        for (p, &(centre, radius)) in self.spheres.iter().enumerate() {
            if self.plates.representative[p] != p {
                continue;
            }
            let c = view.transform_point3(centre);
            if tuning.cull_views && (p == shooter_plate || c.z >= radius) {
                continue;
            }
            // A solid's face turned away from a shooter outside the solid hides nothing.
            if let Some(k) = solids.solid_of[p] {
                if self.outside[k] && self.planes[p].distance(s) < -solids.slack {
                    continue;
                }
            }
            self.in_front.push((p, c, radius));
        }
        // Per view: the first index, the polygons wholly inside the guarded frustum and beyond
        // the near plane (no vertex to clip: llvmpipe's fast path), then the others; without
        // `split_unclipped`, all of them as "others", in the scene's order.
        let mut ranges = [(0usize, 0usize, 0usize); 5];
        // This shot's resolution (`SolveOptions::small_hemi_res`): the views fill the item
        // buffer's lower-left corner, and the reconstruction pass looks up only that.
        let r = (shooter.hemi_res as i32).clamp(1, self.resolution);
        let g = self.guard as f32;
        let side = (1.0 + g * g).sqrt();
        let near = self.near_far[0];
        self.indices.clear();
        // Pixels across per unit of tangent, to tell which polygons project small enough to
        // fall between the pixel centres (`samples`).
        let pixels_per_tangent = r as f32 / 2.0;
        for (k, range) in ranges.iter_mut().enumerate().take(views) {
            let start = self.indices.len();
            self.clipped.clear();
            let face = Mat4::from_mat3(rotations[k]) * view;
            for &(p, c, radius) in &self.in_front {
                let mut inside = false;
                if self.kind == VisibilityKind::Hemicube {
                    // Outside one of the face's four 45° side planes (unit normals (±1, 0, -1)/√2
                    // and (0, ±1, -1)/√2 in face space).
                    let f = rotations[k] * c;
                    let reach = radius * std::f32::consts::SQRT_2;
                    if tuning.cull_views && (-f.z - f.x.abs() < -reach || -f.z - f.y.abs() < -reach)
                    {
                        continue;
                    }
                    let depth = -f.z - radius;
                    if tuning.cull_between_samples
                        && depth > 2.0 * near
                        && 2.0 * radius / depth * pixels_per_tangent < samples::MAX_EXTENT
                        && samples::misses_every_centre(
                            self.outlines.of(p),
                            &face,
                            r as f32,
                            2.0 * near,
                        )
                    {
                        self.missed += 1;
                        continue;
                    }
                    // Inside the guarded side planes (normals (±1, 0, -g)/√(1 + g²), ...).
                    inside = tuning.split_unclipped
                        && -f.z - radius > 2.0 * near
                        && -g * f.z - f.x.abs() > radius * side
                        && -g * f.z - f.y.abs() > radius * side;
                }
                let (first, count) = mesh.ranges[p];
                let corners = &mesh.triangles[first as usize..(first + count) as usize];
                if inside {
                    self.indices.extend_from_slice(corners);
                } else {
                    self.clipped.extend_from_slice(corners);
                }
            }
            let unclipped = self.indices.len() - start;
            self.indices.extend_from_slice(&self.clipped);
            *range = (start, unclipped, self.indices.len() - start - unclipped);
        }
        self.stream.upload(&self.indices);

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
        self.program.use_program();
        self.program.set_f32("ShooterId", shooter_plate as f32);
        self.program.set_mat4("ShooterView", &view.to_cols_array());
        match self.kind {
            VisibilityKind::Hemisphere => {
                self.program.set_vec2("NearFar", self.near_far);
                let (start, unclipped, clipped) = ranges[0];
                mesh.mesh
                    .draw_indexed(&self.stream, start, unclipped + clipped);
            }
            VisibilityKind::Hemicube => {
                let [n, f] = self.near_far;
                let g = self.guard;
                let widen = Mat4::from_scale(Vec3::new(1.0 / g as f32, 1.0 / g as f32, 1.0));
                let projection =
                    widen * Mat4::perspective_rh_gl(std::f32::consts::FRAC_PI_2, 1.0, n, f);
                let margin = (g - 1) / 2 * r;
                unsafe { gl.enable(glow::SCISSOR_TEST) };
                for (k, rotation) in rotations.iter().enumerate() {
                    let x = k as i32 * r;
                    unsafe {
                        gl.viewport(x - margin, -margin, g * r, g * r);
                        let [sx, sy, sw, sh] = if tuning.half_side_faces {
                            front_half(k, r)
                        } else {
                            [0, 0, r, r]
                        };
                        gl.scissor(x + sx, sy, sw, sh);
                    }
                    let m = projection * Mat4::from_mat3(*rotation) * view;
                    self.program
                        .set_mat4("FaceViewProjection", &m.to_cols_array());
                    // Two draws (`split_unclipped`): llvmpipe takes its fast path for a draw
                    // with nothing to clip.
                    let (start, unclipped, clipped) = ranges[k];
                    for (first, count) in [(start, unclipped), (start + unclipped, clipped)] {
                        if count > 0 {
                            mesh.mesh.draw_indexed(&self.stream, first, count);
                        }
                    }
                }
                unsafe { gl.disable(glow::SCISSOR_TEST) };
            }
        }
        unsafe {
            gl.disable(glow::DEPTH_TEST);
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            // Rasterise now (`flush_visibility`): llvmpipe queues the pass and returns, so the
            // CPU picks the receivers meanwhile.
            if tuning.flush_visibility {
                gl.flush();
            }
        }
        ctx.check(NAME)
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
