//! The changes worth trying for a mix without a schedule: few, and aimed
//! at what the diagnosis found (an over-full branch, channels that found no
//! place, a grid too coarse or forced).

use super::{Candidate, Change, Edit};
use crate::mix::Mix;
use crate::synth::Infeasible;

/// Branches, rates per branch and targets per move considered.
const WIDTH: usize = 3;

pub(super) fn for_schedule(mix: &Mix, why: &Infeasible) -> Vec<Candidate> {
    let mut out = grids(mix);
    out.extend(supplies(mix, why));
    let slots = why
        .slots_per_slice
        .map(|s| s * mix.slices_per_frame())
        .unwrap_or(0);
    let mut each = Vec::new();
    for (b, d) in why.branches.iter().enumerate().take(16) {
        if d.demand_slots_per_frame > d.capacity_slots_per_frame {
            let excess = d.demand_slots_per_frame - d.capacity_slots_per_frame;
            let mut mine = Vec::new();
            over_full(mix, why, b, excess, slots, &mut mine);
            each.push(mine);
        }
    }
    out.extend(together(&each));
    out.extend(each.into_iter().flatten());
    troubled(mix, why, slots, &mut out);
    out
}

/// Over-full branches whose part is held to its lowest supply's figures
/// (no `vdd`) and runs faster at a higher supply: that supply, said.
fn supplies(mix: &Mix, why: &Infeasible) -> Vec<Candidate> {
    let mut changes = Vec::new();
    let mut edits = Vec::new();
    for (b, d) in why.branches.iter().enumerate() {
        let br = &mix.branches[b];
        if d.demand_slots_per_frame <= d.capacity_slots_per_frame && d.unplaced.is_empty() {
            continue;
        }
        let Some(top) = br.adc.supplies.last().filter(|_| br.vdd_mv.is_none()) else {
            continue;
        };
        let low = br.adc.supply_figure(None).expect("a supply table");
        if top.max_sps <= low.max_sps && top.sclk_max_hz <= low.sclk_max_hz {
            continue;
        }
        changes.push(Change::Supply {
            branch: br.name.clone(),
            part: br.adc.name.clone(),
            vdd_mv: top.from_mv,
            sclk_max_hz: top.sclk_max_hz,
            max_sps: top.max_sps,
        });
        edits.push(Edit::Vdd {
            name: br.name.clone(),
            mv: top.from_mv,
        });
    }
    if changes.is_empty() {
        return Vec::new();
    }
    vec![Candidate {
        changes,
        edits,
        parts_added: 0,
        channels_changed: 0,
    }]
}

/// Several over-full branches need a change each: the first candidate
/// of one kind on every branch, as one fix.
fn together(each: &[Vec<Candidate>]) -> Vec<Candidate> {
    if each.len() < 2 {
        return Vec::new();
    }
    let kinds: [fn(&Change) -> bool; 3] = [
        |c| matches!(c, Change::MoveChannels { .. }),
        |c| matches!(c, Change::AddBranch { .. }),
        |c| matches!(c, Change::LowerRate { .. }),
    ];
    kinds
        .iter()
        .filter_map(|kind| {
            let firsts: Option<Vec<Candidate>> = each
                .iter()
                .map(|mine| mine.iter().find(|c| c.changes.iter().all(kind)).cloned())
                .collect();
            firsts.map(Candidate::join)
        })
        .collect()
}

/// Another slice length (the nearest that give whole cycles), and a free grid.
fn grids(mix: &Mix) -> Vec<Candidate> {
    let forced = mix.slots_per_slice;
    let free: Vec<Edit> = forced.map(|_| Edit::FreeGrid).into_iter().collect();
    let mut out = Vec::new();
    if forced.is_some() {
        out.push(grid(None, forced, free.clone()));
    }
    let mut slices: Vec<u64> = (1..=mix.frame_us)
        .filter(|&us| {
            mix.frame_us.is_multiple_of(us)
                && us != mix.slice_us
                && (mix.clock_hz as u128 * us as u128).is_multiple_of(1_000_000)
        })
        .collect();
    let dist = |us: &u64| (*us as f64 / mix.slice_us as f64).ln().abs();
    slices.sort_by(|a, b| dist(a).total_cmp(&dist(b)));
    for us in slices.into_iter().take(4) {
        let mut edits = free.clone();
        edits.push(Edit::SliceUs(us));
        out.push(grid(Some((mix.slice_us, us)), forced, edits));
    }
    out
}

