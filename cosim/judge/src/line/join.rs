//! The model's link joined from the line itself, for a check that joins a
//! run mid-stream (a window, a capture from the middle of a run).
//!
//! The transmitter's state in the middle of a run is the run's own, not
//! the schedule's: the frame counter, the backlog frame 0 left and the
//! samples in flight when the window opened.  So until the line shows a
//! whole packet, the link's pins are not compared: the line is read as a
//! host would (the UART receiver, or the AXIS beats) through the host
//! decoder, and the first good packet whose slice began after the join
//! (so that every sample it carries is one the model predicted from the
//! window's MISO) gives its header's frame counter, slice and first cycle.
//! From those and the model's sample stream since the join,
//! [`link::TxModel::at_header`] rebuilds the transmitter's registers as
//! they were when its SYNC byte went out; it is stepped to the current
//! cycle and the model compares every link pin from then on.  The bytes
//! before that header were in flight when the window began: they are
//! skipped (the decoder-level checks, `decode`, still read them) and the
//! report says so ([`crate::model::LinkJoin`]).

use std::collections::VecDeque;

use link::format::{END, SYNC};
use link::UartRx;
use link::{Decoder, HeaderOnLine, Line, Packet, Token, TxConfig, TxModel};
use lut_gen::Pins;

/// The bytes kept while searching at most; older ones are forgotten.
const MAX_BYTES: usize = 1 << 16;
/// Samples and `tready` changes kept while searching at most: beyond, those
/// older than two frames are forgotten (no packet takes that long).
const MAX_LOG: usize = 1 << 18;

/// Where the bytes come from.
#[derive(Debug, Clone)]
enum Wire {
    /// The receiver, fed one sample per cycle from the join (this cycle) on.
    Uart(UartRx, u64),
    /// The first cycle of the beat being offered (`None` inside: unknown,
    /// offered since before the join).
    Axis { offer: Option<Option<u64>> },
}

/// The model's link joined from the line.
#[derive(Debug, Clone)]
pub(crate) struct LinkJoin {
    cfg: TxConfig,
    slices: u64,
    /// Slice boundaries fall on multiples of this in model cycles: the
    /// lock knows the frame phase only modulo the CS/mux pins' repeat, so
    /// the run's slices begin a multiple of it off the model's (the
    /// greatest common divisor of the slice and the repeat).
    step: u64,
    /// The model cycle the check joined at, or the earliest whose samples
    /// are still kept: a packet's slice must begin at or after it.
    from: u64,
    wire: Wire,
    dec: Decoder,
    packets: Vec<Packet>,
    /// Bytes read since the join: (byte, first cycle on the line if seen).
    bytes: VecDeque<(u8, Option<u64>)>,
    /// Bytes forgotten or dropped before `bytes`.
    dropped: u64,
    /// The model's sample stream since the join: (cycle, channel, code).
    samples: Vec<(u64, u16, u16)>,
    /// `tready` since the join, run-length coded: (first cycle, level).
    tready: Vec<(u64, bool)>,
    /// A mix with modes: the `mode` pin since the join, run-length coded
    /// (a boundary's token takes it to its header).
    modes: Vec<(u64, u8)>,
    /// The model's sample codes are not the run's (an analyser's capture
    /// without MISO): a packet's slice is placed by its number and its
    /// records' channels, on the model's own slice grid.
    blind: bool,
}

/// Where the model's link joined the line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Joined {
    /// The model cycle from which every link pin is compared.
    pub cycle: u64,
    /// The model cycle the header's first byte went out in.
    pub header_cycle: u64,
    pub frame: u8,
    pub slice: u16,
    /// Bytes on the line before the header, since the join.
    pub skipped_bytes: u64,
}

impl LinkJoin {
    /// Joining at model cycle `from` a transmitter built as `cfg`.
    pub(crate) fn new(cfg: TxConfig, slices: u64, step: u64, from: u64) -> LinkJoin {
        let wire = match cfg.line {
            Line::Uart(u) => Wire::Uart(UartRx::new(u), from),
            Line::Axis(_) => Wire::Axis { offer: None },
        };
        LinkJoin {
            cfg,
            slices,
            step,
            from,
            wire,
            dec: Decoder::with_modes(slices, cfg.mode_bits),
            packets: Vec::new(),
            bytes: VecDeque::new(),
            dropped: 0,
            samples: Vec::new(),
            tready: Vec::new(),
            modes: Vec::new(),
            blind: false,
        }
    }

