//! The gateware itself, described with rust-hdl (private to this crate).
//!
//! Hierarchy (every sequential element sits at depth 2, so that in rust-hdl's
//! simulator every flip-flop sees the clock edge in the same pass):
//!
//! ```text
//! Core                    fixed-maximum ports (8 branches, 64 mux enables, 8-bit channel)
//!  |- timing: TimingGen   cycle-in-slot counter, slot-in-frame counter, slot-start strobe
//!  |- branches: Vec<BranchUnit>, one per branch of the mix
//!  |    |- rom: SlotRom   that branch's column of the frame table (BRAM-friendly)
//!  |    `- DFFs           CS/SCLK/MISO SPI master and mux control
//!  `- merge: Merger       8-lane pending set + lowest-branch-first sample stream
//! ```
//!
//! No literal appears in a kernel: every number is a sized `Constant`, so the
//! emitted Verilog has no 32-bit literals and lints clean.

use rust_hdl::prelude::*;

use crate::plan::{BranchRom, Plan, MAX_BRANCHES};

/// Width of the cycle-in-slot counter.
pub const CNT_BITS: usize = 16;
/// Width of the slot-in-frame counter (ROM address).
pub const SLOT_BITS: usize = 12;
/// Width of the SCLK phase counter.
pub const PH_BITS: usize = 10;
/// Width of a channel index.
pub const CH_BITS: usize = 8;
/// Width of a device index inside a branch.
pub const DEV_BITS: usize = 5;
/// Per-branch mux enables (one-hot over at most 32 devices).
pub const EN_BITS: usize = 32;
/// Total mux enables on the core.
pub const EN_TOTAL: usize = 64;
/// Width of a ROM word: conv(1) ch(8) next_sel(3) next_dev(5).
pub const WORD_BITS: usize = 17;

fn c<const N: usize>(v: u64) -> Constant<Bits<N>> {
    Constant::new(Bits::<N>::from(v))
}

// ---------------------------------------------------------------------------
// Slot ROM
// ---------------------------------------------------------------------------

/// One branch's column of the frame table, read synchronously (one cycle of
/// latency) so that synthesis maps it to block RAM.  Custom Verilog so the
/// memory is declared with the exact depth of the frame.
#[derive(LogicBlock)]
pub struct SlotRom {
    pub clock: Signal<In, Clock>,
    pub address: Signal<In, Bits<SLOT_BITS>>,
    pub conv: Signal<Out, Bit>,
    pub ch: Signal<Out, Bits<CH_BITS>>,
    pub nsel: Signal<Out, Bits<3>>,
    pub ndev: Signal<Out, Bits<DEV_BITS>>,
    _words: Vec<u32>,
    _addr_bits: usize,
}

impl SlotRom {
    fn new(rom: &BranchRom) -> SlotRom {
        SlotRom {
            clock: Default::default(),
            address: Default::default(),
            conv: Default::default(),
            ch: Default::default(),
            nsel: Default::default(),
            ndev: Default::default(),
            _words: rom.words.clone(),
            _addr_bits: rom.addr_bits,
        }
    }
}

impl Logic for SlotRom {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let a = self.address.val().to_u64() as usize;
            let w = self._words.get(a).copied().unwrap_or(0) as u64;
            self.conv.next = (w >> 16) & 1 == 1;
            self.ch.next = ((w >> 8) & 0xff).into();
            self.nsel.next = ((w >> 5) & 0x7).into();
            self.ndev.next = (w & 0x1f).into();
        }
    }

    fn connect(&mut self) {
        self.conv.connect();
        self.ch.connect();
        self.nsel.connect();
        self.ndev.connect();
    }

    fn hdl(&self) -> Verilog {
        let aw = self._addr_bits;
        let depth = 1usize << aw;
        let mut s = String::new();
        s.push_str(&format!(
            "reg [{}:0] mem [0:{}];\nreg [{}:0] q;\n\ninitial begin\n",
            WORD_BITS - 1,
            depth - 1,
            WORD_BITS - 1
        ));
        for a in 0..depth {
            let w = self._words.get(a).copied().unwrap_or(0);
            s.push_str(&format!("  mem[{a}] = {WORD_BITS}'h{w:05x};\n"));
        }
        s.push_str("end\n\n");
        s.push_str(&format!(
            "always @(posedge clock) begin\n  q <= mem[address[{}:0]];\nend\n\n",
            aw - 1
        ));
        s.push_str(
            "always @(*) begin\n  conv = q[16];\n  ch = q[15:8];\n  nsel = q[7:5];\n  ndev = q[4:0];\nend\n",
        );
        if aw < SLOT_BITS {
            s.push_str(&format!(
                "\n// address bits above the frame depth are always zero\nwire unused_address_hi = |address[{}:{}];\n",
                SLOT_BITS - 1,
                aw
            ));
        }
        Verilog::Custom(s)
    }
}

