//! A split input's value held as a variable while registers only copy it:
//! the split (`split.rs`) waits until something computes with it.
//!
//! Why: with pin select, the request read in a frame's last cycle is the
//! mode decided for the frame after next; the design and the harness copy
//! it into a register (`nxt`, `mnext`) and read it only near the next
//! frame's end.  Split where it is read, the two paths ran that whole
//! frame apart, the same work twice.  Held as a variable, one path runs it
//! and splits where a register's next value (or the assertion) is a
//! function of it that is not the variable itself.
//!
//! Soundness: a path's state is a function of free input variables; a
//! variable only copied into registers is one of them, free like MISO, so
//! the state stands for the states of every value of it, all reachable
//! (nothing else constrains it: the path fixes only the values it split
//! on, and every function of it made the run split).  Splitting later, on
//! the held variables and the step's own split inputs at once, each path
//! with the held variables replaced by their values in the whole state
//! (and its condition and pins), partitions that set exactly as the split
//! at the read would have: union equal, nothing added.  A violation on a
//! path is a trace: the held variable's value goes into the witness at the
//! step it was read from the input.

use super::Sim;

/// `dep` memo values: not yet known, reads no split input, reads one.
const UNKNOWN: u8 = 0;
const NO: u8 = 1;
const YES: u8 = 2;

impl Sim<'_> {
    /// Whether literal `l` is a function of a split input's variable other
    /// than the variable itself (or its complement).
    pub(super) fn computes_with_split(&mut self, l: u32) -> bool {
        let n = (l >> 1) as usize;
        n != 0 && !self.gr.is_var(n) && self.reads_split(n)
    }

    /// Whether node `n`'s cone has a split input's variable (memoised by
    /// node until the graph is collected).
    pub(super) fn reads_split(&mut self, n: usize) -> bool {
        if self.dep_at != self.collections {
            self.dep.clear();
            self.dep_at = self.collections;
        }
        if self.dep.len() < self.gr.a.len() {
            self.dep.resize(self.gr.a.len(), UNKNOWN);
        }
        let mut stack = vec![n];
        while let Some(&m) = stack.last() {
            if self.dep[m] != UNKNOWN {
                stack.pop();
                continue;
            }
            if m == 0 {
                self.dep[m] = NO;
                continue;
            }
            if self.gr.is_var(m) {
                let input = (self.gr.a[m] & !super::graph::VAR) as usize;
                self.dep[m] = if self.splits.contains(&input) {
                    YES
                } else {
                    NO
                };
                continue;
            }
            let (x, y) = ((self.gr.a[m] >> 1) as usize, (self.gr.b[m] >> 1) as usize);
            match (self.dep[x], self.dep[y]) {
                (UNKNOWN, _) => stack.push(x),
                (_, UNKNOWN) => stack.push(y),
                (a, b) => self.dep[m] = if a == YES || b == YES { YES } else { NO },
            }
        }
        self.dep[n] == YES
    }

    /// The split inputs' variables in the cones of `lits` (found through
    /// the memo: only nodes that read one are entered).
    pub(super) fn split_vars_under(&mut self, lits: &[u32]) -> Vec<usize> {
        let mut found = Vec::new();
        let mut seen = std::collections::HashSet::new();
        let mut stack: Vec<usize> = lits.iter().map(|&l| (l >> 1) as usize).collect();
        while let Some(n) = stack.pop() {
            if n == 0 || !seen.insert(n) || !self.reads_split(n) {
                continue;
            }
            if self.gr.is_var(n) {
                found.push(n);
            } else {
                stack.push((self.gr.a[n] >> 1) as usize);
                stack.push((self.gr.b[n] >> 1) as usize);
            }
        }
        found.sort_unstable();
        found
    }

    /// The split inputs' variables the state holds (copied, never computed
    /// with), as nodes, each once.
    pub(super) fn held_requests(&self) -> Vec<usize> {
        let mut held: Vec<usize> = (self.state.iter())
            .map(|&l| (l >> 1) as usize)
            .filter(|&n| n != 0 && self.gr.is_var(n))
            .filter(|&n| {
                let input = (self.gr.a[n] & !super::graph::VAR) as usize;
                self.splits.contains(&input)
            })
            .collect();
        held.sort_unstable();
        held.dedup();
        held
    }

    /// `lits` with each variable node of `fix` replaced by its value.
    pub(super) fn cofactor(&mut self, lits: &[u32], fix: &[(usize, bool)]) -> Vec<u32> {
        let mut memo: std::collections::HashMap<usize, u32> =
            fix.iter().map(|&(n, v)| (n, u32::from(v))).collect();
        lits.iter()
            .map(|&l| self.substituted((l >> 1) as usize, &mut memo) ^ (l & 1))
            .collect()
    }

    /// Node `n` as a literal with the memo's substitutions made.
    fn substituted(&mut self, n: usize, memo: &mut std::collections::HashMap<usize, u32>) -> u32 {
        let mut stack = vec![n];
        while let Some(&m) = stack.last() {
            if memo.contains_key(&m) {
                stack.pop();
                continue;
            }
            if m == 0 || self.gr.is_var(m) || !self.reads_split(m) {
                memo.insert(m, (m as u32) * 2);
                continue;
            }
            let (x, y) = (self.gr.a[m], self.gr.b[m]);
            let (xn, yn) = ((x >> 1) as usize, (y >> 1) as usize);
            match (memo.get(&xn), memo.get(&yn)) {
                (Some(&a), Some(&b)) => {
                    let lit = self.gr.and(a ^ (x & 1), b ^ (y & 1));
                    memo.insert(m, lit);
                }
                (None, _) => stack.push(xn),
                (_, None) => stack.push(yn),
            }
        }
        memo[&n]
    }
}
