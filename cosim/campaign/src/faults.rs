//! The fault campaign: every class of fault injected at many sites across
//! the frame (every branch; the first and last slot; frame and slice
//! boundaries; mid-frame), each run checked in full, plus clean runs over
//! random feasible mixes that must not be rejected (false alarms).
//!
//! Classes come at three levels: pin faults (`judge::PinFault`: a
//! wrong sample, a CS window late, an extra SCLK edge, a mux late or wrong,
//! two mux devices on), a reset glitch the design suffers while its `rst`
//! port stays low, and design-level faults built into the gateware itself
//! (`hdl::GatewareFault`: a slot-ROM word changed to another channel's, two
//! words swapped, the slot counter wrapping one early or late, the slice
//! counter off by one), which only the `rusthdl` target can carry.
//!
//! Every run is judged by each detector on its own ([`Detector`]: the
//! cycle-by-cycle comparison with the model, the model-free invariants,
//! sigrok's SPI decode of the pins, `prove`), so the campaign is a matrix of
//! fault class x detector that can show what each one misses.  An injection
//! no detector catches is undetected; a gateware fault is let off only when
//! it is proved equivalent to the clean gateware at the ports for all time
//! ([`crate::equiv`]).

use std::collections::BTreeMap;
use std::time::Instant;

use judge::Verdict;
use judge::{run_dut, Dut, ModelDut};
use judge::{FaultyDut, PinFault};
use lut_gen::Schedule;
use serde::Serialize;

use crate::equiv::Equivalence;
use crate::sigrok::SpiCapture;
use engines::Backend;
use engines::RustHdlDut;
use engines::SimError;

mod class;
mod methods;
mod modes;
mod verilog;
pub use class::{FaultClass, Level};
pub use methods::{methods, sample as methods_sample, Engine, MethodRun};
pub use verilog::{
    deep_faults, gateware_as_verilog, prove, prove_in, prove_unavailable, ProveVerdict,
    VerilogFault,
};

/// A detector of the judge, measured apart from the others.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Detector {
    /// Every pin in every cycle against the cycle-level reference model.
    Model,
    /// The mix's invariants, without the model: counts, intervals,
    /// settling, SCLK count and period, stream order and content.
    Invariants,
    /// sigrok-cli's SPI decoder on CS, SCLK and MISO against the emitted
    /// samples and the schedule's conversion count.
    Sigrok,
    /// The faulty design proving the full contract (`prove`).
    Prove,
}

impl Detector {
    pub const ALL: [Detector; 4] = [
        Detector::Model,
        Detector::Invariants,
        Detector::Sigrok,
        Detector::Prove,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            Detector::Model => "model",
            Detector::Invariants => "invariants",
            Detector::Sigrok => "sigrok",
            Detector::Prove => "prove",
        }
    }

    /// Why this detector has no view of a fault class (at `level`), by design.
    pub fn blind_to(&self, class: &FaultClass, level: Level) -> Option<&'static str> {
        match (self, level) {
            (Detector::Sigrok, _) if class.on_mux_pins() => Some("the SPI decode reads CS, SCLK and MISO only: mux pins are outside its view, and the design emits whatever code MISO carried"),
            (Detector::Prove, Level::Pins | Level::Reset) => Some("the fault is injected into a simulation's pins, not built into a design: prove reads a design, so it has nothing to prove it against"),
            (Detector::Sigrok, _) if class.on_link() => Some("the SPI decode reads CS, SCLK and MISO only: the link's pins are outside its view"),
            (Detector::Sigrok, Level::Pins) if class.on_mode_pin() => Some("the SPI decode reads CS, SCLK and MISO only: the `mode` output is outside its view"),
            _ => None,
        }
    }
}

/// One detector's column of the matrix, with what it cost in this run.
#[derive(Debug, Clone, Serialize)]
pub struct Column {
    pub detector: Detector,
    /// Why it did not run (a tool missing, an opt-in not asked for).
    pub not_run: Option<String>,
    pub detected: u64,
    /// Injections of the classes it can see (0 when it did not run).
    pub injected: u64,
    /// The runs it was timed on, the simulated cycles they judged and the
    /// wall seconds they took (the model and the invariants: a clean run
    /// of the target checked with and without the model; sigrok: every
    /// decode of the campaign; prove: every proof, no cycles).
    pub runs: u64,
    pub cycles: u64,
    pub seconds: f64,
}

/// An engine the faults ran through: how many of the injections that went
/// through it some detector caught, and what a clean run of it cost.
#[derive(Debug, Clone, Serialize)]
pub struct EngineColumn {
    /// `cycle model`, `rusthdl`, `verilator` or `icarus`.
    pub engine: &'static str,
    pub detected: u64,
    pub injected: u64,
    /// One clean run of the campaign's frames under the checker.
    pub cycles: u64,
    pub seconds: f64,
}

impl Column {
    /// Share of injections it caught (0 when it did not run).
    pub fn share(&self) -> f64 {
        if self.injected == 0 {
            0.0
        } else {
            self.detected as f64 / self.injected as f64
        }
    }
}

