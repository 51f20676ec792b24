//! The viewer's overlays. In the scene (uniforms of `glsl/viewer.frag`): the shooters
//! highlighted, the unshot heat map, patch borders. As insets in the corners of the scene view
//! (`glsl/overlay.*`): the item buffer from the last shooter in false colour, and the lightmap
//! atlas (radiance, or the heat map when that is on).

use crate::display::Viewport;
use crate::gl::objects::Attribute;
use crate::gl::{GlContext, GlError, Mesh, Program, Texture};
use crate::glsl;
use glow::HasContext;

/// The name GL errors of the overlays' draws carry.
pub const NAME: &str = "viewer overlay";

/// Which overlays are on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OverlaySet {
    /// The last and next shooters striped.
    pub shooter: bool,
    /// The last item buffer inset.
    pub item_buffer: bool,
    /// Unshot radiance per patch, log scale, instead of the lighting.
    pub heat_map: bool,
    /// The lightmap atlas inset.
    pub atlas: bool,
    /// The patch grid.
    pub borders: bool,
}

/// The overlays by name, as `--overlays` and the panel list them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Overlay {
    /// None of them.
    None,
    /// The last shooter striped orange, the next one striped cyan (key 1).
    Shooter,
    /// The item buffer from the last shooter, IDs in false colour (key 2).
    ItemBuffer,
    /// Unshot radiance per patch, log scale, instead of the lighting (key 3).
    HeatMap,
    /// The lightmap atlas (key 4).
    Atlas,
    /// The patch grid (key 5).
    Borders,
}

impl OverlaySet {
    /// The set with the overlays of `list` on (`none` turns none on).
    pub fn from_list(list: &[Overlay]) -> OverlaySet {
        let has = |o| list.contains(&o);
        OverlaySet {
            shooter: has(Overlay::Shooter),
            item_buffer: has(Overlay::ItemBuffer),
            heat_map: has(Overlay::HeatMap),
            atlas: has(Overlay::Atlas),
            borders: has(Overlay::Borders),
        }
    }

    /// Toggle by the number keys 1-5.
    pub fn toggle(&mut self, key: u32) {
        match key {
            1 => self.shooter ^= true,
            2 => self.item_buffer ^= true,
            3 => self.heat_map ^= true,
            4 => self.atlas ^= true,
            5 => self.borders ^= true,
            _ => {}
        }
    }
}

/// Decades of unshot radiance the heat map spans below the largest (white).
pub const HEAT_DECADES: f32 = 4.0;

/// What an inset shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Inset {
    /// The item buffer's IDs in false colour.
    ItemBuffer,
    /// A radiance atlas, tone-mapped.
    Radiance {
        /// Radiance multiplier before tone mapping.
        exposure: f32,
    },
    /// Unshot radiance, log scale, white at the largest.
    Heat {
        /// log10 of the largest unshot radiance.
        log_max: f32,
    },
}

/// The insets' program and quad.
pub struct Insets {
    program: Program,
    quad: Mesh,
}

impl Insets {
    /// Compile the insets' program and make their quad.
    pub fn new(ctx: &GlContext) -> Result<Insets, GlError> {
        let gl = &ctx.gl;
        let program = Program::new(
            gl,
            glsl!("overlay.vert"),
            glsl!("overlay.frag"),
            &[(0, "Corner")],
            &[(0, "Color")],
        )?;
        let corners = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0];
        let quad = Mesh::new(
            gl,
            &corners,
            2,
            &[Attribute {
                location: 0,
                size: 2,
                offset: 0,
            }],
        )?;
        Ok(Insets { program, quad })
    }

    /// Draw `texture` flat into `rect` of the window, inside a light 2-pixel frame.
    pub fn draw(
        &self,
        ctx: &GlContext,
        texture: &Texture,
        what: Inset,
        rect: Viewport,
    ) -> Result<(), GlError> {
        let gl = &ctx.gl;
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            gl.draw_buffer(glow::BACK);
            gl.disable(glow::DEPTH_TEST);
            gl.disable(glow::BLEND);
            gl.disable(glow::CULL_FACE);
            gl.enable(glow::SCISSOR_TEST);
            gl.scissor(rect.x - 2, rect.y - 2, rect.width + 4, rect.height + 4);
            gl.clear_color(0.85, 0.85, 0.85, 1.0);
            gl.clear(glow::COLOR_BUFFER_BIT);
            gl.disable(glow::SCISSOR_TEST);
            gl.viewport(rect.x, rect.y, rect.width, rect.height);
        }
        self.program.use_program();
        texture.bind(0);
        self.program.set_i32("Image", 0);
        let (kind, exposure, log_max) = match what {
            Inset::ItemBuffer => (0, 1.0, 0.0),
            Inset::Radiance { exposure } => (1, exposure, 0.0),
            Inset::Heat { log_max } => (2, 1.0, log_max),
        };
        self.program.set_i32("Kind", kind);
        self.program.set_f32("Exposure", exposure);
        self.program.set_f32("HeatMax", log_max);
        self.program.set_f32("HeatDecades", HEAT_DECADES);
        self.quad.draw();
        ctx.check(NAME)
    }
}

/// Where the insets go in the scene view: the item buffer at the top left, the atlas at the
/// bottom left, each at most a third of the view's height and 90 % of its width, keeping the
/// texture's aspect ratio. `None` when the view is too small for it.
pub fn inset_rect(view: Viewport, texture: (i32, i32), top: bool) -> Option<Viewport> {
    let margin = 10;
    let max_w = (view.width as f32 * 0.9) as i32 - 2 * margin;
    let max_h = view.height / 3 - 2 * margin;
    if max_w < 16 || max_h < 16 || texture.0 <= 0 || texture.1 <= 0 {
        return None;
    }
    let scale = (max_w as f32 / texture.0 as f32).min(max_h as f32 / texture.1 as f32);
    let (w, h) = (
        (texture.0 as f32 * scale) as i32,
        (texture.1 as f32 * scale) as i32,
    );
    let y = if top {
        view.y + view.height - margin - h
    } else {
        view.y + margin
    };
    Some(Viewport {
        x: view.x + margin,
        y,
        width: w.max(1),
        height: h.max(1),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn insets_fit_the_view_and_keep_their_aspect() {
        let view = Viewport::full(720, 720);
        let item = inset_rect(view, (1280, 256), true).unwrap();
        assert_eq!(item.x, 10);
        assert!(item.x + item.width <= 648 - 10);
        assert!((item.width as f32 / item.height as f32 - 5.0).abs() < 0.1);
        assert_eq!(item.y + item.height, 710);
        let atlas = inset_rect(view, (57, 69), false).unwrap();
        assert_eq!(atlas.y, 10);
        assert!(atlas.height <= 220);
        assert!(atlas.y + atlas.height < item.y);
        assert!(inset_rect(Viewport::full(40, 40), (10, 10), true).is_none());
    }

    #[test]
    fn keys_toggle_overlays() {
        let mut s = OverlaySet::from_list(&[Overlay::Shooter]);
        assert!(s.shooter && !s.item_buffer);
        s.toggle(1);
        s.toggle(2);
        s.toggle(5);
        assert!(!s.shooter && s.item_buffer && s.borders && !s.heat_map && !s.atlas);
        assert_eq!(
            OverlaySet::from_list(&[Overlay::None]),
            OverlaySet::from_list(&[])
        );
    }
}
