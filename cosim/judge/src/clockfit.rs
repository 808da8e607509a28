//! The design's clock as a capture saw it.
//!
//! A logic analyser's timestamps come from its own oscillator, the design's
//! edges from the board's: the two differ by tens of ppm, which over a
//! capture of milliseconds is microseconds, many design cycles.  The time
//! checks hold every edge to the nominal clock, so before them the capture's
//! clock is measured from its conversion starts (every conversion starts on
//! the slot grid: docs/timing.md), the times are scaled to the mix's clock,
//! and the report's times are scaled back to the capture's own.

use crate::timed::{Capture, TimedReport};

/// Offsets beyond this are no crystal's tolerance: the capture is checked
/// at the nominal clock (its edges then fail where they drift), not scaled.
const MAX_PPM: f64 = 1000.0;

/// The capture's clock against the mix's: `ppm` parts per million slow
/// (positive: each design cycle spans more of the capture's time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ClockFit {
    pub ppm: f64,
    /// The fit's standard error, in ppm (the analyser's sampling puts up
    /// to a sample period on each start).
    sigma: f64,
    /// The most the sampling can tilt the line, in ppm: a sample period at
    /// each end of the starts' span, twice.  The sampling's error is not
    /// noise when the sample period and the slot beat (it sweeps slowly
    /// across the starts), so the standard error alone understates it.
    bias: f64,
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

/// Fits the conversion starts to a slot grid: each gap is a whole number
/// of slots at the nominal clock (rounded), and a least-squares line
/// through (slot index, time) gives the slot's length in the capture's
/// time.  `None` when there are too few starts, or the gaps do not sit on
/// a grid (a design that starts conversions off the slot grid is judged at
/// the nominal clock, where its edges fail).
pub(crate) fn fit(s: &lut_gen::Schedule, cap: &Capture) -> Option<ClockFit> {
    let slot_ps = s.grid.slot_cycles as f64 * 1e12 / s.mix.clock_hz as f64;
    let t = starts(s, cap);
    if t.len() < 8 {
        return None;
    }
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
    let n = k.len() as f64;
    let (mk, mt) = (
        k.iter().sum::<f64>() / n,
        t.iter().map(|&x| x as f64).sum::<f64>() / n,
    );
    let (mut cov, mut var) = (0.0, 0.0);
    for (ki, &ti) in k.iter().zip(&t) {
        cov += (ki - mk) * (ti as f64 - mt);
        var += (ki - mk) * (ki - mk);
    }
    if var == 0.0 {
        return None;
    }
    let slope = cov / var;
    let ppm = (slope / slot_ps - 1.0) * 1e6;
    let icpt = mt - slope * mk;
    let sq: f64 = (k.iter().zip(&t))
        .map(|(ki, &ti)| (ti as f64 - icpt - slope * ki).powi(2))
        .sum();
    let sigma = (sq / (n - 2.0)).sqrt() / var.sqrt() / slot_ps * 1e6;
    let span = (t[t.len() - 1] - t[0]) as f64;
    let bias = 2.0 * 2.0 * cap.period_ps as f64 / span * 1e6;
    let t0 = cap.steps.first().map_or(0, |x| x.0);
    Some(ClockFit {
        ppm,
        sigma,
        bias,
        t0,
    })
}

impl ClockFit {
    /// Whether the capture is scaled: an offset a crystal can have, and
    /// one the fit tells from none (beyond three standard errors and the
    /// sampling's tilt), so a capture at the mix's clock is checked as it
    /// was taken.
    pub(crate) fn worth_scaling(&self) -> bool {
        let a = self.ppm.abs();
        a > 3.0 * self.sigma && a > self.bias && a <= MAX_PPM
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
    }
}
