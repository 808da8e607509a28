//! The transmitter's cycle model: packetizer, FIFO, serializer and UART,
//! register for register as `docs/packet-format.md` ("Timing") states it.
//! The judge steps it beside its model of the sample stream to predict the
//! line in every cycle; the audit runs it to measure the FIFO's worst-case
//! backlog and the latency to the wire.

use std::collections::VecDeque;

use crate::axis::{AxisFormat, ReadyDriver, ReadyPattern, Tlast};
use crate::format::{self, Token, WordKind, CRC_INIT, END, SYNC};
use crate::uart::UartFormat;

/// The physical side of the link: a UART line or an AXI4-Stream master.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Line {
    Uart(UartFormat),
    Axis(AxisFormat),
}

impl Line {
    /// Cycles one byte occupies the line at worst: a UART character, or
    /// the AXIS slave's guarantee (`ready_within`).
    pub fn char_cycles(&self) -> u64 {
        match self {
            Line::Uart(u) => u.char_cycles(),
            Line::Axis(a) => a.ready_within as u64,
        }
    }
}

/// What the transmitter is built for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TxConfig {
    pub line: Line,
    /// Cycles per slice: a packet closes and the next opens every slice.
    pub slice_cycles: u64,
    pub slices_per_frame: u64,
    /// FIFO depth in tokens; `None`: unbounded (to measure the backlog).
    pub depth: Option<usize>,
    /// Bits of the `mode` input (a mix with modes; 0 without): each header
    /// carries its frame's mode and the one before ([`format::slice_field`]).
    pub mode_bits: u32,
}

/// The byte on the line and what it carries, for reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ByteOnLine {
    pub byte: u8,
    pub kind: WordKind,
    /// Byte of its word (0..4).
    pub index: u8,
    /// The packet it belongs to: (frame counter mod 256, slice).
    pub packet: (u8, u16),
    /// The sample a record carries: (channel, code).
    pub sample: Option<(u16, u16)>,
    /// The edge that loaded it: the start bit is the next cycle.
    pub loaded_at: u64,
}

/// A header's first byte as a line seen from the middle of a run showed
/// it: enough to give a transmitter the state the design's had then (see
/// [`TxModel::at_header`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HeaderOnLine {
    /// The cycle its SYNC byte was first on the line (the start bit, or
    /// the first cycle of the beat's offer), counted as a run from reset
    /// counts them: slice boundaries at multiples of `slice_cycles`.
    pub first: u64,
    /// Its frame counter and slice.
    pub frame: u8,
    pub slice: u16,
    /// Its frame's mode and the mode of the frame before (0 without modes).
    pub mode: u8,
    pub prev_mode: u8,
    /// The overflow count the trailer before it carried, and the sticky flag.
    pub overflows: u8,
    pub overflow_flag: bool,
    /// The sample written with the slice boundary's token, whose record
    /// follows the header.
    pub boundary_sample: Option<(u16, u16)>,
    /// The tokens written after the boundary's, up to and including the
    /// edge that loaded the SYNC byte: the FIFO's contents then.
    pub queued: Vec<Token>,
}

/// The transmitter in one cycle (the state its registers hold).
#[derive(Debug, Clone)]
pub struct TxModel {
    cfg: TxConfig,
    /// Cycle counter of the edges seen since reset (the current cycle's number).
    cycle: u64,
    pos: u64,
    fifo: VecDeque<Token>,
    have: bool,
    tok: Token,
    mask: u16,
    started: bool,
    hframe: u8,
    hslice: u16,
    /// The modes of the last header's frame and of the frame before it,
    /// and the `mode` input in the current cycle.
    fmode: u8,
    pmode: u8,
    mode_in: u8,
    crc: u16,
    ovf: u8,
    ovf_flag: bool,
    busy: bool,
    bit: u32,
    div: u32,
    byte: u8,
    tx: bool,
    /// AXIS: `tlast` of the byte offered, and `tready` in the current cycle.
    tlast: bool,
    tready: bool,
    cur: Option<ByteOnLine>,
    /// Largest FIFO occupancy seen.
    pub max_backlog: usize,
    /// Edges at which a trailer's last byte finished on the wire, in order:
    /// the exclusive end cycle of its last stop bit.
    pub trailer_ends: Option<Vec<u64>>,
}

