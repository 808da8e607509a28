//! Timing generator.

use crate::rhdl::*;

use super::c;
use crate::plan::Plan;
use crate::widths::*;

/// Runs ahead of the outputs: `start2` (`start1`, `start0`) is high in cycle
/// `c` iff cycle `c + 2` (`c + 1`, `c`) is the first cycle of a slot; `addr`
/// is the (combinational) next value of the slot pointer, so the ROMs'
/// registered data describe slot `u` from the second cycle of slot `u - 1`
/// through its last, and slot `u + 1` in the first cycle of slot `u`.
///
/// Lean in synthesis: the counters are declared at the core's
/// maximum widths (rust-hdl fixes widths when the crate compiles), but every
/// increment is masked to the mix's own width (`k_*_mask`), so the bits
/// above it have a constant-zero D input and yosys removes them with their
/// carry and compare logic. The ROM address is a one-LUT multiplexer of two
/// registers (`slot`, `succ` = the slot after it) rather than the slot's
/// compare-and-increment, which was the core's critical path into the
/// block RAMs' address pins.
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
    pub(super) cnt: DFF<Bits<CNT_BITS>>,
    pub(super) st: DFF<Bit>,
    pub(super) st2: DFF<Bit>,
    pub(super) st0: DFF<Bit>,
    /// Index of the next slot start (> c): in the frame (full LUT) or in the
    /// slice (compact LUT, logic decoding), with its slice in `sl`.
    pub(super) slot: DFF<Bits<SLOT_BITS>>,
    pub(super) sl: DFF<Bits<SLICE_BITS>>,
    /// The slot after `slot` (wrapping at the last), kept in step with it.
    pub(super) succ: DFF<Bits<SLOT_BITS>>,
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
    /// The slot after slot 0 (`succ` in reset).
    k_succ_rst: Constant<Bits<SLOT_BITS>>,
    /// The mix's own counter widths, as masks.
    k_cnt_mask: Constant<Bits<CNT_BITS>>,
    k_slot_mask: Constant<Bits<SLOT_BITS>>,
}

impl TimingGen {
    pub(super) fn new(plan: &Plan) -> TimingGen {
        // the compact LUT and the logic decoding count slots in the slice
        let in_slice = plan.compact || plan.logic;
        let slot_last = if in_slice {
            plan.slots_per_slice - 1
        } else {
            plan.frame_slots - 1
        };
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
            succ: Default::default(),
            nxt: Default::default(),
            nxt_sl: Default::default(),
            k_compact: Constant::new(in_slice),
            k_sl_last: c(if in_slice {
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
            k_slot_last: c(slot_last),
            k_slot_zero: c(0),
            k_slot_one: c(1),
            k_succ_rst: c(if slot_last == 0 { 0 } else { 1 }),
            k_cnt_mask: c(mask(plan.slot_cycles - 1)),
            k_slot_mask: c(mask(slot_last)),
        }
    }
}

/// All ones over the bits that count `0..=last` (at least one bit).
pub(super) fn mask(last: u64) -> u64 {
    let bits = 64 - last.leading_zeros();
    (1u64 << bits.max(1)) - 1
}

impl Logic for TimingGen {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, cnt, st, st2, st0, slot, sl, succ);
        if self.cnt.q.val() == self.k_cnt_last.val() {
            self.cnt.d.next = self.k_cnt_zero.val();
        } else {
            self.cnt.d.next = (self.cnt.q.val() + self.k_cnt_one.val()) & self.k_cnt_mask.val();
        }
        self.st2.d.next = self.cnt.q.val() == self.k_cnt_last.val();
        self.st.d.next = self.st2.q.val();
        self.st0.d.next = self.st.q.val();
        self.nxt.next = self.slot.q.val();
        self.nxt_sl.next = self.sl.q.val();
        if self.st.q.val() {
            self.nxt.next = self.succ.q.val();
            if (self.slot.q.val() == self.k_slot_last.val()) & self.k_compact.val() {
                if self.sl.q.val() == self.k_sl_last.val() {
                    self.nxt_sl.next = self.k_sl_zero.val();
                } else {
                    self.nxt_sl.next = self.sl.q.val() + self.k_sl_one.val();
                }
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
        self.slot.d.next = self.nxt.val() & self.k_slot_mask.val();
        // The successor of the registered slot, not of `nxt`, so the
        // compare and increment start at a flip-flop rather than behind the
        // `nxt` multiplexer: stale in the cycle after a slot start only,
        // and right again by the next start (slots are at least 2 cycles,
        // `plan`).
        if self.slot.q.val() == self.k_slot_last.val() {
            self.succ.d.next = self.k_slot_zero.val();
        } else {
            self.succ.d.next = (self.slot.q.val() + self.k_slot_one.val()) & self.k_slot_mask.val();
        }
        if self.rst.val() {
            self.succ.d.next = self.k_succ_rst.val();
        }
        self.sl.d.next = self.nxt_sl.val();
        self.addr.next = self.nxt.val();
        self.slice.next = self.nxt_sl.val();
        self.start2.next = self.st2.q.val();
        self.start1.next = self.st.q.val();
        self.start0.next = self.st0.q.val();
    }
}