/// The design the faults go into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Target {
    /// The cycle-level reference model's pins (pin faults and reset glitches).
    Model,
    /// The gateware in rust-hdl's simulator (every class).
    Rusthdl,
}

impl Target {
    /// The target in words, for reports.
    pub fn describe(&self) -> &'static str {
        match self {
            Target::Model => "the cycle model's pins",
            Target::Rusthdl => "the gateware in rust-hdl's simulator",
        }
    }
}

/// A place in the frame where faults land.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Site {
    pub name: &'static str,
    /// Cycle of the run (from cycle 0) at or after which the fault lands.
    pub cycle: u64,
    /// The frame slot of that cycle.
    pub slot: u64,
}

/// One injection and what the checker made of it.
#[derive(Debug, Clone, Serialize)]
pub struct Injection {
    pub fault: String,
    /// The engine it ran on (`cycle model`, `rusthdl`, `verilator`, `icarus`).
    pub engine: &'static str,
    pub site: &'static str,
    pub cycle: u64,
    /// Detectors (that ran) which rejected the run.
    pub detected_by: Vec<Detector>,
    pub divergences: u64,
    pub violations: u64,
    /// Invariant rules broken (first few).
    pub rules: Vec<String>,
    /// sigrok's first complaint.
    pub sigrok: Option<String>,
    /// Gateware faults no detector caught: the equivalence check's answer.
    pub equivalence: Option<Equivalence>,
    /// `prove` on the faulty design (when it ran).
    pub prove: Option<ProveVerdict>,
}

/// A class of fault over all its sites.
#[derive(Debug, Clone, Serialize)]
pub struct ClassOutcome {
    pub name: FaultClass,
    pub level: Level,
    /// Injections (proved-equivalent ones included).
    pub injected: u64,
    /// Injections some detector caught.
    pub detected: u64,
    /// Per detector that ran: injections it caught.
    pub detected_by: BTreeMap<Detector, u64>,
    /// Per detector with no view of this class: why.
    pub cannot_see: BTreeMap<Detector, String>,
    /// Injections no detector caught and no proof excuses.
    pub undetected: Vec<Injection>,
    /// Gateware faults no detector caught, proved equivalent to the clean
    /// gateware at the ports for all time.
    pub proved_equivalent: Vec<Injection>,
}

/// Clean runs over random feasible mixes.
#[derive(Debug, Clone, Serialize)]
pub struct FalseAlarms {
    pub mixes: u64,
    pub runs: u64,
    /// Clean runs the checker wrongly rejected.
    pub rejected: u64,
    pub examples: Vec<String>,
}

/// The whole campaign.
#[derive(Debug, Clone, Serialize)]
pub struct Campaign {
    pub mix: String,
    pub target: Target,
    pub sites: Vec<Site>,
    /// The detectors' names, in column order.
    pub detectors: Vec<Detector>,
    /// The matrix's columns: per detector, its total and its cost.
    pub columns: Vec<Column>,
    /// The engines the faults ran through, each with its total and cost.
    pub engines: Vec<EngineColumn>,
    /// Frames per run (the simulated time one injection covers).
    pub frames: u64,
    pub clock_hz: u64,
    /// The AXI4-Stream slave's `tready` pattern in every run ([`TREADY`];
    /// `None` without an AXI4-Stream link).
    pub tready: Option<String>,
    pub classes: Vec<ClassOutcome>,
    pub injected: u64,
    pub detected: u64,
    pub undetected: u64,
    pub proved_equivalent: u64,
    pub false_alarms: FalseAlarms,
    /// The mix's own clean run: when it fails, no fault was injected.
    pub clean: CleanRun,
}

impl Campaign {
    /// Nothing undetected and no clean run rejected.
    pub fn ok(&self) -> bool {
        self.clean.ok && self.undetected == 0 && self.false_alarms.rejected == 0
    }

    pub fn column(&self, d: Detector) -> Option<&Column> {
        self.columns.iter().find(|c| c.detector == d)
    }
}

/// The sites of a schedule: the start of frame 1 (a frame boundary, its
/// first slot), the start of slice 1 of frame 1 (a slice boundary), the
/// middle of frame 1 and the last slot of frame 1.
pub fn sites(s: &Schedule) -> Vec<Site> {
    let g = &s.grid;
    let f = g.frame_cycles;
    let slot = |c: u64| (c % f) / g.slot_cycles;
    let mut v = vec![Site {
        name: "frame-start",
        cycle: f,
        slot: 0,
    }];
    if g.slices_per_frame > 1 {
        let c = f + g.slots_per_slice * g.slot_cycles;
        v.push(Site {
            name: "slice-boundary",
            cycle: c,
            slot: slot(c),
        });
    }
    let mid = f + f / 2 + 7;
    v.push(Site {
        name: "mid-frame",
        cycle: mid,
        slot: slot(mid),
    });
    let last = f + (g.frame_slots - 1) * g.slot_cycles;
    v.push(Site {
        name: "last-slot",
        cycle: last,
        slot: g.frame_slots - 1,
    });
    v
}

