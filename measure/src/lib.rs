//! measure: the measurements behind `slotforge build`'s report, each
//! returned as a `report::Section` (text, tables, charts with their CSV)
//! and a one-line summary, so the CLI only calls and writes.
//!
//! - `netlist`: a family's gate-level netlist with its cell models, one
//!   file for `sim --netlist` and `prove --netlist`;
//! - `synth`: the yosys + nextpnr flow of each FPGA part (also `hdl/synth.sh`);
//! - `yosys`: yosys for a part (JSON, gate-level netlist, cell models) and
//!   where the flows' programs are (PATH or `.venv/`);
//! - `figure7`: the paper's Figure 7 for the mix's own rates (`dft`);
//! - `timing`: a steady-state slice's timing diagram and WaveDrom JSON;
//! - `speed`: speed against accuracy (`MethodScore`);
//! - `schedulability`: where scheduling breaks around the mix;
//! - `proof`: the formal proof of the gateware (or its cached result);
//! - `budget`: the audit as a datasheet (what binds, the margin, each
//!   budget its own table);
//! - `modescene`: a mix with modes over a scene against its one-mode twin
//!   (`scenelog`: each frame's mode, samples and link bytes off the pins;
//!   `reaction`: each switch's reaction, measured);
//! - `tables`: the slot table (Table 1), per-channel intervals
//!   and the fault campaign as report tables.

mod budget;
mod cell_prune;
mod dft;
mod figure7;
mod modescene;
mod names;
mod netlist;
mod proof;
mod reaction;
mod scenelog;
mod schedulability;
mod speed;
mod synth;
mod tables;
mod timing;
mod yosys;

// Each measurement: a report section and its one-line summary.
pub use figure7::figure7;
pub use modescene::{mode_scene, mode_section, one_mode, ModeScene};
pub use names::short_names;
pub use proof::{cached_proof, proof, ShownProof};
pub use reaction::Reaction;
pub use scenelog::FrameFigures;
pub use schedulability::schedulability;
pub use speed::{speed, CleanRun};
pub use timing::timing;

// The netlist yosys writes for a family, with its cell models (`sim
// --netlist`, `prove --netlist`).
pub use netlist::{netlist, Netlist, NETLIST_SIM_FILE};

// The place-and-route flow on its own (also `hdl/synth.sh`), for each
// FPGA part; yosys for a part (the synthesized JSON, the gate-level netlist
// and the family's cell models, for `sim --netlist`).
pub use synth::{
    anchor, logic_cell_says, median_fmax, place_and_route, place_and_route_for,
    place_and_route_seeds, Anchor, Synth, HAND_ANCHORS,
};
pub use yosys::{find_program, synthesize_for, Synthesized, NETLIST_FILE, SYNTH_JSON};

// The report's tables: the audit's budgets, the slot table, the intervals
// measured and the fault campaign.
pub use budget::{budget_tables, Tightest};
pub use tables::{fault_table, interval_table, slot_table};

/// Private items that this crate's tests check directly (`tests/units/`):
/// the crate has no unit-test harness (`[lib] test = false`, one build of
/// it less in `make test`), so they are reached from the integration tests
/// here.  Not an API: no other crate uses it.
#[doc(hidden)]
pub mod for_tests {
    pub use crate::budget::branch_caption;
    pub use crate::cell_prune::needed_models;
    pub use crate::dft::{alias, peak, spectrum};
    pub use crate::figure7::where_aliasing_puts_it;
    pub use crate::netlist::hollow_cells;
    pub use crate::synth::parse as parse_synth;
    pub use crate::tables::MAX_COLUMNS;
    pub use crate::timing::{label_width, stagger};
    pub use crate::yosys::{built_venv, stat_cells};
}
