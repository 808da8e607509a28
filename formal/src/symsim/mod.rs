//! The `sim` engine: exact symbolic simulation of the AIG from reset, with a
//! state-recurrence check that makes the simulated steps cover all time.
//!
//! Why: the contract's counters run over a whole frame (480,000 cycles at
//! 48 MHz), so induction does not close unaided, and the recurrence miter
//! (`aiger.rs`) makes ABC unroll two design copies over two frames, which
//! needs gigabytes.  But only MISO is free: the control state after reset is
//! the same in every run, and the data registers hold MISO bits of the last
//! conversions.  Simulating with one fresh variable per input bit and step
//! (an and-inverter graph with constants folded and structure hashed, old
//! nodes collected) keeps the state small: control registers are constants,
//! a shift register's bit is a variable, and an assertion comparing the
//! design's word with the harness's record of the same MISO bits folds to
//! the constant "holds" without a SAT call.  Memory stays at the size of the
//! live state, whatever the depth.
//!
//! Soundness of "proved": the state at step `T` is a function `G_T` of the
//! power-on inputs `P` (step 0) and of input variables of earlier steps.  If
//! the state at `T + D` (`D` a whole number of frames) is the *same graph*
//! as at `T` with every input of step `s >= 1` renamed to step `s + D`
//! (checked exactly by a canonical serialization, not a hash), then
//! `G_{T+D}(P, w) = G_T(P, w')` with the window `w` shifted by `D`; as every
//! input variable ranges freely, the sets of states reachable at `T` and
//! `T + D` are equal.  The machine being deterministic given its inputs,
//! every step after `T + D` reaches only states reached at some step in
//! `T .. T + D`.  Every step before `T + D`
//! was checked exactly (a non-constant assertion goes to a SAT solver), so
//! the assertions hold in every reachable state: a proof for all time.  A
//! satisfiable assertion is a real trace from reset (the simulation is
//! exact, not an abstraction): its inputs are the witness.

use std::collections::HashMap;
use std::time::Instant;

use crate::aiger::Aig;

mod graph;
use graph::Graph;
#[cfg(test)]
use graph::VAR;

/// What the symbolic simulation established.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Found {
    /// No assertion fails in steps `0..steps`, and the state at step
    /// `steps` is (up to renaming) the state at step `since`, a whole
    /// number of periods earlier.
    Proved { steps: u64, since: u64 },
    /// An assertion fails at `step`; `inputs[s][i]` is input `i` at step
    /// `s`, and `inputs[0]` goes on with each latch's power-on value (0 for
    /// a latch whose power-on value is fixed).
    Violated { step: u64, inputs: Vec<Vec<bool>> },
    /// No assertion fails in steps `0..steps`; nothing is said beyond.
    Bounded { steps: u64 },
}

/// Figures of a run, for the report and the benchmark.
#[derive(Debug, Clone, Default)]
pub struct Stats {
    /// Steps whose assertion did not fold to a constant (SAT calls).
    pub sat_calls: u64,
    /// Largest graph held between collections.
    pub peak_nodes: usize,
    /// Live nodes of the state at the recurrence (its size).
    pub state_nodes: usize,
    /// Without a recurrence: the latches (AIG order) whose value at the
    /// last comparison differed from a period earlier, the state the
    /// design keeps across frames.
    pub kept: Vec<usize>,
}

/// Simulates `g` from power-on: the state at each step `offset + k *
/// period` is compared (up to renaming) with those of the earlier such
/// steps; the run stops at a recurrence, a failing assertion, `max_steps`
/// or `deadline`.
pub fn run(
    g: &Aig,
    period: u64,
    offset: u64,
    max_steps: u64,
    deadline: Option<Instant>,
) -> (Found, Stats) {
    let mut stats = Stats::default();
    let mut gr = Graph::new();
    let ands = in_dependency_order(g);
    let nv = g.max_var as usize + 1;
    let mut val = vec![0u32; nv];
    let ni = g.inputs.len() as u32;
    // power-on values: 0, 1, or free (a variable of step 0 after the inputs)
    let mut state: Vec<u32> = g
        .latches
        .iter()
        .enumerate()
        .map(|(j, &(l, _, init))| match init {
            0 => 0,
            1 => 1,
            _ if init == l => gr.var(ni + j as u32, 0),
            _ => 0,
        })
        .collect();
    let bad_lits: Vec<u32> = g.bad.clone();
    // every period boundary's state, canonical: a state at `offset + k *
    // period` equal to an earlier boundary's closes the search (a FIFO's
    // pointers may need several frames to come round)
    let mut seen: HashMap<Vec<u64>, u64> = HashMap::new();
    let mut prev_state: Vec<u32> = Vec::new();
    let mut gc_at = 1usize << 20;
    let mut sat_seen = 0;
    for step in 0..max_steps {
        if step >= offset && (step - offset).is_multiple_of(period) {
            let now = canonical_state(&gr, &state, step);
            if let Some(&since) = seen.get(&now) {
                stats.state_nodes = live_nodes(&gr, &state);
                return (Found::Proved { steps: step, since }, stats);
            }
            if step > offset {
                stats.kept = kept(&gr, &prev_state, &state, step, period);
            }
            seen.insert(now, step);
            prev_state.clone_from(&state);
        }
        // every 256 steps, and after every SAT call (a free slave can make
        // each step's assertion a SAT problem)
        if (step.is_multiple_of(256) || stats.sat_calls > sat_seen)
            && deadline.is_some_and(|d| Instant::now() > d)
        {
            return (Found::Bounded { steps: step }, stats);
        }
        sat_seen = stats.sat_calls;
        let st = step as u32;
        for (k, &i) in g.inputs.iter().enumerate() {
            val[(i >> 1) as usize] = gr.var(k as u32, st);
        }
        for (j, &(l, _, _)) in g.latches.iter().enumerate() {
            val[(l >> 1) as usize] = state[j];
        }
        for &(lhs, x, y) in &ands {
            let (x, y) = (
                val[(x >> 1) as usize] ^ (x & 1),
                val[(y >> 1) as usize] ^ (y & 1),
            );
            val[(lhs >> 1) as usize] = gr.and(x, y);
        }
        let lit = |l: u32| val[(l >> 1) as usize] ^ (l & 1);
        let mut bad = 0u32;
        for &b in &bad_lits {
            bad = gr.and(bad ^ 1, lit(b) ^ 1) ^ 1;
        }
        if bad != 0 {
            stats.sat_calls += 1;
            match gr.satisfy(bad) {
                Ok(Some(assign)) => {
                    let mut inputs = vec![vec![false; g.inputs.len()]; step as usize + 1];
                    // after step 0's inputs, each latch's power-on value
                    inputs[0].resize(g.inputs.len() + g.latches.len(), false);
                    for (input, s, v) in assign {
                        inputs[s as usize][input as usize] = v;
                    }
                    return (Found::Violated { step, inputs }, stats);
                }
                Ok(None) => {}
                // no answer is no verdict: nothing is claimed from this step on
                Err(_) => return (Found::Bounded { steps: step }, stats),
            }
        }
        for (j, &(_, next, _)) in g.latches.iter().enumerate() {
            state[j] = lit(next);
        }
        if gr.a.len() > gc_at {
            stats.peak_nodes = stats.peak_nodes.max(gr.a.len());
            let n = state.len();
            state.append(&mut prev_state);
            gr.collect(&mut state);
            prev_state = state.split_off(n);
            gc_at = (1 << 20).max(4 * gr.a.len());
        }
    }
    stats.peak_nodes = stats.peak_nodes.max(gr.a.len());
    (Found::Bounded { steps: max_steps }, stats)
}

