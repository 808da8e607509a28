//! The reference model, built from lut-gen's [`Schedule`] only (never from `hdl`).
//!
//! - [`SlotModel`]: every conversion of a frame (instant, branch, channel,
//!   completion and emission cycles) as a periodic template, so hours of
//!   acquisition cost a few nanoseconds per sample;
//! - [`CycleModel`]: the value of every output pin in every cycle, as
//!   `docs/timing.md` specifies, driven by the MISO bits it captures (so the
//!   predicted `sample_value` is the word shifted in on MISO, whatever the
//!   stimulus).  It only does work at the cycles where something happens.

use lut_gen::Schedule;

use lut_gen::{Layout, Pins};

use crate::model::modes::ModeTrack;

/// One conversion's word in the periodic frame template (a chained
/// conversion gives one per chain member read).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Conversion {
    /// Conversion start (CS falling or CNV rising: the slot tick plus the
    /// branch's hold-off), cycles from the start of the frame.
    pub instant: u64,
    pub branch: usize,
    pub channel: u16,
    /// Chain member (0 for unchained parts).
    pub member: u16,
    /// Cycle in which CS rises again (`instant + read_cycles`).
    pub complete: u64,
    /// Cycle in which `sample_valid` carries it (may lie in the next frame).
    pub emit: u64,
}

/// Slot-level model: the periodic frame template of conversions, and the
/// first frame after reset, which lacks the instants skipped at start-up
/// (docs/timing.md, "Start-up").
#[derive(Debug, Clone)]
pub struct SlotModel {
    pub frame_cycles: u64,
    /// Conversions of one frame in (instant, branch) order.
    pub conversions: Vec<Conversion>,
    /// The same conversions in emission order.
    pub emissions: Vec<Conversion>,
    /// Frame 0: conversions in (instant, branch) order ...
    pub first: Vec<Conversion>,
    /// ... and in emission order.
    pub first_emissions: Vec<Conversion>,
}

/// Whether branch `b`'s instant `t` (cycles from reset release) samples a
/// mux that has had at least `settle` cycles: the mux took its value at the
/// first reset edge, one cycle before cycle 0 at the least.
fn settled_at_startup(t: u64, settle: u64) -> bool {
    t + 1 >= settle
}

/// Emission cycles: one word leaves per cycle; in cycle c + 1 the lowest
/// (branch, member) of those completed by cycle c.
fn merge(mut conversions: Vec<Conversion>) -> (Vec<Conversion>, Vec<Conversion>) {
    let mut order: Vec<usize> = (0..conversions.len()).collect();
    order.sort_by_key(|&i| {
        (
            conversions[i].complete,
            conversions[i].branch,
            conversions[i].member,
        )
    });
    let mut pending = std::collections::BTreeSet::new();
    let mut k = 0;
    let mut c = 0u64;
    while k < order.len() || !pending.is_empty() {
        if pending.is_empty() {
            c = c.max(conversions[order[k]].complete);
        }
        while k < order.len() && conversions[order[k]].complete <= c {
            let i = order[k];
            pending.insert((conversions[i].branch, conversions[i].member, i));
            k += 1;
        }
        let first = *pending.iter().next().unwrap();
        pending.remove(&first);
        conversions[first.2].emit = c + 1;
        c += 1;
    }
    let mut emissions = conversions.clone();
    emissions.sort_by_key(|c| c.emit);
    (conversions, emissions)
}

impl SlotModel {
    pub fn new(s: &Schedule) -> SlotModel {
        let g = &s.grid;
        let nb = s.branches.len();
        let mut conversions = Vec::new();
        for slot in 0..g.frame_slots {
            for b in 0..nb {
                if let Some(ch) = s.at(slot, b) {
                    // the conversion starts at the slot tick, or its hold-off later
                    let instant = slot * g.slot_cycles + s.holdoff(b);
                    for (m, c) in s.words_of(ch) {
                        conversions.push(Conversion {
                            instant,
                            branch: b,
                            channel: c as u16,
                            member: m as u16,
                            complete: instant + s.branches[b].spi.read_cycles,
                            emit: 0,
                        });
                    }
                }
            }
        }
        let first: Vec<Conversion> = conversions
            .iter()
            .filter(|c| settled_at_startup(c.instant, s.branches[c.branch].settle_cycles))
            .copied()
            .collect();
        let (conversions, emissions) = merge(conversions);
        let (first, first_emissions) = merge(first);
        SlotModel {
            frame_cycles: g.frame_cycles,
            conversions,
            emissions,
            first,
            first_emissions,
        }
    }

