//! Command unit: the word a converter with a command word takes on
//! `adc_mosi`, one bit per SCLK period, and the conversions after reset
//! that are prepared rather than data (docs/timing.md, "Command words").

use std::fmt::Write as _;

use crate::rhdl::*;

use lut_gen::{CmdBit, Command};

use crate::modeplan::{FrontModes, FrontWord};
use crate::plan::FrontWords;
use crate::widths::MODE_BITS;

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
    /// Behind a front mux in a mix with modes: the mode in force and the
    /// next frame's (the mode block's `mode` and `minfo`), one each; none
    /// otherwise, so every other unit keeps its ports.
    pub mode: Vec<Signal<In, Bits<MODE_BITS>>>,
    pub nxt: Vec<Signal<In, Bits<MODE_BITS>>>,
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
        let moded = front.iter().filter(|f| f.modes.is_some());
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
            mode: moded.clone().map(|_| Default::default()).collect(),
            nxt: moded.map(|_| Default::default()).collect(),
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
            Some(f) => self.front_input(f),
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

    /// The mode in force and the next frame's (mode mixes only).
    fn modes_now(&self) -> (usize, usize) {
        let v = |x: &[Signal<In, Bits<MODE_BITS>>]| x.first().map_or(0, |s| s.val().to_u64());
        let mb = self
            ._front
            .as_ref()
            .and_then(|f| f.modes.as_ref())
            .map_or(0, |m| m.mode_bits);
        let mask = (1u64 << mb) - 1;
        (
            (v(&self.mode) & mask) as usize,
            (v(&self.nxt) & mask) as usize,
        )
    }

    /// Conversions in the frame in force (the counter's wrap).
    fn frame_words(&self, f: &FrontWords) -> u64 {
        match &f.modes {
            None => f.inputs.len() as u64,
            Some(m) => m
                .words
                .get(self.modes_now().0)
                .map_or(0, |w| w.len() as u64),
        }
    }

    /// The input the word of the frame's conversion `_k` selects: in its
    /// own frame, or the next frame's (the next mode's) conversion `j`.
    fn front_input(&self, f: &FrontWords) -> u64 {
        let Some(m) = &f.modes else {
            return f.inputs[self._k as usize] as u64;
        };
        let (cur, nxt) = self.modes_now();
        let i = match m.words.get(cur).and_then(|w| w.get(self._k as usize)) {
            Some(FrontWord::Here(i)) => Some(*i),
            Some(FrontWord::Next(j)) => m.first.get(nxt).and_then(|f| f.get(*j as usize)).copied(),
            None => None,
        };
        i.unwrap_or(0) as u64
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
                    self._k = (self._k + 1) % self.frame_words(f).max(1);
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
        let n = match &f.modes {
            Some(m) => m.words.iter().map(Vec::len).max().unwrap_or(1) as u64,
            None => f.inputs.len() as u64,
        };
        let kw = (64 - (n.max(1) - 1).leading_zeros()).max(1) as usize;
        let cw = self._bits.iter().filter_map(|b| match b {
            CmdBit::Channel(j) => Some(*j as usize + 1),
            _ => None,
        });
        let cw = cw.max().unwrap_or(1);
        let act = if self._cnv { "pin" } else { "~pin" };
        let words = match f.modes {
            Some(_) => "the word of each conversion of the frame in force".to_string(),
            None => format!("each of the frame's {n} words"),
        };
        let _ = writeln!(
            s,
            "// behind a front mux (its pins on sel/hi): the input {words} selects, by conversion
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
        let last = match f.modes {
            Some(_) => "kl".to_string(),
            None => format!("{kw}'d{}", n - 1),
        };
        let _ = writeln!(
            s,
            "  else if (start0 & {act}) k <= (k == {last}) ? {kw}'d0 : k + {kw}'d1;"
        );
        let _ = writeln!(s, "end");
        if let Some(m) = &f.modes {
            front_modes_table(s, m, kw, cw);
            return true;
        }
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

/// A fronted unit's words in a mix with modes: the frame's last conversion
/// in the mode in force (`kl`, the counter's wrap) and the input each word
/// selects (`chn`): one of its own frame's conversions (`hchn`), or the
/// next frame's conversion `j` in the next frame's mode (`fchn`, decided
/// at the edge that began this frame).
fn front_modes_table(s: &mut String, m: &FrontModes, kw: usize, cw: usize) {
    let mb = m.mode_bits;
    let ahead = m.first.iter().map(Vec::len).max().unwrap_or(1).max(1) as u64;
    let jw = (64 - (ahead - 1).leading_zeros()).max(1) as usize;
    let _ = writeln!(
        s,
        "// the mode in force and the next frame's
wire [{}:0] cur = mode$0[{0}:0];
wire [{0}:0] nxm = nxt$0[{0}:0];",
        mb - 1
    );
    if mb < MODE_BITS {
        let _ = writeln!(
            s,
            "wire unused_modes = |{{mode$0[{}:{mb}], nxt$0[{0}:{mb}]}};",
            MODE_BITS - 1
        );
    }
    let _ = writeln!(
        s,
        "reg [{}:0] kl;
always @(*) begin
  case (cur)",
        kw - 1
    );
    for (i, w) in m.words.iter().enumerate() {
        let _ = writeln!(s, "    {mb}'d{i}: kl = {kw}'d{};", w.len().max(1) - 1);
    }
    let _ = writeln!(
        s,
        "    default: kl = {kw}'d0;
  endcase
end"
    );
    let _ = writeln!(
        s,
        "reg nx;
reg [{}:0] j;
reg [{}:0] hchn;
always @(*) begin
  nx = 1'b0;
  j = {jw}'d0;
  hchn = {cw}'d0;
  case ({{cur, k}})",
        jw - 1,
        cw - 1
    );
    let kb = mb + kw;
    for (i, w) in m.words.iter().enumerate() {
        for (k, x) in w.iter().enumerate() {
            let key = (i << kw) | k;
            let _ = match x {
                FrontWord::Here(v) => writeln!(s, "    {kb}'d{key}: hchn = {cw}'d{v};"),
                FrontWord::Next(v) => {
                    writeln!(s, "    {kb}'d{key}: begin nx = 1'b1; j = {jw}'d{v}; end")
                }
            };
        }
    }
    let _ = writeln!(
        s,
        "    default: ;
  endcase
end"
    );
    let _ = writeln!(
        s,
        "reg [{}:0] fchn;
always @(*) begin
  case ({{nxm, j}})",
        cw - 1
    );
    let fb = mb + jw;
    for (i, f) in m.first.iter().enumerate() {
        for (j, v) in f.iter().enumerate() {
            let _ = writeln!(s, "    {fb}'d{}: fchn = {cw}'d{v};", (i << jw) | j);
        }
    }
    let _ = writeln!(
        s,
        "    default: fchn = {cw}'d0;
  endcase
end
wire [{}:0] chn = nx ? fchn : hchn;",
        cw - 1
    );
}
