//! The gateware itself, described with rust-hdl (private to this crate).
//!
//! Hierarchy (every sequential element sits at depth 2, so that in rust-hdl's
//! simulator every flip-flop sees the clock edge in the same pass):
//!
//! ```text
//! Core                    fixed-maximum ports (16 branches, 64 mux enables, 10-bit channel)
//!  |- timing: TimingGen   cycle-in-slot counter, slot-in-frame counter, slot-start strobes
//!  |- seqs: Vec<SpiSeq>   one SPI sequencer per distinct SPI timing (usually one):
//!  |                      CS/SCLK levels, capture and completion strobes for every slot
//!  |- branches: Vec<BranchUnit>, one per branch of the mix
//!  |    |- rom: SlotRom   that branch's column of the frame table (BRAM-friendly)
//!  |    `- DFFs           "converts this slot" flag, CS/SCLK outputs gated by it,
//!  |                      MISO shift register, channel, mux control
//!  |- pulses: Vec<CnvPulse> one per sequencer whose part is read with CNV low
//!  |- holds: Vec<HoldOff> one per sequencer whose transactions start after the slot tick
//!  |- cmds: Vec<CmdUnit>  one per branch with a command word: adc_mosi, prepared conversions
//!  `- merge: Merger       pending set + lowest-branch-first sample stream (Verilog over the mix's lanes)
//! ```
//!
//! No literal appears in a kernel: every number is a sized `Constant`, so the
//! emitted Verilog has no 32-bit literals and lints clean.

#[cfg(feature = "stock")]
mod bench;
mod branch;
mod command;
mod glue;
mod holdoff;
mod merger;
mod modes;
mod pulse;
mod slot_rom;
mod spi;
mod timing;
mod top;
mod word_reader;

use crate::rhdl::*;

use branch::BranchUnit;
use command::CmdUnit;
use holdoff::HoldOff;
use merger::Merger;
use modes::ModeGen;
use pulse::CnvPulse;
use slot_rom::SlotRom;
use spi::SpiSeq;
use timing::TimingGen;
pub use top::Core;
// For this crate's tests only (`crate::for_tests`).
#[cfg(feature = "stock")]
pub use bench::{spi_trace, SpiTrace, NS as SPI_NS, SLOT as SPI_SLOT};
pub use glue::route_miso;
use word_reader::WordReader;

/// A sized constant: every number in a kernel is one (see above).
fn c<const N: usize>(v: u64) -> Constant<Bits<N>> {
    Constant::new(Bits::<N>::from(v))
}
