//! Operators that know a little VCD: declarations, timestamps and value
//! changes.

use super::{body, find, join, pick, splice, with_nl, Op};
use fastrand::Rng;

/// Widths around the ones the checker cares about, plus nonsense.
const WIDTHS: &[&str] = &[
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

/// Bit ranges, reversed, overflowing and malformed.
const RANGES: &[&str] = &[
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

fn vars(ls: &[Vec<u8>]) -> Vec<usize> {
    find(ls, |l| l.trim_ascii_start().starts_with(b"$var"))
}

/// The whitespace-separated tokens of a line.
fn tokens(l: &[u8]) -> impl Iterator<Item = &[u8]> {
    l.split(|c| c.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
}

pub(super) fn var_width(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let i = *pick(rng, &vars(&ls))?;
    let had = ls[i].ends_with(b"\n");
    let mut toks: Vec<Vec<u8>> = tokens(body(&ls[i])).map(|t| t.to_vec()).collect();
    if toks.len() < 3 {
        return None;
    }
    toks[2] = pick(rng, WIDTHS)?.as_bytes().to_vec();
    ls[i] = with_nl(toks.join(&b' '), had);
    Some(join(&ls))
}

pub(super) fn var_range(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let i = *pick(rng, &vars(&ls))?;
    let had = ls[i].ends_with(b"\n");
    let l = body(&ls[i]).to_vec();
    let r = pick(rng, RANGES)?.as_bytes();
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

pub(super) fn time_disorder(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
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

/// Rewrites a random value change (`0!` or `b101 "`) with the value or
/// identifier `op` spoils: UnknownId, XzValue or VectorLength.
pub(super) fn value_change(mut ls: Vec<Vec<u8>>, rng: &mut Rng, op: Op) -> Option<Vec<u8>> {
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
        Op::UnknownId => (val, unknown_id(&ls, rng)),
        Op::XzValue => (xz_value(val, vector, rng), id),
        _ => (long_vector(rng), id),
    };
    let out = if vector || op == Op::VectorLength {
        [val, b" ".to_vec(), id].concat()
    } else {
        [val, id].concat()
    };
    ls[i] = with_nl(out, had);
    Some(join(&ls))
}

/// An unused code, an empty one, or another declared signal's.
fn unknown_id(ls: &[Vec<u8>], rng: &mut Rng) -> Vec<u8> {
    let ids = declared_ids(ls);
    match rng.u8(..4) {
        0 => b"~~~".to_vec(),
        1 => Vec::new(),
        2 => b"\xff".to_vec(),
        _ => pick(rng, &ids).cloned().unwrap_or_default(),
    }
}

/// The value with one or all of its bits made unknown, or not a bit at all.
fn xz_value(mut v: Vec<u8>, vector: bool, rng: &mut Rng) -> Vec<u8> {
    const XZ: &[u8] = b"xzXZuUwW-lLhH?2";
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
    v
}

/// A vector value with no bits or more than 64.
fn long_vector(rng: &mut Rng) -> Vec<u8> {
    match rng.u8(..4) {
        0 => b"b".to_vec(),
        1 => [b"b".as_slice(), &[b'1'; 70]].concat(),
        2 => [b"b".as_slice(), &[b'x'; 65]].concat(),
        _ => [b"b".as_slice(), &[b'0'; 200], b"1"].concat(),
    }
}

/// Removes a declaration and every value change of its identifier.
pub(super) fn drop_signal(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let i = *pick(rng, &vars(&ls))?;
    let id = tokens(body(&ls[i])).nth(3)?.to_vec();
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

pub(super) fn header_keyword(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
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

fn find_sub(h: &[u8], n: &[u8]) -> Option<usize> {
    h.windows(n.len()).position(|w| w == n)
}

fn declared_ids(ls: &[Vec<u8>]) -> Vec<Vec<u8>> {
    ls.iter()
        .filter(|l| l.trim_ascii_start().starts_with(b"$var"))
        .filter_map(|l| tokens(body(l)).nth(3).map(|t| t.to_vec()))
        .collect()
}
