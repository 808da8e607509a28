//! The report's tables: the slot table in the paper's Table 1 form, the
//! co-simulation's intervals by branch and rate, and the fault campaign
//! (the audit's are in [`crate::budget`]).

use lut_gen::lut::{CompactLut, SliceCell};
use lut_gen::Schedule;
use report::Table;

/// The slot table in the paper's Table 1 form: a row per slot of the slice,
/// a column per branch, each cell the channel converted there in every
/// slice, or a rotation group (`R0`) whose member changes slice by slice;
/// and the rotation groups, a column per slice.
pub fn slot_table(s: &Schedule) -> Vec<(String, Table)> {
    let lut = CompactLut::from_schedule(s);
    let name = |c: u16| s.mix.channels[c as usize].name.clone();
    let cell = |c: &SliceCell| match c {
        SliceCell::Idle => "-".to_string(),
        SliceCell::Fixed(c) => name(*c),
        SliceCell::Rotate(g) => format!("R{g}"),
    };
    let t = if 1 + s.branches.len() > MAX_COLUMNS {
        // a column per branch would be wider than the page: a row per
        // branch listing its slots, which wraps
        let mut t = Table::new(&["branch", "channel in slot 0, 1, 2, ... of the slice"]);
        for (b, br) in s.branches.iter().enumerate() {
            let list: Vec<String> = lut.slice_table.iter().map(|row| cell(&row[b])).collect();
            t.push(vec![br.name.clone(), list.join(", ")]);
        }
        t
    } else {
        let mut cols = vec!["slot".to_string()];
        // branch names are the user's identifiers: shown as code
        cols.extend(s.branches.iter().map(|b| format!("`{}`", b.name)));
        let refs: Vec<&str> = cols.iter().map(String::as_str).collect();
        let mut t = Table::new(&refs);
        for (slot, row) in lut.slice_table.iter().enumerate() {
            let mut r = vec![slot.to_string()];
            r.extend(row.iter().map(cell));
            t.push(r);
        }
        t
    };
    let mut out = vec![(
        format!(
            "Table 1: slots of a {} us slice ({} cycles each), same in every slice",
            s.mix.slice_us, s.grid.slot_cycles
        ),
        t,
    )];
    if !lut.rotations.is_empty() {
        out.push((
            "Rotation groups: the channel of each slice of the frame".into(),
            rotation_table(s, &lut),
        ));
    }
    out
}

/// Columns a table may have and still fit the report's page.
pub const MAX_COLUMNS: usize = 10;

/// The rotation groups: a row per group and a column per slice, or, with
/// more slices than groups (a 20 ms frame of 1 ms slices has 20), a row
/// per slice and a column per group; when either is wider than the page
/// ([`MAX_COLUMNS`]), a row per group listing its channel slice by slice,
/// which wraps.
fn rotation_table(s: &Schedule, lut: &CompactLut) -> Table {
    let name = |c: u16| s.mix.channels[c as usize].name.clone();
    let cell = |e: &Option<u16>| e.map_or("-".into(), name);
    let slices = s.grid.slices_per_frame as usize;
    let groups = &lut.rotations;
    let by_slice = slices > groups.len();
    if 1 + slices.min(groups.len()) > MAX_COLUMNS {
        let mut t = Table::new(&["group", "channel in slice 0, 1, 2, ..."]);
        for (g, group) in groups.iter().enumerate() {
            let list: Vec<String> = group.iter().map(cell).collect();
            t.push(vec![format!("R{g}"), list.join(", ")]);
        }
        return t;
    }
    let (corner, heads): (&str, Vec<String>) = if by_slice {
        (
            "slice",
            (0..groups.len()).map(|g| format!("R{g}")).collect(),
        )
    } else {
        ("group", (0..slices).map(|j| format!("slice {j}")).collect())
    };
    let mut cols = vec![corner.to_string()];
    cols.extend(heads);
    let refs: Vec<&str> = cols.iter().map(String::as_str).collect();
    let mut t = Table::new(&refs);
    if by_slice {
        for j in 0..slices {
            let mut r = vec![j.to_string()];
            r.extend(groups.iter().map(|g| g.get(j).map_or("-".into(), cell)));
            t.push(r);
        }
    } else {
        for (g, group) in groups.iter().enumerate() {
            let mut r = vec![format!("R{g}")];
            r.extend(group.iter().map(cell));
            t.push(r);
        }
    }
    t
}

/// "CH1", "CH1, CH2", or "CH1 to HUM (30)" for a run of names.
fn names(v: &[&str]) -> String {
    match v {
        [] => "-".into(),
        [a] => a.to_string(),
        [a, b] => format!("{a}, {b}"),
        [a, .., z] => format!("{a} to {z} ({})", v.len()),
    }
}

/// "a" or "a to b".
fn span(lo: u64, hi: u64) -> String {
    if lo == hi {
        lo.to_string()
    } else {
        format!("{lo} to {hi}")
    }
}

