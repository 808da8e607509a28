//! Command unit: the word a converter with a command word takes on
//! `adc_mosi`, one bit per SCLK period, and the conversions after reset
//! that are prepared rather than data (docs/timing.md, "Command words").

use std::fmt::Write as _;

use rust_hdl::prelude::*;

use lut_gen::{CmdBit, Command};

use crate::plan::FrontWords;

/// One per branch whose converter takes a command word (none in a mix
/// without one, so the other mixes' Verilog has no trace of it).  Custom
/// Verilog, like the word reader, so the word register is exactly the
/// word's width and the template's fixed bits are constants.
///
/// It reads only what the branch and its sequencer already drive: the
/// branch's conversion pin and SCLK (`pin`, `bsclk`: the levels of this
/// cycle) and the sequencer's SCLK and done strobe (`qsclk`, `qdone`: the
/// levels a converting branch has in the next cycle).  An SCLK period
/// begins in the next cycle where SCLK falls from this cycle to the next,
/// during a conversion; a CNV part's first period has no falling edge (SCK
/// idles low), so a counter from the slot start (`start0`, cycle `t`)
/// finds cycle `t + Su - 1`.  `sel` and `hi` are the branch's mux field
/// (the input the word of its next instant selects, its bit 3 as device 1:
/// `Plan`), loaded into the word at
/// the slot start; bit `k` of the word goes on the lane for period `k + 1`
/// and the lane returns to 0 when the conversion ends.
///
/// `live` is low while conversions after reset are still prepared (the
/// part's `ahead`: their results were selected by no word of ours): each
/// completion (`done`) counts one down, and the core does not hand the
/// merger a completion while `live` is low.
#[derive(LogicBlock)]
pub struct CmdUnit {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start0: Signal<In, Bit>,
    pub pin: Signal<In, Bit>,
    pub bsclk: Signal<In, Bit>,
    pub qsclk: Signal<In, Bit>,
    pub qdone: Signal<In, Bit>,
    pub sel: Signal<In, Bits<3>>,
    /// Channel bit 3 (a 16-channel converter): the branch's device enable 1.
    pub hi: Signal<In, Bit>,
    pub done: Signal<In, Bit>,
    pub mosi: Signal<Out, Bit>,
    pub live: Signal<Out, Bit>,
    _bits: Vec<CmdBit>,
    _ahead: u64,
    _cnv: bool,
    /// The conversion pin is held through the read (else a CNV part read
    /// with CNV low: the pin is active at the slot start only).
    _held: bool,
    _setup: u64,
    _branch: usize,
    /// Behind a front mux: the words' inputs by conversion (`sel`/`hi`
    /// then carry the front mux's pins and are not read).
    _front: Option<FrontWords>,
    /// The twin's registers: the word still to send (bit 0 next), the
    /// lane, the CNV first-period counter, the prepared conversions left.
    _sh: u64,
    _mosi: bool,
    _cnt: u64,
    _prep: u64,
    /// Read with CNV low: the branch converts in this slot (its pin was
    /// active at the slot start).
    _conv: bool,
    /// Behind a front mux: the conversion of the frame whose word is next.
    _k: u64,
}

/// How a command unit is wired: its part's pin style and its branch.
pub(super) struct CmdWiring {
    pub cnv: bool,
    pub held: bool,
    pub setup: u64,
    pub branch: usize,
    pub front: Option<FrontWords>,
}

impl CmdUnit {
    pub(super) fn new(cmd: &Command, w: CmdWiring) -> CmdUnit {
        let CmdWiring {
            cnv,
            held,
            setup,
            branch,
            front,
        } = w;
        CmdUnit {
            clock: Default::default(),
            rst: Default::default(),
            start0: Default::default(),
            pin: Default::default(),
            bsclk: Default::default(),
            qsclk: Default::default(),
            qdone: Default::default(),
            sel: Default::default(),
            hi: Default::default(),
            done: Default::default(),
            mosi: Default::default(),
            live: Default::default(),
            _bits: cmd.bits.clone(),
            _ahead: cmd.ahead as u64,
            _cnv: cnv,
            _held: held,
            _setup: setup,
            _branch: branch,
            _k: front.as_ref().map_or(0, |f| f.first as u64),
            _front: front,
            _sh: 0,
            _mosi: false,
            _cnt: 0,
            _prep: cmd.ahead as u64,
            _conv: false,
        }
    }

    /// The word for input `sel` (bit 3 from `hi`), bit `k` = the `k`-th bit sent.
    fn word(&self, sel: u64) -> u64 {
        let sel = match &self._front {
            Some(f) => f.inputs[self._k as usize] as u64,
            None => sel | (self.hi.val() as u64) << 3,
        };
        self._bits.iter().enumerate().fold(0, |w, (k, b)| {
            let v = match *b {
                CmdBit::Zero => 0,
                CmdBit::One => 1,
                CmdBit::Channel(j) => sel >> j & 1,
            };
            w | v << k
        })
    }

