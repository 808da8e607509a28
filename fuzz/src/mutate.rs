//! Structure-aware mutation operators over real files.
//!
//! Every operator works on bytes split into lines (terminators kept), so the
//! result may be anything, including non-UTF-8; generic operators apply to
//! both targets, the others know a little of TOML or VCD.

use fastrand::Rng;

mod toml;
mod vcd;

/// Numbers that overflow, underflow or otherwise upset a parser.
pub const HUGE: &[&str] = &[
    "18446744073709551616",
    "18446744073709551615",
    "9223372036854775807",
    "9223372036854775808",
    "-9223372036854775808",
    "4294967295",
    "4294967296",
    "65536",
    "1e400",
    "-1e400",
    "1e-400",
    "nan",
    "inf",
    "-1",
    "-0",
    "0",
    "1",
    "1.5",
    "0x10",
    "99999999999999999999999999999999999999",
];

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    // generic
    Truncate,
    FlipBytes,
    DeleteLines,
    DuplicateLines,
    SwapLines,
    HugeNumber,
    NonUtf8,
    // TOML
    DupTable,
    DropTable,
    SwapValues,
    StringValue,
    MoveKey,
    // VCD
    VarWidth,
    VarRange,
    TimeDisorder,
    UnknownId,
    XzValue,
    VectorLength,
    DropSignal,
    HeaderKeyword,
}

pub const GENERIC: &[Op] = &[
    Op::Truncate,
    Op::FlipBytes,
    Op::DeleteLines,
    Op::DuplicateLines,
    Op::SwapLines,
    Op::HugeNumber,
    Op::NonUtf8,
];
pub const TOML_OPS: &[Op] = &[
    Op::DupTable,
    Op::DropTable,
    Op::SwapValues,
    Op::StringValue,
    Op::MoveKey,
];
pub const VCD_OPS: &[Op] = &[
    Op::VarWidth,
    Op::VarRange,
    Op::TimeDisorder,
    Op::UnknownId,
    Op::XzValue,
    Op::VectorLength,
    Op::DropSignal,
    Op::HeaderKeyword,
];

impl Op {
    pub fn name(self) -> &'static str {
        match self {
            Op::Truncate => "truncate",
            Op::FlipBytes => "flip-bytes",
            Op::DeleteLines => "delete-lines",
            Op::DuplicateLines => "duplicate-lines",
            Op::SwapLines => "swap-lines",
            Op::HugeNumber => "huge-number",
            Op::NonUtf8 => "non-utf8",
            Op::DupTable => "dup-table",
            Op::DropTable => "drop-table",
            Op::SwapValues => "swap-values",
            Op::StringValue => "string-value",
            Op::MoveKey => "move-key",
            Op::VarWidth => "var-width",
            Op::VarRange => "var-range",
            Op::TimeDisorder => "time-disorder",
            Op::UnknownId => "unknown-id",
            Op::XzValue => "xz-value",
            Op::VectorLength => "vector-length",
            Op::DropSignal => "drop-signal",
            Op::HeaderKeyword => "header-keyword",
        }
    }
}

/// Lines with their terminators; joining them gives the bytes back.
pub fn lines(b: &[u8]) -> Vec<Vec<u8>> {
    b.split_inclusive(|&c| c == b'\n')
        .map(|l| l.to_vec())
        .collect()
}

pub fn join(ls: &[Vec<u8>]) -> Vec<u8> {
    ls.concat()
}

fn body(l: &[u8]) -> &[u8] {
    l.strip_suffix(b"\n").unwrap_or(l)
}

fn with_nl(mut b: Vec<u8>, had_nl: bool) -> Vec<u8> {
    if had_nl {
        b.push(b'\n');
    }
    b
}

fn pick<'a, T>(rng: &mut Rng, v: &'a [T]) -> Option<&'a T> {
    if v.is_empty() {
        None
    } else {
        Some(&v[rng.usize(..v.len())])
    }
}

/// Indices of lines satisfying `f`.
fn find(ls: &[Vec<u8>], f: impl Fn(&[u8]) -> bool) -> Vec<usize> {
    (0..ls.len()).filter(|&i| f(body(&ls[i]))).collect()
}

/// Byte ranges of the numbers (digit runs, with `_` and one leading `-`).
fn numbers(b: &[u8]) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let mut s = i;
            if s > 0 && b[s - 1] == b'-' {
                s -= 1;
            }
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'_') {
                i += 1;
            }
            v.push((s, i));
        } else {
            i += 1;
        }
    }
    v
}

fn splice(b: &[u8], r: (usize, usize), with: &[u8]) -> Vec<u8> {
    let mut o = Vec::with_capacity(b.len() + with.len());
    o.extend_from_slice(&b[..r.0]);
    o.extend_from_slice(with);
    o.extend_from_slice(&b[r.1..]);
    o
}

const NON_UTF8: &[&[u8]] = &[
    b"\xff",
    b"\xfe\xff",
    b"\xc3\x28",
    b"\x80",
    b"\xe2\x82",
    b"\xf0\x28\x8c\xbc",
    b"\xed\xa0\x80",
    b"\x00",
];

/// Applies one operator; returns the new bytes.  An operator that finds
/// nothing to work on falls back to a byte flip, so every call mutates.
pub fn apply(op: Op, input: &[u8], rng: &mut Rng) -> Vec<u8> {
    match try_apply(op, input, rng) {
        Some(out) if out != input => out,
        _ => flip(input, rng),
    }
}

