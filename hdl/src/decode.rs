//! Arithmetic slot decoding: a branch's ROM word as logic of the slot
//! counters (slot in slice, slice) instead of a block-RAM table read through
//! a frame-wide slot pointer (hdl/DESIGN.md, "Slot LUT").
//!
//! Each bit of the word is a function of the counters' bits. A regular
//! table (a channel that is the slot in the slice, a branch that converts
//! in slot 0 of every slice) depends on few of them: each bit keeps only
//! the counter bits it depends on (counter values the grid never reaches
//! are free), and is emitted as a constant truth table over them, which
//! synthesis folds to a wire, a LUT or a few. Whether this beats the ROM is
//! an estimate ([`SlotLogic::cost`]), compared by `plan` per mix.

use std::collections::HashSet;

use crate::widths::{SLICE_BITS, SLOT_BITS};

/// One word bit: its truth table over `vars` (index bit `i` is `vars[i]`;
/// a var below `slot_bits` is that bit of the slot in slice, else a bit of
/// the slice), unreachable counter values read 0.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BitFn {
    pub vars: Vec<usize>,
    pub table: Vec<bool>,
}

/// A branch's word table as logic of the slot-in-slice and slice counters.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlotLogic {
    pub slot_bits: usize,
    pub slice_bits: usize,
    /// Word bit `i` (bit 0 = the word's lowest).
    pub bits: Vec<BitFn>,
}

/// A truth table with don't-cares (`None`: a counter value the grid never
/// reaches), over `vars`.
type Tt = Vec<Option<bool>>;

/// Drops every var the function does not depend on (either value agrees
/// wherever both are defined), keeping the others in order.
fn reduce(mut t: Tt, mut vars: Vec<usize>) -> (Tt, Vec<usize>) {
    let mut i = vars.len();
    while i > 0 {
        i -= 1;
        let m = 1usize << i;
        let agrees = (0..t.len())
            .filter(|x| x & m == 0)
            .all(|x| match (t[x], t[x | m]) {
                (Some(a), Some(b)) => a == b,
                _ => true,
            });
        if agrees {
            let lo = |x: usize| (x & (m - 1)) | ((x >> 1) & !(m - 1));
            let mut r = vec![None; t.len() / 2];
            for (x, v) in t.iter().enumerate() {
                if v.is_some() {
                    r[lo(x)] = *v;
                }
            }
            t = r;
            vars.remove(i);
        }
    }
    (t, vars)
}

/// Estimated LUT4s of a reduced function, counting a sub-function already
/// seen (`seen`) as free: shared logic, as synthesis shares it.
fn luts(t: &Tt, n: usize, seen: &mut HashSet<Tt>) -> usize {
    let literal = n == 1 && t[0] != Some(true) && t[1] != Some(false);
    if n == 0 || literal || !seen.insert(t.clone()) {
        return 0;
    }
    if n <= 4 {
        return 1;
    }
    // Shannon on the top var: both halves and a 2:1 multiplexer
    let h = t.len() / 2;
    let mut side = |half: &[Option<bool>]| {
        let (r, v) = reduce(half.to_vec(), (0..n - 1).collect());
        luts(&r, v.len(), seen)
    };
    side(&t[..h]) + side(&t[h..]) + 1
}

impl SlotLogic {
    /// The logic of `words` (frame slot `j * sps + p` at `j * sps + p`),
    /// `word_bits` wide, over a grid of `k` slices of `sps` slots; the bits
    /// `free(u)` of frame slot `u`'s word are not read (a slot's channel
    /// where its lane has no word) and may come out either way.
    pub fn of(
        words: &[u32],
        word_bits: usize,
        sps: usize,
        k: usize,
        free: impl Fn(usize) -> u32,
    ) -> SlotLogic {
        let slot_bits = crate::plan::addr_bits(sps as u64);
        let slice_bits = if k > 1 {
            crate::plan::addr_bits(k as u64)
        } else {
            0
        };
        let n = slot_bits + slice_bits;
        let bits = (0..word_bits)
            .map(|i| {
                let t: Tt = (0..1usize << n)
                    .map(|x| {
                        let (p, j) = (x & ((1 << slot_bits) - 1), x >> slot_bits);
                        let u = j * sps + p;
                        let w = words.get(u).filter(|_| p < sps && j < k)?;
                        (free(u) >> i & 1 == 0).then_some(w >> i & 1 == 1)
                    })
                    .collect();
                let (t, vars) = reduce(t, (0..n).collect());
                let table = t.iter().map(|v| v.unwrap_or(false)).collect();
                BitFn { vars, table }
            })
            .collect();
        SlotLogic {
            slot_bits,
            slice_bits,
            bits,
        }
    }

