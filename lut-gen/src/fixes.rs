//! Fixes for a mix without a schedule, each one tried before it is said.
//!
//! Advice computed from counts alone can be wrong (a branch with slots to
//! spare may have no free mux input), so every candidate is applied to the
//! user's own mix text ([`edit`]), parsed and validated as a file, synthesized
//! (the synthesizer re-checks its schedule with [`crate::validate`]), held
//! against the gateware's limits ([`crate::ports::Layout::fits`]) and audited;
//! only a candidate that comes out feasible is offered, and with it the exact
//! text that passed, so a written fix file audits feasible by construction.
//!
//! Candidates are few and bounded ([`MAX_TRIED`] syntheses at most, each
//! with a smaller search bound than the audit's own), cheapest first, and
//! the search stops at [`MAX_OFFERED`] fixes, so an infeasible mix's audit
//! stays quick.

use std::fmt;
use std::path::Path;

use serde::Serialize;

use crate::mix::Mix;
use crate::synth::Infeasible;

mod candidates;
mod edit;

// Public for this crate's tests only (`crate::for_tests`).
pub use edit::{apply, Edit};

/// Fixes offered at most (the cheapest that work).
pub const MAX_OFFERED: usize = 5;
/// Candidates synthesized at most per audit.
pub const MAX_TRIED: usize = 40;
/// Exact-search placements per grid for a candidate: a candidate this
/// bound cannot decide is not offered (the audit's own bound is larger).
pub const CANDIDATE_BUDGET: u64 = 20_000;

/// What a fix changes, in the mix's own names.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Change {
    /// Another slice length (`[frame].slice_us`), and/or the slot grid left
    /// to the synthesizer (`slots_per_slice` dropped).
    Grid {
        slice_us: Option<(u64, u64)>,
        dropped_slots_per_slice: Option<u64>,
    },
    /// Channels moved to another branch, which gets more mux devices if
    /// its free inputs are too few.
    MoveChannels {
        from: String,
        to: String,
        channels: Vec<String>,
        rate_hz: u64,
        mux_devices: Option<(u32, u32)>,
    },
    /// More mux devices on a branch.
    AddMuxDevices { branch: String, from: u32, to: u32 },
    /// Channels sampled at a lower rate.
    LowerRate {
        channels: Vec<String>,
        from_hz: u64,
        to_hz: u64,
    },
    /// A new branch like an existing one, and channels moved onto it.
    AddBranch {
        name: String,
        like: String,
        channels: Vec<String>,
    },
    /// A faster UART (`[link].baud`): a standard baud the clock divides
    /// within the audit's tolerance.
    RaiseBaud { from: u64, to: u64 },
    /// A branch's converter supply said (`vdd`): its datasheet's figures at
    /// that supply instead of its lowest's (true only if the board runs the
    /// part at it).
    Supply {
        branch: String,
        part: String,
        vdd_mv: u32,
        sclk_max_hz: u64,
        max_sps: u64,
    },
}

/// A change that was applied, synthesized and audited feasible.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fix {
    /// One change, or one per over-full branch when several are.
    pub changes: Vec<Change>,
    /// The changes in words (branch and channel names, rates in Hz).
    pub says: String,
    /// What it costs: parts added (ADCs and mux devices), and channels
    /// whose wiring or rate changes. Fixes are ordered by [`cost`]: those
    /// that keep every rate first, then by parts, then by channels.
    pub parts_added: u32,
    pub channels_changed: usize,
    /// The slot grid the fixed mix is scheduled on.
    pub slots_per_slice: u64,
    /// Where `audit --fixes DIR` wrote it (`DIR/fix-<n>.toml`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// The complete fixed mix file, as it was audited.
    #[serde(skip)]
    pub text: String,
}

/// The outcome of a fix search.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FixSearch {
    pub fixes: Vec<Fix>,
    /// Candidates synthesized (the rest of the candidates were not needed
    /// or beyond `MAX_TRIED`).
    pub tried: usize,
}