    /// Frame `f`'s conversions relative to its start, in (instant, branch)
    /// and in emission order.
    pub fn frame(&self, f: u64) -> (&[Conversion], &[Conversion]) {
        if f == 0 {
            (&self.first, &self.first_emissions)
        } else {
            (&self.conversions, &self.emissions)
        }
    }

    /// Every conversion of frames `0..frames`, with absolute cycles.
    pub fn iter(&self, frames: u64) -> impl Iterator<Item = Conversion> + '_ {
        (0..frames).flat_map(move |f| {
            let base = f * self.frame_cycles;
            self.frame(f).0.iter().map(move |c| Conversion {
                instant: c.instant + base,
                complete: c.complete + base,
                emit: c.emit + base,
                ..*c
            })
        })
    }
}

#[derive(Debug, Clone)]
struct BranchModel {
    /// Per mode (one without modes): (cycle in frame, channel) of this
    /// branch's instants.
    inst: Vec<Vec<(u64, u16)>>,
    /// Current instant (the last one at or before the model's cycle) and
    /// its frame's mode.
    t: Option<u64>,
    tch: u16,
    tmode: usize,
    /// Next instant: index in its frame's list and frame.
    ni: usize,
    nf: u64,
    tn: u64,
    tnch: u16,
    tnmode: usize,
    /// The next instant lies past the frames whose mode is decided: it is
    /// looked for again at the next frame start (the mux holds).
    waiting: bool,
    /// Cycle offsets after an instant where this branch's pins change or MISO is captured.
    offs: Vec<u64>,
    oi: usize,
    /// Next cycle at which this branch needs attention.
    next: u64,
    /// The current instant converts (false: skipped at start-up).
    conv: bool,
    /// Mux settling time in cycles.
    settle: u64,
    /// Bits captured from MISO in this conversion (the last in bit 0).
    word: u128,
    su: u64,
    d: u64,
    h: u64,
    r: u64,
    /// Cycles the conversion pin is active (`r`, or the conversion alone
    /// for a part read with CNV low).
    pin: u64,
    /// CNV style: the pin is active high and SCK idles low.
    cnv: bool,
    /// Captures per conversion (rising edges that read a bit).
    caps: u64,
    /// Serial bits per conversion, per word, data bits and leading bits.
    sclks: u64,
    word_sclks: u64,
    bits: u32,
    leading: u64,
    /// (device, select) of each channel (indexed by channel).
    addr: Vec<(u32, u32)>,
    /// A converter with a command word: its word, the index of the current
    /// instant in its frame's list, the channel the current conversion's
    /// word selects (docs/timing.md, "Command words"), each channel's input,
    /// and the conversions after reset still prepared, not data.
    cmd: Option<lut_gen::Command>,
    wi: usize,
    sel: usize,
    inputs: Vec<u32>,
    prepared: u32,
}

