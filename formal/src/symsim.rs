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

use rustc_hash::FxHashMap;

use crate::aiger::Aig;

/// Marks a variable node: `a = VAR | input`, `b = step`.
const VAR: u32 = 1 << 31;

/// Hash-consed and-inverter graph over the input variables of every step.
/// Literal `2n + c`: node `n`, complemented if `c`; node 0 is constant false.
struct Graph {
    a: Vec<u32>,
    b: Vec<u32>,
    table: FxHashMap<u64, u32>,
}

impl Graph {
    fn new() -> Graph {
        Graph {
            a: vec![0],
            b: vec![0],
            table: FxHashMap::default(),
        }
    }

    fn var(&mut self, input: u32, step: u32) -> u32 {
        self.a.push(VAR | input);
        self.b.push(step);
        (self.a.len() as u32 - 1) * 2
    }

    /// Nearly every gate's fanins are constants once the control has left
    /// reset: that case is one well-predicted branch.
    #[inline(always)]
    fn and(&mut self, x: u32, y: u32) -> u32 {
        if (x | y) < 2 {
            return x & y;
        }
        self.and_symbolic(x, y)
    }

    fn and_symbolic(&mut self, x: u32, y: u32) -> u32 {
        if x == 0 || y == 0 || x == y ^ 1 {
            return 0;
        }
        if x == 1 || x == y {
            return y;
        }
        if y == 1 {
            return x;
        }
        let (x, y) = if x < y { (x, y) } else { (y, x) };
        let key = (u64::from(x) << 32) | u64::from(y);
        let a = &mut self.a;
        let b = &mut self.b;
        *self.table.entry(key).or_insert_with(|| {
            a.push(x);
            b.push(y);
            (a.len() as u32 - 1) * 2
        })
    }

    fn is_var(&self, n: usize) -> bool {
        self.a[n] & VAR != 0
    }

    /// Keeps only the nodes `roots` reach (renumbered in creation order, so
    /// a node's fanins stay below it) and rewrites `roots` in place.
    fn collect(&mut self, roots: &mut [u32]) {
        let n = self.a.len();
        let mut live = vec![false; n];
        live[0] = true;
        for &r in roots.iter() {
            live[(r >> 1) as usize] = true;
        }
        for i in (1..n).rev() {
            if live[i] && !self.is_var(i) {
                live[(self.a[i] >> 1) as usize] = true;
                live[(self.b[i] >> 1) as usize] = true;
            }
        }
        let mut map = vec![0u32; n];
        let (mut a, mut b) = (vec![0u32], vec![0u32]);
        let mut table = FxHashMap::default();
        let lit = |map: &[u32], l: u32| (map[(l >> 1) as usize] * 2) | (l & 1);
        for i in 1..n {
            if !live[i] {
                continue;
            }
            map[i] = a.len() as u32;
            if self.is_var(i) {
                a.push(self.a[i]);
                b.push(self.b[i]);
            } else {
                let (x, y) = (lit(&map, self.a[i]), lit(&map, self.b[i]));
                table.insert((u64::from(x) << 32) | u64::from(y), map[i] * 2);
                a.push(x);
                b.push(y);
            }
        }
        for r in roots.iter_mut() {
            *r = lit(&map, *r);
        }
        self.a = a;
        self.b = b;
        self.table = table;
    }