// ---------------------------------------------------------------------------
// Timing generator
// ---------------------------------------------------------------------------

/// Runs one cycle ahead of the outputs: `start1` is high in cycle `c` iff
/// cycle `c + 1` is the first cycle of a slot; `addr` is the (combinational)
/// next value of the slot pointer, so the ROMs' registered data always
/// describe the next slot to start.
#[derive(LogicBlock)]
pub struct TimingGen {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start1: Signal<Out, Bit>,
    pub addr: Signal<Out, Bits<SLOT_BITS>>,
    /// (c + 2) mod slot_cycles during cycle c.
    cnt: DFF<Bits<CNT_BITS>>,
    st: DFF<Bit>,
    /// Frame slot index of the next slot start (> c).
    slot: DFF<Bits<SLOT_BITS>>,
    nxt: Signal<Local, Bits<SLOT_BITS>>,
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
            start1: Default::default(),
            addr: Default::default(),
            cnt: Default::default(),
            st: Default::default(),
            slot: Default::default(),
            nxt: Default::default(),
            k_cnt_last: c(plan.slot_cycles - 1),
            k_cnt_rst: c(1 % plan.slot_cycles),
            k_cnt_zero: c(0),
            k_cnt_one: c(1),
            k_slot_last: c(plan.frame_slots - 1),
            k_slot_zero: c(0),
            k_slot_one: c(1),
        }
    }
}

impl Logic for TimingGen {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, cnt, st, slot);
        if self.cnt.q.val() == self.k_cnt_last.val() {
            self.cnt.d.next = self.k_cnt_zero.val();
        } else {
            self.cnt.d.next = self.cnt.q.val() + self.k_cnt_one.val();
        }
        self.st.d.next = self.cnt.q.val() == self.k_cnt_zero.val();
        self.nxt.next = self.slot.q.val();
        if self.st.q.val() {
            if self.slot.q.val() == self.k_slot_last.val() {
                self.nxt.next = self.k_slot_zero.val();
            } else {
                self.nxt.next = self.slot.q.val() + self.k_slot_one.val();
            }
        }
        if self.rst.val() {
            self.cnt.d.next = self.k_cnt_rst.val();
            self.st.d.next = true;
            self.nxt.next = self.k_slot_zero.val();
        }
        self.slot.d.next = self.nxt.val();
        self.addr.next = self.nxt.val();
        self.start1.next = self.st.q.val();
    }
}

// ---------------------------------------------------------------------------
// Branch: SPI master + mux control
// ---------------------------------------------------------------------------

#[derive(LogicBlock)]
pub struct BranchUnit {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start: Signal<In, Bit>,
    pub addr: Signal<In, Bits<SLOT_BITS>>,
    pub miso: Signal<In, Bit>,
    pub cs_n: Signal<Out, Bit>,
    pub sclk: Signal<Out, Bit>,
    pub mux_sel: Signal<Out, Bits<3>>,
    pub mux_en: Signal<Out, Bits<EN_BITS>>,
    pub done: Signal<Out, Bit>,
    pub res_ch: Signal<Out, Bits<CH_BITS>>,
    pub res_val: Signal<Out, Bits<14>>,
    rom: SlotRom,
    r_cs_n: DFF<Bit>,
    r_sclk: DFF<Bit>,
    ph: DFF<Bits<PH_BITS>>,
    nfall: DFF<Bits<5>>,
    shift: DFF<Bits<14>>,
    cur_ch: DFF<Bits<CH_BITS>>,
    first: DFF<Bit>,
    p_sel: DFF<Bits<3>>,
    p_dev: DFF<Bits<DEV_BITS>>,
    r_sel: DFF<Bits<3>>,
    r_en: DFF<Bits<EN_BITS>>,
    r_done: DFF<Bit>,
    r_rch: DFF<Bits<CH_BITS>>,
    r_rval: DFF<Bits<14>>,
    wrap: Signal<Local, Bit>,
    half: Signal<Local, Bit>,
    k_ph_last: Constant<Bits<PH_BITS>>,
    k_ph_half: Constant<Bits<PH_BITS>>,
    k_ph_start: Constant<Bits<PH_BITS>>,
    k_ph_zero: Constant<Bits<PH_BITS>>,
    k_ph_one: Constant<Bits<PH_BITS>>,
    k_nf_zero: Constant<Bits<5>>,
    k_nf_one: Constant<Bits<5>>,
    k_nf_end: Constant<Bits<5>>,
    k_sh_one: Constant<Bits<4>>,
    k_sh_lsb: Constant<Bits<14>>,
    k_val_zero: Constant<Bits<14>>,
    k_ch_zero: Constant<Bits<CH_BITS>>,
    k_sel_rst: Constant<Bits<3>>,
    k_en_rst: Constant<Bits<EN_BITS>>,
    k_en_one: Constant<Bits<EN_BITS>>,
}

