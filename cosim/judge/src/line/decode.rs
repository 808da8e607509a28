//! The link to the host judged without the reference model: the UART line
//! (`link_tx`) or the AXI4-Stream beats (`m_axis_tdata`/`tvalid`/`tready`/
//! `tlast`); one of the checker's invariants, so that a waveform checked
//! with the model off (`check --no-model`, the fault campaign's
//! `invariants` column) still sees a broken link.
//!
//! From the mix alone (`docs/packet-format.md`):
//! - **beats** (AXIS): a byte is the `tdata` of a cycle with `tvalid` and
//!   `tready` both high; `tlast` is high on exactly the beats that end a
//!   packet (every trailer, or a frame's last slice's with `tlast = "frame"`);
//!   the handshake's stability is the checker's `axis-stable`;
//! - **framing** (UART): every character is a low start bit, 8 data bits, the
//!   parity bit if any and high stop bits, each bit `div` cycles at the
//!   declared baud; the line changes only on a bit boundary of the
//!   character being sent (a cycle is a VCD's resolution), and a start bit
//!   never begins before the previous character's last stop bit ended;
//! - **packets**: the characters (or beats) go through `link`'s own receiver and host
//!   decoder (the packet format has one home): every packet's CRC is good
//!   and no byte falls outside a packet;
//! - **sequence**: the packets are the slices in order, frame counter and
//!   slice as the stream's cycles give them (from reset the counter is the
//!   frame number mod 256; a check that joined a run learns it from the
//!   first good packet), none lost, none repeated, none early;
//! - **content**: each packet carries exactly the samples whose
//!   `sample_valid` strobe fell in its slice's cycles, in order, channel
//!   and value; a trailer reports no FIFO overflow;
//! - **modes** (a mix with modes): each header names the mode `mode`
//!   showed in its slice and the mode of the frame before;
//! - **delivery**: a slice's packet has arrived at the latest the audit's
//!   worst-case latency (`lut_gen::plan_link`) plus one slice after the
//!   slice ended, so a line that goes quiet is caught.

use std::collections::VecDeque;

use link::{AxisFormat, Decoder, Packet, Stats, Tlast, UartFormat};
use link::{RxByte, UartRx};
use lut_gen::Pins;
use lut_gen::Schedule;
use serde_json::json;

use crate::model::Invariants;
use crate::model::Rule;
use crate::model::Violation;

const UART_LINE: &str = "link_tx";
const AXIS_BEATS: &str = "m_axis_tdata";

/// The samples the stream emitted in one slice: (channel, value, cycle).
#[derive(Debug, Clone, Default)]
struct Window {
    samples: Vec<(u16, u16, u64)>,
}

/// The UART line's receiver and bit timing.
#[derive(Debug, Clone)]
struct Uart {
    fmt: UartFormat,
    rx: UartRx,
    /// The receiver's sample 0 is this cycle.
    rx_origin: u64,
    /// The line in the cycle before.
    level: bool,
    /// The start of the character the receiver took last, and whether a
    /// timing fault in it was already reported.
    char_start: Option<u64>,
    char_flagged: bool,
}

/// Where the bytes come from: a serial line or AXI4-Stream beats.
#[derive(Debug, Clone)]
enum Wire {
    Uart(Uart),
    Axis(AxisFormat),
}

/// A joined check learning the run's slice phase: the samples since the
/// join (cycle, channel, code), the join's cycle, the packets that fitted
/// no slice.
type Learning = (Vec<(u64, u16, u16)>, u64, u32);

