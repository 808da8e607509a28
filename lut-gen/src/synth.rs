//! Schedule synthesis: choose the slot grid, then give every channel an
//! offset so that no two conversions of a branch share a slot.
//!
//! A channel of period `p` slots occupies the residue class `offset mod p` of
//! the frame's `N` slots.  When a branch's periods form a divisibility chain
//! (harmonic rates) first-fit in increasing period order never fails while
//! the branch's density is at most 1, so it is used first; otherwise (and for
//! sync groups, which couple branches) an exact search decides (`search`):
//! it finds a schedule, or proves there is none, or says it could not tell
//! within its bound ([`Verdict::Unknown`]), never "infeasible" without a proof.
//! Every result is re-checked by [`crate::validate`], which shares no code
//! with this module.

use std::fmt;

use serde::Serialize;

use crate::mix::Mix;
use crate::parts::{ns_to_cycles, SpiTiming};
use crate::schedule::{BranchPlan, ChannelSlots, FrameGrid, Placement, Schedule};

mod modes;
mod search;

// For this crate's tests only (`crate::for_tests`).
pub use modes::{on_grid, one_mode};

/// The summary of a channel a mode does not sample: no slot, no interval.
const UNSAMPLED: ChannelSlots = ChannelSlots {
    samples_per_frame: 0,
    period_slots: 0,
    offset_slot: 0,
    interval_cycles: 0,
    device: 0,
    select: 0,
};

/// Placements the exact search may try per slot-grid candidate.
pub const SEARCH_BUDGET: u64 = 400_000;

/// A mix without a schedule, and why: proved to have none, or not found
/// within the search's bound.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Infeasible {
    pub mix: String,
    pub verdict: Verdict,
    /// The slot grid the diagnosis refers to (the roomiest legal one), if any.
    pub slots_per_slice: Option<u64>,
    pub reasons: Vec<String>,
    pub branches: Vec<BranchDiagnosis>,
    pub suggestions: Vec<String>,
}

/// How sure the "no schedule" is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Proved: a count (demand over capacity, periods that are not whole
    /// slots, slots too short) or an exhausted search of every grid.
    Infeasible,
    /// The exact search stopped at its bound on some grid without a
    /// schedule and without a proof: the mix may or may not fit.
    Unknown,
}

impl Verdict {
    /// The word the CLI and the JSON use.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Infeasible => "infeasible",
            Verdict::Unknown => "unknown",
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BranchDiagnosis {
    pub name: String,
    pub demand_hz: u64,
    pub capacity_hz: f64,
    pub demand_slots_per_frame: u64,
    pub capacity_slots_per_frame: u64,
    pub unplaced: Vec<String>,
}

impl fmt::Display for Infeasible {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // An over-full branch is the headline: demand against capacity.
        // (a channel faster than its part comes before it)
        let lead = self
            .reasons
            .iter()
            .find(|r| r.contains("conversions per slice"))
            .filter(|_| !self.reasons[0].contains("can convert"));
        match (self.verdict, lead) {
            (Verdict::Unknown, _) => writeln!(
                f,
                "mix `{}`: unknown: no jitter-free schedule found within the search bound, and none proved impossible",
                self.mix
            )?,
            (Verdict::Infeasible, Some(r)) => {
                writeln!(f, "{r}: mix `{}` has no jitter-free schedule", self.mix)?
            }
            (Verdict::Infeasible, None) => {
                writeln!(f, "mix `{}` has no jitter-free schedule", self.mix)?
            }
        }
        if let Some(s) = self.slots_per_slice {
            writeln!(
                f,
                "  (diagnosed at {s} slots per slice, the roomiest legal grid)"
            )?;
        }
        for r in self.reasons.iter().filter(|r| Some(*r) != lead) {
            writeln!(f, "  - {r}")?;
        }
        for b in &self.branches {
            if b.unplaced.is_empty() && b.demand_slots_per_frame <= b.capacity_slots_per_frame {
                continue;
            }
            writeln!(
                f,
                "  branch `{}`: demand {} samples/s ({} slots/frame) vs capacity {:.0} samples/s ({} slots/frame)",
                b.name, b.demand_hz, b.demand_slots_per_frame, b.capacity_hz, b.capacity_slots_per_frame
            )?;
            if !b.unplaced.is_empty() {
                writeln!(f, "    could not place: {}", b.unplaced.join(", "))?;
            }
        }
        if !self.suggestions.is_empty() {
            writeln!(f, "  what would make it fit:")?;
            for s in &self.suggestions {
                writeln!(f, "  * {s}")?;
            }
        }
        Ok(())
    }
}

