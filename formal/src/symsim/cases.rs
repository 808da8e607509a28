//! A split run's paths split on the values of registers, not inputs: auto
//! select's mode and run registers at frame starts.
//!
//! Why: with auto select, each frame start decides the mode from the
//! triggers' window flags, which compare the watched codes (MISO data) with
//! the levels.  The mode and run registers are then functions of the
//! frame's codes, one frame deeper at each frame start, and the state never
//! comes round.  But they take a few values only.  So at a frame start,
//! every latch whose value is a function (a node that is not a single
//! variable: data registers hold one variable per bit; nor an XOR of
//! variables: a CRC over the codes is data too) is a case register,
//! and the path is split into one path per value of those registers that
//! some input reaches (found by SAT, each model blocked in turn), each with
//! the case registers constant again and the case's condition (the
//! registers' functions equal to its values) kept beside the state.
//!
//! Soundness: the path's states at the step are `{state(x) : cond(x)}`;
//! partitioned by the values `a` of the case registers, each part is
//! `{state_a(x) : cond(x) && regs(x) == a}` with `state_a` the state with
//! those registers set to `a`, exactly (no abstraction).  Every later
//! assertion is checked together with the path's condition, so a violation
//! is a real trace.  A conjunct of the condition whose variables are read
//! neither by the state nor by a kept conjunct (the codes of a frame whose
//! words have left the registers) says nothing about the states any more
//! (it is satisfiable: the case's model satisfies it) and is dropped, its
//! variables fixed to that model's values for a witness.  The condition
//! kept is part of the state compared at frame starts (up to renaming), so
//! a path ends only at a set of states some path reached before.

use std::collections::{HashMap, HashSet};

use super::graph::{Assigned, Graph};
use super::split::Branch;
use super::{Found, Sim};

/// At most this many values of the case registers at one frame start: past
/// it the path goes on unsplit (and the run stays bounded if it never
/// comes round).
const MAX_CASES: usize = 256;

/// A SAT model: each variable (input, step) it assigns, with its value.
type Model = HashMap<(u32, u32), bool>;

impl Sim<'_> {
    /// At a frame start: the paths, one per value of the latches whose value
    /// is a function of the inputs, or `None` when there is none (or too
    /// many values).
    pub(super) fn split_cases(&mut self, step: u64) -> Result<Option<Vec<Branch>>, Found> {
        // a single variable, or an XOR of some (a CRC over the codes and the
        // frame count), is data: as many values as its variables allow
        let regs: Vec<usize> = (0..self.state.len())
            .filter(|&j| self.state[j] >= 2 && !self.gr.is_var((self.state[j] >> 1) as usize))
            .filter(|&j| !super::affine::is_affine(&self.gr, self.state[j]))
            .collect();
        if regs.is_empty() {
            return Ok(None);
        }
        // the steps before are checked first, so that the paths start clean
        if let Some(f) = self.check_pending() {
            return Err(self.bounded_at(f));
        }
        let mut query = self.cond_lit();
        let mut cases: Vec<(Vec<bool>, Model)> = Vec::new();
        while cases.len() <= MAX_CASES {
            self.stats.sat_calls += 1;
            let limit = (self.deadline).map(|d| d.saturating_duration_since(Instant::now()));
            let model = match self.gr.satisfy(query, limit) {
                Ok(Some(m)) => m,
                Ok(None) => break,
                Err(_) => return Err(self.bounded_at(Found::Bounded { steps: step })),
            };
            let model: Model = model.into_iter().map(|(i, s, v)| ((i, s), v)).collect();
            let values: Vec<bool> = regs
                .iter()
                .map(|&j| eval(&self.gr, self.state[j], &model))
                .collect();
            let this = self.equal(&regs, &values);
            query = self.gr.and(query, this ^ 1);
            cases.push((values, model));
        }
        if cases.len() > MAX_CASES {
            return Ok(None);
        }
        self.stats.cases += cases.len() as u64;
        let mut paths = Vec::new();
        for (values, model) in cases {
            let mut state = self.state.clone();
            for (&j, &v) in regs.iter().zip(&values) {
                state[j] = u32::from(v);
            }
            let mut cond = self.cond.clone();
            cond.push(self.equal(&regs, &values));
            let mut fixed = self.fixed.clone();
            let (cond, dropped) = prune(&self.gr, &self.live(&state), cond);
            fix(&self.gr, &dropped, &model, &mut fixed);
            paths.push(Branch {
                state,
                prev_state: self.prev_state.clone(),
                fixed,
                cond,
                pin: self.pin.clone(),
            });
        }
        Ok(Some(paths))
    }

    /// "The latches `regs` have `values`", as a literal.
    fn equal(&mut self, regs: &[usize], values: &[bool]) -> u32 {
        let mut all = 1;
        for (&j, &v) in regs.iter().zip(values) {
            all = self.gr.and(all, self.state[j] ^ u32::from(!v));
        }
        all
    }

    /// At a frame start, before the state is compared: the path's
    /// condition without the conjuncts that no longer say anything about
    /// the state (their variables fixed to a model of them, for a witness).
    pub(super) fn prune_cond(&mut self, step: u64) -> Result<(), Found> {
        if self.cond.is_empty() {
            return Ok(());
        }
        let live = self.live(&self.state);
        let (kept, dropped) = prune(&self.gr, &live, std::mem::take(&mut self.cond));
        self.cond = kept;
        if dropped.is_empty() {
            return Ok(());
        }
        let mut all = 1;
        for &c in &dropped {
            all = self.gr.and(all, c);
        }
        self.stats.sat_calls += 1;
        let limit = (self.deadline).map(|d| d.saturating_duration_since(Instant::now()));
        let model = match self.gr.satisfy(all, limit) {
            Ok(Some(m)) => m,
            // the path's condition was satisfiable when it was made: no
            // model now is no answer, never a verdict
            _ => return Err(self.bounded_at(Found::Bounded { steps: step })),
        };
        let model: Model = model.into_iter().map(|(i, s, v)| ((i, s), v)).collect();
        fix(&self.gr, &dropped, &model, &mut self.fixed);
        Ok(())
    }

    /// What a conjunct of the condition must share a variable with to be
    /// kept: the state, and the count a generalisation replaced (a pinned
    /// model reads it, `generalise.rs`).
    fn live(&self, state: &[u32]) -> Vec<u32> {
        state.iter().chain(&self.pin.exact).copied().collect()
    }

    /// The path's condition, one literal (true when there is none).
    pub(super) fn cond_lit(&mut self) -> u32 {
        let mut all = 1;
        for i in 0..self.cond.len() {
            all = self.gr.and(all, self.cond[i]);
        }
        all
    }
}

