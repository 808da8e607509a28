//! The host side: a streaming decoder of the bytes a host received.
//!
//! Bytes go in as they arrive ([`Decoder::push`]); a packet's samples come
//! out when its trailer arrives with a good CRC, so a live stream is followed
//! packet by packet.  Garbage, lost bytes, a cut stream or a capture that
//! starts in the middle of a packet never stop it: it counts what it had to
//! drop ([`Stats`]) and resynchronises on the next header that leads to a
//! good CRC.

use std::collections::VecDeque;

use crate::format::{self, END, SYNC, WORD_BYTES};

/// One sample of a good packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Decoded {
    /// Frame number: the header's counter (mod 256) unwrapped from the first
    /// packet decoded on.
    pub frame: u64,
    pub slice: u16,
    /// A mix with modes: the mode of the packet's frame and of the frame
    /// before it (0 without).
    pub mode: u8,
    pub prev_mode: u8,
    pub channel: u16,
    pub value: u16,
}

/// One good packet (its trailer's CRC matched): what a checker that knows
/// which samples the packet should carry compares, an empty packet included.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Packet {
    /// The header's frame counter unwrapped as in [`Decoded::frame`].
    pub frame: u64,
    pub slice: u16,
    /// A mix with modes: the mode of the packet's frame and of the frame
    /// before it, from the header (0 without modes).
    pub mode: u8,
    pub prev_mode: u8,
    /// (channel, value) of every record, in order.
    pub records: Vec<(u16, u16)>,
    /// The trailer's overflow count.
    pub overflows: u8,
}

/// What the decoder saw.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    pub bytes: u64,
    pub packets: u64,
    pub samples: u64,
    /// Packets whose trailer's CRC did not match.
    pub crc_errors: u64,
    /// Packets missing between two good ones (from the frame and slice counters).
    pub lost_packets: u64,
    /// Times the decoder had to search for a header again after losing sync.
    pub resyncs: u64,
    /// Bytes dropped while searching for a header.
    pub skipped_bytes: u64,
    /// The largest overflow count a trailer reported (the FIFO dropped
    /// that many tokens since reset).
    pub overflows: u8,
    /// Bytes of the packet still open when the stream ended: a capture or
    /// a run stops while the line carries a packet (its trailer leaves
    /// after the slice it closes), so a whole, valid beginning of a packet
    /// at the end is in flight, not lost.  A cut packet that was already
    /// wrong shows as a CRC error, a resync or skipped bytes instead.
    pub in_flight: u64,
}

impl Stats {
    /// No loss, no error.
    pub fn clean(&self) -> bool {
        self.crc_errors == 0
            && self.lost_packets == 0
            && self.resyncs == 0
            && self.skipped_bytes == 0
            && self.overflows == 0
    }
}

/// The streaming decoder.
#[derive(Debug, Clone)]
pub struct Decoder {
    slices: u64,
    /// Bits of each mode in the header's slice field (0: no modes).
    mode_bits: u32,
    /// Bytes of the packet being read (from its SYNC on).
    buf: Vec<u8>,
    /// Bytes to (re)read before new input.
    pending: VecDeque<u8>,
    /// Sequence number (frame * slices + slice) of the last good packet, unwrapped.
    last: Option<u64>,
    synced_once: bool,
    searching: bool,
    stats: Stats,
}

/// Longest packet accepted: more records than a slice can hold in the
/// gateware's limits means garbage.
const MAX_PACKET_BYTES: usize = WORD_BYTES * (2 + 16 * 4096);

impl Decoder {
    /// A decoder for a mix with `slices_per_frame` slices per frame.
    pub fn new(slices_per_frame: u64) -> Decoder {
        Decoder::with_modes(slices_per_frame, 0)
    }

    /// A decoder for a mix with modes of `mode_bits` bits (0: none), whose
    /// headers carry the modes above the slice (`format::slice_field`).
    pub fn with_modes(slices_per_frame: u64, mode_bits: u32) -> Decoder {
        Decoder {
            slices: slices_per_frame.max(1),
            mode_bits,
            buf: Vec::new(),
            pending: VecDeque::new(),
            last: None,
            synced_once: false,
            searching: false,
            stats: Stats::default(),
        }
    }

    pub fn stats(&self) -> &Stats {
        &self.stats
    }

