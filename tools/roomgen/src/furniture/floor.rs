//! Furniture that stands on the floor: tables, chairs, sofas, beds, plants and floor lamps.

use crate::builder::{Builder, Cylinder};
use crate::geometry::{Frame, BACK, BOTTOM, LEFT, RIGHT, TOP};
use crate::palette::Pal;

/// A table: top and four legs.
pub struct Table {
    /// The piece's name (its legs are `<name>_leg`).
    pub name: &'static str,
    pub width: f64,
    pub depth: f64,
    pub height: f64,
    /// The legs' side.
    pub leg: f64,
    pub top: usize,
    pub legs: usize,
}

impl Table {
    pub fn place(&self, b: &mut Builder, fr: &Frame) {
        let Table {
            name,
            width: w,
            depth: d,
            height: h,
            leg,
            top,
            legs,
        } = *self;
        let t = 0.035;
        b.lbox(fr, name, top, [-w / 2.0, h - t, 0.0], [w / 2.0, h, d], 0);
        let inset = 0.04;
        for (u, ww) in [
            (-w / 2.0 + inset, inset),
            (w / 2.0 - inset - leg, inset),
            (-w / 2.0 + inset, d - inset - leg),
            (w / 2.0 - inset - leg, d - inset - leg),
        ] {
            b.lbox(
                fr,
                &format!("{name}_leg"),
                legs,
                [u, 0.0, ww],
                [u + leg, h - t, ww + leg],
                TOP | BOTTOM,
            );
        }
    }
}

/// A chair facing +w: legs, seat, back posts and two slats.
pub fn chair(b: &mut Builder, fr: &Frame, wood: usize, seat: usize) {
    let (w, d, sh, leg) = (0.44, 0.44, 0.46, 0.035);
    let st = 0.04;
    b.lbox(
        fr,
        "chair_seat",
        seat,
        [-w / 2.0, sh - st, 0.0],
        [w / 2.0, sh, d],
        0,
    );
    for (u, ww) in [
        (-w / 2.0 + 0.01, 0.01),
        (w / 2.0 - 0.01 - leg, 0.01),
        (-w / 2.0 + 0.01, d - 0.01 - leg),
        (w / 2.0 - 0.01 - leg, d - 0.01 - leg),
    ] {
        b.lbox(
            fr,
            "chair_leg",
            wood,
            [u, 0.0, ww],
            [u + leg, sh - st, ww + leg],
            TOP | BOTTOM,
        );
    }
    let (p0, p1) = (0.01, 0.01 + leg);
    for u in [-w / 2.0 + 0.01, w / 2.0 - 0.01 - leg] {
        b.lbox(
            fr,
            "chair_post",
            wood,
            [u, sh, p0],
            [u + leg, 0.92, p1],
            BOTTOM,
        );
    }
    for (v0, v1) in [(0.62, 0.7), (0.8, 0.88)] {
        b.lbox(
            fr,
            "chair_slat",
            wood,
            [-w / 2.0 + 0.01 + leg, v0, p0 + 0.008],
            [w / 2.0 - 0.01 - leg, v1, p1 - 0.008],
            LEFT | RIGHT,
        );
    }
}

/// A sofa (or an armchair) against its back: base, arms, back, seat and back cushions.
pub fn sofa(
    b: &mut Builder,
    fr: &Frame,
    w: f64,
    d: f64,
    body: usize,
    cushion: usize,
    seats: usize,
) {
    let arm = 0.18;
    let (ul, ur) = (-w / 2.0, w / 2.0);
    b.lbox(
        fr,
        "sofa_base",
        body,
        [ul + arm, 0.06, 0.0],
        [ur - arm, 0.4, d],
        BOTTOM | LEFT | RIGHT,
    );
    for (a, c) in [(ul, ul + arm), (ur - arm, ur)] {
        b.lbox(fr, "sofa_arm", body, [a, 0.0, 0.0], [c, 0.64, d], BOTTOM);
    }
    b.lbox(
        fr,
        "sofa_back",
        body,
        [ul + arm, 0.4, 0.0],
        [ur - arm, 0.86, 0.2],
        BOTTOM | LEFT | RIGHT,
    );
    let inner = (ur - ul - 2.0 * arm) / seats as f64;
    for k in 0..seats {
        let a = ul + arm + k as f64 * inner + 0.005;
        let c = a + inner - 0.01;
        b.lbox(
            fr,
            "sofa_cushion",
            cushion,
            [a, 0.4, 0.2],
            [c, 0.53, d - 0.02],
            BOTTOM,
        );
        b.lbox(
            fr,
            "sofa_cushion",
            cushion,
            [a, 0.53, 0.2],
            [c, 0.82, 0.34],
            BOTTOM,
        );
    }
    // Little feet under the base.
    for u in [ul + arm + 0.03, ur - arm - 0.07] {
        for ww in [0.04, d - 0.08] {
            b.lbox(
                fr,
                "sofa_foot",
                body,
                [u, 0.0, ww],
                [u + 0.04, 0.06, ww + 0.04],
                TOP | BOTTOM,
            );
        }
    }
}

