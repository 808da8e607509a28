//! CNV pulse: the conversion pin of a part read with CNV low (docs/timing.md,
//! "Reading with CNV low").

use std::fmt::Write as _;

use crate::rhdl::*;

/// One per SPI sequencer whose part is read with CNV low (none otherwise,
/// so every other mix's Verilog has no trace of it).  It runs beside the
/// sequencer, in step with it: `pin_n` is the conversion pin a converting
/// branch has in the next cycle (active low, as the sequencer's `cs_n`),
/// active for the conversion's `conv` cycles only; the branch registers it
/// in place of the sequencer's `cs_n`, so CNV falls when the conversion
/// ends and the word is read while it is low.
///
/// `start2` (or reset) in cycle `t - 2` makes it active from cycle `t - 1`;
/// a counter loaded with `conv - 1` counts to zero in cycle `t + conv - 2`,
/// which releases it at the edge that begins `t + conv - 1`.  Custom
/// Verilog, so the counter is exactly the conversion's width.
#[derive(LogicBlock)]
pub struct CnvPulse {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start2: Signal<In, Bit>,
    pub pin_n: Signal<Out, Bit>,
    _conv: u64,
    /// The twin's registers: the pin (active low) and the counter.
    _pin_n: bool,
    _cnt: u64,
}

impl CnvPulse {
    /// The pulse of a conversion of `conv` cycles (at least 1).
    pub(super) fn new(conv: u64) -> CnvPulse {
        CnvPulse {
            clock: Default::default(),
            rst: Default::default(),
            start2: Default::default(),
            pin_n: Default::default(),
            _conv: conv.max(1),
            _pin_n: true,
            _cnt: 0,
        }
    }

    fn cnt_bits(&self) -> usize {
        (64 - (self._conv - 1).leading_zeros()).max(1) as usize
    }
}

impl Logic for CnvPulse {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            if self.start2.val() || self.rst.val() {
                self._pin_n = false;
                self._cnt = self._conv - 1;
            } else if !self._pin_n {
                if self._cnt == 0 {
                    self._pin_n = true;
                } else {
                    self._cnt -= 1;
                }
            }
        }
        self.pin_n.next = self._pin_n;
    }

    fn connect(&mut self) {
        self.pin_n.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(self.verilog())
    }
}

impl CnvPulse {
    fn verilog(&self) -> String {
        let w = self.cnt_bits();
        let mut s = String::new();
        let _ = writeln!(
            s,
            "// CNV active for the conversion's {} cycles, then low for the read",
            self._conv
        );
        let _ = writeln!(s, "reg r_pin_n;\ninitial r_pin_n = 1'b1;");
        let _ = writeln!(s, "reg [{}:0] cnt;\ninitial cnt = {w}'h0;", w - 1);
        let _ = writeln!(s, "always @(posedge clock) begin");
        let _ = writeln!(s, "  if (start2 | rst) begin");
        let _ = writeln!(
            s,
            "    r_pin_n <= 1'b0;\n    cnt <= {w}'d{};\n  end",
            self._conv - 1
        );
        let _ = writeln!(s, "  else if (~r_pin_n) begin");
        let _ = writeln!(s, "    if (cnt == {w}'h0) r_pin_n <= 1'b1;");
        let _ = writeln!(s, "    else cnt <= cnt - {w}'h1;\n  end");
        let _ = writeln!(s, "end\n");
        let _ = writeln!(s, "always @(*) pin_n = r_pin_n;");
        s
    }
}
