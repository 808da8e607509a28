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

mod affine;
mod cases;
mod cone;
mod defer;
mod eval;
mod explicit;
mod generalise;
mod graph;
mod induction;
mod split;
pub use generalise::{CounterFailure, Counters};
use graph::Graph;
#[cfg(test)]
use graph::VAR;
pub use split::MAX_PATHS;

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
pub struct SymStats {
    /// Satisfiability checks of the assertions (a window's disjunction, or
    /// one step of a window that had a violation).
    pub sat_calls: u64,
    /// Largest graph held between collections.
    pub peak_nodes: usize,
    /// Live nodes of the state at the recurrence (its size).
    pub state_nodes: usize,
    /// Without a recurrence: the latches (AIG order) whose value at the
    /// last comparison differed from a period earlier, the state the
    /// design keeps across frames.
    pub kept: Vec<usize>,
    /// With choice inputs (`prove`): the parts of the assertion proved by
    /// symbolic simulation, by 2-induction and by explicit-state search.
    pub parts: [usize; 3],
    /// A run split on requests (`split.rs`): the distinct states at frame
    /// boundaries it simulated from (0: not split).
    pub branches: usize,
    /// A run split on registers' values at frame starts (`cases.rs`): the
    /// paths those splits made.
    pub cases: u64,
    /// A run with generalised counters (`generalise.rs`): the first step
    /// they were generalised at (the exact search from reset ends there).
    pub generalised: Option<u64>,
    /// Why such a run did not close, if it did not.
    pub counter_failure: Option<CounterFailure>,
    /// A split run: paths dropped because another path had reached the
    /// same state at the same step.
    pub merged: u64,
    /// A split run: paths dropped because another path had reached the
    /// same state at the same step but for a lower count of the slave's
    /// wait (`split.rs`: its futures include theirs).
    pub subsumed: u64,
    /// A split run: paths closed where a split started them, in the state
    /// a path had started in at the same phase of an earlier frame.
    pub mid_closed: u64,
    /// A split run that stopped with more states at frame starts and paths
    /// waiting than it keeps (`split::MAX_PATHS`): the step it stopped at.
    pub path_limit: Option<u64>,
}

/// Steps between the checks of the assertions that did not fold (one SAT
/// call on their disjunction), from each period's first step.
const CHECK: u64 = 256;

/// Simulates `g` from power-on (no input split): the state at each step `offset + k *
/// period` is compared (up to renaming) with those of the earlier such
/// steps; the run stops at a recurrence, a failing assertion, `max_steps`
/// or `deadline`.
#[cfg(test)]
pub fn run(
    g: &Aig,
    period: u64,
    offset: u64,
    max_steps: u64,
    deadline: Option<Instant>,
) -> (Found, SymStats) {
    let limits = Limits {
        period,
        offset,
        max_steps,
        deadline,
    };
    Sim::new(g).run(&limits)
}