impl std::error::Error for Infeasible {}

/// Channels that must sample together: a sync group, or one channel alone.
#[derive(Debug, Clone)]
struct Unit {
    channels: Vec<usize>,
    branches: Vec<usize>,
    period: u64,
}

/// Per-branch slot occupancy of one frame.
struct Occupancy {
    words: Vec<Vec<u64>>,
}

impl Occupancy {
    fn new(branches: usize, slots: u64) -> Self {
        Occupancy {
            words: vec![vec![0; slots.div_ceil(64) as usize]; branches],
        }
    }
    fn taken(&self, b: usize, s: u64) -> bool {
        self.words[b][(s / 64) as usize] >> (s % 64) & 1 == 1
    }
    fn fits(&self, u: &Unit, offset: u64, slots: u64) -> bool {
        u.branches.iter().all(|&b| {
            (offset..slots)
                .step_by(u.period as usize)
                .all(|s| !self.taken(b, s))
        })
    }
    fn take(&mut self, u: &Unit, offset: u64, slots: u64) {
        for &b in &u.branches {
            for s in (offset..slots).step_by(u.period as usize) {
                self.words[b][(s / 64) as usize] |= 1 << (s % 64);
            }
        }
    }
}

/// Offsets in the order that keeps slow channels on one slice slot rotated
/// by the slice counter (as the reference design does): by slot-in-slice first.
pub(crate) fn candidate_offsets(period: u64, slots_per_slice: u64) -> impl Iterator<Item = u64> {
    (0..slots_per_slice.min(period))
        .flat_map(move |s| (s..period).step_by(slots_per_slice as usize))
}

fn branch_plans(mix: &Mix) -> Result<Vec<BranchPlan>, String> {
    let own: Vec<SpiTiming> = mix
        .branches
        .iter()
        .map(|b| {
            SpiTiming::derive(&b.adc, mix.clock_hz, b.sclk_hz, b.chain)
                .map_err(|e| format!("branch `{}`: {}", b.name, e.0))
        })
        .collect::<Result<_, _>>()?;
    let sample: Vec<u64> = own.iter().map(|t| t.sample_cycles).collect();
    let holdoffs = crate::holdoff::holdoffs(mix, &sample);
    Ok(mix
        .branches
        .iter()
        .zip(own)
        .zip(holdoffs)
        .map(|((b, own), h)| {
            let spi = own.with_holdoff(h);
            let settle_cycles = ns_to_cycles(b.settle_ns, mix.clock_hz);
            // The transaction, after its hold-off, and the quiet time fit
            // the slot (the conversions still start a slot apart).
            let held = spi.tick_to_complete() + spi.quiet_cycles;
            BranchPlan {
                name: b.name.clone(),
                spi,
                settle_cycles,
                // The mux switches in the cycle after a CS fall: it has slot-1 cycles to settle.
                min_slot_cycles: spi.min_period_cycles.max(held).max(settle_cycles + 1),
                mux_devices: b.mux_devices,
            }
        })
        .collect())
}

