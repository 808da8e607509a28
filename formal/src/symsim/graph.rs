//! The hash-consed and-inverter graph the symbolic simulation builds.

use std::collections::HashMap;

use rustc_hash::FxHashMap;

/// A variable's value in a SAT model: (input, step, value).
pub(super) type Assigned = (u32, u32, bool);

/// Marks a variable node: `a = VAR | input`, `b = step`.
pub(super) const VAR: u32 = 1 << 31;

/// Hash-consed and-inverter graph over the input variables of every step.
/// Literal `2n + c`: node `n`, complemented if `c`; node 0 is constant false.
pub(super) struct Graph {
    pub(super) a: Vec<u32>,
    pub(super) b: Vec<u32>,
    table: FxHashMap<u64, u32>,
    /// Each (input, step)'s variable node: one per pair, so two paths of
    /// a split run (`split.rs`) that compute the same function of the
    /// inputs hold the same literal and are merged.  Only when `shared`
    /// (a split run): a run of one path makes each variable once anyway.
    vars: FxHashMap<(u32, u32), u32>,
    /// A shared graph's inputs of a step, `0..n` (`step_vars`): one block
    /// of `n` consecutive variable nodes, by its first node and `n`.  Why:
    /// one lookup per step instead of one per input; a design with many
    /// `anyseq` inputs (yosys's undriven bits) spent a third of a split
    /// run in `var`'s lookups.
    rows: FxHashMap<u32, (u32, u32)>,
    pub(super) shared: bool,
    /// `collect`'s marks and renumbering, kept for the next one.
    scratch: (Vec<u8>, Vec<u32>),
}

/// `collect`'s marks: a node is kept; a variable is in a step's row.
const LIVE: u8 = 1;
const IN_ROW: u8 = 2;

impl Graph {
    pub(super) fn new() -> Graph {
        Graph {
            a: vec![0],
            b: vec![0],
            table: FxHashMap::default(),
            vars: FxHashMap::default(),
            rows: FxHashMap::default(),
            shared: false,
            scratch: Default::default(),
        }
    }

    /// The variables of inputs `0..n` at `step` (what `var` gives each),
    /// in `out` (cleared first: a buffer reused step after step).
    /// Inputs `quiet` marks (`Eval::quiet`) take false and no node.
    pub(super) fn step_vars(&mut self, n: u32, step: u32, quiet: &[bool], out: &mut Vec<u32>) {
        out.clear();
        if !self.shared {
            let var = |k: u32| !quiet.get(k as usize).copied().unwrap_or(false);
            out.extend((0..n).map(|k| if var(k) { self.fresh_var(k, step) } else { 0 }));
            return;
        }
        let (a, b) = (&mut self.a, &mut self.b);
        let &mut (first, len) = self.rows.entry(step).or_insert_with(|| {
            let first = a.len() as u32;
            a.extend((0..n).map(|k| VAR | k));
            b.resize(b.len() + n as usize, step);
            (first, n)
        });
        out.extend((0..n.min(len)).map(|k| (first + k) * 2));
        for k in len..n {
            let v = self.var(k, step);
            out.push(v);
        }
        for (x, &q) in out.iter_mut().zip(quiet) {
            if q {
                *x = 0;
            }
        }
    }

    /// A variable node of its own, not shared with `var`'s: a split
    /// input's (`split.rs` finds what reads it among the nodes made after
    /// it, which a shared, older variable would defeat).
    pub(super) fn fresh_var(&mut self, input: u32, step: u32) -> u32 {
        self.a.push(VAR | input);
        self.b.push(step);
        (self.a.len() as u32 - 1) * 2
    }

    pub(super) fn var(&mut self, input: u32, step: u32) -> u32 {
        if !self.shared {
            return self.fresh_var(input, step);
        }
        if let Some(&(first, n)) = self.rows.get(&step).filter(|r| input < r.1) {
            debug_assert!(n > input);
            return (first + input) * 2;
        }
        let (a, b) = (&mut self.a, &mut self.b);
        *self.vars.entry((input, step)).or_insert_with(|| {
            a.push(VAR | input);
            b.push(step);
            (a.len() as u32 - 1) * 2
        })
    }

    /// Nearly every gate's fanins are constants once the control has left
    /// reset: that case is one well-predicted branch.
    #[inline(always)]
    pub(super) fn and(&mut self, x: u32, y: u32) -> u32 {
        if (x | y) < 2 {
            return x & y;
        }
        self.and_symbolic(x, y)
    }

