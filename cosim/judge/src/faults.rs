//! Fault injection: a [`Dut`] wrapper that corrupts a design's pins in one
//! precise way, to prove the checker catches each kind of fault.

use lut_gen::Schedule;

use crate::run::Dut;
use lut_gen::ports::{Layout, Pins};

/// A kind of fault, injected around the first conversion of `branch` at or after a cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// `sample_channel` of one emitted sample has bit 0 flipped.
    WrongChannel,
    /// `sample_value` of one emitted sample has one bit flipped.
    WrongSampleBit,
    /// One `sample_valid` pulse is dropped.
    DropSample,
    /// One CS-low window of `branch` is shifted one cycle later.
    CsLate { branch: usize },
    /// One extra SCLK low pulse inside a CS-low window of `branch`.
    SclkExtraEdge { branch: usize },
    /// `branch`'s mux switches two cycles before the instant instead of right after the previous one.
    MuxLate { branch: usize },
    /// Every mux device of `branch` enabled for a few cycles.
    TwoMuxEn { branch: usize },
    /// The wrong mux input (select bit 0 flipped) held through one instant of `branch`.
    WrongMux { branch: usize },
    /// The design is reset for a few cycles in mid-run while its `rst` port
    /// stays low (a glitch, a brown-out): it restarts its frame.
    ResetGlitch,
}

/// Cycles a [`Fault::ResetGlitch`] holds the design in reset.
pub const GLITCH_CYCLES: u64 = 3;

impl Fault {
    /// The fault's class: its name without the branch.
    pub fn class(&self) -> &'static str {
        match self {
            Fault::WrongChannel => "wrong-channel",
            Fault::WrongSampleBit => "wrong-sample-bit",
            Fault::DropSample => "drop-sample",
            Fault::CsLate { .. } => "cs-late",
            Fault::SclkExtraEdge { .. } => "sclk-extra-edge",
            Fault::MuxLate { .. } => "mux-late",
            Fault::TwoMuxEn { .. } => "two-mux-en",
            Fault::WrongMux { .. } => "wrong-mux",
            Fault::ResetGlitch => "reset-glitch",
        }
    }

    pub fn name(&self) -> String {
        match self {
            Fault::WrongChannel => "wrong-channel".into(),
            Fault::WrongSampleBit => "wrong-sample-bit".into(),
            Fault::DropSample => "drop-sample".into(),
            Fault::CsLate { branch } => format!("cs-late-b{branch}"),
            Fault::SclkExtraEdge { branch } => format!("sclk-extra-edge-b{branch}"),
            Fault::MuxLate { branch } => format!("mux-late-b{branch}"),
            Fault::TwoMuxEn { branch } => format!("two-mux-en-b{branch}"),
            Fault::WrongMux { branch } => format!("wrong-mux-b{branch}"),
            Fault::ResetGlitch => "reset-glitch".into(),
        }
    }

    /// Every fault that applies to the schedule.
    pub fn all(s: &Schedule) -> Vec<Fault> {
        let mut v = vec![
            Fault::WrongChannel,
            Fault::WrongSampleBit,
            Fault::DropSample,
            Fault::ResetGlitch,
        ];
        for b in 0..s.branches.len() {
            if s.branch_instants_in_frame(b).is_empty() {
                continue;
            }
            v.push(Fault::CsLate { branch: b });
            v.push(Fault::SclkExtraEdge { branch: b });
            v.push(Fault::MuxLate { branch: b });
            v.push(Fault::WrongMux { branch: b });
            if s.branches[b].mux_devices >= 2 {
                v.push(Fault::TwoMuxEn { branch: b });
            }
        }
        v
    }
}

/// Wraps a design and injects one fault at or after cycle `at`.
pub struct FaultyDut<D> {
    inner: D,
    fault: Fault,
    layout: Layout,
    at: u64,
    /// (previous instant, target instant) of the fault's branch.
    t_prev: u64,
    t: u64,
    su: u64,
    d: u64,
    r: u64,
    cycle: Option<u64>,
    done: bool,
    prev_cs: u16,
    prev_sclk: u16,
    /// Cycles SCLK is high in one period.
    high: u64,
    held: Option<Pins>,
    changed: bool,
}