    /// Feed received bytes; `out` gets the samples of every packet they complete.
    pub fn push(&mut self, bytes: &[u8], out: &mut Vec<Decoded>) {
        let mut packets = Vec::new();
        self.push_packets(bytes, &mut packets);
        for p in packets {
            out.extend(p.records.iter().map(|&(channel, value)| Decoded {
                frame: p.frame,
                slice: p.slice,
                mode: p.mode,
                prev_mode: p.prev_mode,
                channel,
                value,
            }));
        }
    }

    /// Feed received bytes; `out` gets every packet they complete, whole
    /// (so a packet without records is seen too).
    pub fn push_packets(&mut self, bytes: &[u8], out: &mut Vec<Packet>) {
        self.stats.bytes += bytes.len() as u64;
        self.pending.extend(bytes);
        while let Some(b) = self.pending.pop_front() {
            self.byte(b, out);
        }
    }

    /// The stream ended: the bytes of a packet still open are counted as
    /// in flight.  Only a packet whose every word so far is well formed is
    /// still open (anything else lost sync on its own byte).
    pub fn finish(&mut self) -> Stats {
        self.stats.in_flight = self.buf.len() as u64;
        self.buf.clear();
        self.stats
    }

    fn byte(&mut self, b: u8, out: &mut Vec<Packet>) {
        if self.buf.is_empty() {
            if b == SYNC {
                self.buf.push(b);
                self.searching = false;
            } else {
                self.skip(1);
            }
            return;
        }
        self.buf.push(b);
        let n = self.buf.len();
        if n <= WORD_BYTES {
            if n == WORD_BYTES && self.header_slice() >= self.slices {
                self.lose_sync();
            }
            return;
        }
        let word = (n - 1) / WORD_BYTES * WORD_BYTES;
        let first = self.buf[word];
        let bad = !matches!(first, 0..=3 | END);
        if bad || n > MAX_PACKET_BYTES {
            self.lose_sync();
            return;
        }
        if first == END && n == word + WORD_BYTES {
            self.trailer(out);
        }
    }

    /// (slice, mode, mode of the frame before) of the header read.
    fn header_fields(&self) -> (u64, u8, u8) {
        let field = u16::from_be_bytes([self.buf[2], self.buf[3]]);
        let (slice, mode, prev) = format::split_slice_field(field, self.mode_bits);
        (slice as u64, mode, prev)
    }

    fn header_slice(&self) -> u64 {
        self.header_fields().0
    }

    fn skip(&mut self, n: u64) {
        self.stats.skipped_bytes += n;
        if self.synced_once && !self.searching {
            self.stats.resyncs += 1;
        }
        self.searching = true;
    }

    /// The packet read so far is not one: drop its SYNC and read the rest again.
    fn lose_sync(&mut self) {
        let again: Vec<u8> = self.buf.drain(..).skip(1).collect();
        for b in again.into_iter().rev() {
            self.pending.push_front(b);
        }
        self.skip(1);
    }

    fn trailer(&mut self, out: &mut Vec<Packet>) {
        let n = self.buf.len();
        let want = format::crc(&self.buf[..n - 2]);
        let got = u16::from_le_bytes([self.buf[n - 2], self.buf[n - 1]]);
        if want != got {
            self.stats.crc_errors += 1;
            self.lose_sync();
            return;
        }
        let frame8 = self.buf[1] as u64;
        let (slice, mode, prev_mode) = self.header_fields();
        let period = 256 * self.slices;
        let seq8 = frame8 * self.slices + slice;
        let seq = match self.last {
            None => seq8,
            Some(last) => {
                let delta = (seq8 + period - last % period) % period;
                let delta = if delta == 0 { period } else { delta };
                self.stats.lost_packets += delta - 1;
                last + delta
            }
        };
        self.last = Some(seq);
        let overflows = self.buf[n - 3];
        self.stats.overflows = self.stats.overflows.max(overflows);
        self.stats.packets += 1;
        let records: Vec<(u16, u16)> = self.buf[WORD_BYTES..n - WORD_BYTES]
            .chunks(WORD_BYTES)
            .map(|r| {
                (
                    u16::from_be_bytes([r[0], r[1]]),
                    u16::from_be_bytes([r[2], r[3]]),
                )
            })
            .collect();
        self.stats.samples += records.len() as u64;
        out.push(Packet {
            frame: seq / self.slices,
            slice: (seq % self.slices) as u16,
            mode,
            prev_mode,
            records,
            overflows,
        });
        self.synced_once = true;
        self.searching = false;
        self.buf.clear();
    }
}
