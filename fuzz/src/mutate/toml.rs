//! Operators that know a little TOML: tables, keys and quoted values.

use super::{body, find, join, pick, splice, terminated, with_nl};
use fastrand::Rng;

/// A random table: its header line and the end of its section.
fn table(ls: &[Vec<u8>], rng: &mut Rng) -> Option<(usize, usize)> {
    let heads = find(ls, |l| l.trim_ascii_start().starts_with(b"["));
    let h = *pick(rng, &heads)?;
    let end = heads.iter().copied().find(|&j| j > h).unwrap_or(ls.len());
    Some((h, end))
}

pub(super) fn drop_table(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let (h, end) = table(&ls, rng)?;
    ls.drain(h..end);
    Some(join(&ls))
}

/// A copy of a table right after it or at the end of the file.
pub(super) fn copy_table(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let (h, end) = table(&ls, rng)?;
    let n = ls.len();
    let sect: Vec<Vec<u8>> = ls[h..end].to_vec();
    let at = if rng.bool() { end } else { n };
    if at == n && !ls.last().is_some_and(|l| l.ends_with(b"\n")) {
        ls.push(b"\n".to_vec());
    }
    let at = at.min(ls.len());
    for (j, l) in sect.into_iter().enumerate() {
        ls.insert(at + j, l);
    }
    Some(join(&ls))
}

fn key_values(ls: &[Vec<u8>]) -> Vec<usize> {
    find(ls, |l| l.contains(&b'=') && !l.starts_with(b"#"))
}

pub(super) fn swap_values(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let kv = key_values(&ls);
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

/// Byte ranges of the contents of the file's quoted strings (up to a
/// closing quote or the end of the line).
fn quoted(input: &[u8]) -> Vec<(usize, usize)> {
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
    strs
}

pub(super) fn string_value(input: &[u8], rng: &mut Rng) -> Option<Vec<u8>> {
    // the quoted strings of the file, as candidates and targets
    let strs = quoted(input);
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

pub(super) fn move_key(mut ls: Vec<Vec<u8>>, rng: &mut Rng) -> Option<Vec<u8>> {
    let kv = key_values(&ls);
    let a = *pick(rng, &kv)?;
    let l = terminated(ls.remove(a));
    let at = rng.usize(0..=ls.len());
    ls.insert(at, l);
    Some(join(&ls))
}
