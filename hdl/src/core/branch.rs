//! Branch: per-branch SPI outputs, shift register, mux control.

use crate::rhdl::*;

use super::{c, SlotRom, WordReader};
use crate::plan::BranchRom;
use crate::widths::*;

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
    /// The merger's queue form: its registered enables (`Merger::sh_en`,
    /// `ch_en`): the shift register loads (MISO if `seq_cap`, else the next
    /// lane's word `q_val`), the channel loads (the ROM's if `start1`,
    /// else the next lane's `q_ch`) at the end of this cycle. Tied low in
    /// the priority form.
    pub sh_en: Signal<In, Bit>,
    pub ch_en: Signal<In, Bit>,
    pub q_ch: Signal<In, Bits<CH_BITS>>,
    pub q_val: Signal<In, Bits<VALUE_BITS>>,
    /// The conversion pin at its board polarity (CS low or CNV high while active).
    pub cs_n: Signal<Out, Bit>,
    pub sclk: Signal<Out, Bit>,
    pub mux_sel: Signal<Out, Bits<3>>,
    pub mux_en: Signal<Out, Bits<EN_BITS>>,
    pub done: Signal<Out, Bit>,
    /// `done` of the next cycle (the D input of its flip-flop), for the
    /// merger's registered "anything to take" flag.
    pub done_next: Signal<Out, Bit>,
    pub res_ch: Signal<Out, Bits<CH_BITS>>,
    pub res_val: Signal<Out, Bits<VALUE_BITS>>,
    /// More words of this conversion follow the one on `res_*`.
    pub more: Signal<Out, Bit>,
    /// The branch converts in the slot of the next cycle (the queue form's
    /// MISO routing reads it).
    pub act_q: Signal<Out, Bit>,
    pub(super) rom: SlotRom,
    pub(super) reader: WordReader,
    /// The branch converts in the slot of cycle c + 1 (cycles t - 1 ..= t + S - 2).
    pub(super) act: DFF<Bit>,
    pub(super) r_cs_n: DFF<Bit>,
    pub(super) r_sclk: DFF<Bit>,
    /// Channel of the current slot's conversion (loaded in cycle t - 1).
    pub(super) cur_ch: DFF<Bits<CH_BITS>>,
    pub(super) r_sel: DFF<Bits<3>>,
    pub(super) r_en: DFF<Bits<EN_BITS>>,
    pub(super) r_done: DFF<Bit>,
    /// Compact LUT only: the mux field of the current slot's word (the
    /// branch's next instant after it), moved to the mux at the slot start.
    pub(super) p_sel: DFF<Bits<3>>,
    pub(super) p_dev: DFF<Bits<DEV_BITS>>,
    k_compact: Constant<Bit>,
    /// The merger's queue form.
    k_queue: Constant<Bit>,
    /// The conversion pin is a CNV (active high); SCLK's idle level.
    k_cnv: Constant<Bit>,
    k_sclk_idle: Constant<Bit>,
    k_sel_rst: Constant<Bits<3>>,
    k_en_rst: Constant<Bits<EN_BITS>>,
    k_en_one: Constant<Bits<EN_BITS>>,
    k_conv0: Constant<Bit>,
}

impl BranchUnit {
    pub(super) fn new(rom: &BranchRom, queue: bool, step: bool) -> BranchUnit {
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
            sh_en: Default::default(),
            ch_en: Default::default(),
            q_ch: Default::default(),
            q_val: Default::default(),
            cs_n: Signal::new_with_default(!rom.cnv),
            sclk: Signal::new_with_default(!rom.cnv),
            mux_sel: Default::default(),
            mux_en: Default::default(),
            done: Default::default(),
            done_next: Default::default(),
            res_ch: Default::default(),
            res_val: Default::default(),
            more: Default::default(),
            act_q: Default::default(),
            rom: SlotRom::new(rom),
            reader: WordReader::new(rom, queue, step),
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
            k_queue: Constant::new(queue),
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
        if self.k_queue.val() {
            // the lane above's channel moves up, or the slot's is loaded,
            // under one registered enable
            if self.ch_en.val() {
                if self.start1.val() {
                    self.cur_ch.d.next = self.rom.ch.val();
                } else {
                    self.cur_ch.d.next = self.q_ch.val();
                }
            }
        } else if self.start1.val() {
            self.cur_ch.d.next = self.rom.ch.val();
        }
        if self.start1.val() & self.k_compact.val() {
            self.p_sel.d.next = self.rom.msel.val();
            self.p_dev.d.next = self.rom.mdev.val();
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
        self.reader.en.next = self.sh_en.val();
        self.reader.q_in.next = self.q_val.val();
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
        self.done_next.next = self.seq_done.val() & self.act.q.val() & !self.rst.val();
        self.res_ch.next = self.reader.ch.val();
        self.res_val.next = self.reader.val.val();
        self.more.next = self.reader.more.val();
        self.act_q.next = self.act.q.val();
    }
}