impl<D: Dut> FaultyDut<D> {
    pub fn new(s: &Schedule, inner: D, fault: Fault, at: u64) -> FaultyDut<D> {
        let b = match fault {
            Fault::CsLate { branch }
            | Fault::SclkExtraEdge { branch }
            | Fault::MuxLate { branch }
            | Fault::TwoMuxEn { branch }
            | Fault::WrongMux { branch } => branch,
            _ => 0,
        };
        let mut prev = 0;
        let mut t = 0;
        for i in s.instants(u64::MAX).filter(|i| i.branch == b) {
            if i.cycle >= at && i.cycle > 0 {
                t = i.cycle;
                break;
            }
            prev = i.cycle;
        }
        let spi = s.branches[b].spi;
        FaultyDut {
            inner,
            fault,
            layout: Layout::new(s),
            at,
            t_prev: prev,
            t,
            su: spi.setup_cycles,
            d: spi.sclk_div,
            r: spi.read_cycles,
            cycle: None,
            done: false,
            prev_cs: 0xff,
            prev_sclk: 0xff,
            high: spi.sclk_div - spi.sclk_half,
            held: None,
            changed: false,
        }
    }
}

impl<D: Dut> Dut for FaultyDut<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        let next = self.cycle.map_or(0, |c| c + 1);
        let glitch = !rst
            && self.fault == Fault::ResetGlitch
            && next >= self.at
            && next < self.at + GLITCH_CYCLES;
        let mut p = self.inner.step(rst || glitch, miso);
        if rst {
            self.cycle = None;
            self.prev_cs = p.cs_n;
            return p;
        }
        let c = next;
        self.cycle = Some(c);
        let orig = p;
        let orig_cs = p.cs_n;
        let orig_sclk = p.sclk;
        match self.fault {
            Fault::ResetGlitch => {}
            Fault::WrongChannel | Fault::WrongSampleBit | Fault::DropSample => {
                if !self.done && c >= self.at && p.sample_valid {
                    self.done = true;
                    match self.fault {
                        Fault::WrongChannel => p.sample_channel ^= 1,
                        Fault::WrongSampleBit => p.sample_value ^= 1 << 5,
                        _ => p.sample_valid = false,
                    }
                }
            }
            Fault::CsLate { branch } => {
                if c >= self.t && c <= self.t + self.r {
                    let bit = 1u16 << branch;
                    p.cs_n = (p.cs_n & !bit) | (self.prev_cs & bit);
                }
            }
            Fault::SclkExtraEdge { branch } => {
                // a one-cycle low pulse in a high phase of SCLK, two periods
                // into the read (one more falling edge than the part expects)
                // (in the middle of the high phase when it is 3 cycles or
                // more; else the high phase vanishes: one falling edge fewer)
                let bit = 1u16 << branch;
                let mid_high = self.prev_sclk & bit != 0 || self.high < 3;
                if !self.done && c >= self.t + self.su + 2 * self.d && p.sclk & bit != 0 && mid_high
                {
                    p.sclk &= !bit;
                    self.done = true;
                }
            }
            Fault::MuxLate { branch } => {
                if c == self.t_prev + 1 {
                    self.held = Some(pins_before(&self.layout, &p, branch, self.t_prev));
                }
                if c > self.t_prev && c + 2 < self.t {
                    if let Some(h) = self.held {
                        copy_mux(&self.layout, &mut p, &h, branch);
                    }
                }
            }
            Fault::TwoMuxEn { branch } => {
                if c >= self.t && c < self.t + 5 {
                    let n = self.layout.en_n[branch];
                    p.mux_en |= ((1u128 << n) - 1) << self.layout.en_lo[branch];
                }
            }
            Fault::WrongMux { branch } => {
                if c > self.t_prev && c <= self.t {
                    p.mux_sel ^= 1 << (3 * branch);
                }
            }
        }
        self.prev_cs = orig_cs;
        self.prev_sclk = orig_sclk;
        self.changed |= glitch || p != orig;
        p
    }
}

impl<D> FaultyDut<D> {
    /// Whether the fault has changed anything yet (a fault that found
    /// nothing to change was not injected).
    pub fn injected(&self) -> bool {
        self.changed
    }
}

/// Pins with the mux of `branch` as it was before it switched (we only know
/// the new value at `t_prev + 1`, so keep the select but flip to a different
/// channel: the previous one is not recorded; use select ^ 1 as "old").
fn pins_before(layout: &Layout, p: &Pins, branch: usize, _t_prev: u64) -> Pins {
    let mut h = *p;
    h.mux_sel ^= 1 << (3 * branch);
    let _ = layout;
    h
}

fn copy_mux(layout: &Layout, p: &mut Pins, from: &Pins, b: usize) {
    let selm = 7u64 << (3 * b);
    p.mux_sel = (p.mux_sel & !selm) | (from.mux_sel & selm);
    let enm = ((1u128 << layout.en_n[b]) - 1) << layout.en_lo[b];
    p.mux_en = (p.mux_en & !enm) | (from.mux_en & enm);
}
