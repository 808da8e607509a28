//! Slot ROM.

use crate::rhdl::*;

use crate::decode::SlotLogic;
use crate::modeplan::ModeRom;
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
    /// Logic decoding: the word of `{slice, address}` registered (the
    /// timing generator's counters again, which synthesis merges with
    /// them), evaluated once from the same truth tables as the Verilog.
    _logic: Option<(SlotLogic, Vec<u32>)>,
    /// A mix with modes: the mode is on the address above the slot, and
    /// `slice` carries the next frame's mode (low bits) and whether the
    /// address is in the next frame (the bit above); see `read_modes`.
    _modes: Option<ModeRom>,
    /// Modes: the reset mux field, the word read, its frame is the next
    /// one, and the mux field last output (held).
    _reset: (u32, u32),
    _qm: u32,
    _qn: bool,
    _held: (u32, u32),
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
            _logic: rom.logic.clone().map(|l| {
                let n = 1usize << (l.slot_bits + l.slice_bits);
                let w = (0..n)
                    .map(|x| l.word(x & ((1 << l.slot_bits) - 1), x >> l.slot_bits))
                    .collect();
                (l, w)
            }),
            _modes: rom.modes.clone(),
            _reset: (rom.reset_sel, rom.reset_en.trailing_zeros() % 64),
            _qm: 0,
            _qn: false,
            _held: (0, 0),
            _q1: 0,
            _jq: 0,
            _q2: 0,
        }
    }

    fn word_bits(&self) -> usize {
        1 + self._ch_bits + 3 + self._dev_bits
    }

    /// A mix with modes: the word of the address registered as the full
    /// table's, its `w` bit (no instant left in its mode's frame) replaced
    /// by the first instant of the next frame's mode, or the mux held when
    /// that frame is not decided yet (the word's own frame is the next) or
    /// its mode does not use the branch (docs/timing.md, "Mode switches").
    fn read_modes(&mut self, m: &ModeRom) {
        let wb = self.word_bits();
        let dw = self._dev_bits;
        if self.clock.pos_edge() {
            self._held = if self.rst.val() {
                self._reset
            } else {
                self.mode_field(m)
            };
            let a = self.address.val().to_u64() as usize;
            self._qm = self._words.get(a).copied().unwrap_or(0);
            self._qn = self.slice.val().to_u64() >> m.mode_bits & 1 == 1;
        }
        let (sel, dev) = self.mode_field(m);
        let q = self._qm & ((1 << wb) - 1) & !((1 << (3 + dw)) - 1);
        self.set_outputs((q | sel << dw | dev) as u64);
    }

    /// The mux field out of the word read (see [`SlotRom::read_modes`]).
    fn mode_field(&self, m: &ModeRom) -> (u32, u32) {
        let nm = self.slice.val().to_u64() as usize & ((1 << m.mode_bits) - 1);
        let dw = self._dev_bits;
        // the index into the next mode's fields sits in the select field
        let j = if m.indexed() { self._qm >> dw & 7 } else { 0 };
        let first = (m.first.get(nm)).and_then(|f| f.get(j as usize).copied());
        match (self._qm >> self.word_bits() & 1 == 1, self._qn, first) {
            (false, ..) => (self._qm >> dw & 7, self._qm & ((1 << dw) - 1)),
            (true, false, Some(f)) => f,
            _ => self._held,
        }
    }

    /// The mux field a `w` word takes from the next frame's mode
    /// (`slice[mb-1:0]`): its first instant's, or where the words select
    /// conversions ahead, the one its index (the word's select field,
    /// `q[hi:hi-2]`) names.
    fn first_verilog(m: &ModeRom, dw: usize, hi: usize) -> String {
        let mb = m.mode_bits;
        let (key, kb, what) = if m.indexed() {
            let key = format!("{{slice[{}:0], q[{hi}:{}]}}", mb - 1, hi - 2);
            let what = format!("the input of the next frame's conversion the word's index names (next mode: slice[{}:0], index: q[{hi}:{}])", mb - 1, hi - 2);
            (key, mb + 3, what)
        } else {
            let key = format!("slice[{}:0]", mb - 1);
            let what = format!("the first instant of the next frame's mode ({key})");
            (key, mb, what)
        };
        let mut s = format!(
            "// {what}, if it uses this branch\nreg fuse;\nreg [2:0] fsel;\nreg [{}:0] fdev;\nalways @(*) begin\n  case ({key})\n",
            dw - 1
        );
        let mut labels = 0;
        for (k, f) in m.first.iter().enumerate() {
            let per = if m.indexed() { f.len().max(1) } else { 1 };
            for j in 0..per {
                let (u, (sel, dev)) = f.get(j).map_or((0, (0, 0)), |x| (1, *x));
                let label = if m.indexed() { k << 3 | j } else { k };
                labels += 1;
                s.push_str(&format!(
                    "    {kb}'d{label}: begin fuse = 1'b{u}; fsel = 3'd{sel}; fdev = {dw}'d{dev}; end\n"
                ));
            }
        }
        if labels < 1 << kb {
            s.push_str(&format!(
                "    default: begin fuse = 1'b0; fsel = 3'd0; fdev = {dw}'d0; end\n"
            ));
        }
        s.push_str("  endcase\nend\n\n");
        s
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

    /// The Verilog of [`SlotRom::read_modes`].
    fn modes_verilog(&self, m: &ModeRom) -> String {
        let (cw, dw) = (self._ch_bits, self._dev_bits);
        let wb = self.word_bits();
        let mb = m.mode_bits;
        let aw = self._addr_bits;
        let mut s = format!(
            "// the word (its mode's table at {{mode, slot}}; bit {wb}: no instant left in that mode's frame),\n// whether its frame is the next one, and the mux field last output\nreg [{wb}:0] q;\nreg qn;\nreg [2:0] hsel;\nreg [{}:0] hdev;\n\n",
            dw - 1
        );
        s.push_str(&Self::first_verilog(m, dw, dw + 2));
        let (rsel, rdev) = self._reset;
        s.push_str(&format!(
            "wire hold = q[{wb}] & (qn | ~fuse);\nalways @(posedge clock) begin\n  q <= mem[address[{}:0]];\n  qn <= slice[{mb}];\n  if (rst) begin\n    hsel <= 3'd{rsel};\n    hdev <= {dw}'d{rdev};\n  end else begin\n    hsel <= msel;\n    hdev <= mdev[{}:0];\n  end\nend\n\n",
            aw - 1,
            dw - 1
        ));
        let pad = |field: String, bits: usize, full: usize| {
            if bits < full {
                format!("{{{}'h0, {field}}}", full - bits)
            } else {
                field
            }
        };
        s.push_str(&format!(
            "always @(*) begin\n  conv = q[{}];\n  ch = {};\n  if (hold) begin\n    msel = hsel;\n    mdev = {};\n  end else if (q[{wb}]) begin\n    msel = fsel;\n    mdev = {};\n  end else begin\n    msel = q[{}:{}];\n    mdev = {};\n  end\nend\n",
            wb - 1,
            pad(format!("q[{}:{}]", wb - 2, 3 + dw), cw, CH_BITS),
            pad("hdev".into(), dw, DEV_BITS),
            pad("fdev".into(), dw, DEV_BITS),
            dw + 2,
            dw,
            pad(format!("q[{}:0]", dw - 1), dw, DEV_BITS),
        ));
        let mut unused = vec![];
        if mb + 1 < SLICE_BITS {
            unused.push(format!("slice[{}:{}]", SLICE_BITS - 1, mb + 1));
        }
        if aw < SLOT_BITS {
            unused.push(format!("address[{}:{}]", SLOT_BITS - 1, aw));
        }
        if !unused.is_empty() {
            s.push_str(&format!(
                "\n// inputs and bits this LUT form and size do not use\nwire unused_rom = |{{{}}};\n",
                unused.join(", ")
            ));
        }
        s
    }
}

impl Logic for SlotRom {
    fn update(&mut self) {
        let wb = self.word_bits();
        if let Some((l, w)) = &self._logic {
            if self.clock.pos_edge() {
                let p = self.address.val().to_u64() as usize & ((1 << l.slot_bits) - 1);
                let j = self.slice.val().to_u64() as usize & ((1 << l.slice_bits) - 1);
                let w = w[j << l.slot_bits | p];
                self.set_outputs(w as u64);
            }
        } else if let Some(m) = self._modes.take() {
            self.read_modes(&m);
            self._modes = Some(m);
        } else if let Some(c) = &self._compact {
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
        if let Some((l, _)) = &self._logic {
            s.push_str(&l.verilog(wb));
            unused = l.unused();
            unused.push("rst".to_string());
            used_addr = SLOT_BITS;
        } else if let Some(c) = &self._compact {
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
        } else if let Some(m) = &self._modes {
            table(&mut s, "mem", wb + 1, &self._words);
            s.push_str(&self.modes_verilog(m));
            return Verilog::Custom(s);
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
