//! Slot ROM.

use rust_hdl::prelude::*;

use crate::plan::{BranchRom, CompactRom};
use crate::widths::*;

/// One branch's column of the frame table, read synchronously (one cycle of
/// latency) so that synthesis maps it to block RAM.  Custom Verilog so the
/// memory is declared with the exact depth and word width of the mix.
#[derive(LogicBlock)]
pub struct SlotRom {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub address: Signal<In, Bits<SLOT_BITS>>,
    pub slice: Signal<In, Bits<SLICE_BITS>>,
    pub conv: Signal<Out, Bit>,
    pub ch: Signal<Out, Bits<CH_BITS>>,
    pub msel: Signal<Out, Bits<3>>,
    pub mdev: Signal<Out, Bits<DEV_BITS>>,
    _words: Vec<u32>,
    _addr_bits: usize,
    _ch_bits: usize,
    _dev_bits: usize,
    _compact: Option<CompactRom>,
    /// Compact form: slice-table word, its slice, rotation word.
    _q1: u32,
    _jq: usize,
    _q2: u32,
}

impl SlotRom {
    pub(super) fn new(rom: &BranchRom) -> SlotRom {
        SlotRom {
            clock: Default::default(),
            rst: Default::default(),
            address: Default::default(),
            slice: Default::default(),
            conv: Default::default(),
            ch: Default::default(),
            msel: Default::default(),
            mdev: Default::default(),
            _words: rom.words.clone(),
            _addr_bits: rom.addr_bits,
            _ch_bits: rom.ch_bits,
            _dev_bits: rom.dev_bits,
            _compact: rom.compact.clone(),
            _q1: 0,
            _jq: 0,
            _q2: 0,
        }
    }

    fn word_bits(&self) -> usize {
        1 + self._ch_bits + 3 + self._dev_bits
    }

    /// Compact form: the payload width of a slice-table word and the
    /// rotation-table address read in reset (slot 0's).
    fn compact_numbers(c: &CompactRom, wb: usize) -> (usize, usize) {
        let payload = wb.max(c.group_bits);
        let w0 = c.slice_words[0];
        let a0 = if w0 >> payload & 1 == 1 {
            ((w0 & ((1 << payload) - 1)) as usize) << c.slice_bits
        } else {
            0
        };
        (payload, a0)
    }

    fn set_outputs(&mut self, w: u64) {
        let (cw, dw) = (self._ch_bits, self._dev_bits);
        self.conv.next = (w >> (cw + 3 + dw)) & 1 == 1;
        self.ch.next = ((w >> (3 + dw)) & ((1 << cw) - 1)).into();
        self.msel.next = ((w >> dw) & 0x7).into();
        self.mdev.next = (w & ((1 << dw) - 1)).into();
    }
}

impl Logic for SlotRom {
    fn update(&mut self) {
        let wb = self.word_bits();
        if let Some(c) = &self._compact {
            let (payload, a0) = Self::compact_numbers(c, wb);
            if self.clock.pos_edge() {
                let ra = if self.rst.val() {
                    a0
                } else {
                    (((self._q1 as usize) & ((1 << c.group_bits) - 1)) << c.slice_bits) | self._jq
                };
                self._q2 = c.rot_words.get(ra).copied().unwrap_or(0);
                let a = self.address.val().to_u64() as usize & ((1 << c.slice_addr_bits) - 1);
                self._q1 = c.slice_words.get(a).copied().unwrap_or(0);
                self._jq = self.slice.val().to_u64() as usize & ((1 << c.slice_bits) - 1);
            }
            let w = if self._q1 >> payload & 1 == 1 {
                self._q2
            } else {
                self._q1 & ((1 << payload) - 1)
            };
            self.set_outputs(w as u64);
        } else if self.clock.pos_edge() {
            let a = self.address.val().to_u64() as usize;
            let w = self._words.get(a).copied().unwrap_or(0) as u64;
            self.set_outputs(w);
        }
    }

