//! Time-level checking of a logic-analyser capture: lanes sampled at the
//! analyser's own rate, asynchronous to the design's clock, with no clock
//! and no reset, starting anywhere in a run.
//!
//! The model's edges of every mapped lane over a steady-state frame form a
//! periodic template (cycles).  A capture edge seen at time `t` happened in
//! `(t - T, t]` (T: the sample period), give or take the user's skew, so
//! with `phi` the time of model cycle 0 every edge says
//! `t - T - skew <= phi + cycle * Tc <= t + skew`.  The first conversion start
//! on any mapped CS lane fits some frame positions (candidates); each later
//! edge of each lane must be that lane's next template edge, with the same
//! level, and narrows `phi`'s interval; a candidate whose interval empties
//! is gone.  One candidate left: every later edge that does not fit is a
//! fault, named by its lane's role.  Times are kept exact as integers in
//! units of 1 / (clock_hz) picoseconds.
//!
//! What this proves depends on the resolution `T + 2 skew`: every checked
//! edge within it of the model's time (so every rate, interval, slot order
//! and SCLK count and period to that accuracy); a lane whose edges can come
//! closer than that is not checked; mux settling is proved only where the
//! model's margin exceeds it.

use std::fmt::Write as _;

use lut_gen::Schedule;
use lut_gen::{Layout, Pins, Role, Signal};

pub use crate::capture::line::LineJoin;
use crate::model::CycleModel;

/// One analyser channel mapped to one port bit (`adc_cs_n[0]`), or to a
/// link port's bit (`link_tx`, `m_axis_tdata[3]`: `role` None, `link` the
/// port; decoded, not timed edge by edge).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Lane {
    pub channel: String,
    pub role: Option<Role>,
    pub bit: u32,
    /// The link's port, when `role` is None.
    pub link: Option<Signal>,
    /// A mode port's bit (`mode_sel[i]`, `mode[i]`), when `role` is None.
    pub mode: Option<ModePin>,
}

/// The mode ports of a mix with modes (docs/timing.md, "Mode switches").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModePin {
    /// `mode_sel`: the request, read at each frame's decision cycle.
    Sel,
    /// `mode`: the mode in force, timed like every output.
    Mode,
}

impl Lane {
    pub fn port_bit(&self) -> String {
        match (self.role, self.link) {
            (Some(r), _) => format!("{}[{}]", r.name(), self.bit),
            (None, _) if self.mode.is_some() => {
                let k = usize::from(self.mode == Some(ModePin::Mode));
                format!("{}[{}]", lut_gen::MODE_PORTS[k].name, self.bit)
            }
            (None, Some(Signal::AxisTdata)) => format!("m_axis_tdata[{}]", self.bit),
            (None, l) => lut_gen::LINK_PORTS
                .iter()
                .chain(&lut_gen::AXIS_PORTS)
                .find(|p| Some(p.signal) == l)
                .map_or(lut_gen::LINK_PORTS[0].name, |p| p.name)
                .to_string(),
        }
    }

    /// Whether this lane carries the UART's line.
    pub(crate) fn is_line(&self) -> bool {
        self.role.is_none() && self.mode.is_none() && self.link.is_none_or(|l| l == Signal::LinkTx)
    }

    /// Whether this lane carries a link port's bit (not a core or mode port).
    pub(crate) fn is_link(&self) -> bool {
        self.role.is_none() && self.mode.is_none()
    }

    fn is(&self, r: Role) -> bool {
        self.role == Some(r)
    }

    pub(crate) fn get(&self, p: &Pins) -> bool {
        let v = match self.role {
            Some(Role::CsN) => p.cs_n as u128,
            Some(Role::Sclk) => p.sclk as u128,
            Some(Role::Mosi) => p.mosi as u128,
            Some(Role::MuxSel) => p.mux_sel as u128,
            Some(Role::MuxEn) => p.mux_en,
            Some(Role::SampleValid) => p.sample_valid as u128,
            None if self.mode == Some(ModePin::Sel) => p.mode_sel as u128,
            None if self.mode == Some(ModePin::Mode) => p.mode as u128,
            None => match self.link {
                Some(Signal::AxisTdata) => p.axis_tdata as u128,
                Some(Signal::AxisTvalid) => p.axis_tvalid as u128,
                Some(Signal::AxisTready) => p.axis_tready as u128,
                Some(Signal::AxisTlast) => p.axis_tlast as u128,
                Some(Signal::LinkOverflow) => p.link_overflow as u128,
                _ => p.link_tx as u128,
            },
            _ => 0,
        };
        v >> self.bit & 1 == 1
    }

    /// Lanes the model predicts without MISO: timing and control outputs.
    fn predictable(&self) -> bool {
        self.mode == Some(ModePin::Mode)
            || matches!(
                self.role,
                Some(
                    Role::CsN
                        | Role::Sclk
                        | Role::Mosi
                        | Role::MuxSel
                        | Role::MuxEn
                        | Role::SampleValid
                )
            )
    }

    fn what(&self) -> &'static str {
        match self.role {
            Some(Role::CsN) => "conversion instant (rate, interval, slot order)",
            Some(Role::Sclk) => "serial clock (SCLK count and period per conversion)",
            Some(Role::Mosi) => "command words (every bit, at its time)",
            Some(Role::MuxSel | Role::MuxEn) => "mux switching (slot order, settling before CS)",
            Some(Role::SampleValid) => "sample stream timing",
            None if self.mode.is_some() => "mode in force (switches at frame starts, as decided)",
            None => "link samples (order on the line)",
            _ => "",
        }
    }
}

/// A capture: lanes, the sample period, and the lanes' levels (bit i = lane
/// i) from each time on, in time order (the first entry is the start).
#[derive(Debug, Clone)]
pub struct Capture {
    pub lanes: Vec<Lane>,
    pub period_ps: u64,
    pub steps: Vec<(u64, u64)>,
}

/// One broken expectation.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedViolation {
    pub time_ps: u64,
    pub channel: String,
    pub port_bit: String,
    pub rule: String,
    pub detail: String,
}

