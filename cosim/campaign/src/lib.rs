//! campaign: the fault campaign and the detectors that are not simulation
//! engines. It sits above the engines (`engines`) and the formal flow
//! (`formal`, the `prove` detector), so no engine depends on `formal`.
//!
//! - `faults`: the campaign (pin faults, reset glitches and faults built
//!   into the gateware or its Verilog, at many sites; false alarms over
//!   random mixes), judged by each detector apart: a matrix of fault class x
//!   detector;
//! - `sigrok`: sigrok-cli's SPI decode of the pins as a detector;
//! - `equiv`: a faulty gateware proved equivalent to the clean one at the
//!   ports (yosys miter, ABC), or not;
//! - `mixgen`: random feasible mixes for false-alarm runs and charts
//!   (random mixes with modes, only tests draw: `testkit::modemix`).

// The modules are private: what other crates use is the list below.
mod equiv;
mod faults;
mod mixgen;
mod sigrok;

pub use equiv::{check as check_equivalence, verdict as equivalence_verdict, Equivalence};
pub use faults::{
    campaign_with, deep_faults, gateware_as_verilog, gateware_dut, methods, methods_sample,
    one_gateware_fault_per_class, prove, prove_in, prove_unavailable, sites, Campaign, CleanRun,
    Detector, Engine, FaultClass, Level, MethodRun, OnRun, Plan, ProveVerdict, Target,
    VerilogFault, TREADY,
};
pub use mixgen::{random_mix, LinkShape, Shape};

/// Private items that this crate's tests check directly (`tests/units/`):
/// the crate has no unit-test harness (`[lib] test = false`, one build of
/// it less in `make test`).  Not an API: no other crate uses it.
#[doc(hidden)]
pub mod for_tests {
    pub use crate::sigrok::{
        check as sigrok_check, decode_commands, window_conversions, SpiCapture,
    };
}
