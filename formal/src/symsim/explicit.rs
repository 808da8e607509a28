//! Explicit-state search for a cone whose only free inputs are choices of
//! the environment (an AXI4-Stream slave's `tready`), not data.
//!
//! Such a cone (the link FIFO's fill level) is a control machine: the set
//! of its states reachable at a step is small, but as a symbolic function
//! of every earlier choice it is large and hard for SAT (a counting
//! argument).  Here the set is kept as it is, one bit-vector per state,
//! and each step's successors are computed 64 (state, choice) pairs at a
//! time with bitwise AIG evaluation.  The search is exact: a violation is
//! a real trace from reset, and when the set at a period boundary equals
//! the set at an earlier one, the steps simulated reach every reachable
//! state (the machine is deterministic given its inputs): a proof for all
//! time.
//!
//! Inputs of the cone other than the choices (yosys's `anyseq` bits for a
//! read outside a memory, which no reachable state makes) are evaluated as
//! unknown (three-valued logic): a step whose successors or assertion
//! would depend on one gives no verdict here (`None`, another engine's
//! turn), so the search never rests on a value it chose.

use std::collections::HashMap;
use std::time::Instant;

use super::{in_dependency_order, Found, Limits};
use crate::aiger::Aig;

/// At most this many input bits are enumerated per step, and this many
/// latches may have a free power-on value.
pub const MAX_CHOICE_BITS: usize = 6;
/// At most this many other input bits are enumerated when a step
/// depends on them.
const MAX_OTHER_BITS: usize = 10;
const MAX_FREE_INIT: usize = 12;
/// At most this many states in a step's set: a cone that reads the data
/// (an auto-select mix's FIFO fill depends on the mode, the mode on the
/// codes, the codes on MISO, enumerated bit by bit) doubles its set every
/// few steps and is not the control machine this search is for; past the
/// bound it gives no verdict (symbolic simulation's turn).  Measured: an
/// AXI4-Stream mix with auto select grew to 6.4 GB in 300 s before.
const MAX_STATES: usize = 1 << 16;

/// Searches `g` (a cone) from power-on, every input in `choices`
/// enumerated at every step; `None` if the cone has too many choice bits
/// or free power-on values for enumeration, or a step depends on another
/// input.
/// The latches without a power-on value (each value a start state).
fn free_latches(g: &Aig) -> Vec<usize> {
    (0..g.latches.len())
        .filter(|&j| g.latches[j].2 != 0 && g.latches[j].2 != 1)
        .collect()
}

/// Whether [`run`] can start on `g` at all: few enough choice bits and
/// power-on values to enumerate (it may still give up on too many states).
pub(super) fn fits(g: &Aig, choices: &[usize]) -> bool {
    choices.len() <= MAX_CHOICE_BITS && free_latches(g).len() <= MAX_FREE_INIT
}

/// `wait`: the latches of an AXI4-Stream slave's wait count, least
/// significant first (empty without one): of two successors equal but for
/// it, the one with the lower count is kept alone (see `States::insert`).
pub(super) fn run(g: &Aig, choices: &[usize], wait: &[usize], lim: &Limits) -> Option<Found> {
    let Limits {
        period,
        offset,
        max_steps,
        deadline,
    } = *lim;
    let free = free_latches(g);
    if !fits(g, choices) {
        return None;
    }
    let mut m = Machine::new(g, choices);
    m.wait = wait.to_vec();
    // the power-on set: every value of the free latches
    let mut set = States::new(m.words);
    for v in 0..1u64 << free.len() {
        let mut s = vec![0u64; m.words];
        for (j, &(_, _, init)) in g.latches.iter().enumerate() {
            let bit = match free.iter().position(|&f| f == j) {
                Some(k) => v >> k & 1 == 1,
                None => init == 1,
            };
            s[j / 64] |= u64::from(bit) << (j % 64);
        }
        set.insert(&s, (u32::MAX, v as u32));
    }
    // every step's (predecessor, inputs) per state, one flat list
    let mut history = History::default();
    let mut seen: HashMap<Vec<u64>, u64> = HashMap::new();
    for step in 0..max_steps {
        if step >= offset && (step - offset).is_multiple_of(period) {
            let now = set.sorted();
            if let Some(&since) = seen.get(&now) {
                return Some(Found::Proved { steps: step, since });
            }
            seen.insert(now, step);
        }
        // every step: a step of a large state set can take seconds, and
        // 1024 of them ran a `--timeout 300` proof for most of an hour
        if deadline.is_some_and(|d| Instant::now() > d) {
            return Some(Found::Bounded { steps: step });
        }
        let (next, bad) = m.step(&set)?;
        history.push(step, &set);
        if let Some((state, combo)) = bad {
            return Some(m.witness(&history, step, state, combo, &free));
        }
        // the bound on the set as it would be without subsumption: a state
        // stands for at most 2^bits equal to it but for the wait count, so
        // this gives up no later than the unsubsumed search did (a cone
        // that reads the data still gives up, not crawls to the deadline)
        if next.len() > MAX_STATES >> m.wait.len() {
            return None;
        }
        set = next;
    }
    Some(Found::Bounded { steps: max_steps })
}