    fn connect(&mut self) {
        self.conv.connect();
        self.ch.connect();
        self.msel.connect();
        self.mdev.connect();
    }

    fn hdl(&self) -> Verilog {
        let (cw, dw) = (self._ch_bits, self._dev_bits);
        let wb = self.word_bits();
        let mut s = String::new();
        let table = |s: &mut String, name: &str, bits: usize, words: &[u32]| {
            let digits = bits.div_ceil(4);
            s.push_str(&format!(
                "reg [{}:0] {name} [0:{}];\n",
                bits - 1,
                words.len() - 1
            ));
            s.push_str("initial begin\n");
            for (a, w) in words.iter().enumerate() {
                s.push_str(&format!("  {name}[{a}] = {bits}'h{w:0digits$x};\n"));
            }
            s.push_str("end\n\n");
        };
        let mut unused = vec![];
        let used_addr;
        if let Some(c) = &self._compact {
            let (payload, a0) = Self::compact_numbers(c, wb);
            let sw = 1 + payload;
            let (gb, sb) = (c.group_bits, c.slice_bits);
            table(&mut s, "smem", sw, &c.slice_words);
            table(&mut s, "rmem", wb, &c.rot_words);
            s.push_str(&format!(
                "// slice table word (rotation flag + word or group), its slice, rotation word\nreg [{}:0] q1;\nreg [{}:0] jq;\nreg [{}:0] q2;\nwire [{}:0] ra = rst ? {}'h{a0:x} : {{q1[{}:0], jq}};\nwire [{}:0] q = q1[{}] ? q2 : q1[{}:0];\n\n",
                sw - 1,
                sb - 1,
                wb - 1,
                gb + sb - 1,
                gb + sb,
                gb - 1,
                wb - 1,
                sw - 1,
                wb - 1
            ));
            s.push_str(&format!(
                "always @(posedge clock) begin\n  q1 <= smem[address[{}:0]];\n  jq <= slice[{}:0];\n  q2 <= rmem[ra];\nend\n\n",
                c.slice_addr_bits - 1,
                sb - 1
            ));
            if payload > wb && gb < payload {
                unused.push(format!("q1[{}:{}]", payload - 1, gb.max(wb)));
            }
            used_addr = c.slice_addr_bits;
            if sb < SLICE_BITS {
                unused.push(format!("slice[{}:{}]", SLICE_BITS - 1, sb));
            }
        } else {
            let aw = self._addr_bits;
            table(&mut s, "mem", wb, &self._words);
            s.push_str(&format!("reg [{}:0] q;\n\n", wb - 1));
            s.push_str(&format!(
                "always @(posedge clock) begin\n  q <= mem[address[{}:0]];\nend\n\n",
                aw - 1
            ));
            used_addr = aw;
            unused.push("slice".to_string());
            unused.push("rst".to_string());
        }
        let pad = |field: String, bits: usize, full: usize| {
            if bits < full {
                format!("{{{}'h0, {field}}}", full - bits)
            } else {
                field
            }
        };
        s.push_str(&format!(
            "always @(*) begin\n  conv = q[{}];\n  ch = {};\n  msel = q[{}:{}];\n  mdev = {};\nend\n",
            wb - 1,
            pad(format!("q[{}:{}]", wb - 2, 3 + dw), cw, CH_BITS),
            dw + 2,
            dw,
            pad(format!("q[{}:0]", dw - 1), dw, DEV_BITS),
        ));
        if used_addr < SLOT_BITS {
            unused.push(format!("address[{}:{}]", SLOT_BITS - 1, used_addr));
        }
        if !unused.is_empty() {
            s.push_str(&format!(
                "\n// inputs and bits this LUT form and size do not use\nwire unused_rom = |{{{}}};\n",
                unused.join(", ")
            ));
        }
        Verilog::Custom(s)
    }
}
