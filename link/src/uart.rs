//! The UART character and its divider.

/// Parity bit after the data bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Parity {
    #[default]
    None,
    Even,
    Odd,
}

impl Parity {
    pub fn name(self) -> &'static str {
        match self {
            Parity::None => "none",
            Parity::Even => "even",
            Parity::Odd => "odd",
        }
    }

    pub fn parse(s: &str) -> Option<Parity> {
        match s {
            "none" => Some(Parity::None),
            "even" => Some(Parity::Even),
            "odd" => Some(Parity::Odd),
            _ => None,
        }
    }
}

/// A UART character: one start bit, 8 data bits LSB first, an optional
/// parity bit, 1 or 2 stop bits; every bit `div` clock cycles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UartFormat {
    pub div: u32,
    pub parity: Parity,
    pub stop_bits: u8,
}

impl UartFormat {
    /// Bits per character, start and stop bits included.
    pub fn bits(&self) -> u32 {
        1 + 8 + (self.parity != Parity::None) as u32 + self.stop_bits as u32
    }

    /// Cycles per character.
    pub fn char_cycles(&self) -> u64 {
        self.bits() as u64 * self.div as u64
    }

    /// Line level of bit `i` (0 = start bit) of the character carrying `byte`.
    pub fn bit(&self, byte: u8, i: u32) -> bool {
        match i {
            0 => false,
            1..=8 => (byte >> (i - 1)) & 1 == 1,
            9 if self.parity != Parity::None => {
                let odd_ones = byte.count_ones() % 2 == 1;
                match self.parity {
                    Parity::Even => odd_ones,
                    _ => !odd_ones,
                }
            }
            _ => true,
        }
    }

    /// The divider nearest to `clock_hz / baud` (at least 1).
    pub fn divider(clock_hz: u64, baud: u64) -> u32 {
        (((clock_hz + baud / 2) / baud).max(1)).min(u32::MAX as u64) as u32
    }

    /// The baud rate the divider gives.
    pub fn real_baud(clock_hz: u64, div: u32) -> f64 {
        clock_hz as f64 / div as f64
    }
}
