//! Driving a design cycle by cycle with the ADC model, fully checked, and
//! the slot-level model back end.

use lut_gen::Schedule;
use lut_gen::{Layout, Signal};

use crate::check::checker::{CheckOptions, Checker};
use crate::converter::{Adc, Analog, Stimulus};
use crate::model::Invariants;
use crate::model::Rule;
use crate::model::Verdict;
use crate::model::Violation;
use crate::model::{CycleModel, SlotModel};
use lut_gen::Pins;

/// Anything that behaves like `slotforge_top`: one call per rising clock
/// edge, with `rst` and `adc_miso` as sampled at that edge; returns the
/// outputs after the edge.
pub trait Dut {
    fn step(&mut self, rst: bool, miso: u64) -> Pins;
    /// An AXI4-Stream link's `m_axis_tready` during the cycle the last
    /// step returned, sampled by the next step like `miso` (ignored by a
    /// design without one).
    fn set_tready(&mut self, _ready: bool) {}
    /// `mode_sel` during the cycle the last step returned, sampled by the
    /// next step like `miso` (ignored by a design without the pin).
    fn set_mode_sel(&mut self, _sel: u8) {}
}

impl<D: Dut + ?Sized> Dut for Box<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        (**self).step(rst, miso)
    }
    fn set_tready(&mut self, ready: bool) {
        (**self).set_tready(ready)
    }
    fn set_mode_sel(&mut self, sel: u8) {
        (**self).set_mode_sel(sel)
    }
}

impl<D: Dut + ?Sized> Dut for &mut D {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        (**self).step(rst, miso)
    }
    fn set_tready(&mut self, ready: bool) {
        (**self).set_tready(ready)
    }
    fn set_mode_sel(&mut self, sel: u8) {
        (**self).set_mode_sel(sel)
    }
}

/// The AXI4-Stream slave in front of a design with an AXIS link: `tready`
/// in every cycle from the pattern and the design's `tvalid` in that cycle,
/// recorded in the pins (so the judge, a VCD and the model all see the
/// handshake).  During reset `tready` is high and the pattern restarts, so
/// a pattern is the same sequence from cycle 0 on every back end.
pub struct AxisSlave<D> {
    dut: D,
    pattern: link::ReadyPattern,
    within: u32,
    driver: link::ReadyDriver,
    ready: bool,
}

impl<D: Dut> AxisSlave<D> {
    pub fn new(dut: D, pattern: link::ReadyPattern, ready_within: u32) -> AxisSlave<D> {
        AxisSlave {
            dut,
            pattern,
            within: ready_within,
            driver: link::ReadyDriver::new(pattern, ready_within),
            ready: true,
        }
    }
}

impl<D: Dut> Dut for AxisSlave<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        self.dut.set_tready(self.ready);
        let mut p = self.dut.step(rst, miso);
        self.ready = if rst {
            self.driver = link::ReadyDriver::new(self.pattern, self.within);
            true
        } else {
            self.driver.ready(p.axis_tvalid)
        };
        p.axis_tready = self.ready;
        p
    }
    fn set_mode_sel(&mut self, sel: u8) {
        self.dut.set_mode_sel(sel)
    }
}

/// `dut`, behind an AXI4-Stream slave driving `pattern` when `s`'s link is
/// AXIS (the design itself otherwise).
pub fn with_slave<'a, D: Dut + 'a>(
    s: &Schedule,
    dut: D,
    pattern: link::ReadyPattern,
) -> Box<dyn Dut + 'a> {
    match lut_gen::plan_link(s)
        .and_then(|p| p.ok())
        .and_then(|p| p.axis())
    {
        Some(a) => Box::new(AxisSlave::new(dut, pattern, a.ready_within)),
        None => Box::new(dut),
    }
}

/// The cycle-level model used as a design (for testing the checker, and as
/// a golden pin source).
pub struct ModelDut {
    schedule: Schedule,
    reset: Pins,
    m: Option<CycleModel>,
}

