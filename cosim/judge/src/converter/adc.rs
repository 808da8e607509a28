//! ADC models from the part data (`lut_gen::AdcPart`):
//!
//! - CS parts (AD7940): sample the analog input the branch's mux selects at
//!   the CS falling edge (a part that holds its input later in its
//!   transaction, the MCP3208, takes its input's value at that instant,
//!   `Schedule::sample_after`) and shift the word out on MISO (the leading bits as
//!   zeros, then the code MSB first), one bit per SCLK falling edge;
//! - CNV parts (AD7685, chain mode): every part of the chain samples its own
//!   input at the CNV rising edge; the chain then shifts all words out of the
//!   part nearest the host (member 0 first), MSB first, one bit per SCK
//!   falling edge; after the last word the first part's SDI (tied low)
//!   follows, so the line reads 0.
//!
//! - parts with a command word (MCP3208, AD7689): the part latches DIN
//!   (`adc_mosi`) on each rising SCLK edge of the read; the word selects the
//!   input of the same conversion (`ahead` 0: the part samples once the word
//!   is in, before its first data bit) or of the conversion `ahead` later (a
//!   pipeline; the first `ahead` conversions after reset, and any conversion
//!   whose word was malformed, convert an input no channel is on).
//!
//! Datasheet edges (the AD7940's): bit 0 is driven after CS
//! falls, bit `i` after SCLK falling edge `i`, the line is invalid from 10 ns
//! (t7, hold) to 80..120 ns (t4, access) after each falling edge and high-Z
//! from 45 ns (t8) after falling edge 16.  [`Adc::drive`] works at cycle level
//! (a bit is valid for the whole cycle after the edge; high-Z reads as 1, a
//! weak pull-up).

use std::f64::consts::PI;

use lut_gen::Schedule;

use lut_gen::{Layout, Pins};

/// What each analog input carries.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Stimulus {
    /// A code unique per (channel, slot) over any window of 16384 / channels slots.
    #[default]
    Pattern,
    /// A sine per channel: at the given frequency in Hz on every channel
    /// (`sine:600`; any frequency, also above a channel's Nyquist limit, so
    /// that aliasing can be seen), or with `None` (`sine`) at a
    /// channel-specific frequency below its Nyquist limit.
    Sine(Option<f64>),
    /// A square wave per channel (steps between two channel-specific levels).
    Step,
    /// A linear chirp per channel from 0 to its Nyquist frequency over each frame.
    Chirp,
    /// Contact on named channels (`touch:` / `stroke:`, [`Scene`]); built
    /// with [`Stimulus::parse_for`], which needs the mix's channel names.
    Scene(&'static Scene),
}

/// A scene of contact: the named channels are pressed (codes near full
/// scale) inside frames `[from, to)` and low outside; a stroke presses them
/// one after the other, each for an equal share of the interval (seed 003's
/// Figure 11: a finger sliding over a row of taxels).  Every other channel
/// stays low.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Scene {
    pub stroke: bool,
    /// Channel indices, in the order given.
    pub channels: Vec<usize>,
    pub from: u64,
    pub to: u64,
}

impl Scene {
    /// Whether channel `id` is pressed in `cycle` (frames of `frame_cycles`).
    fn pressed(&self, id: usize, cycle: u64, frame_cycles: u64) -> bool {
        let (a, b) = (self.from * frame_cycles, self.to * frame_cycles);
        if cycle < a || cycle >= b {
            return false;
        }
        let Some(k) = self.channels.iter().position(|&c| c == id) else {
            return false;
        };
        if !self.stroke {
            return true;
        }
        let n = self.channels.len() as u64;
        let share = (cycle - a) * n / (b - a);
        share == k as u64
    }

    /// The `bits`-bit code of channel `id` in `cycle`: pressed, 1/32 below
    /// full scale; else 1/64 of it (a few codes apart per channel).
    fn code(&self, id: u64, cycle: u64, frame_cycles: u64, bits: u32) -> u16 {
        let full = (1u32 << bits) - 1;
        let v = if self.pressed(id as usize, cycle, frame_cycles) {
            full - full / 32 - (id % 8) as u32
        } else {
            full / 64 + (id % 8) as u32
        };
        v as u16
    }
}

