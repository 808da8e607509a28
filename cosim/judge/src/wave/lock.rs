//! Checking a capture that did not start at reset (a `sim --from/--to`
//! window, a run dumped from time T, a board captured mid-run): the frame
//! phase is found from the pins, then every later cycle is checked as
//! strictly as a run seen from reset.
//!
//! How the phase is found: the reference model's CS and mux pins change at
//! known cycles of a steady-state frame (the [`Template`]).  The first change
//! the capture shows fits some of them (each a candidate phase); every later
//! change must be the candidate's next template change, at the same distance.
//! Phases that differ by a shift under which the whole frame's pins repeat
//! are the same phase for every check (the template's `repeat`); phases
//! still left at the end of a short capture predict the same pins in all of
//! it, and are reported.  When one
//! candidate is left the check joins the run at the first cycle where no
//! conversion is in flight ([`CycleModel::quiet`]), replaying the cycles the
//! search kept (run-length coded, so memory follows the pins' activity, not
//! the cycle count).  No candidate left is a problem of the input
//! ([`LockError`]), not of the design.

use std::fmt;

use lut_gen::Schedule;
use lut_gen::Start;
use lut_gen::{Layout, Pins};

use crate::check::{CheckOptions, Checker, Join};
use crate::model::CycleModel;
use crate::model::Verdict;
use crate::wave::read::CycleSink;

/// The pins that fix the frame phase: CS (or CNV) and the mux lanes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Ctl {
    cs_n: u16,
    mux_sel: u64,
    mux_en: u128,
}

fn ctl(p: &Pins) -> Ctl {
    Ctl {
        cs_n: p.cs_n,
        mux_sel: p.mux_sel,
        mux_en: p.mux_en,
    }
}

/// The model's CS/mux changes over one steady-state frame (frame 1; frame 0
/// lacks the instants skipped at start-up).
struct Template {
    frame: u64,
    /// (cycle in the frame, the pins from that cycle on).
    ev: Vec<(u64, Ctl)>,
    /// The smallest shift (dividing the frame) under which the frame's
    /// changes repeat: phases are told apart only modulo it.
    repeat: u64,
}

impl Template {
    /// The template of a mix without switches (`mode` None), or of mode
    /// `m` run steadily (frame 3 of a model held in it from frame 2 on).
    fn new(s: &Schedule, mode: Option<usize>) -> Template {
        let f = s.grid.frame_cycles;
        let (mut m, k) = match mode {
            None => (CycleModel::at(s, f - 1), 1),
            Some(mode) => (
                CycleModel::with_modes(s, &[(2, mode), (3, mode), (4, mode)]),
                3,
            ),
        };
        while m.cycle() < k * f - 1 {
            m.step(0);
        }
        let mut prev = ctl(m.pins());
        let mut ev = Vec::new();
        m.step(0);
        while m.cycle() < (k + 1) * f {
            let c = ctl(m.pins());
            if c != prev {
                ev.push((m.cycle() - k * f, c));
                prev = c;
            }
            m.step(0);
        }
        let repeat = Template::repeat(f, &ev);
        Template {
            frame: f,
            ev,
            repeat,
        }
    }

    // `is_multiple_of` is newer than the workspace's rust-version.
    #[allow(clippy::manual_is_multiple_of)]
    fn repeat(f: u64, ev: &[(u64, Ctl)]) -> u64 {
        let n = ev.len();
        // Most repeats first (the smallest shift).
        for m in (2..=n).rev() {
            if n % m != 0 || f % m as u64 != 0 {
                continue;
            }
            let (shift, step) = (f / m as u64, n / m);
            let same = (0..n).all(|i| {
                let (t, c) = ev[i];
                ev[(i + step) % n] == ((t + shift) % f, c)
            });
            if same {
                return shift;
            }
        }
        f
    }

    /// Cycles from frame cycle `a` forward to frame cycle `b` (a whole frame when equal).
    fn gap(&self, a: u64, b: u64) -> u64 {
        match (b + self.frame - a) % self.frame {
            0 => self.frame,
            g => g,
        }
    }

