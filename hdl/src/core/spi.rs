//! SPI sequencer: one per distinct SPI timing, shared by its branches.

use crate::rhdl::*;

use super::c;
use super::timing::mask;
use crate::plan::SeqTiming;
use crate::widths::*;

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
///
/// Each counter's increment is masked to the mix's own width (`k_*_mask`,
/// the phase counter's wide enough for both the period and the setup), so
/// yosys removes the bits above it (the core's maximum widths
/// cost flip-flops, carry cells and compare LUTs in every design).
#[derive(LogicBlock)]
pub struct SpiSeq {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start2: Signal<In, Bit>,
    pub cs_n: Signal<Out, Bit>,
    pub sclk: Signal<Out, Bit>,
    pub cap: Signal<Out, Bit>,
    /// `cap` of the next cycle (the D input of its flip-flop), for the
    /// merger's queue form's registered shift enable.
    pub cap_next: Signal<Out, Bit>,
    pub done: Signal<Out, Bit>,
    pub(super) r_cs_n: DFF<Bit>,
    pub(super) r_sclk: DFF<Bit>,
    pub(super) ph: DFF<Bits<PH_BITS>>,
    pub(super) nfall: DFF<Bits<NFALL_BITS>>,
    /// Index within its word of the serial bit the next rising edge reads.
    pub(super) wbit: DFF<Bits<WORD_BIT_BITS>>,
    /// `wbit` is a data bit (in `leading_bits .. leading_bits + bits`),
    /// kept in step with it: two equality compares on the current bit
    /// instead of a subtract-and-compare carry chain (the core's critical
    /// path once the counters were trimmed).
    pub(super) indata: DFF<Bit>,
    pub(super) r_cap: DFF<Bit>,
    pub(super) r_done: DFF<Bit>,
    /// Registered compares, kept in step with their counters: `ph` is at
    /// the period's end (`f_wrap`) or its middle (`f_half`), `nfall` is not
    /// zero (`f_nz`) or at the last period (`f_end`). The strobes' D inputs
    /// (and the synchronous resets yosys makes of them) read these flags
    /// instead of comparing the counters, so each is two LUT levels at most.
    pub(super) f_wrap: DFF<Bit>,
    pub(super) f_half: DFF<Bit>,
    pub(super) f_nz: DFF<Bit>,
    pub(super) f_end: DFF<Bit>,
    init: Signal<Local, Bit>,
    step: Signal<Local, Bit>,
    rise: Signal<Local, Bit>,
    /// A converting period ends (SCLK falls, or the conversion's last).
    wrap: Signal<Local, Bit>,
    k_ph_start: Constant<Bits<PH_BITS>>,
    k_ph_zero: Constant<Bits<PH_BITS>>,
    /// The phase before the period's end (its middle), modulo the
    /// counter's width: the flag is set when the counter leaves it.
    k_ph_pre_last: Constant<Bits<PH_BITS>>,
    k_ph_pre_half: Constant<Bits<PH_BITS>>,
    /// The flags' values at the start phase and at phase zero.
    k_wrap_start: Constant<Bit>,
    k_half_start: Constant<Bit>,
    k_half_zero: Constant<Bit>,
    k_nf_pre_end: Constant<Bits<NFALL_BITS>>,
    k_ph_one: Constant<Bits<PH_BITS>>,
    k_nf_zero: Constant<Bits<NFALL_BITS>>,
    k_nf_one: Constant<Bits<NFALL_BITS>>,
    k_end_start: Constant<Bit>,
    k_wb_first: Constant<Bits<WORD_BIT_BITS>>,
    k_wb_last: Constant<Bits<WORD_BIT_BITS>>,
    k_wb_zero: Constant<Bits<WORD_BIT_BITS>>,
    k_wb_one: Constant<Bits<WORD_BIT_BITS>>,
    /// The bit whose successor enters (leaves) the data window, and
    /// whether the first bit of a word is in it.
    k_wb_enter: Constant<Bits<WORD_BIT_BITS>>,
    k_wb_leave: Constant<Bits<WORD_BIT_BITS>>,
    k_in_first: Constant<Bit>,
    /// SCLK level between conversions (CS parts high, CNV parts low).
    k_sclk_idle: Constant<Bit>,
    /// The last rising edge reads a bit (CNV parts; a CS part's last edge
    /// comes after its last bit).
    k_cap_last: Constant<Bit>,
    k_ph_mask: Constant<Bits<PH_BITS>>,
    k_nf_mask: Constant<Bits<NFALL_BITS>>,
    k_wb_mask: Constant<Bits<WORD_BIT_BITS>>,
}

