//! Shared test support: mixes, a behavioural AD7940 and an independent
//! per-cycle prediction written from docs/timing.md (not from the gateware).
#![allow(dead_code)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use lut_gen::Pins;
use lut_gen::Schedule;

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

pub fn eskin34() -> Schedule {
    let mix = lut_gen::load(&root().join("mixes/eskin34.toml")).expect("eskin34 loads");
    lut_gen::synthesize(&mix).expect("eskin34 is feasible")
}

/// The schedule of mix `text`, as if read from the file `name` (which
/// only names it in messages).
pub fn from_toml(name: &str, text: &str) -> Schedule {
    let mix = lut_gen::parse(Path::new(name), text).expect("mix parses");
    lut_gen::synthesize(&mix).expect("mix is feasible")
}

/// The smallest mix: one branch, one channel.
pub fn tiny() -> Schedule {
    from_toml(
        "tiny.toml",
        r#"
name = "tiny"
[clock]
hz = 12_000_000
[frame]
period_us = 1_000
slice_us = 1_000
[[branch]]
name = "only"
adc = "ad7940"
mux = "tmux1108"
mux_devices = 1
[[channel]]
name = "A"
branch = "only"
rate_hz = 1_000
"#,
    )
}

/// Eight branches, several mux devices, mixed rates.
pub fn wide() -> Schedule {
    let mut t = String::from(
        r#"
name = "wide8"
[clock]
hz = 24_000_000
[frame]
period_us = 10_000
slice_us = 1_000
"#,
    );
    let devices = [3, 1, 2, 1, 4, 1, 2, 1];
    for (b, d) in devices.iter().enumerate() {
        t.push_str(&format!(
            "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = {d}\n"
        ));
    }
    let rates = [1_000u64, 2_000, 500, 100, 4_000, 200];
    let mut n = 0;
    for (b, d) in devices.iter().enumerate() {
        let count = (d * 8).min(3 + 2 * b);
        for k in 0..count {
            let rate = rates[(b + k) % rates.len()];
            // spread the inputs over all of the branch's devices (distinct)
            let input = k * (d * 8) / count;
            t.push_str(&format!(
                "[[channel]]\nname = \"C{n}\"\nbranch = \"b{b}\"\nrate_hz = {rate}\ninput = {input}\n"
            ));
            n += 1;
        }
    }
    from_toml("wide8.toml", &t)
}

/// Three branches with three SPI timings (three sequencers) and settling
/// times: 2.5 MHz, 1 MHz and 2 MHz SCLK.
pub fn two_speed() -> Schedule {
    let mut t = String::from(
        r#"
name = "threespeed"
[clock]
hz = 48_000_000
[frame]
period_us = 10_000
slice_us = 1_000
"#,
    );
    for (b, (sclk, settle, d)) in [
        (2_500_000u64, 0u64, 2u32),
        (1_000_000, 5_000, 1),
        (2_000_000, 1_000, 3),
    ]
    .iter()
    .enumerate()
    {
        t.push_str(&format!(
            "[[branch]]\nname = \"s{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = {d}\nsclk_hz = {sclk}\nsettle_ns = {settle}\n"
        ));
    }
    let rates = [2_000u64, 1_000, 100, 1_000, 500];
    let mut n = 0;
    for (b, d) in [2usize, 1, 3].iter().enumerate() {
        for k in 0..(3 + b) {
            t.push_str(&format!(
                "[[channel]]\nname = \"T{n}\"\nbranch = \"s{b}\"\nrate_hz = {}\ninput = {}\n",
                rates[(n) % rates.len()],
                (k * 5) % (d * 8)
            ));
            n += 1;
        }
    }
    from_toml("threespeed.toml", &t)
}

/// `hdl/tests/data/longframe.toml`: a frame of 200 ms with 5 Hz channels
/// and 40 slots per slice: 8000 slots, more than the full-frame ROM takes,
/// so the compact LUT is chosen.  A slow clock (8 MHz) keeps simulating
/// whole frames cheap.
pub fn long_frame() -> Schedule {
    data_mix("longframe")
}

/// `hdl/tests/data/longslot.toml`: one 1 kHz channel alone at 100 MHz, one
/// slot of 100 000 cycles per slice, beyond a 16-bit slot counter.
pub fn long_slot() -> Schedule {
    data_mix("longslot")
}

/// A mix file of `hdl/tests/data/`.
pub fn data_mix(name: &str) -> Schedule {
    let path = root().join(format!("hdl/tests/data/{name}.toml"));
    let mix = lut_gen::load(&path).expect("mix loads");
    lut_gen::synthesize(&mix).expect("mix is feasible")
}