/// The work of the detectors that are not the checker, per injection.
#[derive(Debug, Clone, Copy, Default)]
struct Cost {
    sigrok_runs: u64,
    sigrok_cycles: u64,
    sigrok_seconds: f64,
    prove_runs: u64,
    prove_seconds: f64,
}

impl Cost {
    fn add(self, o: Cost) -> Cost {
        Cost {
            sigrok_runs: self.sigrok_runs + o.sigrok_runs,
            sigrok_cycles: self.sigrok_cycles + o.sigrok_cycles,
            sigrok_seconds: self.sigrok_seconds + o.sigrok_seconds,
            prove_runs: self.prove_runs + o.prove_runs,
            prove_seconds: self.prove_seconds + o.prove_seconds,
        }
    }
}

/// A run judged by every detector that runs.
struct Judged {
    report: Verdict,
    /// sigrok's verdict (`None`: not run).
    sigrok: Option<Result<(), String>>,
    cost: Cost,
}

impl Judged {
    /// sigrok's decode of `cap` (the pins of this run), timed.
    fn decode(
        &mut self,
        s: &Schedule,
        cap: &SpiCapture,
        frames: u64,
        dir: &std::path::Path,
    ) -> Result<(), String> {
        let t = Instant::now();
        self.sigrok = Some(sigrok_verdict(s, cap, frames, dir)?);
        self.cost.sigrok_runs += 1;
        self.cost.sigrok_cycles += (frames - 1) * s.grid.frame_cycles;
        self.cost.sigrok_seconds += t.elapsed().as_secs_f64();
        Ok(())
    }

    fn detected_by(&self) -> Vec<Detector> {
        let r = &self.report;
        let mut v = Vec::new();
        if r.model_compared && r.divergence_count > 0 {
            v.push(Detector::Model);
        }
        if r.violation_count > 0 {
            v.push(Detector::Invariants);
        }
        if matches!(self.sigrok, Some(Err(_))) {
            v.push(Detector::Sigrok);
        }
        v
    }
}

/// Runs `dut` for `frames` frames under the checker (model comparison and
/// invariants, counted apart) and, with `sigrok`, decodes its SPI pins.
fn judge_run(s: &Schedule, dut: &mut dyn Dut, frames: u64, sigrok: bool) -> Result<Judged, String> {
    let opts = modes::run_options(s, frames);
    if !sigrok {
        let report = run_dut(s, dut, frames, &opts, "faults", None);
        return Ok(Judged {
            report,
            sigrok: None,
            cost: Cost::default(),
        });
    }
    let mut cap = SpiCapture::new(s, judge::reset_cycles(s, opts.reset_cycles));
    let report = run_dut(s, dut, frames, &opts, "faults", Some(&mut cap));
    let mut j = Judged {
        report,
        sigrok: None,
        cost: Cost::default(),
    };
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    j.decode(s, &cap, frames, dir.path())?;
    Ok(j)
}

fn outcome(fault: String, site: &Site, j: &Judged, engine: &'static str) -> Injection {
    let r = &j.report;
    let mut rules: Vec<String> = Vec::new();
    for v in &r.violations {
        if rules.len() < 4 && !rules.contains(&v.rule) {
            rules.push(v.rule.clone());
        }
    }
    Injection {
        fault,
        engine,
        site: site.name,
        cycle: site.cycle,
        detected_by: j.detected_by(),
        divergences: r.divergence_count,
        violations: r.violation_count,
        rules,
        sigrok: j.sigrok.clone().and_then(|v| v.err()),
        equivalence: None,
        prove: None,
    }
}

/// One design-level fault at one site.
#[derive(Debug, Clone, Copy)]
struct DesignCase {
    fault: hdl::GatewareFault,
    site: Site,
}

/// The ROM faults of branch `b` at `site`: the branch's first conversion
/// slot at or after the site's slot (cyclically) gets the word of the next
/// slot converting another channel, or is swapped with it.
fn rom_cases(s: &Schedule, b: usize, site: Site) -> Vec<DesignCase> {
    let n = s.grid.frame_slots;
    let conv: Vec<(u64, usize)> = (0..n).filter_map(|u| s.at(u, b).map(|c| (u, c))).collect();
    let Some(i) = conv
        .iter()
        .position(|&(u, _)| u >= site.slot)
        .or(if conv.is_empty() { None } else { Some(0) })
    else {
        return vec![];
    };
    let (u, ch) = conv[i];
    let Some(&(other, _)) = (1..conv.len())
        .map(|k| &conv[(i + k) % conv.len()])
        .find(|&&(_, c)| c != ch)
    else {
        return vec![];
    };
    vec![
        DesignCase {
            fault: hdl::GatewareFault::RomWord {
                branch: b,
                slot: u,
                from: other,
            },
            site,
        },
        DesignCase {
            fault: hdl::GatewareFault::RomSwap {
                branch: b,
                a: u,
                b: other,
            },
            site,
        },
    ]
}

