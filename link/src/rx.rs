//! A UART receiver over a line sampled once per clock cycle: what a host's
//! serial port does, used by the judge to decode the line from the pins.

use crate::uart::UartFormat;

/// A character read from the line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RxByte {
    pub byte: u8,
    /// Cycle (count of samples before it) of the start bit's falling edge.
    pub start: u64,
    /// A stop bit read low, or the parity bit is wrong.
    pub error: bool,
}

/// Receiver state: idle, or inside a character since `start`.
#[derive(Debug, Clone)]
pub struct UartRx {
    fmt: UartFormat,
    n: u64,
    prev: bool,
    start: Option<u64>,
    bits: u32,
    data: u8,
    error: bool,
}

impl UartRx {
    pub fn new(fmt: UartFormat) -> UartRx {
        UartRx {
            fmt,
            n: 0,
            prev: true,
            start: None,
            bits: 0,
            data: 0,
            error: false,
        }
    }

    /// The cycle (count of samples before it) at which the character being
    /// read started: its start bit's falling edge; `None` when idle (after
    /// the middle of the last stop bit, or a start bit found high at its
    /// middle).
    pub fn reading(&self) -> Option<u64> {
        self.start
    }

    /// Feed the line's level in the next cycle; a character when its last
    /// stop bit has been sampled (at the middle of each bit).
    pub fn sample(&mut self, level: bool) -> Option<RxByte> {
        let now = self.n;
        self.n += 1;
        let prev = std::mem::replace(&mut self.prev, level);
        let Some(start) = self.start else {
            if prev && !level {
                self.start = Some(now);
                self.bits = 0;
                self.data = 0;
                self.error = false;
            }
            return None;
        };
        let d = self.fmt.div as u64;
        let t = now - start;
        if t < d / 2 || !(t - d / 2).is_multiple_of(d) {
            return None;
        }
        let i = ((t - d / 2) / d) as u32;
        match i {
            0 => {
                if level {
                    // a glitch, not a start bit
                    self.start = None;
                }
            }
            1..=8 => self.data |= (level as u8) << (i - 1),
            _ => {
                if level != self.fmt.bit(self.data, i) {
                    self.error = true;
                }
            }
        }
        self.bits = i;
        if i + 1 == self.fmt.bits() {
            self.start = None;
            return Some(RxByte {
                byte: self.data,
                start,
                error: self.error,
            });
        }
        None
    }
}