impl BranchModel {
    /// Branch `b`'s model, before its first instant (`addr`: each channel's
    /// (device, select)).
    fn new(s: &Schedule, b: usize, addr: &[(u32, u32)], track: &ModeTrack) -> BranchModel {
        let g = &s.grid;
        let plan = &s.branches[b];
        let spi = &plan.spi;
        let (su, d, h, r) = (
            spi.setup_cycles,
            spi.sclk_div,
            spi.sclk_half,
            spi.read_cycles,
        );
        let cnv = spi.style == lut_gen::Start::Cnv;
        let sclks = spi.sclks();
        let caps = if cnv { sclks } else { sclks - 1 };
        let mut offs = vec![1, r, spi.pin_cycles];
        for i in 0..sclks {
            let fall = su + i * d;
            offs.push(fall);
            offs.push(fall + h);
            if i < caps {
                offs.push(fall + h - 1);
            }
        }
        offs.retain(|&o| o > 0);
        offs.sort_unstable();
        offs.dedup();
        let of = |ms: &Schedule| -> Vec<(u64, u16)> {
            (0..g.frame_slots)
                .filter_map(|slot| {
                    ms.at(slot, b)
                        .map(|ch| (slot * g.slot_cycles + ms.holdoff(b), ch as u16))
                })
                .collect()
        };
        let inst: Vec<Vec<(u64, u16)>> = if s.modes.is_empty() {
            vec![of(s)]
        } else {
            s.modes.iter().map(of).collect()
        };
        let mut m = BranchModel {
            inst,
            t: None,
            tch: 0,
            tmode: 0,
            ni: 0,
            nf: 0,
            tn: u64::MAX,
            tnch: 0,
            tnmode: 0,
            waiting: false,
            offs,
            oi: 0,
            next: 0,
            conv: false,
            settle: plan.settle_cycles,
            word: 0,
            su,
            d,
            h,
            r,
            pin: spi.pin_cycles,
            cnv,
            caps,
            sclks,
            word_sclks: spi.word_sclks as u64,
            bits: spi.bits,
            leading: spi.leading_bits as u64,
            addr: addr.to_vec(),
            cmd: s.mix.branches[b].adc.command.clone(),
            wi: 0,
            sel: 0,
            inputs: s.mix.channels.iter().map(|c| c.input).collect(),
            prepared: s.prepared_conversions(b),
        };
        m.advance_next_instant(g.frame_cycles, track);
        m
    }

    /// The next instant after the current one, in the frames whose mode is
    /// decided (else `waiting`).
    fn advance_next_instant(&mut self, frame_cycles: u64, track: &ModeTrack) {
        self.waiting = false;
        if self.inst.iter().all(|l| l.is_empty()) {
            self.tn = u64::MAX;
            return;
        }
        loop {
            let Some(mode) = track.mode_of(self.nf) else {
                self.tn = u64::MAX;
                self.waiting = true;
                return;
            };
            let list = &self.inst[mode];
            if self.ni < list.len() {
                let (off, ch) = list[self.ni];
                self.tn = self.nf * frame_cycles + off;
                self.tnch = ch;
                self.tnmode = mode;
                self.ni += 1;
                if self.ni == list.len() {
                    self.ni = 0;
                    self.nf += 1;
                }
                return;
            }
            self.ni = 0;
            self.nf += 1;
        }
    }
}

impl BranchModel {
    /// The channel the word of the current conversion selects: the one
    /// `ahead` conversions later on this branch, counted through the frames
    /// in the modes decided (the next frame's is decided while this one
    /// runs; the audit refuses a mode with fewer than `ahead` conversions
    /// of a commanded branch, so the count never runs past it).
    fn selected(&self, frame_cycles: u64, track: &ModeTrack) -> usize {
        let ahead = self.cmd.as_ref().map_or(0, |c| c.ahead as usize);
        let (mut f, mut mode) = (self.t.unwrap_or(0) / frame_cycles, self.tmode);
        let mut i = self.wi + ahead;
        while i >= self.inst[mode].len() {
            i -= self.inst[mode].len();
            f += 1;
            match track.mode_of(f) {
                Some(m) if !self.inst[m].is_empty() => mode = m,
                // past the frames decided: the steady frame's word
                _ => {
                    return self.inst[self.tmode][(self.wi + ahead) % self.inst[self.tmode].len()].1
                        as usize
                }
            }
        }
        self.inst[mode][i].1 as usize
    }

    /// The word the current conversion sends (empty without a command word).
    fn command_word(&self) -> Vec<bool> {
        self.cmd
            .as_ref()
            .map_or(vec![], |c| c.word(self.inputs[self.sel]))
    }
}