    pub(super) fn and_symbolic(&mut self, x: u32, y: u32) -> u32 {
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

    /// Room for the graph to grow to `n` nodes without moving (its
    /// table: to a million more gates at most): it grows by a few nodes a
    /// step to its next collection.
    pub(super) fn reserve(&mut self, n: usize) {
        let more = n.saturating_sub(self.a.len());
        self.a.reserve(more);
        self.b.reserve(more);
        self.table.reserve(more.min(1 << 20));
    }

    pub(super) fn is_var(&self, n: usize) -> bool {
        self.a[n] & VAR != 0
    }

    /// Keeps only the nodes `roots` reach (renumbered in creation order, so
    /// a node's fanins stay below it) and rewrites `roots` in place.
    pub(super) fn collect(&mut self, roots: &mut [u32]) {
        let n = self.a.len();
        // buffers kept from one collection to the next (fresh pages for
        // each cost more than the collection: they are all written)
        let (mut live, mut map) = std::mem::take(&mut self.scratch);
        live.clear();
        live.resize(n, 0);
        map.resize(n, 0);
        live[0] = LIVE;
        for &r in roots.iter() {
            live[(r >> 1) as usize] = LIVE;
        }
        for i in (1..n).rev() {
            if live[i] != 0 && !self.is_var(i) {
                live[(self.a[i] >> 1) as usize] = LIVE;
                live[(self.b[i] >> 1) as usize] = LIVE;
            }
        }
        // a step's row of inputs stays whole (its nodes consecutive) while
        // any of them is live, and goes when none is
        self.rows.retain(|_, &mut (first, len)| {
            let block = first as usize..(first + len) as usize;
            let keep = live[block.clone()].iter().any(|&l| l != 0);
            if keep {
                live[block].fill(LIVE | IN_ROW);
            }
            keep
        });
        // renumbered in place: node `i` moves down to `map[i] <= i`, after
        // every node below it was read
        self.table.clear();
        self.vars.clear();
        let lit = |map: &[u32], l: u32| (map[(l >> 1) as usize] * 2) | (l & 1);
        map[0] = 0;
        let mut to = 1usize;
        for i in 1..n {
            if live[i] == 0 {
                continue;
            }
            map[i] = to as u32;
            let (x, y) = (self.a[i], self.b[i]);
            if x & VAR != 0 {
                if self.shared && live[i] & IN_ROW == 0 {
                    self.vars.insert((x & !VAR, y), map[i] * 2);
                }
                (self.a[to], self.b[to]) = (x, y);
            } else {
                let (x, y) = (lit(&map, x), lit(&map, y));
                self.table
                    .insert((u64::from(x) << 32) | u64::from(y), map[i] * 2);
                (self.a[to], self.b[to]) = (x, y);
            }
            to += 1;
        }
        self.a.truncate(to);
        self.b.truncate(to);
        for r in roots.iter_mut() {
            *r = lit(&map, *r);
        }
        for row in self.rows.values_mut() {
            row.0 = map[row.0 as usize];
        }
        self.scratch = (live, map);
    }

    /// The state `roots` as a canonical word sequence, inputs of step 0 by
    /// their step and of later steps by their age at `now`: two states give
    /// the same sequence only if they are the same graph up to that renaming
    /// (children are ordered by a structural hash; a tie or a collision can
    /// only make equal states differ, never different states equal).
    pub(super) fn canonical(&self, roots: &[u32], now: u32) -> Vec<u64> {
        self.form(roots, |n: usize| -> u64 {
            let (input, step) = (u64::from(self.a[n] & !VAR), self.b[n]);
            if step == 0 {
                input << 33
            } else {
                (input << 33) | (1 << 32) | u64::from(now - step)
            }
        })
    }

    /// The state `roots` up to any one-to-one renaming of its variables
    /// that keeps each one's input: every variable is a free bit of its
    /// own, so such states stand for the same set of values.  Why not
    /// `canonical`: a value held for as long as the environment likes (an
    /// idle branch's last data while a mode leaves it idle) grows older
    /// without end, and no shift by whole frames equates it.
    pub(super) fn canonical_any(&self, roots: &[u32]) -> Vec<u64> {
        self.form(roots, |n: usize| u64::from(self.a[n] & !VAR))
    }

    /// `roots` serialized with each variable named by `leaf` (children by
    /// a structural hash, nodes numbered in depth-first order): equal
    /// sequences are the same graph up to a renaming of variables that
    /// keeps `leaf`.
    fn form(&self, roots: &[u32], leaf: impl Fn(usize) -> u64) -> Vec<u64> {
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

    pub(super) fn ordered(&self, n: usize, hash: &HashMap<usize, u64>) -> (u32, u32) {
        let (x, y) = (self.a[n], self.b[n]);
        let k = |l: u32| (hash[&((l >> 1) as usize)] ^ u64::from(l & 1), l & 1);
        if k(y) < k(x) {
            (y, x)
        } else {
            (x, y)
        }
    }

    /// An assignment of the variables under `lit` that makes it true,
    /// `Ok(None)` if none does (Tseitin encoding of its cone, splr), `Err`
    /// if the solver gave no answer (never read as "holds"), e.g. within
    /// `limit` (at least a second; none: no limit).
    pub(super) fn satisfy(
        &self,
        lit: u32,
        limit: Option<std::time::Duration>,
    ) -> Result<Option<Vec<Assigned>>, String> {
        // an OR of XOR miters (a CRC against a CRC): decided by affine
        // forms, exactly; CDCL would not finish
        if super::affine::never_true(self, lit) {
            return Ok(None);
        }
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
        match solve(clauses, limit) {
            Ok(splr::Certificate::SAT(model)) => {
                let value: HashMap<i32, bool> = model.iter().map(|&m| (m.abs(), m > 0)).collect();
                Ok(Some(
                    cone.iter()
                        .filter(|&&n| n != 0 && self.is_var(n))
                        .map(|&n| (self.a[n] & !VAR, self.b[n], value[&index[&n]]))
                        .collect(),
                ))
            }
            Ok(splr::Certificate::UNSAT) => Ok(None),
            Err(e) => Err(e),
        }
    }
}

/// splr on `clauses`, stopped (`Err`) past `limit` (whole seconds, at least
/// one).  splr reads its own time limit only between search stages, so a
/// hard instance can run far past it: with a limit the solver runs on a
/// thread of its own, and its answer is abandoned (the thread left to the
/// process's end) a second past the limit.
fn solve(
    clauses: Vec<Vec<i32>>,
    limit: Option<std::time::Duration>,
) -> Result<splr::Certificate, String> {
    let Some(limit) = limit else {
        return splr::Certificate::try_from(clauses).map_err(|e| format!("{e:?}"));
    };
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(solve_within(clauses, limit).map_err(|e| format!("{e:?}")));
    });
    let grace = limit.max(std::time::Duration::from_secs(1)) + std::time::Duration::from_secs(1);
    rx.recv_timeout(grace).unwrap_or_else(|_| {
        Err(format!(
            "no answer within {} s (the solver was abandoned)",
            grace.as_secs()
        ))
    })
}

