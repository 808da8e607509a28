//! Faults given as Verilog (mutants of the emitted Verilog from the
//! test-only mutator, `formal`'s deep fault classes) run through the
//! Verilog engines (Verilator, Icarus) like any other fault: every detector
//! judges each run apart, and a run no detector rejects is undetected unless
//! the faulty design is proved equivalent at the ports ([`crate::equiv`]) or
//! proves the full contract (`prove`).
//!
//! `prove` is also a detector here and of the gateware faults: it reads a
//! design, so it sees every fault that is one (and no pin fault, which
//! exists only inside a simulation).

use std::path::Path;
use std::time::Instant;

use judge::reset_cycles;
use lut_gen::Schedule;
use serde::Serialize;

use super::{parallel, Cost, Detector, FaultClass, Injection, Judged, Judgement, Runs};
use crate::equiv::Equivalence;
use crate::sigrok::SpiCapture;
use engines::{Backend, SimOptions};

/// A faulty design as Verilog text (a `slotforge_top` on the pin contract).
#[derive(Debug, Clone)]
pub struct VerilogFault {
    /// The class it is counted in (e.g. `mutant:relop`, `rare-collision`).
    pub class: FaultClass,
    /// What was changed, for the report.
    pub name: String,
    pub verilog: String,
}

/// `formal`'s deep fault classes on `s`: `late-counter@frameN` lands in
/// frame `frames` (just past a run of `frames` frames), `rare-collision`
/// needs two equal codes back to back, which the stimuli never give.
pub fn deep_faults(s: &Schedule, frames: u64) -> Result<Vec<VerilogFault>, String> {
    let clean = engines::verilog(s).map_err(|e| e.to_string())?;
    // the late counter flips `mux_sel[0]`: a mix without any mux has no such pin
    let muxed = lut_gen::Layout::new(s).has(lut_gen::Role::MuxSel);
    [
        formal::DeepFault::LateCounter { frames },
        formal::DeepFault::RareCollision,
    ]
    .into_iter()
    .filter(|f| muxed || !matches!(f, formal::DeepFault::LateCounter { .. }))
    .map(|f| {
        Ok(VerilogFault {
            class: FaultClass::of_deep(f),
            name: f.name(),
            verilog: f.apply(s, &clean)?,
        })
    })
    .collect()
}

/// One fault of each gateware class (`hdl::GatewareFault`) as the faulty
/// Verilog the emitter writes for it, so the Verilog engines run the
/// classes the rusthdl target builds into the gateware (counted at the
/// gateware level); a fault the mix's gateware cannot hold is left out.
pub fn gateware_as_verilog(s: &Schedule) -> Vec<VerilogFault> {
    super::one_gateware_fault_per_class(s)
        .into_iter()
        .filter_map(|(class, f)| {
            let (_, gate) = hdl::verilog_pair(s, f).ok()?;
            Some(VerilogFault {
                name: format!("{class}: {f}"),
                class,
                verilog: gate,
            })
        })
        .collect()
}

/// What `prove` said of one design.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "result", rename_all = "kebab-case")]
pub enum ProveVerdict {
    /// The design violates the contract: a counterexample from reset.
    Failed { cycle: Option<i64> },
    /// The design proves the full contract for all time (nothing of it
    /// left unasserted: `Proof::not_covered` empty).
    Proved,
    /// Neither within the time limits, or a tool failed: no verdict.
    NoVerdict { why: String },
}

/// Time limits of each proof (seconds): the unbounded engine and the
/// bounded search.  Small-frame mixes take seconds; a 48 MHz preset minutes.
pub const PROVE_SECONDS: u64 = 300;

/// `prove` on `design` against `s`.
pub fn prove(s: &Schedule, design: &str) -> (ProveVerdict, f64) {
    let t = Instant::now();
    let v = match tempfile::tempdir() {
        Err(e) => Err(e.to_string()),
        Ok(dir) => prove_in(s, design, dir.path()).map(|(_, v)| v),
    };
    let v = v.unwrap_or_else(|why| ProveVerdict::NoVerdict { why });
    (v, t.elapsed().as_secs_f64())
}

