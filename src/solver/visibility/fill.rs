//! What fills a visibility pass's item buffers: the interface ([`ItemBufferFill`]) and the
//! paper's way, every view drawing the whole scene ([`DrawnViews`]). The llvmpipe engine's
//! (`solver::engine::culled_views`) culls the views or writes the item buffer on the CPU.

use crate::gl::{GlContext, GlError};
use crate::solver::mesh::SceneMesh;
use crate::solver::Shooter;
use glam::Mat4;
use std::any::Any;

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
