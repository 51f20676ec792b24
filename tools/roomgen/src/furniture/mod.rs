//! The furniture of the rooms, each piece in a local frame: u across (centred), v up, w from the
//! back (0) to the front. A piece with many dimensions is a struct placed with `place`; the
//! others are functions.

mod floor;
mod storage;
mod tabletop;
mod wall;

pub use floor::{chair, floor_lamp, plant, sofa, Bed, Table};
pub use storage::{wall_cabinet, Bookcase, Cabinet, Fronts};
pub use tabletop::{computer, table_lamp, television};
pub use wall::{clock, door, picture, Window};