/// The campaign's proof of `design` against `s`, its files in `dir`: the
/// proof itself and the verdict the campaign takes from it (a test reads
/// both from one proof rather than proving the design twice).
pub fn prove_in(
    s: &Schedule,
    design: &str,
    dir: &Path,
) -> Result<(formal::Proof, ProveVerdict), String> {
    let mut o = formal::ProveOptions::new(dir);
    o.timeout_s = PROVE_SECONDS;
    o.bmc_timeout_s = PROVE_SECONDS;
    o.frame_counter = Some(hdl::LINK_FRAME_COUNTER.to_string());
    // no `mode_decision`: a faulted gateware may read its decision where
    // slotforge's does not, which the two runs' tie rests on (formal::tied)
    let p = formal::prove(s, design, &o).map_err(|e| e.to_string())?;
    let v = verdict(&p);
    Ok((p, v))
}

/// What the campaign takes from proof `p`.
fn verdict(p: &formal::Proof) -> ProveVerdict {
    match p.result {
        formal::Outcome::Failed => ProveVerdict::Failed { cycle: p.cycle },
        // a proof that leaves part of the contract unasserted (a
        // link's line) cannot excuse a fault there
        formal::Outcome::Proved if p.not_covered.is_empty() => ProveVerdict::Proved,
        formal::Outcome::Proved => ProveVerdict::NoVerdict {
            why: format!(
                "the asserted properties hold for all time, but prove does not assert: {}",
                p.not_covered.join("; ")
            ),
        },
        formal::Outcome::Bounded => ProveVerdict::NoVerdict {
            why: p.note.clone(),
        },
    }
}

/// Why `prove` cannot run here (`None`: it can).
pub fn prove_unavailable() -> Option<String> {
    ["yosys", "yosys-abc", "iverilog", "vvp"]
        .into_iter()
        .find(|t| !judge::tools::present(t))
        .map(|t| format!("{t} is not installed (make tools)"))
}

/// Runs `engine` on `verilog` for `frames` frames under the checker and,
/// with `sigrok`, sigrok's decode of its pins.
pub(super) fn judge_verilog(
    s: &Schedule,
    engine: Backend,
    verilog: &str,
    frames: u64,
    sigrok: bool,
) -> Result<Judged, String> {
    judge_verilog_timed(s, engine, verilog, frames, sigrok).map(|(j, _)| j)
}

/// [`judge_verilog`] and the wall seconds of the engine's run under the
/// checker (sigrok's decode, counted in its own cost, apart).
fn judge_verilog_timed(
    s: &Schedule,
    engine: Backend,
    verilog: &str,
    frames: u64,
    sigrok: bool,
) -> Result<(Judged, f64), String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let rtl = dir.path().join("faulty.v");
    std::fs::write(&rtl, verilog).map_err(|e| e.to_string())?;
    // a mix with modes: the campaign's switching scenario
    let (modes, stimulus) = super::modes::scenario(s, frames);
    let opts = SimOptions {
        rtl: Some(rtl),
        tready: super::TREADY,
        modes,
        stimulus: stimulus.unwrap_or_default(),
        ..SimOptions::default()
    };
    let mut cap = SpiCapture::new(s, reset_cycles(s, opts.reset_cycles));
    let t = Instant::now();
    let report = engines::run_observed(
        s,
        engine,
        frames,
        &opts,
        sigrok.then_some(&mut cap as &mut dyn engines::Tracer),
    )
    .map_err(|e| e.to_string())?;
    let seconds = t.elapsed().as_secs_f64();
    let mut j = Judged {
        report,
        sigrok: None,
        cost: Cost::default(),
    };
    if sigrok {
        j.decode(s, &cap, frames, dir.path())?;
    }
    Ok((j, seconds))
}