fn units_of(mix: &Mix, frame_slots: u64) -> Vec<Unit> {
    let mut units: Vec<Unit> = Vec::new();
    let mut by_tag: std::collections::BTreeMap<&str, usize> = Default::default();
    for (i, c) in mix.channels.iter().enumerate() {
        if mix.lead_of(i) != i || c.rate_hz == 0 {
            // Read in its lead's conversion (a chain member): placed with
            // it; or not sampled (in this mode).
            continue;
        }
        let period = frame_slots / mix.samples_per_frame(c.rate_hz);
        if let Some(tag) = &c.sync {
            if let Some(&u) = by_tag.get(tag.as_str()) {
                units[u].channels.push(i);
                units[u].branches.push(c.branch);
                continue;
            }
            by_tag.insert(tag, units.len());
        }
        units.push(Unit {
            channels: vec![i],
            branches: vec![c.branch],
            period,
        });
    }
    // Fast channels first; among equals, units spanning more branches first.
    units.sort_by_key(|u| (u.period, std::cmp::Reverse(u.branches.len()), u.channels[0]));
    units
}

/// Result of trying one slot grid.
enum Attempt {
    Placed(Vec<u64>, Placement),
    /// Whether the exact search hit its budget rather than proving failure.
    Failed {
        bounded: bool,
    },
}

fn greedy(units: &[Unit], branches: usize, slots: u64, sps: u64) -> (Vec<Option<u64>>, Occupancy) {
    let mut occ = Occupancy::new(branches, slots);
    let mut offsets = Vec::with_capacity(units.len());
    for u in units {
        let found = candidate_offsets(u.period, sps).find(|&o| occ.fits(u, o, slots));
        if let Some(o) = found {
            occ.take(u, o, slots);
        }
        offsets.push(found);
    }
    (offsets, occ)
}

fn attempt(units: &[Unit], branches: usize, slots: u64, sps: u64, budget: u64) -> Attempt {
    let (offsets, _) = greedy(units, branches, slots, sps);
    if offsets.iter().all(Option::is_some) {
        return Attempt::Placed(
            offsets.into_iter().map(Option::unwrap).collect(),
            Placement::Constructive,
        );
    }
    match search::search(units, branches, sps, budget) {
        search::Outcome::Placed(offsets, nodes) => {
            Attempt::Placed(offsets, Placement::Search { nodes })
        }
        search::Outcome::Exhausted => Attempt::Failed { bounded: false },
        search::Outcome::Bounded => Attempt::Failed { bounded: true },
    }
}

/// Conversions each branch needs per frame (independent of the slot grid).
fn demand_per_frame(mix: &Mix) -> Vec<u64> {
    let mut demand = vec![0u64; mix.branches.len()];
    for (i, c) in mix.channels.iter().enumerate() {
        if mix.lead_of(i) != i {
            continue;
        }
        demand[c.branch] += mix.samples_per_frame(c.rate_hz);
    }
    demand
}

/// Slot grids to try, fewest slots first: divisors of the slice that keep
/// every branch's slot at or above its shortest legal length.
pub fn candidate_slots_per_slice(mix: &Mix, min_slot_cycles: u64) -> Vec<u64> {
    let slice = mix.slice_cycles();
    if let Some(s) = mix.slots_per_slice {
        return vec![s];
    }
    let mut small = Vec::new();
    let mut large = Vec::new();
    let mut d = 1;
    while d * d <= slice {
        if slice.is_multiple_of(d) {
            small.push(d);
            if d * d != slice {
                large.push(slice / d);
            }
        }
        d += 1;
    }
    large.reverse();
    small
        .into_iter()
        .chain(large)
        .filter(|&s| slice / s >= min_slot_cycles)
        .collect()
}

/// Synthesizes a jitter-free schedule, or explains why none exists (or, if
/// the exact search's bound ran out, that none was found).
pub fn synthesize(mix: &Mix) -> Result<Schedule, Infeasible> {
    synthesize_within(mix, SEARCH_BUDGET)
}

/// [`synthesize`] with `budget` placements per slot grid for the exact
/// search (`--search-limit`): a smaller budget answers sooner, and a mix
/// whose search it cuts short is [`Verdict::Unknown`], never infeasible.
///
/// A mix with modes gets one grid every mode fits (the fewest slots that
/// place them all) and a schedule per mode on it ([`Schedule::modes`]); a
/// mode that fits no grid is diagnosed by name.
pub fn synthesize_within(mix: &Mix, budget: u64) -> Result<Schedule, Infeasible> {
    match &mix.modes {
        None => synthesize_one(mix, budget),
        Some(_) => modes::synthesize_modes(mix, budget),
    }
}

