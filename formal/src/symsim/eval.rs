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
//!
//! Two more cuts, both exact.  A gate whose other fanin is false when one
//! changes stays false: it is not queued (were the other to change later in
//! the step, that change queues it; a gate left unqueued by every change
//! was false before and after).  And the latches: a step given the state
//! the step before left (the usual case, compared as one slice) starts
//! from the latches that moved in it, and writes only the latches whose
//! next value's variable changed; any other state is read whole.  An input
//! that only a latch's literal lets through, that literal false in the
//! state (yosys's power-on inputs once reset has passed), takes false and
//! no variable (`quiet`).

use crate::aiger::Aig;

use super::graph::Graph;

/// Each gate's value (`val`, by AIGER variable) and what reads what.
pub(super) struct Eval {
    /// The AND gates, each after its fanins.
    ands: Vec<(u32, u32, u32)>,
    /// Per AIGER variable `v`, `fan[fan_at[v]..fan_at[v + 1]]`: the gates
    /// (index in `ands`) that read it, each with its other fanin (the
    /// constant true when both read `v`: never skipped).
    fan_at: Vec<u32>,
    fan: Vec<(u32, u32)>,
    /// Per AIGER variable, `feeds[feeds_at[v]..feeds_at[v + 1]]`: the
    /// latches whose next value it is.
    feeds_at: Vec<u32>,
    feeds: Vec<u32>,
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
    /// The state the last step left, and the latches whose value in it
    /// differs from the state it was given.
    out: Vec<u32>,
    moved: Vec<u32>,
    /// The latches whose next value's variable changed in this step.
    dirty: Vec<u32>,
    /// A buffer for a step's input literals, reused step after step.
    inputs: Vec<u32>,
    /// Inputs whose value cannot matter while a latch holds a constant:
    /// (input index, latch index, the latch's value that gates it off).
    /// yosys's `write_aiger -zinit` reads each uninitialised register's
    /// power-on value from an input of its own, through `AND(input,
    /// initstate)` alone, false from step 1 on: 40 of eskin34-adaptive's
    /// 44 inputs.  A fresh variable for each of them every step was about
    /// a sixth of its run (making the nodes, collecting them).
    gated: Vec<(u32, u32, u32)>,
    /// `quiet`'s buffer, reused step after step.
    quiet: Vec<bool>,
}

/// Per variable, the items `of` lists for it, as one flat array and each
/// variable's start in it (`at[v]..at[v + 1]`).
fn flat<T: Copy + Default>(
    nv: usize,
    of: impl Iterator<Item = (usize, T)> + Clone,
) -> (Vec<u32>, Vec<T>) {
    let mut at = vec![0u32; nv + 1];
    for (v, _) in of.clone() {
        at[v + 1] += 1;
    }
    for v in 0..nv {
        at[v + 1] += at[v];
    }
    let mut next = at.clone();
    let mut items = vec![T::default(); at[nv] as usize];
    for (v, t) in of {
        items[next[v] as usize] = t;
        next[v] += 1;
    }
    (at, items)
}

/// The inputs that every reader ANDs with one literal of one latch, and
/// nothing else reads (no latch's next value, no assertion): with that
/// literal false the input's value cannot reach anything.
fn gated_inputs(
    g: &Aig,
    fan_at: &[u32],
    fan: &[(u32, u32)],
    feeds_at: &[u32],
) -> Vec<(u32, u32, u32)> {
    let latch_of: std::collections::HashMap<u32, u32> = (g.latches.iter().enumerate())
        .map(|(j, &(l, _, _))| (l >> 1, j as u32))
        .collect();
    let watched: std::collections::HashSet<u32> = (g.bad.iter().chain(&g.constraints))
        .map(|&b| b >> 1)
        .collect();
    let mut out = Vec::new();
    for (k, &i) in g.inputs.iter().enumerate() {
        let v = (i >> 1) as usize;
        if feeds_at[v] != feeds_at[v + 1] || watched.contains(&(i >> 1)) {
            continue;
        }
        let readers = &fan[fan_at[v] as usize..fan_at[v + 1] as usize];
        let Some(&(_, other)) = readers.first() else {
            continue;
        };
        let Some(&j) = latch_of.get(&(other >> 1)) else {
            continue;
        };
        if readers.iter().all(|&(_, o)| o == other) {
            out.push((k as u32, j, other & 1));
        }
    }
    out
}

impl Eval {
    pub(super) fn new(g: &Aig) -> Eval {
        let ands = super::in_dependency_order(g);
        let nv = g.max_var as usize + 1;
        let mut var_level = vec![0u32; nv];
        let mut level = Vec::with_capacity(ands.len());
        for &(lhs, x, y) in &ands {
            let (xv, yv) = ((x >> 1) as usize, (y >> 1) as usize);
            let l = var_level[xv].max(var_level[yv]) + 1;
            var_level[(lhs >> 1) as usize] = l;
            level.push(l);
        }
        let reads = ands.iter().enumerate().flat_map(|(i, &(_, x, y))| {
            let i = i as u32;
            let both = (x >> 1) == (y >> 1);
            let first = ((x >> 1) as usize, (i, if both { 1 } else { y }));
            let second = (!both).then_some(((y >> 1) as usize, (i, x)));
            std::iter::once(first).chain(second)
        });
        let (fan_at, fan) = flat(nv, reads);
        let nexts = (g.latches.iter().enumerate())
            .map(|(j, &(_, next, _))| ((next >> 1) as usize, j as u32));
        let (feeds_at, feeds) = flat(nv, nexts);
        let depth = level.iter().copied().max().unwrap_or(0) as usize + 1;
        let gated = gated_inputs(g, &fan_at, &fan, &feeds_at);
        Eval {
            queued: vec![false; ands.len()],
            ands,
            fan_at,
            fan,
            feeds_at,
            feeds,
            level,
            buckets: vec![Vec::new(); depth],
            val: vec![0u32; nv],
            valid: false,
            out: Vec::new(),
            moved: Vec::new(),
            dirty: Vec::new(),
            inputs: Vec::new(),
            gated,
            quiet: Vec::new(),
        }
    }

