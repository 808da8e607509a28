//! The gateware itself, described with rust-hdl (private to this crate).
//!
//! Hierarchy (every sequential element sits at depth 2, so that in rust-hdl's
//! simulator every flip-flop sees the clock edge in the same pass):
//!
//! ```text
//! Core                    fixed-maximum ports (16 branches, 64 mux enables, 10-bit channel)
//!  |- timing: TimingGen   cycle-in-slot counter, slot-in-frame counter, slot-start strobes
//!  |- seqs: Vec<SpiSeq>   one SPI sequencer per distinct SPI timing (usually one):
//!  |                      CS/SCLK levels, capture and completion strobes for every slot
//!  |- branches: Vec<BranchUnit>, one per branch of the mix
//!  |    |- rom: SlotRom   that branch's column of the frame table (BRAM-friendly)
//!  |    `- DFFs           "converts this slot" flag, CS/SCLK outputs gated by it,
//!  |                      MISO shift register, channel, mux control
//!  `- merge: Merger       pending set + lowest-branch-first sample stream (Verilog over the mix's lanes)
//! ```
//!
//! No literal appears in a kernel: every number is a sized `Constant`, so the
//! emitted Verilog has no 32-bit literals and lints clean.

use std::fmt::Write as _;

use rust_hdl::prelude::*;

use crate::plan::{BranchRom, CompactRom, Plan, SeqTiming};
use crate::widths::*;

fn c<const N: usize>(v: u64) -> Constant<Bits<N>> {
    Constant::new(Bits::<N>::from(v))
}

// ---------------------------------------------------------------------------
// Slot ROM
// ---------------------------------------------------------------------------

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
    fn new(rom: &BranchRom) -> SlotRom {
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

// ---------------------------------------------------------------------------
// Timing generator
// ---------------------------------------------------------------------------

/// Runs ahead of the outputs: `start2` (`start1`, `start0`) is high in cycle
/// `c` iff cycle `c + 2` (`c + 1`, `c`) is the first cycle of a slot; `addr`
/// is the (combinational) next value of the slot pointer, so the ROMs'
/// registered data describe slot `u` from the second cycle of slot `u - 1`
/// through its last, and slot `u + 1` in the first cycle of slot `u`.
#[derive(LogicBlock)]
pub struct TimingGen {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start2: Signal<Out, Bit>,
    pub start1: Signal<Out, Bit>,
    pub start0: Signal<Out, Bit>,
    pub addr: Signal<Out, Bits<SLOT_BITS>>,
    pub slice: Signal<Out, Bits<SLICE_BITS>>,
    /// (c + 2) mod slot_cycles during cycle c.
    cnt: DFF<Bits<CNT_BITS>>,
    st: DFF<Bit>,
    st2: DFF<Bit>,
    st0: DFF<Bit>,
    /// Index of the next slot start (> c): in the frame (full LUT) or in the
    /// slice (compact LUT), with its slice in `sl`.
    slot: DFF<Bits<SLOT_BITS>>,
    sl: DFF<Bits<SLICE_BITS>>,
    nxt: Signal<Local, Bits<SLOT_BITS>>,
    nxt_sl: Signal<Local, Bits<SLICE_BITS>>,
    k_compact: Constant<Bit>,
    k_sl_last: Constant<Bits<SLICE_BITS>>,
    k_sl_zero: Constant<Bits<SLICE_BITS>>,
    k_sl_one: Constant<Bits<SLICE_BITS>>,
    k_cnt_last: Constant<Bits<CNT_BITS>>,
    k_cnt_rst: Constant<Bits<CNT_BITS>>,
    k_cnt_zero: Constant<Bits<CNT_BITS>>,
    k_cnt_one: Constant<Bits<CNT_BITS>>,
    k_slot_last: Constant<Bits<SLOT_BITS>>,
    k_slot_zero: Constant<Bits<SLOT_BITS>>,
    k_slot_one: Constant<Bits<SLOT_BITS>>,
}

impl TimingGen {
    fn new(plan: &Plan) -> TimingGen {
        TimingGen {
            clock: Default::default(),
            rst: Default::default(),
            start2: Default::default(),
            start1: Default::default(),
            start0: Default::default(),
            addr: Default::default(),
            slice: Default::default(),
            cnt: Default::default(),
            st: Default::default(),
            st2: Default::default(),
            st0: Default::default(),
            slot: Default::default(),
            sl: Default::default(),
            nxt: Default::default(),
            nxt_sl: Default::default(),
            k_compact: Constant::new(plan.compact),
            k_sl_last: c(if plan.compact {
                plan.slices_per_frame - 1
            } else {
                0
            }),
            k_sl_zero: c(0),
            k_sl_one: c(1),
            k_cnt_last: c(plan.slot_cycles - 1),
            k_cnt_rst: c(1 % plan.slot_cycles),
            k_cnt_zero: c(0),
            k_cnt_one: c(1),
            k_slot_last: c(if plan.compact {
                plan.slots_per_slice - 1
            } else {
                plan.frame_slots - 1
            }),
            k_slot_zero: c(0),
            k_slot_one: c(1),
        }
    }
}

impl Logic for TimingGen {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, cnt, st, st2, st0, slot, sl);
        if self.cnt.q.val() == self.k_cnt_last.val() {
            self.cnt.d.next = self.k_cnt_zero.val();
        } else {
            self.cnt.d.next = self.cnt.q.val() + self.k_cnt_one.val();
        }
        self.st2.d.next = self.cnt.q.val() == self.k_cnt_last.val();
        self.st.d.next = self.st2.q.val();
        self.st0.d.next = self.st.q.val();
        self.nxt.next = self.slot.q.val();
        self.nxt_sl.next = self.sl.q.val();
        if self.st.q.val() {
            if self.slot.q.val() == self.k_slot_last.val() {
                self.nxt.next = self.k_slot_zero.val();
                if self.k_compact.val() {
                    if self.sl.q.val() == self.k_sl_last.val() {
                        self.nxt_sl.next = self.k_sl_zero.val();
                    } else {
                        self.nxt_sl.next = self.sl.q.val() + self.k_sl_one.val();
                    }
                }
            } else {
                self.nxt.next = self.slot.q.val() + self.k_slot_one.val();
            }
        }
        if self.rst.val() {
            self.cnt.d.next = self.k_cnt_rst.val();
            self.st.d.next = true;
            self.st2.d.next = false;
            self.st0.d.next = false;
            self.nxt.next = self.k_slot_zero.val();
            self.nxt_sl.next = self.k_sl_zero.val();
        }
        self.slot.d.next = self.nxt.val();
        self.sl.d.next = self.nxt_sl.val();
        self.addr.next = self.nxt.val();
        self.slice.next = self.nxt_sl.val();
        self.start2.next = self.st2.q.val();
        self.start1.next = self.st.q.val();
        self.start0.next = self.st0.q.val();
    }
}

