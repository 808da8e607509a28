//! slotforge's acquisition gateware, described with rust-hdl and generated
//! from a `lut_gen::Schedule`, plus its Verilog/constraint emission and a
//! fast in-process simulator.
//!
//! rust-hdl stays behind this API: nothing public here names a rust-hdl type.
//!
//! - [`emit`] / [`Emitted`]: `slotforge_top.v`, `ports.json`, `slots.hex` (the LUT), `slot_rom.hex` (the ROM image),
//!   `slotforge.pcf` (or a board's `.lpf` / `.cst`), `slotforge.sdc`, `slotforge.xdc`, and `slotforge_top.core` (FuseSoC CAPI2);
//! - [`Board`] / [`stock_board`]: board files (`constraints/*.toml`), one per FPGA part;
//! - [`RtlSim`] / `lut_gen::Pins`: cycle-accurate simulation of the same blocks;
//! - `stock_simulation_cycles` / `StockRun` (feature `stock`): the same blocks under
//!   rust-hdl's stock threaded `Simulation` engine (the reference that
//!   `RtlSim`'s speed is measured against), and `rtlsim_cycles`, the
//!   identical run with `RtlSim`.
//!
//! The cycle-level behaviour is `docs/timing.md`; the design choices are in
//! `hdl/DESIGN.md`.

mod board;
mod core;
mod decode;
mod emit;
mod fault;
mod fusesoc;
mod header;
mod link;
mod modeplan;
mod names;
mod plan;
mod sim;

/// The two crates of rust-hdl 0.46 the gateware is written in: the language
/// (`rust-hdl-core`) and its widgets (DFF, RAM, ROM). Not the `rust-hdl`
/// facade, which adds its HLS and simulation-model crates that nothing here
/// uses (about 30 s of CPU in each build, release and test).
mod rhdl {
    pub use rust_hdl_core::prelude::*;
    pub use rust_hdl_widgets::prelude::*;
}
#[cfg(feature = "stock")]
mod stock;
mod widths;

pub use board::{stock_board, Board};
pub use emit::{
    emit, emit_with, verilog_pair, Emitted, LINK_FRAME_COUNTER, MANIFEST_FILE, MODE_DECISION,
    TRIGGER_RUN, VERILOG_FILE,
};
pub use fault::GatewareFault;
pub use fusesoc::{vlnv, CORE_FILE, LAUNCHER_FILE};
pub use plan::{
    LutForm, FULL_LUT_MAX_BITS, MAX_FRAME_SLOTS, MAX_SCLK_DIV, MAX_SLICES_PER_FRAME,
    MAX_SLOTS_PER_SLICE, MAX_SLOT_CYCLES,
};
pub use sim::RtlSim;
#[cfg(feature = "stock")]
pub use stock::{pattern_miso, rtlsim_cycles, stock_simulation_cycles, StockRun};

/// Why gateware could not be produced.
#[derive(Debug, thiserror::Error)]
pub enum HdlError {
    /// The schedule is valid but outside what this gateware implements.
    #[error("unsupported by the gateware: {0}")]
    Unsupported(String),
    /// The board file is unreadable, malformed or lacks pins.
    #[error("board file {path}: {message}")]
    Board { path: String, message: String },
    /// The board has fewer pins than the mix has port bits: the mix does
    /// not fit it (not bad input).
    #[error("board file {path}: {message}")]
    Pins { path: String, message: String },
    /// rust-hdl's stock `Simulation` engine failed (design check, no
    /// convergence, testbench panic).
    #[error("rust-hdl simulation: {0}")]
    Simulation(String),
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
}

/// Private items that this crate's tests check directly (`tests/units/`):
/// the crate has no unit-test harness (`[lib] test = false`, one build of
/// it less in `make test`), so they are reached from the integration tests
/// here.  Not an API: no other crate uses it, and no item here names a
/// rust-hdl type.
#[doc(hidden)]
pub mod for_tests {
    pub use crate::board::board_constraints;
    // The SPI bench, beside the other stock-simulator runs (`stock`).
    pub use crate::core::route_miso;
    #[cfg(feature = "stock")]
    pub use crate::core::{spi_trace, SpiTrace, SPI_NS, SPI_SLOT};
    pub use crate::decode::SlotLogic;
    pub use crate::emit::{core_port_name, core_ports, link_text, CORE, LINK};
    pub use crate::fusesoc::{constraint_kind, vlnv_part};
    pub use crate::link::{LinkParams, Twin};
    pub use crate::modeplan::FrontWord;
    pub use crate::names::{candidate, readable, rename};
    pub use crate::plan::{logic_costs, plan_with};
}
