//! Things standing on a table or a cabinet: table lamps, a computer, a television.

use crate::builder::{Builder, Cylinder};
use crate::geometry::{Frame, BOTTOM, FRONT, TOP};
use crate::palette::Pal;

/// A small table lamp standing at local (0, 0, 0).
pub fn table_lamp(b: &mut Builder, fr: &Frame, p: &Pal, shade: usize, n: usize) {
    b.lcylinder(
        fr,
        "lamp_base",
        p.ceramic,
        Cylinder {
            bottom: [0.0, 0.0, 0.0],
            radius: 0.07,
            height: 0.22,
            sides: n * 3 / 4,
            caps: TOP,
        },
    );
    b.lcylinder(
        fr,
        "lamp_pole",
        p.brass,
        Cylinder {
            bottom: [0.0, 0.22, 0.0],
            radius: 0.01,
            height: 0.1,
            sides: 6,
            caps: 0,
        },
    );
    b.lcylinder(
        fr,
        "lamp_shade",
        shade,
        Cylinder {
            bottom: [0.0, 0.32, 0.0],
            radius: 0.15,
            height: 0.2,
            sides: n,
            caps: TOP | BOTTOM,
        },
    );
}

/// A television on a wall frame's surface at height v0: screen box on a foot.
pub fn television(b: &mut Builder, fr: &Frame, p: &Pal, v0: f64, w: f64) {
    let h = w * 9.0 / 16.0;
    b.lbox(
        fr,
        "tv_foot",
        p.black,
        [-0.15, v0, 0.05],
        [0.15, v0 + 0.02, 0.25],
        BOTTOM,
    );
    b.lbox(
        fr,
        "tv_neck",
        p.black,
        [-0.03, v0 + 0.02, 0.12],
        [0.03, v0 + 0.08, 0.16],
        BOTTOM | TOP,
    );
    b.lbox(
        fr,
        "tv",
        p.black,
        [-w / 2.0, v0 + 0.08, 0.1],
        [w / 2.0, v0 + 0.08 + h, 0.16],
        0,
    );
    b.lrect(
        fr,
        "tv_screen",
        p.screen,
        [-w / 2.0 + 0.015, v0 + 0.095, 0.161],
        [w / 2.0 - 0.015, v0 + 0.065 + h, 0.161],
        FRONT,
    );
}

/// A computer monitor, keyboard and a mug on a desk (frame at the desk top, back at w = 0).
pub fn computer(b: &mut Builder, fr: &Frame, p: &Pal) {
    b.lbox(
        fr,
        "monitor_foot",
        p.black,
        [-0.11, 0.0, 0.06],
        [0.11, 0.015, 0.22],
        BOTTOM,
    );
    b.lbox(
        fr,
        "monitor_neck",
        p.black,
        [-0.025, 0.015, 0.1],
        [0.025, 0.12, 0.13],
        BOTTOM | TOP,
    );
    b.lbox(
        fr,
        "monitor",
        p.black,
        [-0.3, 0.12, 0.08],
        [0.3, 0.47, 0.13],
        0,
    );
    b.lrect(
        fr,
        "monitor_screen",
        p.screen,
        [-0.285, 0.135, 0.131],
        [0.285, 0.455, 0.131],
        FRONT,
    );
    b.lbox(
        fr,
        "keyboard",
        p.grey,
        [-0.22, 0.0, 0.3],
        [0.22, 0.02, 0.45],
        BOTTOM,
    );
    b.lcylinder(
        fr,
        "mug",
        p.ceramic,
        Cylinder {
            bottom: [0.34, 0.0, 0.38],
            radius: 0.04,
            height: 0.1,
            sides: 12,
            caps: TOP,
        },
    );
}
