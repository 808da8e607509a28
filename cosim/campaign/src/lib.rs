//! campaign: the fault campaign and the detectors that are not simulation
//! engines. It sits above the engines (`engines`) and the formal flow
//! (`formal`, the `prove` detector), so no engine depends on `formal`.
//!
//! - [`faults`]: the campaign (pin faults, reset glitches and faults built
//!   into the gateware or its Verilog, at many sites; false alarms over
//!   random mixes), judged by each detector apart: a matrix of fault class x
//!   detector;
//! - [`sigrok`]: sigrok-cli's SPI decode of the pins as a detector;
//! - [`equiv`]: a faulty gateware proved equivalent to the clean one at the
//!   ports (yosys miter, ABC), or not;
//! - [`mixgen`]: random feasible mixes for false-alarm runs and charts.

pub mod equiv;
pub mod faults;
pub mod mixgen;
pub mod sigrok;