/// The outcome of a time-level check.
#[derive(Debug, Clone)]
pub struct TimedReport {
    pub ok: bool,
    pub edges_checked: u64,
    pub conversions: u64,
    /// Time the phase was found at and the frame slot there.
    pub locked_at_ps: u64,
    pub slot: u64,
    pub phases: usize,
    /// The violations found: the first `VIOLATION_CAP`, and the first of
    /// every class (rule and channel) beyond them.
    pub violations: Vec<TimedViolation>,
    /// How many violations there were in all.
    pub violations_total: u64,
    /// What the resolution and the mapped pins allowed to be proved, and not.
    pub proved: Vec<String>,
    pub not_proved: Vec<String>,
    /// A UART line decoded from the capture: where it was joined.
    pub link_join: Option<LineJoin>,
    /// The design's clock measured from the conversion starts, in ppm from
    /// the mix's in the analyser's timebase (positive: faster), when the
    /// capture's times were scaled by it; every time above is the capture's
    /// own.
    pub clock_ppm: Option<f64>,
    /// With `clock_ppm`: how far the scaled times can stray by the end of
    /// the capture (the fit's uncertainty), by which each edge's tolerance
    /// was widened; 0 otherwise.
    pub clock_uncertainty_ps: u64,
    /// A mix with modes: the mode of each frame the capture holds, as the
    /// phase found places them.
    pub modes: Option<crate::capture::modes::ModesSeen>,
}

impl TimedReport {
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "capture: locked at {:.3} us (slot {}){}; {} edges and {} conversions checked at time level, {} violation(s): {}",
            self.locked_at_ps as f64 / 1e6,
            self.slot,
            if self.phases > 1 {
                format!(", {} phases fit it alike", self.phases)
            } else {
                String::new()
            },
            self.edges_checked,
            self.conversions,
            self.violations_total,
            crate::model::verdict_word(self.ok, self.link_join.as_ref().map(|j| j.judged))
        );
        if let Some(ppm) = self.clock_ppm {
            let _ = writeln!(
                s,
                "clock: the conversion starts put the design's clock {ppm:+.1} ppm from the mix's (the board's crystal against the analyser's); the capture was checked at that clock, each edge's tolerance widened by the fit's uncertainty ({:.1} ns over the capture)",
                self.clock_uncertainty_ps as f64 / 1e3
            );
        }
        if let Some(j) = &self.link_join {
            let _ = writeln!(s, "{}", j.text());
        }
        if let Some(m) = &self.modes {
            let _ = writeln!(s, "{}", m.text());
        }
        for v in &self.violations {
            let _ = writeln!(
                s,
                "  {} at {:.3} us on {} ({}): {}",
                v.rule,
                v.time_ps as f64 / 1e6,
                v.channel,
                v.port_bit,
                v.detail
            );
        }
        let listed = self.violations.len() as u64;
        if self.violations_total > listed {
            let _ = writeln!(
                s,
                "  ... and {} more of the classes above (the first {VIOLATION_CAP} and the first of every class are listed)",
                self.violations_total - listed
            );
        }
        // A failed capture proves nothing; it says what it could have.
        let label = if self.ok { "proved" } else { "would prove" };
        for p in &self.proved {
            let _ = writeln!(s, "  {label}: {p}");
        }
        for p in &self.not_proved {
            let _ = writeln!(s, "  not proved: {p}");
        }
        s
    }
}

/// Violations listed in full; later ones are counted, and listed only when
/// their class (rule and channel) is new.
pub const VIOLATION_CAP: usize = 32;

/// Violations as they are found.
#[derive(Default)]
struct Found {
    list: Vec<TimedViolation>,
    total: u64,
}

impl Found {
    fn push(&mut self, v: TimedViolation) {
        self.total += 1;
        let new_class = !self
            .list
            .iter()
            .any(|w| w.rule == v.rule && w.channel == v.channel);
        if self.list.len() < VIOLATION_CAP || new_class {
            self.list.push(v);
        }
    }

    /// Lists `v` before the violations found so far (it happened before them).
    fn put_first(&mut self, v: TimedViolation) {
        let mut first = Found::default();
        first.push(v);
        for w in std::mem::take(&mut self.list) {
            first.push(w);
        }
        first.total = self.total + 1;
        *self = first;
    }
}

/// Why a capture could not be checked (an input problem).
#[derive(Debug, Clone, PartialEq)]
pub struct TimedError(pub String);

impl std::fmt::Display for TimedError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// Per lane: (cycle in frame, new level) of the model's edges in a steady frame.
struct Tpl {
    frame: u64,
    edges: Vec<Vec<(u64, bool)>>,
    /// Closest two edges of each lane, in cycles.
    min_gap: Vec<u64>,
    /// Per branch: the least cycles from a mux change to the next instant.
    settle_margin: Vec<Option<u64>>,
    conversions_per_frame: u64,
    /// A mix with modes: a frame of edges per triple of modes.
    modal: Option<crate::capture::modes::Modal>,
}

fn template(s: &Schedule, lanes: &[Lane]) -> Tpl {
    let l = Layout::new(s);
    let f = s.grid.frame_cycles;
    let mut m = CycleModel::at(s, f - 1);
    let mut prev: Vec<bool> = lanes.iter().map(|x| x.get(m.pins())).collect();
    let mut edges = vec![Vec::new(); lanes.len()];
    let nb = l.branches;
    let mut last_mux = vec![0u64; nb];
    let mut prev_pins = *m.pins();
    let mut margin: Vec<Option<u64>> = vec![None; nb];
    let mut conversions = 0;
    m.step(0);
    while m.cycle() < 2 * f {
        let p = *m.pins();
        for (i, lane) in lanes.iter().enumerate() {
            let v = lane.get(&p);
            if v != prev[i] {
                edges[i].push((m.cycle() - f, v));
                prev[i] = v;
            }
        }
        for b in 0..nb {
            if l.sel(&p, b) != l.sel(&prev_pins, b) || l.en(&p, b) != l.en(&prev_pins, b) {
                last_mux[b] = m.cycle();
            }
            let cs = |q: &Pins| (q.cs_n ^ cnv_mask(s)) >> b & 1 == 0;
            if cs(&p) && !cs(&prev_pins) {
                conversions += 1;
                let g = m.cycle() - last_mux[b];
                margin[b] = Some(margin[b].map_or(g, |x: u64| x.min(g)));
            }
        }
        prev_pins = p;
        m.step(0);
    }
    let min_gap = edges
        .iter()
        .map(|e| {
            let n = e.len();
            (0..n)
                .map(|i| (e[(i + 1) % n].0 + f - e[i].0 - 1) % f + 1)
                .min()
                .unwrap_or(f)
        })
        .collect();
    Tpl {
        frame: f,
        edges,
        min_gap,
        settle_margin: margin,
        conversions_per_frame: conversions,
        modal: None,
    }
}

