//! The simple room: a study / living room, 5.4 m × 4.4 m × 2.7 m, two light panels.

use crate::builder::Builder;
use crate::count_fitting::{Papers, Plan, RoundRug, Tuner, TunerKind};
use crate::furniture::{
    chair, clock, computer, door, plant, sofa, table_lamp, television, Bookcase, Cabinet, Fronts,
    Table, Window,
};
use crate::geometry::{Facing, Frame, BACK, BOTTOM};
use crate::palette::palette;
use crate::random::SplitMix;
use crate::shell::{shell, Finish, Floor, RoomRect, Side};

pub fn simple(b: &mut Builder, rng: &mut SplitMix) -> Plan {
    let p = palette(b);
    let h = 2.7;
    let room = RoomRect {
        name: "study",
        x0: 0.0,
        x1: 5.4,
        z0: 0.0,
        z1: 4.4,
    };
    let finish = Finish {
        wall: b.material("wall_warm", [0.82, 0.77, 0.66]),
        dado: b.material("dado_sage", [0.5, 0.6, 0.52]),
        floor: Floor::Planks {
            width: 0.18,
            length: 1.2,
            mats: p.oak.clone(),
        },
        ceiling_tile: 0.6,
        // Two 0.6 × 1.2 m panels, symmetric about the room's centre.
        lights: vec![[2, 3, 1, 2], [6, 3, 1, 2]],
    };
    shell(b, rng, &p, &room, h, &finish, &[]);

    // North wall: two bookcases, a low cabinet with a lamp, a door; a plant in the corner.
    let mut shelves = Vec::new();
    // (Their boards share corners: fewer vertices, see the crate's notes in lib.rs.)
    b.shared = true;
    for x in [1.0, 2.06] {
        let fr = room.wall(Side::North, x, 0.01);
        shelves.extend(
            Bookcase {
                width: 1.0,
                height: 2.1,
                depth: 0.34,
                rows: 6,
                wood: p.walnut,
                back: p.wood,
            }
            .place(b, &fr),
        );
    }
    b.shared = false;
    let fr = room.wall(Side::North, 3.1, 0.01);
    Cabinet {
        width: 0.9,
        height: 0.8,
        depth: 0.45,
        body: p.white,
        front: p.white,
        fronts: Fronts::Doors(2),
        handle: p.brass,
    }
    .place(b, &fr);
    table_lamp(b, &fr.at(0.2, 0.8, 0.22), &p, p.cream, 16);
    clock(b, &room.wall(Side::North, 3.1, 0.0), &p, 1.75, 0.16, 16);
    door(b, &room.wall(Side::North, 4.25, 0.0), &p, p.wood);
    plant(b, &Frame::new(5.05, 0.0, 4.05, Facing::NegZ), &p, 0.2, 1.3);

    // West wall: a window with curtains, a desk under it with a computer and a chair, a filing
    // cabinet in the corner.
    let wf = room.wall(Side::West, 2.2, 0.0);
    Window {
        width: 1.6,
        glass: (1.0, 2.2),
        ceiling: h,
        curtain: p.green,
    }
    .place(b, &wf, &p);
    let desk = room.wall(Side::West, 2.2, 0.02);
    Table {
        name: "desk",
        width: 1.4,
        depth: 0.7,
        height: 0.75,
        leg: 0.05,
        top: p.wood,
        legs: p.walnut,
    }
    .place(b, &desk);
    computer(b, &desk.at(0.1, 0.75, 0.1), &p);
    let papers = Papers {
        fr: desk.at(0.0, 0.75, 0.0),
        u0: -0.62,
        w: 0.33,
        material: p.paper,
    };
    chair(
        b,
        &Frame::new(1.08, 0.0, 2.2, Facing::NegX),
        p.walnut,
        p.red,
    );
    Cabinet {
        width: 0.45,
        height: 0.72,
        depth: 0.55,
        body: p.grey,
        front: p.grey,
        fronts: Fronts::Drawers(3),
        handle: p.steel,
    }
    .place(b, &room.wall(Side::West, 0.45, 0.01));

    // East wall: a sofa under a picture (the tuned canvas), a side table with a lamp, a plant.
    let ef = room.wall(Side::East, 2.2, 0.02);
    b.shared = true;
    sofa(b, &ef, 2.1, 0.88, p.blue, p.blue, 3);
    b.shared = false;
    let canvas = Tuner {
        kind: TunerKind::Canvas {
            fr: room.wall(Side::East, 2.2, 0.0),
            v: 1.62,
            w: 0.032,
        },
        material: p.canvas,
        a: (0.7, 1.0, 1.4),
        b: (0.45, 0.7, 0.9),
    };
    let (cw, ch) = (canvas.a.2, canvas.b.2);
    b.lbox(
        &room.wall(Side::East, 2.2, 0.0),
        "picture_frame",
        p.frame,
        [-cw / 2.0 - 0.05, 1.62 - ch / 2.0 - 0.05, 0.0],
        [cw / 2.0 + 0.05, 1.62 + ch / 2.0 + 0.05, 0.03],
        BACK,
    );
    let side = room.wall(Side::East, 0.62, 0.02);
    Table {
        name: "side_table",
        width: 0.45,
        depth: 0.45,
        height: 0.55,
        leg: 0.04,
        top: p.walnut,
        legs: p.walnut,
    }
    .place(b, &side);
    table_lamp(b, &side.at(0.0, 0.55, 0.22), &p, p.cream, 16);

    // In the middle: a coffee table on the tuned rug; the round rug by the desk.
    let coffee = Frame::new(3.95, 0.0, 2.2, Facing::NegX);
    Table {
        name: "coffee_table",
        width: 1.1,
        depth: 0.6,
        height: 0.42,
        leg: 0.05,
        top: p.walnut,
        legs: p.walnut,
    }
    .place(b, &coffee.at(0.0, 0.0, -0.3));
    b.lbox(
        &coffee.at(-0.25, 0.42, -0.1),
        "coffee_book",
        p.books[1],
        [0.0, 0.0, 0.0],
        [0.3, 0.04, 0.22],
        BOTTOM,
    );
    let rug = Tuner {
        kind: TunerKind::Rug { x: 3.75, z: 2.2 },
        material: p.rug_red,
        a: (0.9, 1.2, 1.5),
        b: (1.4, 2.0, 2.6),
    };

    // South wall (behind the camera): a sideboard with a television.
    let sf = room.wall(Side::South, 2.7, 0.01);
    Cabinet {
        width: 1.6,
        height: 0.55,
        depth: 0.45,
        body: p.walnut,
        front: p.walnut,
        fronts: Fronts::Doors(4),
        handle: p.brass,
    }
    .place(b, &sf);
    television(b, &sf.at(0.0, 0.55, 0.0), &p, 0.0, 1.0);

    Plan {
        shelves,
        books: p.books.clone(),
        papers,
        round_rug: RoundRug {
            x: 1.45,
            z: 2.2,
            radius: 0.72,
            material: p.rug_blue,
        },
        tuners: [rug, canvas],
    }
}