impl Stimulus {
    /// A stimulus as the command line writes it, with `touch:NAMES@FROM-TO`
    /// and `stroke:NAMES@FROM-TO` (NAMES: channel names or bulk patterns,
    /// comma-separated; FROM-TO: frames, TO exclusive) resolved against the
    /// mix.  The scene lives as long as the program: a stimulus is `Copy`.
    pub fn parse_for(text: &str, s: &Schedule) -> Result<Stimulus, String> {
        let (stroke, rest) = match (text.strip_prefix("touch:"), text.strip_prefix("stroke:")) {
            (Some(r), _) => (false, r),
            (_, Some(r)) => (true, r),
            _ => return text.parse(),
        };
        let (names, span) = rest.rsplit_once('@').ok_or_else(|| {
            format!("stimulus `{text}`: NAMES@FROM-TO expected (e.g. touch:T0,T1@4-12, frames)")
        })?;
        let (a, b) = span
            .split_once('-')
            .and_then(|(a, b)| Some((a.trim().parse::<u64>().ok()?, b.trim().parse::<u64>().ok()?)))
            .filter(|(a, b)| a < b)
            .ok_or_else(|| {
                format!(
                    "stimulus `{text}`: `{span}` is not FROM-TO, two frame numbers with FROM < TO"
                )
            })?;
        let mut channels = Vec::new();
        for written in names.split(',').map(str::trim) {
            for name in
                lut_gen::expand_names(written).map_err(|e| format!("stimulus `{text}`: {e}"))?
            {
                let c = s
                    .mix
                    .channels
                    .iter()
                    .position(|c| c.name == name)
                    .ok_or_else(|| {
                        format!(
                            "stimulus `{text}`: mix `{}` has no channel named `{name}`",
                            s.mix.name
                        )
                    })?;
                if !channels.contains(&c) {
                    channels.push(c);
                }
            }
        }
        let scene = Scene {
            stroke,
            channels,
            from: a,
            to: b,
        };
        Ok(Stimulus::Scene(Box::leak(Box::new(scene))))
    }
}

impl std::str::FromStr for Stimulus {
    type Err = String;
    fn from_str(s: &str) -> Result<Stimulus, String> {
        if let Some(hz) = s.strip_prefix("sine:") {
            let f: f64 = hz.trim().parse().map_err(|_| {
                format!(
                    "stimulus `{s}`: `{hz}` is not a frequency in Hz (e.g. sine:600, sine:1.5e3)"
                )
            })?;
            if !f.is_finite() || f <= 0.0 {
                return Err(format!(
                    "stimulus `{s}`: the frequency must be a positive number of Hz"
                ));
            }
            return Ok(Stimulus::Sine(Some(f)));
        }
        match s {
            "pattern" => Ok(Stimulus::Pattern),
            "sine" => Ok(Stimulus::Sine(None)),
            "step" => Ok(Stimulus::Step),
            "chirp" => Ok(Stimulus::Chirp),
            _ => Err(format!(
                "unknown stimulus `{s}` (pattern, sine, sine:HZ, step, chirp, touch:NAMES@FROM-TO, stroke:NAMES@FROM-TO)"
            )),
        }
    }
}

/// The analog world: the code each channel's input converts to at any instant.
#[derive(Debug, Clone)]
pub struct Analog {
    pub kind: Stimulus,
    channels: u64,
    slot_cycles: u64,
    frame_cycles: u64,
    clock_hz: f64,
    /// Per channel: signal frequency for sine/step, Nyquist frequency for chirp.
    freq: Vec<f64>,
}

