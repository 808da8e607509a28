//! PinFault injection: a [`Dut`] wrapper that corrupts a design's pins in one
//! precise way, to prove the checker catches each kind of fault.

use std::collections::VecDeque;

use lut_gen::Schedule;

use crate::check::run::Dut;
use lut_gen::{Layout, Pins};

/// A kind of fault, injected around the first conversion of `branch` at or after a cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PinFault {
    /// `sample_channel` of one emitted sample has bit 0 flipped.
    WrongChannel,
    /// `sample_value` of one emitted sample has one bit flipped.
    WrongSampleBit,
    /// One `sample_valid` pulse is dropped.
    DropSample,
    /// One CS-low window of `branch` is shifted one cycle later.
    CsLate { branch: usize },
    /// One extra SCLK low pulse inside a CS-low window of `branch`.
    SclkExtraEdge { branch: usize },
    /// `branch`'s mux switches two cycles before the instant instead of right after the previous one.
    MuxLate { branch: usize },
    /// Every mux device of `branch` enabled for a few cycles.
    TwoMuxEn { branch: usize },
    /// The wrong mux input (select bit 0 flipped) held through one instant of `branch`.
    WrongMux { branch: usize },
    /// The design is reset for a few cycles in mid-run while its `rst` port
    /// stays low (a glitch, a brown-out): it restarts its frame.
    ResetGlitch,
    // Faults that keep a legal-looking timeline: every CS window, SCLK burst
    // and mux switch is well formed, so only a model-free check of the
    // mix's invariants (or the model) can tell them from a good design.
    /// One conversion of `branch` (CS, SCLK and mux lanes) moved one slot
    /// later, into a slot where the branch is idle.
    ConversionMoved { branch: usize },
    /// One channel's instants start one sampling interval later: its
    /// conversion at the site vanishes (CS and SCLK idle, no sample), the
    /// following ones fall where they were.
    PhaseShift { branch: usize },
    /// The mux addresses of two channels of `branch` with the same rate
    /// swapped for one frame (each instant converts the other's input).
    SelectSwap { branch: usize },
    /// One conversion of `branch` read with SCLK at half its frequency, still
    /// within the part's limits (the CS window grows to fit the 16 clocks).
    SclkSlow { branch: usize },
    /// One sample leaves with the code of the conversion emitted before it.
    NeighbourCode,
    // Faults of a converter's command word on `adc_mosi` (a branch whose
    // part takes one): CS, SCLK and the samples stay as they were, so the
    // model's `adc_mosi` or the model-free attribution of each conversion
    // to the channel its word selected must tell.
    /// The word of one conversion of `branch` with its first channel bit
    /// (the MSB) inverted: the part converts another input.
    WrongChannelBits { branch: usize },
    /// The word of one conversion of `branch` sent one SCLK period late:
    /// each bit in the period after its own, the lane low in the first.
    LateCommand { branch: usize },
    // Faults of the link to the host, on its pins (a mix with a `[link]`):
    // what a noisy wire, a lost character, a broken driver or a full FIFO
    // shows at the FPGA's edge.  The gateware's own link faults (a FIFO one
    // token short, a wrong divider, a wrong CRC start) are
    // `hdl::GatewareFault`s.
    /// UART: data bit 3 of the first character starting at or after the
    /// site inverted for its whole bit time.
    LinkBitFlip,
    /// UART: the first character starting at or after the site replaced by
    /// an idle line (start to last stop bit): a byte lost on the wire.
    LinkDropByte,
    /// UART: the line stuck at `high` from the site to the end of the run.
    LinkStuck { high: bool },
    /// Any link: the FIFO's sticky overflow flag raised from the site on,
    /// as the design shows a dropped token.
    LinkOverflow,
    /// AXI4-Stream: the first beat at or after the site that waits for
    /// `tready` has `tvalid` dropped in the next cycle (a beat withdrawn).
    AxisTvalidDrop,
    /// AXI4-Stream: the first beat at or after the site that waits for
    /// `tready` has `tdata` bit 0 changed in the next cycle.
    AxisTdataChange,
    // Faults of the `mode` output (a mix with modes, docs/timing.md "Mode
    // switches"), sited at a frame start `S` of a switching run: the
    // campaign puts the first two where the run switches, the third where
    // it does not.
    /// `mode` shows another mode (the next by number: the new one of a
    /// two-mode mix) in the cycle before `S`: a switch a cycle early.
    ModeEarly,
    /// `mode` keeps the mode of the frame before `S` through frame `S`:
    /// a switch shown a frame late.
    ModeStuck,
    /// `mode` shows another mode (the next by number) through frame `S`: a
    /// switch nothing decided.
    ModeUnasked,
}

