//! The packet format (`docs/packet-format.md`).
//!
//! The stream is a sequence of 4-byte words.  Each slice of the frame is one
//! packet: a header word, one record word per sample the merger emitted
//! during that slice (in emission order), and a trailer word that closes
//! it when the next slice's header follows.
//!
//! | word | bytes |
//! |---|---|
//! | header  | `0xA5`, frame counter (mod 256), slice (16 bits, big-endian) |
//! | record  | channel index (16 bits, big-endian, < 1024), code (16 bits, big-endian) |
//! | trailer | `0x5A`, overflow count (saturating), CRC-16/MODBUS low byte, high byte |
//!
//! A record's first byte is below 4, so the first byte of every word says
//! what it is.  The CRC covers the header, the records and the trailer's
//! first two bytes; it is CRC-16/MODBUS (reflected polynomial 0xA001,
//! initial value 0xFFFF), the CRC a UART computes bit by bit in line order.

/// First byte of a header word.
pub const SYNC: u8 = 0xA5;
/// First byte of a trailer word.
pub const END: u8 = 0x5A;
/// Bytes per word (header, record or trailer).
pub const WORD_BYTES: usize = 4;
/// The highest channel index a record can carry (its first byte stays below 4).
pub const MAX_CHANNEL: u16 = 1023;
/// CRC-16/MODBUS initial value.
pub const CRC_INIT: u16 = 0xFFFF;

// The first byte of a word says what it is: the two markers differ from
// each other and from every record's first byte (below 4).
const _: () = assert!(SYNC != END && SYNC >= 4 && END >= 4 && MAX_CHANNEL >> 8 < 4);

/// One CRC-16/MODBUS step over a byte (bits LSB first, as on the line).
pub fn crc_update(mut crc: u16, byte: u8) -> u16 {
    crc ^= byte as u16;
    for _ in 0..8 {
        crc = if crc & 1 == 1 {
            (crc >> 1) ^ 0xA001
        } else {
            crc >> 1
        };
    }
    crc
}

/// CRC-16/MODBUS of `bytes`.
pub fn crc(bytes: &[u8]) -> u16 {
    bytes.iter().fold(CRC_INIT, |c, &b| crc_update(c, b))
}

pub fn header(frame: u8, slice: u16) -> [u8; 4] {
    [SYNC, frame, (slice >> 8) as u8, slice as u8]
}

pub fn record(channel: u16, value: u16) -> [u8; 4] {
    [
        (channel >> 8) as u8,
        channel as u8,
        (value >> 8) as u8,
        value as u8,
    ]
}

pub fn trailer(overflows: u8, crc: u16) -> [u8; 4] {
    [END, overflows, crc as u8, (crc >> 8) as u8]
}

/// A mix with modes (docs/packet-format.md, "Modes"): the header's 16-bit
/// slice field carries, from its top bit down, the mode of the packet's
/// frame and the mode of the frame before it (`mode_bits` bits each), then
/// the slice.  Without modes (`mode_bits` 0) it is the slice alone, so
/// those mixes' bytes are unchanged.
pub fn slice_field(slice: u16, mode: u8, prev: u8, mode_bits: u32) -> u16 {
    if mode_bits == 0 {
        return slice;
    }
    let low = 16 - 2 * mode_bits;
    ((mode as u16) << (low + mode_bits)) | ((prev as u16) << low) | slice
}

/// (slice, mode, mode of the frame before) of a header's slice field.
pub fn split_slice_field(field: u16, mode_bits: u32) -> (u16, u8, u8) {
    if mode_bits == 0 {
        return (field, 0, 0);
    }
    let low = 16 - 2 * mode_bits;
    let m = (1u16 << mode_bits) - 1;
    (
        field & ((1 << low) - 1),
        (field >> (low + mode_bits) & m) as u8,
        (field >> low & m) as u8,
    )
}

/// Whether a frame of `slices` slices leaves room in the slice field for
/// two modes of `mode_bits` bits.
pub fn modes_fit(slices: u64, mode_bits: u32) -> bool {
    mode_bits == 0 || (2 * mode_bits < 16 && slices <= 1 << (16 - 2 * mode_bits))
}

/// What the packetizer writes into the FIFO in one cycle: a slice boundary
/// (the cycle is the first of a slice), a sample, or both; with the `mode`
/// input in that cycle (a mix with modes: a boundary's header carries it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Token {
    pub boundary: bool,
    pub sample: Option<(u16, u16)>,
    pub mode: u8,
}

/// Which word of a token a byte belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WordKind {
    Trailer,
    Header,
    Record,
}

impl WordKind {
    /// The word of byte slot `slot` (0..12) of a token.
    pub fn of_slot(slot: u8) -> WordKind {
        match slot / 4 {
            0 => WordKind::Trailer,
            1 => WordKind::Header,
            _ => WordKind::Record,
        }
    }
}

/// Bytes per frame of a schedule with `samples` samples and `slices`
/// slices per frame: a header, a trailer and a record per sample.
pub fn bytes_per_frame(samples: u64, slices: u64) -> u64 {
    (samples + 2 * slices) * WORD_BYTES as u64
}

/// Words ("packets" in the paper's sense) per frame.
pub fn words_per_frame(samples: u64, slices: u64) -> u64 {
    samples + 2 * slices
}
