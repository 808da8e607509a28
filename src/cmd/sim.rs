//! `slotforge sim MIX --backend B --frames N [--vcd F --from A --to B] [--json] [--stimulus S] [--rtl FILE.v]`
//!
//! Back ends: model, rusthdl, verilator, icarus (see `cosim::Backend`);
//! `--rtl` (verilator, icarus) simulates outside Verilog whose top honours
//! the pin contract (`cosim::rtl`).
//!
//! Exit 0: every cycle passed; 1: a divergence or violation; 2: bad input or
//! a missing tool.

use std::path::PathBuf;

use cosim::{Backend, SimOptions, Stimulus, VcdOut};

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// model (slot-level), rusthdl (in process), verilator or icarus (the emitted Verilog).
    #[arg(long, default_value = "model", value_parser = super::backend)]
    pub backend: Backend,
    /// Frames to simulate.
    #[arg(long, default_value_t = 2)]
    pub frames: u64,
    /// Write a VCD of frames --from..--to (plus a GTKWave .gtkw beside it).
    #[arg(long)]
    pub vcd: Option<PathBuf>,
    /// First frame of the VCD window.
    #[arg(long, default_value_t = 0)]
    pub from: u64,
    /// End (exclusive) of the VCD window; default: one frame after --from.
    #[arg(long)]
    pub to: Option<u64>,
    /// ADC input: pattern (unique code per channel and slot), sine, step or chirp.
    #[arg(long, default_value = "pattern")]
    pub stimulus: String,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Simulate this Verilog (verilator, icarus) instead of the emitted one;
    /// its top module must honour the pin contract for the mix.
    #[arg(long, value_name = "FILE.v")]
    pub rtl: Option<PathBuf>,
}

pub fn run(a: Args) -> u8 {
    let backend = a.backend;
    let stimulus: Stimulus = match a.stimulus.parse() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    if a.frames == 0 {
        eprintln!("error: --frames must be at least 1");
        return 2;
    }
    let to = a.to.unwrap_or(a.from + 1);
    if a.vcd.is_some() && to <= a.from {
        eprintln!("error: --to ({to}) must be after --from ({})", a.from);
        return 2;
    }
    let s = match super::schedule(&a.mix) {
        Ok(s) => s,
        Err(code) => return code,
    };
    if let Err(code) = super::fits_pins(&s) {
        return code;
    }
    let opts = SimOptions {
        stimulus,
        vcd: a.vcd.map(|path| VcdOut {
            path,
            from_frame: a.from,
            to_frame: to,
            gtkw: true,
        }),
        rtl: a.rtl,
        ..SimOptions::default()
    };
    let report = match cosim::run(&s, backend, a.frames, &opts) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).expect("report serializes")
        );
    } else {
        print!("{}", report.summary());
    }
    if report.ok {
        0
    } else {
        1
    }
}
