//! measure: the measurements behind `slotforge build`'s report, each
//! returned as a `report::Section` (text, tables, charts with their CSV)
//! and a one-line summary, so the CLI only calls and writes.
//!
//! - [`synth`]: the one yosys + nextpnr-ice40 flow (also `hdl/synth.sh`);
//! - [`figure7`]: the paper's Figure 7 for the mix's own rates ([`dft`]);
//! - [`timing`]: a steady-state slice's timing diagram and WaveDrom JSON;
//! - [`speed`]: speed against accuracy ([`speed::MethodScore`]);
//! - [`schedulability`]: where scheduling breaks around the mix;
//! - [`proof`]: the formal proof of the gateware (or its cached result);
//! - [`budget`]: the audit as a datasheet (what binds, the margin, each
//!   budget its own table);
//! - [`tables`]: the slot table (Table 1), per-channel intervals
//!   and the fault campaign as report tables.

pub mod budget;
pub mod dft;
pub mod figure7;
pub mod proof;
pub mod schedulability;
pub mod speed;
pub mod synth;
pub mod tables;
pub mod timing;
