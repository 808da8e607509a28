//! One clock step of the AIG on the graph, evaluating only the gates whose
//! fanins changed since the step before (event-driven).
//!
//! Why: once the reset has passed, nearly every gate's value is a constant
//! that stays the same from one cycle to the next (a slot's decoded fields,
//! the mode's tables, the upper bits of every counter); only the gates
//! downstream of what changed (a counter's low bits, MISO's fresh variable
//! of the step, the shift registers) need a new value.  Evaluating those
//! alone, level by level in the gates' order, gives every gate the value a
//! full evaluation would (a gate none of whose fanins changed keeps its
//! value, the graph being hash-consed), at a fraction of the work.

use crate::aiger::Aig;

use super::graph::Graph;

/// Each gate's value (`val`, by AIGER variable) and what reads what.
pub(super) struct Eval {
    /// The AND gates, each after its fanins.
    ands: Vec<(u32, u32, u32)>,
    /// Per AIGER variable: the gates (index in `ands`) that read it.
    fanout: Vec<Vec<u32>>,
    /// Per gate: one more than its deepest fanin gate's level.
    level: Vec<u32>,
    /// Gates waiting, by level, and whether each is waiting.
    buckets: Vec<Vec<u32>>,
    queued: Vec<bool>,
    /// Each variable's literal in the graph after the last step.
    val: Vec<u32>,
    /// Whether `val` holds the last step's values (false at the start and
    /// after the graph was collected, which renumbers its nodes).
    valid: bool,
}

impl Eval {
    pub(super) fn new(g: &Aig) -> Eval {
        let ands = super::in_dependency_order(g);
        let nv = g.max_var as usize + 1;
        let mut fanout = vec![Vec::new(); nv];
        let mut var_level = vec![0u32; nv];
        let mut level = Vec::with_capacity(ands.len());
        for (i, &(lhs, x, y)) in ands.iter().enumerate() {
            let (xv, yv) = ((x >> 1) as usize, (y >> 1) as usize);
            fanout[xv].push(i as u32);
            if yv != xv {
                fanout[yv].push(i as u32);
            }
            let l = var_level[xv].max(var_level[yv]) + 1;
            var_level[(lhs >> 1) as usize] = l;
            level.push(l);
        }
        let depth = level.iter().copied().max().unwrap_or(0) as usize + 1;
        Eval {
            queued: vec![false; ands.len()],
            ands,
            fanout,
            level,
            buckets: vec![Vec::new(); depth],
            val: vec![0u32; nv],
            valid: false,
        }
    }

    /// The graph was collected: every value is evaluated again next step.
    pub(super) fn invalidate(&mut self) {
        self.valid = false;
    }

    /// One step: input `k` takes `inputs[k]`, every latch starts from
    /// `state` and leaves it with its next value; returns the disjunction
    /// of the assertions.
    pub(super) fn step(
        &mut self,
        g: &Aig,
        gr: &mut Graph,
        state: &mut [u32],
        inputs: &[u32],
    ) -> u32 {
        if self.valid {
            self.changed(g, gr, state, inputs);
        } else {
            self.full(g, gr, state, inputs);
        }
        let val = &self.val;
        let lit = |l: u32| val[(l >> 1) as usize] ^ (l & 1);
        let mut bad = 0u32;
        for &b in &g.bad {
            bad = gr.and(bad ^ 1, lit(b) ^ 1) ^ 1;
        }
        for (j, &(_, next, _)) in g.latches.iter().enumerate() {
            state[j] = lit(next);
        }
        bad
    }

    /// Every gate evaluated.
    fn full(&mut self, g: &Aig, gr: &mut Graph, state: &[u32], inputs: &[u32]) {
        let val = &mut self.val;
        for (&i, &lit) in g.inputs.iter().zip(inputs) {
            val[(i >> 1) as usize] = lit;
        }
        for (j, &(l, _, _)) in g.latches.iter().enumerate() {
            val[(l >> 1) as usize] = state[j];
        }
        for &(lhs, x, y) in &self.ands {
            let (x, y) = (
                val[(x >> 1) as usize] ^ (x & 1),
                val[(y >> 1) as usize] ^ (y & 1),
            );
            val[(lhs >> 1) as usize] = gr.and(x, y);
        }
        self.valid = true;
    }

    /// The gates downstream of an input or latch whose value changed.
    fn changed(&mut self, g: &Aig, gr: &mut Graph, state: &[u32], inputs: &[u32]) {
        let mut top = 0usize;
        let sources = g.inputs.iter().zip(inputs.iter().copied());
        let latches = g.latches.iter().map(|l| l.0).zip(state.iter().copied());
        for (l, lit) in sources.map(|(&i, v)| (i, v)).chain(latches) {
            let v = (l >> 1) as usize;
            if self.val[v] != lit {
                self.val[v] = lit;
                top = top.max(self.touch(v));
            }
        }
        let mut lv = 0;
        while lv <= top && lv < self.buckets.len() {
            let mut bucket = std::mem::take(&mut self.buckets[lv]);
            for &i in &bucket {
                self.queued[i as usize] = false;
                let (lhs, x, y) = self.ands[i as usize];
                let val = &self.val;
                let (x, y) = (
                    val[(x >> 1) as usize] ^ (x & 1),
                    val[(y >> 1) as usize] ^ (y & 1),
                );
                let now = gr.and(x, y);
                let v = (lhs >> 1) as usize;
                if self.val[v] != now {
                    self.val[v] = now;
                    top = top.max(self.touch(v));
                }
            }
            bucket.clear();
            self.buckets[lv] = bucket;
            lv += 1;
        }
    }

    /// Queues the gates that read variable `v`; the highest level queued.
    fn touch(&mut self, v: usize) -> usize {
        let mut top = 0;
        for &i in &self.fanout[v] {
            let i = i as usize;
            let l = self.level[i] as usize;
            top = top.max(l);
            if !self.queued[i] {
                self.queued[i] = true;
                self.buckets[l].push(i as u32);
            }
        }
        top
    }
}