/// One design-level fault of each class, at the middle of frame 0 on the
/// first branch that has two channels (ROM faults): what the analyser
/// captures of faulty gateware are tested with.
pub fn one_gateware_fault_per_class(s: &Schedule) -> Vec<(FaultClass, hdl::GatewareFault)> {
    let f = s.grid.frame_cycles;
    let mid = f / 2 + 7;
    let site = Site {
        name: "mid-frame",
        cycle: mid,
        slot: (mid % f) / s.grid.slot_cycles,
    };
    let mut v: Vec<hdl::GatewareFault> = (0..s.branches.len())
        .map(|b| rom_cases(s, b, site))
        .find(|c| !c.is_empty())
        .unwrap_or_default()
        .into_iter()
        .map(|c| c.fault)
        .collect();
    v.push(hdl::GatewareFault::SlotWrap { delta: -1 });
    v.push(hdl::GatewareFault::SlotWrap { delta: 1 });
    if s.grid.slices_per_frame > 1 {
        v.push(hdl::GatewareFault::SliceWrap { delta: -1 });
        v.push(hdl::GatewareFault::SliceWrap { delta: 1 });
    }
    v.extend(
        hdl::GatewareFault::link_faults(s)
            .into_iter()
            .chain(hdl::GatewareFault::mode_faults(s))
            .map(|(_, f)| f),
    );
    v.into_iter()
        .map(|f| (FaultClass::of_gateware(f), f))
        .collect()
}

/// `hdl::RtlSim` with a design-level fault built in, as a [`Dut`] (behind
/// the campaign's slave for an AXI4-Stream link).
pub fn gateware_dut(s: &Schedule, f: hdl::GatewareFault) -> Result<Box<dyn Dut>, SimError> {
    hdl::RtlSim::with_fault(s, f)
        .map(|sim| slave(s, modes::with_requests(s, Box::new(GatewareDut(sim)))))
        .map_err(|e| SimError::Hdl(e.to_string()))
}

/// A progress display's hook ([`Plan::on_run`]): called with (runs done,
/// runs in all) after every run of the campaign (an injection, a clean run,
/// a false-alarm mix), from whichever worker thread finished it.
#[derive(Clone)]
pub struct OnRun(pub std::sync::Arc<dyn Fn(u64, u64) + Send + Sync>);

impl std::fmt::Debug for OnRun {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("OnRun")
    }
}

/// The campaign's run count, told to [`Plan::on_run`].
struct Runs<'a> {
    hook: Option<&'a OnRun>,
    done: std::sync::atomic::AtomicU64,
    total: u64,
}

impl Runs<'_> {
    fn one(&self) {
        let done = 1 + self.done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if let Some(h) = self.hook {
            (h.0)(done.min(self.total), self.total);
        }
    }
}

/// Runs `jobs` on up to two threads (the machine's cores), in order,
/// counting each finished job in `runs`.
fn parallel<T: Send, R: Send>(jobs: Vec<T>, runs: &Runs, f: impl Fn(T) -> R + Sync) -> Vec<R> {
    let n = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .clamp(1, 4);
    let mut slots: Vec<Option<R>> = (0..jobs.len()).map(|_| None).collect();
    let queue = std::sync::Mutex::new(jobs.into_iter().enumerate().collect::<Vec<_>>());
    let results = std::sync::Mutex::new(&mut slots);
    std::thread::scope(|sc| {
        for _ in 0..n {
            sc.spawn(|| loop {
                let job = queue.lock().expect("queue").pop();
                let Some((i, j)) = job else { break };
                let r = f(j);
                runs.one();
                results.lock().expect("results")[i] = Some(r);
            });
        }
    });
    slots
        .into_iter()
        .map(|r| r.expect("every job ran"))
        .collect()
}

/// What the campaign runs: the target of the built-in classes, the
/// Verilog faults and their engines, and whether `prove` runs.
#[derive(Debug, Clone)]
pub struct Plan {
    pub target: Target,
    /// Frames per run (at least 3: faults land in frame 1, and the next
    /// frame shows what a fault left behind).
    pub frames: u64,
    /// Random feasible mixes run clean.
    pub false_alarm_mixes: u64,
    /// The target's own classes (pin faults, reset glitches, and on the
    /// gateware its design-level faults); off, only the Verilog faults run.
    pub builtin: bool,
    /// Faulty designs as Verilog (mutants, deep faults).
    pub verilog_faults: Vec<VerilogFault>,
    /// The engines the Verilog faults run on (verilator, icarus).
    pub verilog_engines: Vec<Backend>,
    /// `prove` as a detector of every fault that is a design (opt-in:
    /// proofs take minutes on a 48 MHz mix).
    pub prove: bool,
    /// Where faults land (`None`: every site of [`sites`]; `build`'s quick
    /// default runs every class at the mid-frame site only).
    pub sites: Option<Vec<Site>>,
    /// Told every finished run, for a progress display (runs done of N).
    pub on_run: Option<OnRun>,
    /// sigrok's SPI decode as a detector (when sigrok-cli is installed);
    /// `build`'s quick campaign leaves it out: its decodes were most of the
    /// campaign's time, and the model and the invariants judge every run.
    pub sigrok: bool,
}