/// How each state of each step was first reached: (predecessor in the
/// step before, input code).  Kept whole only for the steps since the last
/// mark; at every `MARK_EVERY`-th step the set itself is kept instead, and
/// a witness re-runs the steps between two marks (the search is
/// deterministic: the same set gives the same successors in the same
/// order).  Why: one (u32, u32) per state per step grew by gigabytes over a
/// long frame of an AXI4-Stream mix with modes, and the process was killed.
#[derive(Default)]
struct History {
    /// The set at steps 0, MARK_EVERY, 2 * MARK_EVERY, ...
    marks: Vec<Snapshot>,
    /// Per step after the last mark: its states' (predecessor, code).
    recent: Vec<Vec<(u32, u32)>>,
}

/// A step's set of states, flat, and how each was first reached.
struct Snapshot {
    flat: Vec<u64>,
    parents: Vec<(u32, u32)>,
}

/// Steps between two kept sets (see [`History`]).
#[cfg(not(test))]
const MARK_EVERY: u64 = 1024;
/// In the unit tests a mark every 3 steps: the random designs' witnesses
/// (checked against an explicit search and replayed) then cross marks.
#[cfg(test)]
const MARK_EVERY: u64 = 3;

impl History {
    fn push(&mut self, step: u64, set: &States) {
        if step.is_multiple_of(MARK_EVERY) {
            self.recent.clear();
            self.marks.push(Snapshot {
                flat: set.flat.clone(),
                parents: set.parents.clone(),
            });
        } else {
            self.recent.push(set.parents.clone());
        }
    }

    /// Per step from `from` (a mark) to the step before the next mark: its
    /// states' (predecessor, code), by running the search again.
    fn replay(&self, m: &mut Machine, from: u64) -> Vec<Vec<(u32, u32)>> {
        let mark = &self.marks[(from / MARK_EVERY) as usize];
        let mut set = States::of(m.words, mark.flat.clone(), mark.parents.clone());
        let mut steps = vec![mark.parents.clone()];
        for _ in 1..MARK_EVERY {
            // the same steps ran without a violation before
            let (next, _) = m.step(&set).expect("a step that ran once runs again");
            steps.push(next.parents.clone());
            set = next;
        }
        steps
    }
}

/// A set of states, each `words` long, in insertion order, with the
/// (predecessor, choice) that first reached each.  Its index is an
/// open-addressed table of positions in `flat` (no allocation per state:
/// a step inserts some 30 states of an AXI4-Stream FIFO's cone, a few
/// million steps a proof).
struct States {
    words: usize,
    flat: Vec<u64>,
    /// Positions + 1 (0: empty), a power of two long, at most half full.
    slots: Vec<u32>,
    parents: Vec<(u32, u32)>,
    /// The slave's wait count's latches, and per word the bits outside
    /// them: states are told apart by those bits alone (`insert`).
    wait: Vec<usize>,
    mask: Vec<u64>,
}

impl States {
    fn new(words: usize) -> States {
        States::with_capacity(words, 0)
    }

    /// An empty set with room for `n` states (a step's successors are
    /// about as many as its states: no table growth, no reallocation).
    fn with_capacity(words: usize, n: usize) -> States {
        States {
            words,
            flat: Vec::with_capacity(n * words),
            slots: vec![0; (2 * n + 1).next_power_of_two().max(64)],
            parents: Vec::with_capacity(n),
            wait: Vec::new(),
            mask: vec![!0; words],
        }
    }