/// The AND gates, each after its fanins (ASCII AIGER allows any order;
/// a gate read before it is computed would take a stale value).
fn in_dependency_order(g: &Aig) -> Vec<(u32, u32, u32)> {
    let index: HashMap<u32, usize> = g
        .ands
        .iter()
        .enumerate()
        .map(|(i, &(l, _, _))| (l >> 1, i))
        .collect();
    // 0 new, 1 being expanded, 2 placed
    let mut state = vec![0u8; g.ands.len()];
    let mut out = Vec::with_capacity(g.ands.len());
    for i in 0..g.ands.len() {
        let mut stack = vec![(i, false)];
        while let Some((k, expanded)) = stack.pop() {
            if expanded {
                state[k] = 2;
                out.push(g.ands[k]);
                continue;
            }
            if state[k] != 0 {
                continue;
            }
            state[k] = 1;
            stack.push((k, true));
            let (_, x, y) = g.ands[k];
            for f in [x, y] {
                if let Some(&j) = index.get(&(f >> 1)) {
                    if state[j] == 0 {
                        stack.push((j, false));
                    }
                }
            }
        }
    }
    out
}

fn canonical_state(gr: &Graph, state: &[u32], step: u64) -> Vec<u64> {
    gr.canonical(state, step as u32)
}

/// The latches whose value at `step` is not their value a period earlier
/// (up to the renaming of the inputs).
fn kept(gr: &Graph, before: &[u32], now: &[u32], step: u64, period: u64) -> Vec<usize> {
    (0..now.len())
        .filter(|&j| {
            before.get(j).is_none_or(|&b| {
                gr.canonical(&[b], (step - period) as u32) != gr.canonical(&[now[j]], step as u32)
            })
        })
        .collect()
}

fn live_nodes(gr: &Graph, state: &[u32]) -> usize {
    let mut seen = std::collections::HashSet::new();
    let mut stack: Vec<usize> = state.iter().map(|&r| (r >> 1) as usize).collect();
    while let Some(n) = stack.pop() {
        if n == 0 || !seen.insert(n) {
            continue;
        }
        if !gr.is_var(n) {
            stack.push((gr.a[n] >> 1) as usize);
            stack.push((gr.b[n] >> 1) as usize);
        }
    }
    seen.len()
}

/// An ABC-style AIGER witness (`write_cex -a`): what `engine::witness_miso`
/// and the replay read.
pub fn witness_text(g: &Aig, inputs: &[Vec<bool>]) -> String {
    let bit = |b: &bool| if *b { '1' } else { '0' };
    let ni = g.inputs.len();
    let mut s = String::from("1\nb0\n");
    let init = inputs.first().map_or(&[][..], |i| &i[ni.min(i.len())..]);
    s.extend((0..g.latches.len()).map(|j| init.get(j).map_or('0', bit)));
    s.push('\n');
    for step in inputs {
        s.extend(step[..ni.min(step.len())].iter().map(bit));
        s.push('\n');
    }
    s.push_str(".\n");
    s
}

#[cfg(test)]
mod tests;

/// A soundness review of the engine: small hand-made designs whose truth is
/// known (an explicit-state search over every power-on value and input), and
/// every witness replayed on a concrete simulator written here, independent
/// of the engine.  A test that shows a defect is `#[ignore = "BUG: ..."]`.
#[cfg(test)]
mod adversarial;
