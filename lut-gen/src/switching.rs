//! When a mode switch happens (docs/timing.md, "Mode switches"), and the
//! worst reaction latency it implies, from the schedule alone.
//!
//! The contract in brief (F = `frame_cycles`, frame `f` = cycles
//! `[f F, (f+1) F)`): a mode is in force for whole frames; the mode of frame
//! `f + 2` is decided at the edge that begins frame `f + 1` (one frame
//! ahead, so every branch's mux can address the next frame's first instant
//! in the new mode's table as soon as its last instant of the old frame
//! has passed). Pin select: the decision is `mode_sel` as it is during the
//! last cycle of frame `f`. Auto: the decision is the first trigger, in
//! file order, armed in frame `f + 1`'s mode whose condition held in its
//! last `for_frames` windows, window `w` being every watched sample whose
//! conversion completes (`E = t + R`) in frame `w`.

use serde::Serialize;

use crate::mix::When;
use crate::schedule::Schedule;

/// The first sampling instant of a frame of `s`, in cycles from the
/// frame's start: the earliest instant a part holds its input, a
/// conversion's start plus its part's [`Schedule::sample_after`] (an
/// MCP3208 holds its input 6 us into its transaction); `None`: the
/// schedule samples nothing.
pub fn first_instant(s: &Schedule) -> Option<u64> {
    (0..s.branches.len())
        .filter_map(|b| {
            let slot = (0..s.grid.frame_slots).find(|&slot| s.at(slot, b).is_some())?;
            Some(slot * s.grid.slot_cycles + s.sample_after(b))
        })
        .min()
}

/// Worst cycles from the cycle `mode_sel` first shows mode `to` to the first
/// sample of `to`: the value is sampled in a frame's last cycle and applies
/// a frame later, so a change just after one sampling waits a whole frame
/// for the next one and one more for the switch: `2 F + first_instant(to)`.
pub fn pin_latency(s: &Schedule, to: usize) -> u64 {
    let ms = s.modes.get(to).unwrap_or(s);
    2 * s.grid.frame_cycles + first_instant(ms).unwrap_or(0)
}

/// The worst reaction of one trigger.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct TriggerLatency {
    /// The trigger's index among the mix's `[[trigger]]` tables.
    pub trigger: usize,
    /// The mode it leaves where the worst case is (the first such mode on a tie).
    pub from: usize,
    pub to: usize,
    /// Cycles from the first watched sample past the level to the first
    /// sample of mode `to`.
    pub cycles: u64,
    /// That first sample past the level: its channel (a watched one: in a
    /// chain, the first watched member of the conversion) and its instant in
    /// cycles from its frame's start.
    pub channel: usize,
    pub instant: u64,
}

/// Trigger `k`'s worst latency over every mode it leaves (`None`: the mix
/// has no such trigger).
pub fn trigger_latency(s: &Schedule, k: usize) -> Option<TriggerLatency> {
    let t = s.mix.modes.as_ref()?.triggers.get(k)?;
    let to = s.modes.get(t.to)?;
    let first_to = first_instant(to)?;
    let mut worst: Option<TriggerLatency> = None;
    for (m, from) in s.modes.iter().enumerate().filter(|&(m, _)| t.leaves(m)) {
        for (cycles, channel, instant) in latencies(from, t, first_to) {
            if worst.is_none_or(|w| cycles > w.cycles) {
                worst = Some(TriggerLatency {
                    trigger: k,
                    from: m,
                    to: t.to,
                    cycles,
                    channel,
                    instant,
                });
            }
        }
    }
    worst
}

/// For each watched instant `t0` of a frame of `from` (taken in frame 1,
/// after a whole frame of `from`): the latency if `t0` is the first sample
/// past the level, `(cycles, watched channel, t0 - F)`.
///
/// Closed form: windows hold from `w0` on, where `w0` is `t0`'s window for
/// `above` (the sample itself is past the level, and every later window has
/// samples of its channel after it) and for `below` also past the window of
/// every watched sample taken before `t0` (any of them is not past the
/// level); the decision follows window `w0 + n - 1` and applies a frame
/// after that: the switch is at frame `w0 + n + 1`.
fn latencies(from: &Schedule, t: &crate::mix::Trigger, first_to: u64) -> Vec<(u64, usize, u64)> {
    let f = from.grid.frame_cycles;
    // an instant converts its lead's chain: name the watched member in it
    let watched = |lead: usize| {
        t.channels
            .iter()
            .copied()
            .find(|&c| from.mix.lead_of(c) == lead)
    };
    let seen: Vec<(u64, u64, usize)> = from
        .instants(2)
        .filter_map(|i| {
            let c = watched(i.channel)?;
            let e = i.cycle + from.branches[i.branch].spi.tick_to_complete();
            // the cause is the sample's instant, where its part held it
            Some((i.cycle + from.sample_after(i.branch), e / f, c))
        })
        .collect();
    let n = t.for_frames as u64;
    seen.iter()
        .filter(|&&(t0, _, _)| t0 >= f)
        .map(|&(t0, w, c)| {
            let w0 = match t.when {
                When::Above => w,
                When::Below => seen
                    .iter()
                    .filter(|&&(s, _, _)| s < t0)
                    .map(|&(_, ws, _)| ws + 1)
                    .fold(w, u64::max),
            };
            ((w0 + n + 1) * f + first_to - t0, c, t0 - f)
        })
        .collect()
}