/// [`data_mix`] with its clock at `hz` (fewer cycles a frame for the same
/// channels, slots and tables; the file's `hz = ` line replaced).
pub fn data_mix_at(name: &str, hz: u64) -> Schedule {
    let path = root().join(format!("hdl/tests/data/{name}.toml"));
    let text = std::fs::read_to_string(&path).expect("mix reads");
    let line = text
        .lines()
        .find(|l| l.starts_with("hz = "))
        .expect("a clock");
    let text = text.replace(line, &format!("hz = {hz}"));
    let mix = lut_gen::parse(&path, &text).expect("mix parses");
    lut_gen::synthesize(&mix).expect("mix is feasible")
}

/// Behavioural AD7940 (datasheet timing in cycles): the input is sampled at
/// the CS falling edge; bit 0 (a leading zero) appears t3 after CS falls,
/// bit i t4 after SCLK falling edge i; old data is held for t7; after falling
/// edge 16 the output floats.  Undefined windows return pseudo-random bits,
/// so a master sampling at the wrong time reads garbage.
pub struct Adc {
    /// cycles after a falling edge until the new bit is valid (t4, rounded up)
    access: u64,
    /// cycles after a falling edge during which the old bit is still valid (t7, rounded down)
    hold: u64,
    lane: Lane,
    rng: u64,
    pub conversions: Vec<(u64, u16)>,
}

#[derive(Default, Clone, Copy)]
struct Lane {
    prev_cs: bool,
    prev_sclk: bool,
    active: bool,
    word: u16,
    bit: u32,
    last_fall: u64,
    float: bool,
}

impl Adc {
    pub fn new(clock_hz: u64, seed: u64) -> Adc {
        let part = lut_gen::AdcPart::ad7940();
        Adc {
            access: lut_gen::ns_to_cycles(part.data_access_ns, clock_hz),
            hold: part.data_hold_ns * clock_hz / 1_000_000_000,
            lane: Lane {
                prev_cs: true,
                prev_sclk: true,
                ..Default::default()
            },
            rng: seed | 1,
            conversions: vec![],
        }
    }

    fn noise(&mut self) -> bool {
        self.rng ^= self.rng << 13;
        self.rng ^= self.rng >> 7;
        self.rng ^= self.rng << 17;
        self.rng & 1 == 1
    }

    /// The code the ADC converts at cycle `c` on a given channel.
    pub fn code(channel: usize, c: u64) -> u16 {
        let x = (channel as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ c.wrapping_mul(0xD6E8_FEB8_6659_FD93);
        ((x >> 29) & 0x3fff) as u16
    }

    /// Given the pins of cycle `c`, return MISO during cycle `c`.
    /// `channel` is the channel selected by the mux in this cycle.
    pub fn cycle(&mut self, c: u64, cs_n: bool, sclk: bool, channel: Option<usize>) -> bool {
        let mut l = self.lane;
        if l.prev_cs && !cs_n {
            let code = Self::code(channel.unwrap_or(usize::MAX >> 8), c);
            l.active = true;
            l.word = code; // 16-bit word: 00 + 14-bit code
            l.bit = 0;
            l.last_fall = c;
            l.float = false;
            self.conversions.push((c, code));
        }
        if !cs_n && l.active && l.prev_sclk && !sclk {
            l.bit += 1;
            l.last_fall = c;
            if l.bit >= 16 {
                l.float = true;
            }
        }
        if cs_n {
            l.active = false;
        }
        l.prev_cs = cs_n;
        l.prev_sclk = sclk;
        self.lane = l;
        if !l.active || l.float {
            return self.noise();
        }
        let since = c - l.last_fall;
        let bit_of = |i: u32| (l.word >> (15 - i)) & 1 == 1;
        if since >= self.access {
            bit_of(l.bit)
        } else if since < self.hold && l.bit > 0 {
            bit_of(l.bit - 1)
        } else {
            self.noise()
        }
    }
}

/// Which channel of a branch the mux pins address (None if no device is
/// enabled), looked up in tables made once per run: a scan of every
/// channel for every branch in every cycle was most of a 256-channel run.
pub struct Selector {
    branches: Vec<BranchMux>,
}

/// A branch's first bit of `mux_en`, its devices, and the channel at each
/// (device, select input).
struct BranchMux {
    off: usize,
    devices: usize,
    at: HashMap<(u32, u32), usize>,
}

impl Selector {
    pub fn new(s: &Schedule) -> Selector {
        let mut off = 0;
        let branches = (0..s.branches.len())
            .map(|b| {
                let n = s.branches[b].mux_devices as usize;
                let mut at = HashMap::new();
                for (i, c) in s.channels.iter().enumerate() {
                    if s.mix.channels[i].branch == b {
                        // the first of two channels on one input, as a scan finds it
                        at.entry((c.device, c.select)).or_insert(i);
                    }
                }
                off += n;
                BranchMux {
                    off: off - n,
                    devices: n,
                    at,
                }
            })
            .collect();
        Selector { branches }
    }