impl BranchUnit {
    fn new(rom: &BranchRom) -> BranchUnit {
        BranchUnit {
            clock: Default::default(),
            rst: Default::default(),
            start: Default::default(),
            addr: Default::default(),
            miso: Default::default(),
            cs_n: Signal::new_with_default(true),
            sclk: Signal::new_with_default(true),
            mux_sel: Default::default(),
            mux_en: Default::default(),
            done: Default::default(),
            res_ch: Default::default(),
            res_val: Default::default(),
            rom: SlotRom::new(rom),
            r_cs_n: Default::default(),
            r_sclk: Default::default(),
            ph: Default::default(),
            nfall: Default::default(),
            shift: Default::default(),
            cur_ch: Default::default(),
            first: Default::default(),
            p_sel: Default::default(),
            p_dev: Default::default(),
            r_sel: Default::default(),
            r_en: Default::default(),
            r_done: Default::default(),
            r_rch: Default::default(),
            r_rval: Default::default(),
            wrap: Default::default(),
            half: Default::default(),
            k_ph_last: c(rom.sclk_div - 1),
            k_ph_half: c(rom.sclk_half - 1),
            k_ph_start: c(rom.sclk_div - rom.setup_cycles),
            k_ph_zero: c(0),
            k_ph_one: c(1),
            k_nf_zero: c(0),
            k_nf_one: c(1),
            k_nf_end: c(16),
            k_sh_one: c(1),
            k_sh_lsb: c(1),
            k_val_zero: c(0),
            k_ch_zero: c(0),
            k_sel_rst: c(rom.reset_sel as u64),
            k_en_rst: c(rom.reset_en),
            k_en_one: c(1),
        }
    }
}