/// Proves `g`'s assertion part by part when some inputs are an
/// environment's choices (`choices`, input indices) rather than data.
///
/// A part whose cone reads no choice goes to `run` with the other such
/// parts.  A part that reads a choice is tried by k-induction (k <= 2: a
/// harness's one-step relation, "a waiting beat keeps its data", holds
/// whatever the state), with its base case from reset; else by
/// explicit-state search (`explicit`), and if that cannot decide it, by
/// `run`.  Every part holding in every reachable state is the
/// whole assertion holding; a part's violation is the assertion's.
/// `wait`: an AXI4-Stream slave's wait count's latches (`explicit::run`).
#[allow(clippy::too_many_arguments)]
pub fn prove(
    g: &Aig,
    choices: &[usize],
    wait: &[usize],
    splits: &[usize],
    cases: bool,
    period: u64,
    offset: u64,
    max_steps: u64,
    deadline: Option<Instant>,
) -> (Found, SymStats) {
    if choices.is_empty() {
        let lim = Limits {
            period,
            offset,
            max_steps,
            deadline,
        };
        let (f, mut st) = Sim::split_on(g, splits).with_cases(cases).run(&lim);
        st.parts = [1, 0, 0];
        return (f, st);
    }
    let mut g = g.clone();
    let parts = cone::disjuncts(&mut g);
    let [mut symbolic, inductive, mut explicit] = classify(&g, parts, choices);
    let mut stats = SymStats {
        parts: [symbolic.len(), inductive.len(), explicit.len()],
        ..SymStats::default()
    };
    let whole = Limits {
        period,
        offset,
        max_steps,
        deadline,
    };
    let mut results = Vec::new();
    let (ni, nl) = (g.inputs.len(), g.latches.len());
    // the parts on their cone, symbolically simulated within `max_steps`
    let simulate = |parts: &[u32], max_steps: u64| {
        let c = cone::cone(&g, parts);
        let sub = cone::restrict(&g, parts, &c);
        let lim = Limits { max_steps, ..whole };
        let (found, st) = Sim::split_on(&sub, splits).with_cases(cases).run(&lim);
        (lift(found, &c.latches, ni, nl), st, c)
    };
    if !inductive.is_empty() {
        // the base case of 2-induction, a bounded search: it holds if it
        // found no violation in the first steps
        let (found, st, _) = simulate(&inductive, offset + 2);
        stats.sat_calls += st.sat_calls;
        results.push(match found {
            Found::Bounded { steps } if steps >= 2 => Found::Proved {
                steps: offset + 2,
                since: offset,
            },
            f => f,
        });
    }
    // the explicit parts on their cone, when their choices and power-on
    // values are few enough to enumerate
    let search = (!explicit.is_empty())
        .then(|| {
            let c = cone::cone(&g, &explicit);
            (cone::restrict(&g, &explicit, &c), c)
        })
        .filter(|(sub, _)| explicit::fits(sub, choices));
    if search.is_none() && !explicit.is_empty() {
        // else simulated with the symbolic parts, in one run
        stats.parts = [stats.parts[0] + stats.parts[2], stats.parts[1], 0];
        symbolic.append(&mut explicit);
    }
    // the explicit search and the symbolic simulation side by side, one
    // thread each (they share nothing but the AIG they read)
    let all_wait = wait.len();
    let explicit_run = |(sub, c): (Aig, cone::Cone)| {
        // the slave's wait count in the cone's latches: all of it, or none
        let wait: Vec<usize> = (wait.iter())
            .filter_map(|w| c.latches.iter().position(|l| l == w))
            .collect();
        let wait = if wait.len() == all_wait {
            wait
        } else {
            Vec::new()
        };
        explicit::run(&sub, choices, &wait, &whole).map(|f| lift(f, &c.latches, ni, nl))
    };
    let (searched, mut simulated) = std::thread::scope(|sc| {
        let search = search.map(|x| sc.spawn(move || explicit_run(x)));
        let simulated = (!symbolic.is_empty()).then(|| simulate(&symbolic, max_steps));
        let searched = search.map(|t| t.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
        (searched, simulated)
    });
    match searched {
        Some(Some(f)) => results.push(f),
        Some(None) => {
            // too many inputs or states to enumerate: simulated with the
            // symbolic parts, in one run that has the whole time limit (a
            // run of its own took it all, and the other's bound was 0
            // steps); the simulation beside the search is not kept
            stats.parts = [stats.parts[0] + stats.parts[2], stats.parts[1], 0];
            symbolic.extend(explicit);
            simulated = Some(simulate(&symbolic, max_steps));
        }
        None => {}
    }
    if let Some((found, st, c)) = simulated {
        stats.sat_calls += st.sat_calls;
        stats.peak_nodes = stats.peak_nodes.max(st.peak_nodes);
        stats.state_nodes = st.state_nodes;
        stats.branches = st.branches;
        stats.cases = st.cases;
        stats.kept = st.kept.iter().map(|&j| c.latches[j]).collect();
        results.push(found);
    }
    (combine(results), stats)
}

/// The assertion's parts by how they are proved: those whose cone reads
/// no choice (symbolic simulation), those that read one and are k-inductive
/// for k <= 2, and the others (explicit-state search).
fn classify(g: &Aig, parts: Vec<u32>, choices: &[usize]) -> [Vec<u32>; 3] {
    let (mut symbolic, mut inductive, mut explicit) = (Vec::new(), Vec::new(), Vec::new());
    for part in parts {
        let c = cone::cone(g, &[part]);
        if !c.inputs.iter().any(|i| choices.contains(i)) {
            symbolic.push(part);
            continue;
        }
        let alone = cone::restrict(g, &[part], &c);
        if (1..=2).any(|k| induction::step_case(&alone, k) == Ok(true)) {
            inductive.push(part);
        } else {
            explicit.push(part);
        }
    }
    [symbolic, inductive, explicit]
}

/// A part's verdict in the whole AIG's terms: latch `j` of the part is
/// latch `latches[j]` of the whole (its power-on value in a witness, a
/// latch it abstracted).
fn lift(found: Found, latches: &[usize], ni: usize, nl: usize) -> Found {
    match found {
        Found::Violated { step, mut inputs } => {
            let at = ni.min(inputs[0].len());
            let init: Vec<bool> = inputs[0].split_off(at);
            inputs[0].resize(ni + nl, false);
            for (j, v) in init.into_iter().enumerate() {
                inputs[0][ni + latches[j]] = v;
            }
            Found::Violated { step, inputs }
        }
        other => other,
    }
}

/// The whole assertion's verdict from its parts': the earliest violation,
/// else proved if every part is (the last proof's steps: the symbolic
/// parts' when there are any), else the shortest bound.
fn combine(results: Vec<Found>) -> Found {
    let violation = (results.iter())
        .filter(|f| matches!(f, Found::Violated { .. }))
        .min_by_key(|f| match f {
            Found::Violated { step, .. } => *step,
            _ => u64::MAX,
        });
    if let Some(v) = violation {
        return v.clone();
    }
    let bound = (results.iter())
        .filter_map(|f| match f {
            Found::Bounded { steps } => Some(*steps),
            _ => None,
        })
        .min();
    match (bound, results.last()) {
        (Some(steps), _) => Found::Bounded { steps },
        (None, Some(last)) => last.clone(),
        (None, None) => Found::Bounded { steps: 0 },
    }
}

/// [`prove`] without choices, split on `splits` and (`cases`) on registers'
/// values at frame starts, with `counters` generalised at every frame start
/// from `counters.from` (`generalise.rs`): proved when every path's
/// generalised frame start's state comes round; a violation is a trace from
/// reset before a path's first generalisation or, pinned to the count it
/// replaced, in the frame after (else: `Bounded` at the first
/// generalisation, the count that failed in the stats).
#[allow(clippy::too_many_arguments)]
pub fn prove_generalised(
    g: &Aig,
    counters: Counters,
    splits: &[usize],
    cases: bool,
    period: u64,
    offset: u64,
    max_steps: u64,
    deadline: Option<Instant>,
) -> (Found, SymStats) {
    let lim = Limits {
        period,
        offset,
        max_steps,
        deadline,
    };
    // split on `splits` (an AXI4-Stream slave's choices, pin-selected
    // modes' requests) where a step reads them, and on auto select's
    // decisions at frame starts
    let mut sim = Sim::split_on(g, splits).with_cases(cases);
    sim.counters = Some(counters);
    let (f, mut st) = sim.run(&lim);
    st.parts = [1, 0, 0];
    (f, st)
}

/// Where a run stops and compares.
#[derive(Clone, Copy)]
struct Limits {
    period: u64,
    offset: u64,
    max_steps: u64,
    deadline: Option<Instant>,
}

/// The simulation's state: the graph, each latch's value, and the
/// assertions of the steps since the last check.
struct Sim<'a> {
    g: &'a Aig,
    /// Each gate's value, evaluated where a fanin changed (`eval.rs`).
    ev: eval::Eval,
    gr: Graph,
    state: Vec<u32>,
    /// The state at the last boundary (for `kept`).
    prev_state: Vec<u32>,
    /// Steps whose assertion did not fold to "holds", not yet checked,
    /// and their disjunction.
    pending: Vec<(u64, u32)>,
    pending_any: u32,
    stats: SymStats,
    gc_at: usize,
    /// The run's deadline: a SAT check still running then gives no verdict.
    deadline: Option<Instant>,
    /// Inputs split on where the state reads them (`split.rs`), and the
    /// values the path being simulated fixed: (input, step, value).
    splits: Vec<usize>,
    fixed: Vec<graph::Assigned>,
    /// A split run's paths waiting, by the step they continue at.
    queue: std::collections::BTreeMap<(u64, u64, u64), split::Branch>,
    /// Split at frame starts on the values of latches that are functions of
    /// the inputs (`cases.rs`), and the path's condition: conjuncts on the
    /// inputs that every state of the path satisfies.
    split_cases: bool,
    cond: Vec<u32>,
    /// Counters generalised at frame starts (`generalise.rs`), and the
    /// first step they were: no violation from there on is a trace.
    counters: Option<Counters>,
    generalised: Option<u64>,
    /// This path's generalisations (`generalise::Pin`): a violation after
    /// them is pinned to the counts they replaced.
    pin: generalise::Pin,
    /// How many times the graph was collected (its literals renumbered).
    collections: u64,
    /// Whether the state may hold a split input's variable, only copied
    /// (`defer.rs`), and which nodes read one (memo, per collection).
    holding: bool,
    dep: Vec<u8>,
    dep_at: u64,
    /// A split run's next state, a buffer reused step after step.
    next: Vec<u32>,
}

