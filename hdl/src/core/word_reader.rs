//! Word reader: the data bits of one conversion, word by word to the merger.

use std::fmt::Write as _;

use rust_hdl::prelude::*;

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
    /// The shift register and the member of the word on `val`.
    _sh: u128,
    _om: usize,
}

impl WordReader {
    pub(super) fn new(rom: &BranchRom, queue: bool) -> WordReader {
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
        let _ = writeln!(s, "  if (cap) sh <= {shifted_in};");
        let _ = writeln!(s, "  else if (grant && !rst) begin");
        let _ = writeln!(s, "    if (om != {mb}'h{last:x}) begin");
        let _ = writeln!(s, "      sh <= {{sh[{}:0], {bits}'h0}};", w - bits - 1);
        let _ = writeln!(s, "      om <= om + {mb}'h1;");
        let _ = writeln!(s, "    end else om <= {mb}'h0;");
        let _ = writeln!(s, "  end\nend\n");
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
        let _ = writeln!(s, "wire unused_queue = |{{en, q_in}};");
        Verilog::Custom(s)
    }
}