impl Logic for BranchUnit {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, r_cs_n, r_sclk, ph, nfall, shift, cur_ch, first, p_sel, p_dev, r_sel,
            r_en, r_done, r_rch, r_rval
        );
        self.rom.clock.next = self.clock.val();
        self.rom.address.next = self.addr.val();
        self.wrap.next = self.ph.q.val() == self.k_ph_last.val();
        self.half.next = self.ph.q.val() == self.k_ph_half.val();
        self.r_done.d.next = false;
        self.first.d.next = false;
        if self.start.val() & self.rom.conv.val() {
            // The edge that begins sampling instant t: CS falls.
            self.r_cs_n.d.next = false;
            self.r_sclk.d.next = true;
            self.ph.d.next = self.k_ph_start.val();
            self.nfall.d.next = self.k_nf_zero.val();
            self.cur_ch.d.next = self.rom.ch.val();
            self.p_sel.d.next = self.rom.nsel.val();
            self.p_dev.d.next = self.rom.ndev.val();
            self.first.d.next = true;
        } else if !self.r_cs_n.q.val() {
            if self.wrap.val() {
                self.ph.d.next = self.k_ph_zero.val();
            } else {
                self.ph.d.next = self.ph.q.val() + self.k_ph_one.val();
            }
            if self.first.q.val() {
                // Cycle t + 1: switch the mux to the branch's next channel.
                self.r_sel.d.next = self.p_sel.q.val();
                self.r_en.d.next = self.k_en_one.val() << self.p_dev.q.val();
            }
            if self.wrap.val() {
                if self.nfall.q.val() == self.k_nf_end.val() {
                    // Cycle t + R: CS rises, the conversion is complete.
                    self.r_cs_n.d.next = true;
                    self.r_done.d.next = true;
                    self.r_rch.d.next = self.cur_ch.q.val();
                    self.r_rval.d.next = self.shift.q.val();
                } else {
                    self.nfall.d.next = self.nfall.q.val() + self.k_nf_one.val();
                    self.r_sclk.d.next = false;
                }
            }
            if self.half.val() {
                self.r_sclk.d.next = true;
                if (self.nfall.q.val() != self.k_nf_zero.val())
                    & (self.nfall.q.val() != self.k_nf_end.val())
                {
                    // SCLK rising edge i (1..=15): capture serial bit i.
                    if self.miso.val() {
                        self.shift.d.next =
                            (self.shift.q.val() << self.k_sh_one.val()) | self.k_sh_lsb.val();
                    } else {
                        self.shift.d.next = self.shift.q.val() << self.k_sh_one.val();
                    }
                }
            }
        }
        if self.rst.val() {
            self.r_cs_n.d.next = true;
            self.r_sclk.d.next = true;
            self.r_done.d.next = false;
            self.first.d.next = false;
            self.nfall.d.next = self.k_nf_zero.val();
            self.r_rch.d.next = self.k_ch_zero.val();
            self.r_rval.d.next = self.k_val_zero.val();
            self.r_sel.d.next = self.k_sel_rst.val();
            self.r_en.d.next = self.k_en_rst.val();
        }
        self.cs_n.next = self.r_cs_n.q.val();
        self.sclk.next = self.r_sclk.q.val();
        self.mux_sel.next = self.r_sel.q.val();
        self.mux_en.next = self.r_en.q.val();
        self.done.next = self.r_done.q.val();
        self.res_ch.next = self.r_rch.q.val();
        self.res_val.next = self.r_rval.q.val();
    }
}

// ---------------------------------------------------------------------------
// Merged sample stream
// ---------------------------------------------------------------------------

#[derive(LogicBlock)]
pub struct Merger {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub done: Signal<In, Bits<MAX_BRANCHES>>,
    pub ch0: Signal<In, Bits<CH_BITS>>,
    pub ch1: Signal<In, Bits<CH_BITS>>,
    pub ch2: Signal<In, Bits<CH_BITS>>,
    pub ch3: Signal<In, Bits<CH_BITS>>,
    pub ch4: Signal<In, Bits<CH_BITS>>,
    pub ch5: Signal<In, Bits<CH_BITS>>,
    pub ch6: Signal<In, Bits<CH_BITS>>,
    pub ch7: Signal<In, Bits<CH_BITS>>,
    pub v0: Signal<In, Bits<14>>,
    pub v1: Signal<In, Bits<14>>,
    pub v2: Signal<In, Bits<14>>,
    pub v3: Signal<In, Bits<14>>,
    pub v4: Signal<In, Bits<14>>,
    pub v5: Signal<In, Bits<14>>,
    pub v6: Signal<In, Bits<14>>,
    pub v7: Signal<In, Bits<14>>,
    pub valid: Signal<Out, Bit>,
    pub channel: Signal<Out, Bits<CH_BITS>>,
    pub value: Signal<Out, Bits<14>>,
    r_valid: DFF<Bit>,
    r_ch: DFF<Bits<CH_BITS>>,
    r_val: DFF<Bits<14>>,
    pend: DFF<Bits<MAX_BRANCHES>>,
    p: Signal<Local, Bits<MAX_BRANCHES>>,
    k_m0: Constant<Bits<MAX_BRANCHES>>,
    k_m1: Constant<Bits<MAX_BRANCHES>>,
    k_m2: Constant<Bits<MAX_BRANCHES>>,
    k_m3: Constant<Bits<MAX_BRANCHES>>,
    k_m4: Constant<Bits<MAX_BRANCHES>>,
    k_m5: Constant<Bits<MAX_BRANCHES>>,
    k_m6: Constant<Bits<MAX_BRANCHES>>,
    k_m7: Constant<Bits<MAX_BRANCHES>>,
    k_zero: Constant<Bits<MAX_BRANCHES>>,
    k_ch_zero: Constant<Bits<CH_BITS>>,
    k_val_zero: Constant<Bits<14>>,
}

