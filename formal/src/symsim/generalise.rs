//! Counters that only feed data, generalised at frame starts: the packets'
//! 8-bit frame counters (the design's and the harness's) keep the state
//! from coming round for 256 frames, though nothing but the bytes they
//! put on the line depends on them.
//!
//! At each frame start from `Counters::from` on, once the two counters
//! are shown equal in every state the path holds (their XOR unsatisfiable),
//! both are replaced by one fresh variable per bit (input index past the
//! AIG's inputs and latches, of that step).  The set of states the
//! symbolic state then stands for contains the exact one's (any count the
//! run could have reached, with everything else as it was), so the
//! simulation from it covers every reachable state and more: an assertion
//! that holds there holds in every reachable state, and a state equal (up
//! to renaming) to an earlier frame start's closes the search as in
//! `mod.rs`.  An inductive invariant, checked, not assumed.  What is lost
//! is exactness: a violation after a generalisation may come from a count
//! no run reaches with that state, so it is not a trace from reset as it
//! stands.  So it is solved again with every generalisation of the path
//! pinned: each one's variables equal to the counter's literals it
//! replaced (the count before it, a function of the previous
//! generalisation's variables, so the chain goes back to the exact count
//! from reset), and a model of that is a trace from reset (with every pin,
//! the state is the exact one).  Without one, the run ends `Bounded` at the
//! first generalised step (the exact search before it), naming the count
//! that failed.
//!
//! A split run (`split.rs`, `cases.rs`) generalises on every path alike;
//! each path keeps its own [`Pin`] (a path split off inherits its
//! parent's), so the pinned model is that path's exact state, its
//! condition and fixed inputs included.  The counters are shown
//! equal under the path's condition: its states are the ones that satisfy it.

use super::graph::{Assigned, Graph};
use super::{Found, Sim};

/// The harness's counters the engine treats apart: the latch pairs one
/// counter's bits occupy in the design and in the harness (the frame
/// counters, generalised), where generalising starts, and an AXI4-Stream
/// slave's wait count (paths subsumed, `split.rs`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Counters {
    /// `(design's latch, harness's latch)` per bit, least significant
    /// first (AIG latch indices).
    pub pairs: Vec<(usize, usize)>,
    /// The first frame-start step at which they are generalised; every
    /// step before it is simulated exactly from reset.
    pub from: u64,
    /// The slave's wait count (the harness's `waited`; empty without
    /// one), least significant bit first: read by nothing but the slave's
    /// `tready`, so a path whose count is lower has every future of one in
    /// the same state otherwise (`split.rs`).
    pub wait: Vec<usize>,
    /// A violation after a generalisation is pinned to the counts it
    /// replaced, for a trace from reset (the frame counters, whose count is
    /// the one before plus one).  Without (the trigger runs, whose counts
    /// are functions of the codes), it is no verdict (`Bounded`, the count
    /// noted: the caller searches exactly), and the path's condition need
    /// not keep the codes those counts read alive (`cases.rs`), which would
    /// keep every frame's condition and the state from coming round.
    pub pinned: bool,
}

/// One path's generalisations: the counter's literals each replaced, and
/// the variables it put there, bit by bit, one generalisation after the
/// other (a violation is pinned to them).
#[derive(Debug, Clone, Default)]
pub(super) struct Pin {
    pub(super) exact: Vec<u32>,
    pub(super) vars: Vec<u32>,
}

/// Why a run with generalised counters did not close.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CounterFailure {
    /// At frame start `step` the two counters are not equal in every state
    /// (the design counts otherwise than the harness, or the state is not
    /// one that comes round).
    Unequal { step: u64, count: Option<u64> },
    /// From a frame start whose (generalised) count was `count`, an
    /// assertion fails at `step`.
    Violated { step: u64, count: u64 },
}

