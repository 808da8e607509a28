//! k-induction's step case on the AIG, by SAT over the symbolic graph.
//!
//! A property that holds in `k` consecutive steps from *any* state (every
//! latch a free variable) and then fails is a SAT problem over `k + 1`
//! steps; if it has no solution and no violation is reachable in the first
//! `k` steps from reset (the base case, a bounded search from reset), the
//! property holds in every reachable state.  A relation a harness keeps
//! between its registers and the design's one step earlier (AXI4-Stream's
//! "a waiting beat keeps its data") is inductive on its own, whatever the
//! rest of the state.

use super::eval::Eval;
use super::evaluate;
use super::graph::Graph;
use crate::aiger::Aig;

/// Whether the assertions are `k`-inductive: `Ok(true)` if no path of
/// `k + 1` steps from any state has them hold in its first `k` steps and
/// fail in the last; `Err` if the solver gave no answer.
pub fn step_case(g: &Aig, k: u64) -> Result<bool, String> {
    let mut gr = Graph::new();
    let ni = g.inputs.len() as u32;
    let mut state: Vec<u32> = (0..g.latches.len())
        .map(|j| gr.var(ni + j as u32, 0))
        .collect();
    let mut ev = Eval::new(g);
    let mut held = 1u32;
    for step in 0..k {
        let bad = evaluate(g, &mut ev, &mut gr, &mut state, step + 1);
        held = gr.and(held, bad ^ 1);
    }
    let bad = evaluate(g, &mut ev, &mut gr, &mut state, k + 1);
    let fails = gr.and(held, bad);
    Ok(gr.satisfy(fails, None)?.is_none())
}
