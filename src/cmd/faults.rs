//! `slotforge faults MIX [--backend B] [--json]`: inject every class of
//! fault at many sites across the frame (`cosim::faults`) and report what the
//! checker caught, plus clean runs over random feasible mixes that it must
//! not reject.
//!
//! Exit 0: every injection caught and no false alarm; 1: a miss or a false
//! alarm; 2: bad input.

use std::path::PathBuf;

use cosim::faults::{campaign, Target};

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// The design the faults go into: model (the cycle-level reference
    /// model's pins: pin faults and reset glitches) or rusthdl (the
    /// gateware: also faults built into its slot ROM and counters).
    #[arg(long, default_value = "model", value_parser = super::backend)]
    pub backend: cosim::Backend,
    /// Frames per run (at least 3; faults land in frame 1).
    #[arg(long, default_value_t = 3)]
    pub frames: u64,
    /// Random feasible mixes run clean to count false alarms.
    #[arg(long, default_value_t = 10)]
    pub false_alarm_mixes: u64,
    /// Print the campaign as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: Args) -> u8 {
    let s = match super::schedule(&a.mix) {
        Ok(s) => s,
        Err(code) => return code,
    };
    if let Err(code) = super::fits_pins(&s) {
        return code;
    }
    // One back-end name everywhere (cosim::Backend); the campaign injects
    // into the designs it can build in process.
    let target = match a.backend {
        cosim::Backend::Model => Target::Model,
        cosim::Backend::RustHdl => Target::Rusthdl,
        other => {
            eprintln!(
                "error: --backend {}: the fault campaign injects into model or rusthdl (faults built into the gateware need the design in process)",
                other.name()
            );
            return 2;
        }
    };
    let spin = super::progress::spinner("fault campaign", a.quiet || a.json);
    let c = campaign(&s, target, a.frames, a.false_alarm_mixes);
    if let Some(b) = spin {
        b.finish_and_clear();
    }
    let c = match c {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    if a.json {
        let mut v = serde_json::to_value(&c).expect("serializes");
        v["ok"] = serde_json::json!(c.ok());
        println!("{}", serde_json::to_string_pretty(&v).expect("json"));
    } else {
        println!(
            "faults on {} ({:?}), sites: {}",
            c.mix,
            c.target,
            c.sites
                .iter()
                .map(|s| format!("{} (cycle {}, slot {})", s.name, s.cycle, s.slot))
                .collect::<Vec<_>>()
                .join(", ")
        );
        for k in &c.classes {
            println!(
                "  {:<20} {:<8} {:>3} of {:>3} caught{}",
                k.name,
                k.level,
                k.detected,
                k.injected,
                if k.missed.is_empty() { "" } else { "  MISSED" }
            );
            for m in &k.missed {
                println!("      missed {} at {} (cycle {})", m.fault, m.site, m.cycle);
            }
            for m in &k.equivalent {
                println!(
                    "      no effect: {} at {} (cycle {}): every output equals the model's in every cycle (an equivalent fault on this mix; not counted)",
                    m.fault, m.site, m.cycle
                );
            }
        }
        println!(
            "{} of {} injections caught; false alarms: {} of {} clean runs over {} random mixes",
            c.detected,
            c.injected,
            c.false_alarms.rejected,
            c.false_alarms.runs,
            c.false_alarms.mixes
        );
        for e in &c.false_alarms.examples {
            println!("  false alarm: {e}");
        }
    }
    if c.ok() {
        0
    } else {
        1
    }
}
