//! The campaign's tests of its modules' parts, one file per source file
//! they test (they were that file's unit tests).

mod class;
mod mixgen;
mod sigrok;