/// splr with its own (soft) time limit.
fn solve_within(
    clauses: Vec<Vec<i32>>,
    limit: std::time::Duration,
) -> Result<splr::Certificate, splr::SolverError> {
    use splr::SolveIF;
    let config = splr::Config {
        c_timeout: limit.as_secs().max(1) as f64,
        ..Default::default()
    };
    match splr::Solver::try_from((config, clauses.as_slice())) {
        Ok(mut solver) => solver.solve(),
        Err(Ok(cert)) => Ok(cert),
        Err(Err(splr::SolverError::EmptyClause)) => Ok(splr::Certificate::UNSAT),
        Err(Err(e)) => Err(e),
    }
}

#[cfg(test)]
mod limit_tests {
    use super::solve;
    use std::time::{Duration, Instant};

    /// The pigeonhole principle for `n + 1` pigeons in `n` holes: unsatisfiable,
    /// and exponential for resolution, so a CDCL solver takes long on it.
    fn pigeons(n: i32) -> Vec<Vec<i32>> {
        let v = |p: i32, h: i32| p * n + h + 1;
        let mut c: Vec<Vec<i32>> = (0..=n).map(|p| (0..n).map(|h| v(p, h)).collect()).collect();
        for h in 0..n {
            for p in 0..=n {
                for q in p + 1..=n {
                    c.push(vec![-v(p, h), -v(q, h)]);
                }
            }
        }
        c
    }

    /// A hard instance under a one-second limit answers within a few
    /// seconds (no answer, never "holds"); an easy one answers in full.
    #[test]
    fn a_limit_holds_however_hard_the_instance() {
        let t = Instant::now();
        let r = solve(pigeons(12), Some(Duration::from_secs(1)));
        assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
        assert!(!matches!(r, Ok(splr::Certificate::SAT(_))), "{r:?}");
        let easy = solve(pigeons(3), Some(Duration::from_secs(5)));
        assert!(matches!(easy, Ok(splr::Certificate::UNSAT)), "{easy:?}");
    }
}