fn grid(slice_us: Option<(u64, u64)>, dropped: Option<u64>, edits: Vec<Edit>) -> Candidate {
    Candidate {
        changes: vec![Change::Grid {
            slice_us,
            dropped_slots_per_slice: dropped,
        }],
        edits,
        parts_added: 0,
        channels_changed: 0,
    }
}

/// Channels a fix may move or slow down alone: in no sync group and
/// alone in their conversion (no chain partner reads the same input).
fn movable(mix: &Mix, b: usize, rate: Option<u64>) -> Vec<String> {
    (0..mix.channels.len())
        .filter(|&i| {
            let c = &mix.channels[i];
            c.branch == b
                && rate.is_none_or(|r| c.rate_hz == r)
                && c.sync.is_none()
                && mix.conversion_group(i).iter().flatten().count() == 1
        })
        .map(|i| mix.channels[i].name.clone())
        .collect()
}

/// Branch `b` asks `excess` conversions per frame more than it has: move
/// some of its channels elsewhere, lower their rate, or split the branch.
fn over_full(
    mix: &Mix,
    why: &Infeasible,
    b: usize,
    excess: u64,
    slots: u64,
    out: &mut Vec<Candidate>,
) {
    let mut rates: Vec<u64> = mix
        .channels
        .iter()
        .filter(|c| c.branch == b)
        .map(|c| c.rate_hz)
        .collect();
    rates.sort_unstable_by(|x, y| y.cmp(x));
    rates.dedup();
    for &r in rates.iter().take(WIDTH) {
        let n = mix.samples_per_frame(r);
        let have = movable(mix, b, Some(r));
        let count = excess.div_ceil(n) as usize;
        if count <= have.len() {
            let moved = have[have.len() - count..].to_vec();
            moves(mix, why, b, r, &moved, out);
        }
        lower(mix, b, r, excess, slots, &have, out);
    }
    split(mix, b, excess, out);
}

/// `moved` (all at `rate`) from `b` to each of the roomiest other branches.
fn moves(
    mix: &Mix,
    why: &Infeasible,
    b: usize,
    rate: u64,
    moved: &[String],
    out: &mut Vec<Candidate>,
) {
    let mut targets: Vec<usize> = (0..mix.branches.len()).filter(|&t| t != b).collect();
    let room = |t: &usize| {
        why.branches
            .get(*t)
            .map(|d| d.capacity_slots_per_frame as i64 - d.demand_slots_per_frame as i64)
            .unwrap_or(0)
    };
    targets.sort_by_key(|t| std::cmp::Reverse(room(t)));
    for t in targets.into_iter().take(WIDTH) {
        let tb = &mix.branches[t];
        let mut used: Vec<u32> = mix
            .channels
            .iter()
            .filter(|c| c.branch == t)
            .map(|c| c.input)
            .collect();
        used.sort_unstable();
        used.dedup();
        let capacity = tb.input_capacity();
        let short = (used.len() + moved.len()).saturating_sub(capacity as usize) as u32;
        let mut edits: Vec<Edit> = moved
            .iter()
            .map(|n| Edit::MoveChannel {
                name: n.clone(),
                to: tb.name.clone(),
            })
            .collect();
        let mut devices = None;
        if short > 0 {
            let more = short.div_ceil(tb.mux.inputs);
            if tb.mux.inputs <= 1 || tb.mux_devices + more > 32 {
                continue;
            }
            devices = Some((tb.mux_devices, tb.mux_devices + more));
            edits.push(Edit::MuxDevices {
                name: tb.name.clone(),
                devices: tb.mux_devices + more,
            });
        }
        out.push(Candidate {
            changes: vec![Change::MoveChannels {
                from: mix.branches[b].name.clone(),
                to: tb.name.clone(),
                channels: moved.to_vec(),
                rate_hz: rate,
                mux_devices: devices,
            }],
            edits,
            parts_added: devices.map(|(a, z)| z - a).unwrap_or(0),
            channels_changed: moved.len(),
        });
    }
}