    /// [`LinkJoin::new`] for a model whose sample codes are not the run's:
    /// the codes are left out (a record's bytes and the CRC are then not
    /// the line's; the beats' timing, which does not depend on them, is).
    pub(crate) fn blind(mut self) -> LinkJoin {
        self.blind = true;
        self
    }

    /// Model cycle `c`: the design's pins `p` and the model's `e` (its
    /// sample stream).  Once a whole packet has been read: the transmitter
    /// as it is in cycle `c`, and where it joined.
    pub(crate) fn cycle(&mut self, c: u64, p: &Pins, e: &Pins) -> Option<(TxModel, Joined)> {
        if e.sample_valid {
            let code = if self.blind { 0 } else { e.sample_value };
            self.samples.push((c, e.sample_channel, code));
        }
        if self.tready.last().map(|t| t.1) != Some(p.axis_tready) {
            self.tready.push((c, p.axis_tready));
        }
        if self.modes.last().map(|t| t.1) != Some(p.mode) {
            self.modes.push((c, p.mode));
        }
        if self.samples.len() > MAX_LOG || self.tready.len() > MAX_LOG || self.modes.len() > MAX_LOG
        {
            self.forget(c);
        }
        let byte = match &mut self.wire {
            Wire::Uart(rx, origin) => rx
                .sample(p.link_tx)
                .filter(|b| !b.error)
                .map(|b| (b.byte, Some(*origin + b.start))),
            Wire::Axis { offer } => {
                if !p.axis_tvalid {
                    *offer = None;
                    None
                } else {
                    let first = *offer.get_or_insert((c > self.from).then_some(c));
                    p.axis_tready.then(|| {
                        *offer = None;
                        (p.axis_tdata, first)
                    })
                }
            }
        }?;
        if self.bytes.len() == MAX_BYTES {
            self.bytes.pop_front();
            self.dropped += 1;
        }
        self.bytes.push_back(byte);
        self.dec.push_packets(&[byte.0], &mut self.packets);
        let packets = std::mem::take(&mut self.packets);
        let joined = packets.iter().find_map(|pk| self.header(pk));
        let (h, first, skipped) = joined?;
        let tx = self.replay(&h, first, c);
        Some((
            tx,
            Joined {
                cycle: c,
                header_cycle: first,
                frame: h.frame,
                slice: h.slice,
                skipped_bytes: skipped,
            },
        ))
    }

    /// The header of good packet `pk` (it ended with the last byte read),
    /// if the model can join there: its slice began after the join, and
    /// the bytes read are that packet.  With the bytes before it.
    fn header(&self, pk: &Packet) -> Option<(HeaderOnLine, u64, u64)> {
        let n = 4 * (2 + pk.records.len());
        let hi = self.bytes.len().checked_sub(n)?;
        let at = |i: usize| self.bytes[i].0;
        let slice = link::format::slice_field(pk.slice, pk.mode, pk.prev_mode, self.cfg.mode_bits)
            .to_be_bytes();
        let framed = at(hi) == SYNC
            && at(hi + 1) == pk.frame as u8
            && [at(hi + 2), at(hi + 3)] == slice
            && at(self.bytes.len() - 4) == END;
        let first = self.bytes[hi].1.filter(|_| framed)?;
        // The boundary whose token the header went out with: where the
        // model's sample stream has the packet's records in a slice.
        let s = self.cfg.slice_cycles;
        let b = if self.blind {
            self.blind_boundary(pk, first)?
        } else {
            find_boundary(&self.samples, &pk.records, (self.from, first), self.step, s)?
        };
        // the run's slices begin `delta` cycles before the model's
        let delta = (s - b % s) % s;
        let overflows = match hi.checked_sub(4) {
            Some(t) if at(t) == END => at(t + 1),
            _ => pk.overflows,
        };
        let queued = (b + 1..first)
            .map(|c| Token {
                boundary: (c + delta).is_multiple_of(s),
                sample: self.sample_at(c),
                mode: self.mode_at(c),
            })
            .filter(|t| t.boundary || t.sample.is_some())
            .collect();
        let h = HeaderOnLine {
            first: first + delta,
            frame: pk.frame as u8,
            slice: pk.slice,
            mode: pk.mode,
            prev_mode: pk.prev_mode,
            overflows,
            overflow_flag: overflows > 0,
            boundary_sample: self.sample_at(b),
            queued,
        };
        Some((h, first, self.dropped + hi as u64))
    }

