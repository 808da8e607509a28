//! Assertions over XOR networks decided without the SAT solver.
//!
//! A CRC is an affine function of the bytes it covers (XORs of the data bits
//! and a constant), and a check comparing two implementations of it (the
//! design's CRC on the line and the harness's own, `link.packets`) is an OR
//! of XORs of the two.  Structural hashing does not make two XOR trees of the
//! same bits the same node, and CDCL is hopeless on such a miter (parity
//! reasoning).  Here each node that is an XOR of two affine nodes (the
//! and-inverter pattern `!(p & q) & !(!p & !q)`) gets its affine form: the
//! set of variables it XORs and a constant.  An assertion that is an OR of
//! literals whose forms are all the constant 0 is never true: exact, as the
//! forms are the functions themselves.  Anything else goes to SAT.

use std::collections::HashMap;

use super::graph::Graph;

/// A node's affine form: variables (bit `k`: the `k`-th variable met) and
/// the constant.
#[derive(Clone)]
struct Form {
    vars: Vec<u64>,
    one: bool,
}

impl Form {
    fn xor(&self, other: &Form) -> Form {
        let (long, short) = if self.vars.len() >= other.vars.len() {
            (self, other)
        } else {
            (other, self)
        };
        let mut vars = long.vars.clone();
        for (w, x) in vars.iter_mut().zip(&short.vars) {
            *w ^= x;
        }
        while vars.last() == Some(&0) {
            vars.pop();
        }
        Form {
            vars,
            one: self.one ^ other.one,
        }
    }

    fn is_zero(&self) -> bool {
        self.vars.is_empty() && !self.one
    }
}

/// Whether `lit` is false for every input: an OR (and-inverter: a negated
/// AND, split recursively) of affine literals, each the constant 0.  False
/// means "not shown", never "satisfiable".
pub(super) fn never_true(gr: &Graph, lit: u32) -> bool {
    let forms = Forms::new(gr, lit);
    let mut stack = vec![lit];
    while let Some(l) = stack.pop() {
        match forms.of(l) {
            Some(f) if f.is_zero() => continue,
            Some(_) => return false,
            None => {}
        }
        let n = (l >> 1) as usize;
        if l & 1 == 0 || n == 0 || gr.is_var(n) {
            return false; // a conjunction or a variable: not an OR of affine parts
        }
        // !(a & b) = !a | !b
        stack.push(gr.a[n] ^ 1);
        stack.push(gr.b[n] ^ 1);
    }
    true
}

/// Whether `lit` is an affine function of its variables (an XOR of some,
/// or its complement): data such as a CRC over the codes, which takes as
/// many values as its variables allow.
pub(super) fn is_affine(gr: &Graph, lit: u32) -> bool {
    Forms::new(gr, lit).of(lit).is_some()
}

/// The affine forms of the nodes in a literal's cone (`None`: not affine).
struct Forms {
    form: HashMap<usize, Option<Form>>,
}

impl Forms {
    fn new(gr: &Graph, lit: u32) -> Forms {
        let mut cone = Vec::new();
        let mut seen = std::collections::HashSet::new();
        let mut stack = vec![(lit >> 1) as usize];
        while let Some(n) = stack.pop() {
            if !seen.insert(n) {
                continue;
            }
            cone.push(n);
            if n != 0 && !gr.is_var(n) {
                stack.push((gr.a[n] >> 1) as usize);
                stack.push((gr.b[n] >> 1) as usize);
            }
        }
        // fanins are older nodes: ascending order is bottom-up
        cone.sort_unstable();
        let mut forms = Forms {
            form: HashMap::with_capacity(cone.len()),
        };
        let mut vars = 0usize;
        for n in cone {
            let f = if n == 0 {
                Some(Form {
                    vars: Vec::new(),
                    one: false,
                })
            } else if gr.is_var(n) {
                let mut v = vec![0u64; vars / 64 + 1];
                v[vars / 64] |= 1 << (vars % 64);
                vars += 1;
                Some(Form {
                    vars: v,
                    one: false,
                })
            } else {
                forms.xor_of(gr, n)
            };
            forms.form.insert(n, f);
        }
        forms
    }