impl ModelDut {
    pub fn new(s: &Schedule) -> ModelDut {
        ModelDut {
            reset: CycleModel::new(s).reset_pins(),
            schedule: s.clone(),
            m: None,
        }
    }
}

impl Dut for ModelDut {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        if rst {
            self.m = None;
            return self.reset;
        }
        match &mut self.m {
            None => {
                let m = CycleModel::new(&self.schedule);
                let p = *m.pins();
                self.m = Some(m);
                p
            }
            Some(m) => {
                m.step(miso);
                *m.pins()
            }
        }
    }

    fn set_tready(&mut self, ready: bool) {
        if let Some(m) = &mut self.m {
            m.set_tready(ready);
        }
    }

    fn set_mode_sel(&mut self, sel: u8) {
        if let Some(m) = &mut self.m {
            m.set_mode_sel(sel);
        }
    }
}

/// A design with its `mode_sel` driven from requests `(frame, mode)`: from
/// the first cycle of `frame` (cycle 0 is the first after reset) on, the pin
/// shows `mode` (0 before the first request; low during reset), recorded in
/// the pins so the judge, a VCD and the model all see it.  By the contract
/// a request shown from frame `f` on runs from frame `f + 2`.
pub struct ModeRequests<D> {
    dut: D,
    requests: Vec<(u64, u8)>,
    frame_cycles: u64,
    /// The cycle of the pins last returned (None: reset, or none yet).
    c: Option<u64>,
}

impl<D: Dut> ModeRequests<D> {
    pub fn new(s: &Schedule, dut: D, requests: &[(u64, u8)]) -> ModeRequests<D> {
        let mut requests = requests.to_vec();
        requests.sort_by_key(|r| r.0);
        ModeRequests {
            dut,
            requests,
            frame_cycles: s.grid.frame_cycles,
            c: None,
        }
    }

    fn sel_at(&self, c: u64) -> u8 {
        let f = c / self.frame_cycles;
        self.requests.iter().rfind(|r| r.0 <= f).map_or(0, |r| r.1)
    }
}

impl<D: Dut> Dut for ModeRequests<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        // the value during the cycle this step ends
        let sel = self.c.map_or(0, |c| self.sel_at(c));
        self.dut.set_mode_sel(sel);
        let mut p = self.dut.step(rst, miso);
        self.c = if rst {
            None
        } else {
            Some(self.c.map_or(0, |c| c + 1))
        };
        p.mode_sel = self.c.map_or(0, |c| self.sel_at(c));
        p
    }
    fn set_tready(&mut self, ready: bool) {
        self.dut.set_tready(ready)
    }
}

/// Something that watches every cycle of a run (waveform writers).
pub trait Observer {
    /// `cycle` counts from 0 at the first reset cycle of the run.
    fn cycle(&mut self, cycle: u64, rst: bool, pins: &Pins, miso: u64);
}

/// Options of an in-process run.
#[derive(Debug, Clone, Copy)]
pub struct RunOptions {
    pub stimulus: Stimulus,
    pub check: CheckOptions,
    /// Cycles with `rst` high before cycle 0 (at least one).
    pub reset_cycles: u64,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            stimulus: Stimulus::Pattern,
            check: CheckOptions::default(),
            reset_cycles: 4,
        }
    }
}

/// The reset cycles of a run asked for `requested`: at least one.  The
/// gateware is correct for any reset of one cycle or more (docs/timing.md,
/// "Start-up"), so a run's reset is not stretched to the mux settling time.
pub fn reset_cycles(_s: &Schedule, requested: u64) -> u64 {
    requested.max(1)
}