fn flip(input: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = input.to_vec();
    if b.is_empty() {
        return vec![rng.u8(..)];
    }
    for _ in 0..rng.usize(1..=8) {
        let i = rng.usize(..b.len());
        if rng.bool() {
            b[i] ^= 1 << rng.u8(..8);
        } else {
            b[i] = rng.u8(..);
        }
    }
    b
}

fn try_apply(op: Op, input: &[u8], rng: &mut Rng) -> Option<Vec<u8>> {
    let ls = lines(input);
    match op {
        Op::Truncate => truncate(input, &ls, rng),
        Op::FlipBytes => Some(flip(input, rng)),
        Op::DeleteLines => delete_lines(ls, rng),
        Op::DuplicateLines => duplicate_lines(ls, rng),
        Op::SwapLines => swap_lines(ls, rng),
        Op::HugeNumber => huge_number(input, rng),
        Op::NonUtf8 => non_utf8(input, rng),
        Op::DupTable => toml::copy_table(ls, rng),
        Op::DropTable => toml::drop_table(ls, rng),
        Op::SwapValues => toml::swap_values(ls, rng),
        Op::StringValue => toml::string_value(input, rng),
        Op::MoveKey => toml::move_key(ls, rng),
        Op::VarWidth => vcd::var_width(ls, rng),
        Op::VarRange => vcd::var_range(ls, rng),
        Op::TimeDisorder => vcd::time_disorder(ls, rng),
        Op::UnknownId | Op::XzValue | Op::VectorLength => vcd::value_change(ls, rng, op),
        Op::DropSignal => vcd::drop_signal(ls, rng),
        Op::HeaderKeyword => vcd::header_keyword(ls, rng),
    }
}

fn truncate(input: &[u8], ls: &[Vec<u8>], rng: &mut Rng) -> Option<Vec<u8>> {
    if input.is_empty() {
        return None;
    }
    let n = ls.len();
    let cut = if rng.bool() && n > 1 {
        // at a line boundary, or in the middle of a line
        ls[..rng.usize(0..n)].iter().map(|l| l.len()).sum()
    } else {
        rng.usize(0..input.len())
    };
    Some(input[..cut].to_vec())
}

fn delete_lines(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let n = ls.len();
    if n == 0 {
        return None;
    }
    let i = rng.usize(..n);
    let k = rng.usize(1..=3.min(n - i));
    ls.drain(i..i + k);
    Some(join(&ls))
}

fn duplicate_lines(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let n = ls.len();
    if n == 0 {
        return None;
    }
    let i = rng.usize(..n);
    let k = rng.usize(1..=3.min(n - i));
    let run: Vec<Vec<u8>> = ls[i..i + k].to_vec();
    let at = if rng.bool() { i + k } else { rng.usize(0..=n) };
    for (j, l) in run.into_iter().enumerate() {
        ls.insert(at + j, terminated(l));
    }
    Some(join(&ls))
}

fn swap_lines(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let n = ls.len();
    if n < 2 {
        return None;
    }
    let (a, b) = (rng.usize(..n), rng.usize(..n));
    ls.swap(a, b);
    Some(join(&ls))
}

fn huge_number(input: &[u8], rng: &mut Rng) -> Option<Vec<u8>> {
    let nums = numbers(input);
    let r = *pick(rng, &nums)?;
    Some(splice(input, r, pick(rng, HUGE)?.as_bytes()))
}

fn non_utf8(input: &[u8], rng: &mut Rng) -> Option<Vec<u8>> {
    let bad = *pick(rng, NON_UTF8)?;
    let at = rng.usize(0..=input.len());
    if rng.bool() || at == input.len() {
        Some(splice(input, (at, at), bad))
    } else {
        Some(splice(input, (at, at + 1), bad))
    }
}

/// The line with a terminator, so it can move anywhere without joining the next.
fn terminated(l: Vec<u8>) -> Vec<u8> {
    if l.ends_with(b"\n") {
        l
    } else {
        with_nl(l, true)
    }
}

/// Stacks 1-4 operators drawn from `ops` on `seed`; returns the result and
/// the names of the operators applied.
pub fn mutate(seed: &[u8], ops: &[Op], rng: &mut Rng) -> (Vec<u8>, Vec<&'static str>) {
    let k = rng.usize(1..=4);
    let mut b = seed.to_vec();
    let mut names = Vec::with_capacity(k);
    for _ in 0..k {
        let op = ops[rng.usize(..ops.len())];
        b = apply(op, &b, rng);
        names.push(op.name());
    }
    (b, names)
}

#[cfg(test)]
mod tests {
    use super::*;

    const VCD: &[u8] = b"$timescale 1ns $end\n$scope module top $end\n$var wire 1 ! clk $end\n$var wire 3 \" sel [2:0] $end\n$upscope $end\n$enddefinitions $end\n#0\n0!\nb000 \"\n#10\n1!\nb101 \"\n#20\n0!\n";

    #[test]
    fn every_operator_changes_its_input() {
        let mut rng = Rng::with_seed(7);
        for &op in GENERIC.iter().chain(TOML_OPS).chain(VCD_OPS) {
            for _ in 0..50 {
                assert_ne!(apply(op, VCD, &mut rng), VCD, "{}", op.name());
            }
        }
    }

    #[test]
    fn vcd_operators_hit_their_structure() {
        let mut rng = Rng::with_seed(1);
        let out = try_apply(Op::VarWidth, VCD, &mut rng).unwrap();
        assert_eq!(lines(&out).len(), lines(VCD).len());
        let out = try_apply(Op::DropSignal, VCD, &mut rng).unwrap();
        assert!(out.len() < VCD.len());
        assert!(numbers(b"a = 1_000 # -5").len() == 2);
    }
}