    /// The word at slot in slice `p` and slice `j`, as the Verilog computes it.
    pub fn word(&self, p: usize, j: usize) -> u32 {
        let x = p | j << self.slot_bits;
        let mut w = 0;
        for (i, f) in self.bits.iter().enumerate() {
            let a = f
                .vars
                .iter()
                .enumerate()
                .fold(0, |a, (k, &v)| a | (x >> v & 1) << k);
            w |= (f.table[a] as u32) << i;
        }
        w
    }

    /// Estimated LUT4s of all the branches' decoding together.
    pub fn cost(all: &[&SlotLogic]) -> usize {
        let mut seen = HashSet::new();
        let mut n = 0;
        for l in all {
            for f in &l.bits {
                let t: Tt = f.table.iter().map(|&b| Some(b)).collect();
                n += luts(&t, f.vars.len(), &mut seen);
            }
        }
        n
    }

    fn var_name(&self, v: usize) -> String {
        if v < self.slot_bits {
            format!("a[{v}]")
        } else {
            format!("j[{}]", v - self.slot_bits)
        }
    }

    /// The Verilog: `q`, the word, from `address` (slot in slice) and
    /// `slice` registered as `a` and `j` (the timing generator's own
    /// counter registers again, one cycle behind its next-value outputs,
    /// so `q` is the word a ROM read at `{slice, address}` would give).
    pub fn verilog(&self, wb: usize) -> String {
        let (sb, kb) = (self.slot_bits, self.slice_bits);
        let used = |r: std::ops::Range<usize>| {
            self.bits
                .iter()
                .any(|f| f.vars.iter().any(|v| r.contains(v)))
        };
        let mut s = String::new();
        let mut clocked = String::new();
        if used(0..sb) {
            s.push_str(&format!("reg [{}:0] a;\ninitial a = {sb}'d0;\n", sb - 1));
            clocked.push_str(&format!("  a <= address[{}:0];\n", sb - 1));
        }
        if used(sb..sb + kb) {
            s.push_str(&format!("reg [{}:0] j;\ninitial j = {kb}'d0;\n", kb - 1));
            clocked.push_str(&format!("  j <= slice[{}:0];\n", kb - 1));
        }
        if !clocked.is_empty() {
            s = format!(
                "// the slot in the slice and the slice, registered: the timing generator's counters again,\n// with their power-on value, so synthesis merges the two\n{s}always @(posedge clock) begin\n{clocked}end\n\n"
            );
        }
        s.push_str(&format!(
            "// their slot's word as logic: each bit a truth table over the counter bits it depends on\nwire [{}:0] q;\n",
            wb - 1
        ));
        let mut body = String::new();
        for (i, f) in self.bits.iter().enumerate() {
            let names: Vec<String> = f.vars.iter().rev().map(|&v| self.var_name(v)).collect();
            match f.vars.len() {
                0 => body.push_str(&format!("assign q[{i}] = 1'b{};\n", f.table[0] as u8)),
                1 if f.table == [false, true] => {
                    body.push_str(&format!("assign q[{i}] = {};\n", names[0]))
                }
                n => {
                    let bits: String = f
                        .table
                        .iter()
                        .rev()
                        .map(|&b| if b { '1' } else { '0' })
                        .collect();
                    s.push_str(&format!(
                        "localparam [{}:0] k_q{i} = {}'b{bits};\n",
                        (1 << n) - 1,
                        1 << n
                    ));
                    body.push_str(&format!(
                        "assign q[{i}] = k_q{i}[{{{}}}];\n",
                        names.join(", ")
                    ));
                }
            }
        }
        s.push_str(&format!("{body}\n"));
        s
    }

    /// The registered counter bits no word bit reads, and the inputs'
    /// bits above the counters' (for the `unused` wire).
    pub fn unused(&self) -> Vec<String> {
        let (sb, kb) = (self.slot_bits, self.slice_bits);
        let used = |v: usize| self.bits.iter().any(|f| f.vars.contains(&v));
        let any = |r: std::ops::Range<usize>| r.clone().any(used);
        let mut u = vec![];
        for (r, name, width, full) in [
            (0..sb, "address", sb, SLOT_BITS),
            (sb..sb + kb, "slice", kb, SLICE_BITS),
        ] {
            if any(r.clone()) {
                u.extend(r.filter(|&v| !used(v)).map(|v| self.var_name(v)));
                if width < full {
                    u.push(format!("{name}[{}:{width}]", full - 1));
                }
            } else if full > 0 {
                u.push(name.to_string());
            }
        }
        if !any(0..sb + kb) {
            u.push("clock".to_string());
        }
        u
    }
}
