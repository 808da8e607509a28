//! The cycle-exact check: the streaming [`Checker`] fed one cycle of pins at
//! a time, a design ([`Dut`]) driven with the ADC model into it, the
//! slot-level model run, and faults injected into any design's pins.

mod checker;
mod faults;
mod run;

pub(crate) use checker::Join;
pub use checker::{CheckOptions, Checker};
// For this crate's tests only (`crate::for_tests`).
pub use checker::{same, History};
pub use faults::{FaultyDut, PinFault};
pub use run::{
    reset_cycles, run_dut, run_model, run_unchecked, with_slave, AxisSlave, Dut, ModeRequests,
    ModelDut, Observer, RunOptions,
};