/// Runs `frames` frames of `dut` with the ADC model, feeding every cycle to
/// the checker (and to `obs`).
pub fn run_dut<D: Dut + ?Sized>(
    s: &Schedule,
    dut: &mut D,
    frames: u64,
    opts: &RunOptions,
    source: &str,
    mut obs: Option<&mut dyn Observer>,
) -> Verdict {
    let mut adc = Adc::new(s, opts.stimulus);
    let mut chk = Checker::new(s, opts.check);
    let ones = (1u64 << s.branches.len()) - 1;
    let mut miso = ones;
    let mut k = 0u64;
    for _ in 0..reset_cycles(s, opts.reset_cycles) {
        let p = dut.step(true, miso);
        miso = adc.drive(0, &p);
        chk.cycle(true, &p, miso);
        if let Some(o) = obs.as_deref_mut() {
            o.cycle(k, true, &p, miso);
        }
        k += 1;
    }
    let total = frames * s.grid.frame_cycles;
    match obs {
        None => {
            for c in 0..total {
                let p = dut.step(false, miso);
                miso = adc.drive(c, &p);
                chk.cycle(false, &p, miso);
            }
        }
        Some(o) => {
            for c in 0..total {
                let p = dut.step(false, miso);
                miso = adc.drive(c, &p);
                chk.cycle(false, &p, miso);
                o.cycle(k + c, false, &p, miso);
            }
        }
    }
    chk.finish(source)
}

/// Runs `dut` for `frames` frames with no checking at all (the baseline for benchmarks).
pub fn run_unchecked<D: Dut + ?Sized>(
    s: &Schedule,
    dut: &mut D,
    frames: u64,
    stimulus: Stimulus,
) -> u64 {
    let mut adc = Adc::new(s, stimulus);
    let mut miso = (1u64 << s.branches.len()) - 1;
    let mut acc = 0u64;
    for _ in 0..4 {
        let p = dut.step(true, miso);
        miso = adc.drive(0, &p);
    }
    for c in 0..frames * s.grid.frame_cycles {
        let p = dut.step(false, miso);
        miso = adc.drive(c, &p);
        acc = acc.wrapping_add(p.sample_value as u64);
    }
    acc
}

/// The slot-level back end: every conversion of `frames` frames from the
/// periodic frame template, with the stimulus' codes, through the
/// conversion-level invariants (counts, intervals, sample stream), plus the
/// per-branch timing checks that do not need cycles (SPI numbers against
/// the ADC's limits, CS spacing against the quiet time, mux settling).
pub fn run_model(s: &Schedule, frames: u64, stimulus: Stimulus, max_records: usize) -> Verdict {
    let sm = SlotModel::new(s);
    let analog = Analog::new(s, stimulus);
    let mut inv = Invariants::new(s, max_records);
    static_checks(s, &sm, &mut inv);
    let f = s.grid.frame_cycles;
    // A converter with a command word: its first conversions after reset
    // are prepared, never data (`Schedule::prepared_conversions`).
    let mut prep: Vec<u32> = (0..s.branches.len())
        .map(|b| s.prepared_conversions(b))
        .collect();
    let mut skipped = Vec::new();
    for frame in 0..frames {
        let base = frame * f;
        let (conversions, emissions) = sm.frame(frame);
        for cv in conversions {
            if prep[cv.branch] > 0 {
                prep[cv.branch] -= 1;
                skipped.push((base + cv.instant, cv.branch));
                continue;
            }
            inv.instant(base + cv.instant, cv.branch, cv.channel);
        }
        for cv in emissions {
            let t = base + cv.instant;
            if skipped.contains(&(t, cv.branch)) {
                continue;
            }
            // the input's value where the part holds it: `t` is the
            // conversion's start (after any hold-off), the part's own time later
            let held = t + s.branches[cv.branch].spi.sample_cycles;
            let code =
                analog.code_bits(cv.channel as u64, held, s.mix.branches[cv.branch].adc.bits);
            inv.completion(
                base + cv.complete,
                cv.branch,
                Some(cv.channel),
                Some(code),
                t,
            );
            inv.emitted(base + cv.emit, cv.channel, code);
        }
    }
    let cycles = frames * f;
    let (fr, channels) = inv.finish(cycles);
    let samples = inv.emitted_count();
    inv.report("model", &s.mix.name, cycles, fr, channels, samples)
}