/// The link's checks (a mix with a `[link]`).
#[derive(Debug, Clone)]
pub(crate) struct LinkLine {
    wire: Wire,
    /// The port violations name: `link_tx` or `m_axis_tdata`.
    port: &'static str,
    dec: Decoder,
    packets: Vec<Packet>,
    seen: Stats,
    /// The decoder lost its place and the loss was reported.
    lost_place: bool,
    overflow_reported: bool,
    names: Vec<String>,
    slice_cycles: u64,
    slices: u64,
    latency: u64,
    /// Slices with their samples, from `base` on (the oldest not yet received).
    windows: VecDeque<Window>,
    base: u64,
    /// The first slice whose samples the check saw whole (0 from reset).
    first: u64,
    next_boundary: u64,
    /// Window of a packet = the decoder's sequence (frame * slices + slice)
    /// + `offset`; learnt from the first good packet after a join.
    offset: Option<i64>,
    /// In step with the line: from reset, or since the first good packet
    /// after joining a run mid-stream (what came before is a partial
    /// character or packet, not a fault).
    synced: bool,
    /// The run's slices begin this many cycles before the model's: the
    /// lock knows the frame phase only modulo the CS/mux pins' repeat, so
    /// a check that joined learns it from the first packet whose records
    /// it finds in its sample stream (`join::find_boundary`).
    delta: u64,
    /// Joined mid-stream and still learning `delta`: every sample since
    /// the join, (cycle, channel, code), the cycle it joined at, and the
    /// good packets that fitted no slice.
    learning: Option<Learning>,
    /// The run's slices begin a multiple of this off the model's.
    step: u64,
    /// Where a check that joined mid-stream joined the line: (the cycle
    /// the first packet judged ended in, its frame counter and slice, the
    /// bytes before it, the cycle its header began in if still known).
    pub(crate) joined: Option<(u64, u8, u16, u64, Option<u64>)>,
    /// Joined mid-stream and not yet at a packet: the first cycle of each
    /// byte read (the last [`MAX_STARTS`]), for the joined packet's header.
    starts: VecDeque<u64>,
    /// A mix with modes: the `mode` pin's changes (cycle, mode) over the
    /// last frames, and the first cycle seen (0 from reset).
    modes: VecDeque<(u64, u8)>,
    mode_bits: u32,
    seen_from: u64,
}

/// The decoder of a mix's packets (its modes' bits in the headers).
pub(crate) fn decoder(s: &Schedule) -> Decoder {
    let bits = match lut_gen::plan_link(s) {
        Some(Ok(p)) => p.tx_config(s).mode_bits,
        _ => 0,
    };
    Decoder::with_modes(s.grid.slices_per_frame, bits)
}

/// Byte start cycles kept while joining: more than any packet's bytes.
const MAX_STARTS: usize = 1 << 14;

impl LinkLine {
    /// The link's checks for a mix with a feasible `[link]`; `None` otherwise.
    pub(crate) fn new(s: &Schedule) -> Option<LinkLine> {
        let plan = lut_gen::plan_link(s)?.ok()?;
        let (wire, port) = match (plan.uart(), plan.axis()) {
            (Some(fmt), _) => (
                Wire::Uart(Uart {
                    fmt,
                    rx: UartRx::new(fmt),
                    rx_origin: 0,
                    level: true,
                    char_start: None,
                    char_flagged: false,
                }),
                UART_LINE,
            ),
            (None, Some(fmt)) => (Wire::Axis(fmt), AXIS_BEATS),
            (None, None) => return None,
        };
        Some(LinkLine {
            wire,
            port,
            dec: decoder(s),
            packets: Vec::new(),
            seen: Stats::default(),
            lost_place: false,
            overflow_reported: false,
            names: s.mix.channels.iter().map(|c| c.name.clone()).collect(),
            slice_cycles: s.grid.slice_cycles,
            slices: s.grid.slices_per_frame,
            latency: plan.latency_cycles,
            windows: VecDeque::new(),
            base: 0,
            first: 0,
            next_boundary: 0,
            offset: Some(0),
            synced: true,
            delta: 0,
            learning: None,
            step: s.grid.slice_cycles,
            joined: None,
            starts: VecDeque::new(),
            modes: VecDeque::new(),
            mode_bits: plan.tx_config(s).mode_bits,
            seen_from: 0,
        })
    }