/// The order fixes are tried and offered in (see `Candidate::cost`).
pub fn cost(changes: &[Change], parts_added: u32, channels_changed: usize) -> (bool, u32, usize) {
    (
        changes
            .iter()
            .any(|c| matches!(c, Change::LowerRate { .. })),
        parts_added,
        channels_changed,
    )
}

/// A candidate before it is tried.
#[derive(Clone)]
pub(crate) struct Candidate {
    changes: Vec<Change>,
    edits: Vec<Edit>,
    parts_added: u32,
    channels_changed: usize,
}

impl Candidate {
    /// A mix's rates are its requirement: a fix that keeps every rate comes
    /// before one that lowers some; then fewer parts added, then fewer
    /// channels changed.
    fn cost(&self) -> (bool, u32, usize) {
        cost(&self.changes, self.parts_added, self.channels_changed)
    }

    /// The candidates of several branches as one.
    fn join(parts: Vec<Candidate>) -> Candidate {
        let mut all = Candidate {
            changes: Vec::new(),
            edits: Vec::new(),
            parts_added: 0,
            channels_changed: 0,
        };
        for p in parts {
            all.changes.extend(p.changes);
            all.edits.extend(p.edits);
            all.parts_added += p.parts_added;
            all.channels_changed += p.channels_changed;
        }
        all
    }
}

/// Fixes for `mix` (the file `path` holding `text`), which has no schedule
/// for the reasons in `why`.
pub fn search(path: &Path, text: &str, mix: &Mix, why: &Infeasible) -> FixSearch {
    run(path, text, candidates::for_schedule(mix, why))
}

/// Fixes for a mix that has a schedule but whose UART cannot carry its
/// samples (`s`, its schedule; `min_baud`, the slowest line that would):
/// the lowest standard baud that the clock divides within the audit's
/// tolerance and that audits feasible.
pub fn search_link(path: &Path, text: &str, s: &crate::Schedule, min_baud: f64) -> FixSearch {
    let mut out = FixSearch {
        fixes: Vec::new(),
        tried: 0,
    };
    let Some(link) = s
        .mix
        .link
        .as_ref()
        .filter(|l| l.kind == crate::mix::LinkKind::Uart)
    else {
        return out;
    };
    for c in candidates::faster_lines(s.grid.clock_hz, link.baud, min_baud) {
        if out.tried >= MAX_TRIED {
            break;
        }
        let found = run(path, text, vec![c]);
        out.tried += found.tried;
        if !found.fixes.is_empty() {
            out.fixes = found.fixes;
            break;
        }
    }
    out
}

/// Fixes for a mix file the loader refuses because a branch has more
/// channels than mux inputs: more mux devices, tried like any fix.
pub fn search_unloadable(path: &Path, text: &str) -> FixSearch {
    run(path, text, candidates::for_mux_inputs(text))
}

fn run(path: &Path, text: &str, mut cands: Vec<Candidate>) -> FixSearch {
    // stable: equal costs keep the order they were proposed in
    cands.sort_by_key(Candidate::cost);
    let mut seen: Vec<Vec<Edit>> = Vec::new();
    let mut out = FixSearch {
        fixes: Vec::new(),
        tried: 0,
    };
    for c in cands {
        if out.fixes.len() >= MAX_OFFERED || out.tried >= MAX_TRIED {
            break;
        }
        if seen.contains(&c.edits) {
            continue;
        }
        seen.push(c.edits.clone());
        let Some(edited) = edit::apply(text, &c.edits) else {
            continue;
        };
        out.tried += 1;
        let says = c
            .changes
            .iter()
            .map(words)
            .collect::<Vec<_>>()
            .join("; and ");
        let fixed = format!("# slotforge audit: {says}\n{edited}");
        if let Some(sps) = feasible(path, &fixed, CANDIDATE_BUDGET) {
            out.fixes.push(Fix {
                changes: c.changes,
                says,
                parts_added: c.parts_added,
                channels_changed: c.channels_changed,
                slots_per_slice: sps,
                file: None,
                text: fixed,
            });
        }
    }
    out
}