impl Analog {
    pub fn new(s: &Schedule, kind: Stimulus) -> Analog {
        let freq = s
            .mix
            .channels
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let nyq = c.rate_hz as f64 / 2.0;
                match kind {
                    Stimulus::Chirp => nyq,
                    Stimulus::Sine(Some(f)) => f,
                    _ => {
                        c.bandwidth_hz.unwrap_or(nyq / 4.0).min(nyq * 0.9)
                            * (0.5 + 0.5 * ((i % 7) as f64 / 7.0))
                    }
                }
            })
            .collect();
        Analog {
            kind,
            channels: s.channels.len() as u64,
            slot_cycles: s.grid.slot_cycles,
            frame_cycles: s.grid.frame_cycles,
            clock_hz: s.grid.clock_hz as f64,
            freq,
        }
    }

    /// The `bits`-bit code input `id` converts to when sampled in cycle
    /// `cycle` (the 14-bit [`Analog::code`] for 14 bits).
    #[inline]
    pub fn code_bits(&self, id: u64, cycle: u64, bits: u32) -> u16 {
        if let Stimulus::Scene(sc) = self.kind {
            if id < self.channels {
                return sc.code(id, cycle, self.frame_cycles, bits);
            }
        }
        if bits == 14 {
            return self.code(id, cycle);
        }
        let mask = ((1u32 << bits) - 1) as u16;
        if matches!(self.kind, Stimulus::Pattern | Stimulus::Scene(_)) || id >= self.channels {
            let n = (cycle / self.slot_cycles) * (self.channels + 64) + id;
            return (n.wrapping_mul(0x2F5B).wrapping_add(0x1A5) as u16) & mask;
        }
        let c = self.code(id, cycle) as u32;
        (if bits > 14 {
            c << (bits - 14)
        } else {
            c >> (14 - bits)
        }) as u16
            & mask
    }

    /// The 14-bit code input `id` converts to when sampled in cycle `cycle`.
    /// `id < channels` is a channel; larger ids are unconnected inputs.
    #[inline]
    pub fn code(&self, id: u64, cycle: u64) -> u16 {
        if let (Stimulus::Scene(sc), true) = (self.kind, id < self.channels) {
            return sc.code(id, cycle, self.frame_cycles, 14);
        }
        if matches!(self.kind, Stimulus::Pattern | Stimulus::Scene(_)) || id >= self.channels {
            let n = (cycle / self.slot_cycles) * (self.channels + 64) + id;
            return ((n.wrapping_mul(0x2F5B) + 0x1A5) & 0x3fff) as u16;
        }
        let i = id as usize;
        let t = cycle as f64 / self.clock_hz;
        let x = match self.kind {
            Stimulus::Sine(_) => (2.0 * PI * self.freq[i] * t + i as f64).sin(),
            Stimulus::Step => {
                if (self.freq[i] * t).fract() < 0.5 {
                    -0.8 + 0.02 * (i % 10) as f64
                } else {
                    0.8 - 0.02 * (i % 10) as f64
                }
            }
            Stimulus::Chirp => {
                let tf = (cycle % self.frame_cycles) as f64 / self.clock_hz;
                let span = self.frame_cycles as f64 / self.clock_hz;
                (PI * self.freq[i] / span * tf * tf).sin()
            }
            Stimulus::Pattern | Stimulus::Scene(_) => unreachable!(),
        };
        (8192.0 + 8000.0 * x).round().clamp(0.0, 16383.0) as u16
    }

    /// The id of the input a branch's mux pins select (unconnected inputs and
    /// an invalid enable get ids beyond the channels).
    pub fn input_id(&self, layout: &Layout, p: &Pins, b: usize) -> u64 {
        match layout.selected(p, b) {
            Ok(ch) => ch as u64,
            Err(_) => {
                let en = layout.en(p, b);
                self.channels
                    + 1
                    + ((b as u64 * 64 + en.trailing_zeros() as u64 * 8 + layout.sel(p, b) as u64)
                        % 63)
            }
        }
    }
}