    /// The check joins a run at cycle `origin` with the line at `level`:
    /// slices from the first that starts at or after it are checked, and
    /// the line from the first good packet on.
    pub(crate) fn join_at(&mut self, origin: u64, level: bool, step: u64) {
        self.step = step;
        if let Wire::Uart(u) = &mut self.wire {
            u.rx_origin = origin;
            u.level = level;
        }
        self.first = origin.div_ceil(self.slice_cycles);
        self.base = self.first;
        self.next_boundary = self.first * self.slice_cycles;
        self.offset = None;
        self.synced = false;
        self.learning = Some((Vec::new(), origin, 0));
        self.seen_from = origin;
    }

    /// Bytes read from the line so far.
    pub(crate) fn bytes_read(&self) -> u64 {
        self.dec.stats().bytes
    }

    /// The model cycle slice `w` begins in.
    fn start_of(&self, w: u64) -> u64 {
        (w * self.slice_cycles).saturating_sub(self.delta)
    }

    /// Good packet `p` arrived in cycle `c` while learning the run's slice
    /// phase: whether it is known now (the slices rebuilt on it).  Two
    /// packets that fit no slice: the lock's phase is taken, so that a
    /// link whose records are all wrong still fails.
    fn learn(&mut self, c: u64, p: &Packet) -> bool {
        let Some((log, origin, misses)) = &mut self.learning else {
            return true;
        };
        let s = self.slice_cycles;
        let b = crate::line::join::find_boundary(log, &p.records, (*origin, c), self.step, s);
        let delta = match b {
            Some(b) => (s - b % s) % s,
            None if *misses >= 1 => 0,
            None => {
                *misses += 1;
                return false;
            }
        };
        let (log, origin, _) = self.learning.take().unwrap_or_default();
        self.delta = delta;
        if let Some(b) = b {
            // the packet's slice is known: its counters give every other's
            let seq = (p.frame % 256) as i64 * self.slices as i64 + p.slice as i64;
            self.offset = Some(((b + delta) / s) as i64 - seq);
        }
        self.first = (origin + delta).div_ceil(s);
        self.base = self.first;
        let now = (c + delta) / s;
        self.windows = (self.first..=now).map(|_| Window::default()).collect();
        self.next_boundary = self.start_of(now + 1);
        for (at, ch, v) in log {
            let w = (at + delta) / s;
            if w >= self.first {
                self.windows[(w - self.first) as usize]
                    .samples
                    .push((ch, v, at));
            }
        }
        true
    }

    /// The link's pins in cycle `c` (every cycle, in order).
    #[inline]
    pub(crate) fn cycle(&mut self, c: u64, p: &Pins, inv: &mut Invariants) {
        if self.mode_bits > 0 && self.modes.back().map(|m| m.1) != Some(p.mode) {
            self.modes.push_back((c, p.mode));
            let keep = c.saturating_sub(4 * self.slices * self.slice_cycles);
            while self.modes.len() > 2 && self.modes[1].0 <= keep {
                self.modes.pop_front();
            }
        }
        if c >= self.next_boundary {
            self.boundary(c, inv);
        }
        match &mut self.wire {
            Wire::Uart(u) => {
                let tx = p.link_tx;
                let got = u.rx.sample(tx);
                let changed = tx != u.level;
                u.level = tx;
                if changed {
                    self.edge(c, inv);
                }
                if let Some(b) = got {
                    self.character(c, b, inv);
                }
            }
            Wire::Axis(_) => {
                if p.axis_tvalid && p.axis_tready {
                    self.beat(c, p.axis_tdata, p.axis_tlast, inv);
                }
            }
        }
    }

    /// `sample_valid` in cycle `c` with this channel and value.
    pub(crate) fn sample(&mut self, c: u64, channel: u16, value: u16) {
        if let Some((log, _, _)) = &mut self.learning {
            log.push((c, channel, value));
        }
        if c >= self.start_of(self.first) {
            if let Some(w) = self.windows.back_mut() {
                w.samples.push((channel, value, c));
            }
        }
    }

