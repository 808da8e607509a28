//! cosim: the reference model of slotforge's gateware, an AD7940 model,
//! simulation back ends and the cycle-exact waveform checker.
//!
//! The model is built from lut-gen's [`lut_gen::Schedule`] alone, following
//! `docs/timing.md`; it never reads the `hdl` crate.

pub mod adc;
pub mod backend;
pub mod checker;
pub mod faults;
pub mod icarus;
pub mod model;
pub mod mutate;
pub mod pins;
pub mod report;
pub mod run;
pub mod vcd;
pub mod vcdout;
pub mod verilator;

pub use adc::{Adc, Stimulus};
pub use backend::{run, Backend, SimError, SimOptions, VcdOut};
pub use checker::{CheckOptions, Checker, Invariants};
pub use model::{CycleModel, SlotModel};
pub use pins::{Layout, Pins, Signal};
pub use report::Report;
pub use vcd::{check_vcd, VcdError};
