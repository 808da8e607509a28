//! The feature matrix: mixes drawn across every dimension of the mix format
//! (converter and mux kind, front muxes, bulk rows, sync groups, modes
//! none/pin/auto with per-mode rates on every kind of branch, triggers, the
//! link and its options, clock and frame), so that each feature is tested
//! crossed with every other.  [`pairwise`] covers every pair of two
//! dimensions' values at least once; [`random`] adds free draws.  A seed
//! always gives the same mixes.

use std::fmt::Write as _;

use crate::modemix::Draw;

/// The converter on a branch and how its inputs are reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Converter {
    /// AD7940 behind TMUX1108s.
    Ad7940Mux,
    /// AD7940 wired straight to one sensor (`mux = "none"`).
    Ad7940Bare,
    /// MCP3208, its own multiplexer chosen by its command word.
    Mcp3208,
    /// AD7689, whose word selects the conversion after next.
    Ad7689,
    /// AD7689 behind a TMUX1108 front mux (the MCP3208 samples too late for one).
    Ad7689Front,
}

impl Converter {
    /// The part's code width.
    pub fn bits(self) -> u32 {
        match self {
            Converter::Ad7940Mux | Converter::Ad7940Bare => 14,
            Converter::Mcp3208 => 12,
            Converter::Ad7689 | Converter::Ad7689Front => 16,
        }
    }
}

/// Mode select of a mix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Modes {
    None,
    Pin,
    Auto,
}

/// The link to the host.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Link {
    None,
    Uart,
    Axis,
}

/// One point of the matrix: a value of every dimension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Point {
    pub converter: Converter,
    /// The second branch's converter (`None`: one branch only).
    pub other: Option<Converter>,
    pub modes: Modes,
    pub link: Link,
    /// Channel rows written as one bulk table (`P{0..n}`).
    pub bulk: bool,
    /// A sync group across the two branches.
    pub sync: bool,
    /// Clock in MHz.
    pub clock_mhz: u64,
}

const CONVERTERS: [Converter; 5] = [
    Converter::Ad7940Mux,
    Converter::Ad7940Bare,
    Converter::Mcp3208,
    Converter::Ad7689,
    Converter::Ad7689Front,
];
const OTHERS: [Option<Converter>; 4] = [
    None,
    Some(Converter::Ad7940Mux),
    Some(Converter::Mcp3208),
    Some(Converter::Ad7689),
];
const MODES: [Modes; 3] = [Modes::None, Modes::Pin, Modes::Auto];
const LINKS: [Link; 3] = [Link::None, Link::Uart, Link::Axis];
const CLOCKS: [u64; 2] = [24, 48];

/// The number of values of each dimension, in [`Point`]'s field order.
const DIMS: [usize; 7] = [5, 4, 3, 3, 2, 2, 2];

fn point(v: &[usize; 7]) -> Point {
    Point {
        converter: CONVERTERS[v[0]],
        other: OTHERS[v[1]],
        modes: MODES[v[2]],
        link: LINKS[v[3]],
        bulk: v[4] == 1,
        sync: v[5] == 1,
        clock_mhz: CLOCKS[v[6]],
    }
}

/// Points covering every pair of two dimensions' values (greedy: each new
/// point, chosen among a few seeded candidates, covers the most pairs not
/// yet covered).
pub fn pairwise(seed: u64) -> Vec<Point> {
    let mut d = Draw::new(seed);
    let mut todo = std::collections::BTreeSet::new();
    for (i, &ni) in DIMS.iter().enumerate() {
        for (j, &nj) in DIMS.iter().enumerate().skip(i + 1) {
            for a in 0..ni {
                for b in 0..nj {
                    todo.insert((i, a, j, b));
                }
            }
        }
    }
    let covers = |v: &[usize; 7], todo: &std::collections::BTreeSet<_>| {
        todo.iter()
            .filter(|&&(i, a, j, b)| v[i] == a && v[j] == b)
            .count()
    };
    let mut out = vec![];
    while let Some(&(i, a, j, b)) = todo.iter().next() {
        let mut best = ([0; 7], 0);
        for _ in 0..40 {
            let mut v = [0; 7];
            for (k, n) in DIMS.iter().enumerate() {
                v[k] = d.below(*n as u64) as usize;
            }
            (v[i], v[j]) = (a, b);
            let n = covers(&v, &todo);
            if n > best.1 {
                best = (v, n);
            }
        }
        let v = best.0;
        todo.retain(|&(i, a, j, b)| !(v[i] == a && v[j] == b));
        out.push(point(&v));
    }
    out
}