    /// Whether the next cycle begins an SCLK period of a conversion.  Read
    /// with CNV low, the pin is not active in the read: a fall of the
    /// branch's SCK is one of its conversions (it idles low otherwise), and
    /// the first period is one when the pin was active at the slot start.
    fn period_starts(&self) -> bool {
        let fall = self.bsclk.val() & !self.qsclk.val();
        if !self._held {
            return fall || (self._cnt == 1 && self._conv);
        }
        let act = self.pin.val() == self._cnv;
        let first = self._cnv
            && if self._setup == 1 {
                self.start0.val()
            } else {
                self._cnt == 1
            };
        act && (fall || first)
    }

    /// Width of the CNV first-period counter (counts `setup - 1` down).
    fn cnt_bits(&self) -> usize {
        (64 - (self._setup - 1).leading_zeros()).max(1) as usize
    }

    fn prep_bits(&self) -> usize {
        (64 - self._ahead.leading_zeros()).max(1) as usize
    }
}

impl Logic for CmdUnit {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let src = if self.start0.val() {
                self.word(self.sel.val().to_u64())
            } else {
                self._sh
            };
            let per = self.period_starts();
            if self.start0.val() {
                self._sh = src;
            }
            if self.rst.val() || self.qdone.val() {
                self._mosi = false;
            } else if per {
                self._mosi = src & 1 == 1;
                self._sh = src >> 1;
            }
            if self.rst.val() {
                self._cnt = 0;
            } else if self.start0.val() {
                self._cnt = self._setup - 1;
            } else if self._cnt != 0 {
                self._cnt -= 1;
            }
            if self.start0.val() {
                self._conv = self.pin.val();
            }
            if let Some(f) = &self._front {
                if self.rst.val() {
                    self._k = f.first as u64;
                } else if self.start0.val() && self.pin.val() == self._cnv {
                    self._k = (self._k + 1) % f.inputs.len() as u64;
                }
            }
            if self.rst.val() {
                self._prep = self._ahead;
            } else if self.done.val() && self._prep != 0 {
                self._prep -= 1;
            }
        }
        self.mosi.next = self._mosi;
        self.live.next = self._prep == 0;
    }

    fn connect(&mut self) {
        self.mosi.connect();
        self.live.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(self.verilog())
    }
}

impl CmdUnit {
    fn verilog(&self) -> String {
        let l = self._bits.len();
        let mut s = String::new();
        let tmpl: String = Command {
            bits: self._bits.clone(),
            ahead: self._ahead as u32,
        }
        .template();
        let _ = writeln!(
            s,
            "// branch {}: command word {tmpl} (first bit first) on the MOSI lane, selecting the conversion {} later",
            self._branch, self._ahead
        );
        let front = self.front_table(&mut s);
        let bits: Vec<String> = (self._bits.iter().rev())
            .map(|b| match *b {
                CmdBit::Zero => "1'b0".to_string(),
                CmdBit::One => "1'b1".to_string(),
                CmdBit::Channel(j) if front => format!("chn[{j}]"),
                CmdBit::Channel(3) => "hi".to_string(),
                CmdBit::Channel(j) => format!("sel[{j}]"),
            })
            .collect();
        let _ = writeln!(s, "wire [{}:0] word = {{{}}};", l - 1, bits.join(", "));
        let unused: Vec<String> = (0..4u8)
            .filter(|_| !front)
            .filter(|j| !self._bits.contains(&CmdBit::Channel(*j)))
            .map(|j| match j {
                3 => "hi".to_string(),
                j => format!("sel[{j}]"),
            })
            .collect();
        if !unused.is_empty() {
            let _ = writeln!(
                s,
                "// select bits beyond the word's channel bits\nwire unused_sel = |{{{}}};",
                unused.join(", ")
            );
        }
        let _ = writeln!(s, "reg [{}:0] sh;\ninitial sh = {l}'h0;", l - 1);
        let _ = writeln!(s, "reg r_mosi;\ninitial r_mosi = 1'b0;");
        let _ = writeln!(s, "wire [{}:0] src = start0 ? word : sh;", l - 1);
        let first = self.first_strobe(&mut s);
        if self._held {
            let act = if self._cnv { "pin" } else { "~pin" };
            let _ = writeln!(
                s,
                "// an SCLK period of a conversion begins in the next cycle\nwire per = {act} & ((bsclk & ~qsclk){first});"
            );
        } else {
            let _ = writeln!(
                s,
                "// read with CNV low: the branch converts in this slot if CNV was high at its start\nreg conv;\ninitial conv = 1'b0;\nalways @(posedge clock) if (start0) conv <= pin;"
            );
            let _ = writeln!(
                s,
                "// an SCLK period of a conversion begins in the next cycle (SCK idles low between conversions)\nwire per = (bsclk & ~qsclk) | (first & conv);"
            );
        }
        let shifted = if l == 1 {
            "1'b0".to_string()
        } else {
            format!("{{1'b0, src[{}:1]}}", l - 1)
        };
        let _ = writeln!(s, "\nalways @(posedge clock) begin");
        let _ = writeln!(s, "  if (start0) sh <= word;");
        let _ = writeln!(s, "  if (rst | qdone) r_mosi <= 1'b0;");
        let _ = writeln!(s, "  else if (per) begin");
        let _ = writeln!(s, "    r_mosi <= src[0];\n    sh <= {shifted};\n  end");
        let _ = writeln!(s, "end\n");
        self.prepared(&mut s);
        let _ = writeln!(
            s,
            "\nalways @(*) begin\n  mosi = r_mosi;\n  live = {};\nend",
            self.live_expr()
        );
        s
    }