/// Each channel whose rate is more than its branch's converter converts
/// per second at this clock (a chain converts all its members at once, so
/// a channel's limit is the chain's conversions), in words.
fn too_fast_for_the_part(mix: &Mix) -> Vec<String> {
    (mix.channels.iter())
        .filter_map(|c| {
            let b = &mix.branches[c.branch];
            let most = b.max_samples_hz(mix.clock_hz) / b.chain.max(1) as f64;
            (c.rate_hz as f64 > most).then(|| {
                format!(
                    "channel `{}`: {} Hz is faster than branch `{}`'s {} can convert: at most {:.0} samples/s at {} Hz (its datasheet: {})",
                    c.name, c.rate_hz, b.name, b.adc.name, most, mix.clock_hz, b.adc.max_sps
                )
            })
        })
        .collect()
}

/// One mode (or a mix without modes): the grid and the placement.  A
/// channel faster than its converter converts is the first reason, before
/// what any grid makes of it (a rate no grid spaces evenly, a full branch).
fn synthesize_one(mix: &Mix, budget: u64) -> Result<Schedule, Infeasible> {
    synthesize_grid(mix, budget).map_err(|mut e| {
        let mut first = too_fast_for_the_part(mix);
        if !first.is_empty() && e.verdict == Verdict::Infeasible {
            first.append(&mut e.reasons);
            e.reasons = first;
        }
        e
    })
}

fn synthesize_grid(mix: &Mix, budget: u64) -> Result<Schedule, Infeasible> {
    let fail = |reasons: Vec<String>, suggestions: Vec<String>| Infeasible {
        mix: mix.name.clone(),
        verdict: Verdict::Infeasible,
        slots_per_slice: None,
        reasons,
        branches: Vec::new(),
        suggestions,
    };
    let plans = branch_plans(mix).map_err(|e| fail(vec![e], vec![]))?;
    let min_slot = plans.iter().map(|p| p.min_slot_cycles).max().unwrap_or(1);

    // Exact intervals need clock / rate to be whole cycles.
    let inexact: Vec<String> = mix
        .channels
        .iter()
        .filter(|c| c.rate_hz > 0 && !mix.clock_hz.is_multiple_of(c.rate_hz))
        .map(|c| {
            format!(
                "channel `{}`: {} Hz gives {:.3} clock cycles between samples at {} Hz; no grid makes that exact (nearest exact rates: {})",
                c.name,
                c.rate_hz,
                mix.clock_hz as f64 / c.rate_hz as f64,
                mix.clock_hz,
                nearest_exact_rates(mix, c.rate_hz)
            )
        })
        .collect();
    if !inexact.is_empty() {
        return Err(fail(inexact, vec![]));
    }

    let candidates = candidate_slots_per_slice(mix, min_slot);
    if candidates.is_empty() || mix.slice_cycles() / candidates[0] < min_slot {
        let slowest = plans.iter().max_by_key(|p| p.min_slot_cycles).unwrap();
        let most = mix.slice_cycles() / min_slot;
        let reason = match mix.slots_per_slice {
            Some(s) => format!(
                "slots_per_slice = {s} gives {}-cycle slots, shorter than the {} cycles branch `{}` needs (conversion, quiet time, throughput and mux settling)",
                mix.slice_cycles() / s,
                min_slot,
                slowest.name
            ),
            None => format!(
                "a {}-cycle slice cannot hold even one {}-cycle slot of branch `{}`",
                mix.slice_cycles(),
                min_slot,
                slowest.name
            ),
        };
        let suggestion = if most > 0 {
            format!(
                "use at most {most} slots per slice (a divisor of {} cycles)",
                mix.slice_cycles()
            )
        } else {
            "lengthen the slice or raise the clock".to_string()
        };
        return Err(fail(vec![reason], vec![suggestion]));
    }

    let k = mix.slices_per_frame();
    let demand = demand_per_frame(mix);
    let mut bounded = false;
    for &sps in &candidates {
        let slots = k * sps;
        if mix
            .channels
            .iter()
            .any(|c| c.rate_hz > 0 && !slots.is_multiple_of(mix.samples_per_frame(c.rate_hz)))
        {
            continue;
        }
        if demand.iter().any(|&d| d > slots) {
            continue;
        }
        let units = units_of(mix, slots);
        match attempt(&units, mix.branches.len(), slots, sps, budget) {
            Attempt::Placed(offsets, placement) => {
                let schedule = build(mix, plans, sps, &units, &offsets, placement);
                if let Err(problems) = crate::validate::validate(&schedule) {
                    return Err(fail(
                        problems
                            .into_iter()
                            .map(|p| {
                                format!("internal error, validator rejected the schedule: {p}")
                            })
                            .collect(),
                        vec!["please report this mix as a bug".into()],
                    ));
                }
                return Ok(schedule);
            }
            Attempt::Failed { bounded: b, .. } => bounded |= b,
        }
    }
    Err(diagnose(mix, &candidates, bounded.then_some(budget)))
}

