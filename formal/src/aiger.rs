//! The recurrence miter, built on the ASCII AIGER of harness + design.
//!
//! Why: the contract's counters run over a whole frame, so neither IC3 nor
//! k-induction finds an invariant unaided (docs/formal.md).  But the design
//! forgets: its state at step `t >= T0` depends only on `t mod F` and the
//! MISO bits of the last `T0` steps.  The miter checks exactly that, for
//! every input: copy A runs from power-on; copy B is frozen in its power-on
//! state for `F` steps, then runs on the same MISO; at global step `T0 + F`
//! every latch of A must equal B's.  If no input breaks that, the states
//! reachable at `T0 + F` are among those reachable at `T0`, hence (the
//! machine being deterministic given its inputs) every state reachable at
//! any step is reachable before `T0 + F`, and a bounded search of
//! `T0 + F` steps from reset covers all of them: a proof for all time.

/// A parsed ASCII AIGER (`aag`) file: literals as in the file.
#[derive(Debug, Clone)]
pub struct Aig {
    pub max_var: u32,
    pub inputs: Vec<u32>,
    /// (latch literal, next literal, init: 0, 1 or the latch itself = free).
    pub latches: Vec<(u32, u32, u32)>,
    pub ands: Vec<(u32, u32, u32)>,
    /// Bad-state literals (yosys `write_aiger -B`: the harness's assertions).
    pub bad: Vec<u32>,
    /// Invariant constraints (assumptions): the engines here support none,
    /// and refuse an AIG that has any rather than ignore them.
    pub constraints: Vec<u32>,
}

pub fn parse(text: &str) -> Result<Aig, String> {
    let mut lines = text.lines();
    let head: Vec<u32> = lines
        .next()
        .and_then(|h| h.strip_prefix("aag "))
        .ok_or("not an ASCII AIGER file")?
        .split_whitespace()
        .map(|x| {
            x.parse::<u32>()
                .map_err(|_| format!("bad header field `{x}`"))
        })
        .collect::<Result<_, _>>()?;
    if head.len() < 5 {
        return Err("short AIGER header".into());
    }
    let (m, i, l, o, a) = (head[0], head[1], head[2], head[3], head[4]);
    let (b, c, j, f) = (
        head.get(5).copied().unwrap_or(0),
        head.get(6).copied().unwrap_or(0),
        head.get(7).copied().unwrap_or(0),
        head.get(8).copied().unwrap_or(0),
    );
    let mut nums = |n: usize| -> Result<Vec<u32>, String> {
        let line = lines.next().ok_or("truncated AIGER file")?;
        let v: Vec<u32> = line
            .split_whitespace()
            .map(|x| {
                x.parse::<u32>()
                    .map_err(|_| format!("bad AIGER line `{line}`"))
            })
            .collect::<Result<_, _>>()?;
        if v.len() < n {
            return Err(format!("bad AIGER line `{line}`"));
        }
        Ok(v)
    };
    let mut g = Aig {
        max_var: m,
        inputs: Vec::new(),
        latches: Vec::new(),
        ands: Vec::new(),
        bad: Vec::new(),
        constraints: Vec::new(),
    };
    for _ in 0..i {
        g.inputs.push(nums(1)?[0]);
    }
    for _ in 0..l {
        let v = nums(2)?;
        g.latches.push((v[0], v[1], v.get(2).copied().unwrap_or(0)));
    }
    // Outputs are not used; bad states are the harness's
    // assertions (the combined miter checks them on copy A).
    for _ in 0..o {
        nums(1)?;
    }
    for _ in 0..b {
        g.bad.push(nums(1)?[0]);
    }
    for _ in 0..c {
        g.constraints.push(nums(1)?[0]);
    }
    if j + f > 0 {
        return Err("justice/fairness properties are not supported".into());
    }
    for _ in 0..a {
        let v = nums(3)?;
        g.ands.push((v[0], v[1], v[2]));
    }
    Ok(g)
}