    /// Behind a front mux (`sel`, `hi`: the front mux's pins, unread): the
    /// conversion counter and the input its word selects (`chn`).  Whether
    /// there is one.
    fn front_table(&self, s: &mut String) -> bool {
        let Some(f) = &self._front else {
            return false;
        };
        let n = f.inputs.len() as u64;
        let kw = (64 - (n - 1).leading_zeros()).max(1) as usize;
        let cw = self._bits.iter().filter_map(|b| match b {
            CmdBit::Channel(j) => Some(*j as usize + 1),
            _ => None,
        });
        let cw = cw.max().unwrap_or(1);
        let act = if self._cnv { "pin" } else { "~pin" };
        let _ = writeln!(
            s,
            "// behind a front mux (its pins on sel/hi): the input each of the frame's {n} words selects, by conversion
wire unused_sel = |{{sel, hi}};"
        );
        let _ = writeln!(
            s,
            "reg [{}:0] k;
initial k = {kw}'d{};",
            kw - 1,
            f.first
        );
        let _ = writeln!(s, "always @(posedge clock) begin");
        let _ = writeln!(s, "  if (rst) k <= {kw}'d{};", f.first);
        let _ = writeln!(
            s,
            "  else if (start0 & {act}) k <= (k == {kw}'d{}) ? {kw}'d0 : k + {kw}'d1;",
            n - 1
        );
        let _ = writeln!(s, "end");
        let _ = writeln!(
            s,
            "reg [{}:0] chn;
always @(*) begin
  case (k)",
            cw - 1
        );
        for (i, v) in f.inputs.iter().enumerate() {
            let _ = writeln!(s, "    {kw}'d{i}: chn = {cw}'d{v};");
        }
        let _ = writeln!(
            s,
            "    default: chn = {cw}'d0;
  endcase
end"
        );
        true
    }

    /// The CNV part's first period (no falling edge): ` | first` and its
    /// counter; a CS part's first period begins with a falling edge.
    fn first_strobe(&self, s: &mut String) -> &'static str {
        if !self._cnv {
            return "";
        }
        if self._setup == 1 {
            let _ = writeln!(
                s,
                "// the first period begins right after the slot start\nwire first = start0;"
            );
            return " | first";
        }
        let w = self.cnt_bits();
        let _ = writeln!(
            s,
            "// cycles to the first period (setup {} cycles from the slot start)",
            self._setup
        );
        let _ = writeln!(s, "reg [{}:0] cnt;\ninitial cnt = {w}'h0;", w - 1);
        let _ = writeln!(s, "always @(posedge clock) begin");
        let _ = writeln!(s, "  if (rst) cnt <= {w}'h0;");
        let _ = writeln!(s, "  else if (start0) cnt <= {w}'d{};", self._setup - 1);
        let _ = writeln!(s, "  else if (cnt != {w}'h0) cnt <= cnt - {w}'h1;");
        let _ = writeln!(s, "end");
        let _ = writeln!(s, "wire first = cnt == {w}'h1;");
        " | first"
    }

    /// The prepared-conversion counter (a part with `ahead` > 0).
    fn prepared(&self, s: &mut String) {
        if self._ahead == 0 {
            let _ = writeln!(s, "// the word selects its own conversion: nothing is prepared\nwire unused_cmd = done;");
            return;
        }
        let w = self.prep_bits();
        let _ = writeln!(
            s,
            "// conversions after reset still prepared (selected by no word of ours)"
        );
        let _ = writeln!(
            s,
            "reg [{}:0] prep;\ninitial prep = {w}'d{};",
            w - 1,
            self._ahead
        );
        let _ = writeln!(s, "always @(posedge clock) begin");
        let _ = writeln!(s, "  if (rst) prep <= {w}'d{};", self._ahead);
        let _ = writeln!(
            s,
            "  else if (done && prep != {w}'h0) prep <= prep - {w}'h1;"
        );
        let _ = writeln!(s, "end");
    }

    fn live_expr(&self) -> String {
        if self._ahead == 0 {
            "1'b1".into()
        } else {
            format!("prep == {}'h0", self.prep_bits())
        }
    }
}
