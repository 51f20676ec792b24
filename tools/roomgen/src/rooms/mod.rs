//! The two rooms' layouts: the shell and every piece of furniture, placed by hand. Each returns
//! the plan of free places that the count fitting fills.

mod complex;
mod simple;

pub use complex::complex;
pub use simple::simple;
