//! Hold-off: a sequencer whose branches start their transactions `H`
//! cycles after the slot tick (docs/timing.md, "Hold-off"), so a sync group
//! of parts that hold their inputs at different points of their
//! transactions holds at one instant.

use std::fmt::Write as _;

use crate::rhdl::*;

/// One per sequencer with a hold-off (none otherwise, so every other mix's
/// Verilog has no trace of it).  It stands between the timing generator
/// and the sequencer, and between the sequencer and its branches:
///
/// - `fire2` is the timing generator's `start2` `H` cycles late (a counter
///   loaded with `H` at `start2`, firing when it reaches 1): the
///   sequencer's and the CNV pulse's start, so the pin becomes active at
///   `t + H`;
/// - `start0` is `fire2` two cycles late (cycle `t + H`): the branches'
///   mux load and the command unit's slot start, so the mux switches in
///   the cycle after the transaction starts, as at a slot tick;
/// - the sequencer's levels pass to the branches masked from reset until
///   the first `fire2`: the sequencer starts a conversion at reset (its
///   reset is its start), which a held-off branch must not show; reset
///   loads the counter with `H - 1`, the start of an instant at cycle 0.
#[derive(LogicBlock)]
pub struct HoldOff {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start2: Signal<In, Bit>,
    pub cs_in: Signal<In, Bit>,
    pub sclk_in: Signal<In, Bit>,
    pub cap_in: Signal<In, Bit>,
    pub done_in: Signal<In, Bit>,
    pub fire2: Signal<Out, Bit>,
    pub start0: Signal<Out, Bit>,
    pub cs_n: Signal<Out, Bit>,
    pub sclk: Signal<Out, Bit>,
    pub cap: Signal<Out, Bit>,
    pub done: Signal<Out, Bit>,
    _hold: u64,
    _sclk_idle: bool,
    /// The twin's registers: the counter, the mask, `fire2` one and two
    /// cycles late.
    _cnt: u64,
    _mask: bool,
    _d1: bool,
    _d0: bool,
}

impl HoldOff {
    /// A hold-off of `hold` cycles (at least 2: the plan refuses less) for
    /// a sequencer whose SCLK idles at `sclk_idle`.
    pub(super) fn new(hold: u64, sclk_idle: bool) -> HoldOff {
        HoldOff {
            clock: Default::default(),
            rst: Default::default(),
            start2: Default::default(),
            cs_in: Default::default(),
            sclk_in: Default::default(),
            cap_in: Default::default(),
            done_in: Default::default(),
            fire2: Default::default(),
            start0: Default::default(),
            cs_n: Default::default(),
            sclk: Default::default(),
            cap: Default::default(),
            done: Default::default(),
            _hold: hold.max(2),
            _sclk_idle: sclk_idle,
            _cnt: 0,
            _mask: true,
            _d1: false,
            _d0: false,
        }
    }

    fn cnt_bits(&self) -> usize {
        (64 - self._hold.leading_zeros()).max(1) as usize
    }
}

impl Logic for HoldOff {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let fire = self._cnt == 1;
            if self.rst.val() {
                self._cnt = self._hold;
                self._mask = true;
                self._d1 = false;
                self._d0 = false;
            } else {
                if self.start2.val() {
                    self._cnt = self._hold;
                } else if self._cnt != 0 {
                    self._cnt -= 1;
                }
                if fire {
                    self._mask = false;
                }
                self._d0 = self._d1;
                self._d1 = fire;
            }
        }
        self.fire2.next = self._cnt == 1 && !self.rst.val();
        self.start0.next = self._d0;
        self.cs_n.next = self.cs_in.val() || self._mask;
        self.sclk.next = match self._mask {
            true => self._sclk_idle,
            false => self.sclk_in.val(),
        };
        self.cap.next = self.cap_in.val() && !self._mask;
        self.done.next = self.done_in.val() && !self._mask;
    }

    fn connect(&mut self) {
        self.fire2.connect();
        self.start0.connect();
        self.cs_n.connect();
        self.sclk.connect();
        self.cap.connect();
        self.done.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(self.verilog())
    }
}

impl HoldOff {
    fn verilog(&self) -> String {
        let w = self.cnt_bits();
        let idle = self._sclk_idle as u8;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "// transactions start {} cycles after the slot tick",
            self._hold
        );
        let _ = writeln!(s, "reg [{}:0] cnt;\ninitial cnt = {w}'h0;", w - 1);
        let _ = writeln!(s, "reg r_mask;\ninitial r_mask = 1'b1;");
        let _ = writeln!(
            s,
            "reg r_d1;\ninitial r_d1 = 1'b0;\nreg r_d0;\ninitial r_d0 = 1'b0;"
        );
        let _ = writeln!(s, "wire at_one = cnt == {w}'h1;");
        let _ = writeln!(s, "always @(posedge clock) begin");
        let _ = writeln!(
            s,
            "  if (rst) begin\n    cnt <= {w}'d{};\n    r_mask <= 1'b1;\n    r_d1 <= 1'b0;\n    r_d0 <= 1'b0;\n  end",
            self._hold
        );
        let _ = writeln!(s, "  else begin");
        let _ = writeln!(s, "    if (start2) cnt <= {w}'d{};", self._hold);
        let _ = writeln!(s, "    else if (cnt != {w}'h0) cnt <= cnt - {w}'h1;");
        let _ = writeln!(s, "    if (at_one) r_mask <= 1'b0;");
        let _ = writeln!(s, "    r_d1 <= at_one;\n    r_d0 <= r_d1;\n  end");
        let _ = writeln!(s, "end\n");
        let _ = writeln!(s, "always @(*) begin");
        let _ = writeln!(s, "  fire2 = at_one & ~rst;\n  start0 = r_d0;");
        let _ = writeln!(s, "  cs_n = cs_in | r_mask;");
        let _ = writeln!(s, "  sclk = r_mask ? 1'b{idle} : sclk_in;");
        let _ = writeln!(s, "  cap = cap_in & ~r_mask;\n  done = done_in & ~r_mask;");
        let _ = writeln!(s, "end");
        s
    }
}