use std::time::Instant;

/// The conjuncts of `cond` that share variables with `state` (directly or
/// through other kept conjuncts), and the others.
fn prune(gr: &Graph, state: &[u32], cond: Vec<u32>) -> (Vec<u32>, Vec<u32>) {
    let mut live = support(gr, state);
    let supports: Vec<HashSet<usize>> = cond.iter().map(|&c| support(gr, &[c])).collect();
    let mut kept = vec![false; cond.len()];
    loop {
        let mut grew = false;
        for (k, s) in supports.iter().enumerate() {
            if !kept[k] && !s.is_disjoint(&live) {
                kept[k] = true;
                live.extend(s.iter().copied());
                grew = true;
            }
        }
        if !grew {
            break;
        }
    }
    let (kept, dropped): (Vec<_>, Vec<_>) = cond.into_iter().zip(kept).partition(|(_, k)| *k);
    (
        kept.into_iter().map(|(c, _)| c).collect(),
        dropped.into_iter().map(|(c, _)| c).collect(),
    )
}

/// The variables of the `dropped` conjuncts fixed to `model`'s values (false
/// where it says nothing), for a witness.
fn fix(gr: &Graph, dropped: &[u32], model: &Model, fixed: &mut Vec<Assigned>) {
    for n in support(gr, dropped) {
        let key = (gr.a[n] & !super::graph::VAR, gr.b[n]);
        fixed.push((key.0, key.1, model.get(&key).copied().unwrap_or(false)));
    }
}

/// The variable nodes `roots` read.
pub(super) fn support(gr: &Graph, roots: &[u32]) -> HashSet<usize> {
    let mut seen = HashSet::new();
    let mut vars = HashSet::new();
    let mut stack: Vec<usize> = roots.iter().map(|&r| (r >> 1) as usize).collect();
    while let Some(n) = stack.pop() {
        if n == 0 || !seen.insert(n) {
            continue;
        }
        if gr.is_var(n) {
            vars.insert(n);
        } else {
            stack.push((gr.a[n] >> 1) as usize);
            stack.push((gr.b[n] >> 1) as usize);
        }
    }
    vars
}

/// `lit`'s value with each variable as `model` says (false where it says
/// nothing: such a variable is not in the condition the model satisfies).
fn eval(gr: &Graph, lit: u32, model: &Model) -> bool {
    // the cone, evaluated in node order (a node's fanins are older)
    let mut cone = Vec::new();
    let mut seen = HashSet::new();
    let mut stack = vec![(lit >> 1) as usize];
    while let Some(n) = stack.pop() {
        if n == 0 || !seen.insert(n) {
            continue;
        }
        cone.push(n);
        if !gr.is_var(n) {
            stack.push((gr.a[n] >> 1) as usize);
            stack.push((gr.b[n] >> 1) as usize);
        }
    }
    cone.sort_unstable();
    let mut memo: HashMap<usize, bool> = HashMap::from([(0, false)]);
    for n in cone {
        let value = if gr.is_var(n) {
            let key = (gr.a[n] & !super::graph::VAR, gr.b[n]);
            model.get(&key).copied().unwrap_or(false)
        } else {
            let v = |l: u32| memo[&((l >> 1) as usize)] ^ (l & 1 == 1);
            v(gr.a[n]) && v(gr.b[n])
        };
        memo.insert(n, value);
    }
    memo[&((lit >> 1) as usize)] ^ (lit & 1 == 1)
}