/// Cycle-level model of `slotforge_top`'s outputs.
#[derive(Debug, Clone)]
pub struct CycleModel {
    layout: Layout,
    br: Vec<BranchModel>,
    frame_cycles: u64,
    c: u64,
    pins: Pins,
    reset: Pins,
    next_event: u64,
    pending: u16,
    /// Per branch: (channel, value) of the words waiting, first to leave first.
    pend: Vec<std::collections::VecDeque<(u16, u16)>>,
    capture: u16,
    /// Per mode (one without modes): each channel's chain members read.
    groups: Vec<Vec<Vec<Option<usize>>>>,
    /// The modes of the frame in force and the next (docs/timing.md, "Mode
    /// switches"), and `mode_sel` in the current cycle.
    track: ModeTrack,
    mode_sel: u64,
    /// The link's transmitter, fed the predicted sample stream (a mix with
    /// a `[link]`).
    tx: Option<link::TxModel>,
    /// The link is AXI4-Stream: its pins are `axis_*`, not `link_tx`.
    axis: bool,
}

impl CycleModel {
    /// The model at cycle 0 (the first cycle after reset).
    pub fn new(s: &Schedule) -> CycleModel {
        let layout = Layout::new(s);
        let g = &s.grid;
        let addr: Vec<(u32, u32)> = s.channels.iter().map(|c| (c.device, c.select)).collect();
        let track = ModeTrack::new(s);
        let br: Vec<BranchModel> = (0..s.branches.len())
            .map(|b| BranchModel::new(s, b, &addr, &track))
            .collect();
        let groups = if s.modes.is_empty() {
            vec![s.groups.clone()]
        } else {
            s.modes.iter().map(|m| m.groups.clone()).collect()
        };
        // Idle levels: CS high / SCLK high, CNV low / SCK low.
        let cs_idle = br
            .iter()
            .enumerate()
            .filter(|(_, m)| !m.cnv)
            .fold(0u16, |a, (b, _)| a | 1 << b);
        // The transmitter after its reset edge: line idle (high).
        let (tx, axis) = match lut_gen::plan_link(s) {
            Some(Ok(p)) => (Some(link::TxModel::new(p.tx_config(s))), p.axis().is_some()),
            _ => (None, false),
        };
        let mut reset = Pins {
            cs_n: cs_idle,
            sclk: cs_idle,
            link_tx: tx.is_some() && !axis,
            ..Pins::default()
        };
        for (b, m) in br.iter().enumerate() {
            if m.tn != u64::MAX {
                let (dev, sel) = m.addr[m.tnch as usize];
                layout.set_mux(&mut reset, b, dev, sel);
            }
        }
        let mut model = CycleModel {
            layout,
            br,
            frame_cycles: g.frame_cycles,
            c: 0,
            pins: reset,
            reset,
            next_event: 0,
            pending: 0,
            pend: vec![Default::default(); s.branches.len()],
            capture: 0,
            groups,
            track,
            mode_sel: 0,
            tx,
            axis,
        };
        model.process();
        // The edge into cycle 0 samples the reset cycle's stream: no sample.
        model.step_link(false, 0, 0);
        model
    }

    /// The transmitter's edge at the end of the current cycle, fed this
    /// cycle's sample stream; its line and flag in the next cycle.
    #[inline]
    fn step_link(&mut self, valid: bool, ch: u16, v: u16) {
        if let Some(t) = &mut self.tx {
            t.clock(false, valid.then_some((ch, v)));
            self.link_pins();
        }
    }

    /// `mode_sel` in the current cycle (pin select: an input the model takes
    /// from the pins it is compared with), before [`CycleModel::step`].
    #[inline]
    pub fn set_mode_sel(&mut self, v: u8) {
        self.mode_sel = v as u64;
        self.pins.mode_sel = v;
    }

    /// The modes decided so far: the frame in force, its mode and the next.
    pub fn modes(&self) -> &ModeTrack {
        &self.track
    }

    /// The model at cycle 0 with the modes of frames 2 and later given
    /// (`(frame, mode)`), not decided from its inputs: where a check that
    /// joins a run mid-way starts (docs/timing.md, "Mode switches").
    pub fn with_modes(s: &Schedule, modes: &[(u64, usize)]) -> CycleModel {
        let mut m = CycleModel::new(s);
        for &(f, mode) in modes {
            m.track.force(f, mode);
        }
        m
    }

