//! Random mixes with modes (TOML text) for the tests of every crate that
//! takes one, from one seeded xorshift (a seed always gives the same mix).
//! The judge may not see the campaign, so the generators live here.

use std::fmt::Write as _;

/// The tests' seeded xorshift: a seed always gives the same draws.
pub struct Draw(u64);

impl Draw {
    pub fn new(seed: u64) -> Self {
        Draw(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// The next draw, in `0..n`.
    pub fn below(&mut self, n: u64) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0 % n
    }
}

/// The harmonic rates a mode draws for a channel (0: not sampled).
pub const RATES: [u64; 4] = [0, 1_000, 2_000, 4_000];

/// `[[mode]]` tables `m0`.. and the `[modes]` select.
fn modes_section(t: &mut String, modes: usize, select: &str) {
    for m in 0..modes {
        let _ = write!(t, "[[mode]]\nname = \"m{m}\"\n");
    }
    let _ = write!(t, "[modes]\nselect = \"{select}\"\n");
}

/// `m0 = r0, m1 = r1, ..`: a channel's rates per mode.
fn per_mode(rates: &[u64]) -> String {
    let per: Vec<String> = (rates.iter().enumerate())
        .map(|(m, r)| format!("m{m} = {r}"))
        .collect();
    per.join(", ")
}

/// A random mix with 2 to 4 modes `m0`.. (pin or auto select), 1 to 3
/// branches `b0`.. (every one sampled in the reset mode; some modes may
/// leave one out), channels `c0`.. at harmonic rates per mode; under auto
/// select `c0` is watched (up from `m0` above a level, back to `m0` after
/// it is low for 1 to 3 frames) and sampled in every mode.  `None` when a
/// mode would sample nothing.
pub fn random_mode_mix(seed: u64) -> Option<String> {
    let mut d = Draw::new(seed);
    let mut next = move |n: u64| d.below(n);
    let modes = 2 + next(3) as usize;
    let auto = next(2) == 1;
    let nb = 1 + next(3) as usize;
    let mut t = format!(
        "name = \"random-modes-{seed}\"\n[clock]\nhz = 8_000_000\n[frame]\nperiod_us = 1_000\nslice_us = 500\n"
    );
    modes_section(&mut t, modes, if auto { "auto" } else { "pin" });
    if auto {
        let (to, level) = (1 + next(modes as u64 - 1), 4000 + next(8000));
        let _ = write!(t, "[[trigger]]\nto = \"m{to}\"\nfrom = \"m0\"\nwhen = \"above\"\nlevel = {level}\nchannels = [\"c0\"]\n");
        let n = 1 + next(3);
        let _ = write!(t, "[[trigger]]\nto = \"m0\"\nwhen = \"below\"\nlevel = 2000\nchannels = [\"c0\"]\nfor_frames = {n}\n");
    }
    for b in 0..nb {
        let _ = write!(t, "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 2\nsettle_ns = 500\n");
    }
    let n = nb + next(8) as usize;
    let mut used = vec![false; modes];
    for c in 0..n {
        let mut rates: Vec<u64> = (0..modes).map(|_| RATES[next(4) as usize]).collect();
        if c < nb {
            // every branch in the reset mode; c0 (watched) too
            rates[0] = rates[0].max(1_000);
        }
        if c == 0 && auto {
            rates.iter_mut().for_each(|r| *r = (*r).max(1_000));
        }
        for (m, r) in rates.iter().enumerate() {
            used[m] |= *r > 0;
        }
        let _ = write!(
            t,
            "[[channel]]\nname = \"c{c}\"\nbranch = \"b{}\"\ninput = {}\nrate_hz = 1_000\nrates = {{ {} }}\n",
            c % nb,
            c / nb + 8 * next(2) as usize,
            per_mode(&rates)
        );
    }
    used.iter().all(|&u| u).then_some(t)
}

/// The shape of a [`random_pin_mode_mix`]: what differs between the
/// tests that draw one.
pub struct PinShape {
    /// The `[clock]`, `[frame]` (and `[link]`) tables.
    pub header: &'static str,
    /// Mux devices on each of the two branches.
    pub mux_devices: u32,
    /// Channels: 2 plus a draw below this.
    pub more_channels: u64,
}

/// A random mix `random-modes` with 2 or 3 modes (pin select), 2 branches
/// and 2 or more channels at harmonic rates per mode (0: not sampled);
/// `None` when the draw leaves a mode sampling nothing.
pub fn random_pin_mode_mix(seed: u64, shape: &PinShape) -> Option<String> {
    let mut d = Draw::new(seed);
    let modes = 2 + d.below(2) as usize;
    let mut t = format!("name = \"random-modes\"\n{}", shape.header);
    modes_section(&mut t, modes, "pin");
    for b in 0..2 {
        let _ = write!(t, "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = {}\nsettle_ns = 500\n", shape.mux_devices);
    }
    let mut used = vec![false; modes];
    for c in 0..2 + d.below(shape.more_channels) as usize {
        let rates: Vec<u64> = (0..modes).map(|_| RATES[d.below(4) as usize]).collect();
        for (m, r) in rates.iter().enumerate() {
            used[m] |= *r > 0;
        }
        let _ = write!(
            t,
            "[[channel]]\nname = \"c{c}\"\nbranch = \"b{}\"\nrate_hz = 1_000\nrates = {{ {} }}\n",
            c % 2,
            per_mode(&rates)
        );
    }
    used.iter().all(|&u| u).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::random_mode_mix;

    /// Pin and auto mixes both come out, each with its modes scheduled.
    #[test]
    fn random_mode_mixes_of_both_selects_schedule() {
        let mut seen = (0, 0);
        for seed in 1..30 {
            let Some(t) = random_mode_mix(seed) else {
                continue;
            };
            assert_eq!(random_mode_mix(seed).as_deref(), Some(t.as_str()));
            let m = lut_gen::parse(std::path::Path::new("r.toml"), &t).unwrap();
            let Ok(s) = lut_gen::synthesize(&m) else {
                continue;
            };
            assert!(s.modes.len() >= 2, "{t}");
            match s.mode_plan().unwrap().select {
                lut_gen::ModeSelect::Pin => seen.0 += 1,
                lut_gen::ModeSelect::Auto => seen.1 += 1,
            }
        }
        assert!(seen.0 >= 4 && seen.1 >= 4, "{seen:?}");
    }
}