    /// This (empty) set keeping, of states equal but for the wait count
    /// `wait` (latches, least significant first), the lowest count alone.
    /// Why that is exact: the count is read by nothing but the slave's
    /// `tready` (`harness::SLAVE_WAIT`), and a lower count allows every
    /// choice a higher one does, so the lower state's futures include the
    /// other's; a set that holds, for each reachable state, one equal but
    /// for a count no higher covers every reachable state, and its
    /// successors do again (`split.rs` keeps its paths the same way).
    fn subsuming(mut self, wait: &[usize]) -> States {
        for &j in wait {
            self.mask[j / 64] &= !(1u64 << (j % 64));
        }
        self.wait = wait.to_vec();
        self
    }

    /// The wait count of state `s`.
    fn count(&self, s: &[u64]) -> u64 {
        (self.wait.iter().enumerate()).fold(0, |a, (b, &j)| a | (s[j / 64] >> (j % 64) & 1) << b)
    }

    /// `a` and `b` equal but for the wait count.
    fn same(&self, a: &[u64], b: &[u64]) -> bool {
        (a.iter().zip(b).zip(&self.mask)).all(|((x, y), m)| (x ^ y) & m == 0)
    }

    /// A set kept as a snapshot, for stepping (not for inserting).
    fn of(words: usize, flat: Vec<u64>, parents: Vec<(u32, u32)>) -> States {
        States {
            words,
            flat,
            slots: Vec::new(),
            parents,
            wait: Vec::new(),
            mask: vec![!0; words],
        }
    }

    fn len(&self) -> usize {
        self.parents.len()
    }

    fn get(&self, i: usize) -> &[u64] {
        &self.flat[i * self.words..(i + 1) * self.words]
    }

    /// A state's slot to start probing at (a multiplicative hash of its
    /// bits outside the wait count).
    fn home(&self, s: &[u64]) -> usize {
        let h = (s.iter().zip(&self.mask)).fold(0x9E37_79B9_7F4A_7C15u64, |h, (&w, &m)| {
            (h.rotate_left(5) ^ (w & m)).wrapping_mul(0x517C_C1B7_2722_0A95)
        });
        (h >> 32) as usize & (self.slots.len() - 1)
    }

    /// Adds `s`, first reached by `from`, unless the set holds it; of two
    /// states equal but for the wait count, the lower count's (`subsuming`).
    fn insert(&mut self, s: &[u64], from: (u32, u32)) {
        let mask = self.slots.len() - 1;
        let mut at = self.home(s);
        while self.slots[at] != 0 {
            let i = self.slots[at] as usize - 1;
            if self.same(self.get(i), s) {
                if !self.wait.is_empty() && self.count(s) < self.count(self.get(i)) {
                    let w = self.words;
                    self.flat[i * w..(i + 1) * w].copy_from_slice(s);
                    self.parents[i] = from;
                }
                return;
            }
            at = (at + 1) & mask;
        }
        self.flat.extend_from_slice(s);
        self.parents.push(from);
        self.slots[at] = self.parents.len() as u32;
        if 2 * self.parents.len() > self.slots.len() {
            self.grow();
        }
    }

    /// The table twice as long, every state placed again.
    fn grow(&mut self) {
        self.slots = vec![0; 2 * self.slots.len()];
        let mask = self.slots.len() - 1;
        for i in 0..self.len() {
            let mut at = self.home(self.get(i));
            while self.slots[at] != 0 {
                at = (at + 1) & mask;
            }
            self.slots[at] = i as u32 + 1;
        }
    }

    /// The set's canonical form: its states in order.
    fn sorted(&self) -> Vec<u64> {
        let mut v: Vec<&[u64]> = (0..self.len()).map(|i| self.get(i)).collect();
        v.sort_unstable();
        v.concat()
    }
}

/// Literal `l`'s value in every lane, or its lower bound where it may be
/// unknown (`Machine::lo`).
#[inline]
fn lit(lo: &[u64], l: u32) -> u64 {
    lo[(l >> 1) as usize] ^ 0u64.wrapping_sub(u64::from(l & 1))
}