/// Cycles a [`PinFault::ResetGlitch`] holds the design in reset.
pub const GLITCH_CYCLES: u64 = 3;

impl PinFault {
    /// The fault's class: its name without the branch.
    pub fn class(&self) -> &'static str {
        match self {
            PinFault::WrongChannel => "wrong-channel",
            PinFault::WrongSampleBit => "wrong-sample-bit",
            PinFault::DropSample => "drop-sample",
            PinFault::CsLate { .. } => "cs-late",
            PinFault::SclkExtraEdge { .. } => "sclk-extra-edge",
            PinFault::MuxLate { .. } => "mux-late",
            PinFault::TwoMuxEn { .. } => "two-mux-en",
            PinFault::WrongMux { .. } => "wrong-mux",
            PinFault::ResetGlitch => "reset-glitch",
            PinFault::ConversionMoved { .. } => "conversion-moved",
            PinFault::PhaseShift { .. } => "phase-shift",
            PinFault::SelectSwap { .. } => "select-swap",
            PinFault::SclkSlow { .. } => "sclk-slow",
            PinFault::NeighbourCode => "neighbour-code",
            PinFault::WrongChannelBits { .. } => "wrong-channel-bits",
            PinFault::LateCommand { .. } => "late-command",
            PinFault::LinkBitFlip => "link-bit-flip",
            PinFault::LinkDropByte => "link-drop-byte",
            PinFault::LinkStuck { high: true } => "link-stuck-high",
            PinFault::LinkStuck { high: false } => "link-stuck-low",
            PinFault::LinkOverflow => "link-fifo-overflow",
            PinFault::AxisTvalidDrop => "axis-tvalid-drop",
            PinFault::AxisTdataChange => "axis-tdata-change",
            PinFault::ModeEarly => "mode-early",
            PinFault::ModeStuck => "mode-stuck",
            PinFault::ModeUnasked => "mode-unasked",
        }
    }

    /// The branch a fault is injected on (stream faults: none).
    pub fn branch(&self) -> Option<usize> {
        match *self {
            PinFault::CsLate { branch }
            | PinFault::SclkExtraEdge { branch }
            | PinFault::MuxLate { branch }
            | PinFault::TwoMuxEn { branch }
            | PinFault::WrongMux { branch }
            | PinFault::ConversionMoved { branch }
            | PinFault::PhaseShift { branch }
            | PinFault::SelectSwap { branch }
            | PinFault::SclkSlow { branch }
            | PinFault::WrongChannelBits { branch }
            | PinFault::LateCommand { branch } => Some(branch),
            PinFault::WrongChannel
            | PinFault::WrongSampleBit
            | PinFault::DropSample
            | PinFault::ResetGlitch
            | PinFault::NeighbourCode
            | PinFault::LinkBitFlip
            | PinFault::LinkDropByte
            | PinFault::LinkStuck { .. }
            | PinFault::LinkOverflow
            | PinFault::AxisTvalidDrop
            | PinFault::AxisTdataChange
            | PinFault::ModeEarly
            | PinFault::ModeStuck
            | PinFault::ModeUnasked => None,
        }
    }

    pub fn name(&self) -> String {
        match self.branch() {
            Some(b) => format!("{}-b{b}", self.class()),
            None => self.class().into(),
        }
    }

    /// Every fault that applies to the schedule.
    pub fn all(s: &Schedule) -> Vec<PinFault> {
        let mut v = vec![
            PinFault::WrongChannel,
            PinFault::WrongSampleBit,
            PinFault::DropSample,
            PinFault::ResetGlitch,
        ];
        for b in 0..s.branches.len() {
            if s.branch_instants_in_frame(b).is_empty() {
                continue;
            }
            v.push(PinFault::CsLate { branch: b });
            v.push(PinFault::SclkExtraEdge { branch: b });
            // a branch without a mux has no mux pins to fault
            let muxed = s.mix.branches[b].mux.select_bits > 0;
            if muxed {
                v.push(PinFault::MuxLate { branch: b });
                v.push(PinFault::WrongMux { branch: b });
            }
            if muxed && s.branches[b].mux_devices >= 2 {
                v.push(PinFault::TwoMuxEn { branch: b });
            }
            v.push(PinFault::ConversionMoved { branch: b });
            v.push(PinFault::PhaseShift { branch: b });
            if muxed && same_rate_pair(s, b).is_some() {
                v.push(PinFault::SelectSwap { branch: b });
            }
            if slow_sclk_div(s, b).is_some() {
                v.push(PinFault::SclkSlow { branch: b });
            }
            if s.has_command(b) {
                v.push(PinFault::WrongChannelBits { branch: b });
            }
            if late_word_differs(s, b) {
                v.push(PinFault::LateCommand { branch: b });
            }
        }
        v.push(PinFault::NeighbourCode);
        v.extend(PinFault::link(s));
        if s.modes.len() > 1 {
            v.extend([
                PinFault::ModeEarly,
                PinFault::ModeStuck,
                PinFault::ModeUnasked,
            ]);
        }
        v
    }

    /// Whether this is a fault of the `mode` output (sited at frame starts
    /// of a switching run).
    pub fn is_mode(&self) -> bool {
        matches!(
            self,
            PinFault::ModeEarly | PinFault::ModeStuck | PinFault::ModeUnasked
        )
    }

    /// The link's pin faults of the schedule's link (none without one):
    /// the UART's line faults, or AXI4-Stream's faults under back-pressure,
    /// and the overflow flag of either.
    pub fn link(s: &Schedule) -> Vec<PinFault> {
        match s.mix.link.map(|l| l.kind) {
            None => vec![],
            Some(lut_gen::LinkKind::Uart) => vec![
                PinFault::LinkBitFlip,
                PinFault::LinkDropByte,
                PinFault::LinkStuck { high: true },
                PinFault::LinkStuck { high: false },
                PinFault::LinkOverflow,
            ],
            Some(lut_gen::LinkKind::Axis) => vec![
                PinFault::AxisTvalidDrop,
                PinFault::AxisTdataChange,
                PinFault::LinkOverflow,
            ],
        }
    }

    /// Whether this is a fault of the link's pins.
    pub fn is_link(&self) -> bool {
        matches!(
            self,
            PinFault::LinkBitFlip
                | PinFault::LinkDropByte
                | PinFault::LinkStuck { .. }
                | PinFault::LinkOverflow
                | PinFault::AxisTvalidDrop
                | PinFault::AxisTdataChange
        )
    }
}