/// The intervals a run measured, a row per branch and rate (the channels
/// themselves are listed once, in the audit): channels, samples each,
/// the interval the schedule promises and the least and most measured.
pub fn interval_table(s: &Schedule, r: &judge::Verdict) -> Table {
    if s.modes.len() > 1 {
        return mode_interval_table(s, r);
    }
    let mut t = Table::new(&[
        "branch",
        "rate (Hz)",
        "channels",
        "samples each",
        "interval promised (cycles)",
        "interval measured (cycles)",
        "jitter (cycles)",
    ]);
    let mut keys: Vec<(String, u64)> = Vec::new();
    for (i, c) in r.channels.iter().enumerate() {
        let rate = s.mix.channels.get(i).map_or(0, |m| m.rate_hz);
        if !keys.contains(&(c.branch.clone(), rate)) {
            keys.push((c.branch.clone(), rate));
        }
    }
    for (branch, rate) in keys {
        let group: Vec<&judge::ChannelStats> = r
            .channels
            .iter()
            .enumerate()
            .filter(|(i, c)| {
                c.branch == branch && s.mix.channels.get(*i).map_or(0, |m| m.rate_hz) == rate
            })
            .map(|x| x.1)
            .collect();
        let g: Vec<Figures> = (group.iter())
            .map(|c| {
                (
                    c.name.as_str(),
                    c.samples,
                    c.interval_cycles,
                    c.interval_cycles_min,
                    c.interval_cycles_max,
                )
            })
            .collect();
        let mut row = vec![branch, rate.to_string()];
        row.extend(group_cells(&g));
        t.push(row);
    }
    t
}

/// A channel's run figures: name, samples, interval promised, least and
/// most measured.
type Figures<'a> = (&'a str, u64, u64, Option<u64>, Option<u64>);

/// The cells of a row of channels alike (one branch and rate): the names,
/// samples each, the interval promised, the least to most measured, and
/// the jitter (the largest spread of one channel's intervals).
fn group_cells(g: &[Figures]) -> Vec<String> {
    let list: Vec<&str> = g.iter().map(|c| c.0).collect();
    let mm = |v: Vec<u64>| span(*v.iter().min().unwrap_or(&0), *v.iter().max().unwrap_or(&0));
    let lo = g.iter().filter_map(|c| c.3).min();
    let hi = g.iter().filter_map(|c| c.4).max();
    let jitter = g.iter().filter_map(|c| Some(c.4? - c.3?)).max();
    vec![
        names(&list),
        mm(g.iter().map(|c| c.1).collect()),
        mm(g.iter().map(|c| c.2).collect()),
        match (lo, hi) {
            (Some(a), Some(b)) => span(a, b),
            _ => "-".into(),
        },
        jitter.map_or("-".into(), |j| j.to_string()),
    ]
}

/// [`interval_table`] of a mix with modes: a row per mode, branch and rate
/// in that mode, from the run's figures in each mode (intervals restart at
/// a switch, so a jitter-free run shows none across one).
fn mode_interval_table(s: &Schedule, r: &judge::Verdict) -> Table {
    let mut t = Table::new(&[
        "mode",
        "branch",
        "rate (Hz)",
        "channels",
        "samples each",
        "interval promised (cycles)",
        "interval measured (cycles)",
        "jitter (cycles)",
    ]);
    for (m, ms) in s.modes.iter().enumerate() {
        let rate = |i: usize| ms.mix.channels.get(i).map_or(0, |c| c.rate_hz);
        let mut keys: Vec<(String, u64)> = Vec::new();
        for (i, c) in r.channels.iter().enumerate() {
            if rate(i) > 0 && !keys.contains(&(c.branch.clone(), rate(i))) {
                keys.push((c.branch.clone(), rate(i)));
            }
        }
        for (branch, hz) in keys {
            let group: Vec<(&str, &judge::ModeStats)> = (r.channels.iter().enumerate())
                .filter(|(i, c)| c.branch == branch && rate(*i) == hz)
                .filter_map(|(_, c)| Some((c.name.as_str(), c.modes.get(m)?)))
                .collect();
            let Some(mode) = group.first().map(|g| g.1.mode.clone()) else {
                continue;
            };
            let g: Vec<Figures> = (group.iter())
                .map(|(n, c)| {
                    (
                        *n,
                        c.samples,
                        c.interval_cycles,
                        c.interval_cycles_min,
                        c.interval_cycles_max,
                    )
                })
                .collect();
            let mut row = vec![mode, branch, hz.to_string()];
            row.extend(group_cells(&g));
            t.push(row);
        }
    }
    t
}

/// The fault campaign by class: each detector's count apart ("n of N", or
/// "cannot see"), then what no detector caught.
pub fn fault_table(c: &campaign::Campaign) -> Table {
    let mut head: Vec<String> = vec!["class".into(), "level".into(), "injected".into()];
    head.extend(c.detectors.iter().map(|d| d.name().to_string()));
    head.extend(["undetected".into(), "proved equivalent".into()]);
    let head: Vec<&str> = head.iter().map(String::as_str).collect();
    let mut t = Table::new(&head);
    for k in &c.classes {
        let mut row = vec![
            k.name.to_string(),
            k.level.to_string(),
            k.injected.to_string(),
        ];
        for d in &c.detectors {
            row.push(match (k.detected_by.get(d), k.cannot_see.get(d)) {
                (Some(n), _) => format!("{n} of {}", k.injected),
                (None, Some(_)) => "cannot see".into(),
                (None, None) => "not run".into(),
            });
        }
        row.push(k.undetected.len().to_string());
        row.push(k.proved_equivalent.len().to_string());
        t.push(row);
    }
    t
}