impl Plan {
    pub fn new(target: Target, frames: u64, false_alarm_mixes: u64) -> Plan {
        Plan {
            target,
            frames,
            false_alarm_mixes,
            builtin: true,
            verilog_faults: vec![],
            verilog_engines: vec![],
            prove: false,
            sites: None,
            on_run: None,
            sigrok: true,
        }
    }
}

/// Why a detector does not run here (`None`: it runs).
fn not_run(d: Detector, plan: &Plan) -> Option<String> {
    match d {
        Detector::Model | Detector::Invariants => None,
        Detector::Sigrok if !plan.sigrok => Some(
            "not run: left out of the quick campaign (`build --thorough`, `--charts all` or `slotforge faults` run it)".into(),
        ),
        Detector::Sigrok => crate::sigrok::available().err().map(|e| e.to_string()),
        Detector::Prove if !plan.prove => Some(
            "not run: opt-in (`faults --prove`; a proof takes seconds on a small-frame mix, minutes on a 48 MHz one)".into(),
        ),
        Detector::Prove => prove_unavailable().map(|why| format!("not run: {why}")),
    }
}

/// One judged injection: its class, level and outcome, and the work of the
/// detectors besides the checker.
type Judgement = (FaultClass, Level, Injection, Cost);

/// The AXI4-Stream slave of every in-process run of the campaign: the worst
/// case the mix's guarantee allows (every beat accepted in its
/// `ready_within`-th cycle), so the FIFO reaches the backlog its depth is
/// computed for (an always-ready slave would hide a FIFO one token short)
/// and every beat waits (where the stall faults land).
pub const TREADY: link::ReadyPattern = link::ReadyPattern::WorstCase;

/// `dut` behind the campaign's slave when `s`'s link is AXI4-Stream.
fn slave(s: &Schedule, dut: Box<dyn Dut>) -> Box<dyn Dut> {
    judge::with_slave(s, dut, TREADY)
}

/// The design the faults go into, built for `s`, behind the campaign's slave.
fn target_dut(s: &Schedule, target: Target) -> Result<Box<dyn Dut>, SimError> {
    let d: Box<dyn Dut> = match target {
        // a mix with modes runs its switching scenario
        Target::Model => modes::with_requests(s, Box::new(ModelDut::new(s))),
        Target::Rusthdl => modes::with_requests(s, Box::new(RustHdlDut::new(s)?)),
    };
    Ok(slave(s, d))
}

/// The engine name of a target.
fn engine_name(t: Target) -> &'static str {
    match t {
        Target::Model => "cycle model",
        Target::Rusthdl => "rusthdl",
    }
}

/// The pin faults and reset glitches at every site.
fn pin_injections(
    s: &Schedule,
    target: Target,
    sites: &[Site],
    frames: u64,
    sigrok: bool,
    count: &Runs,
) -> Result<Vec<Judgement>, String> {
    let mut jobs = Vec::new();
    for site in sites {
        for f in PinFault::all(s).into_iter().filter(|f| !f.is_mode()) {
            jobs.push((f, *site));
        }
    }
    // the `mode` faults at the scenario's frame starts
    for f in PinFault::all(s).into_iter().filter(PinFault::is_mode) {
        jobs.extend(modes::mode_site(s, f, frames).map(|site| (f, site)));
    }
    let runs = parallel(
        jobs,
        count,
        |(f, site)| -> Result<Option<Judgement>, String> {
            let inner = target_dut(s, target).map_err(|e| e.to_string())?;
            let mut dut = FaultyDut::new(s, inner, f, site.cycle);
            let j = judge_run(s, &mut dut, frames, sigrok)?;
            let level = if f == PinFault::ResetGlitch {
                Level::Reset
            } else {
                Level::Pins
            };
            // a fault that found nothing to change was not injected
            Ok(dut.injected().then(|| {
                (
                    FaultClass::of_pins(f),
                    level,
                    outcome(f.name(), &site, &j, engine_name(target)),
                    j.cost,
                )
            }))
        },
    );
    Ok(runs
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .flatten()
        .collect())
}

/// The design-level faults of the gateware at every site.
fn design_cases(s: &Schedule, sites: &[Site]) -> Vec<DesignCase> {
    let mut design = Vec::new();
    for site in sites {
        for b in 0..s.branches.len() {
            design.extend(rom_cases(s, b, *site));
        }
    }
    for delta in [-1, 1] {
        design.push(DesignCase {
            fault: hdl::GatewareFault::SlotWrap { delta },
            site: sites[0],
        });
    }
    if s.grid.slices_per_frame > 1 {
        for delta in [-1, 1] {
            design.push(DesignCase {
                fault: hdl::GatewareFault::SliceWrap { delta },
                site: sites[0],
            });
        }
    }
    // the link stage's faults (a mix with a [link]), the mode block's (modes)
    let more = hdl::GatewareFault::link_faults(s)
        .into_iter()
        .chain(hdl::GatewareFault::mode_faults(s));
    for (_, fault) in more {
        design.push(DesignCase {
            fault,
            site: sites[0],
        });
    }
    design
}