/// [`template`] of a mix with modes: a frame per triple of modes, and the
/// figures over all of them.
fn template_modal(s: &Schedule, lanes: &[Lane], n: usize) -> Tpl {
    let m = crate::capture::modes::template(s, lanes, n);
    Tpl {
        frame: s.grid.frame_cycles,
        edges: vec![Vec::new(); lanes.len()],
        min_gap: m.min_gap.clone(),
        settle_margin: m.settle_margin.clone(),
        conversions_per_frame: m.conversions.iter().copied().max().unwrap_or(0),
        modal: Some(m),
    }
}

/// The template of `lanes`, per mode triple for a mix with modes.
fn template_any(s: &Schedule, lanes: &[Lane]) -> Tpl {
    match s.mode_plan().map(|p| p.names.len()).filter(|&n| n > 1) {
        Some(n) => template_modal(s, lanes, n),
        None => template(s, lanes),
    }
}

pub(crate) fn cnv_mask(s: &Schedule) -> u16 {
    s.mix
        .branches
        .iter()
        .enumerate()
        .filter(|(_, b)| b.adc.start == lut_gen::Start::Cnv)
        .fold(0u16, |a, (b, _)| a | 1 << b)
}

#[derive(Clone)]
struct Cand {
    /// phi's interval, in units of 1/clock ps.
    lo: i128,
    hi: i128,
    /// Per lane: the next template edge (frame wrap, index), once started.
    ptr: Vec<Option<(u64, usize)>>,
    /// Per lane: after a violation, its edges are matched afresh near their
    /// own time (not reported again until one fits).
    resync: Vec<bool>,
    c0: u64,
    /// A mix with modes: the mode of each frame, as this phase places them.
    modes: crate::capture::modes::Modes,
}

struct Ctx<'a> {
    tpl: &'a Tpl,
    /// Sample period and skew, in units.
    t: i128,
    skew: i128,
    /// One cycle in units (1e12).
    tc: i128,
    clock: i128,
    /// A mix with modes: where the capture says each frame's mode.
    src: Option<crate::capture::modes::ModeSource<'a>>,
}