    /// The check ended after cycle `end - 1`: every packet due before
    /// `end` must have arrived.
    pub(crate) fn finish(&mut self, end: u64, inv: &mut Invariants) {
        self.overdue(end, inv);
    }

    /// A slice begins at or before `c`: its window opens, and packets
    /// overdue by now are reported.
    fn boundary(&mut self, c: u64, inv: &mut Invariants) {
        while self.next_boundary <= c {
            self.windows.push_back(Window::default());
            self.next_boundary += self.slice_cycles;
        }
        self.overdue(c, inv);
    }

    /// The last cycle in which slice `w`'s packet may arrive.
    fn due(&self, w: u64) -> u64 {
        self.start_of(w + 2) + self.latency
    }

    /// Reports the packets due before cycle `now` (the cycles before it
    /// have been seen) that have not arrived.
    fn overdue(&mut self, now: u64, inv: &mut Invariants) {
        while !self.windows.is_empty() && self.due(self.base) < now {
            let w = self.base;
            let win = self.windows.pop_front().unwrap_or_default();
            self.base += 1;
            let (slice, frame) = self.slice_frame(w, inv);
            inv.record(
                Violation::new(Rule::LinkPacketMissing, self.due(w))
                    .signal(self.port.to_string())
                    .expected(json!(format!("frame {frame} slice {slice}")))
                    .actual(json!("none"))
                    .channel(
                        win.samples
                            .first()
                            .and_then(|x| self.names.get(x.0 as usize).cloned()),
                    )
                    .detail(format!(
                        "the packet of frame {frame} slice {slice} ({} samples) has not arrived on {} {} cycles after its slice ended (the audit's worst-case latency, {} cycles, plus a slice)",
                        win.samples.len(),
                        self.port,
                        self.latency + self.slice_cycles,
                        self.latency
                    )),
            );
        }
    }

    /// (slice, frame as reports count them) of window `w`.
    fn slice_frame(&self, w: u64, inv: &Invariants) -> (u64, u64) {
        (w % self.slices, inv.place(self.start_of(w)).1)
    }

    /// The line changed in cycle `c`: on a bit boundary of the character
    /// being sent, or the start bit of the next one after it ended.
    fn edge(&mut self, c: u64, inv: &mut Invariants) {
        let synced = self.synced;
        let Wire::Uart(u) = &mut self.wire else {
            return;
        };
        let (div, len) = (u.fmt.div as u64, u.fmt.char_cycles());
        let started = u.rx.reading().map(|s| s + u.rx_origin) == Some(c);
        let Some(s) = u.char_start else {
            if started {
                u.char_start = Some(c);
            }
            return;
        };
        let t = c - s;
        // as reports count cycles (a check that joined counts from there)
        let at = inv.place(s).0;
        let fault = if started {
            (t < len).then(|| format!("a start bit falls {t} cycles after the previous character's start bit (cycle {at}), before its last stop bit ended ({len} cycles: {} bits of {div} cycles)", u.fmt.bits()))
        } else {
            (t < len && !t.is_multiple_of(div)).then(|| format!("{UART_LINE} changed {t} cycles into the character that started at cycle {at}, off its bit boundaries (every bit lasts {div} cycles at the declared baud)"))
        };
        if let Some(detail) = fault {
            // an early start bit always; an edge off the grid once a character
            if synced && (started || !u.char_flagged) {
                inv.record(
                    Violation::new(Rule::LinkBitTiming, c)
                        .signal(UART_LINE.to_string())
                        .expected(json!(format!("a multiple of {div} cycles")))
                        .actual(json!(t))
                        .detail(detail),
                );
            }
            u.char_flagged = true;
        }
        if started {
            u.char_start = Some(c);
            u.char_flagged = false;
        }
    }