fn build(
    mix: &Mix,
    plans: Vec<BranchPlan>,
    sps: u64,
    units: &[Unit],
    offsets: &[u64],
    placement: Placement,
) -> Schedule {
    let grid = FrameGrid::new(mix, sps);
    let nb = mix.branches.len();
    let mut channels = vec![None; mix.channels.len()];
    let mut table = vec![None; grid.frame_slots as usize * nb];
    for (u, &o) in units.iter().zip(offsets) {
        for &c in &u.channels {
            let ch = &mix.channels[c];
            for m in mix.conversion_group(c).into_iter().flatten() {
                // (rate 0: no unit; its zero summary is filled in below)
                channels[m] = Some(ChannelSlots {
                    samples_per_frame: mix.samples_per_frame(ch.rate_hz),
                    period_slots: u.period,
                    offset_slot: o,
                    interval_cycles: mix.clock_hz / ch.rate_hz,
                    device: mix.pin_input(c) / 8,
                    select: mix.pin_input(c) % 8,
                });
            }
            for s in (o..grid.frame_slots).step_by(u.period as usize) {
                table[s as usize * nb + ch.branch] = Some(c as u16);
            }
        }
    }
    Schedule {
        mix: mix.clone(),
        grid,
        branches: plans,
        channels: channels
            .into_iter()
            .zip(&mix.channels)
            .enumerate()
            .map(|(i, (c, _))| {
                c.unwrap_or(ChannelSlots {
                    device: mix.pin_input(i) / 8,
                    select: mix.pin_input(i) % 8,
                    ..UNSAMPLED
                })
            })
            .collect(),
        frame_table: table,
        placement,
        groups: Schedule::groups_of(mix),
        modes: Vec::new(),
    }
}

/// Rates near `rate` that give whole samples per frame and whole cycles per sample.
fn nearest_exact_rates(mix: &Mix, rate: u64) -> String {
    let exact = (1..=rate.saturating_mul(2).max(2)).filter(|&r| {
        mix.clock_hz.is_multiple_of(r)
            && (r as u128 * mix.frame_us as u128).is_multiple_of(1_000_000)
    });
    nearest(exact, rate)
}

/// The closest candidates below and above `rate` ("a Hz or b Hz"); `rates` ascending.
fn nearest(rates: impl IntoIterator<Item = u64>, rate: u64) -> String {
    let rates: Vec<u64> = rates.into_iter().collect();
    let below = rates.iter().rev().find(|&&r| r < rate);
    let above = rates.iter().find(|&&r| r > rate);
    [below, above]
        .iter()
        .flatten()
        .map(|r| format!("{r} Hz"))
        .collect::<Vec<_>>()
        .join(" or ")
}

