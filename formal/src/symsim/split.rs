//! A run split on a few inputs: requests such as pin-selected modes'
//! `mode_sel`, which a design keeps for as long as it likes.
//!
//! Why: a request that names no mode keeps the mode decided before, so the
//! mode register's value is a function of every earlier request (a chain of
//! `sel valid ? sel : older`) that grows a frame at a time: the state never
//! recurs, and each SAT check has to equate the harness's chain with the
//! design's.  But the mode takes a few values only.  So in a step whose
//! next state (or assertion) reads a split input's variable of that step,
//! the step is simulated once per value of the split inputs, each a path of
//! its own with those values fixed (equal successors kept once); on every
//! path the mode registers are constants again, and everything folds as for
//! one mode.
//!
//! Soundness: the states reachable at a step are the union, over the values
//! of the split inputs, of the states each path reaches (every value is
//! taken), so nothing is left out and nothing is added.  A path's state at
//! a frame boundary that is, up to renaming, a state some path reached at
//! an earlier or the same boundary adds no new state (the argument of
//! `mod.rs`, per path: its successors are the earlier state's).  Any
//! one-to-one renaming of the variables will do, not only a shift by whole
//! frames (`Graph::canonical_any`): each is a free bit of its own, so both
//! states stand for the same values, and a mode that leaves a branch idle
//! keeps its last data for any number of frames; when every
//! path has ended so, every reachable state was simulated, each step
//! checked exactly: proved for all time.  A violation on a path is a real
//! trace: the values fixed on the path and the SAT model of the rest.
//!
//! Subsumed paths: an AXI4-Stream slave may take a beat in any cycle and
//! must by the `ready_within`-th (`tready = tready_any || waited >= n`, the
//! harness's slave).  Two paths at one step whose states differ only in
//! the constant count `waited`: any choices from the higher count are
//! choices from the lower one too (the counts step alike, the lower stays
//! lower, so a `tready` low that the higher allows the lower allows), and
//! nothing else reads the count, so the lower one's futures include the
//! other's, violations and all.  Paths are taken lowest count first at
//! each step, and the first in a state but for the count is kept alone.
//! Why: a burst made a path per (bytes taken, cycles waited); eskin34-axis
//! (`ready_within` 64) did not finish in 32 minutes with the bytes
//! asserted, and finishes in 8 with this.

use std::collections::HashMap;

use super::graph::Assigned;
use super::{kept, Found, Limits, Sim, SymStats, CHECK};

/// At most this many split input bits (2^n values in a step that reads
/// them); a design with more is simulated with them as variables.
pub(super) const MAX_SPLIT_BITS: usize = 8;

/// At most this many states at boundaries and paths waiting: past it the
/// run stops, bounded (a mode mix has a state per pair of modes and data).
pub const MAX_PATHS: usize = 4096;

/// The paths started at one step: (step, graph collections, each one's
/// state and condition, the wait count left out, with that count).
type Started = (u64, u64, HashMap<Vec<u32>, Option<u64>>);

/// At most this many states kept of paths started between frame starts
/// (`started_before`): past it, such paths run to the frame start.
const MAX_MID: usize = 1 << 14;

/// A path waiting at the step it continues from.
pub(super) struct Branch {
    pub(super) state: Vec<u32>,
    /// Its state at the last boundary (for `kept`).
    pub(super) prev_state: Vec<u32>,
    pub(super) fixed: Vec<Assigned>,
    /// Its condition (`cases.rs`): conjuncts its states satisfy.
    pub(super) cond: Vec<u32>,
    /// Its generalisations of the counters (`generalise.rs`).
    pub(super) pin: super::generalise::Pin,
}