impl<'a> Sim<'a> {
    /// A simulation split on `splits` (none past `split::MAX_SPLIT_BITS`:
    /// they stay variables).
    fn split_on(g: &'a Aig, splits: &[usize]) -> Sim<'a> {
        let mut sim = Sim::new(g);
        if splits.len() <= split::MAX_SPLIT_BITS {
            sim.splits = splits.to_vec();
            // paths merge only if they share each input's variable
            sim.gr.shared = !splits.is_empty();
        }
        sim
    }

    /// Also split on registers' values at frame starts (`cases.rs`).
    fn with_cases(mut self, on: bool) -> Sim<'a> {
        self.split_cases = on;
        self
    }

    fn new(g: &'a Aig) -> Sim<'a> {
        let mut gr = Graph::new();
        let ni = g.inputs.len() as u32;
        // power-on values: 0, 1, or free (a variable of step 0 after the inputs)
        let state = g
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
        Sim {
            g,
            ev: eval::Eval::new(g),
            gr,
            state,
            prev_state: Vec::new(),
            pending: Vec::new(),
            pending_any: 0,
            stats: SymStats::default(),
            gc_at: 1 << 20,
            deadline: None,
            splits: Vec::new(),
            fixed: Vec::new(),
            queue: Default::default(),
            split_cases: false,
            cond: Vec::new(),
            counters: None,
            generalised: None,
            pin: generalise::Pin::default(),
            collections: 0,
            holding: false,
            dep: Vec::new(),
            dep_at: 0,
            next: Vec::new(),
        }
    }

    /// Runs to a verdict, `lim.max_steps` or the deadline.
    fn run(self, lim: &Limits) -> (Found, SymStats) {
        if !self.splits.is_empty() || self.split_cases {
            return self.run_split(lim);
        }
        let (found, stats) = self.run_plain(lim);
        // with generalised counters, the exact search ends where they were
        let found = match (found, stats.generalised) {
            (Found::Bounded { steps }, Some(g)) => Found::Bounded {
                steps: steps.min(g),
            },
            (f, _) => f,
        };
        (found, stats)
    }

    /// [`Sim::run`] without splits.
    fn run_plain(mut self, lim: &Limits) -> (Found, SymStats) {
        self.deadline = lim.deadline;
        // every boundary's state, canonical: a state equal to an earlier
        // boundary's closes the search (a FIFO's pointers may need several
        // periods to come round)
        let mut seen: HashMap<Vec<u64>, u64> = HashMap::new();
        for step in 0..lim.max_steps {
            let phase = step.checked_sub(lim.offset).map(|p| p % lim.period);
            if phase.is_some_and(|p| p % CHECK == 0) {
                if let Some(f) = self.check_pending() {
                    return (f, self.stats);
                }
            }
            if phase == Some(0) {
                if let Some(found) = self.boundary(step, lim, &mut seen) {
                    return (found, self.stats);
                }
            }
            if step.is_multiple_of(256) && lim.deadline.is_some_and(|d| Instant::now() > d) {
                let found = self.check_pending();
                return (found.unwrap_or(Found::Bounded { steps: step }), self.stats);
            }
            self.step(step);
            self.collect_if_large();
        }
        let found = self.check_pending();
        self.stats.peak_nodes = self.stats.peak_nodes.max(self.gr.a.len());
        let end = Found::Bounded {
            steps: lim.max_steps,
        };
        (found.unwrap_or(end), self.stats)
    }

    /// At a period boundary: the state compared with the earlier
    /// boundaries'.
    fn boundary(
        &mut self,
        step: u64,
        lim: &Limits,
        seen: &mut HashMap<Vec<u64>, u64>,
    ) -> Option<Found> {
        if let Err(found) = self.generalise(step) {
            return Some(found);
        }
        let now = self.gr.canonical(&self.state, step as u32);
        if let Some(&since) = seen.get(&now) {
            self.stats.state_nodes = live_nodes(&self.gr, &self.state);
            return Some(Found::Proved { steps: step, since });
        }
        if step > lim.offset {
            self.stats.kept = kept(&self.gr, &self.prev_state, &self.state, step, lim.period);
        }
        seen.insert(now, step);
        self.prev_state.clone_from(&self.state);
        None
    }

    /// One clock step: the inputs' variables, the gates, the assertion
    /// (kept for the next check unless it folds to "holds"), the latches.
    fn step(&mut self, step: u64) {
        let (g, gr) = (self.g, &mut self.gr);
        let bad = evaluate(g, &mut self.ev, gr, &mut self.state, step);
        if bad != 0 {
            self.pending.push((step, bad));
            self.pending_any = gr.and(self.pending_any ^ 1, bad ^ 1) ^ 1;
        }
    }

    /// Checks the pending steps' assertions (one SAT call on their
    /// disjunction; on a violation, each step in turn for the earliest).
    fn check_pending(&mut self) -> Option<Found> {
        if self.pending.is_empty() {
            return None;
        }
        let pending = std::mem::take(&mut self.pending);
        let any = std::mem::replace(&mut self.pending_any, 0);
        // a CRC miter shown never true by its affine forms is never true
        // under the condition either (which is not affine: `satisfy` would
        // not see it, and CDCL cannot decide such a miter)
        if !self.cond.is_empty() && affine::never_true(&self.gr, any) {
            return None;
        }
        // a path split on registers' values: its states satisfy its condition
        let cond = self.cond_lit();
        let any = self.gr.and(any, cond);
        let first = pending[0].0;
        self.stats.sat_calls += 1;
        let limit = self
            .deadline
            .map(|d| d.saturating_duration_since(Instant::now()));
        match self.gr.satisfy(any, limit) {
            Ok(None) => return None,
            Ok(Some(_)) => {}
            // no answer is no verdict: nothing is claimed from here on
            Err(_) => return Some(Found::Bounded { steps: first }),
        }
        for (step, bad) in pending {
            self.stats.sat_calls += 1;
            let bad = self.gr.and(bad, cond);
            match self.gr.satisfy(bad, limit) {
                Ok(Some(assign)) => {
                    let general = self.generalised_violation(step, bad, &assign);
                    return Some(general.unwrap_or_else(|| self.violation(step, assign)));
                }
                Ok(None) => {}
                Err(_) => return Some(Found::Bounded { steps: step }),
            }
        }
        // the disjunction was satisfiable and no step is: no verdict
        Some(Found::Bounded { steps: first })
    }

    /// The witness of a violation at `step`: the model's inputs.
    fn violation(&self, step: u64, assign: Vec<graph::Assigned>) -> Found {
        let ni = self.g.inputs.len();
        let mut inputs = vec![vec![false; ni]; step as usize + 1];
        // after step 0's inputs, each latch's power-on value
        inputs[0].resize(ni + self.g.latches.len(), false);
        for (input, s, v) in assign.into_iter().chain(self.fixed.iter().copied()) {
            if self.is_counter_input(input) {
                continue;
            }
            inputs[s as usize][input as usize] = v;
        }
        Found::Violated { step, inputs }
    }

    /// Collects the graph when it has grown fourfold since the last time.
    fn collect_if_large(&mut self) {
        if self.gr.a.len() <= self.gc_at {
            return;
        }
        self.stats.peak_nodes = self.stats.peak_nodes.max(self.gr.a.len());
        // every literal held: this path's, then each waiting path's
        let mut held: Vec<&mut Vec<u32>> = vec![&mut self.state, &mut self.prev_state];
        held.push(&mut self.cond);
        held.push(&mut self.pin.exact);
        held.push(&mut self.pin.vars);
        for b in self.queue.values_mut() {
            held.push(&mut b.state);
            held.push(&mut b.prev_state);
            held.push(&mut b.cond);
            held.push(&mut b.pin.exact);
            held.push(&mut b.pin.vars);
        }
        let mut roots: Vec<u32> = held.iter().flat_map(|v| v.iter().copied()).collect();
        roots.extend(self.pending.iter().map(|&(_, b)| b));
        roots.push(self.pending_any);
        self.gr.collect(&mut roots);
        self.collections += 1;
        // the nodes were renumbered: every gate's value is evaluated again
        self.ev.invalidate();
        let mut at = 0;
        for v in held {
            let n = v.len();
            v.copy_from_slice(&roots[at..at + n]);
            at += n;
        }
        for (p, r) in self.pending.iter_mut().zip(&roots[at..]) {
            p.1 = *r;
        }
        self.pending_any = roots.pop().unwrap_or(0);
        self.gc_at = (1 << 20).max(4 * self.gr.a.len());
        self.gr.reserve(self.gc_at);
    }
}

/// One step of `g` on the graph: input `k` is variable `(k, step)`,
/// every latch starts from `state` and leaves it with its next value;
/// returns the disjunction of the assertions (`val`: each gate's value).
fn evaluate(g: &Aig, ev: &mut eval::Eval, gr: &mut Graph, state: &mut [u32], step: u64) -> u32 {
    let mut inputs = ev.take_inputs();
    let quiet = ev.quiet(state, g.inputs.len());
    gr.step_vars(g.inputs.len() as u32, step as u32, quiet, &mut inputs);
    let bad = ev.step(g, gr, state, &inputs);
    ev.give_inputs(inputs);
    bad
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
