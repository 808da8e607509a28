//! What a simulation run is asked to do: the back end, the stimulus, the
//! checking and the waveform window.

use std::path::PathBuf;

use judge::{CheckOptions, Stimulus};

/// Where the design's pins come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    /// Slot-level reference model with the conversion-level invariants.
    Model,
    /// `hdl::RtlSim` (rust-hdl's model of the emitted blocks), cycle by cycle, fully checked.
    RustHdl,
    /// The emitted `slotforge_top.v` compiled by Verilator, cycle by cycle, fully checked.
    Verilator,
    /// The emitted `slotforge_top.v` in Icarus Verilog with a Verilog ADC model;
    /// its VCD goes through the VCD checker (a cross-check of the other back ends).
    Icarus,
}

impl std::str::FromStr for Backend {
    type Err = String;
    fn from_str(s: &str) -> Result<Backend, String> {
        match s {
            "model" => Ok(Backend::Model),
            "rusthdl" | "rust-hdl" => Ok(Backend::RustHdl),
            "verilator" => Ok(Backend::Verilator),
            "icarus" | "iverilog" => Ok(Backend::Icarus),
            _ => Err(format!(
                "unknown back end `{s}` (model, rusthdl, verilator, icarus)"
            )),
        }
    }
}

impl Backend {
    pub fn name(&self) -> &'static str {
        match self {
            Backend::Model => "model",
            Backend::RustHdl => "rusthdl",
            Backend::Verilator => "verilator",
            Backend::Icarus => "icarus",
        }
    }
}

/// A waveform window to write: cycles `[from, to)` counted from cycle 0
/// (the first cycle after reset); a window from 0 also holds the reset
/// cycles.
#[derive(Debug, Clone)]
pub struct VcdOut {
    pub path: PathBuf,
    pub from: u64,
    pub to: u64,
    /// Also write a GTKWave save file beside it (`.gtkw`).
    pub gtkw: bool,
}

impl VcdOut {
    /// A window of whole frames `[from, to)` of `frame_cycles` cycles.
    pub fn frames(path: PathBuf, from: u64, to: u64, frame_cycles: u64) -> VcdOut {
        VcdOut {
            path,
            from: from * frame_cycles,
            to: to.max(from + 1) * frame_cycles,
            gtkw: false,
        }
    }

    /// The window as run cycles `[k0, k1)` counted from the first of
    /// `reset` reset cycles.
    pub fn run_cycles(&self, reset: u64) -> (u64, u64) {
        let k0 = if self.from == 0 { 0 } else { reset + self.from };
        (k0, reset + self.to.max(self.from + 1))
    }
}

#[derive(Debug, Clone)]
pub struct SimOptions {
    pub stimulus: Stimulus,
    pub check: CheckOptions,
    pub vcd: Option<VcdOut>,
    /// Reset cycles before cycle 0 (one at the least: [`judge::reset_cycles`]).
    pub reset_cycles: u64,
    /// Simulate this Verilog file instead of the emitted one (verilator and
    /// icarus only); its `slotforge_top` must honour the pin contract
    /// ([`crate::rtl::load_rtl`]).
    pub rtl: Option<PathBuf>,
    /// How the AXI4-Stream slave drives `m_axis_tready` (a mix with an
    /// `axis` link only).
    pub tready: link::ReadyPattern,
    /// A mix with pin-selected modes: `mode_sel` requests `(frame, mode)`,
    /// each shown from the first cycle of its frame on (`sim --modes`).
    pub modes: Vec<(u64, u8)>,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            stimulus: Stimulus::Pattern,
            check: CheckOptions::default(),
            vcd: None,
            reset_cycles: 4,
            rtl: None,
            tready: link::ReadyPattern::Always,
            modes: Vec::new(),
        }
    }
}