/// The design-level faults, each judged (and proved, with `prove`); an
/// uncaught one goes to the equivalence check.
fn gateware_injections(
    s: &Schedule,
    sites: &[Site],
    frames: u64,
    sigrok: bool,
    prove: bool,
    count: &Runs,
) -> Result<Vec<Judgement>, String> {
    let runs = parallel(
        design_cases(s, sites),
        count,
        |c| -> Result<Option<Judgement>, String> {
            let class = FaultClass::of_gateware(c.fault);
            let name = format!("{class}: {}", c.fault);
            // a fault the mix's gateware cannot hold (e.g. a frame too long for the full LUT)
            let Ok(sim) = hdl::RtlSim::with_fault(s, c.fault) else {
                return Ok(None);
            };
            let mut dut = slave(s, modes::with_requests(s, Box::new(GatewareDut(sim))));
            let mut j = judge_run(s, &mut dut, frames, sigrok)?;
            let mut inj = outcome(name, &c.site, &j, "rusthdl");
            let pair = hdl::verilog_pair(s, c.fault).map_err(|e| e.to_string());
            let verdict = match (&pair, prove) {
                (Ok((_, gate)), true) => {
                    let (v, secs) = verilog::prove(s, gate);
                    j.cost.prove_runs += 1;
                    j.cost.prove_seconds += secs;
                    Some(v)
                }
                (Err(e), true) => Some(ProveVerdict::NoVerdict { why: e.clone() }),
                _ => None,
            };
            verilog::settle(&mut inj, verdict.as_ref(), || match &pair {
                Ok((gold, gate)) => verilog::equivalence(gold, gate),
                Err(e) => Equivalence::Undecided {
                    why: format!("no Verilog for the fault: {e}"),
                },
            });
            Ok(Some((class, Level::Gateware, inj, j.cost)))
        },
    );
    Ok(runs
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .flatten()
        .collect())
}

/// The matrix: injections grouped by class, counted per detector.
fn classes(judged: Vec<Judgement>, ran: &[Detector]) -> Vec<ClassOutcome> {
    let mut classes: Vec<ClassOutcome> = Vec::new();
    for (class, level, inj, _) in judged {
        // a class at two levels (mode-stuck on the pins, in the gateware) is two rows
        let c = match classes
            .iter()
            .position(|c| c.name == class && c.level == level)
        {
            Some(i) => &mut classes[i],
            None => {
                let cannot_see: BTreeMap<Detector, String> = Detector::ALL
                    .iter()
                    .filter_map(|d| Some((*d, d.blind_to(&class, level)?.to_string())))
                    .collect();
                classes.push(ClassOutcome {
                    name: class,
                    level,
                    injected: 0,
                    detected: 0,
                    detected_by: ran.iter().map(|&d| (d, 0)).collect(),
                    cannot_see,
                    undetected: vec![],
                    proved_equivalent: vec![],
                });
                classes.last_mut().expect("just pushed")
            }
        };
        c.injected += 1;
        for d in &inj.detected_by {
            *c.detected_by.entry(*d).or_default() += 1;
        }
        if !inj.detected_by.is_empty() {
            c.detected += 1;
        } else if inj.equivalence.as_ref().is_some_and(Equivalence::is_proof) {
            c.proved_equivalent.push(inj);
        } else {
            c.undetected.push(inj);
        }
    }
    classes
}

/// The columns: per detector its totals over the classes it can see, and
/// its cost measured now (the checker on a clean run of the target with
/// and without the model; sigrok's decodes and prove's proofs summed over
/// the campaign).
fn columns(
    plan: &Plan,
    classes: &[ClassOutcome],
    cost: Cost,
    clean: &[(u64, f64); 2],
) -> Vec<Column> {
    Detector::ALL
        .iter()
        .map(|&d| {
            let why = not_run(d, plan);
            let (runs, cycles, seconds) = match d {
                _ if why.is_some() => (0, 0, 0.0),
                Detector::Model => (1, clean[0].0, clean[0].1),
                Detector::Invariants => (1, clean[1].0, clean[1].1),
                Detector::Sigrok => (cost.sigrok_runs, cost.sigrok_cycles, cost.sigrok_seconds),
                Detector::Prove => (cost.prove_runs, 0, cost.prove_seconds),
            };
            // what it caught of the classes it can see, over their injections
            let seen = classes.iter().filter(|c| !c.cannot_see.contains_key(&d));
            Column {
                detector: d,
                detected: seen
                    .clone()
                    .map(|c| c.detected_by.get(&d).copied().unwrap_or(0))
                    .sum(),
                injected: if why.is_some() {
                    0
                } else {
                    seen.map(|c| c.injected).sum()
                },
                not_run: why,
                runs,
                cycles,
                seconds,
            }
        })
        .collect()
}