/// Exact rates on a grid of `slots` slots per frame, ascending, with their
/// samples per frame: the period is whole slots and the interval whole cycles.
pub(crate) fn grid_rates(mix: &Mix, slots: u64) -> impl Iterator<Item = (u64, u64)> + '_ {
    let frames_per_s = 1e6 / mix.frame_us as f64;
    (1..=slots)
        .filter(move |n| slots.is_multiple_of(*n))
        .map(move |n| (n, n as f64 * frames_per_s))
        .filter(|(_, r)| r.fract() == 0.0 && mix.clock_hz.is_multiple_of(*r as u64))
        .map(|(n, r)| (n, r as u64))
}

/// Demand against capacity, per slice as an engineer counts it (the ADC
/// fits `sps` conversions in a slice at the roomiest grid); per frame too
/// when a slow rate makes the per-slice demand fractional.
fn over_capacity(branch: &str, per_frame: u64, sps: u64, slices: u64) -> String {
    let slots = sps * slices;
    let over = (per_frame as f64 / slots as f64 - 1.0) * 100.0;
    let per_slice = if per_frame.is_multiple_of(slices) {
        format!("{}", per_frame / slices)
    } else {
        format!("{:.1}", per_frame as f64 / slices as f64)
    };
    format!(
        "branch `{branch}` needs {per_slice} conversions per slice, its ADC fits {sps} \
         ({per_frame} against {slots} per frame, {over:.1} % over)"
    )
}

/// What a diagnosis has found so far, on one grid.
struct Findings {
    reasons: Vec<String>,
    suggestions: Vec<String>,
    /// Per branch: the channels that found no place.
    unplaced: Vec<Vec<String>>,
}

/// The grid a diagnosis is made on: `sps` slots per slice, `slots` per frame.
#[derive(Clone, Copy)]
struct DiagGrid {
    sps: u64,
    slots: u64,
}

/// `bound`: the exact search's budget, if it ran out on some grid.
fn diagnose(mix: &Mix, candidates: &[u64], bound: Option<u64>) -> Infeasible {
    let k = mix.slices_per_frame();
    // The roomiest grid whose periods are all whole; else simply the roomiest.
    let whole = |sps: u64| {
        mix.channels
            .iter()
            .all(|c| c.rate_hz == 0 || (k * sps).is_multiple_of(mix.samples_per_frame(c.rate_hz)))
    };
    let sps = candidates
        .iter()
        .rev()
        .copied()
        .find(|&s| whole(s))
        .unwrap_or(*candidates.last().unwrap());
    let slots = k * sps;
    let dg = DiagGrid { sps, slots };
    let grid = FrameGrid::new(mix, sps);
    let nb = mix.branches.len();
    let demand = demand_per_frame(mix);
    let mut f = Findings {
        reasons: Vec::new(),
        suggestions: Vec::new(),
        unplaced: vec![Vec::new(); nb],
    };

    let not_whole: Vec<&str> = mix
        .channels
        .iter()
        .filter(|c| c.rate_hz > 0 && !slots.is_multiple_of(mix.samples_per_frame(c.rate_hz)))
        .map(|c| c.name.as_str())
        .collect();
    if !not_whole.is_empty() {
        f.reasons.push(format!(
            "no legal slot grid (at most {} slots per slice) spaces {} evenly: their samples per frame do not divide the frame's slots",
            candidates.last().unwrap(),
            not_whole.join(", ")
        ));
        periods_not_whole(mix, dg, &mut f);
    } else {
        for (b, &d) in demand.iter().enumerate() {
            if d > slots {
                f.reasons
                    .push(over_capacity(&mix.branches[b].name, d, sps, k));
            }
        }
        // What would make an over-full branch fit is not guessed here from
        // counts: `audit` tries each change on the mix (`crate::fixes`).
        collisions(mix, dg, &demand, bound, &mut f);
    }

    let branches = (0..nb)
        .map(|b| BranchDiagnosis {
            name: mix.branches[b].name.clone(),
            demand_hz: mix
                .channels
                .iter()
                .filter(|c| c.branch == b)
                .map(|c| c.rate_hz)
                .sum(),
            capacity_hz: mix.clock_hz as f64 / grid.slot_cycles as f64,
            demand_slots_per_frame: demand[b],
            capacity_slots_per_frame: slots,
            unplaced: std::mem::take(&mut f.unplaced[b]),
        })
        .collect();
    Infeasible {
        mix: mix.name.clone(),
        verdict: match bound {
            Some(_) => Verdict::Unknown,
            None => Verdict::Infeasible,
        },
        slots_per_slice: Some(sps),
        reasons: f.reasons,
        branches,
        suggestions: f.suggestions,
    }
}

