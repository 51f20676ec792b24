//! Things on the walls: windows with curtains, doors, pictures and clocks.

use crate::builder::Builder;
use crate::geometry::{Frame, BACK, BOTTOM, FRONT, LEFT, RIGHT, TOP};
use crate::palette::Pal;

/// A window on a wall frame (the wall at w = 0): glass, frame, mullion, sill, curtains on a rod.
pub struct Window {
    pub width: f64,
    /// Bottom and top of the glass.
    pub glass: (f64, f64),
    /// The room's height: the curtain rod hangs below the ceiling.
    pub ceiling: f64,
    pub curtain: usize,
}

impl Window {
    pub fn place(&self, b: &mut Builder, fr: &Frame, p: &Pal) {
        let Window {
            width: w,
            glass: (y0, y1),
            ceiling: room_h,
            curtain,
        } = *self;
        let (ul, ur) = (-w / 2.0, w / 2.0);
        let f = 0.06;
        b.lrect(
            fr,
            "window_glass",
            p.glass,
            [ul, y0, 0.002],
            [ur, y1, 0.002],
            FRONT,
        );
        b.lbox(
            fr,
            "window_frame",
            p.white,
            [ul - f, y0 - f, 0.0],
            [ul, y1 + f, 0.05],
            BACK,
        );
        b.lbox(
            fr,
            "window_frame",
            p.white,
            [ur, y0 - f, 0.0],
            [ur + f, y1 + f, 0.05],
            BACK,
        );
        b.lbox(
            fr,
            "window_frame",
            p.white,
            [ul, y1, 0.0],
            [ur, y1 + f, 0.05],
            BACK | LEFT | RIGHT,
        );
        b.lbox(
            fr,
            "window_frame",
            p.white,
            [ul, y0 - f, 0.0],
            [ur, y0, 0.05],
            BACK | LEFT | RIGHT,
        );
        b.lbox(
            fr,
            "window_mullion",
            p.white,
            [-0.02, y0, 0.0],
            [0.02, y1, 0.035],
            BACK | TOP | BOTTOM,
        );
        b.lbox(
            fr,
            "window_sill",
            p.white,
            [ul - f - 0.04, y0 - f - 0.04, 0.0],
            [ur + f + 0.04, y0 - f, 0.16],
            BACK,
        );
        let rod = room_h - 0.12;
        b.lbox(
            fr,
            "curtain_rod",
            p.steel,
            [ul - 0.6, rod, 0.2],
            [ur + 0.6, rod + 0.025, 0.225],
            0,
        );
        for (a, c) in [(ul - 0.55, ul - 0.12), (ur + 0.12, ur + 0.55)] {
            b.lbox(
                fr,
                "curtain",
                curtain,
                [a, 0.03, 0.23],
                [c, rod - 0.005, 0.29],
                0,
            );
        }
    }
}

/// A closed door on a wall frame: leaf, two raised panels, handle, architrave.
pub fn door(b: &mut Builder, fr: &Frame, p: &Pal, leaf: usize) {
    let (w, h) = (0.9, 2.05);
    b.lrect(
        fr,
        "door_leaf",
        leaf,
        [-w / 2.0, 0.0, 0.03],
        [w / 2.0, h, 0.03],
        FRONT,
    );
    b.lbox(
        fr,
        "door_panel",
        leaf,
        [-0.33, 1.1, 0.03],
        [0.33, 1.9, 0.045],
        BACK,
    );
    b.lbox(
        fr,
        "door_panel",
        leaf,
        [-0.33, 0.15, 0.03],
        [0.33, 0.95, 0.045],
        BACK,
    );
    b.lbox(
        fr,
        "door_handle",
        p.brass,
        [0.32, 1.0, 0.045],
        [0.42, 1.03, 0.09],
        BACK,
    );
    b.lbox(
        fr,
        "architrave",
        p.white,
        [-w / 2.0 - 0.07, 0.0, 0.0],
        [-w / 2.0, h, 0.04],
        BACK | BOTTOM | TOP,
    );
    b.lbox(
        fr,
        "architrave",
        p.white,
        [w / 2.0, 0.0, 0.0],
        [w / 2.0 + 0.07, h, 0.04],
        BACK | BOTTOM | TOP,
    );
    b.lbox(
        fr,
        "architrave",
        p.white,
        [-w / 2.0 - 0.07, h, 0.0],
        [w / 2.0 + 0.07, h + 0.07, 0.04],
        BACK,
    );
    // The wall's depth between leaf and architrave: the leaf's jambs.
    b.lrect(
        fr,
        "door_jamb",
        p.white,
        [-w / 2.0, 0.0, 0.0],
        [-w / 2.0, h, 0.03],
        RIGHT,
    );
    b.lrect(
        fr,
        "door_jamb",
        p.white,
        [w / 2.0, 0.0, 0.0],
        [w / 2.0, h, 0.03],
        LEFT,
    );
    b.lrect(
        fr,
        "door_jamb",
        p.white,
        [-w / 2.0, h, 0.0],
        [w / 2.0, h, 0.03],
        BOTTOM,
    );
}

/// A picture on a wall frame, with a fixed canvas.
pub fn picture(b: &mut Builder, fr: &Frame, p: &Pal, v: f64, w: f64, h: f64, canvas: usize) {
    b.lbox(
        fr,
        "picture_frame",
        p.frame,
        [-w / 2.0 - 0.04, v - h / 2.0 - 0.04, 0.0],
        [w / 2.0 + 0.04, v + h / 2.0 + 0.04, 0.03],
        BACK,
    );
    b.lrect(
        fr,
        "canvas",
        canvas,
        [-w / 2.0, v - h / 2.0, 0.032],
        [w / 2.0, v + h / 2.0, 0.032],
        FRONT,
    );
}

/// A wall clock: a disc with two hands.
pub fn clock(b: &mut Builder, fr: &Frame, p: &Pal, v: f64, r: f64, n: usize) {
    b.vdisc(fr, "clock", p.cream, [0.0, v, 0.03], r, n);
    b.lrect(
        fr,
        "clock_hand",
        p.black,
        [-0.006, v, 0.032],
        [0.006, v + 0.7 * r, 0.032],
        FRONT,
    );
    b.lrect(
        fr,
        "clock_hand",
        p.black,
        [0.0, v - 0.006, 0.033],
        [0.5 * r, v + 0.006, 0.033],
        FRONT,
    );
}