/// Two channels of branch `b` with the same rate (the first such pair).
pub fn same_rate_pair(s: &Schedule, b: usize) -> Option<(usize, usize)> {
    let mix = &s.mix;
    let on: Vec<usize> = (0..mix.channels.len())
        .filter(|&c| mix.channels[c].branch == b)
        .collect();
    on.iter().enumerate().find_map(|(i, &x)| {
        on[i + 1..]
            .iter()
            .find(|&&y| mix.channels[y].rate_hz == mix.channels[x].rate_hz)
            .map(|&y| (x, y))
    })
}

/// Whether every word branch `b` sends, one SCLK period late, selects
/// another input than on time or none (so [`PinFault::LateCommand`] shows
/// without the model too); false for a branch without a command word.
pub fn late_word_differs(s: &Schedule, b: usize) -> bool {
    let Some(cmd) = &s.mix.branches[b].adc.command else {
        return false;
    };
    s.commands_in_frame(b).iter().all(|w| {
        let late: Vec<bool> = std::iter::once(false)
            .chain(w.word.iter().copied())
            .collect();
        cmd.channel_of(&late) != Some(w.input)
    })
}

/// The position of the first channel bit of branch `b`'s command word.
fn first_channel_bit(s: &Schedule, b: usize) -> u64 {
    s.mix.branches[b].adc.command.as_ref().map_or(0, |c| {
        c.bits
            .iter()
            .position(|x| matches!(x, lut_gen::CmdBit::Channel(_)))
            .unwrap_or(0) as u64
    })
}

