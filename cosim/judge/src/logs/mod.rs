//! What a run leaves for people and tools: its pins as a reviewable event
//! log (golden tests), its samples as CSV, and the bytes its link carried.

mod bytes;
mod events;
mod samples;

pub use bytes::LinkBytes;
pub use events::{compare as compare_events, EventLog, Trace};
pub use samples::SampleLog;
// For this crate's tests only (`crate::for_tests`).
pub use events::{time_us, Event};
pub use samples::write_atomic;
