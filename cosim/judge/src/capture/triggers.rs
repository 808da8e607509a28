//! The switch decisions of an auto-select capture (docs/timing.md, "Mode
//! switches"): the frames were judged against the modes the design's
//! `mode` output showed; here each of those modes is held to the decision
//! the triggers make on the samples the capture's MISO carried.
//!
//! The model runs along the capture at the phase found, with the design's
//! modes given (so each trigger's run of windows is the one the design's
//! own switches leave), reading MISO as the capture shows it in the middle
//! of each cycle; its triggers' decision for every frame whose windows all
//! lie inside the capture must be the mode the frame ran.

use lut_gen::{ModeSelect, Role, Schedule};

use crate::capture::check::{Capture, TimedViolation};
use crate::capture::modes::{ModeSource, Modes};
use crate::model::CycleModel;

/// What the decisions check found, proved and could not.
#[derive(Default)]
pub(crate) struct TriggerCheck {
    pub violations: Vec<TimedViolation>,
    pub proved: Vec<String>,
    pub not_proved: Vec<String>,
}

/// The decisions of the frames of phase `(lo, hi)` with `modes`.
pub(crate) fn check(
    s: &Schedule,
    cap: &Capture,
    src: &ModeSource,
    (lo, hi): (i128, i128),
    modes: &Modes,
) -> TriggerCheck {
    let mut out = TriggerCheck::default();
    let Some(plan) = s.mode_plan().filter(|p| p.select == ModeSelect::Auto) else {
        return out;
    };
    let mut watched: Vec<usize> = (plan.triggers.iter())
        .flat_map(|t| t.channels.iter().map(|&c| s.mix.channels[c].branch))
        .collect();
    watched.sort_unstable();
    watched.dedup();
    let miso =
        |b: usize| (cap.lanes.iter()).position(|l| l.role == Some(Role::Miso) && l.bit == b as u32);
    let missing: Vec<String> = (watched.iter())
        .filter(|&&b| miso(b).is_none())
        .map(|&b| format!("adc_miso[{b}]"))
        .collect();
    // MISO is read in the middle of a cycle: the capture must resolve it
    let res_ps = src.res / src.clock;
    let coarse: Vec<String> = (watched.iter())
        .filter(|&&b| res_ps as f64 >= 1e12 / s.mix.branches[b].sclk_hz as f64 / 2.0)
        .map(|&b| s.mix.branches[b].name.clone())
        .collect();
    if !missing.is_empty() || !coarse.is_empty() {
        out.not_proved.push(if missing.is_empty() {
            format!(
                "the switch decisions: the capture's resolution ({:.1} ns) cannot read MISO of branch {} bit by bit; the frames were judged against the modes the `mode` output showed",
                res_ps as f64 / 1e3,
                coarse.join(", ")
            )
        } else {
            format!(
                "the switch decisions (map {} to read the samples the triggers watch); the frames were judged against the modes the `mode` output showed",
                missing.join(", ")
            )
        });
        return out;
    }
    let lanes: Vec<(usize, usize)> = (0..s.mix.branches.len())
        .filter_map(|b| Some((b, miso(b)?)))
        .collect();
    let decided = run(s, cap, src, (lo, hi), modes, &lanes);
    let names = &plan.names;
    let reach = plan
        .triggers
        .iter()
        .map(|t| t.for_frames.max(1) as u64)
        .max();
    // windows of frames w0 + 1 on are read whole from the capture
    let judged_from = decided.w0 + 2 + reach.unwrap_or(1);
    let mut judged = 0;
    for &(w, d) in &decided.list {
        if w < judged_from || w > decided.w_end {
            continue;
        }
        judged += 1;
        let ran = modes.of(src, lo, hi, w);
        if d != ran {
            out.violations.push(TimedViolation {
                time_ps: ((lo + (hi - lo) / 2 + w as i128 * src.frame * src.tc) / src.clock)
                    as u64,
                channel: src.lane_names(cap),
                port_bit: "mode".into(),
                rule: "mode decision (the triggers on the captured samples)".into(),
                detail: format!(
                    "the frame runs mode {ran} ({}), but the triggers' windows of the samples MISO carried decide mode {d} ({})",
                    names[ran], names[d]
                ),
            });
        }
    }
    out.proved.push(format!(
        "the switch decisions of {judged} frame(s): each frame's mode the one the triggers decide on the samples MISO carried (read in the middle of each cycle)"
    ));
    out
}

/// The triggers' decisions along the capture: `(frame, mode)` by the
/// phase's frame numbers, and the frames the capture holds whole.
struct Decided {
    list: Vec<(u64, usize)>,
    w0: u64,
    w_end: u64,
}

/// Runs the model from two frames before the capture's first whole frame
/// (`w0`, the model's frame 2) to its end, its modes those of `modes`,
/// MISO of branch `b` from capture lane `lanes[..] = (b, lane)`.
fn run(
    s: &Schedule,
    cap: &Capture,
    src: &ModeSource,
    (lo, hi): (i128, i128),
    modes: &Modes,
    lanes: &[(usize, usize)],
) -> Decided {
    let f = src.frame;
    let mid = lo + (hi - lo) / 2;
    let frame_t = f * src.tc;
    let w0 = ((src.start - mid).max(0) + frame_t - 1) / frame_t;
    let w0 = w0 as u64;
    let w_end = ((src.end - mid) / frame_t).max(0) as u64;
    let forced: Vec<(u64, usize)> = (w0..=w_end + 2)
        .map(|w| (w - w0 + 2, modes.of(src, lo, hi, w)))
        .collect();
    let mut m = CycleModel::with_modes(s, &forced);
    m.modes_mut().keep_decisions();
    let base = (w0 as i128 - 2) * f;
    let cycles = (w_end - w0 + 3) as i128 * f;
    let steps = &cap.steps;
    let mut k = 0usize;
    for c in 0..cycles {
        let t = mid + (base + c) * src.tc + src.tc / 2;
        let ps = (t / src.clock).max(0) as u64;
        while k + 1 < steps.len() && steps[k + 1].0 <= ps {
            k += 1;
        }
        let inside = t >= src.start && t <= src.end;
        let miso = match inside {
            true => (lanes.iter()).fold(0u64, |a, &(b, l)| a | (steps[k].1 >> l & 1) << b),
            false => 0,
        };
        m.step(miso);
    }
    let list = (m.modes().decisions().iter())
        .filter(|d| d.0 >= 2)
        .map(|&(fm, d)| (fm + w0 - 2, d))
        .collect();
    Decided { list, w0, w_end }
}