/// The SCLK divider of [`PinFault::SclkSlow`] on branch `b`: twice the
/// branch's, if the part still allows that frequency.
pub fn slow_sclk_div(s: &Schedule, b: usize) -> Option<u64> {
    let d = s.branches[b].spi.sclk_div * 2;
    let part = &s.mix.branches[b].adc;
    (d * part.sclk_min_hz <= s.mix.clock_hz).then_some(d)
}

/// Wraps a design and injects one fault at or after cycle `at`.
pub struct FaultyDut<D> {
    inner: D,
    fault: PinFault,
    layout: Layout,
    at: u64,
    /// (previous instant, target instant) of the fault's branch.
    t_prev: u64,
    t: u64,
    su: u64,
    d: u64,
    r: u64,
    cycle: Option<u64>,
    done: bool,
    prev_cs: u16,
    prev_sclk: u16,
    /// Cycles SCLK is high in one period.
    high: u64,
    held: Option<Pins>,
    changed: bool,
    /// Legal-timeline faults: the original pins of the last `hist_len`
    /// cycles (the newest last), the cycles a lane is moved or stretched
    /// by, the channels concerned and the last sample value emitted.
    hist: VecDeque<Pins>,
    hist_len: usize,
    shift: u64,
    d_slow: u64,
    words: u64,
    channels: (u16, u16),
    last_value: Option<u16>,
    frame: u64,
    /// Every channel's mux (device, select).
    addresses: Vec<(u32, u32)>,
    /// The UART's character (link faults), the cycle the character on the
    /// line ends (its next start bit is a falling edge at or after it), and
    /// the start of the character a fault hits.
    uart: Option<link::UartFormat>,
    char_end: u64,
    hit: Option<u64>,
    /// AXI4-Stream: a beat waited for `tready` in the previous cycle.
    stalled: bool,
    /// Command-word faults: the channel bit inverted, and the fault's
    /// branch's `adc_mosi` lane as the design drove it in the last SCLK
    /// period (the newest last).
    cmd_bit: u64,
    mosi_hist: VecDeque<bool>,
    /// Mode faults: the number of modes, and `mode` in the cycle before.
    modes: u8,
    mode_before: u8,
}