/// A clean run of the target under the checker, with and without the
/// model, timed: [(cycles, seconds) with the model, without].  With
/// `sigrok`, its decode judges the run with the model too, as it judges
/// every fault's: a decode that rejected every run would "catch" every
/// fault, and the campaign would vouch for it.
fn clean_target_runs(
    s: &Schedule,
    target: Target,
    frames: u64,
    sigrok: bool,
) -> ([(u64, f64); 2], CleanRun) {
    let timed = |model: bool| -> (u64, f64, Option<String>) {
        let Ok(mut dut) = target_dut(s, target) else {
            return (
                0,
                0.0,
                Some(format!("{} could not be built", engine_name(target))),
            );
        };
        let mut opts = modes::run_options(s, frames);
        opts.check.model = model;
        let reset = judge::reset_cycles(s, opts.reset_cycles);
        let mut cap = (sigrok && model).then(|| SpiCapture::new(s, reset));
        let obs = cap.as_mut().map(|c| c as &mut dyn judge::Observer);
        let t = Instant::now();
        let r = run_dut(s, &mut dut, frames, &opts, "clean", obs);
        let seconds = t.elapsed().as_secs_f64();
        let why = match (r.ok, &cap) {
            (false, _) => Some(r.summary().trim_end().to_string()),
            (true, Some(cap)) => sigrok_rejects(s, cap, frames),
            (true, None) => None,
        };
        (r.cycles, seconds, why)
    };
    let (a, b) = (timed(true), timed(false));
    let clean = CleanRun {
        engine: engine_name(target),
        cycles: a.0,
        ok: a.2.is_none(),
        why: a.2,
    };
    ([(a.0, a.1), (b.0, b.1)], clean)
}

/// sigrok's verdict on `cap` as the campaign takes it: a pass while the
/// test switch turns the detector off.  The one place that reads the
/// switch, for the faulty runs ([`Judged::decode`]) and the clean one
/// ([`sigrok_rejects`]); `sigrok::check` itself stays the detector.
fn sigrok_verdict(
    s: &Schedule,
    cap: &SpiCapture,
    frames: u64,
    dir: &std::path::Path,
) -> Result<Result<(), String>, String> {
    if judge::switch::disabled("sigrok") {
        return Ok(Ok(()));
    }
    crate::sigrok::check(s, cap, frames, dir)
}

/// Why sigrok's decode rejects the clean run captured in `cap`, if it does.
fn sigrok_rejects(s: &Schedule, cap: &SpiCapture, frames: u64) -> Option<String> {
    let verdict = tempfile::tempdir()
        .map_err(|e| e.to_string())
        .and_then(|dir| sigrok_verdict(s, cap, frames, dir.path()));
    match verdict {
        Ok(Ok(())) => None,
        Ok(Err(e)) => Some(format!("sigrok's decode: {e}")),
        Err(e) => Some(format!("sigrok could not decode the run: {e}")),
    }
}

/// The mix's own clean run on the campaign's target, checked against the
/// model: unless it passes, no detection means anything (a checker that
/// rejects the clean design "detects" every fault), so none is reported.
#[derive(Debug, Clone, Serialize)]
pub struct CleanRun {
    pub engine: &'static str,
    pub cycles: u64,
    pub ok: bool,
    /// Why it failed: the verdict's summary.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub why: Option<String>,
}