/// `n` free draws.
pub fn random(seed: u64, n: usize) -> Vec<Point> {
    let mut d = Draw::new(seed ^ 0x5eed);
    (0..n)
        .map(|_| {
            let mut v = [0; 7];
            for (k, m) in DIMS.iter().enumerate() {
                v[k] = d.below(*m as u64) as usize;
            }
            point(&v)
        })
        .collect()
}

/// A mix at point `p` (TOML text), named `matrix-<seed>`; its rates,
/// inputs and link options drawn from `seed`.
pub fn mix(p: &Point, seed: u64) -> String {
    let mut d = Draw::new(seed);
    let mut t = format!(
        "name = \"matrix-{seed}\"\n[clock]\nhz = {}\n[frame]\nperiod_us = 2_000\nslice_us = 1_000\n",
        p.clock_mhz * 1_000_000
    );
    let modes = match p.modes {
        Modes::None => 0,
        _ => 2,
    };
    if modes > 0 {
        let select = if p.modes == Modes::Pin { "pin" } else { "auto" };
        let _ = write!(t, "[[mode]]\nname = \"rest\"\n[[mode]]\nname = \"busy\"\n[modes]\nselect = \"{select}\"\n");
    }
    if p.modes == Modes::Auto {
        // between a touch (1/32 below full scale) and the rest (1/64 of it)
        let full = 1u64 << p.converter.bits();
        let level = full / 4 + d.below(full / 2);
        let (n, low) = (1 + d.below(2), full / 16);
        let _ = write!(t, "[[trigger]]\nto = \"busy\"\nwhen = \"above\"\nlevel = {level}\nchannels = [\"A0\"]\n[[trigger]]\nto = \"rest\"\nwhen = \"below\"\nlevel = {low}\nchannels = [\"A0\"]\nfor_frames = {n}\n");
    }
    let branches: Vec<Converter> = std::iter::once(p.converter).chain(p.other).collect();
    for (b, c) in branches.iter().enumerate() {
        t.push_str(&branch(b, *c));
    }
    for (b, c) in branches.iter().enumerate() {
        channels(&mut t, &mut d, p, b, *c, modes);
    }
    t.push_str(&link(p.link, &mut d));
    t
}

/// Branch `b`'s table.
fn branch(b: usize, c: Converter) -> String {
    let name = ["a", "b"][b];
    let body = match c {
        Converter::Ad7940Mux => {
            "adc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 2\nsettle_ns = 1_000"
        }
        Converter::Ad7940Bare => "adc = \"ad7940\"\nmux = \"none\"",
        Converter::Mcp3208 => "adc = \"mcp3208\"\nmux = \"internal\"",
        Converter::Ad7689 => "adc = \"ad7689\"\nmux = \"internal\"",
        Converter::Ad7689Front => {
            "adc = \"ad7689\"\nmux = \"internal\"\nfront_mux = \"tmux1108\"\nsettle_ns = 1_000"
        }
    };
    format!("[[branch]]\nname = \"{name}\"\n{body}\n")
}

/// Channels per converter: one on a bare AD7940, else two to four.
fn count(c: Converter, d: &mut Draw) -> u64 {
    match c {
        Converter::Ad7940Bare => 1,
        _ => 2 + d.below(3),
    }
}