impl<D: Dut> FaultyDut<D> {
    pub fn new(s: &Schedule, inner: D, fault: PinFault, at: u64) -> FaultyDut<D> {
        let b = fault.branch().unwrap_or(0);
        let spi = s.branches[b].spi;
        let slot = s.grid.slot_cycles;
        let d_slow = slow_sclk_div(s, b).unwrap_or(spi.sclk_div);
        let n = (spi.words * spi.word_sclks) as u64;
        let r_slow = spi.read_cycles + n * (d_slow - spi.sclk_div);
        // the span a fault's conversion needs before the branch's next one
        let need = match fault {
            PinFault::ConversionMoved { .. } => slot + spi.read_cycles + spi.quiet_cycles + 1,
            PinFault::SclkSlow { .. } => r_slow + spi.quiet_cycles + 1,
            _ => 0,
        };
        // a sync group's hold-off moves the branch's whole conversion (CS,
        // SCLK, words, mux switch) after its slot tick: the fault with it
        let h = s.holdoff(b);
        let (prev, t) = target_instant(s, b, at, need);
        let (prev, t) = (prev.saturating_add(h), t.saturating_add(h));
        let (hist_len, shift) = match fault {
            PinFault::ConversionMoved { .. } => ((slot + spi.read_cycles + 2) as usize, slot),
            PinFault::SclkSlow { .. } => ((r_slow + 2) as usize, r_slow),
            _ => (0, 0),
        };
        let channels = match fault {
            PinFault::SelectSwap { branch } => same_rate_pair(s, branch)
                .map(|(x, y)| (x as u16, y as u16))
                .unwrap_or((0, 0)),
            PinFault::PhaseShift { branch } => {
                let c = s.at((t % s.grid.frame_cycles) / slot, branch).unwrap_or(0) as u16;
                (c, c)
            }
            _ => (0, 0),
        };
        FaultyDut {
            inner,
            fault,
            layout: Layout::new(s),
            at,
            t_prev: prev,
            t,
            su: spi.setup_cycles,
            d: spi.sclk_div,
            r: spi.read_cycles,
            cycle: None,
            done: false,
            prev_cs: 0xff,
            prev_sclk: 0xff,
            high: spi.sclk_div - spi.sclk_half,
            held: None,
            changed: false,
            hist: VecDeque::with_capacity(hist_len + 1),
            hist_len,
            shift,
            d_slow,
            words: n,
            channels,
            last_value: None,
            frame: s.grid.frame_cycles,
            addresses: s.channels.iter().map(|c| (c.device, c.select)).collect(),
            uart: lut_gen::plan_link(s)
                .and_then(|p| p.ok())
                .and_then(|p| p.uart()),
            char_end: 0,
            hit: None,
            stalled: false,
            cmd_bit: first_channel_bit(s, b),
            mosi_hist: VecDeque::with_capacity(spi.sclk_div as usize + 1),
            modes: s.modes.len().max(1) as u8,
            mode_before: 0,
        }
    }
}

/// (previous instant, first instant at or after `at`, not at cycle 0) of
/// branch `b` whose next instant is at least `need` cycles later; a fault
/// that finds none within two frames lands nowhere (it is not injected).
fn target_instant(s: &Schedule, b: usize, at: u64, need: u64) -> (u64, u64) {
    let limit = at + 2 * s.grid.frame_cycles;
    let mut it = s
        .instants(u64::MAX)
        .filter(|i| i.branch == b)
        .map(|i| i.cycle)
        .take_while(|&c| c <= limit + s.grid.frame_cycles)
        .peekable();
    let mut prev = 0;
    while let Some(c) = it.next() {
        if c > limit {
            break;
        }
        let next = it.peek().copied().unwrap_or(u64::MAX);
        if c >= at && c > 0 && next - c >= need {
            return (prev, c);
        }
        prev = c;
    }
    (u64::MAX, u64::MAX)
}

