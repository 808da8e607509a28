//! judge: what slotforge holds a design's waveform against, built from
//! lut-gen's [`lut_gen::Schedule`] alone (`docs/timing.md`).
//!
//! This crate depends on neither `hdl` nor rust-hdl, so the independence of
//! the reference model from the gateware is enforced by the crate graph: a
//! gateware bug cannot hide behind the same bug in the model.  The
//! simulation engines that produce waveforms live beside it, in `cosim`.
//!
//! - [`model`]: the reference model ([`SlotModel`] for conversions over
//!   hours, [`CycleModel`] for every pin at every cycle);
//! - [`adc`]: the AD7940 model and stimuli;
//! - [`checker`] / [`invariants`]: the streaming cycle-exact comparison and
//!   the mix's invariants, whose [`Rule`]s a violation names;
//! - [`run`]: a [`Dut`] driven with the ADC model into the checker, and the
//!   slot-level model run;
//! - [`faults`]: faults injected into any [`Dut`]'s pins;
//! - [`vcd`] / [`vcdout`]: reading a VCD from any simulator, writing one;
//! - [`timed`] / [`capture`]: logic-analyser captures (no clock, any
//!   sample rate) checked at time level, the channel map, sigrok input;
//! - [`fst`]: FST input, through the `wellen` crate;
//! - `linkjoin`: the model's link joined from the line, for a check that
//!   joins a run mid-stream;
//! - `linkline`: the link (UART line or AXI4-Stream beats) decoded and judged without the model;
//! - [`lock`]: finding the frame phase of a capture that did not start at
//!   reset, and checking it from there;
//! - [`events`]: a run's pins as a reviewable event log, and the
//!   comparison of two logs by signal role (golden tests);
//! - [`samples`]: a run's samples as CSV (`cycle,time_s,channel,value`);
//! - [`switch`]: the test-only switch that turns a detector off.
//!
//! The pins themselves ([`Pins`], [`Layout`], [`Signal`]) are the pin
//! contract's, `lut_gen::ports`.

pub mod adc;
pub mod capture;
pub mod checker;
pub mod events;
pub mod faults;
pub mod fst;
pub mod invariants;
mod linkjoin;
mod linkline;
pub mod lock;
pub mod model;
pub mod report;
pub mod rule;
pub mod run;
pub mod samples;
pub mod switch;
pub mod timed;
pub mod timedlink;
pub mod tools;
pub mod vcd;
mod vcdlex;
pub mod vcdout;

pub use adc::{Adc, Stimulus};
pub use checker::{CheckOptions, Checker};
pub use invariants::Invariants;
pub use lock::{LockError, LockInfo};
pub use lut_gen::ports::{Layout, Pins, Signal};
pub use model::{CycleModel, SlotModel};
pub use report::Report;
pub use rule::Rule;
pub use run::{Dut, ModelDut, Observer};
pub use vcd::{check_vcd, VcdError};