/// Branch `b`'s channels `A0..` / `B0..`: written out or as one bulk row,
/// rates per mode (the first channel of a branch sampled in every mode, so
/// every branch runs in the reset mode and the watched `A0` in all), the
/// last one of each branch in the sync group `s` when the point asks.
fn channels(t: &mut String, d: &mut Draw, p: &Point, b: usize, c: Converter, modes: usize) {
    let prefix = ["A", "B"][b];
    let n = count(c, d);
    let synced = p.sync && p.other.is_some();
    // a sync group's members share every rate: both branches' last channel
    // takes the same draw (drawn from the seed, not from `d`, so both agree)
    let sync_rates: Vec<u64> = (0..modes.max(1)).map(|m| [1_000, 2_000][m % 2]).collect();
    let mut rows = vec![];
    for k in 0..n {
        let rates: Vec<u64> = (0..modes.max(1))
            .map(|_| [0, 500, 1_000, 2_000][d.below(4) as usize])
            .map(|r| if k == 0 { r.max(1_000) } else { r })
            .collect();
        let last = synced && k == n - 1;
        rows.push((if last { sync_rates.clone() } else { rates }, last));
    }
    let base = |r: &[u64]| r.iter().copied().find(|&r| r > 0).unwrap_or(1_000);
    let input = |k: u64| match c {
        Converter::Ad7940Bare => None,
        Converter::Ad7689Front => Some(format!("input = 0\nfront_input = {}\n", k)),
        _ => Some(format!("input = {}\n", 7 - k)),
    };
    let rate_text = |r: &[u64]| {
        if modes == 0 {
            String::new()
        } else {
            format!("rates = {{ rest = {}, busy = {} }}\n", r[0], r[1])
        }
    };
    // a bulk row holds channels of one rate and no sync: the first channel
    // (sampled in every mode) stays a row of its own
    let bulk_from = if p.bulk && n > 2 { Some(1) } else { None };
    for (k, (r, last)) in rows.iter().enumerate() {
        let k = k as u64;
        if bulk_from == Some(k) {
            let end = if synced { n - 2 } else { n - 1 };
            if end > k {
                let _ = write!(
                    t,
                    "[[channel]]\nname = \"{prefix}{{{k}..{end}}}\"\nbranch = \"{}\"\nrate_hz = {}\n{}{}",
                    ["a", "b"][b],
                    base(r),
                    rate_text(r),
                    bulk_input(c, k)
                );
                continue;
            }
        }
        if bulk_from.is_some_and(|f| k > f && (!synced || k < n - 1)) {
            continue;
        }
        let _ = write!(
            t,
            "[[channel]]\nname = \"{prefix}{k}\"\nbranch = \"{}\"\nrate_hz = {}\n{}{}{}",
            ["a", "b"][b],
            base(r),
            rate_text(r),
            input(k).unwrap_or_default(),
            if *last { "sync = \"s\"\n" } else { "" }
        );
    }
}

/// The first input of a bulk row starting at channel `k` (counted up).
fn bulk_input(c: Converter, k: u64) -> String {
    match c {
        Converter::Ad7940Bare => String::new(),
        Converter::Ad7689Front => format!("input = 0\nfront_input = {k}\n"),
        // the row counts inputs up from its first: k.. (written-out
        // channels count down from 7, so these stay apart)
        _ => format!("input = {k}\n"),
    }
}

/// The `[link]` table.
fn link(l: Link, d: &mut Draw) -> String {
    match l {
        Link::None => String::new(),
        Link::Uart => {
            let parity = ["none", "even", "odd"][d.below(3) as usize];
            let stop = 1 + d.below(2);
            format!("[link]\nkind = \"uart\"\nbaud = 3_000_000\nparity = \"{parity}\"\nstop_bits = {stop}\n")
        }
        Link::Axis => {
            let tlast = ["slice", "frame"][d.below(2) as usize];
            let within = [1, 8, 64][d.below(3) as usize];
            format!("[link]\nkind = \"axis\"\ntlast = \"{tlast}\"\nready_within = {within}\n")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pair of two dimensions' values is in the pairwise draw.
    #[test]
    fn the_pairwise_draw_covers_every_pair() {
        let pts = pairwise(1);
        let vals = |p: &Point| {
            [
                CONVERTERS.iter().position(|c| *c == p.converter).unwrap(),
                OTHERS.iter().position(|c| *c == p.other).unwrap(),
                MODES.iter().position(|c| *c == p.modes).unwrap(),
                LINKS.iter().position(|c| *c == p.link).unwrap(),
                p.bulk as usize,
                p.sync as usize,
                CLOCKS.iter().position(|c| *c == p.clock_mhz).unwrap(),
            ]
        };
        for (i, &ni) in DIMS.iter().enumerate() {
            for (j, &nj) in DIMS.iter().enumerate().skip(i + 1) {
                for a in 0..ni {
                    for b in 0..nj {
                        assert!(
                            pts.iter().any(|p| vals(p)[i] == a && vals(p)[j] == b),
                            "dims {i}={a}, {j}={b}"
                        );
                    }
                }
            }
        }
        assert!(pts.len() < 40, "{}", pts.len());
        assert_eq!(pairwise(1), pts);
    }
}