/// `text` with `vdd` set on the named branches (millivolts), or `None`
/// when the text is not TOML or a branch is missing.
pub(crate) fn with_vdd(text: &str, branches: &[(String, u32)]) -> Option<String> {
    let edits: Vec<Edit> = branches
        .iter()
        .map(|(name, mv)| Edit::Vdd {
            name: name.clone(),
            mv: *mv,
        })
        .collect();
    edit::apply(text, &edits)
}

/// Whether mix text audits feasible (parsed and validated, scheduled,
/// within the gateware's limits, its link planned): its slots per slice.
pub fn feasible(path: &Path, text: &str, budget: u64) -> Option<u64> {
    let mix = crate::parse(path, text).ok()?;
    let s = crate::synthesize_within(&mix, budget).ok()?;
    crate::ports::Layout::fits(&s).ok()?;
    let report = crate::AuditReport::of_schedule(&s);
    report.feasible.then_some(s.grid.slots_per_slice)
}

/// Channel names as a user reads them: all of a few, else the first few
/// and how many.
fn names(ch: &[String]) -> String {
    let q: Vec<String> = ch.iter().map(|n| format!("`{n}`")).collect();
    if q.len() <= 6 {
        return q.join(", ");
    }
    format!("{} and {} more", q[..4].join(", "), q.len() - 4)
}

/// What a change does, in the user's words.
pub fn words(c: &Change) -> String {
    match c {
        Change::Grid {
            slice_us,
            dropped_slots_per_slice,
        } => {
            let mut parts = Vec::new();
            if let Some((old, new)) = slice_us {
                parts.push(format!(
                    "slice the frame in {new} us slices instead of {old} us (`[frame] slice_us = {new}`)"
                ));
            }
            if let Some(s) = dropped_slots_per_slice {
                parts.push(format!(
                    "let the synthesizer choose the slot grid (remove `[frame] slots_per_slice = {s}`)"
                ));
            }
            parts.join(", and ")
        }
        Change::MoveChannels {
            from,
            to,
            channels,
            rate_hz,
            mux_devices,
        } => {
            let mut s = format!(
                "move {} ({rate_hz} Hz) from branch `{from}` to branch `{to}`",
                names(channels)
            );
            if let Some((a, b)) = mux_devices {
                s.push_str(&format!(
                    ", and give `{to}` {b} mux devices instead of {a} for the inputs"
                ));
            }
            s
        }
        Change::AddMuxDevices { branch, from, to } => {
            format!("give branch `{branch}` {to} mux devices instead of {from}")
        }
        Change::LowerRate {
            channels,
            from_hz,
            to_hz,
        } => format!("lower {} from {from_hz} Hz to {to_hz} Hz", names(channels)),
        Change::AddBranch {
            name,
            like,
            channels,
        } => format!(
            "add a branch `{name}` built like `{like}` (its own ADC and mux) and move {} to it",
            names(channels)
        ),
        Change::Supply {
            branch,
            part,
            vdd_mv,
            sclk_max_hz,
            max_sps,
        } => {
            let v = crate::parts::volts(*vdd_mv);
            format!(
                "say `vdd = {v}` on branch `{branch}` if its {part} runs at {v} V (its datasheet's figures there: SCLK up to {}, {max_sps} S/s)",
                crate::mix::hz_words(*sclk_max_hz)
            )
        }
        Change::RaiseBaud { from, to } => {
            format!("raise the link's baud from {from} to {to} (`[link] baud = {to}`)")
        }
    }
}

impl fmt::Display for FixSearch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.fixes.is_empty() {
            return writeln!(
                f,
                "  no fix found: none of the {} changes tried (moving channels, more mux devices, another branch, lower rates, another slice) gives a schedule",
                self.tried
            );
        }
        writeln!(
            f,
            "  what makes it fit (each change applied to the mix and audited feasible; cheapest first):"
        )?;
        for (i, x) in self.fixes.iter().enumerate() {
            writeln!(f, "  {}. {}", i + 1, x.says)?;
        }
        Ok(())
    }
}