    /// The start of packet `pk`'s slice on the model's own grid: the last
    /// before `first` (its header's cycle) with its number, if its samples'
    /// channels are the packet's records' and it began after the join.
    fn blind_boundary(&self, pk: &Packet, first: u64) -> Option<u64> {
        let s = self.cfg.slice_cycles;
        let mut k = first.checked_sub(1)? / s;
        while k % self.slices != pk.slice as u64 {
            k = k.checked_sub(1)?;
        }
        let b = k * s;
        let i = self.samples.partition_point(|x| x.0 < b);
        let j = self.samples.partition_point(|x| x.0 < b + s);
        let chans = self.samples[i..j].iter().map(|x| x.1);
        (b >= self.from && chans.eq(pk.records.iter().map(|r| r.0))).then_some(b)
    }

    /// Bytes read from the line so far.
    pub(crate) fn bytes_read(&self) -> u64 {
        self.dropped + self.bytes.len() as u64
    }

    /// Forgets the samples and `tready` of the cycles over two frames
    /// before `c`.
    fn forget(&mut self, c: u64) {
        let keep = c.saturating_sub(2 * self.slices * self.cfg.slice_cycles);
        if keep <= self.from {
            return;
        }
        self.from = keep;
        let i = self.samples.partition_point(|x| x.0 < keep);
        self.samples.drain(..i);
        let level = self.tready_at(keep);
        let i = self.tready.partition_point(|x| x.0 <= keep);
        self.tready.drain(..i);
        self.tready.insert(0, (keep, level));
        let mode = self.mode_at(keep);
        let i = self.modes.partition_point(|x| x.0 <= keep);
        self.modes.drain(..i);
        self.modes.insert(0, (keep, mode));
    }

    fn mode_at(&self, c: u64) -> u8 {
        let i = self.modes.partition_point(|x| x.0 <= c);
        if i > 0 {
            self.modes[i - 1].1
        } else {
            0
        }
    }

    fn sample_at(&self, c: u64) -> Option<(u16, u16)> {
        let i = self.samples.partition_point(|x| x.0 < c);
        self.samples
            .get(i)
            .filter(|x| x.0 == c)
            .map(|&(_, ch, v)| (ch, v))
    }

    fn tready_at(&self, c: u64) -> bool {
        let i = self.tready.partition_point(|x| x.0 <= c);
        i > 0 && self.tready[i - 1].1
    }

    /// The transmitter rebuilt at header `h` (in model cycle `first`),
    /// stepped to cycle `c` with the model's sample stream and the slave's
    /// `tready`.
    fn replay(&self, h: &HeaderOnLine, first: u64, c: u64) -> TxModel {
        let mut tx = TxModel::at_header(self.cfg, h);
        for t in first..c {
            tx.set_tready(self.tready_at(t));
            tx.set_mode(self.mode_at(t));
            tx.clock(false, self.sample_at(t));
        }
        tx.set_tready(self.tready_at(c));
        tx
    }
}

/// The start, in `[lo, hi)` and a multiple of `step`, of the slice whose
/// samples (of `samples`: (cycle, channel, code) in cycle order) are
/// exactly `records` in order; `s` cycles a slice.  The lock finds the
/// frame phase from the CS/mux pins, which may repeat within a frame
/// (every channel at twice the frame rate): then the packets' slices are
/// what tells the phases apart.  Several fits (a slice that starts or
/// ends without samples, equal codes): the one on the model's own slice
/// grid if it fits, else none; none either when it lies before `lo`.
pub fn find_boundary(
    samples: &[(u64, u16, u16)],
    records: &[(u16, u16)],
    (lo, hi): (u64, u64),
    step: u64,
    s: u64,
) -> Option<u64> {
    if records.is_empty() {
        return None;
    }
    let step = step.max(1);
    let mut fits = Vec::new();
    // from a slice before the join: a fit there makes one after it ambiguous
    let mut b = lo.saturating_sub(s).div_ceil(step) * step;
    while b < hi {
        let i = samples.partition_point(|x| x.0 < b);
        let j = samples.partition_point(|x| x.0 < b + s);
        if j - i == records.len()
            && samples[i..j]
                .iter()
                .zip(records)
                .all(|(x, r)| (x.1, x.2) == *r)
        {
            fits.push(b);
        }
        b += step;
    }
    let b = match fits.as_slice() {
        [b] => Some(*b),
        _ => fits.into_iter().find(|b| b % s == 0),
    };
    b.filter(|&b| b >= lo)
}
