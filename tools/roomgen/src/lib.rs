//! roomgen: a deterministic generator of the paper's two virtual indoor rooms (section 4,
//! Table 1), with exactly the paper's counts:
//!
//! | room | faces | vertices | lights | patches |
//! |---|---|---|---|---|
//! | simple | 1,602 | 6,431 | 2 | 14,445 |
//! | complex | 8,549 | 35,785 | 6 | 86,077 |
//!
//! "Faces" are the polygons `gpu_radiosity::scene::load_obj` keeps, "vertices" the `v` lines of
//! the OBJ, "lights" the polygons whose material emits, "patches" the patches of `PatchLayout`
//! at the scene's own `# patch-size`. Its output is committed as `scenes/simple/` and
//! `scenes/complex/`; the solver only reads those files.
//!
//! Both rooms are built in metres (+y up) from axis-aligned boxes, vertical cylinders and flat
//! discs: a shell (plank or tiled floor, a ceiling of tiles in which the emissive light panels
//! sit, walls with a dado and skirting boards, doorways between rooms) and furniture (bookcases,
//! tables with legs, chairs, sofas, beds, cabinets, a kitchen, lamps, plants, rugs, pictures...).
//! Coordinates are kept as integers in tenths of a millimetre, so every box face is exactly planar
//! and the text is exact; the only randomness is a splitmix64 stream with a fixed seed.
//!
//! The parts, in the order a room is made:
//! - `rooms`: each room's layout, placed by hand from `shell` and `furniture` pieces,
//!   which emit their faces through the `builder` (in `geometry`'s integer coordinates
//!   and local frames), with materials from `palette`;
//! - `count_fitting`: fills the free places the layout leaves (books, papers, a round rug's
//!   sides, a rug's and a canvas's size in whole patches, the patch size) so that each count is
//!   exact, then loads the result back the way `load_obj` would and asserts the four counts.
//!   The simple room gets a patch size of 0.1428 m, the complex one 0.1127 m;
//! - `files`: the OBJ and MTL texts.
//!
//! Every piece uses its own vertices (4 per quad) except a few shared-vertex pieces (the simple
//! room's bookcases and sofa), and n-gon caps and discs add n − 4 each: that is what leaves the
//! round rug's sides free to make the vertex count exact.

mod builder;
mod count_fitting;
mod files;
mod furniture;
mod geometry;
mod palette;
mod random;
mod rooms;
mod shell;

use builder::Builder;
use glam::Vec3;
use random::SplitMix;

/// Which of the paper's two rooms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Room {
    Simple,
    Complex,
}

/// The four counts of Table 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Counts {
    pub faces: usize,
    pub vertices: usize,
    pub lights: usize,
    pub patches: u64,
}

impl Room {
    pub fn name(self) -> &'static str {
        match self {
            Room::Simple => "simple",
            Room::Complex => "complex",
        }
    }

    /// The paper's counts (Table 1).
    pub fn targets(self) -> Counts {
        match self {
            Room::Simple => Counts {
                faces: 1_602,
                vertices: 6_431,
                lights: 2,
                patches: 14_445,
            },
            Room::Complex => Counts {
                faces: 8_549,
                vertices: 35_785,
                lights: 6,
                patches: 86_077,
            },
        }
    }

    /// Where the search for the patch size starts, in metres: chosen by hand so that the fixed
    /// content leaves about the rectangles' preferred sizes to make up.
    fn patch_size(self) -> f64 {
        match self {
            Room::Simple => 0.143,
            Room::Complex => 0.113,
        }
    }

    fn seed(self) -> u64 {
        match self {
            Room::Simple => 0x5EED_0001,
            Room::Complex => 0x5EED_0002,
        }
    }

    fn camera(self) -> &'static str {
        match self {
            Room::Simple => "eye 4.9 1.62 0.32 target 1.6 0.95 3.7 up 0 1 0 fov 62",
            Room::Complex => "eye 0.4 1.6 0.6 target 5.3 1.0 4.4 up 0 1 0 fov 64",
        }
    }
}

/// A generated room: the OBJ and MTL texts, and what the tests need to check them.
pub struct GeneratedScene {
    pub obj: String,
    pub mtl: String,
    pub counts: Counts,
    pub patch_size: f32,
    /// The empty space of the rooms (each room's box, each doorway's opening), min and max
    /// corners in metres: every vertex lies in their union, and every wall, floor and ceiling
    /// polygon has this space in front of it and none behind it.
    pub interior: Vec<(Vec3, Vec3)>,
    /// How the counts were hit, in words (also a comment line of the OBJ).
    pub tuning: String,
}

/// Generate `room`; the OBJ names `mtl_file` (to be written next to it) in its `mtllib` line.
pub fn generate(room: Room, mtl_file: &str) -> GeneratedScene {
    let mut b = Builder::default();
    let mut rng = SplitMix(room.seed());
    let plan = match room {
        Room::Simple => rooms::simple(&mut b, &mut rng),
        Room::Complex => rooms::complex(&mut b, &mut rng),
    };
    let fitted = count_fitting::fit(room, &mut b, &mut rng, &plan);
    let header = files::Header {
        counts: &fitted.counts,
        patch_size: &fitted.patch_size_text,
        mtl_file,
        tuning: &fitted.tuning,
    };
    let obj = files::obj_text(&b, room, &header);
    let mtl = files::mtl_text(&b, room);
    let interior = b
        .interior
        .iter()
        .map(|(lo, hi)| {
            (
                Vec3::from(lo.map(|v| v as f32)),
                Vec3::from(hi.map(|v| v as f32)),
            )
        })
        .collect();
    GeneratedScene {
        obj,
        mtl,
        counts: fitted.counts,
        patch_size: fitted.patch_size,
        interior,
        tuning: fitted.tuning,
    }
}