impl Ctx<'_> {
    /// Lane `lane`'s edges in frame `w` of phase `c`.
    /// Whether frames 0..=2 of phase `c` may run `modes`: the capture
    /// says nothing else of those it tells.
    fn assume(&self, c: &Cand, modes: &[u8; 3]) -> bool {
        let Some(src) = &self.src else {
            return true;
        };
        (0..3).all(|w| {
            src.decide(c.lo, c.hi, w as u64, &modes[..w])
                .is_none_or(|d| d == modes[w])
        })
    }

    /// Phases equal in all but the modes assumed before the capture told
    /// them: one stands for all (a phase's future depends only on the
    /// modes the capture tells).
    fn dedupe(&self, cands: &mut Vec<Cand>) {
        let Some(src) = &self.src else {
            return;
        };
        let key = |c: &Cand| {
            let w = c.ptr.iter().flatten().map(|p| p.0).min().unwrap_or(0);
            let m: Vec<usize> = (w.saturating_sub(1)..w + 2)
                .map(|k| c.modes.of(src, c.lo, c.hi, k))
                .collect();
            (c.lo, c.hi, c.ptr.clone(), c.resync.clone(), c.c0, m)
        };
        let mut seen = Vec::new();
        cands.retain(|c| {
            let k = key(c);
            let new = !seen.contains(&k);
            if new {
                seen.push(k);
            }
            new
        });
    }

    fn frame_edges<'t>(&'t self, c: &Cand, lane: usize, w: u64) -> &'t [(u64, bool)] {
        let (Some(m), Some(src)) = (&self.tpl.modal, &self.src) else {
            return &self.tpl.edges[lane];
        };
        let at = |k: u64| c.modes.of(src, c.lo, c.hi, k);
        let b = at(w);
        let a = if w == 0 { b } else { at(w - 1) };
        &m.frames[m.triple((a, b, at(w + 1)))][lane]
    }

    /// Template edge `(w, j)` of `lane`: its model cycle and level (None
    /// past the frame's edges: a frame of a mode without any).
    fn edge_at(&self, c: &Cand, lane: usize, (w, j): (u64, usize)) -> Option<(u64, bool)> {
        let e = self.frame_edges(c, lane, w).get(j)?;
        Some((w * self.tpl.frame + e.0, e.1))
    }

    fn abs(&self, c: &Cand, lane: usize, p: (u64, usize)) -> u64 {
        self.edge_at(c, lane, p)
            .map_or((p.0 + 1) * self.tpl.frame, |e| e.0)
    }

    /// The edge after `(w, j)`: in a mix with modes, frames of modes
    /// without an edge on the lane are passed over (up to the capture's
    /// end, where an empty frame stands for "no more").
    fn next(&self, c: &Cand, lane: usize, (w, j): (u64, usize)) -> (u64, usize) {
        if j + 1 < self.frame_edges(c, lane, w).len() {
            return (w, j + 1);
        }
        let Some(src) = &self.src else {
            return (w + 1, 0);
        };
        let end = src.end_frame(c.lo).max(w + 1);
        let mut n = w + 1;
        while n < end && self.frame_edges(c, lane, n).is_empty() {
            n += 1;
        }
        (n, 0)
    }

    /// Narrows `c`'s interval with an edge of `lane` at `t` (units) that is
    /// model cycle `cycle`; false when it does not fit.
    fn fit(&self, c: &mut Cand, cycle: u64, t: i128) -> bool {
        let ct = cycle as i128 * self.tc;
        let lo = c.lo.max(t - ct - self.t - self.skew);
        let hi = c.hi.min(t - ct + self.skew);
        if lo > hi {
            return false;
        }
        c.lo = lo;
        c.hi = hi;
        true
    }

    /// The first observed edge of a lane after the lock (or after a
    /// violation, `resync`): the first template edge of its level near
    /// enough.  After the lock no template edge may be passed over that
    /// came more than the resolution after the lock's edge: it would have
    /// been seen.
    fn start(&self, c: &mut Cand, lane: usize, t: i128, v: bool) -> Result<(), String> {
        let level = |x: bool| if x { "rising" } else { "falling" };
        let none = || format!("{} edge at no time the schedule has one", level(v));
        if self.src.is_none() && self.tpl.edges[lane].is_empty() {
            return Err(none());
        }
        let back = ((self.t + 2 * self.skew) / self.tc) as u64 + 2;
        let from = if c.resync[lane] {
            // The earliest model cycle an edge at `t` can be.
            let earliest = (t - c.hi - self.t - self.skew).max(0) / self.tc;
            (earliest as u64).saturating_sub(back)
        } else {
            c.c0.saturating_sub(back)
        };
        let (mut w, mut j) = (from / self.tpl.frame, 0usize);
        let in_frame = from % self.tpl.frame;
        let e = self.frame_edges(c, lane, w);
        while j < e.len() && e[j].0 < in_frame {
            j += 1;
        }
        if j == e.len() {
            (w, j) = self.next(c, lane, (w, e.len().saturating_sub(1)));
        }
        // one frame's edges (a mode mix: up to the capture's end)
        let bound = match &self.src {
            Some(_) => usize::MAX,
            None => self.tpl.edges[lane].len() + 1,
        };
        for _ in 0..bound {
            let Some((cyc, lv)) = self.edge_at(c, lane, (w, j)) else {
                return Err(none());
            };
            if lv == v {
                let mut d = c.clone();
                if self.fit(&mut d, cyc, t) {
                    *c = d;
                    c.ptr[lane] = Some(self.next(c, lane, (w, j)));
                    return Ok(());
                }
            }
            if cyc as i128 * self.tc + c.lo > t + self.skew {
                return Err(none());
            }
            // Seen after the lock's edge for sure: more than the resolution later.
            let after_lock = cyc > c.c0 && (cyc - c.c0) as i128 * self.tc > self.t + 2 * self.skew;
            if !c.resync[lane] && after_lock {
                return Err(format!(
                    "{} edge where the schedule's {} edge at frame cycle {} came first: an edge is missing",
                    level(v),
                    level(lv),
                    cyc % self.tpl.frame
                ));
            }
            (w, j) = self.next(c, lane, (w, j));
        }
        Err(none())
    }

    fn step(&self, c: &mut Cand, lane: usize, t: i128, v: bool) -> Result<(), String> {
        let Some(p) = c.ptr[lane] else {
            return self.start(c, lane, t, v);
        };
        let Some((cyc, want)) = self.edge_at(c, lane, p) else {
            return Err(format!(
                "{} edge where the schedule has none (the modes of the frames since)",
                if v { "rising" } else { "falling" }
            ));
        };
        let at = |x: i128| x as f64 / self.clock as f64 / 1e3;
        let (elo, ehi) = (
            c.lo + cyc as i128 * self.tc - self.skew,
            c.hi + cyc as i128 * self.tc + self.t + self.skew,
        );
        if want != v {
            return Err(format!(
                "{} edge at {:.3} us where the schedule's next edge is {} in [{:.3}, {:.3}] us (frame cycle {}): an edge is missing or extra",
                if v { "rising" } else { "falling" },
                at(t) / 1e3,
                if want { "rising" } else { "falling" },
                at(elo) / 1e3,
                at(ehi) / 1e3,
                cyc % self.tpl.frame
            ));
        }
        if !self.fit(c, cyc, t) {
            let early = t < elo;
            return Err(format!(
                "edge at {:.3} us, {} than the schedule's [{:.3}, {:.3}] us (frame cycle {}, slot timing to within the capture's resolution)",
                at(t) / 1e3,
                if early { "earlier" } else { "later" },
                at(elo) / 1e3,
                at(ehi) / 1e3,
                cyc % self.tpl.frame
            ));
        }
        c.ptr[lane] = Some(self.next(c, lane, p));
        Ok(())
    }
}

/// Checks a capture at time level against the schedule (the link's line
/// held to the model).
pub fn check_capture(s: &Schedule, cap: &Capture, skew_ps: u64) -> Result<TimedReport, TimedError> {
    check_capture_with(s, cap, skew_ps, true)
}

/// [`check_capture`]; without the `model` the link's line is decoded and
/// judged but not held to the model's timing and codes (`--no-model`).
pub fn check_capture_with(
    s: &Schedule,
    cap: &Capture,
    skew_ps: u64,
    model: bool,
) -> Result<TimedReport, TimedError> {
    match crate::capture::clock_fit::fit(s, cap, skew_ps).filter(|f| f.worth_scaling()) {
        Some(f) => {
            let tol = Tolerance {
                skew_ps,
                fit_ps: f.uncertainty_ps(),
            };
            let mut r = check_at_mix_clock(s, &f.scaled(cap), tol, model)?;
            f.unscale(&mut r);
            Ok(r)
        }
        None => check_at_mix_clock(s, cap, Tolerance { skew_ps, fit_ps: 0 }, model),
    }
}

/// What an edge's time may be off by besides the sample period, in ps: the
/// user's skew between lanes, and the clock fit's uncertainty when the
/// capture was scaled.  Both widen each side of an edge's window.
#[derive(Debug, Clone, Copy)]
struct Tolerance {
    skew_ps: u64,
    fit_ps: u64,
}

impl Tolerance {
    fn each_side_ps(self) -> u64 {
        self.skew_ps + self.fit_ps
    }

    /// The claim the resolution makes, in words.
    fn resolution_said(self, period_ps: u64) -> String {
        let res = (period_ps + 2 * self.each_side_ps()) as f64 / 1e3;
        let fit = match self.fit_ps {
            0 => String::new(),
            p => format!(
                " and twice the clock fit's uncertainty {:.1} ns",
                p as f64 / 1e3
            ),
        };
        format!(
            "every checked edge within {res:.1} ns of the schedule's time (sample period {:.1} ns plus twice the skew {:.1} ns{fit}): rates, intervals and slot order of the mapped conversion lanes to ±{res:.1} ns",
            period_ps as f64 / 1e3,
            self.skew_ps as f64 / 1e3,
        )
    }
}

