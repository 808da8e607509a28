//! hdl's tests of its modules' parts, one file per source file they test
//! (they were that file's unit tests).

mod board;
mod decode;
mod emit;
mod fault;
mod fusesoc;
mod glue;
mod link;
mod modeplan;
mod names;
mod plan;
