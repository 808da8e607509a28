//! The back ends behind one call: [`run`].

use std::fmt;
use std::path::PathBuf;

use lut_gen::Schedule;

use crate::adc::Stimulus;
use crate::checker::CheckOptions;
use crate::pins::Pins;
use crate::report::Report;
use crate::run::{run_dut, run_model, Dut, ModelDut, Observer, RunOptions};
use crate::vcdout::{write_gtkw, VcdWriter};
use crate::verilator::{BackendError, VerilatedDut};

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

/// A waveform window to write: frames `[from, to)` (frame 0 includes the reset cycles).
#[derive(Debug, Clone)]
pub struct VcdOut {
    pub path: PathBuf,
    pub from_frame: u64,
    pub to_frame: u64,
    /// Also write a GTKWave save file beside it (`.gtkw`).
    pub gtkw: bool,
}

#[derive(Debug, Clone)]
pub struct SimOptions {
    pub stimulus: Stimulus,
    pub check: CheckOptions,
    pub vcd: Option<VcdOut>,
    /// Reset cycles before cycle 0 (raised to [`crate::run::reset_cycles`]).
    pub reset_cycles: u64,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            stimulus: Stimulus::Pattern,
            check: CheckOptions::default(),
            vcd: None,
            reset_cycles: 4,
        }
    }
}

/// Why a simulation could not run (exit 2), as opposed to a failed check.
#[derive(Debug)]
pub enum SimError {
    /// The gateware cannot be generated for this schedule.
    Hdl(String),
    Backend(BackendError),
    Io(String),
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Hdl(m) => write!(f, "gateware: {m}"),
            SimError::Backend(e) => write!(f, "simulation back end: {e}"),
            SimError::Io(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for SimError {}

impl From<BackendError> for SimError {
    fn from(e: BackendError) -> Self {
        SimError::Backend(e)
    }
}

/// `hdl::RtlSim` as a [`Dut`].
pub struct RustHdlDut(pub hdl::RtlSim);

impl RustHdlDut {
    pub fn new(s: &Schedule) -> Result<RustHdlDut, SimError> {
        hdl::RtlSim::new(s)
            .map(RustHdlDut)
            .map_err(|e| SimError::Hdl(e.to_string()))
    }
}

impl Dut for RustHdlDut {
    #[inline]
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        let p = self.0.step(rst, miso as u8);
        Pins {
            cs_n: p.cs_n,
            sclk: p.sclk,
            mux_sel: p.mux_sel,
            mux_en: p.mux_en,
            sample_valid: p.sample_valid,
            sample_channel: p.sample_channel,
            sample_value: p.sample_value,
        }
    }
}

/// The emitted Verilog of a schedule.
pub fn verilog(s: &Schedule) -> Result<String, SimError> {
    hdl::emit(s, None)
        .map(|e| e.verilog().to_string())
        .map_err(|e| SimError::Hdl(e.to_string()))
}

/// Simulates `frames` frames on `backend` with the ADC model and checks them.
pub fn run(
    s: &Schedule,
    backend: Backend,
    frames: u64,
    opts: &SimOptions,
) -> Result<Report, SimError> {
    if backend == Backend::Icarus {
        return crate::icarus::run(s, frames, opts);
    }
    let reset = crate::run::reset_cycles(s, opts.reset_cycles);
    let ro = RunOptions {
        stimulus: opts.stimulus,
        check: opts.check,
        reset_cycles: reset,
    };
    let mut writer = match &opts.vcd {
        None => None,
        Some(v) => {
            let f = s.grid.frame_cycles;
            let from = if v.from_frame == 0 {
                0
            } else {
                reset + v.from_frame * f
            };
            let to = reset + v.to_frame.max(v.from_frame + 1) * f;
            if v.gtkw {
                write_gtkw(&v.path.with_extension("gtkw"), &v.path, s)
                    .map_err(|e| SimError::Io(format!("{}: {e}", v.path.display())))?;
            }
            Some(
                VcdWriter::create(&v.path, s, from, to)
                    .map_err(|e| SimError::Io(format!("{}: {e}", v.path.display())))?,
            )
        }
    };
    let obs = writer.as_mut().map(|w| w as &mut dyn Observer);
    let report = match backend {
        Backend::Model => {
            if let (Some(obs), Some(v)) = (obs, &opts.vcd) {
                // The slot-level model has no pins: the cycle model draws the window.
                let mut dut = ModelDut::new(s);
                let _ = run_dut(
                    s,
                    &mut dut,
                    v.to_frame.max(v.from_frame + 1).min(frames.max(1)),
                    &ro,
                    "model",
                    Some(obs),
                );
            }
            run_model(s, frames, opts.stimulus, opts.check.max_records)
        }
        Backend::RustHdl => {
            let mut dut = RustHdlDut::new(s)?;
            run_dut(s, &mut dut, frames, &ro, "rusthdl", obs)
        }
        Backend::Verilator => {
            let v = verilog(s)?;
            let (mut dut, _) = VerilatedDut::new(&v)?;
            run_dut(s, &mut dut, frames, &ro, "verilator", obs)
        }
        Backend::Icarus => unreachable!("handled above"),
    };
    if let Some(w) = writer {
        w.finish().map_err(|e| SimError::Io(e.to_string()))?;
    }
    Ok(report)
}