impl TxModel {
    /// The transmitter before any clock edge; it needs a reset.
    pub fn new(cfg: TxConfig) -> TxModel {
        let mut t = TxModel {
            cfg,
            cycle: 0,
            pos: 0,
            fifo: VecDeque::new(),
            have: false,
            tok: Token::default(),
            mask: 0,
            started: false,
            hframe: 0,
            hslice: 0,
            fmode: 0,
            pmode: 0,
            mode_in: 0,
            crc: CRC_INIT,
            ovf: 0,
            ovf_flag: false,
            busy: false,
            bit: 0,
            div: 0,
            byte: 0,
            tx: true,
            tlast: false,
            tready: true,
            cur: None,
            max_backlog: 0,
            trailer_ends: None,
        };
        t.reset();
        t
    }

    /// The transmitter in cycle `h.first` of a run it did not see from
    /// reset, rebuilt from a header on the line: the boundary's token is
    /// being sent (its trailer went before, the SYNC byte is on the line)
    /// and the tokens written since wait behind it, so its registers are
    /// the design's, counters included.  (A run's state cannot be had from
    /// the schedule alone: the frame counter, the backlog left by frame 0
    /// and the samples in flight are the run's own.)
    pub fn at_header(cfg: TxConfig, h: &HeaderOnLine) -> TxModel {
        let mut t = TxModel::new(cfg);
        let tok = Token {
            boundary: true,
            sample: h.boundary_sample,
            mode: h.mode,
        };
        // In cycle x of a run the transmitter has seen x + 1 edges.
        t.cycle = h.first + 1;
        t.pos = h.first % cfg.slice_cycles;
        t.fifo = h.queued.iter().copied().collect();
        t.tok = tok;
        t.started = true;
        // slots 0..=4 (the trailer and the SYNC byte) have been loaded
        t.mask = Self::slots(&tok, true) & !0x1F;
        t.have = t.mask != 0;
        t.hframe = h.frame;
        t.hslice = h.slice;
        t.fmode = h.mode;
        t.pmode = h.prev_mode;
        t.crc = format::crc_update(CRC_INIT, SYNC);
        t.ovf = h.overflows;
        t.ovf_flag = h.overflow_flag;
        t.busy = true;
        t.byte = SYNC;
        t.tx = !matches!(cfg.line, Line::Uart(_));
        t.cur = Some(ByteOnLine {
            byte: SYNC,
            kind: WordKind::Header,
            index: 0,
            packet: (h.frame, h.slice),
            sample: None,
            loaded_at: h.first,
        });
        t
    }

    fn reset(&mut self) {
        self.pos = self.cfg.slice_cycles - 1;
        self.fifo.clear();
        self.have = false;
        self.mask = 0;
        self.started = false;
        self.hframe = 0;
        self.hslice = 0;
        self.fmode = 0;
        self.pmode = 0;
        self.crc = CRC_INIT;
        self.ovf = 0;
        self.ovf_flag = false;
        self.busy = false;
        self.bit = 0;
        self.div = 0;
        self.tx = true;
        self.tlast = false;
        self.byte = 0;
        self.cur = None;
    }

    pub fn config(&self) -> &TxConfig {
        &self.cfg
    }

    /// The line (`link_tx`) in the current cycle.
    pub fn line(&self) -> bool {
        self.tx
    }

    /// AXIS `tvalid` in the current cycle (a byte is offered).
    pub fn tvalid(&self) -> bool {
        self.busy
    }

    /// AXIS `tdata` in the current cycle (the last byte offered).
    pub fn tdata(&self) -> u8 {
        self.byte
    }

    /// AXIS `tlast` in the current cycle.
    pub fn tlast(&self) -> bool {
        self.tlast
    }

    /// AXIS: the slave's `tready` in the current cycle, before [`TxModel::clock`].
    pub fn set_tready(&mut self, r: bool) {
        self.tready = r;
    }

    /// A mix with modes: the `mode` input in the current cycle, before
    /// [`TxModel::clock`] (a boundary's token takes it to its header).
    pub fn set_mode(&mut self, mode: u8) {
        self.mode_in = mode;
    }

    /// The sticky overflow flag (`link_overflow`) in the current cycle.
    pub fn overflow(&self) -> bool {
        self.ovf_flag
    }

    /// Tokens waiting in the FIFO in the current cycle.
    pub fn backlog(&self) -> usize {
        self.fifo.len()
    }

    /// The byte being sent, and which of its bits is on the line.
    pub fn on_line(&self) -> Option<(ByteOnLine, u32)> {
        if self.busy {
            self.cur.map(|c| (c, self.bit))
        } else {
            None
        }
    }