    /// Branch `b`'s bits of `mux_en` in `pins`.
    pub fn enables(&self, b: usize, pins: &Pins) -> u128 {
        let m = &self.branches[b];
        (pins.mux_en >> m.off) & ((1u128 << m.devices) - 1)
    }

    /// The channel branch `b`'s mux pins address in `pins`.
    pub fn selected(&self, b: usize, pins: &Pins) -> Option<usize> {
        let en = self.enables(b, pins);
        if en.count_ones() != 1 {
            return None;
        }
        let dev = en.trailing_zeros();
        let sel = ((pins.mux_sel >> (3 * b)) & 7) as u32;
        self.branches[b].at.get(&(dev, sel)).copied()
    }
}

/// docs/timing.md, literally: the pins (except the sample stream) in cycle `c`.
pub struct Reference<'a> {
    s: &'a Schedule,
    /// per branch: instant slots in the frame
    inst: Vec<Vec<u64>>,
}

impl<'a> Reference<'a> {
    pub fn new(s: &'a Schedule) -> Self {
        let inst = (0..s.branches.len())
            .map(|b| {
                (0..s.grid.frame_slots)
                    .filter(|&t| s.at(t, b).is_some())
                    .collect()
            })
            .collect();
        Reference { s, inst }
    }

    /// The instant of branch `b` whose conversion window contains `c`.
    pub fn instant_covering(&self, b: usize, c: u64) -> Option<u64> {
        let g = &self.s.grid;
        let spi = &self.s.branches[b].spi;
        // every instant is a slot start; windows are shorter than a slot but
        // check the previous slot too, to not rely on that
        let slot_abs = c / g.slot_cycles;
        for back in 0..2u64 {
            if slot_abs < back {
                continue;
            }
            let sa = slot_abs - back;
            let t = sa * g.slot_cycles;
            // "Start-up": an instant the mux cannot have settled for since
            // the first reset edge (one cycle before cycle 0) is skipped
            let settled = t + 1 >= self.s.branches[b].settle_cycles;
            if self.s.at(sa % g.frame_slots, b).is_some()
                && settled
                && t <= c
                && c < t + spi.read_cycles
            {
                return Some(t);
            }
        }
        None
    }

    /// First instant t' >= c of branch b, with its channel.
    pub fn next_instant(&self, b: usize, c: u64) -> Option<(u64, usize)> {
        let g = &self.s.grid;
        let first_slot = c.div_ceil(g.slot_cycles);
        let list = &self.inst[b];
        if list.is_empty() {
            return None;
        }
        let f = first_slot / g.frame_slots;
        let within = first_slot % g.frame_slots;
        // the list is in slot order: a binary search, not a scan per cycle
        let (frame, slot) = match list.get(list.partition_point(|&t| t < within)) {
            Some(&t) => (f, t),
            None => (f + 1, list[0]),
        };
        let t = frame * g.frame_cycles + slot * g.slot_cycles;
        Some((t, self.s.at(slot, b).unwrap()))
    }

    /// (cs_n, sclk, mux_sel, mux_en) in cycle c.
    pub fn pins(&self, c: u64) -> (u16, u16, u64, u128) {
        let (mut cs, mut sclk, mut sel, mut en) = (0u16, 0u16, 0u64, 0u128);
        let mut off = 0;
        for (b, bp) in self.s.branches.iter().enumerate() {
            let spi = &bp.spi;
            let mut cs_b = 1;
            let mut sclk_b = 1;
            if let Some(t) = self.instant_covering(b, c) {
                cs_b = 0;
                let j = c - t;
                if j >= spi.setup_cycles && (j - spi.setup_cycles) % spi.sclk_div < spi.sclk_half {
                    sclk_b = 0;
                }
            }
            cs |= cs_b << b;
            sclk |= sclk_b << b;
            if let Some((_, ch)) = self.next_instant(b, c) {
                let cc = &self.s.channels[ch];
                sel |= (cc.select as u64) << (3 * b);
                en |= 1u128 << (off + cc.device as usize);
            }
            off += bp.mux_devices as usize;
        }
        (cs, sclk, sel, en)
    }
}

