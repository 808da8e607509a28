//! The reaction to a mode switch as a run measured it: for each switch the
//! pins showed, the cycles from its cause (the first watched sample past the
//! trigger's level, its condition holding from then on; or the first cycle
//! `mode_sel` showed the new mode) to the first sample at the new rates,
//! beside the audit's worst case for the same trigger or pin
//! (docs/timing.md, "Mode switches").

use lut_gen::{ModeSelect, Schedule, Trigger, When};

use crate::scenelog::{SceneLog, Strobe};

/// One switch of a run and the reaction measured to it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Reaction {
    /// The trigger that decided it (index among the `[[trigger]]` tables);
    /// `None`: the `mode_sel` pin.
    pub trigger: Option<usize>,
    pub from: usize,
    pub to: usize,
    /// The first frame in mode `to`.
    pub frame: u64,
    /// The cause: the instant of the first watched sample past the level,
    /// or the first cycle of the request on `mode_sel`.
    pub cause: u64,
    /// The first sampling instant at the new rates (of a sample that left on
    /// the sample port).
    pub first: u64,
    /// The audit's worst case for the same trigger (or the pin's for `to`).
    pub predicted: u64,
}

impl Reaction {
    pub fn measured(&self) -> u64 {
        self.first.saturating_sub(self.cause)
    }
}

/// Every switch in the log with its reaction (a switch whose cause the run
/// does not show, such as one decided from samples before the log, is left
/// out).
pub fn reactions(s: &Schedule, log: &SceneLog) -> Vec<Reaction> {
    let Some(modes) = s.mix.modes.as_ref() else {
        return Vec::new();
    };
    let f = s.grid.frame_cycles;
    let mut out = Vec::new();
    let mut stint = 0;
    for w in log.frames.windows(2) {
        let (from, to) = (w[0].mode as usize, w[1].mode as usize);
        if from == to {
            continue;
        }
        let frame = w[1].frame;
        let first = log
            .strobes
            .iter()
            .filter_map(|x| log.instant(s, x))
            .filter(|&t| t >= frame * f)
            .min();
        let cause = match modes.select {
            ModeSelect::Pin => request(log, to, frame, f).map(|c| (None, c, pin(s, to))),
            ModeSelect::Auto => modes
                .triggers
                .iter()
                .enumerate()
                .filter(|(_, t)| t.to == to && t.leaves(from))
                .find_map(|(k, t)| {
                    let c = onset(s, log, t, stint, frame)?;
                    Some((Some(k), c, lut_gen::trigger_latency(s, k)?.cycles))
                }),
        };
        if let (Some((trigger, cause, predicted)), Some(first)) = (cause, first) {
            out.push(Reaction {
                trigger,
                from,
                to,
                frame,
                cause,
                first,
                predicted,
            });
        }
        stint = frame;
    }
    out
}

fn pin(s: &Schedule, to: usize) -> u64 {
    lut_gen::pin_latency(s, to)
}

/// The first cycle of the run of `mode_sel == to` that the decision before
/// frame `frame` saw (the pin in the last cycle of frame `frame - 2`).
fn request(log: &SceneLog, to: usize, frame: u64, f: u64) -> Option<u64> {
    let seen_at = (frame.checked_sub(1)? * f).checked_sub(1)?;
    let i = log.requests.partition_point(|r| r.0 <= seen_at);
    let r = log.requests.get(i.checked_sub(1)?)?;
    (r.1 as usize == to).then_some(r.0)
}

/// Trigger `t`'s cause of the switch at `frame` in a stint of its mode from
/// frame `stint` on: the instant of the first watched sample past its level
/// from which its condition held until the decision (windows by the frame
/// a conversion completes in), or `None` if it did not hold `for_frames`
/// windows up to window `frame - 2`.
fn onset(s: &Schedule, log: &SceneLog, t: &Trigger, stint: u64, frame: u64) -> Option<u64> {
    let f = s.grid.frame_cycles;
    let last = frame.checked_sub(2)?;
    // (instant, window, value) of every watched sample of the stint
    let seen: Vec<(u64, u64, u16)> = log
        .strobes
        .iter()
        .filter(|x| t.channels.contains(&x.channel))
        .filter_map(|x: &Strobe| {
            let i = log.instant(s, x)?;
            let branch = s.mix.channels[x.channel].branch;
            let w = (i + s.branches[branch].spi.read_cycles) / f;
            (i >= stint * f && w <= last).then_some((i, w, x.value))
        })
        .collect();
    let past = |v: u16| match t.when {
        When::Above => v as u32 > t.level,
        When::Below => (v as u32) < t.level,
    };
    let holds = |w: u64| {
        let mut inw = seen.iter().filter(|x| x.1 == w);
        match t.when {
            When::Above => inw.any(|x| past(x.2)),
            When::Below => {
                let v: Vec<_> = inw.collect();
                !v.is_empty() && v.iter().all(|x| past(x.2))
            }
        }
    };
    // the run of windows that held, back from the decision's last one
    let mut w0 = last + 1;
    while w0 > stint && holds(w0 - 1) {
        w0 -= 1;
    }
    if last + 1 - w0 < t.for_frames as u64 {
        return None;
    }
    match t.when {
        When::Above => seen
            .iter()
            .filter(|x| x.1 == w0 && past(x.2))
            .map(|x| x.0)
            .min(),
        // after the last watched sample not past the level
        When::Below => {
            let wrong = seen.iter().filter(|x| !past(x.2)).map(|x| x.0).max();
            seen.iter()
                .filter(|x| wrong.is_none_or(|k| x.0 > k))
                .map(|x| x.0)
                .min()
        }
    }
}
