//! How each solver's engines are combined into a result: which runs first,
//! and what a run that cannot tell falls back to.

use crate::engine::{self, Combined, Prepared, Solver, SolverVerdict};
use crate::{Outcome, ProveError, ProveOptions, DEEP_FRAMES, PROVED};
use std::path::Path;

/// What a strategy found: the outcome, its depth (see `Proof::depth`) and
/// what it means, in words.
pub(crate) type Finding = (Outcome, u64, String);

/// Steps 0..=2F+1 from power-on: the recurrence bound (aiger.rs).
pub(crate) fn recurrence_bound(f: u64) -> u64 {
    2 * f + 2
}

/// Steps the first bounded search covers: at least the recurrence bound and
/// two more.
pub(crate) fn search_depth(f: u64, opts: &ProveOptions) -> u64 {
    opts.depth.unwrap_or(0).max(recurrence_bound(f) + 2)
}

fn bmc_only(why: String, steps: u64, f: u64) -> Finding {
    (
        Outcome::Bounded,
        steps,
        format!(
            "NOT a proof: {why}; no violation from reset within {steps} steps ({} cycles after reset, {:.2} frames)",
            steps.saturating_sub(2),
            steps.saturating_sub(2) as f64 / f as f64
        ),
    )
}

fn failed(step: u64) -> Finding {
    (
        Outcome::Failed,
        step,
        format!(
            "a trace from reset violates the contract at step {step} (cycle {})",
            step as i64 - 2
        ),
    )
}

fn proved_by_recurrence(f: u64) -> Finding {
    let base = recurrence_bound(f);
    (
        Outcome::Proved,
        base,
        format!(
            "{PROVED}: no violation from reset within {base} steps, and for every input the state at step {base} recurs at step {} of a copy started a frame later, so those steps reach every reachable state (state recurrence, ABC bmc3)",
            base - f
        ),
    )
}

/// A bounded search's verdict when it found a violation; `bounded` otherwise.
fn violation_or(v: SolverVerdict, bounded: impl FnOnce(u64) -> Finding) -> Finding {
    match v {
        SolverVerdict::Violated { step } => failed(step),
        SolverVerdict::Bounded { steps } => bounded(steps),
        SolverVerdict::Proved => unreachable!("bmc3 proves nothing"),
    }
}

/// ABC: both checks in one run first (the common cases: proved, or a
/// violation from reset); the separate checks only when it cannot tell.
pub(crate) fn abc(prep: &Prepared, f: u64, opts: &ProveOptions) -> Result<Finding, ProveError> {
    Ok(match engine::combined(prep, f, opts.timeout_s)? {
        Some(Combined::Holds) => proved_by_recurrence(f),
        Some(Combined::Fails { step }) => {
            // the miter's witness is in its own inputs: the design's, from the plain search
            violation_or(engine::bmc(prep, step + 2, opts.bmc_timeout_s)?, |steps| {
                bmc_only(
                    "the plain search did not reproduce the combined search's violation".into(),
                    steps,
                    f,
                )
            })
        }
        _ => abc_separate(prep, f, opts)?,
    })
}

/// The search from reset to past the recurrence bound, then the recurrence
/// check.
fn abc_separate(prep: &Prepared, f: u64, opts: &ProveOptions) -> Result<Finding, ProveError> {
    let base = recurrence_bound(f);
    Ok(
        match engine::bmc(prep, search_depth(f, opts), opts.bmc_timeout_s)? {
            SolverVerdict::Bounded { steps } if steps > base => {
                match engine::recurrence(prep, f, opts.timeout_s)? {
                    Some(true) => proved_by_recurrence(f),
                    // No argument for all time: search deeper for a violation.
                    r => deeper(prep, f, opts, steps, r.is_some())?,
                }
            }
            v => violation_or(v, |steps| {
                bmc_only(
                    format!("the search from reset stopped at its time limit ({} s) before the recurrence bound {base}", opts.bmc_timeout_s),
                    steps,
                    f,
                )
            }),
        },
    )
}

/// The state does not recur (`refuted`) or the check timed out: a longer
/// search from reset, as the design may keep state older than a frame.
fn deeper(
    prep: &Prepared,
    f: u64,
    opts: &ProveOptions,
    steps: u64,
    refuted: bool,
) -> Result<Finding, ProveError> {
    let why = if refuted {
        "the design's state does not recur a frame later for every input (it keeps state older than a frame), so no bound covers all time".to_string()
    } else {
        format!(
            "the recurrence check did not finish in {} s",
            opts.timeout_s
        )
    };
    let deeper = opts.depth.unwrap_or(0).max(DEEP_FRAMES * f);
    Ok(violation_or(
        engine::bmc(prep, deeper, opts.bmc_timeout_s)?,
        |more| bmc_only(why, more.max(steps), f),
    ))
}

/// PDR or cvc5's k-induction, which close a proof on their own; when they
/// do not, ABC's bounded search from reset.
pub(crate) fn closing(
    prep: &Prepared,
    work: &Path,
    f: u64,
    opts: &ProveOptions,
) -> Result<Finding, ProveError> {
    let closed = if opts.solver == Solver::Pdr {
        engine::pdr(prep, opts.timeout_s)?
    } else {
        engine::smt_induction(prep, 4, opts.timeout_s)?
    };
    Ok(match closed {
        Some(SolverVerdict::Proved) => (
            Outcome::Proved,
            0,
            format!("{PROVED} by {}", opts.solver.name()),
        ),
        Some(SolverVerdict::Violated { step }) => failed(step),
        _ => {
            let aig = engine::prepare(work, Solver::Abc)?;
            violation_or(
                engine::bmc(&aig, search_depth(f, opts), opts.bmc_timeout_s)?,
                |steps| {
                    bmc_only(
                        format!(
                            "{} did not close in {} s",
                            opts.solver.name(),
                            opts.timeout_s
                        ),
                        steps,
                        f,
                    )
                },
            )
        }
    })
}
