//! Storage against the walls: bookcases (whose shelves the count fitting fills with books),
//! cabinets with doors or drawers, and wall cabinets.

use crate::builder::Builder;
use crate::count_fitting::Shelf;
use crate::geometry::{Frame, BACK, BOTTOM, FRONT, LEFT, RIGHT, TOP};

/// A bookcase against a wall (back at w = 0): sides, top, back, plinth and shelves.
pub struct Bookcase {
    pub width: f64,
    pub height: f64,
    pub depth: f64,
    /// Shelves, the bottom one included.
    pub rows: usize,
    pub wood: usize,
    pub back: usize,
}

impl Bookcase {
    /// Returns its shelves' free spaces.
    pub fn place(&self, b: &mut Builder, fr: &Frame) -> Vec<Shelf> {
        let Bookcase {
            width: w,
            height: h,
            depth: d,
            rows,
            wood: m,
            back,
        } = *self;
        let t = 0.02;
        let (ul, ur) = (-w / 2.0, w / 2.0);
        b.lbox(
            fr,
            "bookcase_side",
            m,
            [ul, 0.0, 0.0],
            [ul + t, h, d],
            BOTTOM,
        );
        b.lbox(
            fr,
            "bookcase_side",
            m,
            [ur - t, 0.0, 0.0],
            [ur, h, d],
            BOTTOM,
        );
        b.lbox(
            fr,
            "bookcase_top",
            m,
            [ul + t, h - t, 0.0],
            [ur - t, h, d],
            LEFT | RIGHT,
        );
        b.lrect(
            fr,
            "bookcase_back",
            back,
            [ul + t, 0.08, 0.0],
            [ur - t, h - t, 0.01],
            FRONT,
        );
        b.lbox(
            fr,
            "bookcase_plinth",
            m,
            [ul + t, 0.0, d - 0.03],
            [ur - t, 0.08, d - 0.01],
            LEFT | RIGHT | BOTTOM,
        );
        let bottom = 0.08;
        let pitch = (h - t - bottom) / rows as f64;
        let mut shelves = Vec::new();
        for k in 0..rows {
            let v = bottom + k as f64 * pitch;
            let omit = if k == 0 {
                LEFT | RIGHT | BACK | BOTTOM
            } else {
                LEFT | RIGHT | BACK
            };
            b.lbox(
                fr,
                "bookcase_shelf",
                m,
                [ul + t, v, 0.01],
                [ur - t, v + t, d - 0.01],
                omit,
            );
            shelves.push(Shelf {
                fr: *fr,
                u0: ul + t,
                u1: ur - t,
                v0: v + t,
                clearance: pitch - t,
                w_back: 0.01,
                w_front: d - 0.01,
            });
        }
        shelves
    }
}

/// A cabinet's front: n doors side by side, or n drawers one above the other.
#[derive(Clone, Copy)]
pub enum Fronts {
    Doors(usize),
    Drawers(usize),
}

/// A cabinet against a wall: recessed plinth, carcass, doors or drawers with handles.
pub struct Cabinet {
    pub width: f64,
    pub height: f64,
    pub depth: f64,
    pub body: usize,
    pub front: usize,
    pub fronts: Fronts,
    pub handle: usize,
}

impl Cabinet {
    pub fn place(&self, b: &mut Builder, fr: &Frame) {
        let Cabinet {
            width: w,
            height: h,
            depth: d,
            body,
            front,
            fronts,
            handle,
        } = *self;
        let plinth = 0.08;
        b.lbox(
            fr,
            "cabinet_plinth",
            body,
            [-w / 2.0 + 0.03, 0.0, 0.03],
            [w / 2.0 - 0.03, plinth, d - 0.07],
            TOP | BOTTOM | BACK,
        );
        b.lbox(
            fr,
            "cabinet",
            body,
            [-w / 2.0, plinth, 0.0],
            [w / 2.0, h, d - 0.02],
            BACK | BOTTOM,
        );
        let (v0, v1) = (plinth + 0.01, h - 0.01);
        match fronts {
            Fronts::Doors(n) => {
                let dw = w / n as f64;
                for k in 0..n {
                    let u0 = -w / 2.0 + k as f64 * dw + 0.003;
                    let u1 = u0 + dw - 0.006;
                    b.lbox(
                        fr,
                        "cabinet_door",
                        front,
                        [u0, v0, d - 0.02],
                        [u1, v1, d],
                        BACK,
                    );
                    // Handles near the meeting edges.
                    let hu = if k % 2 == 0 { u1 - 0.05 } else { u0 + 0.03 };
                    let hv = (v1 - 0.12).min(1.05);
                    b.lbox(
                        fr,
                        "handle",
                        handle,
                        [hu, hv - 0.12, d],
                        [hu + 0.02, hv, d + 0.025],
                        BACK,
                    );
                }
            }
            Fronts::Drawers(n) => {
                let dh = (v1 - v0) / n as f64;
                for k in 0..n {
                    let a = v0 + k as f64 * dh + 0.003;
                    let c = a + dh - 0.006;
                    b.lbox(
                        fr,
                        "drawer",
                        front,
                        [-w / 2.0 + 0.003, a, d - 0.02],
                        [w / 2.0 - 0.003, c, d],
                        BACK,
                    );
                    let hv = c - 0.05;
                    b.lbox(
                        fr,
                        "handle",
                        handle,
                        [-0.06, hv - 0.02, d],
                        [0.06, hv, d + 0.025],
                        BACK,
                    );
                }
            }
        }
    }
}

/// A wall cabinet (carcass and one door), its frame at its bottom on the wall.
pub fn wall_cabinet(b: &mut Builder, fr: &Frame, w: f64, h: f64, d: f64, m: usize, handle: usize) {
    b.lbox(
        fr,
        "upper_cabinet",
        m,
        [-w / 2.0 + 0.003, 0.0, 0.0],
        [w / 2.0 - 0.003, h, d - 0.02],
        BACK,
    );
    b.lbox(
        fr,
        "cabinet_door",
        m,
        [-w / 2.0 + 0.006, 0.005, d - 0.02],
        [w / 2.0 - 0.006, h - 0.005, d],
        BACK,
    );
    b.lbox(
        fr,
        "handle",
        handle,
        [-0.06, 0.03, d],
        [0.06, 0.05, d + 0.025],
        BACK,
    );
}
