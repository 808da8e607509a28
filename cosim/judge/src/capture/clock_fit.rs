//! The design's clock as a capture saw it.
//!
//! A logic analyser's timestamps come from its own oscillator, the design's
//! edges from the board's: the two differ by tens of ppm, which over a
//! capture of milliseconds is microseconds, many design cycles.  The time
//! checks hold every edge to the nominal clock, so before them the capture's
//! clock is measured from its conversion starts (every conversion starts on
//! the slot grid: docs/timing.md), the times are scaled to the mix's clock,
//! and the report's times are scaled back to the capture's own.

use crate::capture::check::{Capture, TimedReport};

/// Offsets beyond this are no crystal's tolerance: the capture is checked
/// at the nominal clock (its edges then fail where they drift), not scaled.
const MAX_PPM: f64 = 1000.0;

/// The capture's clock against the mix's: `ppm` parts per million slow
/// (positive: each design cycle spans more of the capture's time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ClockFit {
    pub ppm: f64,
    /// Whether the mix's own clock fits every start (the capture is then
    /// checked as it was taken).
    nominal_fits: bool,
    /// How far the times scaled by `ppm` can stray from the design's clock
    /// over the capture, in ps.
    uncertainty_ps: f64,
    /// The capture's first time, which scaling keeps.
    t0: u64,
}

/// The conversion starts on the capture's CS (or CNV) lanes: each lane's
/// edges to its active level.
fn starts(s: &lut_gen::Schedule, cap: &Capture) -> Vec<u64> {
    let mut out = Vec::new();
    for (i, l) in cap.lanes.iter().enumerate() {
        if l.role != Some(lut_gen::Role::CsN) {
            continue;
        }
        let Some(br) = s.mix.branches.get(l.bit as usize) else {
            continue;
        };
        let active = u64::from(br.adc.start == lut_gen::Start::Cnv);
        for w in cap.steps.windows(2) {
            let (was, now) = (w[0].1 >> i & 1, w[1].1 >> i & 1);
            if was != now && now == active {
                out.push(w[1].0);
            }
        }
    }
    out.sort_unstable();
    out
}

/// Each start's slot on the grid: every gap is a whole number of slots at
/// the nominal clock (rounded).  `None` when a gap is not (a design that
/// starts conversions off the slot grid is judged at the nominal clock,
/// where its edges fail).
fn slots(t: &[u64], slot_ps: f64) -> Option<Vec<f64>> {
    let mut k = vec![0f64];
    for w in t.windows(2) {
        let gap = (w[1] - w[0]) as f64 / slot_ps;
        let n = gap.round();
        // within a tenth of a slot of the grid, even at the largest offset
        if (gap - n).abs() > 0.1 + gap * MAX_PPM * 1e-6 {
            return None;
        }
        k.push(k.last().unwrap() + n);
    }
    Some(k)
}

/// The least-squares slope (ps per slot) of the starts `t` at slots `k`.
fn least_squares(k: &[f64], t: &[u64]) -> Option<f64> {
    let n = k.len() as f64;
    let mk = k.iter().sum::<f64>() / n;
    let mt = t.iter().map(|&x| x as f64).sum::<f64>() / n;
    let (mut cov, mut var) = (0.0, 0.0);
    for (ki, &ti) in k.iter().zip(t) {
        cov += (ki - mk) * (ti as f64 - mt);
        var += (ki - mk) * (ki - mk);
    }
    (var > 0.0).then(|| cov / var)
}

/// The slopes (ps per slot) of every line through all the starts when each
/// happened up to `slack_ps` before the time the capture shows it (a
/// sample period, plus the lanes' skew on either side): for two starts `i`
/// before `j`, the slope lies within `(t_j - t_i -+ slack) / (k_j - k_i)`.
/// Taken over the pairs of at most 512 starts spread over the capture (a
/// subset's bounds hold for the whole, only looser).  `None` when no line
/// fits: the starts are not on one clock.
fn feasible_slopes(k: &[f64], t: &[u64], slack_ps: f64) -> Option<(f64, f64)> {
    let n = k.len();
    let pick: Vec<usize> = (0..n.min(512))
        .map(|i| i * (n - 1) / (n.min(512) - 1).max(1))
        .collect();
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for (a, &i) in pick.iter().enumerate() {
        for &j in &pick[a + 1..] {
            let dk = k[j] - k[i];
            if dk > 0.0 {
                let dt = t[j] as f64 - t[i] as f64;
                lo = lo.max((dt - slack_ps) / dk);
                hi = hi.min((dt + slack_ps) / dk);
            }
        }
    }
    (lo <= hi && lo.is_finite()).then_some((lo, hi))
}