    /// The state `roots` as a canonical word sequence, inputs of step 0 by
    /// their step and of later steps by their age at `now`: two states give
    /// the same sequence only if they are the same graph up to that renaming
    /// (children are ordered by a structural hash; a tie or a collision can
    /// only make equal states differ, never different states equal).
    fn canonical(&self, roots: &[u32], now: u32) -> Vec<u64> {
        let leaf = |n: usize| -> u64 {
            let (input, step) = (u64::from(self.a[n] & !VAR), self.b[n]);
            if step == 0 {
                input << 33
            } else {
                (input << 33) | (1 << 32) | u64::from(now - step)
            }
        };
        let mix = |x: u64| {
            let x = (x ^ (x >> 31)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            x ^ (x >> 29)
        };
        // structural hashes, bottom-up over the cone (nodes are topological)
        let mut hash: HashMap<usize, u64> = HashMap::new();
        let mut stack: Vec<usize> = roots.iter().map(|&r| (r >> 1) as usize).collect();
        let mut cone = Vec::new();
        while let Some(n) = stack.pop() {
            if n == 0 || hash.contains_key(&n) {
                continue;
            }
            hash.insert(n, 0);
            cone.push(n);
            if !self.is_var(n) {
                stack.push((self.a[n] >> 1) as usize);
                stack.push((self.b[n] >> 1) as usize);
            }
        }
        cone.sort_unstable();
        hash.insert(0, 0x5151);
        let lh = |hash: &HashMap<usize, u64>, l: u32| hash[&((l >> 1) as usize)] ^ u64::from(l & 1);
        for &n in &cone {
            let h = if self.is_var(n) {
                mix(leaf(n) ^ 0xABCD)
            } else {
                let (x, y) = (lh(&hash, self.a[n]), lh(&hash, self.b[n]));
                mix(mix(x.min(y)) ^ y.max(x).rotate_left(17))
            };
            hash.insert(n, h);
        }
        // serialization in depth-first order, children by hash
        let mut id: HashMap<usize, u64> = HashMap::from([(0, 0)]);
        let mut out = Vec::new();
        for &r in roots {
            let mut st = vec![((r >> 1) as usize, false)];
            while let Some((n, expanded)) = st.pop() {
                if id.contains_key(&n) {
                    continue;
                }
                if self.is_var(n) {
                    out.extend([1, leaf(n)]);
                } else if !expanded {
                    st.push((n, true));
                    let (x, y) = self.ordered(n, &hash);
                    st.push(((y >> 1) as usize, false));
                    st.push(((x >> 1) as usize, false));
                    continue;
                } else {
                    let (x, y) = self.ordered(n, &hash);
                    let c = |l: u32| id[&((l >> 1) as usize)] * 2 + u64::from(l & 1);
                    out.extend([2, c(x), c(y)]);
                }
                id.insert(n, id.len() as u64);
            }
            out.push(3);
            out.push(id[&((r >> 1) as usize)] * 2 + u64::from(r & 1));
        }
        out
    }

    fn ordered(&self, n: usize, hash: &HashMap<usize, u64>) -> (u32, u32) {
        let (x, y) = (self.a[n], self.b[n]);
        let k = |l: u32| (hash[&((l >> 1) as usize)] ^ u64::from(l & 1), l & 1);
        if k(y) < k(x) {
            (y, x)
        } else {
            (x, y)
        }
    }

    /// An assignment of the variables under `lit` that makes it true, or
    /// None if none does (Tseitin encoding of its cone, splr).
    fn satisfy(&self, lit: u32) -> Option<Vec<(u32, u32, bool)>> {
        let mut index: HashMap<usize, i32> = HashMap::new();
        let mut stack = vec![(lit >> 1) as usize];
        let mut cone = Vec::new();
        while let Some(n) = stack.pop() {
            if index.contains_key(&n) {
                continue;
            }
            index.insert(n, index.len() as i32 + 1);
            cone.push(n);
            if n != 0 && !self.is_var(n) {
                stack.push((self.a[n] >> 1) as usize);
                stack.push((self.b[n] >> 1) as usize);
            }
        }
        let v = |l: u32| {
            let x = index[&((l >> 1) as usize)];
            if l & 1 == 1 {
                -x
            } else {
                x
            }
        };
        let mut clauses: Vec<Vec<i32>> = vec![vec![v(lit)]];
        for &n in &cone {
            let o = index[&n];
            if n == 0 {
                clauses.push(vec![-o]);
            } else if !self.is_var(n) {
                let (x, y) = (v(self.a[n]), v(self.b[n]));
                clauses.push(vec![-o, x]);
                clauses.push(vec![-o, y]);
                clauses.push(vec![o, -x, -y]);
            }
        }
        match splr::Certificate::try_from(clauses) {
            Ok(splr::Certificate::SAT(model)) => {
                let value: HashMap<i32, bool> = model.iter().map(|&m| (m.abs(), m > 0)).collect();
                Some(
                    cone.iter()
                        .filter(|&&n| n != 0 && self.is_var(n))
                        .map(|&n| (self.a[n] & !VAR, self.b[n], value[&index[&n]]))
                        .collect(),
                )
            }
            _ => None,
        }
    }
}

/// What the symbolic simulation established.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Found {
    /// No assertion fails in steps `0..steps`, and the state at step
    /// `steps` is (up to renaming) the state at step `since`, a whole
    /// number of periods earlier.
    Proved { steps: u64, since: u64 },
    /// An assertion fails at `step`; `inputs[s][i]` is input `i` at step `s`.
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
        if step.is_multiple_of(4096) && deadline.is_some_and(|d| Instant::now() > d) {
            return (Found::Bounded { steps: step }, stats);
        }
        let st = step as u32;
        for (k, &i) in g.inputs.iter().enumerate() {
            val[(i >> 1) as usize] = gr.var(k as u32, st);
        }
        for (j, &(l, _, _)) in g.latches.iter().enumerate() {
            val[(l >> 1) as usize] = state[j];
        }
        for &(lhs, x, y) in &g.ands {
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
            if let Some(assign) = gr.satisfy(bad) {
                let mut inputs = vec![vec![false; g.inputs.len()]; step as usize + 1];
                for (input, s, v) in assign {
                    if (input as usize) < g.inputs.len() {
                        inputs[s as usize][input as usize] = v;
                    }
                }
                return (Found::Violated { step, inputs }, stats);
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
    let mut s = String::from("1\nb0\n");
    s.push_str(&"0".repeat(g.latches.len()));
    s.push('\n');
    for step in inputs {
        s.extend(step.iter().map(|&b| if b { '1' } else { '0' }));
        s.push('\n');
    }
    s.push_str(".\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aiger::parse;

    /// A 2-bit counter (period 4) with a shift register of the input; the
    /// assertion: the register's bit 1 equals the input of two steps ago,
    /// which a second register records.
    fn counter_and_shift(bug: bool) -> Aig {
        // inputs: 2 (x); latches: 4 c0, 6 c1, 8 s0, 10 s1, 12 r0, 14 r1
        // c0' = !c0; c1' = c1 ^ c0; s0' = x; s1' = s0; r0' = x; r1' = r0 (or !r0 if bug at c = 3)
        // bad = s1 ^ r1
        let mut t = String::new();
        let ands: Vec<(u32, u32, u32)> = vec![
            (16, 6, 5),   // c1 & !c0
            (18, 7, 4),   // !c1 & c0
            (20, 11, 14), // !s1 & r1
            (22, 10, 15), // s1 & !r1
            (24, 4, 6),   // c0 & c1 (count 3)
            (26, 25, 12), // !(c0&c1) & r0
            (28, 24, 13), // c0&c1 & !r0
        ];
        // c1' = (c1&!c0) | (!c1&c0) = !( !16 & !18 )
        let mut all = ands.clone();
        all.push((30, 17, 19)); // !16 & !18 -> c1' = 31
        all.push((32, 21, 23)); // !20 & !22 -> bad = 33
        all.push((34, 27, 29)); // !26 & !28 -> r1' (bug) = 35
        let r1_next = if bug { 35 } else { 12 };
        t.push_str(&format!("aag 17 1 6 0 {} 1\n2\n", all.len()));
        for (l, n) in [(4, 5), (6, 31), (8, 2), (10, 8), (12, 2), (14, r1_next)] {
            t.push_str(&format!("{l} {n} 0\n"));
        }
        t.push_str("33\n");
        for (l, x, y) in all {
            t.push_str(&format!("{l} {x} {y}\n"));
        }
        parse(&t).unwrap()
    }

    #[test]
    fn a_forgetting_design_proves_at_its_recurrence() {
        let (f, st) = run(&counter_and_shift(false), 4, 2, 100, None);
        assert_eq!(
            f,
            Found::Proved {
                steps: 10,
                since: 6
            }
        );
        assert_eq!(st.sat_calls, 0, "the equal bits fold to a constant");
    }

    #[test]
    fn a_fault_under_one_input_is_found_with_its_witness() {
        let g = counter_and_shift(true);
        let (f, _) = run(&g, 4, 2, 100, None);
        let Found::Violated { step, inputs } = f else {
            panic!("{f:?}")
        };
        // r1 takes !r0 when the counter is 3 (steps 3, 7, ...); s1 and r1
        // then differ at the next step whatever the input: the witness
        // replays to a failure at that step
        assert_eq!(step, 4);
        assert_eq!(inputs.len(), 5);
    }

    #[test]
    fn a_state_that_comes_round_after_several_periods_proves_there() {
        // one latch toggled every step has period 2; compared every 3
        // steps from step 2, it differs at 5 and equals step 2's at 8
        let g = parse("aag 1 0 1 0 0 0\n2 3 0\n").unwrap();
        let (f, st) = run(&g, 3, 2, 50, None);
        assert_eq!(f, Found::Proved { steps: 8, since: 2 });
        assert_eq!(st.kept, vec![0], "the latch that changed over a period");
        let (f, _) = run(&g, 3, 2, 8, None);
        assert_eq!(
            f,
            Found::Bounded { steps: 8 },
            "no claim before the recurrence"
        );
    }

    #[test]
    fn collection_keeps_the_state() {
        let mut gr = Graph::new();
        let x = gr.var(0, 1);
        let y = gr.var(1, 1);
        let _dead = gr.and(x, y ^ 1);
        let z = gr.and(x, y);
        let mut roots = vec![z ^ 1, x];
        let before = gr.canonical(&roots, 5);
        gr.collect(&mut roots);
        assert_eq!(gr.a.len(), 4);
        assert_eq!(gr.canonical(&roots, 5), before);
    }
}