#[derive(Debug, Clone, Default)]
struct AdcState {
    /// The serial stream of the conversion, first bit in the top of `len` bits.
    stream: u128,
    len: u32,
    falls: u32,
    /// DIN bits latched in this read (first in the top) and their count.
    din: u64,
    nin: u32,
    /// Parts with a command word `ahead` > 0: the input each coming
    /// conversion converts (`None`: no word of ours selected it).
    queue: std::collections::VecDeque<Option<u32>>,
    /// The cycle of this conversion's start.
    t: u64,
}

/// One branch's part(s), as the model needs them.
#[derive(Debug, Clone)]
struct PartModel {
    cnv: bool,
    /// Read with CNV low: the conversion starts at CNV rising and the part
    /// drives SDO and latches DIN only while CNV is low.
    low_read: bool,
    bits: u32,
    leading: u32,
    word_sclks: u32,
    /// Per lead channel: the channel of each chain member.
    groups: Vec<Vec<Option<usize>>>,
    chain: u32,
    command: Option<lut_gen::Command>,
    /// Input of the converter's own multiplexer -> channel on this branch
    /// (wired straight).
    inputs: Vec<Option<u16>>,
    /// Behind a front mux: per converter input wired to it, front input
    /// (device * 8 + select) -> channel; empty for a straight input.
    front: Vec<std::collections::BTreeMap<u32, u16>>,
    /// Cycles from the conversion's start to the instant the part holds
    /// its input (`SpiTiming::sample_cycles`; `Schedule::sample_after`
    /// counts from the slot tick, a hold-off earlier): the input is sampled there.
    after: u64,
}

/// The ADCs of all branches, at cycle level.
#[derive(Debug, Clone)]
pub struct Adc {
    pub analog: Analog,
    layout: Layout,
    st: Vec<AdcState>,
    parts: Vec<PartModel>,
    /// The CS-active-low view: "selected" is low (CNV lanes held high
    /// through the read inverted; a CNV read with CNV low is selected
    /// while low, as it is), SCLK's shifting edge a fall (CNV lanes inverted).
    flip: u16,
    flip_sclk: u16,
    /// Lanes read with CNV low: their conversion starts when the view rises.
    low_read: u16,
    prev_cs: u16,
    prev_sclk: u16,
    miso: u64,
}

impl Adc {
    pub fn new(s: &Schedule, kind: Stimulus) -> Adc {
        let nb = s.branches.len();
        let all = ((1u32 << nb) - 1) as u16;
        let parts: Vec<PartModel> = s
            .mix
            .branches
            .iter()
            .map(|b| PartModel {
                cnv: b.adc.start == lut_gen::Start::Cnv,
                low_read: b.adc.start == lut_gen::Start::Cnv
                    && b.adc.read == lut_gen::CnvRead::CnvLow,
                bits: b.adc.bits,
                leading: b.adc.leading_bits,
                word_sclks: b.adc.word_sclks(),
                groups: s.groups.clone(),
                chain: b.chain,
                command: b.adc.command.clone(),
                inputs: Vec::new(),
                front: Vec::new(),
                after: 0,
            })
            .collect();
        let mut parts = parts;
        let layout = Layout::new(s);
        for (b, pm) in parts.iter_mut().enumerate() {
            pm.after = s.branches[b].spi.sample_cycles;
            pm.inputs = layout.lookup[b].clone();
            // a part that selects by its word has its inputs by the mix's
            // `input`: the mux layout's table stops at 8 per device, and a
            // 16-input part's inputs 8 to 15 converted no channel's code
            if s.mix.branches[b].fronted || pm.command.is_some() {
                (pm.inputs, pm.front) = Self::fronted_inputs(s, b);
            }
        }
        let st: Vec<AdcState> = parts
            .iter()
            .map(|pm| AdcState {
                queue: std::iter::repeat_n(
                    None,
                    pm.command.as_ref().map_or(0, |c| c.ahead) as usize,
                )
                .collect(),
                ..AdcState::default()
            })
            .collect();
        let mask = |f: &dyn Fn(&PartModel) -> bool| {
            (parts.iter().enumerate())
                .filter(|(_, p)| f(p))
                .fold(0u16, |a, (b, _)| a | 1 << b)
        };
        let flip_sclk = mask(&|p| p.cnv);
        let low_read = mask(&|p| p.low_read);
        Adc {
            analog: Analog::new(s, kind),
            layout,
            st,
            parts,
            flip: flip_sclk & !low_read,
            flip_sclk,
            low_read,
            // every pin at its idle level in the view (CNV read low idles low)
            prev_cs: all & !low_read,
            prev_sclk: all,
            miso: (1u64 << nb) - 1,
        }
    }