/// Exact rates below `rate` on a grid of `slots` slots per frame (any
/// exact rate without a grid), fastest first.
fn rates_below(mix: &Mix, rate: u64, slots: u64) -> Vec<(u64, u64)> {
    let mut v: Vec<(u64, u64)> = if slots > 0 {
        crate::synth::grid_rates(mix, slots)
            .filter(|&(_, r)| r < rate)
            .collect()
    } else {
        (1..rate)
            .filter(|&r| {
                mix.clock_hz.is_multiple_of(r)
                    && (r as u128 * mix.frame_us as u128).is_multiple_of(1_000_000)
            })
            .map(|r| (mix.samples_per_frame(r), r))
            .collect()
    };
    v.sort_by_key(|&(_, r)| std::cmp::Reverse(r));
    v
}

/// Lower some of `have` (at `rate` on `b`) just enough to free `excess`
/// conversions per frame: the fewest channels, and all of them.
fn lower(
    mix: &Mix,
    b: usize,
    rate: u64,
    excess: u64,
    slots: u64,
    have: &[String],
    out: &mut Vec<Candidate>,
) {
    let n = mix.samples_per_frame(rate);
    let below = rates_below(mix, rate, slots);
    let fewest = (excess / n + 1) as usize;
    let mut counts = vec![fewest.min(have.len()), have.len()];
    counts.dedup();
    for count in counts.into_iter().filter(|&c| c > 0) {
        // each lowered channel must give up ceil(excess / count) conversions
        let give = excess.div_ceil(count as u64);
        let Some(&(_, to)) = below.iter().find(|&&(m, _)| m + give <= n) else {
            continue;
        };
        let ch = have[have.len() - count..].to_vec();
        out.push(lowered(ch, rate, to));
    }
    let _ = b;
}

fn lowered(ch: Vec<String>, from: u64, to: u64) -> Candidate {
    Candidate {
        edits: ch
            .iter()
            .map(|n| Edit::Rate {
                name: n.clone(),
                hz: to,
            })
            .collect(),
        channels_changed: ch.len(),
        changes: vec![Change::LowerRate {
            channels: ch,
            from_hz: from,
            to_hz: to,
        }],
        parts_added: 0,
    }
}

/// A second branch like `b`, taking the fewest of `b`'s movable channels
/// (fastest first) that free `excess` conversions per frame.
fn split(mix: &Mix, b: usize, excess: u64, out: &mut Vec<Candidate>) {
    let like = &mix.branches[b];
    let name = (2..)
        .map(|k| format!("{}_{k}", like.name))
        .find(|n| mix.branch_index(n).is_none())
        .unwrap();
    let mut by_rate = movable(mix, b, None);
    let rate = |n: &String| mix.channels[mix.channel_index(n).unwrap()].rate_hz;
    by_rate.sort_by_key(|n| std::cmp::Reverse(rate(n)));
    let mut freed = 0;
    let ch: Vec<String> = by_rate
        .into_iter()
        .take_while(|n| {
            let more = freed < excess;
            freed += mix.samples_per_frame(rate(n));
            more
        })
        .collect();
    // (take_while counted the first channel it left behind too)
    let freed: u64 = ch.iter().map(|n| mix.samples_per_frame(rate(n))).sum();
    if ch.is_empty() || freed < excess {
        return;
    }
    let mut edits = vec![Edit::BranchLike {
        name: name.clone(),
        like: like.name.clone(),
    }];
    edits.extend(ch.iter().map(|n| Edit::MoveChannel {
        name: n.clone(),
        to: name.clone(),
    }));
    out.push(Candidate {
        parts_added: 1 + like.mux_devices * u32::from(like.mux.inputs > 1),
        channels_changed: ch.len(),
        changes: vec![Change::AddBranch {
            name,
            like: like.name.clone(),
            channels: ch,
        }],
        edits,
    });
}