impl<D: Dut> Dut for FaultyDut<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        let next = self.cycle.map_or(0, |c| c + 1);
        let glitch = !rst
            && self.fault == PinFault::ResetGlitch
            && next >= self.at
            && next < self.at + GLITCH_CYCLES;
        let mut p = self.inner.step(rst || glitch, miso);
        if rst {
            self.cycle = None;
            self.prev_cs = p.cs_n;
            return p;
        }
        let c = next;
        self.cycle = Some(c);
        let orig = p;
        let orig_cs = p.cs_n;
        let orig_sclk = p.sclk;
        if self.hist_len > 0 {
            if self.hist.len() == self.hist_len {
                self.hist.pop_front();
            }
            self.hist.push_back(orig);
        }
        match self.fault {
            PinFault::ResetGlitch => {}
            PinFault::WrongChannel
            | PinFault::WrongSampleBit
            | PinFault::DropSample
            | PinFault::NeighbourCode => self.sample_fault(c, &mut p, &orig),
            PinFault::CsLate { .. }
            | PinFault::SclkExtraEdge { .. }
            | PinFault::PhaseShift { .. } => self.serial_fault(c, &mut p),
            PinFault::MuxLate { .. }
            | PinFault::TwoMuxEn { .. }
            | PinFault::WrongMux { .. }
            | PinFault::SelectSwap { .. } => self.mux_fault(c, &mut p),
            PinFault::ConversionMoved { branch } => self.move_conversion(c, &mut p, branch),
            PinFault::SclkSlow { branch } => self.slow_sclk(c, &mut p, branch),
            PinFault::WrongChannelBits { branch } | PinFault::LateCommand { branch } => {
                self.command_fault(c, &mut p, branch)
            }
            PinFault::LinkBitFlip | PinFault::LinkDropByte => self.uart_char(c, &mut p),
            PinFault::LinkStuck { .. }
            | PinFault::LinkOverflow
            | PinFault::AxisTvalidDrop
            | PinFault::AxisTdataChange => self.link_fault(c, &mut p, &orig),
            PinFault::ModeEarly | PinFault::ModeStuck | PinFault::ModeUnasked => {
                self.mode_fault(c, &mut p)
            }
        }
        let frozen = matches!(self.fault, PinFault::PhaseShift { .. })
            && c >= self.t
            && c <= self.t.saturating_add(self.r);
        if !frozen {
            self.prev_cs = orig_cs;
            self.prev_sclk = orig_sclk;
        }
        self.changed |= glitch || p != orig;
        p
    }
}

impl<D> FaultyDut<D> {
    /// Cycle `c` under the command word's faults, in the target
    /// conversion's read (bit `i` of the word is on the lane through SCLK
    /// period `i + 1`: docs/timing.md, "Command words").
    fn command_fault(&mut self, c: u64, p: &mut Pins, b: usize) {
        let Some(lane) = self.layout.mosi_lo[b] else {
            return;
        };
        let was = p.mosi >> lane & 1 == 1;
        let d = self.d as usize;
        let delayed = (self.mosi_hist.len() == d).then(|| self.mosi_hist[0]);
        if self.mosi_hist.len() == d {
            self.mosi_hist.pop_front();
        }
        self.mosi_hist.push_back(was);
        if c < self.t + self.su || c >= self.t.saturating_add(self.r) {
            return;
        }
        let i = (c - self.t - self.su) / self.d;
        let v = match self.fault {
            PinFault::WrongChannelBits { .. } if i == self.cmd_bit => !was,
            PinFault::LateCommand { .. } if i == 0 => false,
            PinFault::LateCommand { .. } => delayed.unwrap_or(false),
            _ => was,
        };
        p.mosi = (p.mosi & !(1 << lane)) | (v as u16) << lane;
    }

    /// Cycle `c` under the sample stream's faults.
    #[inline]
    fn sample_fault(&mut self, c: u64, p: &mut Pins, orig: &Pins) {
        match self.fault {
            PinFault::WrongChannel | PinFault::WrongSampleBit | PinFault::DropSample
                if !self.done && c >= self.at && p.sample_valid =>
            {
                self.done = true;
                match self.fault {
                    PinFault::WrongChannel => p.sample_channel ^= 1,
                    PinFault::WrongSampleBit => p.sample_value ^= 1 << 5,
                    _ => p.sample_valid = false,
                }
            }
            PinFault::NeighbourCode if p.sample_valid => {
                if let (false, true, Some(v)) = (self.done, c >= self.at, self.last_value) {
                    p.sample_value = v;
                    self.done = true;
                }
                self.last_value = Some(orig.sample_value);
            }
            _ => {}
        }
    }