    /// Capture cycle of a candidate's next change, given its last at capture cycle `last`.
    fn next_change(&self, (phase, k): (u64, usize), last: u64) -> u64 {
        last + self.gap((last + phase) % self.frame, self.ev[k].0)
    }

    /// Candidate (phase, next event) for a first change `prev -> cur` at
    /// capture cycle `i`, the search having seen `unchanged` cycles without one.
    fn candidates(&self, i: u64, unchanged: u64, prev: Ctl, cur: Ctl) -> Vec<(u64, usize)> {
        let n = self.ev.len();
        let mut seen = std::collections::BTreeSet::new();
        let mut out = Vec::new();
        for k in 0..n {
            // The change before must lie before the capture: it showed none.
            let before = self.ev[(k + n - 1) % n];
            if self.ev[k].1 == cur
                && before.1 == prev
                && self.gap(before.0, self.ev[k].0) >= unchanged
            {
                let phase = (self.ev[k].0 + self.frame - i % self.frame) % self.frame;
                if seen.insert(phase % self.repeat) {
                    out.push((phase, (k + 1) % n));
                }
            }
        }
        out
    }
}

/// How a capture's frame phase was found.
#[derive(Debug, Clone, PartialEq)]
pub struct LockInfo {
    /// Capture cycle (counted from the capture's first clock cycle) at which one phase was left.
    pub locked_at: u64,
    /// Where that cycle lies in the schedule's frame.
    pub frame_cycle: u64,
    pub slot: u64,
    pub slot_cycle: u64,
    /// CS/mux changes it took, and the phases the first one allowed.
    pub changes: u64,
    pub first_candidates: usize,
    /// The frame's CS/mux pins repeat every this many cycles (the frame when
    /// they do not): the phase is known modulo it, which is all the checks need.
    pub repeat_cycles: u64,
    /// Capture cycle at which strict checking began (no conversion in flight).
    pub checked_from: u64,
    /// Phases that fit the whole capture (1, unless the capture is shorter
    /// than what tells them apart: then they predict the same pins in every
    /// cycle of it, so every check gives the same result for each).
    pub phases: usize,
    /// Branches whose first conversion's mux settling the capture could not
    /// show (the mux moved before the capture began).
    pub settle_unknown: Vec<String>,
    /// Cycles the search had to forget (its buffer was full): checking began later.
    pub forgotten_cycles: u64,
}

impl fmt::Display for LockInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "locked on the frame phase at capture cycle {} (frame cycle {}, slot {}, cycle {} of the slot) after {} CS/mux change(s) ({} phase(s) fitted the first); checked from capture cycle {}",
            self.locked_at,
            self.frame_cycle,
            self.slot,
            self.slot_cycle,
            self.changes,
            self.first_candidates,
            self.checked_from
        )?;
        if self.repeat_cycles != 0 {
            write!(
                f,
                "; the CS/mux pins repeat every {} cycles, so the phase is known modulo that",
                self.repeat_cycles
            )?;
        }
        if self.phases > 1 {
            write!(
                f,
                "; {} phases predict the same pins in every cycle of this capture (it is too short to tell them apart), so every pin is checked alike for each",
                self.phases
            )?;
        }
        if !self.settle_unknown.is_empty() {
            write!(
                f,
                "; mux settling of the first conversion not shown for branch(es) {}",
                self.settle_unknown.join(", ")
            )?;
        }
        if self.forgotten_cycles > 0 {
            write!(
                f,
                "; the first {} cycles were not kept while searching",
                self.forgotten_cycles
            )?;
        }
        Ok(())
    }
}

/// Why a capture's frame phase could not be found (an input problem: exit 2).
#[derive(Debug, Clone, PartialEq)]
pub enum LockError {
    /// Not one CS or mux change in the capture.
    NoChanges { cycles: u64 },
    /// No phase of the schedule fits the CS/mux changes up to `cycle`.
    Impossible {
        cycle: u64,
        fitted_before: usize,
        detail: String,
    },
    /// The phase was found but the capture ended before a conversion boundary.
    TooShort { locked_at: u64, cycles: u64 },
}