/// Literal `l`'s bounds `[lo, hi]` in every lane: its value twice unless
/// its variable is `tainted` (see `Machine::hi`).
#[inline]
fn bounds(m: &Machine, l: u32) -> (u64, u64) {
    let v = (l >> 1) as usize;
    let (lo, hi) = match m.tainted[v] {
        true => (m.lo[v], m.hi[v]),
        false => (m.lo[v], m.lo[v]),
    };
    match l & 1 {
        0 => (lo, hi),
        _ => (!hi, !lo),
    }
}

/// Transposes a 64 x 64 bit matrix in place: bit `c` of row `r` becomes
/// bit `r` of row `c` (the recursive block swap, six rounds).  It turns
/// 64 lanes' state words into one lane mask per latch and back.
fn transpose64(m: &mut [u64; 64]) {
    let mut width = 32;
    let mut mask: u64 = 0x0000_0000_FFFF_FFFF;
    while width != 0 {
        let mut r = 0;
        while r < 64 {
            for k in r..r + width {
                let t = ((m[k] >> width) ^ m[k + width]) & mask;
                m[k] ^= t << width;
                m[k + width] ^= t;
            }
            r += 2 * width;
        }
        width >>= 1;
        mask ^= mask << width;
    }
}

/// The cone's gates, evaluated 64 lanes at a time.
struct Machine<'a> {
    g: &'a Aig,
    ands: Vec<(u32, u32, u32)>,
    choices: Vec<usize>,
    words: usize,
    /// Each variable's value in each lane (one bit a lane); for a
    /// variable that may be unknown, its lower bound.
    lo: Vec<u64>,
    /// The upper bound of a `tainted` variable (unknown: lo 0, hi 1).
    hi: Vec<u64>,
    /// The gates outside the tainted fanout (`lo` is their value) and
    /// those inside it (two bounds), each in dependency order.
    known: Vec<(u32, u32, u32)>,
    maybe: Vec<(u32, u32, u32)>,
    /// The variables an input other than a choice reaches (its fanout):
    /// only these may be unknown, so only their gates carry two bounds
    /// (eskin34-axis: 29 of 810 gates; the three-valued loop over all of
    /// them was 40 % of its search).
    tainted: Vec<bool>,
    /// The inputs that are not choices (their variables): unknown unless a
    /// lane enumerates them.
    others: Vec<u32>,
    /// The slave's wait count's latches (`run`).
    wait: Vec<usize>,
}