    /// MISO of every branch during cycle `cycle`, given the outputs in it.
    #[inline]
    pub fn drive(&mut self, cycle: u64, p: &Pins) -> u64 {
        // CS view: conversion active low, shifting clock edge = a fall.
        let (cs_n, sclk) = (p.cs_n ^ self.flip, p.sclk ^ self.flip_sclk);
        if cs_n == self.prev_cs && sclk == self.prev_sclk {
            return self.miso;
        }
        let rose_cs = !self.prev_cs & cs_n;
        // A conversion starts where the view falls, or for a part read with
        // CNV low where CNV rises (which ends the read before it too).
        let fell_cs = (self.prev_cs & !cs_n & !self.low_read) | (rose_cs & self.low_read);
        // CS parts shift on SCLK falling edges; CNV parts on SCK falling
        // edges, which are rises in the inverted view.
        let fell_sclk =
            (self.prev_sclk & !sclk & !self.flip_sclk) | (!self.prev_sclk & sclk & self.flip_sclk);
        let fell_sclk = fell_sclk & !cs_n;
        // DIN is latched on the real SCLK's rising edges while selected.
        let real_prev = self.prev_sclk ^ self.flip_sclk;
        let rose_real = !real_prev & p.sclk & !cs_n;
        let mut miso = 0u64;
        for b in 0..self.st.len() {
            let bit = 1u16 << b;
            let pm = &self.parts[b];
            let st = &mut self.st[b];
            if rose_cs & bit != 0 {
                Self::end_of_read(pm, st);
            }
            if fell_cs & bit != 0 && pm.command.is_some() {
                let en = self.layout.en(p, b);
                let pin = (!pm.front.is_empty() && en.count_ones() == 1)
                    .then(|| en.trailing_zeros() * 8 + self.layout.sel(p, b));
                Self::start_commanded(&self.analog, pm, st, (cycle, b), pin);
            } else if fell_cs & bit != 0 {
                let id = self.analog.input_id(&self.layout, p, b);
                st.stream = 0;
                st.len = 0;
                st.falls = 0;
                for m in 0..pm.chain as usize {
                    // Each chained part converts its own input: the member's
                    // channel, or an unconnected input.
                    let mid = match pm.groups.get(id as usize).and_then(|g| g.get(m)) {
                        Some(Some(c)) => *c as u64,
                        Some(None) => id + 100 + m as u64,
                        None if m == 0 => id,
                        None => id + 100 + m as u64,
                    };
                    let code = self.analog.code_bits(mid, cycle + pm.after, pm.bits) as u128;
                    let trailing = pm.word_sclks - pm.leading - pm.bits;
                    st.stream = (st.stream << pm.word_sclks) | (code << trailing);
                    st.len += pm.word_sclks;
                }
            }
            if rose_real & bit != 0 && pm.command.is_some() {
                Self::latch(&self.analog, pm, st, self.layout.mosi(p, b), b);
            }
            if fell_sclk & bit != 0 {
                st.falls = st.falls.saturating_add(1);
            }
            let v = if cs_n & bit != 0 {
                1 // high-Z, weak pull-up
            } else if st.falls >= st.len {
                // CS parts (and a CNV read low): high-Z after the last bit;
                // a chain: the first part's SDI (tied low) comes through.
                if pm.cnv && !pm.low_read {
                    0
                } else {
                    1
                }
            } else {
                ((st.stream >> (st.len - 1 - st.falls)) & 1) as u8
            };
            miso |= (v as u64) << b;
        }
        self.prev_cs = cs_n;
        self.prev_sclk = sclk;
        self.miso = miso;
        miso
    }