/// One cycle, in units of 1/clock ps.
const TC: i128 = 1_000_000_000_000;

/// [`check_capture_with`] with the capture's times taken as the mix's clock.
fn check_at_mix_clock(
    s: &Schedule,
    cap: &Capture,
    tol: Tolerance,
    model: bool,
) -> Result<TimedReport, TimedError> {
    let skew_ps = tol.each_side_ps();
    let clock = s.mix.clock_hz as i128;
    let tc_ps = 1e12 / s.mix.clock_hz as f64;
    let mut not_proved = Vec::new();
    let checked = checked_lanes(s, cap, skew_ps, &mut not_proved);
    let lanes: Vec<Lane> = checked.iter().map(|&i| cap.lanes[i].clone()).collect();
    let tpl = template_any(s, &lanes);
    // The lock waits for the first conversion start on any CS lane: the
    // earliest evidence of the frame phase (a lane whose branch converts
    // late, or is not probed, does not delay it).
    let cs_lanes: Vec<usize> = (0..lanes.len())
        .filter(|&i| lanes[i].is(Role::CsN))
        .collect();
    if cs_lanes.is_empty() {
        return Err(TimedError(
            "no mapped CS (or CNV) lane the capture's resolution can check: the frame phase cannot be found; map adc_cs_n[N] to an analyser channel".into(),
        ));
    }
    let (t, skew, tc) = (cap.period_ps as i128 * clock, skew_ps as i128 * clock, TC);
    let src = (tpl.modal.as_ref())
        .map(|_| crate::capture::modes::ModeSource::new(s, cap, (t + 2 * skew, tc, clock)))
        .transpose()?;
    let ctx = Ctx {
        tpl: &tpl,
        t,
        skew,
        tc,
        clock,
        src,
    };
    let mut scan = Scan::default();
    scan.run(&ctx, &lanes, &checked, cap, cnv_mask(s));
    let end = cap.steps.last().map(|s| s.0).unwrap_or(0) as i128 * clock;
    scan.settle_lost(&ctx, &lanes, end)?;
    let Some(cands) = scan.cands.take() else {
        return Err(no_conversion_start(&lanes, &cs_lanes));
    };
    let mut found = scan.found;
    if scan.edges_checked == 0 && found.total == 0 {
        return Err(TimedError(format!(
            "the capture ends before any edge after its first conversion start (at {:.3} us): nothing to check",
            scan.locked_at as f64 / 1e6
        )));
    }
    // A lane must not miss an edge the schedule puts inside the capture.
    if cands.len() == 1 {
        missing_edges(&ctx, &lanes, &cands[0], end, &mut found);
    }
    let span_ps = (end / clock) as u64 - scan.conv_start.unwrap_or(0);
    let mut conversions =
        (span_ps as f64 / (tpl.frame as f64 * tc_ps) * tpl.conversions_per_frame as f64) as u64;
    let (mut proved, np) = what_was_proved(s, &lanes, &tpl, cap.period_ps, tol);
    not_proved.extend(np);
    let modes_seen = modes_seen(s, cap, &ctx, &cands, scan.conv_start.unwrap_or(0), end);
    let modes_seen = modes_seen.map(|(seen, n, trig)| {
        conversions = n;
        trig.violations.into_iter().for_each(|v| found.push(v));
        proved.extend(trig.proved);
        not_proved.extend(trig.not_proved);
        seen
    });
    let link_join = check_link_lane(
        s,
        cap,
        &ctx,
        &cands,
        model,
        &mut found,
        &mut proved,
        &mut not_proved,
    );
    Ok(TimedReport {
        ok: found.total == 0,
        edges_checked: scan.edges_checked,
        conversions,
        locked_at_ps: scan.locked_at,
        slot: cands
            .first()
            .map(|c| (c.c0 % tpl.frame) / s.grid.slot_cycles)
            .unwrap_or(0),
        phases: cands.len(),
        violations: found.list,
        violations_total: found.total,
        proved,
        not_proved,
        link_join,
        clock_ppm: None,
        clock_uncertainty_ps: 0,
        modes: modes_seen,
    })
}

/// A mix with modes: the modes of the frames from the lock (`from`, ps) to
/// the end as the first phase places them, the conversions they hold, and
/// (auto select) the switch decisions judged.
fn modes_seen(
    s: &Schedule,
    cap: &Capture,
    ctx: &Ctx,
    cands: &[Cand],
    from: u64,
    end: i128,
) -> Option<(
    crate::capture::modes::ModesSeen,
    u64,
    crate::capture::triggers::TriggerCheck,
)> {
    let (src, modal, c) = (ctx.src.as_ref()?, ctx.tpl.modal.as_ref()?, cands.first()?);
    let (seen, n) =
        crate::capture::modes::seen(s, src, modal, (c.lo, c.hi, c.c0), &c.modes, (from, end));
    // the decisions are judged at a unique phase, from the `mode` output's modes
    let trig = match cands.len() == 1 && seen.by == "mode" {
        true => crate::capture::triggers::check(s, cap, src, (c.lo, c.hi), &c.modes),
        false => Default::default(),
    };
    Some((seen, n, trig))
}

/// The capture's lanes the resolution lets us check edge by edge; why each
/// other one is not goes to `not_proved`.
fn checked_lanes(
    s: &Schedule,
    cap: &Capture,
    skew_ps: u64,
    not_proved: &mut Vec<String>,
) -> Vec<usize> {
    let tc_ps = 1e12 / s.mix.clock_hz as f64;
    let res_ps = cap.period_ps + 2 * skew_ps;
    let all = &cap.lanes;
    let tpl_all = template_any(s, all);
    (0..all.len())
        .filter(|&i| {
            let lane = &all[i];
            if lane.is_link() {
                // The link's line: decoded below, not timed edge by edge.
                return false;
            }
            if lane.mode == Some(ModePin::Sel) {
                not_proved.push(format!(
                    "{} ({}): an input; read at each frame's decision cycle for the mode of the frame after next, not timed",
                    lane.channel,
                    lane.port_bit()
                ));
                return false;
            }
            if !lane.predictable() {
                let linked = lane.is(Role::Miso) && all.iter().any(|l| l.is_line());
                not_proved.push(format!(
                    "{} ({}): its values come from the ADC, not the schedule; not checked at time level{}",
                    lane.channel,
                    lane.port_bit(),
                    if linked {
                        " (read at the edges that capture it, for the link's sample codes)"
                    } else {
                        ""
                    }
                ));
                return false;
            }
            let gap_ps = tpl_all.min_gap[i] as f64 * tc_ps;
            if gap_ps <= res_ps as f64 {
                not_proved.push(format!(
                    "{} ({}): its edges come {:.1} ns apart, not more than the capture's resolution ({:.1} ns: sample period plus twice the skew); a faster analyser proves it",
                    lane.channel,
                    lane.port_bit(),
                    gap_ps / 1e3,
                    res_ps as f64 / 1e3
                ));
                return false;
            }
            true
        })
        .collect()
}

