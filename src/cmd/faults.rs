//! `slotforge faults MIX [--backend B] [--json]`: inject every class of
//! fault at many sites across the frame (`campaign::faults`) and report what the
//! checker caught, plus clean runs over random feasible mixes that it must
//! not reject.
//!
//! Every run is judged by each detector apart (model comparison, invariants,
//! sigrok's SPI decode, `prove`): the output is a matrix of fault class x
//! detector.  Exit 0: every injection detected (or, for a gateware fault,
//! proved equivalent) and no false alarm; 1: anything undetected or a false
//! alarm; 2: bad input.

use std::fmt::Write as _;
use std::path::PathBuf;

use campaign::{campaign_with, deep_faults, Campaign, Plan, Target};

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// The design the faults go into: model (the cycle-level reference
    /// model's pins: pin faults and reset glitches) or rusthdl (the
    /// gateware: also faults built into its slot ROM and counters).
    #[arg(long, default_value = "model", value_parser = super::backend)]
    pub backend: engines::Backend,
    /// Frames per run (at least 3; faults land in frame 1).
    #[arg(long, value_parser = super::whole_number, default_value_t = 3)]
    pub frames: u64,
    /// Random feasible mixes run clean to count false alarms.
    #[arg(long, value_parser = super::whole_number, default_value_t = 10)]
    pub false_alarm_mixes: u64,
    /// Also run `formal`'s deep fault classes (edits of the emitted
    /// Verilog: a counter that misbehaves after the run's last frame, a
    /// merger collision no stimulus drives) on these Verilog engines
    /// (comma-separated: verilator, icarus).
    #[arg(long, value_delimiter = ',', value_parser = super::backend)]
    pub engines: Vec<engines::Backend>,
    /// `prove` as a detector of every fault that is a design (gateware and
    /// Verilog faults): seconds per fault on a small-frame mix, minutes on
    /// a 48 MHz one.
    #[arg(long)]
    pub prove: bool,
    /// Print the campaign as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress display (on stderr: a bar on a terminal; otherwise
    /// nothing in the first second, then a line every few seconds).
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: Args) -> u8 {
    // A mix with modes runs its switching scenario on every target and
    // engine (docs/faults.md, "Mode switches").
    let s = match super::load_any_modes(&a.mix, super::Limits::Contract) {
        Ok(s) => s,
        Err(code) => return code,
    };
    // One back-end name everywhere (engines::Backend); pin faults go into
    // a design in process, the Verilog engines run faulty designs.
    let target = match a.backend {
        engines::Backend::Model => Target::Model,
        engines::Backend::RustHdl => Target::Rusthdl,
        other => {
            eprintln!(
                "error: --backend {0}: pin faults are injected into a design in process (model or rusthdl); the gateware's faults and the deep faults run as Verilog on {0} with `--backend rusthdl --engines {0}`",
                other.name()
            );
            return 2;
        }
    };
    if let Some(e) = a
        .engines
        .iter()
        .find(|e| !matches!(e, engines::Backend::Verilator | engines::Backend::Icarus))
    {
        eprintln!(
            "error: --engines {}: the deep faults are Verilog; they run on verilator or icarus",
            e.name()
        );
        return 2;
    }
    let mut plan = Plan::new(target, a.frames, a.false_alarm_mixes);
    plan.prove = a.prove;
    if !a.engines.is_empty() {
        plan.verilog_engines = a.engines.clone();
        // the late counter lands just past the run's last frame
        plan.verilog_faults = match deep_faults(&s, a.frames.max(3)) {
            Ok(v) => v,
            Err(e) => {
                eprintln!("error: the deep faults: {e}");
                return 2;
            }
        };
        // and one fault of each gateware class, as the Verilog it emits
        plan.verilog_faults
            .extend(campaign::gateware_as_verilog(&s));
    }
    // Progress goes to stderr, so `--json` on stdout keeps it.
    let progress = std::sync::Arc::new(super::progress::Counter::new(
        "fault campaign",
        super::progress::Unit::Runs,
        1,
        a.quiet,
    ));
    let shown = std::sync::Arc::clone(&progress);
    plan.on_run = Some(campaign::OnRun(std::sync::Arc::new(move |done, total| {
        shown.set(done, total)
    })));
    let c = campaign_with(&s, &plan);
    progress.finish();
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
        print!("{}", text(&c));
    }
    if c.ok() {
        0
    } else {
        1
    }
}

/// The campaign as text: the matrix, then what was missed and why.
fn text(c: &Campaign) -> String {
    let mut o = String::new();
    if !c.clean.ok {
        let _ = writeln!(
            o,
            "faults on {}: its clean run on {} FAILS, so no fault was injected (a checker that rejects the clean design would \"detect\" every fault):\n  {}",
            c.mix,
            c.clean.engine,
            c.clean.why.as_deref().unwrap_or("").replace('\n', "\n  ")
        );
        return o;
    }
    let _ = writeln!(
        o,
        "clean run of {} on {}: PASS ({} cycles, checked against the model)",
        c.mix, c.clean.engine, c.clean.cycles
    );
    header(&mut o, c);
    matrix(&mut o, c);
    columns(&mut o, c);
    missed(&mut o, c);
    let _ = writeln!(
        o,
        "{} injections: {} detected, {} undetected, {} proved equivalent; false alarms: {} of {} over {}",
        c.injected,
        c.detected,
        c.undetected,
        c.proved_equivalent,
        c.false_alarms.rejected,
        super::counted(c.false_alarms.runs, "clean run"),
        super::counted(c.false_alarms.mixes, "random mix")
    );
    for e in &c.false_alarms.examples {
        let _ = writeln!(o, "  false alarm: {e}");
    }
    o
}

