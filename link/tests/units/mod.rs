//! link's tests of its modules' parts, one file per source file they test
//! (they were that file's unit tests).

mod axis;
mod decode;
mod format;
mod rx;
mod tx;
mod uart;