/// Channels whose period is not whole slots on the grid: each is unplaced,
/// with the rates that would fit.
fn periods_not_whole(mix: &Mix, dg: DiagGrid, f: &mut Findings) {
    for c in mix
        .channels
        .iter()
        .filter(|c| c.rate_hz > 0 && !dg.slots.is_multiple_of(mix.samples_per_frame(c.rate_hz)))
    {
        f.unplaced[c.branch].push(c.name.clone());
        f.suggestions.push(format!(
            "`{}`: rates that fit {} slots per slice exactly: {}",
            c.name,
            dg.sps,
            nearest(grid_rates(mix, dg.slots).map(|(_, r)| r), c.rate_hz)
        ));
    }
}

/// First-fit on the grid: who is left unplaced, the nearest rates that would
/// fit beside the others, and why it failed.
fn collisions(mix: &Mix, dg: DiagGrid, demand: &[u64], bound: Option<u64>, f: &mut Findings) {
    let DiagGrid { sps, slots } = dg;
    let units = units_of(mix, slots);
    let (offsets, occ) = greedy(&units, mix.branches.len(), slots, sps);
    let overfull = demand.iter().any(|&d| d > slots);
    // (rate, nearest fitting rates) -> channels, so identical advice is given once.
    let mut collisions: Vec<((u64, String), Vec<String>)> = Vec::new();
    for (u, o) in units.iter().zip(&offsets) {
        if o.is_some() {
            continue;
        }
        for &c in &u.channels {
            f.unplaced[mix.channels[c].branch].push(mix.channels[c].name.clone());
        }
        if overfull {
            continue;
        }
        let c = &mix.channels[u.channels[0]];
        let fits = grid_rates(mix, slots)
            .filter(|&(n, _)| {
                let p = slots / n;
                let probe = Unit {
                    period: p,
                    ..u.clone()
                };
                candidate_offsets(p, sps).any(|o| occ.fits(&probe, o, slots))
            })
            .map(|(_, r)| r);
        let near = nearest(fits, c.rate_hz);
        if !near.is_empty() {
            let key = (c.rate_hz, near);
            match collisions.iter_mut().find(|(k, _)| *k == key) {
                Some((_, names)) => names.push(c.name.clone()),
                None => collisions.push((key, vec![c.name.clone()])),
            }
        }
    }
    for ((rate, near), names) in collisions {
        f.suggestions.push(format!(
            "{} ({rate} Hz) collide with the other channels' progressions; nearest rates that fit beside them, one channel at a time: {near}",
            names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
        ));
    }
    if !overfull && f.unplaced.iter().all(Vec::is_empty) {
        f.reasons.push("first-fit placed every channel at this grid, but no grid admitted all of them with one rate each".into());
    }
    if !overfull && f.unplaced.iter().any(|u| !u.is_empty()) {
        f.reasons.push(if let Some(budget) = bound {
            format!("rates that are not harmonic collide; the exact search stopped at its bound of {budget} placements per grid with neither a schedule nor a proof that none exists: the mix may fit")
        } else {
            "rates that are not harmonic collide: two progressions of periods p and q meet unless their offsets differ modulo gcd(p, q), and no choice of offsets separates them all".into()
        });
    }
}