    /// A fronted branch's channels by converter input: wired straight, and
    /// through the front mux by its input.
    #[allow(clippy::type_complexity)]
    fn fronted_inputs(
        s: &Schedule,
        b: usize,
    ) -> (Vec<Option<u16>>, Vec<std::collections::BTreeMap<u32, u16>>) {
        let n = s.mix.branches[b].input_capacity() as usize;
        let mut straight = vec![None; n];
        let mut front = vec![std::collections::BTreeMap::new(); n];
        for (c, ch) in s.mix.channels.iter().enumerate() {
            if ch.branch != b || ch.input as usize >= n {
                continue;
            }
            match ch.front_input {
                Some(f) => _ = front[ch.input as usize].insert(f, c as u16),
                None => straight[ch.input as usize] = Some(c as u16),
            }
        }
        (straight, front)
    }

    /// An id no channel has: the converter's input when no word of ours
    /// selected one (branch `b`).
    fn unselected(analog: &Analog, b: usize) -> u64 {
        analog.channels + 1 + b as u64
    }

    /// The code stream of a single part converting `id` at `t`.
    fn fill(analog: &Analog, pm: &PartModel, st: &mut AdcState, id: u64) {
        let code = analog.code_bits(id, st.t + pm.after, pm.bits) as u128;
        let trailing = pm.word_sclks - pm.leading - pm.bits;
        st.stream = code << trailing;
    }

    /// The id of the channel on input `input` of the part's multiplexer;
    /// an input wired to a front mux converts the channel on the front
    /// input `pin` its pins address at the sampling instant.
    fn id_of(
        analog: &Analog,
        pm: &PartModel,
        input: Option<u32>,
        b: usize,
        pin: Option<u32>,
    ) -> u64 {
        let ch = input.and_then(|i| match pm.front.get(i as usize) {
            Some(f) if !f.is_empty() => pin.and_then(|p| f.get(&p).copied()),
            _ => pm.inputs.get(i as usize).copied().flatten(),
        });
        ch.map_or(Self::unselected(analog, b), |c| c as u64)
    }

    /// A conversion of a part with a command word starts at `cycle`.
    fn start_commanded(
        analog: &Analog,
        pm: &PartModel,
        st: &mut AdcState,
        (cycle, b): (u64, usize),
        pin: Option<u32>,
    ) {
        st.t = cycle;
        st.len = pm.word_sclks;
        st.falls = 0;
        st.din = 0;
        st.nin = 0;
        st.stream = 0;
        if pm.command.as_ref().is_some_and(|c| c.ahead > 0) {
            let input = st.queue.pop_front().flatten();
            Self::fill(analog, pm, st, Self::id_of(analog, pm, input, b, pin));
        }
    }

    /// DIN bit `v` latched; with `ahead` 0 the last bit of the word selects
    /// the input this conversion samples.
    fn latch(analog: &Analog, pm: &PartModel, st: &mut AdcState, v: bool, b: usize) {
        let Some(cmd) = &pm.command else { return };
        st.din = (st.din << 1) | v as u64;
        st.nin += 1;
        if cmd.ahead == 0 && st.nin as usize == cmd.bits.len() {
            let input = cmd.channel_of(&Self::word(st));
            Self::fill(analog, pm, st, Self::id_of(analog, pm, input, b, None));
        }
    }

    /// The DIN bits latched so far, first first.
    fn word(st: &AdcState) -> Vec<bool> {
        (0..st.nin).rev().map(|i| st.din >> i & 1 == 1).collect()
    }

    /// The read ends: a pipelined part takes the word for a later conversion.
    fn end_of_read(pm: &PartModel, st: &mut AdcState) {
        if let Some(cmd) = pm.command.as_ref().filter(|c| c.ahead > 0) {
            let w = Self::word(st);
            st.queue.push_back(cmd.channel_of(&w));
            while st.queue.len() > cmd.ahead as usize {
                st.queue.pop_front();
            }
        }
    }
}
