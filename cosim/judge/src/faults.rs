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
}

impl Fault {
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
        }
    }

    /// Every fault that applies to the schedule.
    pub fn all(s: &Schedule) -> Vec<Fault> {
        let mut v = vec![
            Fault::WrongChannel,
            Fault::WrongSampleBit,
            Fault::DropSample,
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
    h: u64,
    r: u64,
    cycle: Option<u64>,
    done: bool,
    prev_cs: u16,
    held: Option<Pins>,
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
            h: spi.sclk_half,
            r: spi.read_cycles,
            cycle: None,
            done: false,
            prev_cs: 0xff,
            held: None,
        }
    }
}

impl<D: Dut> Dut for FaultyDut<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        let mut p = self.inner.step(rst, miso);
        if rst {
            self.cycle = None;
            self.prev_cs = p.cs_n;
            return p;
        }
        let c = self.cycle.map_or(0, |c| c + 1);
        self.cycle = Some(c);
        let orig_cs = p.cs_n;
        match self.fault {
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
                if c == self.t + self.su + 3 * self.d + self.h + 1 {
                    p.sclk &= !(1u16 << branch);
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
                    p.mux_en |= ((1u64 << n) - 1) << self.layout.en_lo[branch];
                }
            }
            Fault::WrongMux { branch } => {
                if c > self.t_prev && c <= self.t {
                    p.mux_sel ^= 1 << (3 * branch);
                }
            }
        }
        self.prev_cs = orig_cs;
        p
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
    let enm = ((1u64 << layout.en_n[b]) - 1) << layout.en_lo[b];
    p.mux_en = (p.mux_en & !enm) | (from.mux_en & enm);
}

#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct FirstDivergence {
    pub signal: String,
    pub cycle: u64,
}

/// What the checker made of one injected fault.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct FaultOutcome {
    pub fault: String,
    /// The cycle around which the fault was injected.
    pub injected_at: u64,
    pub caught: bool,
    pub divergence_count: u64,
    pub violation_count: u64,
    /// First divergent signal and its cycle, if any.
    pub first_divergence: Option<FirstDivergence>,
    /// Invariant rules the fault broke (first few, deduplicated).
    pub rules: Vec<String>,
}

/// Every fault of [`Fault::all`], injected one at a time into the design that
/// `make_dut` builds, mid-way through the second frame, each run checked in full.
pub fn campaign<D: Dut>(
    s: &Schedule,
    frames: u64,
    mut make_dut: impl FnMut() -> D,
) -> Vec<FaultOutcome> {
    let frames = frames.max(2);
    let at = s.grid.frame_cycles + s.grid.frame_cycles / 2 + 7;
    Fault::all(s)
        .into_iter()
        .map(|f| {
            let mut dut = FaultyDut::new(s, make_dut(), f, at);
            let r = crate::run::run_dut(s, &mut dut, frames, &Default::default(), "faults", None);
            let mut rules: Vec<String> = Vec::new();
            for v in &r.violations {
                if rules.len() < 4 && !rules.contains(&v.rule) {
                    rules.push(v.rule.clone());
                }
            }
            FaultOutcome {
                fault: f.name(),
                injected_at: at,
                caught: !r.ok,
                divergence_count: r.divergence_count,
                violation_count: r.violation_count,
                first_divergence: r.divergences.first().map(|d| FirstDivergence {
                    signal: d.signal.clone(),
                    cycle: d.cycle,
                }),
                rules,
            }
        })
        .collect()
}
