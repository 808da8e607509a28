//! `slotforge check MIX WAVE.vcd [--scope S] [--json]`
//!
//! Exit 0: the waveform keeps every invariant and matches the reference
//! model at every cycle; 1: it does not; 2: bad mix, unreadable or malformed
//! VCD, or ports not found.

use std::path::PathBuf;

use judge::CheckOptions;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// The waveform (VCD) from any simulator.
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
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
    /// Also write JUnit XML: one test case for the waveform, a failure
    /// carrying the first divergence or violation.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
}

pub fn run(a: Args) -> u8 {
    let s = match super::schedule(&a.mix) {
        Ok(s) => s,
        Err(code) => return code,
    };
    if let Err(code) = super::fits_pins(&s) {
        return code;
    }
    if let Some(j) = &a.junit {
        if let Err(e) = super::junit::check_writable(j) {
            eprintln!("error: {e}");
            return 2;
        }
    }
    let started = std::time::Instant::now();
    let opts = CheckOptions {
        model: !a.no_model,
        ..CheckOptions::default()
    };
    let spin =
        super::progress::spinner(&format!("checking {}", a.wave.display()), a.quiet || a.json);
    let checked = judge::vcd::check_vcd_with(&s, &a.wave, a.scope.as_deref(), opts);
    if let Some(b) = spin {
        b.finish_and_clear();
    }
    let (report, info) = match checked {
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
        println!("{}", serde_json::to_string_pretty(&v).expect("json"));
    } else {
        if !info.clock_dumped {
            eprintln!(
                "note: `clk` is not dumped; clock edges inferred every {} time units",
                info.inferred_period.unwrap_or(0)
            );
        }
        print!("{}", report.summary());
    }
    if let Some(j) = &a.junit {
        let summary = report.summary();
        let first = summary.lines().next().unwrap_or("").to_string();
        let case = super::junit::Case {
            name: a.wave.display().to_string(),
            seconds: started.elapsed().as_secs_f64(),
            outcome: if report.ok {
                super::junit::Outcome::Passed
            } else {
                super::junit::Outcome::Failed(first, summary)
            },
        };
        if let Err(e) = super::junit::write(j, &format!("slotforge check {}", s.mix.name), &[case])
        {
            eprintln!("error: {e}");
            return 2;
        }
    }
    if report.ok {
        0
    } else {
        1
    }
}
