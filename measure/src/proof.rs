//! The formal proof of the emitted gateware as a report section:
//! `formal::prove` (minutes for a 48 MHz preset), or the proof of the same
//! Verilog and harness remembered by `formal::cache` (in the build
//! directory's `prove/cache/`, and under `$SLOTFORGE_CACHE/proofs` when set).
//! A bounded result is shown as bounded, never as proved.

use std::path::{Path, PathBuf};

use formal::{Outcome, Proof, ProveOptions};
use lut_gen::Schedule;
use report::{Section, Table};

/// Where the build keeps its proof (relative to the build directory): the
/// cache and a counterexample's VCD and `.gtkw`.
pub const DIR: &str = "prove";

/// A proof to show: how it came (`cached`) and the report's section.
pub struct ShownProof {
    pub proof: Proof,
    pub cached: bool,
    pub section: Section,
    /// The step's one line.
    pub line: String,
}

/// The emitted Verilog, the cache key of proving it against `s`'s harness,
/// and what that harness does not assert (a remembered proof is shown with
/// the list of the harness it was proved against, read afresh).
fn keyed(s: &Schedule) -> Result<(String, String, Vec<String>), String> {
    let design = hdl::emit(s, None)
        .map_err(|e| e.to_string())?
        .verilog()
        .to_string();
    let h = formal::generate(s).map_err(|e| e.to_string())?;
    let key = formal::cache::key(&h.verilog, &design, ProveOptions::new("").solver);
    let uncovered = h.not_covered.iter().map(|c| c.sentence(s)).collect();
    Ok((design, key, uncovered))
}

/// The remembered proof under `key`, with `uncovered` as its list.
fn remembered(dirs: &[PathBuf], key: &str, uncovered: Vec<String>) -> Option<Proof> {
    let mut p = formal::cache::load(dirs, key)?;
    p.not_covered = uncovered;
    Some(p)
}

fn cache_dirs(out: &Path) -> Vec<PathBuf> {
    let mut d = vec![out.join(DIR).join("cache")];
    d.extend(formal::cache::shared_dir());
    d
}

/// The remembered proof of `s`'s emitted gateware, if one exists.
pub fn cached_proof(s: &Schedule, out: &Path) -> Option<ShownProof> {
    let (_, key, uncovered) = keyed(s).ok()?;
    let p = remembered(&cache_dirs(out), &key, uncovered)?;
    Some(shown(p, true))
}

/// Proves `s`'s emitted gateware (or shows the remembered proof) and keeps
/// a proof in the caches.  `Err`: the proof could not run (a tool missing
/// or failing, a mix beyond the harness).
pub fn proof(s: &Schedule, out: &Path) -> Result<ShownProof, String> {
    let (design, key, uncovered) = keyed(s)?;
    let dirs = cache_dirs(out);
    if let Some(p) = remembered(&dirs, &key, uncovered) {
        return Ok(shown(p, true));
    }
    let mut opts = ProveOptions::new(out.join(DIR));
    opts.frame_counter = Some(hdl::LINK_FRAME_COUNTER.to_string());
    opts.mode_decision = Some(hdl::MODE_DECISION.to_string());
    opts.trigger_run = Some(hdl::TRIGGER_RUN.to_string());
    let p = formal::prove(s, &design, &opts).map_err(|e| e.to_string())?;
    for d in &dirs {
        formal::cache::store(d, &key, &p)?;
    }
    Ok(shown(p, false))
}

/// "proved for all time" of the whole contract only when nothing is left
/// out; else what is left out, named.
fn claim(uncovered: &[String]) -> String {
    match uncovered {
        [] => "proved for all time (the whole contract)".into(),
        [one] => {
            format!("proved for all time, except one part of the contract not asserted: {one}")
        }
        many => format!(
            "proved for all time, except {} parts of the contract not asserted (the section's \
             table \"Not covered\")",
            many.len()
        ),
    }
}

fn word(o: Outcome) -> &'static str {
    match o {
        Outcome::Proved => "proved",
        Outcome::Bounded => "bounded only (not a proof)",
        Outcome::Failed => "FAILED",
    }
}

/// The section and line of `p`.
pub fn shown(p: Proof, cached: bool) -> ShownProof {
    let line = match p.result {
        Outcome::Proved => format!(
            "{}: {} properties, depth {} steps, solver {:.1} s{}",
            claim(&p.not_covered),
            p.properties.len(),
            p.depth,
            p.solver_seconds,
            if cached {
                " (remembered: same Verilog and harness)"
            } else {
                ""
            }
        ),
        Outcome::Bounded => format!(
            "BOUNDED ONLY, not a proof: no violation within {} steps of reset",
            p.depth
        ),
        Outcome::Failed => format!(
            "FAILED: a trace from reset violates the contract at cycle {}",
            p.cycle.unwrap_or(-1)
        ),
    };
    let mut t = Table::new(&["property", "result", "what it asserts"]);
    for q in &p.properties {
        t.push(vec![q.name.clone(), word(q.result).into(), q.what.clone()]);
    }
    let mut paragraphs = vec![
        format!(
            "`slotforge prove` ({}, docs/formal.md): the pin contract asserted at the ports of \
             the emitted `slotforge_top` for any MISO input, one reset cycle assumed. Result: {}, \
             depth {} steps, {:.1} s in all, solver {:.1} s.",
            p.solver.name(),
            match (p.result, p.not_covered.len()) {
                (Outcome::Proved, n) if n > 0 => format!(
                    "proved, except the {n} part{} of the contract not asserted (table \"Not covered\")",
                    if n == 1 { "" } else { "s" }
                ),
                (o, _) => word(o).into(),
            },
            p.depth,
            p.seconds,
            p.solver_seconds
        ),
        p.note.clone(),
    ];
    if cached {
        paragraphs.push(
            "Shown from the proof cache: an earlier run proved this same Verilog against this \
             same harness with this same engine (the key hashes all three); times are that run's."
                .into(),
        );
    }
    let mut links = Vec::new();
    if let Some(c) = &p.counterexample {
        paragraphs.push(format!(
            "Counterexample at cycle {}; the checker on its trace: {}",
            c.cycle,
            c.diagnosis.lines().next().unwrap_or("")
        ));
        let name = |f: &Path| {
            format!(
                "{DIR}/{}",
                f.file_name()
                    .map(|n| n.to_string_lossy())
                    .unwrap_or_default()
            )
        };
        links.push((name(&c.vcd), "the counterexample (VCD)".into()));
        links.push((name(&c.gtkw), "its GTKWave save file".into()));
    }
    let mut tables = vec![("Properties".into(), t)];
    if !p.not_covered.is_empty() {
        let mut n = Table::new(&["part of the contract not asserted (not proved)"]);
        for q in &p.not_covered {
            n.push(vec![q.clone()]);
        }
        tables.push(("Not covered".into(), n));
    }
    let section = Section {
        title: "Formal proof".into(),
        paragraphs,
        tables,
        links,
        ..Section::default()
    };
    ShownProof {
        proof: p,
        cached,
        section,
        line,
    }
}
