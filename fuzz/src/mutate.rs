//! Structure-aware mutation operators over real files.
//!
//! Every operator works on bytes split into lines (terminators kept), so the
//! result may be anything, including non-UTF-8; generic operators apply to
//! both targets, the others know a little of TOML or VCD.

use fastrand::Rng;

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
    let mut ls = lines(input);
    let n = ls.len();
    match op {
        Op::Truncate => {
            if input.is_empty() {
                return None;
            }
            let cut = if rng.bool() && n > 1 {
                // at a line boundary, or in the middle of a line
                ls[..rng.usize(0..n)].iter().map(|l| l.len()).sum()
            } else {
                rng.usize(0..input.len())
            };
            Some(input[..cut].to_vec())
        }
        Op::FlipBytes => Some(flip(input, rng)),
        Op::DeleteLines => {
            if n == 0 {
                return None;
            }
            let i = rng.usize(..n);
            let k = rng.usize(1..=3.min(n - i));
            ls.drain(i..i + k);
            Some(join(&ls))
        }
        Op::DuplicateLines => {
            if n == 0 {
                return None;
            }
            let i = rng.usize(..n);
            let k = rng.usize(1..=3.min(n - i));
            let run: Vec<Vec<u8>> = ls[i..i + k].to_vec();
            let at = if rng.bool() { i + k } else { rng.usize(0..=n) };
            for (j, l) in run.into_iter().enumerate() {
                let l = if l.ends_with(b"\n") {
                    l
                } else {
                    with_nl(l, true)
                };
                ls.insert(at + j, l);
            }
            Some(join(&ls))
        }
        Op::SwapLines => {
            if n < 2 {
                return None;
            }
            let (a, b) = (rng.usize(..n), rng.usize(..n));
            ls.swap(a, b);
            Some(join(&ls))
        }
        Op::HugeNumber => {
            let nums = numbers(input);
            let r = *pick(rng, &nums)?;
            Some(splice(input, r, pick(rng, HUGE)?.as_bytes()))
        }
        Op::NonUtf8 => {
            let bad = *pick(rng, NON_UTF8)?;
            let at = rng.usize(0..=input.len());
            if rng.bool() || at == input.len() {
                Some(splice(input, (at, at), bad))
            } else {
                Some(splice(input, (at, at + 1), bad))
            }
        }

        // ---------------------------------------------------------- TOML
        Op::DupTable | Op::DropTable => {
            let heads = find(&ls, |l| l.trim_ascii_start().starts_with(b"["));
            let h = *pick(rng, &heads)?;
            let end = heads.iter().copied().find(|&j| j > h).unwrap_or(n);
            let sect: Vec<Vec<u8>> = ls[h..end].to_vec();
            if op == Op::DropTable {
                ls.drain(h..end);
            } else {
                let at = if rng.bool() { end } else { n };
                if at == n && !ls.last().is_some_and(|l| l.ends_with(b"\n")) {
                    ls.push(b"\n".to_vec());
                }
                let at = at.min(ls.len());
                for (j, l) in sect.into_iter().enumerate() {
                    ls.insert(at + j, l);
                }
            }
            Some(join(&ls))
        }
        Op::SwapValues => {
            let kv = find(&ls, |l| l.contains(&b'=') && !l.starts_with(b"#"));
            let (a, b) = (*pick(rng, &kv)?, *pick(rng, &kv)?);
            let split = |l: &[u8]| -> (Vec<u8>, Vec<u8>) {
                let e = l.iter().position(|&c| c == b'=').unwrap();
                (l[..=e].to_vec(), l[e + 1..].to_vec())
            };
            let (ka, va) = split(body(&ls[a]));
            let (kb, vb) = split(body(&ls[b]));
            let (na, nb) = (ls[a].ends_with(b"\n"), ls[b].ends_with(b"\n"));
            ls[a] = with_nl([ka, vb].concat(), na);
            ls[b] = with_nl([kb, va].concat(), nb);
            Some(join(&ls))
        }
        Op::StringValue => {
            // the quoted strings of the file, as candidates and targets
            let mut strs = Vec::new();
            let mut i = 0;
            while let Some(s) = input[i..].iter().position(|&c| c == b'"') {
                let s = i + s;
                let Some(e) = input[s + 1..].iter().position(|&c| c == b'"' || c == b'\n') else {
                    break;
                };
                let e = s + 1 + e;
                strs.push((s + 1, e));
                i = e + 1;
            }
            let r = *pick(rng, &strs)?;
            let long = "n".repeat(5000);
            let other = pick(rng, &strs).map(|o| input[o.0..o.1].to_vec());
            let with: Vec<u8> = match rng.u8(..7) {
                0 => Vec::new(),
                1 => b" ".to_vec(),
                2 => long.into_bytes(),
                3 => "ünïcödé ✓".as_bytes().to_vec(),
                4 => b"\\u0000".to_vec(),
                5 => b"\\".to_vec(),
                _ => other.unwrap_or_default(),
            };
            Some(splice(input, r, &with))
        }
        Op::MoveKey => {
            let kv = find(&ls, |l| l.contains(&b'=') && !l.starts_with(b"#"));
            let a = *pick(rng, &kv)?;
            let l = ls.remove(a);
            let l = if l.ends_with(b"\n") {
                l
            } else {
                with_nl(l, true)
            };
            let at = rng.usize(0..=ls.len());
            ls.insert(at, l);
            Some(join(&ls))
        }

        // ---------------------------------------------------------- VCD
        Op::VarWidth => {
            let vars = find(&ls, |l| l.trim_ascii_start().starts_with(b"$var"));
            let i = *pick(rng, &vars)?;
            let had = ls[i].ends_with(b"\n");
            let mut toks: Vec<Vec<u8>> = body(&ls[i])
                .split(|c| c.is_ascii_whitespace())
                .filter(|t| !t.is_empty())
                .map(|t| t.to_vec())
                .collect();
            if toks.len() < 3 {
                return None;
            }
            const W: &[&str] = &[
                "0",
                "1",
                "2",
                "3",
                "4",
                "7",
                "8",
                "13",
                "14",
                "15",
                "16",
                "17",
                "31",
                "32",
                "63",
                "64",
                "65",
                "4294967295",
                "4294967296",
                "-1",
                "x",
            ];
            toks[2] = pick(rng, W)?.as_bytes().to_vec();
            ls[i] = with_nl(toks.join(&b' '), had);
            Some(join(&ls))
        }
        Op::VarRange => {
            let vars = find(&ls, |l| l.trim_ascii_start().starts_with(b"$var"));
            let i = *pick(rng, &vars)?;
            let had = ls[i].ends_with(b"\n");
            let l = body(&ls[i]).to_vec();
            const R: &[&str] = &[
                "[0:0]",
                "[1:0]",
                "[0:1]",
                "[3:0]",
                "[15:0]",
                "[13:0]",
                "[64:0]",
                "[-1:0]",
                "[0:-1]",
                "[9223372036854775807:0]",
                "[0:9223372036854775807]",
                "[-9223372036854775808:9223372036854775807]",
                "[2]",
                "[",
                "]",
                "[:]",
                "[a:b]",
            ];
            let r = pick(rng, R)?.as_bytes();
            let out = match l.iter().position(|&c| c == b'[') {
                Some(s) => {
                    let e = l[s..]
                        .iter()
                        .position(|&c| c == b']')
                        .map(|e| s + e + 1)
                        .unwrap_or(s + 1);
                    splice(&l, (s, e), r)
                }
                None => {
                    // before the closing `$end`
                    let at = find_sub(&l, b"$end").unwrap_or(l.len());
                    splice(&l, (at, at), &[r, b" "].concat())
                }
            };
            ls[i] = with_nl(out, had);
            Some(join(&ls))
        }
        Op::TimeDisorder => {
            let ts = find(&ls, |l| l.starts_with(b"#"));
            let i = *pick(rng, &ts)?;
            let had = ls[i].ends_with(b"\n");
            let t: u64 = std::str::from_utf8(&body(&ls[i])[1..])
                .ok()
                .and_then(|s| s.trim().parse().ok())
                .unwrap_or(0);
            match rng.u8(..4) {
                0 => {
                    let nt = match rng.u8(..3) {
                        0 => t / 2,
                        1 => t.saturating_sub(1),
                        _ => 0,
                    };
                    ls[i] = with_nl(format!("#{nt}").into_bytes(), had);
                }
                1 => {
                    let l = ls.remove(i);
                    let at = rng.usize(0..=ls.len());
                    ls.insert(at, with_nl(body(&l).to_vec(), true));
                }
                2 => {
                    let j = *pick(rng, &ts)?;
                    ls.swap(i, j);
                }
                _ => {
                    let big = [
                        u64::MAX,
                        u64::MAX - 1,
                        t.saturating_mul(1000),
                        t + 1_000_000_007,
                    ];
                    let nt = *pick(rng, &big)?;
                    ls[i] = with_nl(format!("#{nt}").into_bytes(), had);
                }
            }
            Some(join(&ls))
        }
        Op::UnknownId | Op::XzValue | Op::VectorLength => {
            let changes = find(&ls, |l| {
                !l.is_empty()
                    && (matches!(l[0], b'0' | b'1' | b'x' | b'z' | b'X' | b'Z')
                        || (l[0] == b'b' && l.contains(&b' ')))
            });
            let i = *pick(rng, &changes)?;
            let had = ls[i].ends_with(b"\n");
            let l = body(&ls[i]).to_vec();
            let (val, id) = if l[0] == b'b' {
                let sp = l.iter().position(|&c| c == b' ').unwrap();
                (l[..sp].to_vec(), l[sp + 1..].to_vec())
            } else {
                (l[..1].to_vec(), l[1..].to_vec())
            };
            let vector = l[0] == b'b';
            let (val, id) = match op {
                Op::UnknownId => {
                    // an unused code, an empty one, or another declared signal's
                    let ids = declared_ids(&ls);
                    let new: Vec<u8> = match rng.u8(..4) {
                        0 => b"~~~".to_vec(),
                        1 => Vec::new(),
                        2 => b"\xff".to_vec(),
                        _ => pick(rng, &ids).cloned().unwrap_or_default(),
                    };
                    (val, new)
                }
                Op::XzValue => {
                    const XZ: &[u8] = b"xzXZuUwW-lLhH?2";
                    let mut v = val;
                    if vector {
                        let k = rng.usize(1..v.len().max(2));
                        if rng.bool() {
                            for c in v[1..].iter_mut() {
                                *c = *pick(rng, XZ).unwrap();
                            }
                        } else if k < v.len() {
                            v[k] = *pick(rng, XZ).unwrap();
                        }
                    } else {
                        v[0] = *pick(rng, XZ).unwrap();
                    }
                    (v, id)
                }
                _ => {
                    let v: Vec<u8> = match rng.u8(..4) {
                        0 => b"b".to_vec(),
                        1 => [b"b".as_slice(), &[b'1'; 70]].concat(),
                        2 => [b"b".as_slice(), &[b'x'; 65]].concat(),
                        _ => [b"b".as_slice(), &[b'0'; 200], b"1"].concat(),
                    };
                    (v, id)
                }
            };
            let out = if vector || op == Op::VectorLength {
                [val, b" ".to_vec(), id].concat()
            } else {
                [val, id].concat()
            };
            ls[i] = with_nl(out, had);
            Some(join(&ls))
        }
        Op::DropSignal => {
            let vars = find(&ls, |l| l.trim_ascii_start().starts_with(b"$var"));
            let i = *pick(rng, &vars)?;
            let toks: Vec<&[u8]> = body(&ls[i])
                .split(|c| c.is_ascii_whitespace())
                .filter(|t| !t.is_empty())
                .collect();
            let id = toks.get(3)?.to_vec();
            ls.remove(i);
            ls.retain(|l| {
                let l = body(l);
                let ch = if l.first() == Some(&b'b') {
                    l.iter()
                        .position(|&c| c == b' ')
                        .map(|p| &l[p + 1..])
                        .unwrap_or(b"")
                } else if !l.is_empty() && !matches!(l[0], b'#' | b'$' | b' ') {
                    &l[1..]
                } else {
                    return true;
                };
                ch != id.as_slice()
            });
            Some(join(&ls))
        }
        Op::HeaderKeyword => {
            let kw = find(&ls, |l| l.trim_ascii_start().starts_with(b"$"));
            let i = *pick(rng, &kw)?;
            let had = ls[i].ends_with(b"\n");
            let l = body(&ls[i]).to_vec();
            let out = match rng.u8(..4) {
                0 => match find_sub(&l, b"$end") {
                    Some(p) => splice(&l, (p, p + 4), b""),
                    None => [l.as_slice(), b" $end"].concat(),
                },
                1 => b"$upscope $end".to_vec(),
                2 => b"$scope module $end".to_vec(),
                _ => b"$enddefinitions $end".to_vec(),
            };
            ls[i] = with_nl(out, had);
            Some(join(&ls))
        }
    }
}

fn find_sub(h: &[u8], n: &[u8]) -> Option<usize> {
    h.windows(n.len()).position(|w| w == n)
}

fn declared_ids(ls: &[Vec<u8>]) -> Vec<Vec<u8>> {
    ls.iter()
        .filter(|l| l.trim_ascii_start().starts_with(b"$var"))
        .filter_map(|l| {
            body(l)
                .split(|c| c.is_ascii_whitespace())
                .filter(|t| !t.is_empty())
                .nth(3)
                .map(|t| t.to_vec())
        })
        .collect()
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