struct Builder {
    next_var: u32,
    inputs: Vec<u32>,
    latches: Vec<(u32, u32, u32)>,
    ands: Vec<(u32, u32, u32)>,
}

impl Builder {
    fn var(&mut self) -> u32 {
        self.next_var += 1;
        self.next_var * 2
    }
    fn and(&mut self, x: u32, y: u32) -> u32 {
        if x == 0 || y == 0 {
            return 0;
        }
        if x == 1 {
            return y;
        }
        if y == 1 {
            return x;
        }
        let z = self.var();
        self.ands.push((z, x, y));
        z
    }
    fn or(&mut self, x: u32, y: u32) -> u32 {
        self.and(x ^ 1, y ^ 1) ^ 1
    }
    fn xor(&mut self, x: u32, y: u32) -> u32 {
        let a = self.and(x, y ^ 1);
        let b = self.and(x ^ 1, y);
        self.or(a, b)
    }
    fn mux(&mut self, s: u32, t: u32, e: u32) -> u32 {
        let a = self.and(s, t);
        let b = self.and(s ^ 1, e);
        self.or(a, b)
    }
    fn all(&mut self, xs: &[u32]) -> u32 {
        xs.iter().fold(1, |acc, &x| self.and(acc, x))
    }
    fn any(&mut self, xs: &[u32]) -> u32 {
        xs.iter().fold(0, |acc, &x| self.or(acc, x))
    }
}

/// The recurrence miter of `g`: the inputs in `shared` (by position in
/// `g.inputs`, the design's MISO) feed both copies; every other input
/// (power-on values) is duplicated.  Its one bad state is "at global step
/// `check_step`, some latch of copy A differs from copy B", with copy B
/// frozen for the first `delay` steps.
pub fn recurrence_miter(g: &Aig, shared: &[usize], delay: u64, check_step: u64) -> Vec<u8> {
    miter(g, shared, delay, check_step, false)
}

/// The recurrence miter with the search from reset folded in: its bad state
/// is also "some assertion of copy A fails" (copy A runs from power-on, so
/// its steps are those of the plain search).  One `bmc3` to `check_step`
/// then does both checks: a violation before `check_step` is the design's;
/// one at `check_step` may be either.
pub fn combined_miter(g: &Aig, shared: &[usize], delay: u64, check_step: u64) -> Vec<u8> {
    miter(g, shared, delay, check_step, true)
}

fn miter(g: &Aig, shared: &[usize], delay: u64, check_step: u64, with_base: bool) -> Vec<u8> {
    let m = g.max_var;
    let mut b = Builder {
        next_var: 2 * m,
        inputs: Vec::new(),
        latches: Vec::new(),
        ands: Vec::new(),
    };
    // Copy A keeps the literals; copy B's variable v is v + m, except shared inputs.
    let mut map_b: Vec<u32> = (0..=m).map(|v| (v + m) * 2).collect();
    map_b[0] = 0;
    for (k, &lit) in g.inputs.iter().enumerate() {
        let v = lit / 2;
        b.inputs.push(lit);
        if shared.contains(&k) {
            map_b[v as usize] = lit;
        } else {
            b.inputs.push(map_b[v as usize]);
        }
    }
    let lb = |lit: u32, map: &[u32]| map[(lit / 2) as usize] ^ (lit & 1);
    for &(z, x, y) in &g.ands {
        b.ands.push((z, x, y));
        b.ands.push((lb(z, &map_b), lb(x, &map_b), lb(y, &map_b)));
    }
    // Global step counter k (saturating at check_step) and `go` (k >= delay).
    let bits = 64 - check_step.leading_zeros();
    let k: Vec<u32> = (0..bits).map(|_| b.var()).collect();
    let eq = |b: &mut Builder, v: u64| {
        let lits: Vec<u32> = k
            .iter()
            .enumerate()
            .map(|(i, &l)| if v >> i & 1 == 1 { l } else { l ^ 1 })
            .collect();
        b.all(&lits)
    };
    let at_check = eq(&mut b, check_step);
    let mut carry = at_check ^ 1;
    for &l in &k {
        let next = b.xor(l, carry);
        carry = b.and(l, carry);
        b.latches.push((l, next, 0));
    }
    let go = b.var();
    let go_now = if delay == 0 { 1 } else { eq(&mut b, delay - 1) };
    let go_next = b.or(go, go_now);
    b.latches.push((go, go_next, 0));
    let mut diffs = Vec::new();
    for &(l, next, init) in &g.latches {
        let init_b = if init > 1 { lb(init, &map_b) } else { init };
        let init_a = init;
        b.latches.push((l, next, init_a));
        let (lb_l, nb) = (lb(l, &map_b), lb(next, &map_b));
        let held = b.mux(go, nb, lb_l);
        b.latches.push((lb_l, held, init_b));
        diffs.push(b.xor(l, lb_l));
    }
    let differ = b.any(&diffs);
    let recur_bad = b.and(at_check, differ);
    let bad = if with_base {
        let base_bad = b.any(&g.bad);
        b.or(recur_bad, base_bad)
    } else {
        recur_bad
    };
    binary(&b, bad)
}

