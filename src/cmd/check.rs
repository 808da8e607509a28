//! `slotforge check MIX WAVE.vcd [--scope S] [--json]`
//!
//! Exit 0: the waveform keeps every invariant and matches the reference
//! model at every cycle; 1: it does not; 2: bad mix, unreadable or malformed
//! VCD, ports not found, or (a capture that does not start at reset) no
//! single frame phase fits its pins.

use std::path::PathBuf;

use judge::CheckOptions;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// The waveform (VCD or FST) from any simulator, from reset or from anywhere in a run.
    pub wave: PathBuf,
    /// Scope of slotforge_top's ports (e.g. `tb.dut`); found automatically when unambiguous.
    #[arg(long)]
    pub scope: Option<String>,
    /// Check the invariants only, not the cycle-exact model.
    #[arg(long)]
    pub no_model: bool,
    /// Print the report as JSON.
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
    let opts = CheckOptions {
        model: !a.no_model,
        ..CheckOptions::default()
    };
    let (report, info) = match judge::vcd::check_vcd_with(&s, &a.wave, a.scope.as_deref(), opts) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    if a.json {
        let mut v = serde_json::to_value(&report).expect("report serializes");
        v["scope"] = serde_json::json!(info.scope);
        v["timescale"] = serde_json::json!(info.timescale);
        v["clock_dumped"] = serde_json::json!(info.clock_dumped);
        v["lock"] = match &info.lock {
            Some(l) => serde_json::json!({
                "locked_at_cycle": l.locked_at,
                "frame_cycle": l.frame_cycle,
                "slot": l.slot,
                "slot_cycle": l.slot_cycle,
                "changes": l.changes,
                "first_candidates": l.first_candidates,
                "repeat_cycles": l.repeat_cycles,
                "checked_from_cycle": l.checked_from,
                "settle_unknown": l.settle_unknown,
                "forgotten_cycles": l.forgotten_cycles,
                "text": l.to_string(),
            }),
            None => serde_json::Value::Null,
        };
        println!("{}", serde_json::to_string_pretty(&v).expect("json"));
    } else {
        if !info.clock_dumped {
            eprintln!(
                "note: `clk` is not dumped; clock edges inferred every {} time units",
                info.inferred_period.unwrap_or(0)
            );
        }
        if let Some(l) = &info.lock {
            eprintln!("note: the capture does not start at reset: {l}");
        }
        print!("{}", report.summary());
    }
    if report.ok {
        0
    } else {
        1
    }
}