/// Each Verilog fault on each engine, judged; `prove` once per fault (its
/// verdict holds for every engine's run of it).  A fault the engine cannot
/// build is not injected there.
pub(super) fn verilog_injections(
    s: &Schedule,
    faults: &[VerilogFault],
    engines: &[Backend],
    frames: u64,
    sigrok: bool,
    prove: bool,
    count: &Runs,
) -> Result<Vec<Judgement>, String> {
    let clean = engines::verilog(s).map_err(|e| e.to_string())?;
    let mut jobs = Vec::new();
    for f in faults {
        for &e in engines {
            jobs.push((f, e));
        }
    }
    let runs = parallel(jobs, count, |(f, e)| -> Result<Option<Judgement>, String> {
        let Ok(j) = judge_verilog(s, e, &f.verilog, frames, sigrok) else {
            return Ok(None);
        };
        let site = super::Site {
            name: e.name(),
            cycle: 0,
            slot: 0,
        };
        let inj = super::outcome(f.name.clone(), &site, &j, e.name());
        Ok(Some((
            f.class.clone(),
            f.class.level_as_verilog(),
            inj,
            j.cost,
        )))
    });
    let mut out: Vec<Judgement> = runs
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .flatten()
        .collect();
    // prove each fault once, then the undetected ones' equivalence
    for f in faults {
        let (verdict, secs) = if prove {
            let (v, t) = self::prove(s, &f.verilog);
            (Some(v), t)
        } else {
            (None, 0.0)
        };
        let mut first = true;
        // one equivalence check per fault, whichever engines missed it
        let mut eq: Option<Equivalence> = None;
        for j in out.iter_mut().filter(|j| j.2.fault == f.name) {
            settle(&mut j.2, verdict.as_ref(), || {
                eq.get_or_insert_with(|| equivalence(&clean, &f.verilog))
                    .clone()
            });
            if first && verdict.is_some() {
                j.3.prove_runs += 1;
                j.3.prove_seconds += secs;
                first = false;
            }
        }
    }
    Ok(out)
}

/// `prove`'s verdict into the injection; a run nothing caught gets the
/// equivalence check's answer (or the contract proof as its excuse).
pub(super) fn settle(
    inj: &mut Injection,
    verdict: Option<&ProveVerdict>,
    equivalence: impl FnOnce() -> Equivalence,
) {
    if let Some(v) = verdict {
        if matches!(v, ProveVerdict::Failed { .. }) {
            inj.detected_by.push(Detector::Prove);
        }
        inj.prove = Some(v.clone());
    }
    if inj.detected_by.is_empty() {
        let e = equivalence();
        inj.equivalence = Some(match (e, verdict) {
            (e @ Equivalence::Proved { .. }, _) => e,
            (_, Some(ProveVerdict::Proved)) => Equivalence::ContractProved,
            (e, _) => e,
        });
    }
}

/// The equivalence check of `gate` against the clean Verilog `gold`.
pub(super) fn equivalence(gold: &str, gate: &str) -> Equivalence {
    let undecided = |why: String| Equivalence::Undecided { why };
    match tempfile::tempdir() {
        Ok(dir) => {
            crate::equiv::check(gold, gate, dir.path()).unwrap_or_else(|e| undecided(e.to_string()))
        }
        Err(e) => undecided(e.to_string()),
    }
}

/// A clean run of `engine` judged by every detector (a rejection is a
/// false alarm), timed under the checker: (cycles, seconds, the false
/// alarm).  Verilator's first run also builds (and caches) its model, so
/// a second run is the one timed; Icarus compiles the design in every run
/// (a fraction of a second beside `vvp`), so its judged run is the timed
/// one, and a second `vvp` run of the same design would only repeat it.
pub(super) fn clean_engine_run(
    s: &Schedule,
    engine: Backend,
    frames: u64,
    sigrok: bool,
) -> Result<(u64, f64, Option<String>), String> {
    let clean = engines::verilog(s).map_err(|e| e.to_string())?;
    let (j, seconds) = judge_verilog_timed(s, engine, &clean, frames, sigrok)?;
    let why = if !j.report.ok {
        Some(j.report.summary())
    } else {
        j.sigrok.clone().and_then(|v| v.err())
    };
    if engine == Backend::Icarus {
        return Ok((j.report.cycles, seconds, why));
    }
    let t = Instant::now();
    let timed = judge_verilog(s, engine, &clean, frames, false)?;
    Ok((timed.report.cycles, t.elapsed().as_secs_f64(), why))
}