impl Sim<'_> {
    /// The input index of the counter's bit `b`'s variable (past every
    /// input and latch, so never a MISO bit or a power-on value).
    fn counter_input(&self, b: usize) -> u32 {
        (self.g.inputs.len() + self.g.latches.len() + b) as u32
    }

    /// At frame start `step`: both counters become one fresh variable per
    /// bit, once shown equal; `Err` (the run's verdict) when they are not.
    pub(super) fn generalise(&mut self, step: u64) -> Result<(), Found> {
        let Some(c) = self.counters.as_ref().filter(|c| step >= c.from) else {
            return Ok(());
        };
        let (pairs, pinned) = (c.pairs.clone(), c.pinned);
        let mut differ = 0u32;
        for &(d, h) in &pairs {
            let bit = xor(&mut self.gr, self.state[d], self.state[h]);
            differ = self.gr.and(differ ^ 1, bit ^ 1) ^ 1;
        }
        if differ != 0 {
            self.stats.sat_calls += 1;
            let limit = self
                .deadline
                .map(|d| d.saturating_duration_since(std::time::Instant::now()));
            let mut found = self.gr.satisfy(differ, limit);
            if matches!(found, Ok(Some(_))) && !self.cond.is_empty() {
                // the path's states are those that satisfy its condition
                let cond = self.cond_lit();
                let under = self.gr.and(differ, cond);
                self.stats.sat_calls += 1;
                found = self.gr.satisfy(under, limit);
            }
            if !matches!(found, Ok(None)) {
                let count = found.ok().flatten().and_then(|a| self.count_of(&a));
                self.stats.counter_failure = Some(CounterFailure::Unequal { step, count });
                return Err(Found::Bounded {
                    steps: self.generalised.unwrap_or(step),
                });
            }
        }
        for (b, &(d, h)) in pairs.iter().enumerate() {
            let v = self.gr.var(self.counter_input(b), step as u32);
            if pinned {
                self.pin.exact.push(self.state[d]);
            }
            self.pin.vars.push(v);
            self.state[d] = v;
            self.state[h] = v;
        }
        self.generalised.get_or_insert(step);
        self.stats.generalised = self.generalised;
        Ok(())
    }

    /// A violation `bad` at `step` found by the SAT model `assign`: `None`
    /// when it is a trace from reset (the path has not generalised); else
    /// the violation with every generalisation pinned to the exact count,
    /// if there is one; else the run's verdict (bounded by the exact part),
    /// the count it came from noted.
    pub(super) fn generalised_violation(
        &mut self,
        step: u64,
        bad: u32,
        assign: &[Assigned],
    ) -> Option<Found> {
        if self.pin.vars.is_empty() {
            return None;
        }
        let pinned = self.counters.as_ref().is_some_and(|c| c.pinned);
        if let Some(model) = pinned.then(|| self.pinned_model(bad)).flatten() {
            return Some(self.violation(step, model));
        }
        let count = self.count_of(assign).unwrap_or(0);
        self.stats.counter_failure = Some(CounterFailure::Violated { step, count });
        Some(Found::Bounded {
            steps: self.generalised.unwrap_or(step),
        })
    }

    /// The count of the latest generalisation a model reads (its
    /// variables' values, unassigned bits 0); `None` if it reads none.
    fn count_of(&self, assign: &[Assigned]) -> Option<u64> {
        let first = self.counter_input(0);
        let ours = |i: u32| self.is_counter_input(i);
        let at = (assign.iter()).filter(|a| ours(a.0)).map(|a| a.1).max()?;
        let count = (assign.iter())
            .filter(|a| ours(a.0) && a.1 == at && a.2)
            .map(|a| 1u64 << (a.0 - first))
            .sum();
        Some(count)
    }

    /// A model of `bad` with every generalisation's variables equal to the
    /// counter's literals they replaced (a trace from reset), if any.
    fn pinned_model(&mut self, bad: u32) -> Option<Vec<Assigned>> {
        let mut lit = bad;
        let pins: Vec<(u32, u32)> = (self.pin.vars.iter().copied())
            .zip(self.pin.exact.iter().copied())
            .collect();
        for (v, exact) in pins {
            let differ = xor(&mut self.gr, v, exact);
            lit = self.gr.and(lit, differ ^ 1);
        }
        self.stats.sat_calls += 1;
        let limit = self
            .deadline
            .map(|d| d.saturating_duration_since(std::time::Instant::now()));
        self.gr.satisfy(lit, limit).ok().flatten()
    }

    /// Whether input `i` is a counter's variable (never in a witness: a
    /// pinned model gives it the value the real inputs make).
    pub(super) fn is_counter_input(&self, i: u32) -> bool {
        i >= self.counter_input(0)
    }
}

/// `x XOR y` in the graph.
fn xor(gr: &mut Graph, x: u32, y: u32) -> u32 {
    let one = gr.and(x, y ^ 1);
    let other = gr.and(x ^ 1, y);
    gr.and(one ^ 1, other ^ 1) ^ 1
}
