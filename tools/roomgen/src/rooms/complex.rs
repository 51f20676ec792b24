//! The complex room: a four-room flat (living room, kitchen-diner, bedroom, study),
//! 11 m × 8.6 m, six light panels.

use crate::builder::{Builder, Cylinder};
use crate::count_fitting::{Papers, Plan, RoundRug, Tuner, TunerKind, RUG_Y};
use crate::furniture::{
    chair, clock, computer, floor_lamp, picture, plant, sofa, table_lamp, television, wall_cabinet,
    Bed, Bookcase, Cabinet, Fronts, Table, Window,
};
use crate::geometry::{Facing, Frame, BACK, BOTTOM, FRONT, TOP};
use crate::palette::{palette, Pal};
use crate::random::SplitMix;
use crate::shell::{shell, Doorway, Finish, Floor, RoomRect, Side};

pub fn complex(b: &mut Builder, rng: &mut SplitMix) -> Plan {
    let p = palette(b);
    let h = 2.7;
    let t = 0.15; // inner walls
    let living = RoomRect {
        name: "living",
        x0: 0.0,
        x1: 6.0,
        z0: 0.0,
        z1: 4.6,
    };
    let kitchen = RoomRect {
        name: "kitchen",
        x0: 6.0 + t,
        x1: 11.0,
        z0: 0.0,
        z1: 4.6,
    };
    let bedroom = RoomRect {
        name: "bedroom",
        x0: 0.0,
        x1: 4.6,
        z0: 4.6 + t,
        z1: 8.6,
    };
    let study = RoomRect {
        name: "study",
        x0: 4.6 + t,
        x1: 11.0,
        z0: 4.6 + t,
        z1: 8.6,
    };
    // Doorways: living-kitchen (wide), living-bedroom, living-study.
    let to_kitchen = Doorway {
        along_x: true,
        through: (living.x1, kitchen.x0),
        across: (1.2, 2.8),
        height: 2.25,
    };
    let to_bedroom = Doorway {
        along_x: false,
        through: (living.z1, bedroom.z0),
        across: (3.5, 4.35),
        height: 2.05,
    };
    let to_study = Doorway {
        along_x: false,
        through: (living.z1, study.z0),
        across: (5.05, 5.9),
        height: 2.05,
    };
    for d in [&to_kitchen, &to_bedroom, &to_study] {
        d.place(b, p.white, p.oak[0]);
    }
    let planks = |p: &Pal| Floor::Planks {
        width: 0.18,
        length: 1.2,
        mats: p.oak.clone(),
    };
    let f_living = Finish {
        wall: b.material("wall_warm", [0.82, 0.77, 0.66]),
        dado: b.material("dado_sage", [0.5, 0.6, 0.52]),
        floor: planks(&p),
        ceiling_tile: 0.6,
        lights: vec![[2, 3, 1, 2], [7, 3, 1, 2]],
    };
    let f_kitchen = Finish {
        wall: b.material("wall_yellow", [0.86, 0.8, 0.56]),
        dado: b.material("dado_white", [0.8, 0.8, 0.76]),
        floor: Floor::Tiles {
            size: 0.4,
            mats: [
                b.material("tile_light", [0.78, 0.76, 0.72]),
                b.material("tile_dark", [0.3, 0.3, 0.33]),
            ],
        },
        ceiling_tile: 0.6,
        lights: vec![[2, 3, 2, 1], [5, 3, 1, 2]],
    };
    let f_bedroom = Finish {
        wall: b.material("wall_blue", [0.62, 0.7, 0.8]),
        dado: b.material("dado_blue", [0.4, 0.5, 0.64]),
        floor: planks(&p),
        ceiling_tile: 0.6,
        lights: vec![[3, 3, 2, 1]],
    };
    let f_study = Finish {
        wall: b.material("wall_green", [0.66, 0.74, 0.6]),
        dado: b.material("dado_green", [0.36, 0.46, 0.34]),
        floor: planks(&p),
        ceiling_tile: 0.6,
        lights: vec![[5, 2, 2, 1]],
    };
    shell(
        b,
        rng,
        &p,
        &living,
        h,
        &f_living,
        &[
            to_kitchen.opening(Side::East),
            to_bedroom.opening(Side::North),
            to_study.opening(Side::North),
        ],
    );
    shell(
        b,
        rng,
        &p,
        &kitchen,
        h,
        &f_kitchen,
        &[to_kitchen.opening(Side::West)],
    );
    shell(
        b,
        rng,
        &p,
        &bedroom,
        h,
        &f_bedroom,
        &[to_bedroom.opening(Side::South)],
    );
    shell(
        b,
        rng,
        &p,
        &study,
        h,
        &f_study,
        &[to_study.opening(Side::South)],
    );

    let mut shelves = Vec::new();

    // Living room. North wall: two bookcases and a plant; west wall: sofa under the tuned canvas;
    // south wall: a window; east wall: a TV unit; in the middle a coffee table on the tuned rug.
    for x in [0.75, 1.8] {
        shelves.extend(
            Bookcase {
                width: 1.0,
                height: 2.2,
                depth: 0.34,
                rows: 6,
                wood: p.walnut,
                back: p.wood,
            }
            .place(b, &living.wall(Side::North, x, 0.01)),
        );
    }
    plant(b, &Frame::new(2.85, 0.0, 4.2, Facing::NegZ), &p, 0.22, 1.4);
    let wf = living.wall(Side::South, 2.6, 0.0);
    Window {
        width: 1.8,
        glass: (0.95, 2.2),
        ceiling: h,
        curtain: p.mustard,
    }
    .place(b, &wf, &p);
    let sofa_fr = living.wall(Side::West, 2.3, 0.02);
    sofa(b, &sofa_fr, 2.3, 0.9, p.grey, p.grey, 3);
    let canvas = Tuner {
        kind: TunerKind::Canvas {
            fr: living.wall(Side::West, 2.3, 0.0),
            v: 1.65,
            w: 0.032,
        },
        material: p.canvas,
        a: (0.8, 1.2, 1.5),
        b: (0.5, 0.7, 0.9),
    };
    let (cw, ch) = (canvas.a.2, canvas.b.2);
    b.lbox(
        &living.wall(Side::West, 2.3, 0.0),
        "picture_frame",
        p.frame,
        [-cw / 2.0 - 0.05, 1.65 - ch / 2.0 - 0.05, 0.0],
        [cw / 2.0 + 0.05, 1.65 + ch / 2.0 + 0.05, 0.03],
        BACK,
    );
    for z in [0.75, 3.85] {
        let st = living.wall(Side::West, z, 0.02);
        Table {
            name: "side_table",
            width: 0.45,
            depth: 0.45,
            height: 0.55,
            leg: 0.04,
            top: p.walnut,
            legs: p.walnut,
        }
        .place(b, &st);
        table_lamp(b, &st.at(0.0, 0.55, 0.22), &p, p.cream, 24);
    }
    let coffee = Frame::new(1.75, 0.0, 2.3, Facing::PosX);
    Table {
        name: "coffee_table",
        width: 1.2,
        depth: 0.64,
        height: 0.42,
        leg: 0.05,
        top: p.walnut,
        legs: p.walnut,
    }
    .place(b, &coffee.at(0.0, 0.0, -0.32));
    b.lbox(
        &coffee.at(0.2, 0.42, -0.1),
        "coffee_book",
        p.books[3],
        [0.0, 0.0, 0.0],
        [0.3, 0.04, 0.22],
        BOTTOM,
    );
    let rug = Tuner {
        kind: TunerKind::Rug { x: 1.85, z: 2.3 },
        material: p.rug_red,
        a: (1.0, 1.4, 1.6),
        b: (1.6, 2.3, 2.9),
    };
    // Armchairs facing the sofa.
    for z in [1.3, 3.3] {
        sofa(
            b,
            &Frame::new(3.55, 0.0, z, Facing::NegX),
            0.85,
            0.85,
            p.mustard,
            p.mustard,
            1,
        );
    }
    let tv = living.wall(Side::East, 3.7, 0.01);
    Cabinet {
        width: 1.4,
        height: 0.5,
        depth: 0.42,
        body: p.walnut,
        front: p.walnut,
        fronts: Fronts::Drawers(2),
        handle: p.brass,
    }
    .place(b, &tv);
    television(b, &tv.at(0.0, 0.5, 0.0), &p, 0.0, 1.1);
    floor_lamp(b, &Frame::new(5.6, 0.0, 0.4, Facing::NegX), &p, p.cream);
    clock(b, &living.wall(Side::East, 0.55, 0.0), &p, 1.9, 0.18, 64);

    // Kitchen: a counter run along the east wall (base cabinets, worktop, sink, hob, wall
    // cabinets, hood, tiled splashback), a fridge; a round dining table with four chairs.
    let run = kitchen.wall(Side::East, 2.5, 0.0);
    let (len, n_units) = (3.6, 6);
    let unit = len / n_units as f64;
    for k in 0..n_units {
        let u = -len / 2.0 + (k as f64 + 0.5) * unit;
        let fronts = if k == 1 || k == 4 {
            Fronts::Drawers(3)
        } else {
            Fronts::Doors(1)
        };
        Cabinet {
            width: unit,
            height: 0.86,
            depth: 0.6,
            body: p.white,
            front: p.white,
            fronts,
            handle: p.steel,
        }
        .place(b, &run.at(u, 0.0, 0.0));
    }
    let wood_top = b.material("worktop", [0.4, 0.32, 0.26]);
    b.lbox(
        &run,
        "worktop",
        wood_top,
        [-len / 2.0, 0.86, 0.0],
        [len / 2.0, 0.9, 0.63],
        BACK,
    );
    let sink_u = -len / 2.0 + 1.5 * unit;
    b.lrect(
        &run,
        "sink",
        p.steel,
        [sink_u - 0.25, 0.9005, 0.12],
        [sink_u + 0.25, 0.9005, 0.5],
        TOP,
    );
    b.lcylinder(
        &run,
        "tap",
        p.steel,
        Cylinder {
            bottom: [sink_u, 0.9, 0.06],
            radius: 0.015,
            height: 0.3,
            sides: 8,
            caps: TOP,
        },
    );
    b.lbox(
        &run,
        "tap_spout",
        p.steel,
        [sink_u - 0.01, 1.17, 0.075],
        [sink_u + 0.01, 1.19, 0.2],
        BACK,
    );
    let hob_u = -len / 2.0 + 4.5 * unit;
    b.lrect(
        &run,
        "hob",
        p.black,
        [hob_u - 0.29, 0.9005, 0.08],
        [hob_u + 0.29, 0.9005, 0.56],
        TOP,
    );
    for (du, dw, r) in [
        (-0.14, 0.19, 0.09),
        (0.14, 0.19, 0.07),
        (-0.14, 0.44, 0.07),
        (0.14, 0.44, 0.09),
    ] {
        let c = run.world([hob_u + du, 0.901, dw]);
        b.hdisc("burner", p.grey, c, r, 40);
    }
    for k in 0..n_units {
        let u = -len / 2.0 + (k as f64 + 0.5) * unit;
        if k == 4 {
            b.lbox(
                &run,
                "hood",
                p.steel,
                [u - unit / 2.0 + 0.01, 1.55, 0.0],
                [u + unit / 2.0 - 0.01, 1.75, 0.5],
                BACK,
            );
            b.lbox(
                &run,
                "hood_flue",
                p.steel,
                [u - 0.12, 1.75, 0.0],
                [u + 0.12, h, 0.25],
                BACK | TOP,
            );
            continue;
        }
        let top = run.at(u, 1.45, 0.0);
        wall_cabinet(b, &top, unit, 0.75, 0.35, p.white, p.steel);
    }
    // Splashback tiles (0.15 m, 4 mm joints).
    let tile_m = b.material("splash_tile", [0.82, 0.86, 0.84]);
    let cols = (len / 0.15).floor() as usize;
    for i in 0..cols {
        for j in 0..3 {
            let u = -len / 2.0 + i as f64 * 0.15 + 0.002;
            let v = 0.902 + j as f64 * 0.15 + 0.002;
            b.lrect(
                &run,
                "splash_tile",
                tile_m,
                [u, v, 0.003],
                [u + 0.146, v + 0.146, 0.003],
                FRONT,
            );
        }
    }
    let fridge = kitchen.wall(Side::East, 0.37, 0.01);
    b.lbox(
        &fridge,
        "fridge",
        p.white,
        [-0.32, 0.0, 0.0],
        [0.32, 1.9, 0.62],
        BACK | BOTTOM,
    );
    b.lbox(
        &fridge,
        "fridge_door",
        p.white,
        [-0.315, 0.02, 0.62],
        [0.315, 0.78, 0.66],
        BACK,
    );
    b.lbox(
        &fridge,
        "fridge_door",
        p.white,
        [-0.315, 0.8, 0.62],
        [0.315, 1.88, 0.66],
        BACK,
    );
    for (v0, v1) in [(0.5, 0.74), (0.84, 1.2)] {
        b.lbox(
            &fridge,
            "handle",
            p.steel,
            [0.25, v0, 0.66],
            [0.27, v1, 0.69],
            BACK,
        );
    }
    // Round dining table.
    let (tx, tz) = (8.1, 2.1);
    b.hdisc("rug_round", p.rug_blue, [tx, RUG_Y, tz], 1.05, 64);
    b.cylinder(
        "dining_foot",
        p.walnut,
        Cylinder {
            bottom: [tx, 0.0, tz],
            radius: 0.3,
            height: 0.03,
            sides: 32,
            caps: TOP,
        },
    );
    b.cylinder(
        "dining_column",
        p.walnut,
        Cylinder {
            bottom: [tx, 0.03, tz],
            radius: 0.06,
            height: 0.69,
            sides: 12,
            caps: 0,
        },
    );
    b.cylinder(
        "dining_top",
        p.walnut,
        Cylinder {
            bottom: [tx, 0.72, tz],
            radius: 0.6,
            height: 0.04,
            sides: 96,
            caps: TOP | BOTTOM,
        },
    );
    for k in 0..4 {
        let a = std::f64::consts::FRAC_PI_2 * k as f64;
        let (dx, dz) = (0.33 * a.cos(), 0.33 * a.sin());
        b.hdisc("plate", p.ceramic, [tx + dx, 0.762, tz + dz], 0.12, 48);
        b.cylinder(
            "glass",
            p.glass,
            Cylinder {
                bottom: [tx + 0.3 * (a + 0.6).cos(), 0.76, tz + 0.3 * (a + 0.6).sin()],
                radius: 0.035,
                height: 0.11,
                sides: 16,
                caps: TOP,
            },
        );
    }
    b.cylinder(
        "fruit_bowl",
        p.ceramic,
        Cylinder {
            bottom: [tx, 0.76, tz],
            radius: 0.13,
            height: 0.07,
            sides: 48,
            caps: TOP,
        },
    );
    for (x, z, f) in [
        (tx + 0.92, tz, Facing::NegX),
        (tx - 0.92, tz, Facing::PosX),
        (tx, tz + 0.92, Facing::NegZ),
        (tx, tz - 0.92, Facing::PosZ),
    ] {
        chair(b, &Frame::new(x, 0.0, z, f), p.walnut, p.green);
    }
    clock(b, &kitchen.wall(Side::South, 8.1, 0.0), &p, 1.9, 0.2, 64);
    let wfk = kitchen.wall(Side::North, 8.1, 0.0);
    Window {
        width: 1.6,
        glass: (1.0, 2.2),
        ceiling: h,
        curtain: p.red,
    }
    .place(b, &wfk, &p);
    plant(b, &Frame::new(6.55, 0.0, 0.4, Facing::PosZ), &p, 0.2, 1.3);

    // Bedroom: bed against the north wall between two night stands with lamps, a wardrobe on
    // the west wall, a chest of drawers, a window on the west wall, a rug.
    let bed_fr = bedroom.wall(Side::North, 2.3, 0.01);
    let duvet = b.material("duvet", [0.78, 0.7, 0.55]);
    Bed {
        width: 1.6,
        length: 2.0,
        wood: p.walnut,
        sheet: p.white,
        duvet,
        pillow: p.cream,
    }
    .place(b, &bed_fr);
    for x in [1.15, 3.45] {
        let ns = bedroom.wall(Side::North, x, 0.01);
        Cabinet {
            width: 0.5,
            height: 0.55,
            depth: 0.4,
            body: p.walnut,
            front: p.walnut,
            fronts: Fronts::Drawers(2),
            handle: p.brass,
        }
        .place(b, &ns);
        table_lamp(b, &ns.at(0.0, 0.55, 0.2), &p, p.cream, 24);
    }
    picture(
        b,
        &bedroom.wall(Side::North, 2.3, 0.0),
        &p,
        1.65,
        1.2,
        0.5,
        p.rug_blue,
    );
    let wardrobe = bedroom.wall(Side::East, 6.6, 0.01);
    Cabinet {
        width: 1.8,
        height: 2.2,
        depth: 0.6,
        body: p.white,
        front: p.wood,
        fronts: Fronts::Doors(3),
        handle: p.brass,
    }
    .place(b, &wardrobe);
    let chest = bedroom.wall(Side::South, 1.5, 0.01);
    Cabinet {
        width: 1.2,
        height: 0.85,
        depth: 0.48,
        body: p.wood,
        front: p.wood,
        fronts: Fronts::Drawers(4),
        handle: p.brass,
    }
    .place(b, &chest);
    b.cylinder(
        "vase",
        p.rug_blue,
        Cylinder {
            bottom: chest.world([0.35, 0.85, 0.24]),
            radius: 0.06,
            height: 0.25,
            sides: 16,
            caps: TOP,
        },
    );
    // A round mirror above the chest of drawers.
    let mirror = b.material("mirror", [0.7, 0.72, 0.74]);
    b.vdisc(&chest, "mirror", mirror, [0.0, 1.55, 0.02], 0.35, 64);
    let wfb = bedroom.wall(Side::West, 6.8, 0.0);
    Window {
        width: 1.4,
        glass: (1.0, 2.2),
        ceiling: h,
        curtain: p.blue,
    }
    .place(b, &wfb, &p);
    b.hdisc("rug_round", p.rug_blue, [2.3, RUG_Y, 5.75], 0.7, 96);
    plant(b, &Frame::new(4.2, 0.0, 8.2, Facing::NegZ), &p, 0.18, 1.1);

    // Study: bookcases along the north and east walls, a desk with a computer and papers, an
    // office chair, an armchair with a floor lamp, a filing cabinet, the round rug.
    for x in [5.5, 6.55, 7.6, 8.65, 9.7] {
        shelves.extend(
            Bookcase {
                width: 1.0,
                height: 2.2,
                depth: 0.34,
                rows: 6,
                wood: p.walnut,
                back: p.wood,
            }
            .place(b, &study.wall(Side::North, x, 0.01)),
        );
    }
    for z in [5.9, 6.95] {
        shelves.extend(
            Bookcase {
                width: 1.0,
                height: 2.2,
                depth: 0.34,
                rows: 6,
                wood: p.walnut,
                back: p.wood,
            }
            .place(b, &study.wall(Side::West, z, 0.01)),
        );
    }
    let desk = study.wall(Side::South, 8.6, 0.02);
    Table {
        name: "desk",
        width: 1.6,
        depth: 0.75,
        height: 0.75,
        leg: 0.05,
        top: p.wood,
        legs: p.walnut,
    }
    .place(b, &desk);
    computer(b, &desk.at(-0.25, 0.75, 0.02), &p);
    let papers = Papers {
        fr: desk.at(0.0, 0.75, 0.0),
        u0: 0.36,
        w: 0.36,
        material: p.paper,
    };
    chair(
        b,
        &Frame::new(8.35, 0.0, 5.95, Facing::NegZ),
        p.walnut,
        p.blue,
    );
    let filing = study.wall(Side::South, 9.9, 0.01);
    Cabinet {
        width: 0.5,
        height: 1.1,
        depth: 0.6,
        body: p.grey,
        front: p.grey,
        fronts: Fronts::Drawers(4),
        handle: p.steel,
    }
    .place(b, &filing);
    sofa(
        b,
        &study.wall(Side::South, 6.4, 0.02),
        0.9,
        0.85,
        p.red,
        p.red,
        1,
    );
    floor_lamp(b, &Frame::new(7.15, 0.0, 5.05, Facing::PosZ), &p, p.cream);
    clock(b, &study.wall(Side::South, 8.6, 0.0), &p, 1.9, 0.16, 64);
    let wfs = study.wall(Side::East, 6.7, 0.0);
    Window {
        width: 1.2,
        glass: (1.0, 2.2),
        ceiling: h,
        curtain: p.green,
    }
    .place(b, &wfs, &p);

    Plan {
        shelves,
        books: p.books.clone(),
        papers,
        round_rug: RoundRug {
            x: 7.6,
            z: 6.9,
            radius: 0.9,
            material: p.rug_red,
        },
        tuners: [rug, canvas],
    }
}