    /// The modes, to keep their decisions ([`ModeTrack::keep_decisions`]).
    pub(crate) fn modes_mut(&mut self) -> &mut ModeTrack {
        &mut self.track
    }

    /// The link's transmitter configuration (a mix with a `[link]`).
    pub fn tx_config(&self) -> Option<link::TxConfig> {
        self.tx.as_ref().map(|t| *t.config())
    }

    /// Replaces the link's transmitter with `tx` (in the current cycle): a
    /// check that joined mid-run takes the run's own transmitter state from
    /// the line (`line::join`).
    pub fn set_tx(&mut self, tx: link::TxModel) {
        if self.tx.is_some() {
            self.tx = Some(tx);
            self.link_pins();
        }
    }

    /// The link's pins from the transmitter's state.
    #[inline]
    fn link_pins(&mut self) {
        if let Some(t) = &self.tx {
            self.pins.link_overflow = t.overflow();
            if self.axis {
                self.pins.axis_tdata = t.tdata();
                self.pins.axis_tvalid = t.tvalid();
                self.pins.axis_tlast = t.tlast();
            } else {
                self.pins.link_tx = t.line();
            }
        }
    }

    /// The AXI4-Stream slave's `tready` in the current cycle (an input the
    /// model takes from the pins it is compared with), before [`CycleModel::step`].
    #[inline]
    pub fn set_tready(&mut self, ready: bool) {
        if let Some(t) = &mut self.tx {
            t.set_tready(ready);
        }
        self.pins.axis_tready = ready;
    }

    /// The byte on the link's line in the current cycle and which of its
    /// bits (0: the start bit): what a capture's line is held against.
    pub fn link_byte(&self) -> Option<(link::ByteOnLine, u32)> {
        self.tx.as_ref()?.on_line()
    }

    /// The branches (bit b) whose MISO is read at the edge ending the
    /// current cycle.
    pub fn capturing(&self) -> u16 {
        self.capture
    }

    /// What the link's line carries in the current cycle, for reports:
    /// the byte, its bit, its word and packet, and the sample of a record.
    pub fn link_context(&self) -> Option<String> {
        let (b, bit) = self.tx.as_ref()?.on_line()?;
        let what = match (b.kind, b.sample) {
            (link::format::WordKind::Record, Some((ch, v))) => {
                format!("record of channel {ch} = {v}")
            }
            (link::format::WordKind::Record, None) => "record".into(),
            (link::format::WordKind::Header, _) => "header".into(),
            (link::format::WordKind::Trailer, _) => "trailer".into(),
        };
        Some(format!(
            "link: bit {bit} of byte {:#04x} (byte {} of the {what}) of packet frame {} slice {} (mod 256 frames)",
            b.byte, b.index, b.packet.0, b.packet.1
        ))
    }

    /// Output values in every cycle in which `rst` was sampled high.
    pub fn reset_pins(&self) -> Pins {
        self.reset
    }

    /// The cycle the model is in.
    pub fn cycle(&self) -> u64 {
        self.c
    }

    /// Predicted outputs in the current cycle.
    #[inline]
    pub fn pins(&self) -> &Pins {
        &self.pins
    }

    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The channel branch `b` is busy with or heading for in the current cycle.
    pub fn branch_channel(&self, b: usize) -> u16 {
        let m = &self.br[b];
        match m.t {
            Some(t) if self.c < t + m.r => m.tch,
            _ => m.tnch,
        }
    }

    /// The command word branch `b` is sending in the current cycle: (the
    /// channel it selects, the bit on the lane, the conversion's instant),
    /// or `None` outside a word (the lane idles low).  For the checker's
    /// report of a wrong `adc_mosi` bit.
    pub fn command_bit(&self, b: usize) -> Option<(usize, usize, u64)> {
        let m = &self.br[b];
        let t = m.t?;
        let k = self.c.checked_sub(t)?;
        let len = m.cmd.as_ref()?.bits.len();
        if !m.conv || k < m.su || k >= m.r {
            return None;
        }
        let i = ((k - m.su) / m.d) as usize;
        (i < len).then_some((m.sel, i, t))
    }