impl SpiSeq {
    pub(super) fn new(t: &SeqTiming) -> SpiSeq {
        // the phase counts modulo 2^w: from sclk_div - setup through the
        // wrap to sclk_div - 1, so 2^w must exceed both
        let ph_mask = mask(t.sclk_div.max(t.setup_cycles));
        let ph_mod = ph_mask + 1;
        let ph_start = (t.sclk_div + ph_mod - t.setup_cycles) % ph_mod;
        let w = t.word_sclks;
        let in_data = |b: u64| b >= t.leading_bits && b < t.leading_bits + t.bits;
        SpiSeq {
            clock: Default::default(),
            rst: Default::default(),
            start2: Default::default(),
            cs_n: Default::default(),
            sclk: Default::default(),
            cap: Default::default(),
            cap_next: Default::default(),
            done: Default::default(),
            r_cs_n: Default::default(),
            r_sclk: Default::default(),
            ph: Default::default(),
            nfall: Default::default(),
            wbit: Default::default(),
            indata: Default::default(),
            r_cap: Default::default(),
            r_done: Default::default(),
            f_wrap: Default::default(),
            f_half: Default::default(),
            f_nz: Default::default(),
            f_end: Default::default(),
            init: Default::default(),
            step: Default::default(),
            rise: Default::default(),
            wrap: Default::default(),
            k_ph_start: c(ph_start),
            k_ph_zero: c(0),
            k_ph_pre_last: c((t.sclk_div - 2) % ph_mod),
            k_ph_pre_half: c((t.sclk_half + ph_mod - 2) % ph_mod),
            k_wrap_start: Constant::new(ph_start == t.sclk_div - 1),
            k_half_start: Constant::new(ph_start == t.sclk_half - 1),
            k_half_zero: Constant::new(t.sclk_half == 1),
            k_nf_pre_end: c(t.sclks.saturating_sub(1)),
            k_ph_one: c(1),
            k_nf_zero: c(0),
            k_nf_one: c(1),
            k_end_start: Constant::new(t.sclks == 0),
            k_wb_first: c(t.first_bit()),
            k_wb_last: c(t.word_sclks - 1),
            k_wb_zero: c(0),
            k_wb_one: c(1),
            k_wb_enter: c((t.leading_bits + w - 1) % w),
            k_wb_leave: c((t.leading_bits + t.bits + w - 1) % w),
            k_in_first: Constant::new(in_data(t.first_bit())),
            k_sclk_idle: Constant::new(!t.cnv),
            k_cap_last: Constant::new(t.cnv),
            k_ph_mask: c(ph_mask),
            k_nf_mask: c(mask(t.sclks)),
            k_wb_mask: c(mask(t.word_sclks - 1)),
        }
    }
}