// ---------------------------------------------------------------------------
// SPI sequencer: one per distinct SPI timing, shared by its branches
// ---------------------------------------------------------------------------

/// Every conversion starts at a slot start, so CS/SCLK/capture timing
/// inside a slot is the same for every branch with the same SPI timing.
/// The sequencer runs one cycle ahead of the branches' output registers and
/// starts a (virtual) conversion in every slot: in cycle `c`, `cs_n` (the
/// conversion pin, active low whatever its polarity on the board) and
/// `sclk` are the levels a converting branch has in cycle `c + 1`, `cap` is
/// high iff a converting branch captures a data bit from MISO at the edge
/// that ends cycle `c`, and `done` is high in cycle `t + R - 1`.
///
/// One phase counter times both the setup (for CNV parts the conversion
/// time too) and the SCLK periods: it starts at `sclk_div - setup` modulo
/// `2^PH_BITS`, so it reaches the end of a period exactly `setup` cycles
/// after the start, however long the setup.
#[derive(LogicBlock)]
pub struct SpiSeq {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start2: Signal<In, Bit>,
    pub cs_n: Signal<Out, Bit>,
    pub sclk: Signal<Out, Bit>,
    pub cap: Signal<Out, Bit>,
    pub done: Signal<Out, Bit>,
    r_cs_n: DFF<Bit>,
    r_sclk: DFF<Bit>,
    ph: DFF<Bits<PH_BITS>>,
    nfall: DFF<Bits<NFALL_BITS>>,
    /// Index within its word of the serial bit the next rising edge reads.
    wbit: DFF<Bits<WORD_BIT_BITS>>,
    r_cap: DFF<Bit>,
    r_done: DFF<Bit>,
    wrap: Signal<Local, Bit>,
    half: Signal<Local, Bit>,
    k_ph_last: Constant<Bits<PH_BITS>>,
    k_ph_half: Constant<Bits<PH_BITS>>,
    k_ph_start: Constant<Bits<PH_BITS>>,
    k_ph_zero: Constant<Bits<PH_BITS>>,
    k_ph_one: Constant<Bits<PH_BITS>>,
    k_nf_zero: Constant<Bits<NFALL_BITS>>,
    k_nf_one: Constant<Bits<NFALL_BITS>>,
    k_nf_end: Constant<Bits<NFALL_BITS>>,
    k_wb_first: Constant<Bits<WORD_BIT_BITS>>,
    k_wb_last: Constant<Bits<WORD_BIT_BITS>>,
    k_wb_zero: Constant<Bits<WORD_BIT_BITS>>,
    k_wb_one: Constant<Bits<WORD_BIT_BITS>>,
    k_data_lo: Constant<Bits<WORD_BIT_BITS>>,
    k_data_n: Constant<Bits<WORD_BIT_BITS>>,
    /// SCLK level between conversions (CS parts high, CNV parts low).
    k_sclk_idle: Constant<Bit>,
    /// The last rising edge reads a bit (CNV parts; a CS part's last edge
    /// comes after its last bit).
    k_cap_last: Constant<Bit>,
}

impl SpiSeq {
    fn new(t: &SeqTiming) -> SpiSeq {
        let ph_mod = 1u64 << PH_BITS;
        SpiSeq {
            clock: Default::default(),
            rst: Default::default(),
            start2: Default::default(),
            cs_n: Default::default(),
            sclk: Default::default(),
            cap: Default::default(),
            done: Default::default(),
            r_cs_n: Default::default(),
            r_sclk: Default::default(),
            ph: Default::default(),
            nfall: Default::default(),
            wbit: Default::default(),
            r_cap: Default::default(),
            r_done: Default::default(),
            wrap: Default::default(),
            half: Default::default(),
            k_ph_last: c(t.sclk_div - 1),
            k_ph_half: c(t.sclk_half - 1),
            k_ph_start: c((t.sclk_div + ph_mod - t.setup_cycles) % ph_mod),
            k_ph_zero: c(0),
            k_ph_one: c(1),
            k_nf_zero: c(0),
            k_nf_one: c(1),
            k_nf_end: c(t.sclks),
            k_wb_first: c(t.first_bit()),
            k_wb_last: c(t.word_sclks - 1),
            k_wb_zero: c(0),
            k_wb_one: c(1),
            k_data_lo: c(t.leading_bits),
            k_data_n: c(t.bits),
            k_sclk_idle: Constant::new(!t.cnv),
            k_cap_last: Constant::new(t.cnv),
        }
    }
}

impl Logic for SpiSeq {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, r_cs_n, r_sclk, ph, nfall, wbit, r_cap, r_done);
        self.wrap.next = self.ph.q.val() == self.k_ph_last.val();
        self.half.next = self.ph.q.val() == self.k_ph_half.val();
        self.r_cap.d.next = false;
        self.r_done.d.next = false;
        if self.start2.val() {
            // Cycle t - 2: a converting branch's conversion pin becomes
            // active at the edge that begins t.
            self.r_cs_n.d.next = false;
            self.r_sclk.d.next = self.k_sclk_idle.val();
            self.ph.d.next = self.k_ph_start.val();
            self.nfall.d.next = self.k_nf_zero.val();
            self.wbit.d.next = self.k_wb_first.val();
        } else if !self.r_cs_n.q.val() {
            if self.wrap.val() {
                self.ph.d.next = self.k_ph_zero.val();
            } else {
                self.ph.d.next = self.ph.q.val() + self.k_ph_one.val();
            }
            if self.wrap.val() {
                if self.nfall.q.val() == self.k_nf_end.val() {
                    // Cycle t + R - 2: the pin is released (and SCLK back at
                    // idle) at the edge that begins t + R.
                    self.r_cs_n.d.next = true;
                    self.r_sclk.d.next = self.k_sclk_idle.val();
                    self.r_done.d.next = true;
                } else {
                    self.nfall.d.next = self.nfall.q.val() + self.k_nf_one.val();
                    self.r_sclk.d.next = false;
                }
            }
            if self.half.val() & (self.nfall.q.val() != self.k_nf_zero.val()) {
                // SCLK rising edge `nfall` begins the next cycle + 1: capture
                // the serial bit it reads at the end of the next cycle, if
                // that bit is a data bit.
                self.r_sclk.d.next = true;
                if self.wbit.q.val() == self.k_wb_last.val() {
                    self.wbit.d.next = self.k_wb_zero.val();
                } else {
                    self.wbit.d.next = self.wbit.q.val() + self.k_wb_one.val();
                }
                // (wbit - leading) wraps to >= 32 below the window.
                if ((self.wbit.q.val() - self.k_data_lo.val()) < self.k_data_n.val())
                    & ((self.nfall.q.val() != self.k_nf_end.val()) | self.k_cap_last.val())
                {
                    self.r_cap.d.next = true;
                }
            }
        }
        if self.rst.val() {
            // The state of cycle t - 1 for an instant t at cycle 0.
            self.r_cs_n.d.next = false;
            self.r_sclk.d.next = self.k_sclk_idle.val();
            self.ph.d.next = self.k_ph_start.val();
            self.nfall.d.next = self.k_nf_zero.val();
            self.wbit.d.next = self.k_wb_first.val();
            self.r_cap.d.next = false;
            self.r_done.d.next = false;
        }
        self.cs_n.next = self.r_cs_n.q.val();
        self.sclk.next = self.r_sclk.q.val();
        self.cap.next = self.r_cap.q.val();
        self.done.next = self.r_done.q.val();
    }
}

