//! `slotforge faults MIX [--backend B] [--json]`: inject each kind of fault
//! into a design's pins and report whether the checker caught it.
//!
//! Exit 0: every fault caught; 1: a fault slipped through; 2: bad input.

use std::path::PathBuf;

use cosim::RustHdlDut;
use judge::faults::{campaign, FaultOutcome};
use judge::ModelDut;

/// The designs faults are injected into (in process: the injector sits
/// between the design's pins and the checker).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// The cycle-level reference model's pins.
    Model,
    /// The gateware in rust-hdl's simulator.
    Rusthdl,
}

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// The design the faults are injected into: model (the cycle-level
    /// reference model's pins) or rusthdl (the gateware, in process).
    #[arg(long, value_enum, default_value_t = Target::Model)]
    pub backend: Target,
    /// Frames per faulty run (at least 2; the fault lands in the second).
    #[arg(long, default_value_t = 2)]
    pub frames: u64,
    /// Print the outcomes as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: Args) -> u8 {
    let s = match super::schedule(&a.mix) {
        Ok(s) => s,
        Err(code) => return code,
    };
    if let Err(code) = super::fits_pins(&s) {
        return code;
    }
    let outcomes: Vec<FaultOutcome> = match a.backend {
        Target::Model => campaign(&s, a.frames, || ModelDut::new(&s)),
        Target::Rusthdl => {
            if let Err(e) = RustHdlDut::new(&s) {
                eprintln!("error: {e}");
                return 2;
            }
            campaign(&s, a.frames, || {
                RustHdlDut::new(&s).expect("built once already")
            })
        }
    };
    let missed = outcomes.iter().filter(|o| !o.caught).count();
    if a.json {
        let v = serde_json::json!({
            "mix": s.mix.name,
            "backend": match a.backend {
                Target::Model => "model",
                Target::Rusthdl => "rusthdl",
            },
            "ok": missed == 0,
            "faults": outcomes,
        });
        println!("{}", serde_json::to_string_pretty(&v).expect("serializes"));
    } else {
        for o in &outcomes {
            let first = o
                .first_divergence
                .as_ref()
                .map(|d| format!("first divergence {} at cycle {}", d.signal, d.cycle))
                .unwrap_or_else(|| "no divergence".into());
            println!(
                "{:<22} {}  {} divergent cycles, {} violations ({}); {}",
                o.fault,
                if o.caught { "CAUGHT" } else { "MISSED" },
                o.divergence_count,
                o.violation_count,
                if o.rules.is_empty() {
                    "-".to_string()
                } else {
                    o.rules.join(", ")
                },
                first
            );
        }
        println!(
            "{} of {} faults caught",
            outcomes.len() - missed,
            outcomes.len()
        );
    }
    if missed == 0 {
        0
    } else {
        1
    }
}