impl Logic for SpiSeq {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, r_cs_n, r_sclk, ph, nfall, wbit, indata, r_cap, r_done, f_wrap, f_half,
            f_nz, f_end
        );
        // Cycle t - 2 (`start2`), or reset (the state of cycle t - 1 for
        // an instant t at cycle 0): a converting branch's conversion pin
        // becomes active at the edge that begins t.
        self.init.next = self.start2.val() | self.rst.val();
        // The conversion runs: the phase counts. `init` overrides all of
        // it below (a set or reset of each flip-flop, one LUT from `rst`
        // and `start2`), so it is not in here.
        self.step.next = !self.r_cs_n.q.val();
        // SCLK rising edge `nfall` begins the next cycle + 1.
        self.rise.next = self.step.val() & self.f_half.q.val() & self.f_nz.q.val();
        self.r_cap.d.next = false;
        self.r_done.d.next = false;
        if self.step.val() {
            if self.f_wrap.q.val() {
                self.ph.d.next = self.k_ph_zero.val();
                self.f_wrap.d.next = false;
                self.f_half.d.next = self.k_half_zero.val();
            } else {
                self.ph.d.next = (self.ph.q.val() + self.k_ph_one.val()) & self.k_ph_mask.val();
                self.f_wrap.d.next = self.ph.q.val() == self.k_ph_pre_last.val();
                self.f_half.d.next = self.ph.q.val() == self.k_ph_pre_half.val();
            }
            if self.f_wrap.q.val() {
                if self.f_end.q.val() {
                    // Cycle t + R - 2: the pin is released (and SCLK back at
                    // idle) at the edge that begins t + R.
                    self.r_cs_n.d.next = true;
                    self.r_done.d.next = true;
                } else {
                    self.nfall.d.next =
                        (self.nfall.q.val() + self.k_nf_one.val()) & self.k_nf_mask.val();
                }
            }
        }
        if self.rise.val() {
            // Capture the serial bit this edge reads at the end of the next
            // cycle, if that bit is a data bit.
            if self.wbit.q.val() == self.k_wb_last.val() {
                self.wbit.d.next = self.k_wb_zero.val();
            } else {
                self.wbit.d.next = (self.wbit.q.val() + self.k_wb_one.val()) & self.k_wb_mask.val();
            }
            if self.wbit.q.val() == self.k_wb_enter.val() {
                self.indata.d.next = true;
            } else if self.wbit.q.val() == self.k_wb_leave.val() {
                self.indata.d.next = false;
            }
            if self.indata.q.val() & (!self.f_end.q.val() | self.k_cap_last.val()) {
                self.r_cap.d.next = true;
            }
        }
        // SCLK and the falling-edge flags as gates, not as flip-flops with
        // an enable: an iCE40 flip-flop's reset (`init`) acts only when
        // enabled, so an enable would have `init` in it, three LUT levels
        // from `start2` (the core's critical path); as gates `init` is
        // their synchronous set or reset alone. SCLK rises at `rise`, and
        // at a period's end falls, or returns to idle after the last.
        self.wrap.next = self.step.val() & self.f_wrap.q.val();
        self.r_sclk.d.next = self.rise.val()
            | (!self.wrap.val() & self.r_sclk.q.val())
            | (self.wrap.val() & self.f_end.q.val() & self.k_sclk_idle.val());
        self.f_nz.d.next = self.f_nz.q.val() | (self.wrap.val() & !self.f_end.q.val());
        self.f_end.d.next = self.f_end.q.val()
            | (self.wrap.val() & (self.nfall.q.val() == self.k_nf_pre_end.val()));
        if self.init.val() {
            self.r_cs_n.d.next = false;
            self.r_sclk.d.next = self.k_sclk_idle.val();
            self.ph.d.next = self.k_ph_start.val();
            self.f_wrap.d.next = self.k_wrap_start.val();
            self.f_half.d.next = self.k_half_start.val();
            self.nfall.d.next = self.k_nf_zero.val();
            self.f_nz.d.next = false;
            self.f_end.d.next = self.k_end_start.val();
            self.wbit.d.next = self.k_wb_first.val();
            self.indata.d.next = self.k_in_first.val();
            self.r_cap.d.next = false;
            self.r_done.d.next = false;
        }
        self.cs_n.next = self.r_cs_n.q.val();
        self.sclk.next = self.r_sclk.q.val();
        self.cap.next = self.r_cap.q.val();
        self.cap_next.next = self.r_cap.d.val();
        self.done.next = self.r_done.q.val();
    }
}