impl fmt::Display for LockError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LockError::NoChanges { cycles } => write!(
                f,
                "the capture starts after reset and no CS or mux pin changes in its {cycles} cycles: the frame phase cannot be found (is it the right mix, are the pins mapped?)"
            ),
            LockError::Impossible {
                cycle,
                fitted_before,
                detail,
            } => write!(
                f,
                "no frame phase of this mix's schedule fits the capture's CS/mux pins at capture cycle {cycle} ({fitted_before} phase(s) fitted before it): {detail}; is it the right mix, or did the design go wrong before its phase could be found?"
            ),
            LockError::TooShort { locked_at, cycles } => write!(
                f,
                "the frame phase was found at capture cycle {locked_at} but the capture ({cycles} cycles) ends before a conversion boundary where checking could begin"
            ),
        }
    }
}

impl std::error::Error for LockError {}

/// One cycle as the capture gave it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Rec {
    rst: Option<bool>,
    pins: Pins,
    xz: Pins,
    miso: u64,
    miso_xz: u64,
}

/// Cycles kept while searching, run-length coded: (first cycle, record).
#[derive(Default)]
struct Buffer {
    runs: Vec<(u64, Rec)>,
    forgotten: u64,
}

/// Runs kept at most while searching; older ones are forgotten (checking
/// then begins later).
const MAX_RUNS: usize = 1 << 20;

impl Buffer {
    fn push(&mut self, i: u64, r: Rec) {
        if self.runs.last().map(|l| l.1) != Some(r) {
            if self.runs.len() >= MAX_RUNS {
                let drop = MAX_RUNS / 2;
                self.forgotten = self.runs[drop].0;
                self.runs.drain(..drop);
            }
            self.runs.push((i, r));
        }
    }

    fn first(&self) -> u64 {
        self.runs.first().map(|r| r.0).unwrap_or(0)
    }

    fn at(&self, i: u64) -> Rec {
        let k = self.runs.partition_point(|r| r.0 <= i);
        self.runs[k - 1].1
    }
}

struct Search {
    tpl: Template,
    /// A mix with switches: the mode the template runs (the one the `mode`
    /// pin shows), the cycle the search (re)started at, and why the last
    /// attempt failed (a switch's frame changes fit no one mode's template:
    /// the search starts over, and a change of `mode`, a frame start, gives
    /// the phase outright).
    mode: Option<usize>,
    since: u64,
    failed: Option<LockError>,
    cands: Option<Vec<(u64, usize)>>,
    prev: Option<Ctl>,
    changes: u64,
    /// Capture cycle of the last CS/mux change.
    last_change: u64,
    first_candidates: usize,
    buf: Buffer,
}

enum Mode {
    /// `rst` unknown so far.
    Waiting,
    /// Reset seen: today's check from reset.
    Reset(Box<Checker>),
    Search(Box<Search>),
    /// Phase found; checking begins at capture cycle `from` with `model`.
    Pending {
        search: Box<Search>,
        info: LockInfo,
        model: Box<CycleModel>,
        from: u64,
    },
    Joined(Box<Checker>, LockInfo),
    Failed(LockError),
}

/// A [`CycleSink`] that checks a capture from reset when it shows one, and
/// otherwise locks on its frame phase first.
pub struct WindowCheck<'a> {
    s: &'a Schedule,
    opts: CheckOptions,
    layout: Layout,
    /// CNV lanes (their CS view is inverted).
    flip: u16,
    /// Capture cycle of the next cycle.
    i: u64,
    mode: Mode,
    /// Whether `rst` has had a value: one that never has (a VCD without
    /// `$dumpvars` whose `rst` does not change) is taken as released.
    rst_seen: bool,
    /// The capture has ended: a pending join takes what it has.
    ending: bool,
}