/// Channels without a place (or without an exact interval), grouped by
/// branch and rate: a lower rate for the group, or a move of the group.
fn troubled(mix: &Mix, why: &Infeasible, slots: u64, out: &mut Vec<Candidate>) {
    let mut groups: Vec<(usize, u64, Vec<String>)> = Vec::new();
    let unplaced = why.branches.iter().flat_map(|d| d.unplaced.iter());
    let inexact = mix
        .channels
        .iter()
        .filter(|c| !mix.clock_hz.is_multiple_of(c.rate_hz))
        .map(|c| &c.name);
    for name in unplaced.chain(inexact) {
        let Some(i) = mix.channel_index(name) else {
            continue;
        };
        let c = &mix.channels[i];
        if !movable(mix, c.branch, None).contains(name) {
            continue;
        }
        match groups
            .iter_mut()
            .find(|g| g.0 == c.branch && g.1 == c.rate_hz)
        {
            Some(g) if !g.2.contains(name) => g.2.push(name.clone()),
            Some(_) => {}
            None => groups.push((c.branch, c.rate_hz, vec![name.clone()])),
        }
    }
    for (b, rate, ch) in groups.into_iter().take(WIDTH) {
        for (_, to) in rates_below(mix, rate, slots).into_iter().take(WIDTH) {
            out.push(lowered(ch.clone(), rate, to));
        }
        moves(mix, why, b, rate, &ch, out);
    }
}

/// A mix the loader refuses for want of mux inputs: for each branch with
/// more channels than its devices have inputs, the devices it needs.
pub(super) fn for_mux_inputs(text: &str) -> Vec<Candidate> {
    let Ok(doc) = text.parse::<toml_edit::DocumentMut>() else {
        return Vec::new();
    };
    let tables = |k: &str| {
        doc.get(k)
            .and_then(|i| i.as_array_of_tables())
            .map(|a| a.iter().collect::<Vec<_>>())
            .unwrap_or_default()
    };
    let channels = tables("channel");
    let mut out = Vec::new();
    for b in tables("branch") {
        let name = b.get("name").and_then(|v| v.as_str()).unwrap_or_default();
        let mux = b.get("mux").and_then(|v| v.as_str()).unwrap_or_default();
        let Some(part) = crate::parts::MuxPart::by_name(mux) else {
            continue;
        };
        let devices = b
            .get("mux_devices")
            .and_then(|v| v.as_integer())
            .unwrap_or(1)
            .max(1) as u32;
        let chain = b
            .get("chain")
            .and_then(|v| v.as_integer())
            .unwrap_or(1)
            .max(1) as u32;
        let n = channels
            .iter()
            .filter(|c| c.get("branch").and_then(|v| v.as_str()) == Some(name))
            .count() as u32;
        let need = n.div_ceil(chain).div_ceil(part.inputs);
        if part.inputs <= 1 || need <= devices || need > 32 {
            continue;
        }
        out.push(Candidate {
            changes: vec![Change::AddMuxDevices {
                branch: name.to_string(),
                from: devices,
                to: need,
            }],
            edits: vec![Edit::MuxDevices {
                name: name.to_string(),
                devices: need,
            }],
            parts_added: need - devices,
            channels_changed: 0,
        });
    }
    out
}

/// The standard UART bauds a host's serial port offers, lowest first.
const STANDARD_BAUDS: [u64; 22] = [
    9_600, 19_200, 38_400, 57_600, 115_200, 230_400, 250_000, 460_800, 500_000, 576_000, 921_600,
    1_000_000, 1_152_000, 1_500_000, 2_000_000, 2_500_000, 3_000_000, 4_000_000, 6_000_000,
    8_000_000, 10_000_000, 12_000_000,
];

/// A faster line for a UART too slow for its mix: every standard baud
/// above `baud` and at or above `min_baud` (the slowest divider that
/// carries the mix) that the clock divides within the loader's tolerance,
/// lowest first.
pub(super) fn faster_lines(clock_hz: u64, baud: u64, min_baud: f64) -> Vec<Candidate> {
    use crate::mix::{MAX_BAUD_ERROR_PCT, MIN_BAUD_DIVIDER};
    STANDARD_BAUDS
        .into_iter()
        .filter(|&b| b > baud && (min_baud.is_nan() || b as f64 >= min_baud * 0.98))
        .filter(|&b| {
            let div = link::UartFormat::divider(clock_hz, b);
            let real = link::UartFormat::real_baud(clock_hz, div);
            div >= MIN_BAUD_DIVIDER
                && (real - b as f64).abs() / b as f64 * 100.0 <= MAX_BAUD_ERROR_PCT
        })
        .map(|to| Candidate {
            changes: vec![Change::RaiseBaud { from: baud, to }],
            edits: vec![Edit::Baud(to)],
            parts_added: 0,
            channels_changed: 0,
        })
        .collect()
}