/// Per engine: injections through it, those some detector caught, and a
/// clean run's cost.
fn engine_columns(judged: &[Judgement], costs: &[(&'static str, u64, f64)]) -> Vec<EngineColumn> {
    costs
        .iter()
        .map(|&(engine, cycles, seconds)| {
            let mine = judged.iter().filter(|j| j.2.engine == engine);
            EngineColumn {
                engine,
                injected: mine.clone().count() as u64,
                detected: mine.filter(|j| !j.2.detected_by.is_empty()).count() as u64,
                cycles,
                seconds,
            }
        })
        .collect()
}

/// The campaign of `plan` on `s`.
pub fn campaign_with(s: &Schedule, plan: &Plan) -> Result<Campaign, SimError> {
    let frames = plan.frames.max(3);
    let target = plan.target;
    let sites = plan.sites.clone().unwrap_or_else(|| sites(s));
    if target == Target::Rusthdl {
        RustHdlDut::new(s)?;
    }
    let ran: Vec<Detector> = Detector::ALL
        .into_iter()
        .filter(|d| not_run(*d, plan).is_none())
        .collect();
    let sigrok = ran.contains(&Detector::Sigrok);
    let prove = ran.contains(&Detector::Prove);
    let count = Runs {
        hook: plan.on_run.as_ref(),
        done: 0.into(),
        total: planned_runs(s, plan, &sites),
    };
    // the mix's own clean run first: a campaign on a design that fails
    // clean would vouch for nothing
    let (clean, clean_run) = clean_target_runs(s, target, frames, sigrok);
    count.one();
    let judge_faults = plan.builtin && clean_run.ok;
    let mut judged = Vec::new();
    if judge_faults {
        judged = pin_injections(s, target, &sites, frames, sigrok, &count).map_err(SimError::Io)?;
    }
    if judge_faults && target == Target::Rusthdl {
        judged.extend(
            gateware_injections(s, &sites, frames, sigrok, prove, &count).map_err(SimError::Io)?,
        );
    }
    let mut engine_costs = Vec::new();
    if plan.builtin {
        engine_costs.push((engine_name(target), clean[0].0, clean[0].1));
    }
    let mut false_alarms = counted_false_alarms(target, plan.false_alarm_mixes, sigrok, &count);
    if !plan.verilog_faults.is_empty() && clean_run.ok {
        for &e in &plan.verilog_engines {
            let (cycles, secs, why) =
                verilog::clean_engine_run(s, e, frames, sigrok).map_err(SimError::Io)?;
            count.one();
            engine_costs.push((e.name(), cycles, secs));
            false_alarms.runs += 1;
            if let Some(why) = why {
                false_alarms.rejected += 1;
                false_alarms
                    .examples
                    .push(format!("{} on the clean Verilog: {why}", e.name()));
            }
        }
        judged.extend(
            verilog::verilog_injections(
                s,
                &plan.verilog_faults,
                &plan.verilog_engines,
                frames,
                sigrok,
                prove,
                &count,
            )
            .map_err(SimError::Io)?,
        );
    }
    let cost = judged.iter().fold(Cost::default(), |a, j| a.add(j.3));
    let engines = engine_columns(&judged, &engine_costs);
    let classes = classes(judged, &ran);
    let columns = columns(plan, &classes, cost, &clean);
    let sum = |f: fn(&ClassOutcome) -> u64| classes.iter().map(f).sum();
    Ok(Campaign {
        mix: s.mix.name.clone(),
        target,
        sites,
        detectors: Detector::ALL.to_vec(),
        columns,
        engines,
        frames,
        clock_hz: s.grid.clock_hz,
        tready: s
            .mix
            .link
            .filter(|l| l.kind == lut_gen::LinkKind::Axis)
            .map(|_| TREADY.name()),
        injected: sum(|c| c.injected),
        detected: sum(|c| c.detected),
        undetected: sum(|c| c.undetected.len() as u64),
        proved_equivalent: sum(|c| c.proved_equivalent.len() as u64),
        classes,
        false_alarms,
        clean: clean_run,
    })
}

/// The runs `campaign_with` makes for `plan`, counted the way [`Runs`]
/// counts them: every injection job, the target's clean runs as one, each
/// false-alarm mix, and each Verilog engine's clean run.
fn planned_runs(s: &Schedule, plan: &Plan, sites: &[Site]) -> u64 {
    let mut n = 1 + plan.false_alarm_mixes;
    if plan.builtin {
        let all = PinFault::all(s);
        let mode = all.iter().filter(|f| f.is_mode()).count();
        n += (sites.len() * (all.len() - mode) + mode) as u64;
        if plan.target == Target::Rusthdl {
            n += design_cases(s, sites).len() as u64;
        }
    }
    if !plan.verilog_faults.is_empty() {
        let e = plan.verilog_engines.len() as u64;
        n += e + e * plan.verilog_faults.len() as u64;
    }
    n
}

/// `hdl::RtlSim` with a fault built in, as a [`Dut`].
struct GatewareDut(hdl::RtlSim);

impl Dut for GatewareDut {
    fn step(&mut self, rst: bool, miso: u64) -> lut_gen::Pins {
        self.0.step(rst, miso)
    }
    fn set_tready(&mut self, ready: bool) {
        self.0.set_tready(ready)
    }
    fn set_mode_sel(&mut self, sel: u8) {
        self.0.set_mode_sel(sel)
    }
}

/// Clean runs of `target` over the first `n` feasible mixes of
/// [`random_mix`], judged by every detector (sigrok with `sigrok`), each
/// counted in `count`; every rejection is a false alarm.
fn counted_false_alarms(target: Target, n: u64, sigrok: bool, count: &Runs) -> FalseAlarms {
    let mut fa = FalseAlarms {
        mixes: 0,
        runs: 0,
        rejected: 0,
        examples: vec![],
    };
    let mut seed = 0;
    while fa.mixes < n && seed < 50 * n.max(1) {
        seed += 1;
        let text = random_mix(seed);
        let Ok(mix) = lut_gen::parse(std::path::Path::new("random.toml"), &text) else {
            continue;
        };
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        if lut_gen::Layout::fits(&s).is_err() {
            continue;
        }
        let Ok(mut dut) = target_dut(&s, target) else {
            continue;
        };
        fa.mixes += 1;
        let j = judge_run(&s, &mut dut, 2, sigrok);
        count.one();
        fa.runs += 1;
        let why = match &j {
            Err(e) => Some(format!("sigrok-cli failed: {e}")),
            Ok(j) if !j.report.ok => Some(j.report.summary()),
            Ok(Judged {
                sigrok: Some(Err(e)),
                ..
            }) => Some(format!("sigrok: {e}")),
            Ok(_) => None,
        };
        if let Some(why) = why {
            fa.rejected += 1;
            if fa.examples.len() < 3 {
                fa.examples.push(format!("seed {seed}: {why}"));
            }
        }
    }
    fa
}

/// A random mix (TOML text) of 1-3 AD7940 branches with 2 ms frames, 1-3
/// mux devices each, random SCLK and settling, and 2-9 channels at rates
/// from 500 Hz to 8 kHz; some are infeasible on purpose.
fn random_mix(seed: u64) -> String {
    crate::mixgen::random_mix(seed, &crate::mixgen::Shape::default())
}