impl<'a> WindowCheck<'a> {
    pub fn new(s: &'a Schedule, opts: CheckOptions) -> WindowCheck<'a> {
        let flip = s
            .mix
            .branches
            .iter()
            .enumerate()
            .filter(|(_, b)| b.adc.start == Start::Cnv)
            .fold(0u16, |a, (b, _)| a | 1 << b);
        WindowCheck {
            s,
            opts,
            layout: Layout::new(s),
            flip,
            i: 0,
            mode: Mode::Waiting,
            rst_seen: false,
            ending: false,
        }
    }

    /// The report, and how the phase was found when the capture did not start at reset.
    pub fn finish(mut self, source: &str) -> Result<(Verdict, Option<LockInfo>), LockError> {
        self.ending = true;
        if matches!(self.mode, Mode::Pending { .. }) {
            self.i -= 1;
            self.try_join();
            self.i += 1;
        }
        if let Mode::Search(search) = &mut self.mode {
            if let Some(c) = search.cands.take() {
                let n = c.len();
                // A phase whose next change falls inside the capture is wrong: it showed none.
                let c: Vec<(u64, usize)> = c
                    .into_iter()
                    .filter(|&k| search.tpl.next_change(k, search.last_change) >= self.i)
                    .collect();
                if !c.is_empty() {
                    // The rest predict the same CS/mux pins (and so every
                    // pin) in every cycle of the capture: check with one.
                    self.i -= 1;
                    self.locked(c[0].0, c.len());
                    self.i += 1;
                } else {
                    self.mode = Mode::Failed(LockError::Impossible {
                        cycle: self.i,
                        fitted_before: n,
                        detail: "every phase that fitted its changes needs another one before the capture ends".into(),
                    });
                }
            }
        }
        match self.mode {
            Mode::Waiting => Ok((Checker::new(self.s, self.opts).finish(source), None)),
            Mode::Reset(c) => Ok((c.finish(source), None)),
            Mode::Joined(c, info) => Ok((c.finish(source), Some(info))),
            Mode::Failed(e) => Err(e),
            Mode::Pending { info, .. } => Err(LockError::TooShort {
                locked_at: info.locked_at,
                cycles: self.i,
            }),
            Mode::Search(mut k) => Err(k
                .failed
                .take()
                .unwrap_or(LockError::NoChanges { cycles: self.i })),
        }
    }

    fn search_step(&mut self, r: Rec) {
        let i = self.i;
        let Mode::Search(search) = &mut self.mode else {
            unreachable!()
        };
        search.buf.push(i, r);
        let shown = r.pins.mode as usize;
        if search.mode.is_some_and(|m| m != shown) && shown < self.s.modes.len() {
            // `mode` changed: cycle i begins a frame, in the mode shown
            search.tpl = Template::new(self.s, Some(shown));
            search.mode = Some(shown);
            let f = search.tpl.frame;
            self.locked((f - i % f) % f, 1);
            return;
        }
        let cur = ctl(&r.pins);
        let known = ctl(&r.xz) == ctl(&NO_XZ);
        let prev = search.prev.replace(cur).filter(|_| known);
        if !known {
            // x/z on CS or a mux lane: start over once they are known.
            search.cands = None;
            search.prev = None;
            return;
        }
        let Some(prev) = prev.filter(|p| *p != cur) else {
            return;
        };
        search.changes += 1;
        search.last_change = i;
        let tpl = &search.tpl;
        let n = tpl.ev.len();
        let fitted_before = search.cands.as_ref().map(Vec::len);
        let cands = match search.cands.take() {
            None => {
                let c = tpl.candidates(i, i - search.since, prev, cur);
                search.first_candidates = c.len();
                c
            }
            Some(mut c) => {
                c.retain_mut(|(phase, k)| {
                    let (t, v) = tpl.ev[*k];
                    let ok = t == (i + *phase) % tpl.frame && v == cur;
                    *k = (*k + 1) % n;
                    ok
                });
                c
            }
        };
        match cands.len() {
            0 => {
                let e = LockError::Impossible {
                    cycle: i,
                    fitted_before: fitted_before.unwrap_or(0),
                    detail: format!(
                        "CS/mux pins change from {} to {}",
                        fmt_ctl(&prev),
                        fmt_ctl(&cur)
                    ),
                };
                if search.mode.is_some() {
                    search.failed = Some(e);
                    search.since = i;
                } else {
                    self.mode = Mode::Failed(e);
                }
            }
            1 => self.locked(cands[0].0, 1),
            _ => search.cands = Some(cands),
        }
    }

    /// One phase left (capture cycle `i` is frame cycle `(i + phase) % F`):
    /// find the first cycle the check can join at.
    fn locked(&mut self, phase: u64, phases: usize) {
        let Mode::Search(search) = std::mem::replace(&mut self.mode, Mode::Waiting) else {
            unreachable!()
        };
        let f = search.tpl.frame;
        let g = &self.s.grid;
        let i = self.i;
        let fc = (i + phase) % f;
        // Join after the first kept cycle: the checker needs the cycle before.
        let mut from = search.buf.first() + 1;
        let mut model = match search.mode {
            None => CycleModel::at(self.s, f + (from + phase) % f),
            // frame 3 of a model in the modes the capture showed
            Some(_) => self.model_in_modes(&search.buf, 3 * f + (from + phase) % f, from),
        };
        while !model.quiet() {
            model.step(0);
            from += 1;
        }
        let info = LockInfo {
            locked_at: i,
            frame_cycle: fc,
            slot: fc / g.slot_cycles,
            slot_cycle: fc % g.slot_cycles,
            changes: search.changes,
            first_candidates: search.first_candidates,
            repeat_cycles: if search.tpl.repeat < f {
                search.tpl.repeat
            } else {
                0
            },
            checked_from: from,
            phases,
            settle_unknown: Vec::new(),
            forgotten_cycles: search.buf.forgotten,
        };
        self.mode = Mode::Pending {
            search,
            info,
            model: Box::new(model),
            from,
        };
        self.try_join();
    }

    /// Frames after the join frame whose modes were decided before the
    /// capture could show why (`ModeTrack::join`): a joined model takes them
    /// from the `mode` pin, so the check waits until the capture showed the
    /// last one's first cycle (or ended).
    fn modes_known(&self) -> bool {
        let Mode::Pending {
            search,
            model,
            from,
            ..
        } = &self.mode
        else {
            return true;
        };
        if search.mode.is_none() || self.ending {
            return true;
        }
        let f = self.s.grid.frame_cycles;
        let learn = crate::model::ModeTrack::new(self.s).join(0);
        self.i + model.cycle() % f >= from + learn * f
    }

    /// The model at model cycle `at` (capture cycle `from`) with every
    /// frame up to the join's in the mode the capture shows at `from`, and
    /// the next frames' modes as the `mode` pin showed them at their starts.
    fn model_in_modes(&self, buf: &Buffer, at: u64, from: u64) -> CycleModel {
        let f = self.s.grid.frame_cycles;
        // capture cycle `start + k f` begins model frame `mf + k`
        let (mf, start) = (at / f, from as i64 - (at % f) as i64);
        let mut forced: Vec<(u64, usize)> = (2..=mf)
            .map(|g| (g, buf.at(from).pins.mode as usize))
            .collect();
        let learn = crate::model::ModeTrack::new(self.s).join(0);
        for d in 1..=learn {
            let c = (start + (d * f) as i64) as u64;
            if c <= self.i {
                forced.push((mf + d, buf.at(c).pins.mode as usize));
            }
        }
        let mut model = CycleModel::with_modes(self.s, &forced);
        while model.cycle() < at {
            model.step(0);
        }
        model
    }

    /// Joins once the capture has reached the cycle checking begins at.
    fn try_join(&mut self) {
        let Mode::Pending { from, .. } = &self.mode else {
            return;
        };
        if *from > self.i || !self.modes_known() {
            return;
        }
        let Mode::Pending {
            search,
            mut info,
            model,
            from,
        } = std::mem::replace(&mut self.mode, Mode::Waiting)
        else {
            unreachable!()
        };
        let model = match search.mode {
            Some(_) => Box::new(self.model_in_modes(&search.buf, model.cycle(), from)),
            None => model,
        };
        let at = model.cycle();
        let buf = &search.buf;
        let nb = self.layout.branches;
        let (mut mux_since, mut cs_rise) = (vec![None; nb], vec![None; nb]);
        for w in buf.runs.windows(2) {
            let ((_, a), (c, b)) = (w[0], w[1]);
            if c >= from {
                break;
            }
            let model_cycle = at.saturating_sub(from - c);
            for br in 0..nb {
                let l = &self.layout;
                if l.sel(&a.pins, br) != l.sel(&b.pins, br)
                    || l.en(&a.pins, br) != l.en(&b.pins, br)
                {
                    mux_since[br] = Some(model_cycle);
                }
                let view = |p: &Pins| (p.cs_n ^ self.flip) >> br & 1;
                if view(&a.pins) == 0 && view(&b.pins) == 1 {
                    cs_rise[br] = Some(model_cycle);
                }
            }
        }
        info.settle_unknown = (0..nb)
            .filter(|&b| mux_since[b].is_none())
            .map(|b| self.s.mix.branches[b].name.clone())
            .collect();
        let prev = buf.at(from - 1);
        let join = Join {
            capture_cycle: from,
            prev: prev.pins,
            prev_xz: prev.xz,
            mux_since,
            cs_rise,
            repeat: search.tpl.repeat,
        };
        let mut chk = Checker::join(self.s, self.opts, *model, &join);
        for c in from..=self.i {
            let r = buf.at(c);
            chk.cycle_xz(r.rst, &r.pins, &r.xz, r.miso, r.miso_xz);
        }
        self.mode = Mode::Joined(Box::new(chk), info);
    }
}

/// No bit unknown: an `xz` mask of every pin low.
const NO_XZ: Pins = Pins::LOW;

fn fmt_ctl(c: &Ctl) -> String {
    format!(
        "cs_n={:b} mux_sel={:#x} mux_en={:#x}",
        c.cs_n, c.mux_sel, c.mux_en
    )
}

impl CycleSink for WindowCheck<'_> {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, xz: &Pins, miso: u64, miso_xz: u64) {
        self.rst_seen |= rst.is_some();
        let rst = if self.rst_seen { rst } else { Some(false) };
        // Built only where the search keeps it: once joined, a cycle is
        // the checker's alone.
        let r = || Rec {
            rst,
            pins: *pins,
            xz: *xz,
            miso,
            miso_xz,
        };
        match &mut self.mode {
            Mode::Reset(c) | Mode::Joined(c, _) => c.cycle_xz(rst, pins, xz, miso, miso_xz),
            Mode::Failed(_) => {}
            _ if rst == Some(true) => {
                // A reset: check from it, as always.
                let mut c = Checker::new(self.s, self.opts);
                c.cycle_xz(rst, pins, xz, miso, miso_xz);
                self.mode = Mode::Reset(Box::new(c));
            }
            Mode::Waiting => {
                // A VCD without `$dumpvars` gives a port no value before its
                // first change: the capture is read from where every pin
                // the search reads has one, as a window, and an `rst` that
                // never had a value is taken as released (a reset that
                // shows up later still wins, above).  Capture cycles are
                // counted from there.
                let unknown = xz.cs_n != 0 || xz.sclk != 0 || xz.mux_sel != 0 || xz.mux_en != 0;
                if rst != Some(true) && !unknown {
                    let mode = (self.s.modes.len() > 1)
                        .then(|| (pins.mode as usize).min(self.s.modes.len() - 1));
                    self.mode = Mode::Search(Box::new(Search {
                        tpl: Template::new(self.s, mode),
                        mode,
                        since: 0,
                        failed: None,
                        cands: None,
                        prev: None,
                        changes: 0,
                        last_change: 0,
                        first_candidates: 0,
                        buf: Buffer::default(),
                    }));
                    self.search_step(r());
                } else {
                    // Not read yet: capture cycles count from the first
                    // one read.
                    return;
                }
            }
            Mode::Search(_) => self.search_step(r()),
            Mode::Pending { search, .. } => {
                search.buf.push(self.i, r());
                self.try_join();
            }
        }
        self.i += 1;
    }
}
