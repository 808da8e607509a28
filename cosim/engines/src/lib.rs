//! engines: the simulation engines that run slotforge's gateware and hand
//! its pins to the judge.
//!
//! The judge (reference model, ADC model, checker, waveform I/O) is the
//! `judge` crate beside this one, which never sees `hdl`; this crate depends
//! on both and holds the back ends:
//!
//! - [`run`] (`backend`): one dispatch over [`Backend`]: `model` (the
//!   judge's slot-level model), `rusthdl` (`rusthdl`: `hdl::RtlSim` in
//!   process), `verilator` (`verilator`: the emitted Verilog verilated at
//!   run time), `icarus` (`icarus`: the emitted Verilog in Icarus with a
//!   Verilog ADC, its VCD read by the judge);
//! - `rtl`: outside Verilog for the verilator and icarus back ends
//!   (`SimOptions::rtl`), its top's ports checked against the pin contract;
//! - [`SimOptions`] / [`SimError`]: what a run is asked to do and why it
//!   could not run.
//!
//! The fault campaign and the detectors that are not engines (sigrok, port
//! equivalence) are the `campaign` crate above this one.

// The modules are private: what other crates use is the list below.
mod backend;
mod error;
mod icarus;
mod icarus_cmd;
mod options;
mod rtl;
mod rusthdl;
mod verilator;

pub use backend::{run, run_observed, run_traced, Tracer};
pub use error::{BackendError, SimError};
pub use icarus::testbench as icarus_testbench;
pub use judge::{CheckOptions, Stimulus, Verdict};
pub use options::{Backend, SimOptions, VcdOut};
pub use rtl::load_rtl;
pub use rusthdl::{verilog, RustHdlDut};
pub use verilator::VerilatedDut;

/// Private items that this crate's tests check directly
/// (`tests/rtl_units.rs`): the crate has no unit-test harness (`[lib] test
/// = false`, one build of it less in `make test`).  Not an API: no other
/// crate uses it.
#[doc(hidden)]
pub mod for_tests {
    pub use crate::rtl::{eval_const, scan_ports, PortDir};
}