    /// Cycle `c` under the serial lanes' faults (CS and SCLK).
    #[inline]
    fn serial_fault(&mut self, c: u64, p: &mut Pins) {
        match self.fault {
            PinFault::CsLate { branch } if c >= self.t && c <= self.t.saturating_add(self.r) => {
                let bit = 1u16 << branch;
                p.cs_n = (p.cs_n & !bit) | (self.prev_cs & bit);
            }
            PinFault::SclkExtraEdge { branch } => {
                // a one-cycle low pulse in a high phase of SCLK, two periods
                // into the read (one more falling edge than the part expects)
                // (in the middle of the high phase when it is 3 cycles or
                // more; else the high phase vanishes: one falling edge fewer)
                let bit = 1u16 << branch;
                let mid_high = self.prev_sclk & bit != 0 || self.high < 3;
                if !self.done
                    && c >= self.t.saturating_add(self.su + 2 * self.d)
                    && p.sclk & bit != 0
                    && mid_high
                {
                    p.sclk &= !bit;
                    self.done = true;
                }
            }
            PinFault::PhaseShift { branch } => {
                let bit = 1u16 << branch;
                if c >= self.t && c <= self.t.saturating_add(self.r) {
                    // the branch's lanes stay as they were before the instant
                    p.cs_n = (p.cs_n & !bit) | (self.prev_cs & bit);
                    p.sclk = (p.sclk & !bit) | (self.prev_sclk & bit);
                }
                if !self.done
                    && c > self.t.saturating_add(self.r)
                    && p.sample_valid
                    && p.sample_channel == self.channels.0
                {
                    p.sample_valid = false;
                    self.done = true;
                }
            }
            _ => {}
        }
    }

    /// Cycle `c` under the mux lanes' faults.
    #[inline]
    fn mux_fault(&mut self, c: u64, p: &mut Pins) {
        match self.fault {
            PinFault::MuxLate { branch } => {
                if c == self.t_prev.saturating_add(1) {
                    self.held = Some(pins_before(&self.layout, p, branch, self.t_prev));
                }
                if c > self.t_prev && c + 2 < self.t {
                    if let Some(h) = self.held {
                        copy_mux(&self.layout, p, &h, branch);
                    }
                }
            }
            PinFault::TwoMuxEn { branch } if c >= self.t && c < self.t.saturating_add(5) => {
                let n = self.layout.en_n[branch];
                p.mux_en |= ((1u128 << n) - 1) << self.layout.en_lo[branch];
            }
            PinFault::WrongMux { branch } if c > self.t_prev && c <= self.t => {
                p.mux_sel ^= 1 << self.layout.sel_lo[branch];
            }
            PinFault::SelectSwap { branch } if c >= self.at && c < self.at + self.frame => {
                self.swap_selects(p, branch);
            }
            _ => {}
        }
    }

    /// Cycle `c` under the link's faults but the UART character's.
    #[inline]
    fn link_fault(&mut self, c: u64, p: &mut Pins, orig: &Pins) {
        match self.fault {
            PinFault::LinkStuck { high } if c >= self.at => {
                p.link_tx = high;
            }
            PinFault::LinkOverflow if c >= self.at => {
                p.link_overflow = true;
            }
            PinFault::AxisTvalidDrop | PinFault::AxisTdataChange => {
                if self.stalled && !self.done && c >= self.at {
                    self.done = true;
                    if self.fault == PinFault::AxisTdataChange {
                        p.axis_tdata ^= 0x01;
                    } else {
                        p.axis_tvalid = false;
                    }
                }
                self.stalled = orig.axis_tvalid && !orig.axis_tready;
            }
            _ => {}
        }
    }

    /// The original pins `k` cycles ago (0: this cycle).
    fn orig(&self, k: u64) -> Option<&Pins> {
        let n = self.hist.len() as u64;
        (k < n).then(|| &self.hist[(n - 1 - k) as usize])
    }

    /// [`PinFault::ConversionMoved`]: the branch's CS, SCLK and mux lanes
    /// delayed by one slot from the instant until the moved window closes.
    fn move_conversion(&self, c: u64, p: &mut Pins, b: usize) {
        let end = self.t.saturating_add(self.shift + self.r + 1);
        if c < self.t || c >= end {
            return;
        }
        if let Some(o) = self.orig(self.shift).copied() {
            let bit = 1u16 << b;
            p.cs_n = (p.cs_n & !bit) | (o.cs_n & bit);
            p.sclk = (p.sclk & !bit) | (o.sclk & bit);
            copy_mux(&self.layout, p, &o, b);
        }
    }