impl<'a> Machine<'a> {
    fn new(g: &'a Aig, choices: &[usize]) -> Machine<'a> {
        Machine {
            g,
            ands: in_dependency_order(g),
            choices: choices.to_vec(),
            words: g.latches.len().div_ceil(64).max(1),
            lo: vec![0; g.max_var as usize + 1],
            hi: vec![0; g.max_var as usize + 1],
            tainted: vec![false; g.max_var as usize + 1],
            known: Vec::new(),
            maybe: Vec::new(),
            wait: Vec::new(),
            others: {
                // the other inputs the cone reads
                let read: std::collections::HashSet<u32> = (g.ands.iter())
                    .flat_map(|&(_, x, y)| [x >> 1, y >> 1])
                    .chain(g.latches.iter().map(|&(_, nx, _)| nx >> 1))
                    .chain(g.bad.iter().map(|&b| b >> 1))
                    .collect();
                (g.inputs.iter().enumerate())
                    .filter(|&(i, l)| !choices.contains(&i) && read.contains(&(l >> 1)))
                    .map(|(_, &l)| l >> 1)
                    .collect()
            },
        }
        .with_taint()
    }

    /// Marks the fanout of the inputs that are not choices (`tainted`) and
    /// parts the gates: a gate outside it reads none inside, so the `known`
    /// gates, then the `maybe` ones, each in dependency order, is an order
    /// of dependency too.
    fn with_taint(mut self) -> Self {
        for &v in &self.others {
            self.tainted[v as usize] = true;
        }
        for &(lhs, x, y) in &self.ands {
            self.tainted[(lhs >> 1) as usize] =
                self.tainted[(x >> 1) as usize] || self.tainted[(y >> 1) as usize];
        }
        let tainted = &self.tainted;
        (self.maybe, self.known) =
            (self.ands.iter()).partition(|&&(l, _, _)| tainted[(l >> 1) as usize]);
        self
    }

    /// Every successor of `set` under every choice; or the first (state,
    /// input code) whose step violates an assertion; `None` if a step
    /// depends on more inputs that are not choices than can be enumerated.
    ///
    /// A lane is a state and an input code: the choices in its low bits,
    /// the other inputs above.  Lanes first run with the other inputs
    /// unknown; a lane whose successor or assertion depends on them runs
    /// again once for each of their values.
    fn step(&mut self, set: &States) -> Option<(States, Option<(u32, u32)>)> {
        let nc = self.choices.len();
        let mut lanes: Vec<(u32, u32, bool)> = (0..set.len() as u32)
            .flat_map(|s| (0..1u32 << nc).map(move |c| (s, c, false)))
            .collect();
        let mut next = States::with_capacity(self.words, set.len()).subsuming(&self.wait);
        let mut st = vec![0u64; self.words];
        let mut at = 0;
        while at < lanes.len() {
            let end = lanes.len().min(at + 64);
            let (bad, unknown, nexts) = self.eval(set, &lanes[at..end]);
            for k in 0..end - at {
                let (s, code, exact) = lanes[at + k];
                if unknown >> k & 1 == 1 {
                    if exact || self.others.len() > MAX_OTHER_BITS {
                        return None;
                    }
                    let expanded =
                        (0..1u32 << self.others.len()).map(|o| (s, code | o << nc, true));
                    lanes.extend(expanded);
                } else if bad >> k & 1 == 1 {
                    return Some((next, Some((s, code))));
                } else {
                    for (w, word) in st.iter_mut().enumerate() {
                        *word = nexts[w][k];
                    }
                    next.insert(&st, (s, code));
                }
            }
            at = end;
        }
        Some((next, None))
    }

    /// Evaluates up to 64 lanes: the lanes whose assertion fails, those
    /// whose successor or assertion is unknown, and the successors, by
    /// state word and lane (`[w][k]`: word `w` of lane `k`'s next state).
    fn eval(&mut self, set: &States, chunk: &[(u32, u32, bool)]) -> (u64, u64, Vec<[u64; 64]>) {
        self.load(set, chunk);
        let lo = &mut self.lo;
        for &(lhs, x, y) in &self.known {
            lo[(lhs >> 1) as usize] = lit(lo, x) & lit(lo, y);
        }
        for &(lhs, x, y) in &self.maybe {
            let ((xl, xh), (yl, yh)) = (bounds(self, x), bounds(self, y));
            let v = (lhs >> 1) as usize;
            (self.lo[v], self.hi[v]) = (xl & yl, xh & yh);
        }
        let lanes = match chunk.len() {
            64 => !0,
            n => (1u64 << n) - 1,
        };
        let outs = (self.g.bad.iter()).chain(self.g.latches.iter().map(|(_, nx, _)| nx));
        let unknown_any = outs
            .filter(|&&l| self.tainted[(l >> 1) as usize])
            .fold(0, |a, &l| {
                let (lo, hi) = bounds(self, l);
                a | (lo ^ hi)
            })
            & lanes;
        let bad = self.g.bad.iter().fold(0, |a, &b| a | lit(&self.lo, b)) & lanes;
        // the successors: each latch's next value per lane, transposed back
        let nexts = (0..self.words)
            .map(|wd| {
                let mut m = [0u64; 64];
                let latches = self.g.latches.iter().skip(64 * wd).take(64);
                for (j, &(_, nx, _)) in latches.enumerate() {
                    m[j] = lit(&self.lo, nx);
                }
                transpose64(&mut m);
                m
            })
            .collect();
        (bad, unknown_any, nexts)
    }

    /// The lanes' latches (their states' words, transposed 64 latches at a
    /// time) and inputs: the choices by the lanes' codes, the other inputs
    /// unknown unless a lane enumerates them (lo 0, hi 1 there).
    fn load(&mut self, set: &States, chunk: &[(u32, u32, bool)]) {
        let nc = self.choices.len();
        for w in 0..self.words {
            let mut m = [0u64; 64];
            for (k, &(s, _, _)) in chunk.iter().enumerate() {
                m[k] = set.get(s as usize)[w];
            }
            transpose64(&mut m);
            for (j, &(l, _, _)) in self.g.latches.iter().enumerate().skip(64 * w).take(64) {
                self.lo[(l >> 1) as usize] = m[j - 64 * w];
            }
        }
        let lane_bits = |b: usize| {
            (chunk.iter().enumerate()).fold(0u64, |a, (k, &(_, code, _))| {
                a | u64::from(code >> b & 1) << k
            })
        };
        for (b, &i) in self.choices.iter().enumerate() {
            self.lo[(self.g.inputs[i] >> 1) as usize] = lane_bits(b);
        }
        let exact =
            (chunk.iter().enumerate()).fold(0u64, |a, (k, &(_, _, e))| a | u64::from(e) << k);
        for (b, &v) in self.others.iter().enumerate() {
            let o = lane_bits(nc + b) & exact;
            (self.lo[v as usize], self.hi[v as usize]) = (o, o | !exact);
        }
    }

    /// The inputs from reset to a violation at `step` from `state` under
    /// `combo` (inputs outside the choices are 0; `inputs[0]` goes on with
    /// each latch's power-on value).
    fn witness(
        &mut self,
        history: &History,
        step: u64,
        state: u32,
        combo: u32,
        free: &[usize],
    ) -> Found {
        let ni = self.g.inputs.len();
        let mut inputs = vec![vec![false; ni]; step as usize + 1];
        // each choice bit's input, then each other input's
        let bits: Vec<Option<usize>> = (self.choices.iter().map(|&i| Some(i)))
            .chain((self.others.iter()).map(|&v| self.g.inputs.iter().position(|&l| l >> 1 == v)))
            .collect();
        let set_choice = |row: &mut Vec<bool>, c: u32| {
            for (b, i) in bits.iter().enumerate() {
                if let Some(i) = *i {
                    row[i] = c >> b & 1 == 1;
                }
            }
        };
        set_choice(&mut inputs[step as usize], combo);
        let mut at = state;
        let mark = step - step % MARK_EVERY;
        // the steps since the last mark, then each stretch between two
        // marks run again, back to power-on
        let mut window: Vec<Vec<(u32, u32)>> = Vec::new();
        for s in (0..=step).rev() {
            let (base, i) = (s - s % MARK_EVERY, (s % MARK_EVERY) as usize);
            if s < mark && i as u64 == MARK_EVERY - 1 {
                window = history.replay(self, base);
            }
            let (from, c) = match (s >= mark, i) {
                (_, 0) => history.marks[(base / MARK_EVERY) as usize].parents[at as usize],
                (true, i) => history.recent[i - 1][at as usize],
                (false, i) => window[i][at as usize],
            };
            if s == 0 {
                // a power-on state: `c` is the free latches' values
                inputs[0].resize(ni + self.g.latches.len(), false);
                for (k, &j) in free.iter().enumerate() {
                    inputs[0][ni + j] = c >> k & 1 == 1;
                }
                break;
            }
            set_choice(&mut inputs[s as usize - 1], c);
            at = from;
        }
        Found::Violated { step, inputs }
    }
}

#[cfg(test)]
mod tests {
    use super::{transpose64, States};

    /// Every bit lands where a bit-by-bit transpose puts it.
    #[test]
    fn transpose64_moves_bit_c_of_row_r_to_bit_r_of_row_c() {
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        let mut m = [0u64; 64];
        for row in m.iter_mut() {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            *row = x;
        }
        let before = m;
        transpose64(&mut m);
        for (r, row) in before.iter().enumerate() {
            for (c, col) in m.iter().enumerate() {
                assert_eq!(col >> r & 1, row >> c & 1, "row {r}, bit {c}");
            }
        }
    }

    /// The set keeps each state once, in insertion order, across its
    /// table's growth, with the parent that first reached it.
    #[test]
    fn a_state_set_keeps_each_state_once_in_order() {
        let mut s = States::new(2);
        for i in 0..1000u64 {
            s.insert(&[i % 300, i % 7], (i as u32, 0));
        }
        // (i % 300, i % 7) repeats with period 2100: 1000 distinct states
        assert_eq!(s.len(), 1000);
        for i in 0..300u64 {
            s.insert(&[i % 300, i % 7], (u32::MAX, 0));
        }
        assert_eq!(s.len(), 1000);
        assert_eq!(s.get(5), &[5, 5]);
        assert_eq!(s.parents[999], (999, 0));
    }
}
