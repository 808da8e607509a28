//! The link as seen on the line: the UART line or the AXI4-Stream beats
//! decoded and judged without the model (one of the checker's invariants),
//! and the model's link joined from the line for a check that joins a run
//! mid-stream.

mod decode;
mod join;

pub(crate) use decode::{decoder, tlast_wrong, LinkLine};
pub(crate) use join::{Joined, LinkJoin};
// For this crate's tests only (`crate::for_tests`).
pub use join::find_boundary;