/// Run `cycles` cycles after `reset_cycles` of reset with one ADC model per
/// branch; compare every pin with the reference in every cycle and return
/// (pins per cycle is not kept) the list of (cycle, channel, value) samples
/// and the ADC conversions per branch.
pub struct Run {
    pub samples: Vec<(u64, u16, u16)>,
    pub adcs: Vec<Adc>,
    pub instants: Vec<(u64, usize, Option<usize>)>,
}

pub fn run_and_compare(s: &Schedule, cycles: u64) -> Run {
    run_and_compare_with(s, cycles, hdl::LutForm::Auto)
}

pub fn run_and_compare_with(s: &Schedule, cycles: u64, form: hdl::LutForm) -> Run {
    let reference = Reference::new(s);
    let mut sim = hdl::RtlSim::with_form(s, form).expect("gateware for the mix");
    let nb = s.branches.len();
    let mut adcs: Vec<Adc> = (0..nb)
        .map(|b| Adc::new(s.grid.clock_hz, 0x1234 + b as u64))
        .collect();
    // reset: several cycles, outputs must be the reset values
    let mut miso = 0u64;
    for _ in 0..3 {
        let p = sim.step(true, miso);
        let all = ((1u32 << nb) - 1) as u16;
        assert_eq!(p.cs_n, all, "cs_n during reset");
        assert_eq!(p.sclk, all, "sclk during reset");
        assert!(!p.sample_valid && p.sample_channel == 0 && p.sample_value == 0);
        let (_, _, sel, en) = reference.pins(0);
        assert_eq!(
            (p.mux_sel, p.mux_en),
            (sel, en),
            "mux during reset addresses the first instants"
        );
        miso = 0;
    }
    let mut samples = vec![];
    let mut instants = vec![];
    let mut prev_cs = ((1u32 << nb) - 1) as u16;
    // sample stream reference: per branch completion queue
    let mut pending: Vec<Option<(usize, u16)>> = vec![None; nb];
    let mut expect_next: Option<(usize, u16)> = None;
    let mut last_sample = (0u16, 0u16);
    let mut inflight: Vec<Option<(usize, u16, u64)>> = vec![None; nb];
    let selector = Selector::new(s);
    for c in 0..cycles {
        let p = sim.step(false, miso);
        let (cs, sclk, sel, en) = reference.pins(c);
        assert_eq!(p.cs_n, cs, "cs_n in cycle {c}");
        assert_eq!(p.sclk, sclk, "sclk in cycle {c}");
        assert_eq!(p.mux_sel, sel, "mux_sel in cycle {c}");
        assert_eq!(p.mux_en, en, "mux_en in cycle {c}");
        for b in 0..nb {
            let en_b = selector.enables(b, &p);
            assert!(
                en_b.count_ones() <= 1,
                "two devices of branch {b} enabled in cycle {c}"
            );
        }
        // sample stream per docs/timing.md
        match expect_next.take() {
            Some((ch, v)) => {
                assert!(p.sample_valid, "sample_valid in cycle {c}");
                assert_eq!(
                    (p.sample_channel as usize, p.sample_value),
                    (ch, v),
                    "sample in cycle {c}"
                );
                last_sample = (ch as u16, v);
                samples.push((c, ch as u16, v));
            }
            None => {
                assert!(!p.sample_valid, "no sample expected in cycle {c}");
                assert_eq!(
                    (p.sample_channel, p.sample_value),
                    last_sample,
                    "held sample in cycle {c}"
                );
            }
        }
        // ADCs see this cycle's pins and drive MISO during it
        let mut m = 0u64;
        for b in 0..nb {
            let cs_b = (p.cs_n >> b) & 1 == 1;
            let sclk_b = (p.sclk >> b) & 1 == 1;
            let fell = (prev_cs >> b) & 1 == 1 && !cs_b;
            let ch = selector.selected(b, &p);
            if fell {
                instants.push((c, b, ch));
            }
            if adcs[b].cycle(c, cs_b, sclk_b, ch) {
                m |= 1 << b;
            }
            if fell {
                let code = adcs[b].conversions.last().unwrap().1;
                inflight[b] = Some((ch.expect("a channel is selected at the instant"), code, c));
            }
            // completion in cycle c = t + R
            if let Some((ch, code, t)) = inflight[b] {
                if c == t + s.branches[b].spi.read_cycles {
                    pending[b] = Some((ch, code));
                    inflight[b] = None;
                }
            }
        }
        if let Some(b) = (0..nb).find(|&b| pending[b].is_some()) {
            expect_next = pending[b].take();
        }
        prev_cs = p.cs_n;
        miso = m;
    }
    Run {
        samples,
        adcs,
        instants,
    }
}