/// A bed with its head at w = 0: headboard, frame on legs, mattress, duvet, pillows.
pub struct Bed {
    pub width: f64,
    pub length: f64,
    pub wood: usize,
    pub sheet: usize,
    pub duvet: usize,
    pub pillow: usize,
}

impl Bed {
    pub fn place(&self, b: &mut Builder, fr: &Frame) {
        let Bed {
            width: w,
            length: l,
            wood,
            sheet,
            duvet,
            pillow,
        } = *self;
        b.lbox(
            fr,
            "headboard",
            wood,
            [-w / 2.0 - 0.03, 0.0, 0.0],
            [w / 2.0 + 0.03, 1.05, 0.06],
            BOTTOM,
        );
        b.lbox(
            fr,
            "bed_frame",
            wood,
            [-w / 2.0, 0.12, 0.06],
            [w / 2.0, 0.34, l + 0.06],
            BACK,
        );
        for u in [-w / 2.0 + 0.02, w / 2.0 - 0.07] {
            for ww in [0.08, l + 0.06 - 0.07] {
                b.lbox(
                    fr,
                    "bed_leg",
                    wood,
                    [u, 0.0, ww],
                    [u + 0.05, 0.12, ww + 0.05],
                    TOP | BOTTOM,
                );
            }
        }
        b.lbox(
            fr,
            "mattress",
            sheet,
            [-w / 2.0 + 0.02, 0.34, 0.08],
            [w / 2.0 - 0.02, 0.54, l + 0.04],
            BOTTOM,
        );
        b.lbox(
            fr,
            "duvet",
            duvet,
            [-w / 2.0, 0.54, 0.62],
            [w / 2.0, 0.6, l + 0.06],
            BOTTOM,
        );
        let n = if w > 1.2 { 2 } else { 1 };
        let pw = (w - 0.16) / n as f64;
        for k in 0..n {
            let a = -w / 2.0 + 0.08 + k as f64 * pw + 0.02;
            b.lbox(
                fr,
                "pillow",
                pillow,
                [a, 0.54, 0.14],
                [a + pw - 0.04, 0.66, 0.52],
                BOTTOM,
            );
        }
    }
}

/// A potted plant standing at local (0, 0, 0) of `fr`: pot, soil, and a stylised shrub.
pub fn plant(b: &mut Builder, fr: &Frame, p: &Pal, r: f64, height: f64) {
    let pot_h = 0.4 * r.max(0.2) / 0.2 * 0.8;
    b.lcylinder(
        fr,
        "pot",
        p.terracotta,
        Cylinder {
            bottom: [0.0, 0.0, 0.0],
            radius: r,
            height: pot_h,
            sides: 12,
            caps: TOP,
        },
    );
    b.lbox(
        fr,
        "plant_stem",
        p.walnut,
        [-0.02, pot_h, -0.02],
        [0.02, pot_h + 0.25, 0.02],
        BOTTOM | TOP,
    );
    let mut y = pot_h + 0.25;
    let mut rr = r * 1.6;
    let layers = ((height - y) / 0.3).round().max(1.0) as usize;
    let lh = (height - y) / layers as f64;
    for k in 0..layers {
        let m = if k % 2 == 0 { p.leaf } else { p.leaf_dark };
        let caps = if k == 0 { TOP | BOTTOM } else { TOP };
        b.lcylinder(
            fr,
            "foliage",
            m,
            Cylinder {
                bottom: [0.0, y, 0.0],
                radius: rr,
                height: lh,
                sides: 10,
                caps,
            },
        );
        y += lh;
        rr *= 0.78;
    }
}

/// A floor lamp (not a light source): base disc, pole, shade.
pub fn floor_lamp(b: &mut Builder, fr: &Frame, p: &Pal, shade: usize) {
    b.lcylinder(
        fr,
        "lamp_base",
        p.black,
        Cylinder {
            bottom: [0.0, 0.0, 0.0],
            radius: 0.16,
            height: 0.03,
            sides: 32,
            caps: TOP,
        },
    );
    b.lcylinder(
        fr,
        "lamp_pole",
        p.steel,
        Cylinder {
            bottom: [0.0, 0.03, 0.0],
            radius: 0.015,
            height: 1.32,
            sides: 8,
            caps: 0,
        },
    );
    b.lcylinder(
        fr,
        "lamp_shade",
        shade,
        Cylinder {
            bottom: [0.0, 1.35, 0.0],
            radius: 0.22,
            height: 0.3,
            sides: 32,
            caps: TOP | BOTTOM,
        },
    );
}