    #[cfg(test)]
    pub(super) fn gates_inputs(&self) -> bool {
        !self.gated.is_empty()
    }

    /// Per input, whether it is gated off in `state` (`gated`): it takes
    /// the constant false rather than a variable, an exact step whatever
    /// its value.  Empty when none is.
    pub(super) fn quiet(&mut self, state: &[u32], n: usize) -> &[bool] {
        self.quiet.clear();
        for &(k, j, off) in &self.gated {
            if state[j as usize] == off {
                self.quiet.resize(n, false);
                self.quiet[k as usize] = true;
            }
        }
        &self.quiet
    }

    /// The graph was collected: every value is evaluated again next step.
    pub(super) fn invalidate(&mut self) {
        self.valid = false;
    }

    /// The input buffer (empty or last step's), to be given back.
    pub(super) fn take_inputs(&mut self) -> Vec<u32> {
        std::mem::take(&mut self.inputs)
    }

    pub(super) fn give_inputs(&mut self, inputs: Vec<u32>) {
        self.inputs = inputs;
    }

    /// The latches whose value the last step changed (its next value is
    /// not the value it was given), in no particular order.
    pub(super) fn moved(&self) -> &[u32] {
        &self.moved
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
        self.dirty.clear();
        // the state the last step left: only the latches it moved differ
        let again = self.valid && *state == *self.out;
        if self.valid {
            self.changed(g, gr, state, inputs, again);
        } else {
            self.full(g, gr, state, inputs);
        }
        let val = &self.val;
        let lit = |l: u32| val[(l >> 1) as usize] ^ (l & 1);
        let mut bad = 0u32;
        for &b in &g.bad {
            bad = gr.and(bad ^ 1, lit(b) ^ 1) ^ 1;
        }
        self.moved.clear();
        if again {
            // every other latch's next value is the last step's, which is
            // the value it has
            for &j in &self.dirty {
                let (l, next, _) = g.latches[j as usize];
                let now = lit(next);
                state[j as usize] = now;
                self.out[j as usize] = now;
                if now != val[(l >> 1) as usize] {
                    self.moved.push(j);
                }
            }
            // in the latches' order, as a whole state's scan gives them:
            // the next step touches their readers in that order
            self.moved.sort_unstable();
        } else {
            for (j, &(l, next, _)) in g.latches.iter().enumerate() {
                state[j] = lit(next);
                if state[j] != val[(l >> 1) as usize] {
                    self.moved.push(j as u32);
                }
            }
            self.out.clear();
            self.out.extend_from_slice(state);
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

    /// The gates downstream of an input or latch whose value changed;
    /// `again`: the state is the one the last step left, so only the
    /// latches it moved can differ.
    fn changed(&mut self, g: &Aig, gr: &mut Graph, state: &[u32], inputs: &[u32], again: bool) {
        let mut top = 0usize;
        for (&i, &lit) in g.inputs.iter().zip(inputs) {
            top = top.max(self.set((i >> 1) as usize, lit));
        }
        if again {
            for k in 0..self.moved.len() {
                let j = self.moved[k] as usize;
                top = top.max(self.set((g.latches[j].0 >> 1) as usize, state[j]));
            }
        } else {
            for (j, &(l, _, _)) in g.latches.iter().enumerate() {
                top = top.max(self.set((l >> 1) as usize, state[j]));
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
                top = top.max(self.set((lhs >> 1) as usize, now));
            }
            bucket.clear();
            self.buckets[lv] = bucket;
            lv += 1;
        }
    }

    /// Variable `v` takes `lit`: if that is a change, the gates that read
    /// it are queued and the latches it feeds noted; the highest level
    /// queued (0 if none).
    #[inline]
    fn set(&mut self, v: usize, lit: u32) -> usize {
        if self.val[v] == lit {
            return 0;
        }
        self.val[v] = lit;
        let feeds = self.feeds_at[v] as usize..self.feeds_at[v + 1] as usize;
        if !feeds.is_empty() {
            self.dirty.extend_from_slice(&self.feeds[feeds]);
        }
        self.touch(v)
    }

    /// Queues the gates that read variable `v` and may change (not those
    /// whose other fanin is false); the highest level queued.
    fn touch(&mut self, v: usize) -> usize {
        let mut top = 0;
        let fan = self.fan_at[v] as usize..self.fan_at[v + 1] as usize;
        for &(i, other) in &self.fan[fan] {
            if self.val[(other >> 1) as usize] ^ (other & 1) == 0 {
                continue;
            }
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
