//! The judge's tests of its rooms' parts, one file per source file they
//! test (they were that file's unit tests).

mod bytes;
mod checker;
mod events;
mod join;
mod read;
mod samples;
mod tools;