    /// Whether nothing is queued or in flight.
    pub fn idle(&self) -> bool {
        self.fifo.is_empty() && !self.have && !self.busy
    }

    /// The clock edge at the end of the current cycle.  `sample` is the
    /// merged stream in this cycle (`sample_valid` with channel and code).
    pub fn clock(&mut self, rst: bool, sample: Option<(u16, u16)>) {
        self.cycle += 1;
        if rst {
            self.reset();
            return;
        }
        let token = Token {
            boundary: self.pos == 0,
            sample,
            mode: self.mode_in,
        };
        let ready = match self.cfg.line {
            Line::Uart(u) => !self.busy || (self.div + 1 == u.div && self.bit + 1 == u.bits()),
            Line::Axis(_) => !self.busy || self.tready,
        };
        let load = ready && self.have;
        let pop = !self.have && !self.fifo.is_empty();
        let popped = if pop { self.fifo.pop_front() } else { None };
        if token.boundary || token.sample.is_some() {
            let room = self.cfg.depth.is_none_or(|d| self.fifo.len() < d || pop);
            if room {
                self.fifo.push_back(token);
            } else {
                self.ovf = self.ovf.saturating_add(1);
                self.ovf_flag = true;
            }
        }
        self.max_backlog = self.max_backlog.max(self.fifo.len());
        if self.busy {
            match self.cfg.line {
                Line::Uart(u) => self.uart_tick(u),
                // a beat is taken at an edge where tvalid and tready are high
                Line::Axis(_) => self.busy = !self.tready,
            }
        }
        if load {
            self.load_byte();
        }
        if let Some(t) = popped {
            self.tok = t;
            self.have = true;
            self.mask = Self::slots(&t, self.started);
        }
        self.pos = if self.pos + 1 == self.cfg.slice_cycles {
            0
        } else {
            self.pos + 1
        };
    }

    /// One clock of the UART's bit timer while a character is on the line.
    fn uart_tick(&mut self, u: UartFormat) {
        if self.div + 1 == u.div {
            self.div = 0;
            if self.bit + 1 == u.bits() {
                self.busy = false;
                self.tx = true;
            } else {
                self.bit += 1;
                self.tx = u.bit(self.byte, self.bit);
            }
        } else {
            self.div += 1;
        }
    }

    /// The byte slots (bit `i` = slot `i` of 12) a token sends: the previous
    /// packet's trailer (once a header has been sent), a header at a slice
    /// boundary, a record for a sample.
    fn slots(t: &Token, started: bool) -> u16 {
        let mut m = 0;
        if t.boundary && started {
            m |= 0x00F;
        }
        if t.boundary {
            m |= 0x0F0;
        }
        if t.sample.is_some() {
            m |= 0xF00;
        }
        m
    }

    fn load_byte(&mut self) {
        let slot = self.mask.trailing_zeros() as u8;
        self.mask &= self.mask - 1;
        self.have = self.mask != 0;
        let (ch, val) = self.tok.sample.unwrap_or((0, 0));
        if slot == 4 {
            // a header: its frame's mode, and the one before at a frame's first
            if self.hslice == 0 {
                self.pmode = self.fmode;
            }
            self.fmode = self.tok.mode;
        }
        let field = format::slice_field(self.hslice, self.fmode, self.pmode, self.cfg.mode_bits);
        let byte = match slot {
            0 => END,
            1 => self.ovf,
            2 => self.crc as u8,
            3 => (self.crc >> 8) as u8,
            4 => SYNC,
            5 => self.hframe,
            6 => (field >> 8) as u8,
            7 => field as u8,
            8 => (ch >> 8) as u8,
            9 => ch as u8,
            10 => (val >> 8) as u8,
            _ => val as u8,
        };
        let kind = WordKind::of_slot(slot);
        let packet = match kind {
            WordKind::Header => (self.hframe, self.hslice),
            _ => self.last_header(),
        };
        match slot {
            2 | 3 => {}
            4 => self.crc = format::crc_update(CRC_INIT, byte),
            _ => self.crc = format::crc_update(self.crc, byte),
        }
        if slot == 3 {
            if let Some(v) = self.trailer_ends.as_mut() {
                v.push(self.cycle + self.cfg.line.char_cycles());
            }
        }
        if slot == 7 {
            self.started = true;
            self.hslice += 1;
            if self.hslice as u64 == self.cfg.slices_per_frame {
                self.hslice = 0;
                self.hframe = self.hframe.wrapping_add(1);
            }
        }
        self.byte = byte;
        self.busy = true;
        self.bit = 0;
        self.div = 0;
        match self.cfg.line {
            Line::Uart(_) => self.tx = false,
            Line::Axis(a) => {
                let last_slice = packet.1 as u64 + 1 == self.cfg.slices_per_frame;
                self.tlast = slot == 3 && (a.tlast == Tlast::Slice || last_slice);
            }
        }
        self.cur = Some(ByteOnLine {
            byte,
            kind,
            index: slot % 4,
            packet,
            sample: self.tok.sample.filter(|_| kind == WordKind::Record),
            loaded_at: self.cycle - 1,
        });
    }

