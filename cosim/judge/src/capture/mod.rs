//! Logic-analyser captures judged at time level (no clock, any sample rate,
//! starting anywhere): the capture and its channel map read (sigrok input),
//! the design's clock fitted, and the per-link (UART line, AXI4-Stream) and
//! per-mode checks, with an auto-select capture's switch decisions.

mod axis;
mod axis_hold;
mod check;
mod clock_fit;
mod line;
mod modes;
mod read;
mod triggers;

pub use check::{check_capture, check_capture_with, LineJoin, TimedReport};
pub use modes::ModesSeen;
pub use read::{parse_map, read as read_capture, read_progress as read_capture_progress};