    /// The command word branch `b`'s current conversion sends (empty
    /// without a command word or before its first conversion).
    pub fn command_word(&self, b: usize) -> Vec<bool> {
        self.br[b].command_word()
    }

    /// No conversion that began before the current cycle is still running or
    /// waiting to be emitted: a check that joins here (a capture from the
    /// middle of a run) needs none of the MISO bits it did not see.
    pub fn quiet(&self) -> bool {
        self.pending == 0
            && self.capture == 0
            && !self.pins.sample_valid
            && self.br.iter().all(|m| match m.t {
                Some(t) => t == self.c || self.c > t + m.r,
                None => true,
            })
    }

    /// The channel and value the sample port holds while no sample is sent
    /// (the last ones sent): for a check that joins a run mid-stream.
    pub fn hold_sample(&mut self, channel: u16, value: u16) {
        if !self.pins.sample_valid {
            self.pins.sample_channel = channel;
            self.pins.sample_value = value;
        }
    }

    /// The model `cycles` cycles after reset, stepped with MISO low.
    pub fn at(s: &Schedule, cycles: u64) -> CycleModel {
        let mut m = CycleModel::new(s);
        while m.c < cycles {
            m.step(0);
        }
        m
    }

    /// Ends the current cycle, in which `adc_miso` carried `miso` (bit b =
    /// branch b), and moves to the next one.
    #[inline]
    pub fn step(&mut self, miso: u64) {
        if self.tx.is_some() {
            let p = self.pins;
            self.step_pins(miso);
            if let Some(t) = &mut self.tx {
                t.set_mode(p.mode);
            }
            self.step_link(p.sample_valid, p.sample_channel, p.sample_value);
        } else {
            self.step_pins(miso);
        }
    }

    #[inline]
    fn step_pins(&mut self, miso: u64) {
        if self.capture == 0
            && self.pending == 0
            && !self.pins.sample_valid
            && self.c + 1 < self.next_event
        {
            self.c += 1;
            return;
        }
        self.step_slow(miso);
    }

    fn step_slow(&mut self, miso: u64) {
        let mut cap = self.capture;
        while cap != 0 {
            let b = cap.trailing_zeros() as usize;
            cap &= cap - 1;
            let m = &mut self.br[b];
            m.word = (m.word << 1) | ((miso >> b) & 1) as u128;
        }
        self.capture = 0;
        if self.pending != 0 {
            let b = self.pending.trailing_zeros() as usize;
            let (ch, v) = self.pend[b].pop_front().unwrap_or_default();
            if self.pend[b].is_empty() {
                self.pending &= self.pending - 1;
            }
            self.pins.sample_valid = true;
            self.pins.sample_channel = ch;
            self.pins.sample_value = v;
        } else {
            self.pins.sample_valid = false;
        }
        self.c += 1;
        if self.c >= self.next_event {
            self.process();
        }
    }