impl Default for Merger {
    fn default() -> Merger {
        let m = |b: u64| c::<MAX_BRANCHES>(0xff & !(1u64 << b));
        Merger {
            clock: Default::default(),
            rst: Default::default(),
            done: Default::default(),
            ch0: Default::default(),
            ch1: Default::default(),
            ch2: Default::default(),
            ch3: Default::default(),
            ch4: Default::default(),
            ch5: Default::default(),
            ch6: Default::default(),
            ch7: Default::default(),
            v0: Default::default(),
            v1: Default::default(),
            v2: Default::default(),
            v3: Default::default(),
            v4: Default::default(),
            v5: Default::default(),
            v6: Default::default(),
            v7: Default::default(),
            valid: Default::default(),
            channel: Default::default(),
            value: Default::default(),
            r_valid: Default::default(),
            r_ch: Default::default(),
            r_val: Default::default(),
            pend: Default::default(),
            p: Default::default(),
            k_m0: m(0),
            k_m1: m(1),
            k_m2: m(2),
            k_m3: m(3),
            k_m4: m(4),
            k_m5: m(5),
            k_m6: m(6),
            k_m7: m(7),
            k_zero: c(0),
            k_ch_zero: c(0),
            k_val_zero: c(0),
        }
    }
}

impl Logic for Merger {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, r_valid, r_ch, r_val, pend);
        // P(c): pending completions plus those of this cycle.
        self.p.next = self.pend.q.val() | self.done.val();
        self.r_valid.d.next = self.p.val().any();
        self.pend.d.next = self.k_zero.val();
        if self.p.val().get_bit(0) {
            self.r_ch.d.next = self.ch0.val();
            self.r_val.d.next = self.v0.val();
            self.pend.d.next = self.p.val() & self.k_m0.val();
        } else if self.p.val().get_bit(1) {
            self.r_ch.d.next = self.ch1.val();
            self.r_val.d.next = self.v1.val();
            self.pend.d.next = self.p.val() & self.k_m1.val();
        } else if self.p.val().get_bit(2) {
            self.r_ch.d.next = self.ch2.val();
            self.r_val.d.next = self.v2.val();
            self.pend.d.next = self.p.val() & self.k_m2.val();
        } else if self.p.val().get_bit(3) {
            self.r_ch.d.next = self.ch3.val();
            self.r_val.d.next = self.v3.val();
            self.pend.d.next = self.p.val() & self.k_m3.val();
        } else if self.p.val().get_bit(4) {
            self.r_ch.d.next = self.ch4.val();
            self.r_val.d.next = self.v4.val();
            self.pend.d.next = self.p.val() & self.k_m4.val();
        } else if self.p.val().get_bit(5) {
            self.r_ch.d.next = self.ch5.val();
            self.r_val.d.next = self.v5.val();
            self.pend.d.next = self.p.val() & self.k_m5.val();
        } else if self.p.val().get_bit(6) {
            self.r_ch.d.next = self.ch6.val();
            self.r_val.d.next = self.v6.val();
            self.pend.d.next = self.p.val() & self.k_m6.val();
        } else if self.p.val().get_bit(7) {
            self.r_ch.d.next = self.ch7.val();
            self.r_val.d.next = self.v7.val();
            self.pend.d.next = self.p.val() & self.k_m7.val();
        }
        if self.rst.val() {
            self.r_valid.d.next = false;
            self.r_ch.d.next = self.k_ch_zero.val();
            self.r_val.d.next = self.k_val_zero.val();
            self.pend.d.next = self.k_zero.val();
        }
        self.valid.next = self.r_valid.q.val();
        self.channel.next = self.r_ch.q.val();
        self.value.next = self.r_val.q.val();
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
    pub sample_value: Signal<Out, Bits<14>>,
    pub timing: TimingGen,
    pub branches: Vec<BranchUnit>,
    pub merge: Merger,
    /// Devices per branch (the glue's only per-mix parameter besides the count).
    _devices: Vec<usize>,
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
            branches: plan.branches.iter().map(BranchUnit::new).collect(),
            merge: Merger::default(),
            _devices: plan.branches.iter().map(|b| b.devices).collect(),
        }
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
        let start = self.timing.start1.val();
        let addr = self.timing.addr.val();
        let miso = self.adc_miso.val().to_u64();
        let (mut cs, mut sclk, mut sel, mut en, mut done) = (0u64, 0u64, 0u64, 0u128, 0u64);
        let mut en_off = 0usize;
        let mut chs = [0u64; MAX_BRANCHES];
        let mut vals = [0u64; MAX_BRANCHES];
        for (b, u) in self.branches.iter_mut().enumerate() {
            u.clock.next = clk;
            u.rst.next = rst;
            u.start.next = start;
            u.addr.next = addr;
            u.miso.next = (miso >> b) & 1 == 1;
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
        let idle: u64 = if nb >= MAX_BRANCHES {
            0
        } else {
            (0xffu64 >> nb) << nb
        };
        self.adc_cs_n.next = (cs | idle).into();
        self.adc_sclk.next = (sclk | idle).into();
        self.mux_sel.next = sel.into();
        self.mux_en.next = (en as u64).into();
        self.merge.done.next = done.into();
        self.merge.ch0.next = chs[0].into();
        self.merge.ch1.next = chs[1].into();
        self.merge.ch2.next = chs[2].into();
        self.merge.ch3.next = chs[3].into();
        self.merge.ch4.next = chs[4].into();
        self.merge.ch5.next = chs[5].into();
        self.merge.ch6.next = chs[6].into();
        self.merge.ch7.next = chs[7].into();
        self.merge.v0.next = vals[0].into();
        self.merge.v1.next = vals[1].into();
        self.merge.v2.next = vals[2].into();
        self.merge.v3.next = vals[3].into();
        self.merge.v4.next = vals[4].into();
        self.merge.v5.next = vals[5].into();
        self.merge.v6.next = vals[6].into();
        self.merge.v7.next = vals[7].into();
        self.sample_valid.next = self.merge.valid.val();
        self.sample_channel.next = self.merge.channel.val();
        self.sample_value.next = self.merge.value.val();
    }

    fn connect(&mut self) {
        self.timing.clock.connect();
        self.timing.rst.connect();
        self.merge.clock.connect();
        self.merge.rst.connect();
        for u in self.branches.iter_mut() {
            u.clock.connect();
            u.rst.connect();
            u.start.connect();
            u.addr.connect();
            u.miso.connect();
        }
        self.merge.done.connect();
        self.merge.ch0.connect();
        self.merge.ch1.connect();
        self.merge.ch2.connect();
        self.merge.ch3.connect();
        self.merge.ch4.connect();
        self.merge.ch5.connect();
        self.merge.ch6.connect();
        self.merge.ch7.connect();
        self.merge.v0.connect();
        self.merge.v1.connect();
        self.merge.v2.connect();
        self.merge.v3.connect();
        self.merge.v4.connect();
        self.merge.v5.connect();
        self.merge.v6.connect();
        self.merge.v7.connect();
        self.adc_cs_n.connect();
        self.adc_sclk.connect();
        self.mux_sel.connect();
        self.mux_en.connect();
        self.sample_valid.connect();
        self.sample_channel.connect();
        self.sample_value.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(core_glue(self.branches.len(), &self._devices))
    }
}

/// The Verilog twin of `Core::update`: pure wiring, generated per mix.
fn core_glue(nb: usize, devices: &[usize]) -> String {
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
    for b in 0..nb {
        let u = format!("branches${b}");
        s.push_str(&format!(
            "  {u}$clock = clock;\n  {u}$rst = rst;\n  {u}$start = timing$start1;\n  {u}$addr = timing$addr;\n  {u}$miso = adc_miso[{b}];\n"
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
    for b in 0..MAX_BRANCHES {
        if b < nb {
            s.push_str(&format!(
                "  merge$ch{b} = branches${b}$res_ch;\n  merge$v{b} = branches${b}$res_val;\n"
            ));
        } else {
            s.push_str(&format!(
                "  merge$ch{b} = {CH_BITS}'h0;\n  merge$v{b} = 14'h0;\n"
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
            "// lanes of branches the mix does not have\nwire unused_miso = |adc_miso[{}:{}];\n",
            MAX_BRANCHES - 1,
            nb
        ));
    }
    s
}