// ---------------------------------------------------------------------------
// Branch: per-branch SPI outputs, shift register, mux control
// ---------------------------------------------------------------------------

#[derive(LogicBlock)]
pub struct BranchUnit {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start2: Signal<In, Bit>,
    pub start1: Signal<In, Bit>,
    pub start0: Signal<In, Bit>,
    pub addr: Signal<In, Bits<SLOT_BITS>>,
    pub slice: Signal<In, Bits<SLICE_BITS>>,
    pub seq_cs_n: Signal<In, Bit>,
    pub seq_sclk: Signal<In, Bit>,
    pub seq_cap: Signal<In, Bit>,
    pub seq_done: Signal<In, Bit>,
    pub miso: Signal<In, Bit>,
    /// The merger takes this branch's word at the end of this cycle.
    pub grant: Signal<In, Bit>,
    /// The conversion pin at its board polarity (CS low or CNV high while active).
    pub cs_n: Signal<Out, Bit>,
    pub sclk: Signal<Out, Bit>,
    pub mux_sel: Signal<Out, Bits<3>>,
    pub mux_en: Signal<Out, Bits<EN_BITS>>,
    pub done: Signal<Out, Bit>,
    pub res_ch: Signal<Out, Bits<CH_BITS>>,
    pub res_val: Signal<Out, Bits<VALUE_BITS>>,
    /// More words of this conversion follow the one on `res_*`.
    pub more: Signal<Out, Bit>,
    rom: SlotRom,
    reader: WordReader,
    /// The branch converts in the slot of cycle c + 1 (cycles t - 1 ..= t + S - 2).
    act: DFF<Bit>,
    r_cs_n: DFF<Bit>,
    r_sclk: DFF<Bit>,
    /// Channel of the current slot's conversion (loaded in cycle t - 1).
    cur_ch: DFF<Bits<CH_BITS>>,
    r_sel: DFF<Bits<3>>,
    r_en: DFF<Bits<EN_BITS>>,
    r_done: DFF<Bit>,
    /// Compact LUT only: the mux field of the current slot's word (the
    /// branch's next instant after it), moved to the mux at the slot start.
    p_sel: DFF<Bits<3>>,
    p_dev: DFF<Bits<DEV_BITS>>,
    k_compact: Constant<Bit>,
    /// The conversion pin is a CNV (active high); SCLK's idle level.
    k_cnv: Constant<Bit>,
    k_sclk_idle: Constant<Bit>,
    k_sel_rst: Constant<Bits<3>>,
    k_en_rst: Constant<Bits<EN_BITS>>,
    k_en_one: Constant<Bits<EN_BITS>>,
    k_conv0: Constant<Bit>,
}

impl BranchUnit {
    fn new(rom: &BranchRom) -> BranchUnit {
        BranchUnit {
            clock: Default::default(),
            rst: Default::default(),
            start2: Default::default(),
            start1: Default::default(),
            start0: Default::default(),
            addr: Default::default(),
            slice: Default::default(),
            seq_cs_n: Default::default(),
            seq_sclk: Default::default(),
            seq_cap: Default::default(),
            seq_done: Default::default(),
            miso: Default::default(),
            grant: Default::default(),
            cs_n: Signal::new_with_default(!rom.cnv),
            sclk: Signal::new_with_default(!rom.cnv),
            mux_sel: Default::default(),
            mux_en: Default::default(),
            done: Default::default(),
            res_ch: Default::default(),
            res_val: Default::default(),
            more: Default::default(),
            rom: SlotRom::new(rom),
            reader: WordReader::new(rom),
            act: Default::default(),
            r_cs_n: Default::default(),
            r_sclk: Default::default(),
            cur_ch: Default::default(),
            r_sel: Default::default(),
            r_en: Default::default(),
            r_done: Default::default(),
            p_sel: Default::default(),
            p_dev: Default::default(),
            k_compact: Constant::new(rom.compact.is_some()),
            k_cnv: Constant::new(rom.cnv),
            k_sclk_idle: Constant::new(!rom.cnv),
            k_sel_rst: c(rom.reset_sel as u64),
            k_en_rst: c(rom.reset_en),
            k_en_one: c(1),
            k_conv0: Constant::new(rom.conv0),
        }
    }
}

impl Logic for BranchUnit {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, act, r_cs_n, r_sclk, cur_ch, r_sel, r_en, r_done, p_sel, p_dev);
        self.rom.clock.next = self.clock.val();
        self.rom.rst.next = self.rst.val();
        self.rom.address.next = self.addr.val();
        self.rom.slice.next = self.slice.val();
        if self.start2.val() {
            // Cycle t - 2: the ROM describes the slot starting at t.
            self.act.d.next = self.rom.conv.val();
        }
        if self.start1.val() {
            self.cur_ch.d.next = self.rom.ch.val();
            if self.k_compact.val() {
                self.p_sel.d.next = self.rom.msel.val();
                self.p_dev.d.next = self.rom.mdev.val();
            }
        }
        if self.start0.val() {
            if self.k_compact.val() {
                self.r_sel.d.next = self.p_sel.q.val();
                self.r_en.d.next = self.k_en_one.val() << self.p_dev.q.val();
            } else {
                // First cycle of a slot: the ROM already describes the next
                // slot, whose mux field is the channel of the branch's next
                // instant.
                self.r_sel.d.next = self.rom.msel.val();
                self.r_en.d.next = self.k_en_one.val() << self.rom.mdev.val();
            }
        }
        self.r_cs_n.d.next = self.seq_cs_n.val() | !self.act.q.val();
        if self.act.q.val() {
            self.r_sclk.d.next = self.seq_sclk.val();
        } else {
            self.r_sclk.d.next = self.k_sclk_idle.val();
        }
        // Cycle t + R - 1: the conversion completes in the next cycle.
        self.r_done.d.next = self.seq_done.val() & self.act.q.val();
        // Every slot's capture strobes shift, converting or not: the words
        // are taken by the merger before the next slot starts.
        self.reader.clock.next = self.clock.val();
        self.reader.rst.next = self.rst.val();
        self.reader.cap.next = self.seq_cap.val();
        self.reader.miso.next = self.miso.val();
        self.reader.grant.next = self.grant.val();
        self.reader.lead.next = self.cur_ch.q.val();
        if self.rst.val() {
            self.act.d.next = self.k_conv0.val();
            self.r_cs_n.d.next = true;
            self.r_sclk.d.next = self.k_sclk_idle.val();
            self.r_done.d.next = false;
            self.r_sel.d.next = self.k_sel_rst.val();
            self.r_en.d.next = self.k_en_rst.val();
        }
        self.cs_n.next = self.r_cs_n.q.val() ^ self.k_cnv.val();
        self.sclk.next = self.r_sclk.q.val();
        self.mux_sel.next = self.r_sel.q.val();
        self.mux_en.next = self.r_en.q.val();
        self.done.next = self.r_done.q.val();
        self.res_ch.next = self.reader.ch.val();
        self.res_val.next = self.reader.val.val();
        self.more.next = self.reader.more.val();
    }
}