/// Whether `level` on `lane` starts a conversion: CS falling (a CNV lane:
/// rising).
#[inline]
fn starts(cnv: u16, lane: &Lane, level: bool) -> bool {
    lane.is(Role::CsN) && level == (cnv >> lane.bit & 1 == 1)
}

/// An edge of checked lane `lane` at `t_ps` (`t`: in units of 1/clock ps)
/// to `level`.
#[derive(Clone, Copy)]
struct Edge {
    lane: usize,
    t: i128,
    t_ps: u64,
    level: bool,
}

/// The scan of a capture's edges against the schedule's frame phases.
#[derive(Default)]
struct Scan {
    /// The phases still fitting; `None` until a conversion start locks the
    /// scan (again, after every phase broke).
    cands: Option<Vec<Cand>>,
    first_cands: usize,
    locked_at: u64,
    found: Found,
    lost: Option<Lost>,
    edges_checked: u64,
    conv_start: Option<u64>,
    relocked_at: u64,
    edges_at_relock: u64,
    /// The stretch since the last lock, and the longest that broke.
    seg: Segment,
    best_seg: Segment,
}

impl Scan {
    /// Every edge of the checked lanes (`checked[li]` is lane `li`'s bit in
    /// the capture), in time order.
    fn run(&mut self, ctx: &Ctx, lanes: &[Lane], checked: &[usize], cap: &Capture, cnv: u16) {
        let mut prev = cap.steps.first().map(|s| s.1).unwrap_or(0);
        for &(t_ps, v) in cap.steps.iter().skip(1) {
            let changed = v ^ prev;
            prev = v;
            if changed == 0 {
                continue;
            }
            let t = t_ps as i128 * ctx.clock;
            for (li, &ai) in checked.iter().enumerate() {
                if changed >> ai & 1 == 0 {
                    continue;
                }
                let at = Edge {
                    lane: li,
                    t,
                    t_ps,
                    level: v >> ai & 1 == 1,
                };
                if self.cands.is_none() {
                    // Lock on the first conversion start of any CS lane.
                    if starts(cnv, &lanes[li], at.level) {
                        self.lock(ctx, lanes.len(), at);
                    }
                } else {
                    self.edge(ctx, lanes, at, cnv);
                }
            }
        }
    }

    /// A conversion start `at` locks the scan: every phase
    /// that puts a template edge of that level there is a candidate.
    fn lock(&mut self, ctx: &Ctx, nlanes: usize, at: Edge) {
        let Edge {
            lane: li,
            t,
            t_ps,
            level,
        } = at;
        let tpl = ctx.tpl;
        let mut c = Vec::new();
        // A mix with modes: the lock's frame (1) and its neighbours in every
        // mode the capture does not rule out.
        let n = tpl.modal.as_ref().map_or(1, |m| m.n);
        for k in 0..n * n * n {
            let modes = [k / (n * n), k / n % n, k % n].map(|x| x as u8);
            let edges = match &tpl.modal {
                Some(m) => &m.frames[k][li],
                None => &tpl.edges[li],
            };
            for (j, &(cyc, lv)) in edges.iter().enumerate() {
                if lv != level {
                    continue;
                }
                let abs = tpl.frame + cyc;
                let mut cand = Cand {
                    lo: i128::MIN / 4,
                    hi: i128::MAX / 4,
                    ptr: vec![None; nlanes],
                    resync: vec![false; nlanes],
                    c0: abs,
                    modes: Default::default(),
                };
                if ctx.fit(&mut cand, abs, t) && ctx.assume(&cand, &modes) {
                    *cand.modes.0.borrow_mut() = modes.to_vec();
                    cand.ptr[li] = Some(ctx.next(&cand, li, (1, j)));
                    c.push(cand);
                }
            }
        }
        if self.lost.is_none() {
            self.first_cands = c.len();
            self.locked_at = t_ps;
            self.conv_start = Some(t_ps);
        }
        self.relocked_at = t_ps;
        self.edges_at_relock = self.edges_checked;
        self.seg = Segment {
            from_ps: t_ps,
            to_ps: t_ps,
            starts: 0,
        };
        self.cands = Some(c);
    }

    /// An edge on lane `li` once locked: a unique phase reports it if it
    /// does not fit; several phases keep those it fits.
    fn edge(&mut self, ctx: &Ctx, lanes: &[Lane], at: Edge, cnv: u16) {
        let Edge {
            lane: li,
            t,
            t_ps,
            level,
        } = at;
        let Some(c) = &mut self.cands else {
            return;
        };
        self.edges_checked += 1;
        let lane = &lanes[li];
        if c.len() == 1 {
            let cand = &mut c[0];
            let resyncing = cand.ptr[li].is_none() && cand.resync[li];
            if let Err(e) = ctx.step(cand, li, t, level) {
                if !resyncing {
                    self.found.push(TimedViolation {
                        time_ps: t_ps,
                        channel: lane.channel.clone(),
                        port_bit: lane.port_bit(),
                        rule: lane.what().into(),
                        detail: e,
                    });
                }
                cand.ptr[li] = None;
                cand.resync[li] = true;
            }
            return;
        }
        let mut errs = Vec::new();
        c.retain_mut(|cand| match ctx.step(cand, li, t, level) {
            Ok(()) => true,
            Err(e) => {
                errs.push((cand.lo, cand.hi, e));
                false
            }
        });
        ctx.dedupe(c);
        let start_edge = starts(cnv, lane, level);
        if !c.is_empty() && start_edge {
            self.seg.starts += 1;
        }
        if c.is_empty() {
            if self.seg.starts > self.best_seg.starts {
                self.best_seg = Segment {
                    to_ps: t_ps,
                    ..self.seg
                };
            }
            // Every phase that fitted so far broke here: find the phase
            // again from the next conversion start, and judge at the end
            // whether the pins prove a fault here (`prelock_fault`).
            if self.lost.is_none() {
                self.lost = Some(Lost {
                    time_ps: t_ps,
                    lane: li,
                    fitted: self.first_cands,
                    errs,
                });
            }
            self.cands = None;
        }
    }

