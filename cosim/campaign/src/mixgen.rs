//! The one random-mix generator: feasible-looking mixes as TOML text, drawn
//! from a [`Shape`] with a seeded xorshift, so a seed always gives the same
//! mix.  The fault campaign's false-alarm runs use the default shape
//! ([`crate::faults::random_mix`]); `build`'s schedulability chart uses a
//! shape around the user's own mix ([`Shape::around`]).

use std::fmt::Write as _;

/// What random mixes are drawn from.
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    pub clock_hz: u64,
    pub frame_us: u64,
    pub slice_us: u64,
    /// Branch count, drawn from `lo..=hi`.
    pub branches: (u64, u64),
    /// Mux devices (8 inputs each) per branch, drawn from `lo..=hi`.
    pub mux_devices: (u64, u64),
    pub sclk_hz: Vec<u64>,
    pub settle_ns: Vec<u64>,
    /// Channel count, drawn from `lo..=hi` (a channel whose mux input is
    /// taken already is left out).
    pub channels: (u64, u64),
    pub rates_hz: Vec<u64>,
    /// Each branch is drawn without a multiplexer (`mux = "none"`, one
    /// channel) with probability 1 in `muxless`; 0: every branch has one
    /// (and the draw is the same as before the option existed).
    pub muxless: u64,
    /// Each branch (with a mux) is drawn with a converter that takes a
    /// command word (`mcp3208` or `ad7689`, `mux = "internal"`, its eight
    /// inputs) with probability 1 in `commanded`; 0: never (and the draw
    /// is the same as before the option existed).
    pub commanded: u64,
    /// A `[link]` drawn for every mix (none: no link).  Drawn after
    /// everything else, so a seed's branches and channels are the same
    /// with or without it.
    pub link: Option<LinkShape>,
}

/// Which links a random mix may get.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkShape {
    /// A UART at one of a few bauds (1 in 3 too slow for a busy mix: audit
    /// refuses it, as it would a user's), any parity and stop bits.
    Uart,
    /// AXI4-Stream with a drawn `tlast` and `ready_within`.
    Axis,
    /// Either, drawn per mix.
    Either,
}

impl Default for Shape {
    /// Small mixes of harmonic rates on a 2 ms frame: quick to run, and
    /// each one feasible unless the draw overloads a branch.
    fn default() -> Shape {
        Shape {
            clock_hz: 48_000_000,
            frame_us: 2_000,
            slice_us: 1_000,
            branches: (1, 3),
            mux_devices: (1, 3),
            sclk_hz: vec![2_500_000, 1_000_000, 2_000_000],
            settle_ns: vec![0, 1_000, 2_000, 5_000],
            channels: (2, 9),
            rates_hz: vec![500, 1_000, 2_000, 4_000, 8_000],
            muxless: 0,
            commanded: 0,
            link: None,
        }
    }
}

impl Shape {
    /// Mixes around `mix`: its clock, frame, slice, branch count and rates,
    /// with from one channel up to `max_channels` (enough to overload it).
    pub fn around(mix: &lut_gen::Mix, max_channels: u64) -> Shape {
        // a mix with modes: a channel its reset mode leaves out has rate 0
        // there, which no mix may ask for (every random mix drawn with it
        // was refused, and the chart had no point)
        let mut rates: Vec<u64> = (mix.channels.iter().map(|c| c.rate_hz))
            .filter(|&r| r > 0)
            .collect();
        rates.sort_unstable();
        rates.dedup();
        let nb = mix.branches.len() as u64;
        let per_branch = max_channels.div_ceil(nb.max(1));
        Shape {
            clock_hz: mix.clock_hz,
            frame_us: mix.frame_us,
            slice_us: mix.slice_us,
            branches: (nb, nb),
            // room for every channel a branch may get, with few input
            // clashes, within the mix format's 32 devices a branch (more
            // and no random mix parses: eskin34 asked for 36)
            mux_devices: (
                per_branch.div_ceil(4).clamp(1, 32),
                per_branch.div_ceil(4).clamp(1, 32),
            ),
            sclk_hz: vec![2_500_000],
            settle_ns: vec![1_000],
            channels: (1, max_channels.max(1)),
            rates_hz: rates,
            muxless: 0,
            commanded: 0,
            link: None,
        }
    }
}

/// The random mix of `seed` drawn from `shape`, as TOML text.
pub fn random_mix(seed: u64, shape: &Shape) -> String {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let pick = |v: u64, (lo, hi): (u64, u64)| lo + v % (hi - lo + 1);
    let nb = pick(next(), shape.branches);
    let mut t = format!(
        "name = \"random\"\n[clock]\nhz = {}\n[frame]\nperiod_us = {}\nslice_us = {}\n",
        shape.clock_hz, shape.frame_us, shape.slice_us
    );
    // inputs per branch: 8 per mux device, one without a mux
    let mut devs = Vec::new();
    for b in 0..nb {
        let d = pick(next(), shape.mux_devices);
        let sclk = shape.sclk_hz[(next() % shape.sclk_hz.len() as u64) as usize];
        let settle = shape.settle_ns[(next() % shape.settle_ns.len() as u64) as usize];
        if shape.muxless > 0 && next() % shape.muxless == 0 {
            devs.push(1);
            let _ = write!(
                t,
                "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nsclk_hz = {sclk}\nmux = \"none\"\n"
            );
            continue;
        }
        if shape.commanded > 0 && next() % shape.commanded == 0 {
            devs.push(8);
            let adc = ["mcp3208", "ad7689"][(next() % 2) as usize];
            let _ = write!(
                t,
                "[[branch]]\nname = \"b{b}\"\nadc = \"{adc}\"\nmux = \"internal\"\n"
            );
            continue;
        }
        devs.push(d * 8);
        let _ = write!(
            t,
            "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nsclk_hz = {sclk}\nmux = \"tmux1108\"\nmux_devices = {d}\nsettle_ns = {settle}\n"
        );
    }
    let n = pick(next(), shape.channels);
    let mut used = std::collections::BTreeSet::new();
    for i in 0..n {
        let b = next() % nb;
        let input = next() % devs[b as usize];
        if !used.insert((b, input)) {
            continue;
        }
        let rate = shape.rates_hz[(next() % shape.rates_hz.len() as u64) as usize];
        let _ = write!(
            t,
            "[[channel]]\nname = \"c{i}\"\nbranch = \"b{b}\"\nrate_hz = {rate}\ninput = {input}\n"
        );
    }
    if let Some(l) = shape.link {
        t.push_str(&link_table(l, &mut next));
    }
    t
}

/// A `[link]` table of shape `l`, drawn with `next`.
fn link_table(l: LinkShape, next: &mut impl FnMut() -> u64) -> String {
    let axis = match l {
        LinkShape::Uart => false,
        LinkShape::Axis => true,
        LinkShape::Either => next() % 2 == 1,
    };
    if axis {
        let tlast = ["slice", "frame"][(next() % 2) as usize];
        let within = [1, 2, 4, 16, 64][(next() % 5) as usize];
        format!("[link]\nkind = \"axis\"\ntlast = \"{tlast}\"\nready_within = {within}\n")
    } else {
        let baud = [3_000_000, 6_000_000, 12_000_000][(next() % 3) as usize];
        let parity = ["none", "even", "odd"][(next() % 3) as usize];
        let stop = 1 + next() % 2;
        format!(
            "[link]\nkind = \"uart\"\nbaud = {baud}\nparity = \"{parity}\"\nstop_bits = {stop}\n"
        )
    }
}