    /// The receiver read a character (at the middle of its last stop bit).
    fn character(&mut self, c: u64, b: RxByte, inv: &mut Invariants) {
        let Wire::Uart(u) = &self.wire else {
            return;
        };
        if b.error {
            if self.synced {
                let (origin, parity) = (u.rx_origin, u.fmt.parity);
                inv.record(
                    Violation::new(Rule::LinkFraming, c)
                        .signal(UART_LINE.to_string())
                        .expected(json!("stop bit high"))
                        .actual(json!(0))
                        .detail(format!(
                            "the character that started at cycle {} (data 0x{:02x}) has a low stop bit{} at the declared baud",
                            inv.place(b.start + origin).0,
                            b.byte,
                            if parity == link::Parity::None { "" } else { " or a wrong parity bit" }
                        )),
                );
            }
            return;
        }
        let start = b.start + u.rx_origin;
        self.started(start);
        self.byte(c, b.byte, inv);
    }

    /// A byte began on the line in cycle `c`: kept while joining.
    fn started(&mut self, c: u64) {
        if self.joined.is_some() || self.first == 0 {
            return;
        }
        if self.starts.len() == MAX_STARTS {
            self.starts.pop_front();
        }
        self.starts.push_back(c);
    }

    /// An AXI4-Stream beat in cycle `c`: its byte, and `tlast` where the
    /// packet format ends a packet.
    fn beat(&mut self, c: u64, byte: u8, tlast: bool, inv: &mut Invariants) {
        let Wire::Axis(fmt) = self.wire else { return };
        let before = self.seen;
        self.started(c);
        let ends = self.byte(c, byte, inv);
        let clean = self.seen.crc_errors == before.crc_errors
            && self.seen.skipped_bytes == before.skipped_bytes;
        let wrong = tlast_wrong(fmt, ends, self.slices, tlast, byte);
        if let Some(detail) = wrong.filter(|_| self.synced && clean && !self.lost_place) {
            inv.record(
                Violation::new(Rule::AxisTlast, c)
                    .signal("m_axis_tlast".to_string())
                    .expected(json!(!tlast as u8))
                    .actual(json!(tlast as u8))
                    .detail(detail),
            );
        }
    }

    /// A byte off the link in cycle `c` through the host decoder; the slice
    /// of the last packet it completed, if any.
    fn byte(&mut self, c: u64, byte: u8, inv: &mut Invariants) -> Option<u16> {
        self.dec.push_packets(&[byte], &mut self.packets);
        let st = *self.dec.stats();
        if self.synced && st.crc_errors > self.seen.crc_errors {
            self.lost_place = true;
            inv.record(
                Violation::new(Rule::LinkCrc, c)
                    .signal(self.port.to_string())
                    .detail("a packet's trailer carries a CRC that does not match its bytes"),
            );
        } else if self.synced && st.skipped_bytes > self.seen.skipped_bytes && !self.lost_place {
            self.lost_place = true;
            inv.record(
                Violation::new(Rule::LinkResync, c)
                    .signal(self.port.to_string())
                    .expected(json!(format!("0x{:02x} (a header)", link::format::SYNC)))
                    .actual(json!(format!("0x{byte:02x}")))
                    .detail(format!(
                        "byte 0x{byte:02x} is not where the packet format puts a word: the decoder lost its place and searches for a header"
                    )),
            );
        }
        self.seen = st;
        let mut packets = std::mem::take(&mut self.packets);
        let ended = packets.last().map(|p| p.slice);
        for p in packets.drain(..) {
            self.packet(c, p, inv);
        }
        self.packets = packets;
        ended
    }