/// Fits the conversion starts to a slot grid: the slot's length in the
/// capture's time is the least-squares slope through (slot index, time),
/// kept within the slopes every start allows given the sampling (see
/// [`feasible_slopes`]), which also bound its error.  `None` when there
/// are too few starts, they do not sit on a grid, or no one clock fits them.
pub(crate) fn fit(s: &lut_gen::Schedule, cap: &Capture, skew_ps: u64) -> Option<ClockFit> {
    let slot_ps = s.grid.slot_cycles as f64 * 1e12 / s.mix.clock_hz as f64;
    let t = starts(s, cap);
    if t.len() < 8 {
        return None;
    }
    let k = slots(&t, slot_ps)?;
    let (lo, hi) = feasible_slopes(&k, &t, (cap.period_ps + 2 * skew_ps) as f64)?;
    let slope = least_squares(&k, &t)?.clamp(lo, hi);
    let t0 = cap.steps.first().map_or(0, |x| x.0);
    let span_slots = cap.steps.last().map_or(0, |x| x.0 - t0) as f64 / slot_ps;
    Some(ClockFit {
        ppm: (slope / slot_ps - 1.0) * 1e6,
        nominal_fits: (lo..=hi).contains(&slot_ps),
        uncertainty_ps: (slope - lo).max(hi - slope) * span_slots,
        t0,
    })
}

impl ClockFit {
    /// Whether the capture is scaled: an offset a crystal can have, and the
    /// mix's own clock does not fit every start (a capture at the mix's
    /// clock is checked as it was taken).
    pub(crate) fn worth_scaling(&self) -> bool {
        !self.nominal_fits && self.ppm.abs() <= MAX_PPM
    }

    /// How far the scaled times can stray from the design's clock by the
    /// end of the capture, in ps (from the slopes the starts allow).  The
    /// time checks widen each edge's tolerance by it, as by a skew.
    pub(crate) fn uncertainty_ps(&self) -> u64 {
        self.uncertainty_ps.ceil() as u64
    }

    fn factor(&self) -> f64 {
        1.0 + self.ppm * 1e-6
    }

    /// The capture with its times at the mix's clock.
    pub(crate) fn scaled(&self, cap: &Capture) -> Capture {
        let f = self.factor();
        Capture {
            lanes: cap.lanes.clone(),
            period_ps: (cap.period_ps as f64 / f).round() as u64,
            steps: (cap.steps.iter())
                .map(|&(t, v)| (self.t0 + ((t - self.t0) as f64 / f).round() as u64, v))
                .collect(),
        }
    }

    /// A time of the scaled capture, in the capture's own.
    fn back(&self, t: u64) -> u64 {
        self.t0 + (t.saturating_sub(self.t0) as f64 * self.factor()).round() as u64
    }

    /// The report's times back in the capture's own, and the offset said.
    pub(crate) fn unscale(&self, r: &mut TimedReport) {
        r.locked_at_ps = self.back(r.locked_at_ps);
        for v in &mut r.violations {
            v.time_ps = self.back(v.time_ps);
        }
        if let Some(j) = &mut r.link_join {
            j.header_ps = j.header_ps.map(|t| self.back(t));
            j.unjudged_ps = self.back(j.unjudged_ps);
        }
        if let Some(m) = &mut r.modes {
            for sw in &mut m.switches {
                sw.0 = self.back(sw.0);
            }
        }
        r.clock_ppm = Some(-self.ppm);
        r.clock_uncertainty_ps = self.uncertainty_ps();
    }
}