/// The first word of a conversion stands for it (chains give several).
fn sm_first_member(sm: &SlotModel, c: &crate::model::Conversion) -> u16 {
    sm.conversions
        .iter()
        .filter(|o| o.branch == c.branch && o.instant == c.instant)
        .map(|o| o.member)
        .min()
        .unwrap_or(0)
}

fn static_checks(s: &Schedule, sm: &SlotModel, inv: &mut Invariants) {
    use lut_gen::ns_to_cycles;
    use serde_json::json;
    let mix = &s.mix;
    let clock = mix.clock_hz;
    let layout = Layout::new(s);
    for (b, plan) in s.branches.iter().enumerate() {
        let adc = &mix.branches[b].adc;
        let spi = &plan.spi;
        let d = spi.sclk_div;
        let sig = Some(Signal::Sclk(b).name(&layout));
        if d * adc.sclk_max_hz < clock || d * adc.sclk_min_hz > clock {
            inv.record(
                Violation::new(Rule::SclkFrequency, 0)
                    .signal(sig.clone())
                    .expected(json!(adc.sclk_max_hz))
                    .actual(json!(clock / d))
                    .detail(format!("branch {}: SCLK divider {d}", plan.name)),
            );
        }
        let (lo, hi) = (spi.sclk_half, d - spi.sclk_half);
        if lo * 100 < d * adc.duty_min_pct as u64 || hi * 100 < d * adc.duty_min_pct as u64 {
            inv.record(
                Violation::new(Rule::SclkDuty, 0)
                    .signal(sig.clone())
                    .detail(format!(
                        "branch {}: SCLK low {lo} / high {hi} cycles",
                        plan.name
                    )),
            );
        }
        if spi.setup_cycles
            < ns_to_cycles(adc.conversion_ns, clock) + ns_to_cycles(adc.setup_ns, clock).max(1)
        {
            inv.record(
                Violation::new(Rule::CsSetup, 0)
                    .signal(Signal::CsN(b).name(&layout))
                    .detail(format!(
                        "branch {}: setup {} cycles",
                        plan.name, spi.setup_cycles
                    )),
            );
        }
        let quiet = ns_to_cycles(adc.quiet_ns, clock).max(1);
        let settle = ns_to_cycles(mix.branches[b].settle_ns, clock);
        let inst: Vec<u64> = sm
            .conversions
            .iter()
            .filter(|c| c.branch == b && c.member == sm_first_member(sm, c))
            .map(|c| c.instant)
            .collect();
        for (i, &t) in inst.iter().enumerate() {
            let next = if i + 1 < inst.len() {
                inst[i + 1]
            } else {
                inst[0] + s.grid.frame_cycles
            };
            let gap = next - t;
            if gap < spi.read_cycles + quiet {
                inv.record(
                    Violation::new(Rule::CsQuiet, next % s.grid.frame_cycles)
                        .signal(Signal::CsN(b).name(&layout))
                        .expected(json!(spi.read_cycles + quiet))
                        .actual(json!(gap))
                        .detail(format!(
                            "branch {}: conversions {gap} cycles apart",
                            plan.name
                        )),
                );
            }
            if gap.saturating_sub(1) < settle {
                inv.record(
                    Violation::new(Rule::MuxSettle, next % s.grid.frame_cycles)
                        .signal(Signal::MuxSel(b).name(&layout))
                        .expected(json!(settle))
                        .actual(json!(gap - 1))
                        .detail(format!(
                            "branch {}: mux has {} cycles to settle",
                            plan.name,
                            gap - 1
                        )),
                );
            }
        }
    }
}