    /// After the scan, if every phase broke at some edge: a phase found
    /// again that holds to the end (`end`) proves a fault at that edge; a
    /// capture that fitted the schedule for a while shows the design left
    /// it; otherwise the capture does not fit this mix (an error).
    fn settle_lost(&mut self, ctx: &Ctx, lanes: &[Lane], end: i128) -> Result<(), TimedError> {
        let Some(l) = self.lost.take() else {
            return Ok(());
        };
        let held = self.cands.as_ref().is_some_and(|c| !c.is_empty())
            && end - self.relocked_at as i128 * ctx.clock >= ctx.tpl.frame as i128 * ctx.tc
            && self.edges_checked > self.edges_at_relock;
        if held {
            let now = &self.cands.as_ref().expect("held")[0];
            let v = prelock_fault(ctx, lanes, &l, now, self.relocked_at);
            self.found.put_first(v);
        } else if self.best_seg.starts >= SEGMENT_STARTS {
            // The pins ran this mix's schedule for a while, then left it.
            self.found
                .put_first(left_schedule(lanes, &l, &self.best_seg));
            self.cands = Some(Vec::new());
        } else {
            return Err(TimedError(format!(
                "no frame phase of this mix's schedule fits the capture's edges at {:.3} us ({} fitted before), and none found after it holds for a frame: is it the right mix and map?",
                l.time_ps as f64 / 1e6,
                l.fitted
            )));
        }
        Ok(())
    }
}

/// The edge where the capture, after fitting the schedule through `best`,
/// broke every phase for good.
fn left_schedule(lanes: &[Lane], l: &Lost, best: &Segment) -> TimedViolation {
    let lane = &lanes[l.lane];
    TimedViolation {
        time_ps: l.time_ps,
        channel: lane.channel.clone(),
        port_bit: lane.port_bit(),
        rule: lane.what().into(),
        detail: format!(
            "{} (this edge broke every frame phase still in the running; the capture fits this mix's schedule from {:.3} to {:.3} us, {} conversion starts at their times after the first, and no phase fits it past there for a frame: the design left the schedule)",
            l.errs.first().map(|e| e.2.as_str()).unwrap_or("no phase fits"),
            best.from_ps as f64 / 1e6,
            best.to_ps as f64 / 1e6,
            best.starts
        ),
    }
}

fn no_conversion_start(lanes: &[Lane], cs_lanes: &[usize]) -> TimedError {
    let probed: Vec<String> = cs_lanes
        .iter()
        .map(|&i| format!("{} ({})", lanes[i].channel, lanes[i].port_bit()))
        .collect();
    TimedError(format!(
        "no conversion start on {} in the capture: the frame phase cannot be found",
        probed.join(", ")
    ))
}

/// The schedule's edges the unique phase `c` still waits for that should
/// have come before the capture's end.
fn missing_edges(ctx: &Ctx, lanes: &[Lane], c: &Cand, end: i128, found: &mut Found) {
    for (li, lane) in lanes.iter().enumerate() {
        if let Some(p) = c.ptr[li] {
            let latest = c.hi + ctx.abs(c, li, p) as i128 * ctx.tc + ctx.t + ctx.skew;
            if latest < end {
                found.push(TimedViolation {
                    time_ps: (latest / ctx.clock) as u64,
                    channel: lane.channel.clone(),
                    port_bit: lane.port_bit(),
                    rule: lane.what().into(),
                    detail: "the schedule's edge never came: an edge is missing".into(),
                });
            }
        }
    }
}

/// The link's line, decoded when a lane carries it (timed by the unique
/// phase, if one).
#[allow(clippy::too_many_arguments)]
fn check_link_lane(
    s: &Schedule,
    cap: &Capture,
    ctx: &Ctx,
    cands: &[Cand],
    model: bool,
    found: &mut Found,
    proved: &mut Vec<String>,
    not_proved: &mut Vec<String>,
) -> Option<LineJoin> {
    let layout = Layout::new(s);
    let phases: Vec<_> = cands
        .iter()
        .map(|c| crate::capture::line::LinkPhase {
            lo: c.lo,
            hi: c.hi,
            t: ctx.t,
            skew: ctx.skew,
        })
        .collect();
    let line = cap.lanes.iter().position(|l| l.is_line());
    let axis = cap.lanes.iter().any(|l| l.is_link()) && layout.axis;
    let modes = phase_modes(s, cap, ctx, cands);
    let lk = match line {
        _ if axis => crate::capture::axis::check_axis(s, cap, (&phases, &modes), model),
        Some(li) if !layout.axis => {
            crate::capture::line::check_link(s, cap, li, &phases, &modes, model)
        }
        _ if layout.axis => {
            not_proved.push("the link's samples (map m_axis_tdata[7:0], m_axis_tvalid, m_axis_tready and m_axis_tlast to analyser channels to read its beats)".into());
            return None;
        }
        _ if layout.link => {
            not_proved.push(
                "the link's samples (map link_tx to an analyser channel to decode them)".into(),
            );
            return None;
        }
        _ => return None,
    };
    for v in lk.violations {
        found.push(v);
    }
    proved.extend(lk.proved);
    not_proved.extend(lk.not_proved);
    lk.join
}

/// A mix with modes: per phase, the mode of each of its frames to the
/// capture's end, as the capture showed them (empty without modes).
fn phase_modes(s: &Schedule, cap: &Capture, ctx: &Ctx, cands: &[Cand]) -> Vec<Vec<usize>> {
    let Some(src) = ctx.src.as_ref() else {
        return vec![Vec::new(); cands.len()];
    };
    let f = s.grid.frame_cycles as i128 * ctx.tc;
    let end = cap.steps.last().map_or(0, |x| x.0) as i128 * ctx.clock;
    (cands.iter())
        .map(|c| {
            let frames = ((end - c.lo).max(0) / f + 1) as u64;
            (0..=frames)
                .map(|w| c.modes.of(src, c.lo, c.hi, w))
                .collect()
        })
        .collect()
}

