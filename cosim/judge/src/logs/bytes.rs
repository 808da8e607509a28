//! The bytes a run's link carried, as a host would have received them: what
//! `slotforge sim --link-bytes` writes and `slotforge decode` reads.
//!
//! A UART's bytes are read from `link_tx` by a receiver sampling the line
//! once per cycle at the divider the link was planned with
//! (`link::UartRx`, the host's serial port); an AXI4-Stream's are the
//! `tdata` of every beat the slave accepted (`tvalid` and `tready` high in
//! one cycle).  Only what the line finished carrying counts: a character
//! whose stop bit had not been sampled when the run ended is not a byte yet.
//! Like [`crate::SampleLog`], it keeps what follows the last reset cycle.

use link::UartFormat;
use link::UartRx;
use lut_gen::Pins;
use lut_gen::Schedule;

use crate::check::Observer;
use crate::wave::CycleSink;

/// How the bytes are read off the pins.
#[derive(Debug, Clone)]
enum Wire {
    Uart { fmt: UartFormat, rx: UartRx },
    Axis,
}

/// The bytes of a run's link, collected while it runs (an [`Observer`] and
/// a [`CycleSink`], so any back end can feed it).
#[derive(Debug, Clone)]
pub struct LinkBytes {
    wire: Wire,
    /// The bytes received since the last reset cycle.
    pub bytes: Vec<u8>,
    /// Characters whose stop or parity bit was wrong (their data bytes are
    /// kept, as a serial port hands them on).
    pub framing_errors: u64,
}

impl LinkBytes {
    /// A collector for the mix's planned link; `None` when the mix has no
    /// `[link]` or its link cannot be planned (the audit says why).
    pub fn new(s: &Schedule) -> Option<LinkBytes> {
        let plan = lut_gen::plan_link(s)?.ok()?;
        let wire = match plan.uart() {
            Some(fmt) => Wire::Uart {
                fmt,
                rx: UartRx::new(fmt),
            },
            None => Wire::Axis,
        };
        Some(LinkBytes {
            wire,
            bytes: Vec::new(),
            framing_errors: 0,
        })
    }

    /// Writes the bytes, raw, to `path` atomically (a new temporary file
    /// beside it, renamed over `path`).
    pub fn write(&self, path: &std::path::Path) -> std::io::Result<()> {
        crate::logs::samples::write_atomic(path, &self.bytes)
    }

    fn push(&mut self, rst: bool, p: &Pins) {
        if rst {
            // the line's story starts again after the last reset cycle
            self.bytes.clear();
            self.framing_errors = 0;
            if let Wire::Uart { fmt, rx } = &mut self.wire {
                *rx = UartRx::new(*fmt);
            }
            return;
        }
        match &mut self.wire {
            Wire::Uart { rx, .. } => {
                if let Some(b) = rx.sample(p.link_tx) {
                    self.framing_errors += b.error as u64;
                    self.bytes.push(b.byte);
                }
            }
            Wire::Axis => {
                if p.axis_tvalid && p.axis_tready {
                    self.bytes.push(p.axis_tdata);
                }
            }
        }
    }
}

impl Observer for LinkBytes {
    fn cycle(&mut self, _cycle: u64, rst: bool, pins: &Pins, _miso: u64) {
        self.push(rst, pins);
    }
}

impl CycleSink for LinkBytes {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, _xz: &Pins, _miso: u64, _miso_xz: u64) {
        // an unknown reset level counts as reset, as in `Trace`
        self.push(rst.unwrap_or(true), pins);
    }
}
