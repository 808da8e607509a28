//! The SPI master and mux control in rust-hdl's simulator (direct clock
//! loop with `simulate()`), against a behavioural AD7940 with the
//! datasheet's delays expressed in nanoseconds.
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