/// Conversion starts a stretch of the capture must fit at their times (after
/// the lock's own) to show the pins ran this mix's schedule: then a break
/// after it that no phase survives is the design's, not the input's.
const SEGMENT_STARTS: u64 = 1;

/// A stretch of the capture between a lock and the edge that broke it.
#[derive(Debug, Clone, Copy, Default)]
struct Segment {
    from_ps: u64,
    to_ps: u64,
    /// Conversion starts fitted after the lock's.
    starts: u64,
}

/// Every frame phase that fitted the capture broke at one edge.
struct Lost {
    time_ps: u64,
    lane: usize,
    /// Phases that fitted the first conversion start.
    fitted: usize,
    /// Each broken phase's interval and why it broke.
    errs: Vec<(i128, i128, String)>,
}

/// The fault that broke every phase before one was unique, once a phase
/// found again afterwards held to the end of the capture.  If that phase
/// is one that fitted before (the same modulo a frame, within the
/// resolution), the pins prove the design broke the schedule at that edge:
/// it is reported with that phase's reason.  If it is another, the design's
/// frame phase jumped there.
fn prelock_fault(
    ctx: &Ctx,
    lanes: &[Lane],
    l: &Lost,
    now: &Cand,
    relocked_ps: u64,
) -> TimedViolation {
    let frame = ctx.tpl.frame as i128 * ctx.tc;
    let same = l.errs.iter().find(|(lo, hi, _)| {
        let tol = (hi - lo) + (now.hi - now.lo) + ctx.t + 2 * ctx.skew;
        let d = (now.lo - lo).rem_euclid(frame);
        d <= tol || frame - d <= tol
    });
    let lane = &lanes[l.lane];
    let relock = relocked_ps as f64 / 1e6;
    let (rule, detail) = match same {
        Some((_, _, e)) => (
            lane.what().to_string(),
            format!(
                "{e} (before the frame phase was unique: the phase that holds from {relock:.3} us to the end fitted every edge before this one)"
            ),
        ),
        None => (
            "frame phase".to_string(),
            format!(
                "the edges up to here fit {} frame phase(s) of the schedule, those from {relock:.3} us to the end another one: the design's frame phase jumped",
                l.fitted
            ),
        ),
    };
    TimedViolation {
        time_ps: l.time_ps,
        channel: lane.channel.clone(),
        port_bit: lane.port_bit(),
        rule,
        detail,
    }
}

/// The claims a capture at this resolution with these lanes supports.
fn what_was_proved(
    s: &Schedule,
    lanes: &[Lane],
    tpl: &Tpl,
    period_ps: u64,
    tol: Tolerance,
) -> (Vec<String>, Vec<String>) {
    let tc_ps = 1e12 / s.mix.clock_hz as f64;
    let res = (period_ps + 2 * tol.each_side_ps()) as f64;
    let mut yes = Vec::new();
    let mut no = Vec::new();
    yes.push(tol.resolution_said(period_ps));
    if res >= tc_ps {
        no.push(format!(
            "cycle exactness: the capture cannot resolve one {:.1} ns clock cycle",
            tc_ps / 1e3
        ));
    }
    let layout = Layout::new(s);
    // Every bit of branch `b`'s lane of `r` is checked.
    let has = |r: Role, b: usize| {
        let (msb, lsb) = layout.lane_bits(r, b);
        (lsb..=msb).all(|bit| lanes.iter().any(|l| l.is(r) && l.bit == bit))
    };
    for (b, br) in s.mix.branches.iter().enumerate() {
        if !has(Role::CsN, b) {
            no.push(format!(
                "branch {}: no CS lane checked, nothing of its conversions",
                br.name
            ));
            continue;
        }
        if has(Role::Sclk, b) {
            yes.push(format!(
                "branch {}: every SCLK edge of every conversion (count and period)",
                br.name
            ));
        } else {
            no.push(format!(
                "branch {}: SCLK count and period (no SCLK lane checked)",
                br.name
            ));
        }
        if layout.has_lane(Role::Mosi, b) {
            if has(Role::Mosi, b) {
                yes.push(format!(
                    "branch {}: every bit of every command word on adc_mosi, at its time",
                    br.name
                ));
            } else {
                no.push(format!(
                    "branch {}: its command words (no adc_mosi lane checked)",
                    br.name
                ));
            }
        }
        if !layout.muxed[b] {
            continue; // no mux, no mux lanes: nothing to settle
        }
        let settle_ns = br.settle_ns as f64;
        let mux = has(Role::MuxSel, b) && has(Role::MuxEn, b);
        match (mux, tpl.settle_margin[b]) {
            (true, Some(m)) if settle_ns > 0.0 => {
                let shown = m as f64 * tc_ps - res;
                if shown / 1e3 >= settle_ns {
                    yes.push(format!(
                        "branch {}: mux settled at least {:.0} ns before each instant (needs {settle_ns:.0} ns)",
                        br.name,
                        shown / 1e3
                    ));
                } else {
                    no.push(format!(
                        "branch {}: mux settling ({settle_ns:.0} ns needed; the schedule's margin is {:.0} ns, the capture's resolution {:.1} ns leaves {:.0} ns): an analyser period under {:.1} ns proves it",
                        br.name,
                        m as f64 * tc_ps / 1e3,
                        res / 1e3,
                        shown / 1e3,
                        (m as f64 * tc_ps / 1e3 - settle_ns) * 1e3 / 1e3 - 2.0 * tol.each_side_ps() as f64 / 1e3
                    ));
                }
            }
            (false, _) => no.push(format!(
                "branch {}: slot order by channel and mux settling (not every mux_sel/mux_en bit of it is checked)",
                br.name
            )),
            _ => {}
        }
    }
    if !lanes.iter().any(|l| l.is(Role::SampleValid)) {
        no.push("sample stream timing (no sample_valid lane checked)".into());
    }
    (yes, no)
}