/// The target, the sites and the AXI4-Stream slave of every run.
fn header(o: &mut String, c: &Campaign) {
    let sites: Vec<String> = c
        .sites
        .iter()
        .map(|s| format!("{} (cycle {}, slot {})", s.name, s.cycle, s.slot))
        .collect();
    let _ = writeln!(
        o,
        "faults on {} (into {}), sites: {}",
        c.mix,
        c.target.describe(),
        sites.join(", ")
    );
    if let Some(p) = &c.tready {
        let _ = writeln!(
            o,
            "  every run's AXI4-Stream slave: tready {p} (every beat waits the longest the mix's guarantee allows)"
        );
    }
}

/// PinFault class x detector, and why a detector cannot see a class.
fn matrix(o: &mut String, c: &Campaign) {
    let _ = write!(o, "  {:<20} {:<8}", "class", "level");
    for d in &c.detectors {
        let _ = write!(o, " {:>12}", d.name());
    }
    let _ = writeln!(o, " {:>10} {:>10}", "undetected", "proved-eq");
    for k in &c.classes {
        let _ = write!(o, "  {:<20} {:<8}", k.name, k.level);
        for d in &c.detectors {
            let cell = match (k.detected_by.get(d), k.cannot_see.get(d)) {
                (_, Some(_)) => "cannot see".to_string(),
                (Some(n), None) => format!("{n} of {}", k.injected),
                (None, None) => "not run".to_string(),
            };
            let _ = write!(o, " {cell:>12}");
        }
        let _ = writeln!(
            o,
            " {:>10} {:>10}",
            k.undetected.len(),
            k.proved_equivalent.len()
        );
    }
    let mut blind: Vec<(&str, &str)> = Vec::new();
    for k in &c.classes {
        for (d, why) in &k.cannot_see {
            if !blind.contains(&(d.name(), why.as_str())) {
                blind.push((d.name(), why));
            }
        }
    }
    for (d, why) in blind {
        let _ = writeln!(o, "  cannot see: {d}: {why}");
    }
}

/// Per detector and per engine: what it caught, or why it did not run.
fn columns(o: &mut String, c: &Campaign) {
    for col in &c.columns {
        match &col.not_run {
            Some(why) => {
                let _ = writeln!(o, "  {}: {why}", col.detector.name());
            }
            None => {
                let _ = writeln!(
                    o,
                    "  {}: {} of {} injections",
                    col.detector.name(),
                    col.detected,
                    col.injected
                );
            }
        }
    }
    for e in &c.engines {
        let _ = writeln!(
            o,
            "  engine {}: {} of {} injections through it detected; a clean run of {} cycles took {:.3} s",
            e.engine, e.detected, e.injected, e.cycles, e.seconds
        );
    }
}

/// The injections no detector caught: undetected, or proved equivalent.
fn missed(o: &mut String, c: &Campaign) {
    for k in &c.classes {
        for m in &k.undetected {
            let _ = writeln!(
                o,
                "      UNDETECTED {} on {} at {} (cycle {}){}",
                m.fault,
                m.engine,
                m.site,
                m.cycle,
                m.equivalence
                    .as_ref()
                    .map(|e| format!(": equivalence {}", equivalence(e)))
                    .unwrap_or_default()
            );
        }
        for m in &k.proved_equivalent {
            let why = match m.equivalence {
                Some(campaign::Equivalence::ContractProved) => {
                    "the faulty design proves the full pin contract for all time (prove)"
                }
                _ => "every output equals the clean gateware's for every input, for all time",
            };
            let _ = writeln!(
                o,
                "      proved equivalent: {} on {} at {} (cycle {}): {why}",
                m.fault, m.engine, m.site, m.cycle
            );
        }
    }
}

/// The equivalence check's answer in words (not the enum's Debug form).
fn equivalence(e: &campaign::Equivalence) -> String {
    use campaign::Equivalence as E;
    match e {
        E::Proved { seconds } => format!("proved ({seconds:.1} s)"),
        E::Differs { frame: Some(f) } => format!("differs (counterexample at frame {f})"),
        E::Differs { frame: None } => "differs".into(),
        E::Undecided { why } => format!("undecided: {why}"),
        E::ContractProved => "the faulty design proves the whole pin contract".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::equivalence;
    use campaign::Equivalence;

    #[test]
    fn the_equivalence_verdict_is_words_not_the_enum() {
        let e = equivalence(&Equivalence::Differs { frame: Some(3) });
        assert_eq!(e, "differs (counterexample at frame 3)");
        for v in [
            Equivalence::Proved { seconds: 1.25 },
            Equivalence::Differs { frame: None },
            Equivalence::Undecided {
                why: "time limit".into(),
            },
        ] {
            let t = equivalence(&v);
            assert!(!t.contains('{') && !t.contains("Some"), "{t}");
        }
    }
}