    /// Handles the events of cycle `self.c`.
    fn process(&mut self) {
        let c = self.c;
        let mut next = u64::MAX;
        if self.track.switches() {
            self.frame_start(c);
            next = (self.track.frame() + 1) * self.frame_cycles;
        }
        for b in 0..self.br.len() {
            let m = &mut self.br[b];
            if m.next <= c {
                if c == m.tn {
                    m.t = Some(m.tn);
                    m.tch = m.tnch;
                    m.tmode = m.tnmode;
                    m.conv = settled_at_startup(m.tn, m.settle);
                    m.wi = m.ni.checked_sub(1).unwrap_or(m.inst[m.tmode].len() - 1);
                    m.sel = m.selected(self.frame_cycles, &self.track);
                    m.advance_next_instant(self.frame_cycles, &self.track);
                    m.oi = 0;
                    m.word = 0;
                }
                let bit = 1u16 << b;
                let (mut cs, mut sclk) = (true, true);
                let ch = if m.t == Some(c) { m.tch } else { m.tnch };
                if let Some(t) = m.t {
                    let k = c - t;
                    while m.oi < m.offs.len() && m.offs[m.oi] <= k {
                        m.oi += 1;
                    }
                    m.next = if m.oi < m.offs.len() {
                        (t + m.offs[m.oi]).min(m.tn)
                    } else {
                        m.tn
                    };
                    if k < m.r && m.conv {
                        // the pin: through the read, or the conversion alone
                        cs = k >= m.pin;
                        if k >= m.su && (k - m.su) % m.d < m.h {
                            sclk = false;
                        }
                        if k >= m.su && k < m.su + m.caps * m.d && (k - m.su) % m.d == m.h - 1 {
                            self.capture |= bit;
                        }
                    }
                    if k == m.r && m.conv && m.prepared > 0 {
                        // A prepared conversion: its word was never ours.
                        m.prepared -= 1;
                    } else if k == m.r && m.conv {
                        // Bit j of the serial stream sits at sclks-1-j of `word`.
                        self.pending |= bit;
                        let mask = (1u128 << m.bits) - 1;
                        for (w, c) in self.groups[m.tmode][m.tch as usize].iter().enumerate() {
                            if let Some(c) = c {
                                let end = w as u64 * m.word_sclks + m.leading + m.bits as u64;
                                let v = (m.word >> (m.sclks - end)) & mask;
                                self.pend[b].push_back((*c as u16, v as u16));
                                self.track.sample(*c, v as u16);
                            }
                        }
                    }
                } else {
                    m.next = m.tn;
                }
                if m.cnv {
                    // CNV is active high; SCK idles low and is high in the
                    // second half of each period (rising edge i in its middle).
                    cs = !cs;
                    sclk = match m.t {
                        Some(t) => {
                            let k = c - t;
                            m.conv && k >= m.su && k < m.r && (k - m.su) % m.d >= m.h
                        }
                        None => false,
                    };
                }
                self.pins.cs_n = (self.pins.cs_n & !bit) | if cs { bit } else { 0 };
                self.pins.sclk = (self.pins.sclk & !bit) | if sclk { bit } else { 0 };
                if let Some(i) = self.layout.mosi_lo[b] {
                    let v = Self::mosi_at(&self.br[b], c);
                    self.pins.mosi = (self.pins.mosi & !(1 << i)) | (v as u16) << i;
                }
                let m = &mut self.br[b];
                if m.tn != u64::MAX || m.t.is_some() {
                    let (dev, sel) = m.addr[ch as usize];
                    self.layout.set_mux(&mut self.pins, b, dev, sel);
                }
            }
            next = next.min(self.br[b].next);
        }
        self.next_event = next;
    }

    /// `adc_mosi` of a commanded branch in cycle `c`: bit `k` of the
    /// conversion's word through SCLK period `k + 1` (docs/timing.md,
    /// "Command words"), else 0.
    fn mosi_at(m: &BranchModel, c: u64) -> bool {
        let Some(t) = m.t else { return false };
        let k = c - t;
        if !m.conv || k < m.su || k >= m.r {
            return false;
        }
        let i = ((k - m.su) / m.d) as usize;
        m.cmd
            .as_ref()
            .and_then(|w| w.bits.get(i))
            .is_some_and(|b| match *b {
                lut_gen::CmdBit::Zero => false,
                lut_gen::CmdBit::One => true,
                lut_gen::CmdBit::Channel(j) => m.inputs[m.sel] >> j & 1 == 1,
            })
    }

    /// At the edge that begins a frame (cycle `c`): the mode of the frame
    /// after it is decided from `mode_sel` of the cycle before or the
    /// windows closed, `mode` shows the new frame's, and a branch that had
    /// no instant in the frames decided looks again (its mux moves in the
    /// next cycle).
    fn frame_start(&mut self, c: u64) {
        if c != (self.track.frame() + 1) * self.frame_cycles {
            return;
        }
        self.track.frame_start(self.mode_sel);
        self.pins.mode = self.track.mode() as u8;
        // Its mux moves in the frame's second cycle, as after an instant
        // (the gateware loads a mux at a slot start, from the slot's word).
        for m in self.br.iter_mut().filter(|m| m.waiting) {
            m.advance_next_instant(self.frame_cycles, &self.track);
            m.next = c + 1;
        }
    }
}
