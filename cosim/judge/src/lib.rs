//! judge: what slotforge holds a design's waveform against, built from
//! lut-gen's [`lut_gen::Schedule`] alone (`docs/timing.md`).
//!
//! This crate depends on neither `hdl` nor rust-hdl, so the independence of
//! the reference model from the gateware is enforced by the crate graph: a
//! gateware bug cannot hide behind the same bug in the model.  The
//! simulation engines that produce waveforms live beside it, in `engines`.
//!
//! The judge's rooms, each a private module with a short face, importing
//! one way only (each room uses only rooms listed before it, and the two
//! root files `switch` and `tools`):
//!
//! - `model`: the reference model ([`SlotModel`], [`CycleModel`]), the
//!   modes, the invariants and their [`Rule`]s, the [`Verdict`];
//! - `converter`: the ADC models, the command words read back, the CNV-low read;
//! - `line`: the link on the line, decoded and judged without the model,
//!   and joined from it mid-stream;
//! - `check`: the streaming [`Checker`], a [`Dut`] run against the model,
//!   faults on its pins;
//! - `wave`: VCD and FST read and checked, windows locked on their frame
//!   phase, VCD, FST and GTKWave files written;
//! - `logs`: event logs (golden tests), sample CSVs, the link's bytes;
//! - `capture`: logic-analyser captures judged at time level;
//! - [`switch`]: the test-only switch that turns a detector off; [`tools`]:
//!   the one runner of external tools.
//!
//! The pins themselves ([`Pins`], [`Layout`], [`Signal`]) are the pin
//! contract's, `lut_gen::PORTS`.

// The modules are private: what other crates use is the list below, so the
// judge's internals can move without touching its users.
mod capture;
mod check;
mod converter;
mod line;
mod logs;
mod model;
pub mod switch;
pub mod tools;
mod wave;

pub use lut_gen::{Layout, Pins, Signal};

// The reference model, its ADC and the checker.
pub use check::{CheckOptions, Checker};
pub use converter::{Adc, Analog, Scene, Stimulus};
pub use model::{
    counted, ChannelStats, CycleModel, Divergence, Invariants, ModeStats, ModeTrack, Rule,
    SlotModel, Verdict, Violation,
};

// Running a design (any `Dut`) against the model, with faults on its pins.
pub use check::{
    reset_cycles, run_dut, run_model, run_unchecked, with_slave, AxisSlave, Dut, FaultyDut,
    ModeRequests, ModelDut, Observer, PinFault, RunOptions,
};

// Waveforms: VCD and FST in, VCD and GTKWave save files out, windows locked
// on their frame phase.
pub use wave::{
    channels_path, check_vcd, check_vcd_progress, check_vcd_with, edge_ps, fst_from_vcd, id_code,
    parse_vcd, read_cycles, wire_header, write_gtkw, write_run, CycleSink, LockError, LockInfo,
    VcdError, VcdInfo, VcdWriter, WindowCheck,
};

// Logic-analyser captures, judged at time level.
pub use capture::{
    check_capture, check_capture_with, parse_map, read_capture, read_capture_progress, LineJoin,
    ModesSeen, TimedReport,
};

// Logs: a run's pins as events (golden tests), its samples as CSV, the
// bytes its link carried.
pub use logs::{compare_events, EventLog, LinkBytes, SampleLog, Trace};

/// Private items that this crate's tests check directly (`tests/units/`):
/// the crate has no unit-test harness (`[lib] test = false`, one build of
/// it less in `make test`), so they are reached from the integration tests
/// here.  Not an API: no other crate uses it.
#[doc(hidden)]
pub mod for_tests {
    pub use crate::check::{same, History};
    pub use crate::line::find_boundary;
    pub use crate::logs::{time_us, write_atomic, Event};
    pub use crate::wave::set_chunk_bytes;
}
