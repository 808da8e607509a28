//! Word reader: the data bits of one conversion, word by word to the merger.

use std::fmt::Write as _;

use crate::rhdl::*;

use crate::plan::BranchRom;
use crate::widths::*;

/// The data bits a branch shifts in from MISO (every word of a chain, MSB
/// first), and which word the merger takes next.  After a completion the
/// first word out sits in the top `bits` of the register; each word the
/// merger takes shifts the next one up, and names it by its chain member.
/// Custom Verilog so the register has exactly the mix's width (`chain *
/// bits`) and the member table only the branch's own conversions.
#[derive(LogicBlock)]
pub struct WordReader {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub cap: Signal<In, Bit>,
    pub miso: Signal<In, Bit>,
    pub grant: Signal<In, Bit>,
    /// Queue form of the merger (a single-word branch only): the next
    /// lane's word.
    pub q_in: Signal<In, Bits<VALUE_BITS>>,
    /// Queue form: the register loads at the end of this cycle (a
    /// flip-flop equal to `cap | mv`), MISO if `cap` else `q_in`.
    pub en: Signal<In, Bit>,
    /// The conversion's lead channel (its frame-table entry).
    pub lead: Signal<In, Bits<CH_BITS>>,
    pub val: Signal<Out, Bits<VALUE_BITS>>,
    pub ch: Signal<Out, Bits<CH_BITS>>,
    pub more: Signal<Out, Bit>,
    _bits: usize,
    _chain: usize,
    _members: Vec<(u32, Vec<u32>)>,
    _queue: bool,
    /// A chain stepped under the merger's registered `en` (`cap | r_any`,
    /// `merger::stepped_reader`) rather than under `grant`.
    _step: bool,
    /// The shift register and the member of the word on `val`.
    _sh: u128,
    _om: usize,
}

impl WordReader {
    pub(super) fn new(rom: &BranchRom, queue: bool, step: bool) -> WordReader {
        WordReader {
            clock: Default::default(),
            rst: Default::default(),
            cap: Default::default(),
            miso: Default::default(),
            grant: Default::default(),
            q_in: Default::default(),
            en: Default::default(),
            lead: Default::default(),
            val: Default::default(),
            ch: Default::default(),
            more: Default::default(),
            _bits: rom.bits as usize,
            _chain: rom.chain as usize,
            _members: rom.members.clone(),
            _queue: queue && rom.chain == 1,
            _step: step && rom.chain > 1,
            _sh: 0,
            _om: 0,
        }
    }

    fn width(&self) -> usize {
        self._bits * self._chain
    }

    fn member_channel(&self, lead: u32, m: usize) -> u32 {
        match self._members.iter().find(|(l, _)| *l == lead) {
            Some((_, chans)) => chans[m],
            None => lead,
        }
    }
}

impl WordReader {
    /// A clock edge of the stepped chain (the Verilog's `_step` text): the
    /// member steps on a grant as before; the register loads under `en`,
    /// MISO on `cap`, else the next word up (also after the last word and
    /// in reset, when nothing reads it before the next capture refills it).
    fn step_edge(&mut self, mask: u128) {
        let (cap, grant, rst) = (self.cap.val(), self.grant.val(), self.rst.val());
        if !cap && grant && !rst {
            self._om = if self._om + 1 < self._chain {
                self._om + 1
            } else {
                0
            };
        }
        if self.en.val() {
            self._sh = if cap {
                (self._sh << 1) | self.miso.val() as u128
            } else {
                self._sh << self._bits
            } & mask;
        }
    }
}

impl Logic for WordReader {
    fn update(&mut self) {
        let w = self.width();
        let mask = if w >= 128 {
            u128::MAX
        } else {
            (1u128 << w) - 1
        };
        if self.clock.pos_edge() {
            if self.rst.val() {
                self._om = 0;
            }
            if self._queue {
                if self.en.val() && self.cap.val() {
                    self._sh = ((self._sh << 1) | self.miso.val() as u128) & mask;
                } else if self.en.val() {
                    self._sh = self.q_in.val().to_u64() as u128 & mask;
                }
            } else if self._step {
                self.step_edge(mask);
            } else if self.cap.val() {
                self._sh = ((self._sh << 1) | self.miso.val() as u128) & mask;
            } else if self.grant.val() && self._chain > 1 && !self.rst.val() {
                if self._om + 1 < self._chain {
                    self._sh = (self._sh << self._bits) & mask;
                    self._om += 1;
                } else {
                    self._om = 0;
                }
            }
        }
        let top = (self._sh >> (w - self._bits)) as u64 & ((1u64 << self._bits) - 1);
        self.val.next = top.into();
        let lead = self.lead.val().to_u64() as u32;
        self.ch.next = (self.member_channel(lead, self._om) as u64).into();
        self.more.next = self._om + 1 < self._chain;
    }

    fn connect(&mut self) {
        self.val.connect();
        self.ch.connect();
        self.more.connect();
    }

