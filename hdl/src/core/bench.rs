//! The SPI master and mux control in rust-hdl's simulator (direct clock
//! loop with `simulate()`), against a behavioural AD7940 with the
//! datasheet's delays expressed in nanoseconds: the bench of the SPI test
//! in `tests/stock.rs`, which checks the [`SpiTrace`] it returns.  Behind
//! the `stock` feature (tests only) beside the other stock-simulator
//! runs; its face is plain data, no rust-hdl type.
use super::*;
use crate::plan::{BranchRom, Plan, SeqTiming};

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
/// Nanoseconds per cycle.
pub const NS: u64 = 1_000_000_000 / CLOCK_HZ;
/// Cycles per slot.
pub const SLOT: u64 = 500;

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
        muxed: true,
        en_offset: 0,
        cnv: false,
        bits: 14,
        chain: 1,
        members: vec![],
        compact: None,
        command: None,
        front: None,
        modes: None,
        logic: None,
        ch_used: vec![],
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
        modes: None,
        compact: false,
        logic: false,
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
            pin_cycles: setup + 16 * div,
            cnv: false,
            sclks: 16,
            word_sclks: 16,
            leading_bits: 2,
            bits: 14,
            holdoff: 0,
        }],
        branches: vec![rom()],
        queue: None,
        lane_ch: None,
    };
    let mut h = Harness {
        clock: Default::default(),
        rst: Default::default(),
        miso: Default::default(),
        timing: TimingGen::new(&plan),
        seq: SpiSeq::new(&plan.seqs[0]),
        unit: BranchUnit::new(&plan.branches[0], false, false),
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

/// The branch's pins, cycle by cycle after reset, and what it read.
#[derive(Debug, Default)]
pub struct SpiTrace {
    /// Every `simulate()` call converged.
    pub converged: bool,
    /// `(cs_n, sclk, mux_en)` in each of the two reset cycles.
    pub reset: Vec<(bool, bool, u64)>,
    pub cs_n: Vec<bool>,
    pub sclk: Vec<bool>,
    pub sel: Vec<u64>,
    pub en: Vec<u64>,
    /// `(cycle, channel, code)` of each completed conversion.
    pub done: Vec<(u64, u64, u64)>,
}

/// The branch with an SCLK divider `div` and `setup` cycles from CS to the
/// first SCLK edge, run for `cycles` cycles against an AD7940 whose code is
/// `word`.
pub fn spi_trace(div: u64, setup: u64, cycles: u64, word: u16) -> SpiTrace {
    let mut h = harness(div, setup);
    let mut adc = Ad7940 {
        word,
        cs_fall_ns: None,
        falls: vec![],
        garbage: false,
    };
    let mut t = SpiTrace {
        converged: true,
        ..Default::default()
    };
    let mut miso = false;
    let mut prev = (true, true);
    for c in 0..cycles + 2 {
        let reset = c < 2;
        h.rst.next = reset;
        h.miso.next = miso;
        h.clock.next = Clock::from(false);
        t.converged &= simulate(&mut h, 100);
        h.clock.next = Clock::from(true);
        t.converged &= simulate(&mut h, 100);
        let (cs_n, sclk) = (h.unit.cs_n.val(), h.unit.sclk.val());
        if reset {
            t.reset.push((cs_n, sclk, h.unit.mux_en.val().to_u64()));
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