    /// The packet of the last header sent, from the counters of the next one.
    fn last_header(&self) -> (u8, u16) {
        if self.hslice == 0 {
            (
                self.hframe.wrapping_sub(1),
                (self.cfg.slices_per_frame - 1) as u16,
            )
        } else {
            (self.hframe, self.hslice - 1)
        }
    }
}

/// What the audit needs to know about a link carrying a periodic stream.
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyState {
    /// The FIFO's exact worst-case backlog, in tokens.
    pub backlog: usize,
    /// Worst cycles from a sampling instant to the end of its packet's
    /// trailer on the wire.
    pub latency_cycles: u64,
    /// Frames simulated until the transmitter's state at a frame start
    /// repeated.
    pub frames: u64,
}

/// A model's header fields between headers: its frame's mode, the mode
/// before, the overflow count and flag.  For this crate's tests
/// (`crate::for_tests`), which rebuild a model at a header from them; the
/// fields stay off `TxModel`'s face.
pub fn header_state(t: &TxModel) -> (u8, u8, u8, bool) {
    (t.fmode, t.pmode, t.ovf, t.ovf_flag)
}

/// Run the transmitter (unbounded FIFO) on a periodic stream until its state
/// at a frame start repeats.  `frame` lists the merged stream of one frame in
/// steady state: `(valid cycle in frame, instant cycle in frame, channel,
/// code)`; a sample may leave after its frame ends (a valid cycle beyond the
/// frame) and its instant is then in the frame it belongs to.  `None` if the
/// backlog keeps growing for `max_frames` frames (the link cannot drain it).
pub fn steady_state(
    cfg: TxConfig,
    frame: &[(u64, u64, u16)],
    max_frames: u64,
) -> Option<SteadyState> {
    let frame_cycles = cfg.slice_cycles * cfg.slices_per_frame;
    let cfg = TxConfig { depth: None, ..cfg };
    let mut t = TxModel::new(cfg);
    t.trailer_ends = Some(Vec::new());
    t.clock(true, None);
    // AXIS: the slowest slave the guarantee allows
    let mut slave = match cfg.line {
        Line::Axis(a) => Some(ReadyDriver::new(ReadyPattern::WorstCase, a.ready_within)),
        Line::Uart(_) => None,
    };
    let mut valid: std::collections::BTreeMap<u64, u16> = Default::default();
    let mut windows: Vec<u64> = Vec::new(); // earliest instant per window
    let mut prev_state = None;
    for f in 0..max_frames {
        let base = f * frame_cycles;
        for &(v, i, ch) in frame {
            valid.insert(base + v, ch);
            let w = ((base + v) / cfg.slice_cycles) as usize;
            if windows.len() <= w {
                windows.resize(w + 1, u64::MAX);
            }
            windows[w] = windows[w].min(base + i);
        }
        let state = (
            t.fifo.clone(),
            t.have,
            t.mask,
            t.busy,
            t.bit,
            t.div,
            t.started,
        );
        if prev_state.as_ref() == Some(&state) && f >= 2 {
            let ends = t.trailer_ends.as_ref().expect("recorded");
            // trailer k closes window k; windows of the last frame may be open
            let latency = windows
                .iter()
                .enumerate()
                .filter(|&(w, &i)| i != u64::MAX && w < ends.len())
                .map(|(w, &i)| ends[w] - i)
                .max()
                .unwrap_or(0);
            return Some(SteadyState {
                backlog: t.max_backlog,
                latency_cycles: latency,
                frames: f,
            });
        }
        prev_state = Some(state);
        for c in base..base + frame_cycles {
            let s = valid.remove(&c).map(|ch| (ch, 0));
            if let Some(d) = slave.as_mut() {
                let r = d.ready(t.tvalid());
                t.set_tready(r);
            }
            t.clock(false, s);
        }
    }
    None
}