    /// A good packet arrived in cycle `c`.
    fn packet(&mut self, c: u64, p: Packet, inv: &mut Invariants) {
        self.lost_place = false;
        if !self.learn(c, &p) {
            return; // its slice is not known yet: in flight at the join
        }
        // A packet closes when the next slice's header is sent: its slice
        // ended before this cycle's.
        let closed = ((c + self.delta) / self.slice_cycles) as i64 - 1;
        if self.joined.is_none() && self.first > 0 {
            let bytes = 4 * (2 + p.records.len() as u64);
            let before = self.dec.stats().bytes.saturating_sub(bytes);
            let header = (self.starts.len() as u64)
                .checked_sub(bytes)
                .map(|i| self.starts[i as usize]);
            self.joined = Some((c, p.frame as u8, p.slice, before, header));
            self.starts = VecDeque::new();
        }
        let w = self.window_of(closed, &p);
        self.overflow(c, &p, inv);
        if w < self.first as i64 {
            return; // its slice began before the check joined
        }
        let (frame8, slice) = (p.frame % 256, p.slice);
        if w < self.base as i64 || w > closed {
            let when = if w > closed {
                "before its slice ended: the frame counter or slice is wrong"
            } else {
                "again, or after a later one"
            };
            let (s, f) = self.slice_frame(self.base, inv);
            inv.record(
                Violation::new(Rule::LinkSequence, c)
                    .signal(self.port.to_string())
                    .expected(json!(format!("the packet of frame {f} slice {s}")))
                    .actual(json!(format!("frame counter {frame8} slice {slice}")))
                    .detail(format!(
                        "the packet with frame counter {frame8} slice {slice} arrived {when}"
                    )),
            );
            return;
        }
        let w = w as u64;
        while self.base < w {
            let (s, f) = self.slice_frame(self.base, inv);
            self.windows.pop_front();
            self.base += 1;
            inv.record(
                Violation::new(Rule::LinkPacketLost, c)
                    .signal(self.port.to_string())
                    .expected(json!(format!("frame {f} slice {s}")))
                    .actual(json!(format!("frame counter {frame8} slice {slice}")))
                    .detail(format!("the packet of frame {f} slice {s} never came: the next good packet on the line is frame counter {frame8} slice {slice}")),
            );
        }
        let win = self.windows.pop_front().unwrap_or_default();
        self.base += 1;
        self.compare(c, w, &win, &p.records, inv);
        if self.mode_bits > 0 {
            self.check_modes(c, w, &p, inv);
        }
    }

    /// The `mode` pin in cycle `x`, if the check saw it.
    fn mode_at(&self, x: i64) -> Option<u8> {
        if x < self.seen_from as i64 {
            // before cycle 0 of a run from reset: mode 0 (frame 0's "before")
            return (self.seen_from == 0).then_some(0);
        }
        let i = self.modes.partition_point(|m| m.0 as i64 <= x);
        (i > 0).then(|| self.modes[i - 1].1)
    }

    /// A mix with modes: the header's mode against `mode` in its slice's
    /// first cycle, and its mode of the frame before against `mode` a frame
    /// earlier.
    fn check_modes(&self, c: u64, w: u64, p: &Packet, inv: &mut Invariants) {
        let start = self.start_of(w) as i64;
        let frame = (self.slices * self.slice_cycles) as i64;
        let (Some(mode), prev) = (self.mode_at(start), self.mode_at(start - frame)) else {
            return;
        };
        if p.mode == mode && prev.is_none_or(|m| m == p.prev_mode) {
            return;
        }
        let (slice, f) = self.slice_frame(w, inv);
        let shown = match prev {
            Some(m) => format!("mode {mode} (the frame before: {m})"),
            None => format!("mode {mode}"),
        };
        inv.record(
            Violation::new(Rule::LinkMode, c)
                .signal(self.port.to_string())
                .expected(json!(shown))
                .actual(json!(format!("mode {} (the frame before: {})", p.mode, p.prev_mode)))
                .detail(format!(
                    "the packet of frame {f} slice {slice} names mode {} (the frame before: {}), but `mode` showed {shown}",
                    p.mode, p.prev_mode
                )),
        );
    }

