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
    /// Check the invariants only, not the cycle-exact model (with --map:
    /// the link's line decoded and judged, not timed against the model).
    #[arg(long)]
    pub no_model: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// A logic-analyser capture (sigrok-cli's VCD or a `.sr` session): its
    /// channels mapped to port bits as ports.json names them
    /// (`D0=adc_cs_n[0],D1=adc_sclk[0]`), or a file of such lines.  The
    /// capture is checked at time level, at its own sample rate.
    #[arg(long)]
    pub map: Option<String>,
    /// With --map: the analyser's channel-to-channel skew allowed (`5ns`).
    #[arg(long, default_value = "0ns")]
    pub skew: String,
    /// No progress display (on stderr: a bar on a terminal; otherwise, for
    /// a waveform of 2 MiB or more, nothing in the first second, then a
    /// line every few seconds).
    #[arg(long)]
    pub quiet: bool,
    /// Also write JUnit XML: one test case for the waveform, a failure
    /// carrying the first divergence or violation.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
}

/// `5ns`, `0.5us`, `200ps` in picoseconds.
fn parse_skew(v: &str) -> Result<u64, String> {
    let i = v.find(|c: char| c.is_ascii_alphabetic()).unwrap_or(v.len());
    let x: f64 = v[..i]
        .trim()
        .parse()
        .map_err(|_| format!("--skew `{v}`: expected a time such as 5ns"))?;
    let k = match &v[i..] {
        "ps" => 1.0,
        "ns" => 1e3,
        "us" => 1e6,
        _ => return Err(format!("--skew `{v}`: the unit must be ps, ns or us")),
    };
    if x < 0.0 {
        return Err(format!("--skew `{v}` is negative"));
    }
    Ok((x * k).round() as u64)
}

/// `check --map`: a logic-analyser capture at time level.
fn run_capture(a: &Args, s: &lut_gen::Schedule, map: &str) -> u8 {
    let prepared = parse_skew(&a.skew).and_then(|skew| {
        let lanes = judge::parse_map(map, s)?;
        // plain lines off a terminal only for a capture of several chunks
        let progress = super::progress::Counter::new(
            &format!("reading {}", a.wave.display()),
            super::progress::Unit::Bytes,
            2 << 20,
            a.quiet,
        );
        let cap =
            judge::read_capture_progress(&a.wave, lanes, &|done, total| progress.set(done, total));
        progress.finish();
        let cap = cap?;
        judge::check_capture_with(s, &cap, skew, !a.no_model)
            .map_err(|e| format!("{}: {e}", a.wave.display()))
    });
    let r = match prepared {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    if a.json {
        let v = serde_json::json!({
            "ok": r.ok,
            "mode": "time-level capture",
            "locked_at_ps": r.locked_at_ps,
            "clock_ppm": r.clock_ppm,
            "clock_uncertainty_ps": r.clock_uncertainty_ps,
            "modes": r.modes.as_ref().map(|m| serde_json::json!({
                "by": m.by,
                "first": m.first,
                "switches": m.switches.iter().map(|(ps, to)| serde_json::json!({
                    "time_ps": ps, "to": to})).collect::<Vec<_>>(),
            })),
            "slot": r.slot,
            "phases": r.phases,
            "edges_checked": r.edges_checked,
            "conversions": r.conversions,
            "violations_total": r.violations_total,
            "violations": r.violations.iter().map(|v| serde_json::json!({
                "time_ps": v.time_ps, "channel": v.channel, "signal": v.port_bit,
                "rule": v.rule, "detail": v.detail})).collect::<Vec<_>>(),
            "proved": r.proved,
            "not_proved": r.not_proved,
            "link_join": r.link_join.as_ref().map(|j| serde_json::json!({
                "by": j.by,
                "judged": j.judged,
                "why_not": j.why_not,
                "header_ps": j.header_ps,
                "frame_counter": j.frame_counter,
                "slice": j.slice,
                "skipped_bytes": j.skipped_bytes,
                "unjudged_ps": j.unjudged_ps,
                "text": j.text(),
            })),
        });
        println!("{}", serde_json::to_string_pretty(&v).expect("json"));
    } else {
        print!("{}", r.summary());
    }
    if r.ok {
        0
    } else {
        1
    }
}

pub fn run(a: Args) -> u8 {
    // A VCD carries the mode ports; a capture's map names them.
    let s = match super::load_any_modes(&a.mix, super::Limits::Contract) {
        Ok(s) => s,
        Err(code) => return code,
    };
    if let Err(code) = super::junit::check_writable(a.junit.as_deref()) {
        return code;
    }
    let started = std::time::Instant::now();
    if let Some(map) = &a.map {
        // a mix with modes: each frame judged against its mode, read from
        // the map's `mode_sel` or `mode` (refused without either)
        return run_capture(&a, &s, map);
    }
    let opts = CheckOptions {
        model: !a.no_model,
        ..CheckOptions::default()
    };
    // plain lines off a terminal only for a file of several chunks
    let progress = super::progress::Counter::new(
        &format!("checking {}", a.wave.display()),
        super::progress::Unit::Bytes,
        2 << 20,
        a.quiet,
    );
    let checked =
        judge::check_vcd_progress(&s, &a.wave, a.scope.as_deref(), opts, &|done, total| {
            progress.set(done, total)
        });
    progress.finish();
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
