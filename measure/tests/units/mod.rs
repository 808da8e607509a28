//! measure's tests of its modules' parts, one file per source file they
//! test (they were that file's unit tests).

mod budget;
mod cell_prune;
mod dft;
mod figure7;
mod modescene;
mod names;
mod netlist;
mod synth;
mod tables;
mod timing;
mod yosys;
