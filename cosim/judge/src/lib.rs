//! judge: what slotforge holds a design's waveform against, built from
//! lut-gen's [`lut_gen::Schedule`] alone (`docs/timing.md`).
//!
//! This crate depends on neither `hdl` nor rust-hdl, so the independence of
//! the reference model from the gateware is enforced by the crate graph: a
//! gateware bug cannot hide behind the same bug in the model.  The
//! simulation engines that produce waveforms live beside it, in `engines`.
//!
//! - `model`: the reference model ([`SlotModel`] for conversions over
//!   hours, [`CycleModel`] for every pin at every cycle);
//! - `adc`: the AD7940 model and stimuli;
//! - `checker` / `invariants`: the streaming cycle-exact comparison and
//!   the mix's invariants, whose [`Rule`]s a violation names; `cmdword`:
//!   the command words on `adc_mosi` read back as the part reads them;
//! - `run`: a [`Dut`] driven with the ADC model into the checker, and the
//!   slot-level model run;
//! - `faults`: faults injected into any [`Dut`]'s pins;
//! - `vcd` / `vcdout`: reading a VCD from any simulator, writing one;
//! - `timed` / `capture`: logic-analyser captures (no clock, any
//!   sample rate) checked at time level, the channel map, sigrok input;
//!   `timedmodes` / `timedtrig`: a mix with modes, frame by frame, and its
//!   switch decisions;
//! - `fst`: FST input, through the `wellen` crate;
//! - `linkjoin`: the model's link joined from the line, for a check that
//!   joins a run mid-stream;
//! - `linkline`: the link (UART line or AXI4-Stream beats) decoded and judged without the model;
//! - `lock`: finding the frame phase of a capture that did not start at
//!   reset, and checking it from there;
//! - `events`: a run's pins as a reviewable event log, and the
//!   comparison of two logs by signal role (golden tests);
//! - `samples`: a run's samples as CSV (`cycle,sampled_s,channel,value`) and the bytes a link carried;
//! - [`switch`]: the test-only switch that turns a detector off.
//!
//! The pins themselves ([`Pins`], [`Layout`], [`Signal`]) are the pin
//! contract's, `lut_gen::PORTS`.

// The modules are private: what other crates use is the list below, so the
// judge's internals can move without touching its users.
mod adc;
mod axishold;
mod capture;
mod checker;
mod clockfit;
mod cmdword;
mod events;
mod faults;
mod fst;
mod invariants;
mod linkbytes;
mod linkjoin;
mod linkline;
mod lock;
mod lowread;
mod modecheck;
mod model;
mod modes;
mod rule;
mod run;
mod samples;
pub mod switch;
mod timed;
mod timedaxis;
mod timedlink;
mod timedmodes;
mod timedtrig;
pub mod tools;
mod vcd;
mod vcdlex;
mod vcdout;
mod verdict;

pub use lut_gen::{Layout, Pins, Signal};

// The reference model, its ADC and the checker.
pub use adc::{Adc, Analog, Scene, Stimulus};
pub use checker::{CheckOptions, Checker};
pub use invariants::Invariants;
pub use model::{CycleModel, SlotModel};
pub use modes::ModeTrack;
pub use rule::Rule;
pub use verdict::{counted, ChannelStats, Divergence, Verdict, Violation};

// Running a design (any `Dut`) against the model, with faults on its pins.
pub use faults::{FaultyDut, PinFault};
pub use run::{
    reset_cycles, run_dut, run_model, run_unchecked, with_slave, AxisSlave, Dut, ModeRequests,
    ModelDut, Observer, RunOptions,
};

// Waveforms: VCD and FST in, VCD and GTKWave save files out, windows locked
// on their frame phase.
pub use fst::from_vcd as fst_from_vcd;
pub use lock::{LockError, LockInfo, WindowCheck};
pub use vcd::{
    check_vcd, check_vcd_progress, check_vcd_with, parse_only as parse_vcd, read_cycles, CycleSink,
    VcdError, VcdInfo,
};
pub use vcdout::{channels_path, edge_ps, id_code, wire_header, write_gtkw, write_run, VcdWriter};

// Logic-analyser captures, judged at time level.
pub use capture::{parse_map, read as read_capture, read_progress as read_capture_progress};
pub use timed::{check_capture, check_capture_with, LineJoin, TimedReport};
pub use timedmodes::ModesSeen;

// Logs: a run's pins as events (golden tests), its samples as CSV, the
// bytes its link carried.
pub use events::{compare as compare_events, EventLog, Trace};
pub use linkbytes::LinkBytes;
pub use samples::SampleLog;
