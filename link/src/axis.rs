//! The AXI4-Stream form of the link: the same byte stream as the UART's
//! (docs/packet-format.md), one byte per beat on `tdata[7:0]`, `tlast` on
//! the last byte of a trailer, and the `tready` patterns the back ends drive.
//!
//! The slave's guarantee the FIFO depth is computed for: **every beat is
//! accepted within `ready_within` cycles of being offered** (`tready` is
//! high at the latest in the `ready_within`-th cycle of `tvalid` for a
//! byte).  The worst case that guarantee allows is a slave that takes every
//! byte in exactly its `ready_within`-th cycle: the link then drains one
//! byte per `ready_within` cycles, as a UART whose character lasts
//! `ready_within` cycles.

/// Where `tlast` is set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tlast {
    /// On the last byte of every trailer: one AXIS packet per slice.
    #[default]
    Slice,
    /// On the last byte of the trailer of a frame's last slice.
    Frame,
}

impl Tlast {
    pub fn name(self) -> &'static str {
        match self {
            Tlast::Slice => "slice",
            Tlast::Frame => "frame",
        }
    }

    pub fn parse(s: &str) -> Option<Tlast> {
        match s {
            "slice" => Some(Tlast::Slice),
            "frame" => Some(Tlast::Frame),
            _ => None,
        }
    }
}

/// The AXIS link's format: where `tlast` goes and the slave's guarantee.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisFormat {
    pub tlast: Tlast,
    /// Cycles within which the slave accepts an offered beat (>= 1; 1 is a
    /// slave that is always ready).
    pub ready_within: u32,
}

/// How a back end drives `tready`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReadyPattern {
    /// `tready` high in every cycle.
    Always,
    /// `tready` from a seeded xorshift32 (bit 0 of the state, the state
    /// stepped once per cycle), forced high when the guarantee's deadline
    /// is reached, so the pattern stays within the guarantee.
    Random { seed: u32 },
    /// The worst case the guarantee allows: every beat accepted in exactly
    /// its `ready_within`-th cycle.
    WorstCase,
}

impl ReadyPattern {
    pub fn name(self) -> String {
        match self {
            ReadyPattern::Always => "always".into(),
            ReadyPattern::Random { seed } => format!("random:{seed}"),
            ReadyPattern::WorstCase => "worst".into(),
        }
    }

    /// `always`, `worst`, `random` (seed 1) or `random:SEED`.
    pub fn parse(s: &str) -> Option<ReadyPattern> {
        match s {
            "always" => Some(ReadyPattern::Always),
            "worst" => Some(ReadyPattern::WorstCase),
            "random" => Some(ReadyPattern::Random { seed: 1 }),
            _ => {
                let seed: u32 = s.strip_prefix("random:")?.parse().ok()?;
                (seed != 0).then_some(ReadyPattern::Random { seed })
            }
        }
    }
}

/// The slave's side of the handshake: `tready` in each cycle from the
/// pattern and the master's `tvalid` in that cycle (a slave may wait for
/// `tvalid` before it raises `tready`; AXI4-Stream allows it).
#[derive(Debug, Clone)]
pub struct ReadyDriver {
    pattern: ReadyPattern,
    within: u32,
    state: u32,
    /// Cycles the current beat has waited (tvalid high, tready low).
    wait: u32,
}

impl ReadyDriver {
    pub fn new(pattern: ReadyPattern, ready_within: u32) -> ReadyDriver {
        let state = match pattern {
            ReadyPattern::Random { seed } => seed.max(1),
            _ => 1,
        };
        ReadyDriver {
            pattern,
            within: ready_within.max(1),
            state,
            wait: 0,
        }
    }

    /// `tready` in this cycle, given `tvalid` in this cycle; call once per
    /// cycle after reset (during reset the driver is not stepped).
    pub fn ready(&mut self, tvalid: bool) -> bool {
        let due = self.wait + 1 >= self.within;
        let r = match self.pattern {
            ReadyPattern::Always => true,
            ReadyPattern::WorstCase => due,
            ReadyPattern::Random { .. } => {
                let mut x = self.state;
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                self.state = x;
                x & 1 == 1 || due
            }
        };
        self.wait = if tvalid && !r { self.wait + 1 } else { 0 };
        r
    }
}
