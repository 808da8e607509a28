//! The assertion split into parts, and each part's cone of influence.
//!
//! The harness asserts one conjunction of every property, so the AIG has
//! one bad literal: "some property fails".  Written as a disjunction of
//! smaller literals, each part depends on fewer registers and inputs, and
//! each can go to the engine its cone suits (a part that reads no MISO bit
//! but the slave's choices is a small control machine).

use std::collections::HashMap;

use crate::aiger::Aig;

/// At most this many parts (a wide comparison splits bit by bit).
const MAX_PARTS: usize = 4096;

/// The bad literals of `g` as a disjunction of literals, each once: a
/// complemented AND is the OR of its complemented fanins, and an AND with
/// such an OR on one side distributes over it (the new ANDs are appended
/// to `g`).
pub fn disjuncts(g: &mut Aig) -> Vec<u32> {
    let mut def: HashMap<u32, (u32, u32)> =
        g.ands.iter().map(|&(l, x, y)| (l >> 1, (x, y))).collect();
    let mut out = Vec::new();
    let mut stack = g.bad.clone();
    while let Some(l) = stack.pop() {
        if l == 0 {
            continue;
        }
        let full = out.len() + stack.len() >= MAX_PARTS;
        match def.get(&(l >> 1)).copied() {
            // !(x & y) = !x | !y
            Some((x, y)) if l & 1 == 1 && !full => {
                stack.push(x ^ 1);
                stack.push(y ^ 1);
            }
            // x & (!a | !b) = (x & !a) | (x & !b)
            Some((x, y)) if l & 1 == 0 && !full => {
                let or_side = |s: u32| s & 1 == 1 && def.contains_key(&(s >> 1));
                let (keep, or) = match (or_side(x), or_side(y)) {
                    (_, true) => (x, y),
                    (true, false) => (y, x),
                    _ => {
                        out.push(l);
                        continue;
                    }
                };
                let (a, b) = def[&(or >> 1)];
                for part in [a ^ 1, b ^ 1] {
                    g.max_var += 1;
                    let v = g.max_var;
                    g.ands.push((v * 2, keep, part));
                    def.insert(v, (keep, part));
                    stack.push(v * 2);
                }
            }
            _ => out.push(l),
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The latches and inputs (indices in `g`'s lists) `roots` depend on,
/// through gates and latches' next-state functions.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Cone {
    pub latches: Vec<usize>,
    pub inputs: Vec<usize>,
    ands: Vec<usize>,
}

pub fn cone(g: &Aig, roots: &[u32]) -> Cone {
    let and_of: HashMap<u32, usize> = (g.ands.iter().enumerate())
        .map(|(i, &(l, _, _))| (l >> 1, i))
        .collect();
    let latch_of: HashMap<u32, usize> = (g.latches.iter().enumerate())
        .map(|(j, &(l, _, _))| (l >> 1, j))
        .collect();
    let input_of: HashMap<u32, usize> = (g.inputs.iter().enumerate())
        .map(|(i, &l)| (l >> 1, i))
        .collect();
    let mut seen = vec![false; g.max_var as usize + 1];
    let mut stack: Vec<u32> = roots.iter().map(|&r| r >> 1).collect();
    let (mut latches, mut inputs, mut ands) = (Vec::new(), Vec::new(), Vec::new());
    while let Some(v) = stack.pop() {
        if v == 0 || std::mem::replace(&mut seen[v as usize], true) {
            continue;
        }
        if let Some(&i) = and_of.get(&v) {
            ands.push(i);
            stack.extend([g.ands[i].1 >> 1, g.ands[i].2 >> 1]);
        } else if let Some(&j) = latch_of.get(&v) {
            latches.push(j);
            stack.push(g.latches[j].1 >> 1);
        } else if let Some(&i) = input_of.get(&v) {
            inputs.push(i);
        }
    }
    latches.sort_unstable();
    inputs.sort_unstable();
    ands.sort_unstable();
    Cone {
        latches,
        inputs,
        ands,
    }
}

/// `g` with only the cone of `roots`, which become its bad literals; every
/// input stays (a witness's inputs mean the same in both).  Latch `j` of
/// the result is latch `cone.latches[j]` of `g`.
pub fn restrict(g: &Aig, roots: &[u32], c: &Cone) -> Aig {
    Aig {
        max_var: g.max_var,
        inputs: g.inputs.clone(),
        latches: c.latches.iter().map(|&j| g.latches[j]).collect(),
        ands: c.ands.iter().map(|&i| g.ands[i]).collect(),
        bad: roots.to_vec(),
        constraints: Vec::new(),
    }
}