    fn of(&self, lit: u32) -> Option<Form> {
        let f = self.form.get(&((lit >> 1) as usize))?.as_ref()?;
        let mut f = f.clone();
        f.one ^= lit & 1 == 1;
        Some(f)
    }

    /// `n = !(s & a) & !(!s & b)`, the complement of `s ? a : b`, where
    /// `s`, `a`, `b` are affine and `a` is `b` or its complement: then the
    /// multiplexer is `b` or `b ^ s`.  The 3-AND XOR `!(p & q) & !(!p &
    /// !q)` is the case `s = p`, `a = q`, `b = !q`; a LUT's multiplexer tree
    /// (a gate-level netlist's cell models) gives the others, its two
    /// branches an XOR and an XNOR built apart.
    fn xor_of(&self, gr: &Graph, n: usize) -> Option<Form> {
        let (x, y) = (gr.a[n], gr.b[n]);
        let (xn, yn) = ((x >> 1) as usize, (y >> 1) as usize);
        if x & 1 == 0 || y & 1 == 0 || xn == 0 || yn == 0 || gr.is_var(xn) || gr.is_var(yn) {
            return None;
        }
        let (p, q) = (gr.a[xn], gr.b[xn]);
        let (r, t) = (gr.a[yn], gr.b[yn]);
        let (sel, a, b) = [(p, q, r, t), (p, q, t, r), (q, p, r, t), (q, p, t, r)]
            .into_iter()
            .find(|&(s, _, ns, _)| ns == s ^ 1)
            .map(|(s, a, _, b)| (s, a, b))?;
        let (fa, fb) = (self.of(a)?, self.of(b)?);
        let d = fa.xor(&fb);
        let ite = if d.is_zero() {
            fb
        } else if d.vars.is_empty() {
            fb.xor(&self.of(sel)?)
        } else {
            return None;
        };
        Some(Form {
            one: !ite.one,
            ..ite
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3-AND XOR, as yosys' `abc -g AND` writes one.
    fn xor(gr: &mut Graph, p: u32, q: u32) -> u32 {
        let a = gr.and(p, q);
        let b = gr.and(p ^ 1, q ^ 1);
        gr.and(a ^ 1, b ^ 1)
    }

    #[test]
    fn two_xor_trees_of_the_same_bits_are_equal() {
        let mut gr = Graph::new();
        let v: Vec<u32> = (0..6).map(|i| gr.var(i, 1)).collect();
        // ((v0 ^ v1) ^ v2) ^ (v3 ^ 1) against v0 ^ ((v1 ^ v3) ^ !v2)... equal
        let l = xor(&mut gr, v[0], v[1]);
        let l = xor(&mut gr, l, v[2]);
        let l = xor(&mut gr, l, v[3] ^ 1);
        let r = xor(&mut gr, v[1], v[3]);
        let r = xor(&mut gr, r, v[2] ^ 1);
        let r = xor(&mut gr, v[0], r);
        let differ = xor(&mut gr, l, r);
        assert!(never_true(&gr, differ));
        // an OR of such checks, and one that can fail
        let other = xor(&mut gr, v[4], v[4] ^ 1); // constant 1 folded? no: v ^ !v
        let any = gr.and(differ ^ 1, other ^ 1) ^ 1;
        assert!(!never_true(&gr, any));
        let wrong = xor(&mut gr, l, v[5]);
        assert!(!never_true(&gr, wrong));
        let ok2 = xor(&mut gr, r, l);
        let both = gr.and(differ ^ 1, ok2 ^ 1) ^ 1;
        assert!(never_true(&gr, both));
    }

    /// `s ? a : b` as and-inverter gates: `!(!(s & a) & !(!s & b))`.
    fn mux(gr: &mut Graph, s: u32, a: u32, b: u32) -> u32 {
        let x = gr.and(s, a);
        let y = gr.and(s ^ 1, b);
        gr.and(x ^ 1, y ^ 1) ^ 1
    }

    /// A LUT's multiplexer tree: an XOR and an XNOR of the same bits built
    /// apart (not one node's complement), selected by a third bit, is that
    /// bit's XOR with them; a multiplexer of two unrelated XORs is not
    /// affine, and an equality check against it goes to SAT.
    #[test]
    fn a_multiplexer_of_an_xor_and_its_complement_is_affine() {
        let mut gr = Graph::new();
        let v: Vec<u32> = (0..4).map(|i| gr.var(i, 1)).collect();
        let x = xor(&mut gr, v[0], v[1]);
        let nx = xor(&mut gr, v[0], v[1] ^ 1);
        assert_ne!(nx, x ^ 1, "built apart");
        let m = mux(&mut gr, v[2], x, nx);
        // v2 ? v0 ^ v1 : !(v0 ^ v1) = v0 ^ v1 ^ v2 ^ 1
        let e = xor(&mut gr, v[2], v[0]);
        let e = xor(&mut gr, e, v[1] ^ 1);
        assert!(is_affine(&gr, m));
        let (ok, bad) = (xor(&mut gr, m, e), xor(&mut gr, m, e ^ 1));
        assert!(never_true(&gr, ok));
        assert!(!never_true(&gr, bad));
        // both branches the same function: the select drops out
        let same = xor(&mut gr, v[1], v[0]);
        let m2 = mux(&mut gr, v[3], x, same);
        let ok2 = xor(&mut gr, m2, x);
        assert!(never_true(&gr, ok2));
        // two unrelated XORs: not affine, not shown
        let y = xor(&mut gr, v[0], v[3]);
        let m3 = mux(&mut gr, v[2], x, y);
        assert!(!is_affine(&gr, m3));
        let unknown = xor(&mut gr, m3, x);
        assert!(!never_true(&gr, unknown));
    }

    /// The value of `lit` when variable node `vars[k]` is bit `k` of `bits`.
    fn value(gr: &Graph, vars: &[u32], bits: u32, lit: u32) -> bool {
        let n = (lit >> 1) as usize;
        let v = if n == 0 {
            false
        } else if let Some(k) = vars.iter().position(|&x| (x >> 1) as usize == n) {
            bits >> k & 1 == 1
        } else {
            value(gr, vars, bits, gr.a[n]) && value(gr, vars, bits, gr.b[n])
        };
        v ^ (lit & 1 == 1)
    }

    /// Random graphs of XORs (both shapes), multiplexers (of an XOR and its
    /// complement built apart, of two like functions, of anything) and
    /// ANDs over 5 variables: every check the affine forms call never
    /// true is false under all 32 assignments, and some are so decided.
    #[test]
    fn what_the_forms_call_never_true_is_never_true_on_random_graphs() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move |n: usize| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n as u64) as usize
        };
        let mut decided = 0;
        for _ in 0..200 {
            let mut gr = Graph::new();
            let vars: Vec<u32> = (0..5).map(|i| gr.var(i, 1)).collect();
            let mut lits = vars.clone();
            for _ in 0..24 {
                let pick = |r: usize, lits: &[u32]| lits[r % lits.len()] ^ ((r as u32 / 7) & 1);
                let (a, b, c) = (
                    pick(next(99), &lits),
                    pick(next(99), &lits),
                    pick(next(99), &lits),
                );
                let l = match next(5) {
                    0 => xor(&mut gr, a, b),
                    1 => {
                        let (x, nx) = (xor(&mut gr, a, b), xor(&mut gr, a, b ^ 1));
                        mux(&mut gr, c, x, nx)
                    }
                    2 => {
                        let (x, y) = (xor(&mut gr, a, b), xor(&mut gr, b, a));
                        mux(&mut gr, c, x, y)
                    }
                    3 => mux(&mut gr, a, b, c),
                    _ => gr.and(a, b),
                };
                lits.push(l);
            }
            for _ in 0..24 {
                let (x, y) = (lits[next(lits.len())], lits[next(lits.len())]);
                let check = xor(&mut gr, x, y ^ (next(2) as u32));
                if never_true(&gr, check) {
                    decided += 1;
                    for bits in 0..32 {
                        assert!(
                            !value(&gr, &vars, bits, check),
                            "check {check} at {bits:05b}"
                        );
                    }
                }
            }
        }
        assert!(decided > 50, "only {decided} checks decided");
    }

    #[test]
    fn a_conjunction_is_not_shown_false() {
        let mut gr = Graph::new();
        let (a, b) = (gr.var(0, 1), gr.var(1, 1));
        let x = gr.and(a, b);
        assert!(!never_true(&gr, x));
    }
}