    fn hdl(&self) -> Verilog {
        let (bits, n) = (self._bits, self._chain);
        let w = self.width();
        let mb = MEMBER_BITS;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "// {n} word(s) of {bits} data bits, the first out in the top bits"
        );
        let _ = writeln!(s, "reg [{}:0] sh;\ninitial sh = {w}'h0;", w - 1);
        let shifted_in = if w == 1 {
            "miso".to_string()
        } else {
            format!("{{sh[{}:0], miso}}", w - 2)
        };
        let top = if bits == w {
            "sh".to_string()
        } else {
            format!("sh[{}:{}]", w - 1, w - bits)
        };
        let val = if bits < VALUE_BITS {
            format!("{{{}'h0, {top}}}", VALUE_BITS - bits)
        } else {
            top
        };
        if n == 1 {
            let _ = writeln!(s, "\nalways @(posedge clock) begin");
            let q = if w == VALUE_BITS {
                "q_in".to_string()
            } else {
                format!("q_in[{}:0]", w - 1)
            };
            if self._queue {
                let _ = writeln!(
                    s,
                    "  // the merger's queue form: MISO, or the next lane's word moving up"
                );
                let _ = writeln!(s, "  if (en) sh <= cap ? {shifted_in} : {q};");
            } else {
                let _ = writeln!(s, "  if (cap) sh <= {shifted_in};");
            }
            let _ = writeln!(s, "end\n");
            let _ = writeln!(s, "always @(*) begin");
            let _ = writeln!(s, "  val = {val};\n  ch = lead;\n  more = 1'b0;");
            let _ = writeln!(s, "end\n");
            let _ = writeln!(s, "// a single word: nothing to step through");
            let unused = if !self._queue {
                "grant, rst, en, q_in".to_string()
            } else if w < VALUE_BITS {
                format!("grant, rst, q_in[{}:{w}]", VALUE_BITS - 1)
            } else {
                "grant, rst".to_string()
            };
            let _ = writeln!(s, "wire unused_reader = |{{{unused}}};");
            return Verilog::Custom(s);
        }
        let last = n - 1;
        let _ = writeln!(s, "// chain member of the word on val");
        let _ = writeln!(s, "reg [{}:0] om;\ninitial om = {mb}'h0;\n", mb - 1);
        let _ = writeln!(s, "always @(posedge clock) begin");
        let _ = writeln!(s, "  if (rst) om <= {mb}'h0;");
        if self._step {
            let _ = writeln!(s, "  if (!cap && grant && !rst) om <= (om != {mb}'h{last:x}) ? om + {mb}'h1 : {mb}'h0;");
            let _ = writeln!(
                s,
                "  // under the merger's registered cap | r_any: no LUT before the enable"
            );
            let _ = writeln!(
                s,
                "  if (en) sh <= cap ? {shifted_in} : {{sh[{}:0], {bits}'h0}};\nend\n",
                w - bits - 1
            );
            return self.chain_outputs(s);
        }
        let _ = writeln!(s, "  if (cap) sh <= {shifted_in};");
        let _ = writeln!(s, "  else if (grant && !rst) begin");
        let _ = writeln!(s, "    if (om != {mb}'h{last:x}) begin");
        let _ = writeln!(s, "      sh <= {{sh[{}:0], {bits}'h0}};", w - bits - 1);
        let _ = writeln!(s, "      om <= om + {mb}'h1;");
        let _ = writeln!(s, "    end else om <= {mb}'h0;");
        let _ = writeln!(s, "  end\nend\n");
        self.chain_outputs(s)
    }
}

impl WordReader {
    /// A chain's word, `more` and member table (the end of `hdl`'s text).
    fn chain_outputs(&self, mut s: String) -> Verilog {
        let (bits, n, w, mb) = (self._bits, self._chain, self.width(), MEMBER_BITS);
        let last = n - 1;
        let top = format!("sh[{}:{}]", w - 1, w - bits);
        let val = if bits < VALUE_BITS {
            format!("{{{}'h0, {top}}}", VALUE_BITS - bits)
        } else {
            top
        };
        let _ = writeln!(s, "always @(*) begin");
        let _ = writeln!(s, "  val = {val};");
        let _ = writeln!(s, "  more = om != {mb}'h{last:x};");
        let _ = writeln!(s, "  case ({{lead, om}})");
        let kb = CH_BITS + mb;
        for (lead, chans) in &self._members {
            for (m, c) in chans.iter().enumerate() {
                let key = ((*lead as usize) << mb) | m;
                let _ = writeln!(s, "    {kb}'h{key:x}: ch = {CH_BITS}'d{c};");
            }
        }
        let _ = writeln!(s, "    default: ch = lead;\n  endcase\nend");
        let _ = writeln!(s, "\n// a chain is never the merger's queue");
        if self._step {
            let _ = writeln!(s, "wire unused_queue = |q_in;");
        } else {
            let _ = writeln!(s, "wire unused_queue = |{{en, q_in}};");
        }
        Verilog::Custom(s)
    }
}