    /// [`PinFault::SclkSlow`]: the conversion's serial clocks stretched to the
    /// slow period (setup as it was, the tail after the last clock kept).
    fn slow_sclk(&self, c: u64, p: &mut Pins, b: usize) {
        let (t, su, d, d2, n) = (self.t, self.su, self.d, self.d_slow, self.words);
        let end = t.saturating_add(self.shift);
        if c < t.saturating_add(su) || c >= end {
            return;
        }
        let j = c - t - su;
        let src = if j < n * d2 {
            t + su + j * d / d2
        } else {
            t + su + n * d + (j - n * d2)
        };
        if let Some(o) = self.orig(c - src) {
            let bit = 1u16 << b;
            p.cs_n = (p.cs_n & !bit) | (o.cs_n & bit);
            p.sclk = (p.sclk & !bit) | (o.sclk & bit);
        }
    }

    /// [`PinFault::LinkBitFlip`], [`PinFault::LinkDropByte`]: the UART's
    /// characters followed on the design's own line from cycle 0 (a start
    /// bit is a falling edge once the previous character has ended), and
    /// the first one starting at or after the site corrupted.
    fn uart_char(&mut self, c: u64, p: &mut Pins) {
        let Some(u) = self.uart else { return };
        if self.hit.is_none() && c >= self.char_end && !p.link_tx {
            self.char_end = c + u.char_cycles();
            if c >= self.at {
                self.hit = Some(c);
            }
        }
        let Some(t) = self.hit else { return };
        let d = u.div as u64;
        match self.fault {
            // the line's bit 4 is data bit 3 (bit 0 is the start bit)
            PinFault::LinkBitFlip if c >= t + 4 * d && c < t + 5 * d => p.link_tx = !p.link_tx,
            PinFault::LinkDropByte if c < t + u.char_cycles() => p.link_tx = true,
            _ => {}
        }
    }

    /// [`PinFault::SelectSwap`]: branch `b` addressing one of the pair shows
    /// the other's mux address.
    fn swap_selects(&self, p: &mut Pins, b: usize) {
        let (x, y) = self.channels;
        let other = match self.layout.selected(p, b) {
            Ok(ch) if ch == x => y,
            Ok(ch) if ch == y => x,
            _ => return,
        };
        let (dev, sel) = self.addresses[other as usize];
        self.layout.set_mux(p, b, dev, sel);
    }
}

impl<D> FaultyDut<D> {
    /// The mode faults at frame start `at` (which the campaign chooses).
    fn mode_fault(&mut self, c: u64, p: &mut Pins) {
        let other = (p.mode + 1) % self.modes;
        let frame = c >= self.at && c < self.at + self.frame;
        match self.fault {
            PinFault::ModeEarly if c + 1 == self.at => p.mode = other,
            PinFault::ModeStuck if frame => p.mode = self.mode_before,
            PinFault::ModeUnasked if frame => p.mode = other,
            _ => self.mode_before = p.mode,
        }
    }

    /// Whether the fault has changed anything yet (a fault that found
    /// nothing to change was not injected).
    pub fn injected(&self) -> bool {
        self.changed
    }
}

/// Pins with the mux of `branch` as it was before it switched (we only know
/// the new value at `t_prev + 1`, so keep the select but flip to a different
/// channel: the previous one is not recorded; use select ^ 1 as "old").
fn pins_before(layout: &Layout, p: &Pins, branch: usize, _t_prev: u64) -> Pins {
    let mut h = *p;
    h.mux_sel ^= 1 << layout.sel_lo[branch];
    h
}

fn copy_mux(layout: &Layout, p: &mut Pins, from: &Pins, b: usize) {
    if !layout.muxed[b] {
        return; // no mux lanes
    }
    let selm = 7u64 << layout.sel_lo[b];
    p.mux_sel = (p.mux_sel & !selm) | (from.mux_sel & selm);
    let enm = ((1u128 << layout.en_n[b]) - 1) << layout.en_lo[b];
    p.mux_en = (p.mux_en & !enm) | (from.mux_en & enm);
}