// ---------------------------------------------------------------------------
// Word reader: the data bits of one conversion, word by word to the merger
// ---------------------------------------------------------------------------

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
    /// The conversion's lead channel (its frame-table entry).
    pub lead: Signal<In, Bits<CH_BITS>>,
    pub val: Signal<Out, Bits<VALUE_BITS>>,
    pub ch: Signal<Out, Bits<CH_BITS>>,
    pub more: Signal<Out, Bit>,
    _bits: usize,
    _chain: usize,
    _members: Vec<(u32, Vec<u32>)>,
    /// The shift register and the member of the word on `val`.
    _sh: u128,
    _om: usize,
}

impl WordReader {
    fn new(rom: &BranchRom) -> WordReader {
        WordReader {
            clock: Default::default(),
            rst: Default::default(),
            cap: Default::default(),
            miso: Default::default(),
            grant: Default::default(),
            lead: Default::default(),
            val: Default::default(),
            ch: Default::default(),
            more: Default::default(),
            _bits: rom.bits as usize,
            _chain: rom.chain as usize,
            _members: rom.members.clone(),
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
            if self.cap.val() {
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
            let _ = writeln!(s, "  if (cap) sh <= {shifted_in};");
            let _ = writeln!(s, "end\n");
            let _ = writeln!(s, "always @(*) begin");
            let _ = writeln!(s, "  val = {val};\n  ch = lead;\n  more = 1'b0;");
            let _ = writeln!(s, "end\n");
            let _ = writeln!(s, "// a single word: nothing to step through");
            let _ = writeln!(s, "wire unused_reader = |{{grant, rst}};");
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
        Verilog::Custom(s)
    }
}

// ---------------------------------------------------------------------------
// Merged sample stream
// ---------------------------------------------------------------------------

/// P(c) = pending completions plus this cycle's; the lowest branch in it
/// leaves in the next cycle (docs/timing.md, "Merged sample stream").
/// Fixed-maximum lanes (`MAX_BRANCHES`); the update is a loop and the
/// Verilog a priority chain over the mix's branches only, generated per mix,
/// so the lanes a mix does not have cost nothing.
#[derive(LogicBlock)]
pub struct Merger {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub done: Signal<In, Bits<MAX_BRANCHES>>,
    /// Lane `b` has more words of the same conversion after the one offered.
    pub more: Signal<In, Bits<MAX_BRANCHES>>,
    pub ch: [Signal<In, Bits<CH_BITS>>; MAX_BRANCHES],
    pub v: [Signal<In, Bits<VALUE_BITS>>; MAX_BRANCHES],
    /// The lane whose word is taken at the end of this cycle (one-hot).
    pub grant: Signal<Out, Bits<MAX_BRANCHES>>,
    pub valid: Signal<Out, Bit>,
    pub channel: Signal<Out, Bits<CH_BITS>>,
    pub value: Signal<Out, Bits<VALUE_BITS>>,
    r_valid: DFF<Bit>,
    r_ch: DFF<Bits<CH_BITS>>,
    r_val: DFF<Bits<VALUE_BITS>>,
    pend: DFF<Bits<MAX_BRANCHES>>,
    /// Branches of the mix (lanes `0..nb` are used).
    _nb: usize,
}

impl Merger {
    fn new(nb: usize) -> Merger {
        Merger {
            clock: Default::default(),
            rst: Default::default(),
            done: Default::default(),
            more: Default::default(),
            ch: std::array::from_fn(|_| Default::default()),
            v: std::array::from_fn(|_| Default::default()),
            grant: Default::default(),
            valid: Default::default(),
            channel: Default::default(),
            value: Default::default(),
            r_valid: Default::default(),
            r_ch: Default::default(),
            r_val: Default::default(),
            pend: Default::default(),
            _nb: nb,
        }
    }
}

impl Logic for Merger {
    fn update(&mut self) {
        dff_setup!(self, clock, r_valid, r_ch, r_val, pend);
        let p = self.pend.q.val().to_u64() | self.done.val().to_u64();
        self.r_valid.d.next = p != 0;
        self.pend.d.next = 0u64.into();
        self.grant.next = 0u64.into();
        if p != 0 {
            let b = p.trailing_zeros() as usize;
            let more = self.more.val().to_u64() & (1 << b);
            self.r_ch.d.next = self.ch[b].val();
            self.r_val.d.next = self.v[b].val();
            // A chained conversion stays pending until its last word leaves.
            self.pend.d.next = ((p & (p - 1)) | more).into();
            self.grant.next = (1u64 << b).into();
        }
        if self.rst.val() {
            self.r_valid.d.next = false;
            self.r_ch.d.next = 0u64.into();
            self.r_val.d.next = 0u64.into();
            self.pend.d.next = 0u64.into();
        }
        self.valid.next = self.r_valid.q.val();
        self.channel.next = self.r_ch.q.val();
        self.value.next = self.r_val.q.val();
    }

    fn connect(&mut self) {
        self.r_valid.clock.connect();
        self.r_valid.d.connect();
        self.r_ch.clock.connect();
        self.r_ch.d.connect();
        self.r_val.clock.connect();
        self.r_val.d.connect();
        self.pend.clock.connect();
        self.pend.d.connect();
        self.grant.connect();
        self.valid.connect();
        self.channel.connect();
        self.value.connect();
    }

    fn hdl(&self) -> Verilog {
        let nb = self._nb;
        let w = MAX_BRANCHES;
        let mut s = format!(
            "// P(c) of the mix's {nb} lanes: pending plus this cycle's completions\nwire [{}:0] p = pend$q[{0}:0] | done[{0}:0];\n\n",
            nb - 1
        );
        s.push_str("always @(*) begin\n");
        for f in ["r_valid", "r_ch", "r_val", "pend"] {
            s.push_str(&format!("  {f}$clock = clock;\n"));
        }
        s.push_str(&format!(
            "  r_valid$d = |p;\n  r_ch$d = r_ch$q;\n  r_val$d = r_val$q;\n  pend$d = {w}'h0;\n  grant = {w}'h0;\n"
        ));
        for b in 0..nb {
            let kw = if b == 0 { "if" } else { "else if" };
            let mut rest = String::new();
            if nb > 1 {
                rest = format!("p & {nb}'h{:x}", ((1u64 << nb) - 1) & !(1u64 << b));
            }
            let pend = if nb == 1 {
                format!("{w}'h0")
            } else if nb < w {
                format!("{{{}'h0, {rest}}}", w - nb)
            } else {
                rest
            };
            s.push_str(&format!(
                "  {kw} (p[{b}]) begin\n    r_ch$d = ch${b};\n    r_val$d = v${b};\n    pend$d = {pend};\n    pend$d[{b}] = more[{b}];\n    grant = {w}'h{:x};\n  end\n",
                1u64 << b
            ));
        }
        s.push_str(&format!(
            "  if (rst) begin\n    r_valid$d = 1'b0;\n    r_ch$d = {CH_BITS}'h0;\n    r_val$d = {VALUE_BITS}'h0;\n    pend$d = {w}'h0;\n  end\n"
        ));
        s.push_str("  valid = r_valid$q;\n  channel = r_ch$q;\n  value = r_val$q;\nend\n");
        let mut unused: Vec<String> = Vec::new();
        if nb < w {
            unused.push(format!("done[{}:{nb}]", w - 1));
            unused.push(format!("more[{}:{nb}]", w - 1));
            unused.push(format!("pend$q[{}:{nb}]", w - 1));
            for b in nb..w {
                unused.push(format!("ch${b}"));
                unused.push(format!("v${b}"));
            }
        }
        if !unused.is_empty() {
            s.push_str(&format!(
                "\n// lanes of branches the mix does not have (tied to zero by the core)\nwire unused_lanes = |{{{}}};\n",
                unused.join(", ")
            ));
        }
        Verilog::Custom(s)
    }
}

// ---------------------------------------------------------------------------
// Core: fixed-maximum ports, per-mix children, generated glue
// ---------------------------------------------------------------------------

#[derive(LogicBlock)]
pub struct Core {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub adc_miso: Signal<In, Bits<MAX_BRANCHES>>,
    pub adc_cs_n: Signal<Out, Bits<MAX_BRANCHES>>,
    pub adc_sclk: Signal<Out, Bits<MAX_BRANCHES>>,
    pub mux_sel: Signal<Out, Bits<{ 3 * MAX_BRANCHES }>>,
    pub mux_en: Signal<Out, Bits<EN_TOTAL>>,
    pub sample_valid: Signal<Out, Bit>,
    pub sample_channel: Signal<Out, Bits<CH_BITS>>,
    pub sample_value: Signal<Out, Bits<VALUE_BITS>>,
    pub timing: TimingGen,
    pub seqs: Vec<SpiSeq>,
    pub branches: Vec<BranchUnit>,
    pub merge: Merger,
    /// Devices per branch (the glue's per-mix parameters besides the count).
    _devices: Vec<usize>,
    /// Sequencer of each branch.
    _seq_of: Vec<usize>,
    /// The value last written to `mux_en.next` (simulation only).
    _mux_en: u128,
    /// The value last written to `mux_sel.next` (simulation only).
    _mux_sel: u64,
}

impl Core {
    pub fn new(plan: &Plan) -> Core {
        Core {
            clock: Default::default(),
            rst: Default::default(),
            adc_miso: Default::default(),
            adc_cs_n: Default::default(),
            adc_sclk: Default::default(),
            mux_sel: Default::default(),
            mux_en: Default::default(),
            sample_valid: Default::default(),
            sample_channel: Default::default(),
            sample_value: Default::default(),
            timing: TimingGen::new(plan),
            seqs: plan.seqs.iter().map(SpiSeq::new).collect(),
            branches: plan.branches.iter().map(BranchUnit::new).collect(),
            merge: Merger::new(plan.branches.len()),
            _devices: plan.branches.iter().map(|b| b.devices).collect(),
            _seq_of: plan.branches.iter().map(|b| b.seq).collect(),
            _mux_en: 0,
            _mux_sel: 0,
        }
    }
}

/// Drive one clock signal to `level` now (as its own `update_all` would).
#[inline(always)]
fn drive(sig: &mut Signal<In, Clock>, level: Clock) {
    sig.next = level;
    sig.update_all();
}

impl Core {
    /// `mux_en` as a number (the value of the `mux_en` signal).
    pub fn mux_en_u128(&self) -> u128 {
        self._mux_en
    }

    /// `mux_sel` as a number (the value of the `mux_sel` signal).
    pub fn mux_sel_u64(&self) -> u64 {
        self._mux_sel
    }

    /// Put `level` on every clock signal of the hierarchy at once: the
    /// zero-skew clock net of the emitted Verilog.
    ///
    /// rust-hdl's own propagation moves the clock one hierarchy level per
    /// evaluation pass (`Core.clock` -> `timing.clock` -> `timing.cnt.clock`),
    /// which costs three passes per clock level before any flip-flop can
    /// react. After this call the next pass sees the edge at every flip-flop
    /// and ROM together, and the per-pass copies that the blocks' own
    /// `update` (`clock!`/`dff_setup!` wiring) make are no-ops.  Only the
    /// clock moves here; data still propagates through rust-hdl's passes.
    pub fn drive_clock(&mut self, level: bool) {
        let k = Clock::from(level);
        drive(&mut self.clock, k);
        let t = &mut self.timing;
        drive(&mut t.clock, k);
        drive(&mut t.cnt.clock, k);
        drive(&mut t.st.clock, k);
        drive(&mut t.st2.clock, k);
        drive(&mut t.st0.clock, k);
        drive(&mut t.slot.clock, k);
        drive(&mut t.sl.clock, k);
        for q in self.seqs.iter_mut() {
            drive(&mut q.clock, k);
            drive(&mut q.r_cs_n.clock, k);
            drive(&mut q.r_sclk.clock, k);
            drive(&mut q.ph.clock, k);
            drive(&mut q.nfall.clock, k);
            drive(&mut q.wbit.clock, k);
            drive(&mut q.r_cap.clock, k);
            drive(&mut q.r_done.clock, k);
        }
        for u in self.branches.iter_mut() {
            drive(&mut u.clock, k);
            drive(&mut u.rom.clock, k);
            drive(&mut u.act.clock, k);
            drive(&mut u.r_cs_n.clock, k);
            drive(&mut u.r_sclk.clock, k);
            drive(&mut u.reader.clock, k);
            drive(&mut u.cur_ch.clock, k);
            drive(&mut u.r_sel.clock, k);
            drive(&mut u.r_en.clock, k);
            drive(&mut u.r_done.clock, k);
            drive(&mut u.p_sel.clock, k);
            drive(&mut u.p_dev.clock, k);
        }
        let m = &mut self.merge;
        drive(&mut m.clock, k);
        drive(&mut m.r_valid.clock, k);
        drive(&mut m.r_ch.clock, k);
        drive(&mut m.r_val.clock, k);
        drive(&mut m.pend.clock, k);
    }
}

impl Logic for Core {
    fn update(&mut self) {
        let clk = self.clock.val();
        let rst = self.rst.val();
        self.timing.clock.next = clk;
        self.timing.rst.next = rst;
        self.merge.clock.next = clk;
        self.merge.rst.next = rst;
        let start = self.timing.start2.val();
        let start1 = self.timing.start1.val();
        let start0 = self.timing.start0.val();
        let addr = self.timing.addr.val();
        let slice = self.timing.slice.val();
        let mut seq = [(false, false, false, false); MAX_BRANCHES];
        for (i, q) in self.seqs.iter_mut().enumerate() {
            q.clock.next = clk;
            q.rst.next = rst;
            q.start2.next = start;
            seq[i] = (q.cs_n.val(), q.sclk.val(), q.cap.val(), q.done.val());
        }
        let miso = self.adc_miso.val().to_u64();
        let grant = self.merge.grant.val().to_u64();
        let (mut cs, mut sclk, mut sel, mut en, mut done) = (0u64, 0u64, 0u64, 0u128, 0u64);
        let mut more = 0u64;
        let mut en_off = 0usize;
        let mut chs = [0u64; MAX_BRANCHES];
        let mut vals = [0u64; MAX_BRANCHES];
        for (b, u) in self.branches.iter_mut().enumerate() {
            u.clock.next = clk;
            u.rst.next = rst;
            u.start2.next = start;
            u.start1.next = start1;
            u.start0.next = start0;
            u.addr.next = addr;
            u.slice.next = slice;
            let (q_cs, q_sclk, q_cap, q_done) = seq[self._seq_of[b]];
            u.seq_cs_n.next = q_cs;
            u.seq_sclk.next = q_sclk;
            u.seq_cap.next = q_cap;
            u.seq_done.next = q_done;
            u.miso.next = (miso >> b) & 1 == 1;
            u.grant.next = (grant >> b) & 1 == 1;
            more |= (u.more.val() as u64) << b;
            cs |= (u.cs_n.val() as u64) << b;
            sclk |= (u.sclk.val() as u64) << b;
            sel |= u.mux_sel.val().to_u64() << (3 * b);
            let d = self._devices[b];
            let mask = if d >= 64 { u64::MAX } else { (1u64 << d) - 1 };
            en |= ((u.mux_en.val().to_u64() & mask) as u128) << en_off;
            en_off += d;
            done |= (u.done.val() as u64) << b;
            chs[b] = u.res_ch.val().to_u64();
            vals[b] = u.res_val.val().to_u64();
        }
        // Unused lanes read as all ones on CS/SCLK (idle level) in the core;
        // the wrapper only exposes the mix's branches.
        let nb = self.branches.len();
        let idle: u64 = ((1u64 << MAX_BRANCHES) - 1) & !((1u64 << nb) - 1);
        self.adc_cs_n.next = (cs | idle).into();
        self.adc_sclk.next = (sclk | idle).into();
        // `mux_sel` (48 bits) and `mux_en` (128 bits) are wider than rust-hdl's
        // short bit vectors (32 bits), so it stores them as `[bool; N]`:
        // converting them on every evaluation pass dominated the simulation,
        // so they are written only when their value changes (same signal value).
        if sel != self._mux_sel {
            self._mux_sel = sel;
            self.mux_sel.next = sel.into();
        }
        if en != self._mux_en {
            self._mux_en = en;
            self.mux_en.next = en.to_bits();
        }
        self.merge.done.next = done.into();
        self.merge.more.next = more.into();
        // Lanes >= nb keep their default 0 (the glue ties them to zero).
        let m = &mut self.merge;
        for b in 0..nb {
            m.ch[b].next = chs[b].into();
            m.v[b].next = vals[b].into();
        }
        self.sample_valid.next = self.merge.valid.val();
        self.sample_channel.next = self.merge.channel.val();
        self.sample_value.next = self.merge.value.val();
    }

    fn connect(&mut self) {
        self.timing.clock.connect();
        self.timing.rst.connect();
        self.merge.clock.connect();
        self.merge.rst.connect();
        for q in self.seqs.iter_mut() {
            q.clock.connect();
            q.rst.connect();
            q.start2.connect();
        }
        for u in self.branches.iter_mut() {
            u.clock.connect();
            u.rst.connect();
            u.start2.connect();
            u.start1.connect();
            u.start0.connect();
            u.addr.connect();
            u.slice.connect();
            u.seq_cs_n.connect();
            u.seq_sclk.connect();
            u.seq_cap.connect();
            u.seq_done.connect();
            u.miso.connect();
            u.grant.connect();
        }
        self.merge.done.connect();
        self.merge.more.connect();
        for b in 0..MAX_BRANCHES {
            self.merge.ch[b].connect();
            self.merge.v[b].connect();
        }
        self.adc_cs_n.connect();
        self.adc_sclk.connect();
        self.mux_sel.connect();
        self.mux_en.connect();
        self.sample_valid.connect();
        self.sample_channel.connect();
        self.sample_value.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(core_glue(
            self.branches.len(),
            &self._devices,
            &self._seq_of,
            self.seqs.len(),
        ))
    }
}

/// The Verilog twin of `Core::update`: pure wiring, generated per mix.
fn core_glue(nb: usize, devices: &[usize], seq_of: &[usize], nseq: usize) -> String {
    let mut s = String::new();
    let cat = |f: &dyn Fn(usize) -> String, pad: Option<String>| -> String {
        let mut parts: Vec<String> = (0..nb).rev().map(f).collect();
        if let Some(p) = pad {
            parts.insert(0, p);
        }
        format!("{{{}}}", parts.join(", "))
    };
    let pad_lanes = |v: &str| {
        if nb < MAX_BRANCHES {
            Some(format!("{{{}{{{v}}}}}", MAX_BRANCHES - nb))
        } else {
            None
        }
    };
    s.push_str("always @(*) begin\n");
    for (who, _) in [("timing", 0), ("merge", 0)] {
        s.push_str(&format!("  {who}$clock = clock;\n  {who}$rst = rst;\n"));
    }
    for i in 0..nseq {
        let q = format!("seqs${i}");
        s.push_str(&format!(
            "  {q}$clock = clock;\n  {q}$rst = rst;\n  {q}$start2 = timing$start2;\n"
        ));
    }
    for (b, seq) in seq_of.iter().enumerate().take(nb) {
        let u = format!("branches${b}");
        let q = format!("seqs${seq}");
        s.push_str(&format!(
            "  {u}$clock = clock;\n  {u}$rst = rst;\n  {u}$start2 = timing$start2;\n  {u}$start1 = timing$start1;\n  {u}$start0 = timing$start0;\n  {u}$addr = timing$addr;\n  {u}$slice = timing$slice;\n"
        ));
        s.push_str(&format!(
            "  {u}$seq_cs_n = {q}$cs_n;\n  {u}$seq_sclk = {q}$sclk;\n  {u}$seq_cap = {q}$cap;\n  {u}$seq_done = {q}$done;\n  {u}$miso = adc_miso[{b}];\n  {u}$grant = merge$grant[{b}];\n"
        ));
    }
    s.push_str(&format!(
        "  adc_cs_n = {};\n",
        cat(&|b| format!("branches${b}$cs_n"), pad_lanes("1'b1"))
    ));
    s.push_str(&format!(
        "  adc_sclk = {};\n",
        cat(&|b| format!("branches${b}$sclk"), pad_lanes("1'b1"))
    ));
    s.push_str(&format!(
        "  mux_sel = {};\n",
        cat(
            &|b| format!("branches${b}$mux_sel"),
            if nb < MAX_BRANCHES {
                Some(format!("{}'h0", 3 * (MAX_BRANCHES - nb)))
            } else {
                None
            }
        )
    ));
    let total: usize = devices.iter().sum();
    s.push_str(&format!(
        "  mux_en = {};\n",
        cat(
            &|b| format!("branches${b}$mux_en[{}:0]", devices[b] - 1),
            if total < EN_TOTAL {
                Some(format!("{}'h0", EN_TOTAL - total))
            } else {
                None
            }
        )
    ));
    s.push_str(&format!(
        "  merge$done = {};\n",
        cat(&|b| format!("branches${b}$done"), pad_lanes("1'b0"))
    ));
    s.push_str(&format!(
        "  merge$more = {};\n",
        cat(&|b| format!("branches${b}$more"), pad_lanes("1'b0"))
    ));
    for b in 0..MAX_BRANCHES {
        if b < nb {
            s.push_str(&format!(
                "  merge$ch${b} = branches${b}$res_ch;\n  merge$v${b} = branches${b}$res_val;\n"
            ));
        } else {
            s.push_str(&format!(
                "  merge$ch${b} = {CH_BITS}'h0;\n  merge$v${b} = {VALUE_BITS}'h0;\n"
            ));
        }
    }
    s.push_str(
        "  sample_valid = merge$valid;\n  sample_channel = merge$channel;\n  sample_value = merge$value;\nend\n",
    );
    let unused: Vec<String> = (0..nb)
        .filter(|&b| devices[b] < EN_BITS)
        .map(|b| format!("branches${b}$mux_en[{}:{}]", EN_BITS - 1, devices[b]))
        .collect();
    if !unused.is_empty() {
        s.push_str(&format!(
            "\n// enables of devices a branch does not have are always zero\nwire unused_mux_en = |{{{}}};\n",
            unused.join(", ")
        ));
    }
    if nb < MAX_BRANCHES {
        s.push_str(&format!(
            "// lanes of branches the mix does not have\nwire unused_miso = |adc_miso[{}:{}];\nwire unused_grant = |merge$grant[{0}:{1}];\n",
            MAX_BRANCHES - 1,
            nb
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    //! The SPI master and mux control in rust-hdl's simulator (direct clock
    //! loop with `simulate()`), against a behavioural AD7940 with the
    //! datasheet's delays expressed in nanoseconds.
    use super::*;
    use crate::plan::BranchRom;

    #[derive(LogicBlock)]
    struct Harness {
        clock: Signal<In, Clock>,
        rst: Signal<In, Bit>,
        miso: Signal<In, Bit>,
        timing: TimingGen,
        seq: SpiSeq,
        unit: BranchUnit,
    }

    impl Logic for Harness {
        #[hdl_gen]
        fn update(&mut self) {
            self.timing.clock.next = self.clock.val();
            self.timing.rst.next = self.rst.val();
            self.unit.clock.next = self.clock.val();
            self.unit.rst.next = self.rst.val();
            self.seq.clock.next = self.clock.val();
            self.seq.rst.next = self.rst.val();
            self.seq.start2.next = self.timing.start2.val();
            self.unit.start2.next = self.timing.start2.val();
            self.unit.start1.next = self.timing.start1.val();
            self.unit.start0.next = self.timing.start0.val();
            self.unit.addr.next = self.timing.addr.val();
            self.unit.slice.next = self.timing.slice.val();
            self.unit.seq_cs_n.next = self.seq.cs_n.val();
            self.unit.seq_sclk.next = self.seq.sclk.val();
            self.unit.seq_cap.next = self.seq.cap.val();
            self.unit.seq_done.next = self.seq.done.val();
            self.unit.miso.next = self.miso.val();
            self.unit.grant.next = self.unit.done.val();
        }
    }

    const CLOCK_HZ: u64 = 50_000_000; // 20 ns per cycle
    const NS: u64 = 1_000_000_000 / CLOCK_HZ;
    const SLOT: u64 = 500;

    /// 4 slots: converts channel 0 (dev 1, sel 3) in slot 0, channel 7
    /// (dev 0, sel 5) in slot 2; slots 1 and 3 idle.
    fn rom() -> BranchRom {
        let mut r = BranchRom {
            words: vec![],
            addr_bits: 2,
            ch_bits: 3,
            dev_bits: 1,
            seq: 0,
            reset_sel: 3,
            reset_en: 0b10,
            conv0: true,
            devices: 2,
            en_offset: 0,
            cnv: false,
            bits: 14,
            chain: 1,
            members: vec![],
            compact: None,
        };
        // mux fields: the first instant at this slot or later
        r.words = vec![
            r.word(true, 0, 3, 1),
            r.word(false, 0, 5, 0),
            r.word(true, 7, 5, 0),
            r.word(false, 0, 3, 1),
        ];
        r
    }

    fn harness(div: u64, setup: u64) -> Harness {
        let plan = Plan {
            link: None,
            compact: false,
            slots_per_slice: 4,
            slices_per_frame: 1,
            slot_cycles: SLOT,
            frame_slots: 4,
            channel_bits: 3,
            seqs: vec![SeqTiming {
                sclk_div: div,
                sclk_half: div / 2,
                setup_cycles: setup,
                read_cycles: setup + 16 * div,
                cnv: false,
                sclks: 16,
                word_sclks: 16,
                leading_bits: 2,
                bits: 14,
            }],
            branches: vec![rom()],
        };
        let mut h = Harness {
            clock: Default::default(),
            rst: Default::default(),
            miso: Default::default(),
            timing: TimingGen::new(&plan),
            seq: SpiSeq::new(&plan.seqs[0]),
            unit: BranchUnit::new(&plan.branches[0]),
        };
        h.connect_all();
        h
    }

    /// AD7940 serial output with datasheet timing: t3 (CS to first bit)
    /// <= 48 ns, t4 (SCLK fall to data) <= 120 ns, t7 (hold) >= 10 ns,
    /// t8 (16th fall to high-Z) <= 45 ns.  Outside valid windows it drives
    /// alternating garbage.
    struct Ad7940 {
        word: u16,
        cs_fall_ns: Option<u64>,
        falls: Vec<u64>,
        garbage: bool,
    }

    impl Ad7940 {
        fn miso(&mut self, now_ns: u64) -> bool {
            self.garbage = !self.garbage;
            let Some(cs) = self.cs_fall_ns else {
                return self.garbage;
            };
            let bit = |i: usize| (self.word >> (15 - i)) & 1 == 1;
            // most recent fall whose data is valid, and whether an older bit is held
            let n = self.falls.len();
            if n >= 16 && now_ns >= self.falls[15] + 45 {
                return self.garbage;
            }
            if n == 0 {
                return if now_ns >= cs + 48 {
                    bit(0)
                } else {
                    self.garbage
                };
            }
            let last = self.falls[n - 1];
            if now_ns >= last + 120 {
                if n < 16 {
                    bit(n)
                } else {
                    self.garbage
                }
            } else if now_ns < last + 10 {
                bit(n - 1)
            } else {
                self.garbage
            }
        }
    }

    struct Trace {
        cs_n: Vec<bool>,
        sclk: Vec<bool>,
        sel: Vec<u64>,
        en: Vec<u64>,
        done: Vec<(u64, u64, u64)>,
    }

    fn run(div: u64, setup: u64, cycles: u64, word: u16) -> Trace {
        let mut h = harness(div, setup);
        let mut adc = Ad7940 {
            word,
            cs_fall_ns: None,
            falls: vec![],
            garbage: false,
        };
        let mut t = Trace {
            cs_n: vec![],
            sclk: vec![],
            sel: vec![],
            en: vec![],
            done: vec![],
        };
        let mut miso = false;
        let mut prev = (true, true);
        for c in 0..cycles + 2 {
            let reset = c < 2;
            h.rst.next = reset;
            h.miso.next = miso;
            h.clock.next = Clock::from(false);
            assert!(simulate(&mut h, 100));
            h.clock.next = Clock::from(true);
            assert!(simulate(&mut h, 100));
            let (cs_n, sclk) = (h.unit.cs_n.val(), h.unit.sclk.val());
            if reset {
                assert!(cs_n && sclk);
                assert_eq!(h.unit.mux_en.val().to_u64(), 0b10);
                continue;
            }
            let cyc = c - 2;
            let now = cyc * NS;
            if prev.0 && !cs_n {
                adc.cs_fall_ns = Some(now);
                adc.falls.clear();
            }
            if cs_n {
                adc.cs_fall_ns = None;
            }
            if !cs_n && prev.1 && !sclk {
                adc.falls.push(now);
            }
            // MISO is sampled at the end of this cycle: the worst case is
            // its value just before the next edge.
            miso = adc.miso(now + NS - 1);
            prev = (cs_n, sclk);
            t.cs_n.push(cs_n);
            t.sclk.push(sclk);
            t.sel.push(h.unit.mux_sel.val().to_u64());
            t.en.push(h.unit.mux_en.val().to_u64());
            if h.unit.done.val() {
                t.done.push((
                    cyc,
                    h.unit.res_ch.val().to_u64(),
                    h.unit.res_val.val().to_u64(),
                ));
            }
        }
        t
    }

    fn check_spi(div: u64, setup: u64) {
        let r = setup + 16 * div;
        let word = 0x2d5b & 0x3fff;
        let t = run(div, setup, 4 * SLOT, word);
        for (k, &inst) in [0u64, 2 * SLOT].iter().enumerate() {
            // CS low exactly for R cycles from the instant
            assert!(inst == 0 || t.cs_n[inst as usize - 1]);
            for c in inst..inst + r {
                assert!(!t.cs_n[c as usize], "cs_n low in cycle {c}");
            }
            assert!(t.cs_n[(inst + r) as usize]);
            // SCLK: idle high, 16 falling edges, exact phase, CS-to-SCLK setup
            let falls: Vec<u64> = (inst + 1..inst + r + 1)
                .filter(|&c| t.sclk[c as usize - 1] && !t.sclk[c as usize])
                .collect();
            assert_eq!(falls.len(), 16);
            assert!(falls[0] - inst >= 1 && (falls[0] - inst) * NS >= 10, "t2");
            for (i, &f) in falls.iter().enumerate() {
                assert_eq!(f, inst + setup + i as u64 * div);
                for c in f..f + div / 2 {
                    assert!(!t.sclk[c as usize]);
                }
                for c in f + div / 2..f + div {
                    assert!(t.sclk[c as usize]);
                }
            }
            // the 14-bit code was captured despite worst-case delays
            let (done_at, ch, val) = t.done[k];
            assert_eq!(done_at, inst + r);
            assert_eq!(ch, [0, 7][k]);
            assert_eq!(val, word as u64);
        }
        // mux: reset value until instant 0, next channel from t+1, stable
        // through the next instant; one device at a time
        assert_eq!((t.sel[0], t.en[0]), (3, 0b10));
        for c in 1..2 * SLOT + 1 {
            assert_eq!(
                (t.sel[c as usize], t.en[c as usize]),
                (5, 0b01),
                "cycle {c}"
            );
        }
        for c in 2 * SLOT + 1..4 * SLOT {
            assert_eq!(
                (t.sel[c as usize], t.en[c as usize]),
                (3, 0b10),
                "cycle {c}"
            );
        }
        assert!(t.en.iter().all(|e| e.count_ones() == 1));
    }

    #[test]
    fn spi_master_reads_ad7940_at_2_5_mhz() {
        check_spi(20, 1); // 50 MHz / 20 = 2.5 MHz, 200 ns low phase > t4
    }

    #[test]
    fn spi_master_with_long_setup_and_slow_sclk() {
        // setup longer than half a period; R = 404 of the 500-cycle slot
        check_spi(24, 20);
    }
}