/// Binary AIGER (what ABC reads): inputs, latches and AND gates renumbered
/// in that order (the gates are already topological), gates delta-encoded.
fn binary(b: &Builder, bad: u32) -> Vec<u8> {
    let mut map = vec![u32::MAX; b.next_var as usize + 1];
    map[0] = 0;
    let mut n = 0u32;
    for &i in &b.inputs {
        n += 1;
        map[(i / 2) as usize] = n;
    }
    for &(l, _, _) in &b.latches {
        n += 1;
        map[(l / 2) as usize] = n;
    }
    for &(z, _, _) in &b.ands {
        n += 1;
        map[(z / 2) as usize] = n;
    }
    let lit = |l: u32| map[(l / 2) as usize] * 2 + (l & 1);
    let mut out = format!(
        "aig {n} {} {} 0 {} 1\n",
        b.inputs.len(),
        b.latches.len(),
        b.ands.len()
    )
    .into_bytes();
    for &(_, next, init) in &b.latches {
        let init = if init > 1 { lit(init) } else { init };
        out.extend_from_slice(format!("{} {init}\n", lit(next)).as_bytes());
    }
    out.extend_from_slice(format!("{}\n", lit(bad)).as_bytes());
    let varint = |out: &mut Vec<u8>, mut x: u32| {
        while x >= 0x80 {
            out.push((x as u8 & 0x7f) | 0x80);
            x >>= 7;
        }
        out.push(x as u8);
    };
    for &(z, x, y) in &b.ands {
        let (z, x, y) = (lit(z), lit(x), lit(y));
        let (r0, r1) = if x >= y { (x, y) } else { (y, x) };
        debug_assert!(z > r0, "AND gates out of topological order");
        varint(&mut out, z - r0);
        varint(&mut out, r0 - r1);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2-bit counter that ignores its input recurs with period 4 from step
    /// 0; a latch that keeps its input forever never recurs.
    #[test]
    fn parses_and_builds() {
        // latches 2 (bit0), 4 (bit1); bit0' = !bit0, bit1' = bit1 ^ bit0.
        let counter = "aag 6 1 2 0 3 1\n12\n2 3\n4 10\n0\n6 4 3\n8 5 2\n10 7 9\n";
        let g = parse(counter).unwrap();
        assert_eq!(g.latches.len(), 2);
        assert_eq!(g.ands.len(), 3);
        let m = recurrence_miter(&g, &[0], 4, 6);
        let head =
            String::from_utf8_lossy(&m[..m.iter().position(|&c| c == b'\n').unwrap()]).into_owned();
        // one input, two copies of each latch plus the 3-bit counter and `go`
        assert!(head.starts_with("aig "), "{head}");
        let f: Vec<u32> = head[4..].split(' ').map(|x| x.parse().unwrap()).collect();
        assert_eq!((f[1], f[2], f[3], f[5]), (1, 4 + 3 + 1, 0, 1));
    }
}