    /// The slice (window) a packet is of, when the last slice closed is
    /// `closed`: from the 8-bit frame counter and slice, through the offset
    /// a joined check learns from its first good packet (the latest closed
    /// slice with that number), taken as the window of that number nearest
    /// the one expected next. The decoder's own count of frames past 255 is
    /// not used: a packet repeated or out of order looks like a wrap to it.
    fn window_of(&mut self, closed: i64, p: &Packet) -> i64 {
        let slices = self.slices as i64;
        let period = 256 * slices;
        let seq = (p.frame % 256) as i64 * slices + p.slice as i64;
        let offset = *self.offset.get_or_insert_with(|| {
            let back = (closed - p.slice as i64).rem_euclid(slices);
            closed - back - seq
        });
        self.synced = true;
        let ahead = (seq + offset - self.base as i64).rem_euclid(period);
        self.base as i64
            + if ahead > period / 2 {
                ahead - period
            } else {
                ahead
            }
    }

    /// A trailer's overflow count must be 0 (reported once).
    fn overflow(&mut self, c: u64, p: &Packet, inv: &mut Invariants) {
        if p.overflows > 0 && !self.overflow_reported {
            self.overflow_reported = true;
            inv.record(
                Violation::new(Rule::LinkOverflowCount, c)
                    .signal(self.port.to_string())
                    .expected(json!(0))
                    .actual(json!(p.overflows))
                    .detail(format!(
                        "a trailer reports {} token(s) dropped by the link's FIFO",
                        p.overflows
                    )),
            );
        }
    }

    /// A packet's records against the samples its slice emitted.
    fn compare(&self, c: u64, w: u64, win: &Window, records: &[(u16, u16)], inv: &mut Invariants) {
        let want = &win.samples;
        let i = (0..want.len().max(records.len()))
            .find(|&i| want.get(i).map(|x| (x.0, x.1)) != records.get(i).copied());
        let Some(i) = i else { return };
        let (slice, frame) = self.slice_frame(w, inv);
        let name = |ch: u16| {
            self.names
                .get(ch as usize)
                .cloned()
                .unwrap_or_else(|| format!("channel index {ch}"))
        };
        let got = records.get(i).map_or("nothing".into(), |&(ch, v)| {
            format!("{} = {v:#06x}", name(ch))
        });
        let had = want.get(i).map_or("nothing".into(), |&(ch, v, at)| {
            format!(
                "{} = {v:#06x} (sample_valid in cycle {})",
                name(ch),
                inv.place(at).0
            )
        });
        inv.record(
            Violation::new(Rule::LinkSamples, c)
                .signal(self.port.to_string())
                .expected(json!(had))
                .actual(json!(got))
                .channel(
                    want.get(i)
                        .map(|x| x.0)
                        .or(records.get(i).map(|x| x.0))
                        .map(name),
                )
                .detail(format!(
                    "the packet of frame {frame} slice {slice} carries {} records where the sample stream emitted {} in that slice; record {i} is {got}, the stream's sample {i} is {had}",
                    records.len(),
                    want.len()
                )),
        );
    }
}

/// The AXI4-Stream rule for `tlast` on the beat of `byte`, whose packet
/// (if it completed one) ended slice `ends` of `slices`: `None` when `tlast`
/// is where the format puts it, else what is wrong, in words.  The cycle
/// judge and the capture judge both ask it.
pub(crate) fn tlast_wrong(
    fmt: AxisFormat,
    ends: Option<u16>,
    slices: u64,
    tlast: bool,
    byte: u8,
) -> Option<String> {
    let want = ends.is_some_and(|sl| fmt.tlast == Tlast::Slice || sl as u64 + 1 == slices);
    (tlast != want).then(|| {
        format!(
            "tlast is {} on the beat of byte {byte:#04x}, which {} (tlast = \"{}\")",
            tlast as u8,
            if ends.is_some() {
                "ends a packet"
            } else {
                "does not end a packet"
            },
            fmt.tlast.name()
        )
    })
}