impl Sim<'_> {
    /// Runs every path to a boundary whose state was seen, a violation,
    /// `lim.max_steps` or the deadline; paths are taken by their step, so a
    /// bound covers every path to it.
    pub(super) fn run_split(mut self, lim: &Limits) -> (Found, SymStats) {
        self.deadline = lim.deadline;
        let mut seen: HashMap<Vec<u64>, u64> = HashMap::new();
        // the paths a split started between frame starts (`started_before`)
        let mut mid: HashMap<Vec<u64>, u64> = HashMap::new();
        let (mut seq, mut closed, mut ended) = (0u64, None, false);
        let start = Branch {
            state: std::mem::take(&mut self.state),
            prev_state: Vec::new(),
            fixed: Vec::new(),
            cond: Vec::new(),
            pin: std::mem::take(&mut self.pin),
        };
        self.queue.insert((0, 0, 0), start);
        // the earliest violation so far: later paths stop before it
        let mut first: Option<(u64, Found)> = None;
        // the paths started at one step (by their state): paths are taken
        // by their step, so a path whose state one of them had is the same
        // machine in the same state and adds nothing (any of their inputs
        // is a trace to it), with the slave's wait count, if any (a path
        // whose count is higher is subsumed); cleared when the graph is
        // collected
        let mut started: Started = (u64::MAX, 0, HashMap::new());
        while let Some(((from, _, _), b)) = self.queue.pop_first() {
            let stop = first.as_ref().map_or(lim.max_steps, |f| f.0);
            if from >= stop && first.is_some() {
                continue; // at or past the earliest violation
            }
            if (started.0, started.1) != (from, self.collections) {
                started = (from, self.collections, HashMap::new());
            }
            let (key, count) = (self.merge_key(&b), self.wait_count(&b.state));
            if let Some(&first) = started.2.get(&key) {
                match first == count {
                    true => self.stats.merged += 1,
                    false => self.stats.subsumed += 1,
                }
                continue;
            }
            started.2.insert(key, count);
            if from >= stop {
                // a path that reached the last step: nothing is said beyond
                self.stats.branches = seen.len();
                return (Found::Bounded { steps: from }, self.stats);
            }
            if seen.len() + self.queue.len() > MAX_PATHS {
                self.stats.branches = seen.len();
                let steps = self.covered(from);
                self.stats.path_limit = Some(steps);
                return (first.map_or(Found::Bounded { steps }, |f| f.1), self.stats);
            }
            (self.state, self.prev_state, self.fixed) = (b.state, b.prev_state, b.fixed);
            self.cond = b.cond;
            self.pin = b.pin;
            self.holding = !self.held_requests().is_empty();
            self.pending.clear();
            self.pending_any = 0;
            if self.started_before(from, lim, &mut mid) {
                // by the next frame start it is closed as a recurrence there
                let next = from + (lim.period - (from - lim.offset) % lim.period);
                closed = closed.max(Some(next));
                continue;
            }
            let path_lim = Limits {
                max_steps: stop,
                ..*lim
            };
            match self.run_path(from, &path_lim, &mut seen) {
                Ok(Path::Closed(step)) => closed = closed.max(Some(step)),
                // the others, waiting at earlier steps, go on to it too
                Ok(Path::End) => ended = true,
                Ok(Path::Split(step, children)) => {
                    for c in children {
                        seq += 1;
                        let order = self.wait_count(&c.state).unwrap_or(u64::MAX);
                        self.queue.insert((step, order, seq), c);
                    }
                }
                Err(Found::Violated { step, inputs }) => {
                    first = Some((step, Found::Violated { step, inputs }));
                }
                // the search stopped at the earliest violation's step
                Err(Found::Bounded { .. }) if first.is_some() && stop < lim.max_steps => {}
                Err(found) => {
                    self.stats.branches = seen.len();
                    return (first.map_or(found, |f| f.1), self.stats);
                }
            }
        }
        self.stats.branches = seen.len();
        if let Some((_, f)) = first {
            return (f, self.stats);
        }
        if ended {
            // every path reached the last step or closed before it
            let steps = lim.max_steps;
            return (Found::Bounded { steps }, self.stats);
        }
        let steps = closed.unwrap_or(lim.offset);
        (
            Found::Proved {
                steps,
                since: lim.offset,
            },
            self.stats,
        )
    }

    /// Whether this path, started by a split at `from` between frame starts
    /// (no assertion pending: a split checks them first), is in a state
    /// and condition, up to renaming, that a path started in at the same
    /// phase of a frame at `from` or before: then its futures are that
    /// one's (the machine is the same; frame starts, where counters are
    /// generalised and cases split, fall at the same phases), as a frame
    /// start's recurrence closes a path, but up to a frame sooner.
    fn started_before(
        &mut self,
        from: u64,
        lim: &Limits,
        mid: &mut HashMap<Vec<u64>, u64>,
    ) -> bool {
        let phase = from.checked_sub(lim.offset).map(|p| p % lim.period);
        if phase.is_none_or(|p| p == 0) || mid.len() >= MAX_MID {
            return false;
        }
        // a slave's choices start paths at every step of a burst: a
        // canonical form for each costs more than the frames it saves
        // (modes-pin with an AXI4-Stream: 6.7 -> 10.2 s)
        if self.counters.as_ref().is_some_and(|c| !c.wait.is_empty()) {
            return false;
        }
        let mut roots = self.state.clone();
        if !self.cond.is_empty() {
            roots.push(self.cond_lit());
        }
        let now = self.gr.canonical_any(&roots);
        if mid
            .get(&now)
            .is_some_and(|&at| at <= from && (from - at).is_multiple_of(lim.period))
        {
            self.stats.mid_closed += 1;
            return true;
        }
        mid.entry(now).or_insert(from);
        false
    }

    /// The slave's wait count in `state`, when every bit of it is a
    /// constant there.
    fn wait_count(&self, state: &[u32]) -> Option<u64> {
        let wait = &self.counters.as_ref()?.wait;
        if wait.is_empty() {
            return None;
        }
        wait.iter()
            .enumerate()
            .try_fold(0u64, |a, (b, &j)| match state[j] {
                0 => Some(a),
                1 => Some(a | 1 << b),
                _ => None,
            })
    }

    /// What a path started at a step is merged on: its state and
    /// condition, the slave's wait count left out when it is a constant
    /// (the paths are taken lowest count first, and the first subsumes).
    fn merge_key(&self, b: &Branch) -> Vec<u32> {
        let mut key: Vec<u32> = b.state.iter().chain(&b.cond).copied().collect();
        if self.wait_count(&b.state).is_some() {
            for &j in &self.counters.as_ref().expect("a wait count").wait {
                key[j] = 0;
            }
        }
        key
    }

    /// The steps every path has been simulated to: `step` on this one, the
    /// first waiting path's start on the others.
    fn covered(&self, step: u64) -> u64 {
        self.queue
            .first_key_value()
            .map_or(step, |(k, _)| k.0.min(step))
    }

    /// This path from `from` until it closes at a boundary or splits.
    fn run_path(
        &mut self,
        from: u64,
        lim: &Limits,
        seen: &mut HashMap<Vec<u64>, u64>,
    ) -> Result<Path, Found> {
        for step in from..lim.max_steps {
            let phase = step.checked_sub(lim.offset).map(|p| p % lim.period);
            if phase.is_some_and(|p| p % CHECK == 0) {
                if let Some(f) = self.check_pending() {
                    return Err(self.bounded_at(f));
                }
            }
            if phase == Some(0) {
                // the frame counters, once shown equal, become one free
                // value (`generalise.rs`): on every path alike
                // a bound here, not past a path waiting at an earlier step
                // (it may still find a violation before this one)
                if let Err(f) = self.generalise(step) {
                    return Err(self.bounded_at(f));
                }
                if self.split_cases {
                    self.prune_cond(step)?;
                }
                let mut roots = self.state.clone();
                if !self.cond.is_empty() {
                    // the path's condition is part of its set of states
                    roots.push(self.cond_lit());
                }
                let now = self.gr.canonical_any(&roots);
                // a state seen at this step or before: its successors are
                // covered (one seen later may hide an earlier violation)
                if seen.get(&now).is_some_and(|&at| at <= step) {
                    return Ok(Path::Closed(step));
                }
                if step > lim.offset && !self.prev_state.is_empty() {
                    self.stats.kept =
                        kept(&self.gr, &self.prev_state, &self.state, step, lim.period);
                }
                seen.insert(now, step);
                // auto select's decisions: one path per value of the
                // registers that are functions of the codes (each compared
                // at this step in turn, with the last boundary's state)
                if self.split_cases {
                    if let Some(children) = self.split_cases(step)? {
                        return Ok(Path::Split(step, children));
                    }
                }
                self.prev_state.clone_from(&self.state);
            }
            if step.is_multiple_of(256) && lim.deadline.is_some_and(|d| Instant::now() > d) {
                let found = self.check_pending();
                let steps = self.covered(step);
                return Err(self.bounded_at(found.unwrap_or(Found::Bounded { steps })));
            }
            if let Some(children) = self.step_split(step)? {
                return Ok(Path::Split(step + 1, children));
            }
            self.collect_if_large();
        }
        match self.check_pending() {
            Some(f) => Err(self.bounded_at(f)),
            None => Ok(Path::End),
        }
    }

    /// A bound of this path as a bound of the run (no further than every
    /// waiting path got).
    pub(super) fn bounded_at(&self, f: Found) -> Found {
        match f {
            Found::Bounded { steps } => Found::Bounded {
                steps: self.covered(steps),
            },
            other => other,
        }
    }

    /// One step; `Some(paths)` when its successor reads a split input of
    /// the step: one path per value of the split inputs (equal successors
    /// once), the step's assertion checked on each.
    fn step_split(&mut self, step: u64) -> Result<Option<Vec<Branch>>, Found> {
        if self.splits.is_empty() {
            // split on registers only (`cases.rs`), at frame starts
            self.step(step);
            return Ok(None);
        }
        let (g, ni) = (self.g, self.g.inputs.len());
        let mark = self.gr.a.len();
        // the split inputs' variables first: a node older than them reads none
        let mut vars = [0usize; MAX_SPLIT_BITS];
        for (i, &k) in self.splits.iter().enumerate() {
            vars[i] = (self.gr.fresh_var(k as u32, step as u32) >> 1) as usize;
        }
        let vars = &vars[..self.splits.len()];
        let mut inputs = self.ev.take_inputs();
        let quiet = self.ev.quiet(&self.state, ni);
        self.gr
            .step_vars(ni as u32, step as u32, quiet, &mut inputs);
        for (&k, &n) in self.splits.iter().zip(vars) {
            inputs[k] = n as u32 * 2;
        }
        // the next state in a buffer of its own (the state is kept for a
        // split), reused step after step
        let mut next = std::mem::take(&mut self.next);
        next.clear();
        next.extend_from_slice(&self.state);
        let bad = self.ev.step(g, &mut self.gr, &mut next, &inputs);
        // a latch that did not move holds an older node than the variables
        let roots = (self.ev.moved().iter()).map(|&j| next[j as usize]);
        let read = reads(&self.gr, roots.chain([bad]), mark, vars);
        if !((read || self.holding) && self.computes(&next, bad, read)) {
            // nothing computes with a split input: a request only copied
            // into registers is held as its variable (`defer.rs`)
            self.holding |= read;
            if read {
                self.share_held(&mut next, step, vars);
            }
            std::mem::swap(&mut self.state, &mut next);
            self.next = next;
            self.ev.give_inputs(inputs);
            if bad != 0 {
                self.pending.push((step, bad));
                self.pending_any = self.gr.and(self.pending_any ^ 1, bad ^ 1) ^ 1;
            }
            return Ok(None);
        }
        // the steps before are checked first, so that the paths start clean
        if let Some(f) = self.check_pending() {
            return Err(self.bounded_at(f));
        }
        // the split variables the step computes with (this step's and held
        // ones): one path per value of them, each with the held ones
        // replaced in its state; the others stay held
        let need = self.needed(&next, bad);
        let held: Vec<usize> = (self.held_requests().into_iter())
            .filter(|n| need.contains(n))
            .collect();
        let now: Vec<usize> = (self.splits.iter().copied())
            .filter(|&k| need.contains(&((inputs[k] >> 1) as usize)))
            .collect();
        let ns = now.len();
        let mut paths: Vec<Branch> = Vec::new();
        for a in 0u32..1 << (ns + held.len()) {
            let mut fixed = self.fixed.clone();
            for (i, &k) in now.iter().enumerate() {
                inputs[k] = (a >> i) & 1;
                fixed.push((k as u32, step as u32, (a >> i) & 1 == 1));
            }
            let fix: Vec<(usize, bool)> = (held.iter().enumerate())
                .map(|(i, &n)| (n, (a >> (ns + i)) & 1 == 1))
                .collect();
            for &(n, v) in &fix {
                let input = self.gr.a[n] & !super::graph::VAR;
                fixed.push((input, self.gr.b[n], v));
            }
            let (mut next, cond, pin) = self.fixed_at(&fix);
            let bad = self.ev.step(g, &mut self.gr, &mut next, &inputs);
            // the split inputs not fixed here are at most copied (`needed`)
            self.share_held(&mut next, step, vars);
            let bad = match bad {
                0 => 0,
                // never true by its affine forms: so under the condition
                // too (`satisfy` would not see it through the condition)
                _ if !cond.is_empty() && super::affine::never_true(&self.gr, bad) => 0,
                _ => {
                    let all = (cond.iter()).fold(1, |all, &c| self.gr.and(all, c));
                    self.gr.and(bad, all)
                }
            };
            if bad != 0 {
                self.stats.sat_calls += 1;
                let limit = (self.deadline).map(|d| d.saturating_duration_since(Instant::now()));
                match self.gr.satisfy(bad, limit) {
                    Ok(None) => {}
                    Ok(Some(assign)) => {
                        (self.fixed, self.cond, self.pin) = (fixed, cond, pin);
                        let general = self.generalised_violation(step, bad, &assign);
                        // a bound no further than every waiting path got
                        let found = general.unwrap_or_else(|| self.violation(step, assign));
                        return Err(self.bounded_at(found));
                    }
                    Err(_) => return Err(self.bounded_at(Found::Bounded { steps: step })),
                }
            }
            if paths.iter().all(|p| p.state != next || p.cond != cond) {
                paths.push(Branch {
                    state: next,
                    prev_state: self.prev_state.clone(),
                    fixed,
                    cond,
                    pin,
                });
            }
        }
        Ok(Some(paths))
    }

    /// The step's split variables that `next` holds (in a step that does
    /// not split, or on a path of one that splits on the others), each its own node
    /// (`Graph::fresh_var`: what reads it is found among the nodes made
    /// after it), replaced by the one variable node every path of the run
    /// shares for that input and step (`Graph::var`).  Why: held by two
    /// paths, two nodes of one (input, step) made equal states unequal
    /// literals, and the paths never merged (an AXI4-Stream mix with the
    /// mode decision tied to `mode_sel`: 102 paths in a burst became 4,096
    /// in 14 steps).  Only a copy is held (`defer.rs`), so a latch's literal
    /// is the variable or its complement: a renaming, the state the same.
    fn share_held(&mut self, next: &mut [u32], step: u64, vars: &[usize]) {
        if !self.gr.shared {
            return;
        }
        for (&k, &n) in self.splits.iter().zip(vars) {
            let shared = self.gr.var(k as u32, step as u32);
            for l in next.iter_mut().filter(|l| (**l >> 1) as usize == n) {
                *l = shared ^ (*l & 1);
            }
        }
    }

    /// Whether the next state (a latch whose value changes) or the
    /// assertion computes with a split input's variable (`defer.rs`);
    /// also when holding this step's (`read`) would split on too many bits
    /// at once.
    fn computes(&mut self, next: &[u32], bad: u32, read: bool) -> bool {
        if bad >= 2 && self.reads_split((bad >> 1) as usize) {
            return true;
        }
        // the latches whose value changes: those the step moved
        for k in 0..self.ev.moved().len() {
            let j = self.ev.moved()[k] as usize;
            if self.computes_with_split(next[j]) {
                return true;
            }
        }
        if !read {
            // only a step that reads its split inputs holds more
            return false;
        }
        let mut held: Vec<usize> = (next.iter())
            .map(|&l| (l >> 1) as usize)
            .filter(|&n| n != 0 && self.gr.is_var(n) && self.reads_split(n))
            .collect();
        held.sort_unstable();
        held.dedup();
        held.len() + self.splits.len() > MAX_SPLIT_BITS
    }

    /// The split variables under the latches whose next value computes
    /// with one, and under the assertion if it reads one.
    fn needed(&mut self, next: &[u32], bad: u32) -> Vec<usize> {
        let mut roots: Vec<u32> = (0..next.len())
            .filter(|&j| next[j] != self.state[j] && self.computes_with_split(next[j]))
            .map(|j| next[j])
            .collect();
        roots.push(bad);
        let mut need = self.split_vars_under(&roots);
        if need.is_empty() {
            // more held than `MAX_SPLIT_BITS` allows: all of them
            need = self.split_vars_under(next);
        }
        need
    }

    /// The path's state, condition and pins with the held requests `fix`
    /// replaced by their values.
    fn fixed_at(&mut self, fix: &[(usize, bool)]) -> (Vec<u32>, Vec<u32>, super::generalise::Pin) {
        if fix.is_empty() {
            return (self.state.clone(), self.cond.clone(), self.pin.clone());
        }
        let state = self.cofactor(&self.state.clone(), fix);
        let cond = self.cofactor(&self.cond.clone(), fix);
        let mut pin = self.pin.clone();
        pin.exact = self.cofactor(&pin.exact, fix);
        (state, cond, pin)
    }
}

use std::time::Instant;

/// How a path's simulation ended.
enum Path {
    /// At a boundary (this step) whose state was seen.
    Closed(u64),
    /// Split: the paths continuing from this step.
    Split(u64, Vec<Branch>),
    /// At the run's last step, without a violation.
    End,
}

/// Whether any of `roots` reads a node of `vars`: only nodes made since
/// `mark` can (the variables were made first, and a node's fanins are
/// older than it).
fn reads(
    gr: &super::graph::Graph,
    roots: impl Iterator<Item = u32>,
    mark: usize,
    vars: &[usize],
) -> bool {
    let mut stack: Vec<usize> = (roots.map(|r| (r >> 1) as usize))
        .filter(|&n| n >= mark)
        .collect();
    if stack.is_empty() {
        // no root was made this step: none reads a variable of it
        return false;
    }
    let mut seen = std::collections::HashSet::new();
    while let Some(n) = stack.pop() {
        if n < mark || !seen.insert(n) {
            continue;
        }
        if vars.contains(&n) {
            return true;
        }
        if !gr.is_var(n) {
            stack.push((gr.a[n] >> 1) as usize);
            stack.push((gr.b[n] >> 1) as usize);
        }
    }
    false
}
