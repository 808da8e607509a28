//! The report's tables: the audit (from its JSON, so every audited field is
//! shown, as HTML tables instead of clipped text), the slot table in the
//! paper's Table 1 form, the co-simulation's per-channel interval
//! statistics, and the fault campaign.

use lut_gen::lut::{CompactLut, SliceCell};
use lut_gen::{AuditReport, Schedule};
use report::Table;
use serde_json::Value;

/// A JSON scalar as a cell.
fn cell(v: &Value) -> String {
    match v {
        Value::Null => "-".into(),
        Value::String(s) => s.clone(),
        Value::Number(n) => match n.as_f64() {
            Some(f) if n.is_f64() => format!("{}", (f * 1e4).round() / 1e4),
            _ => n.to_string(),
        },
        Value::Bool(b) => b.to_string(),
        Value::Array(a) if a.iter().all(|x| !x.is_object()) => {
            a.iter().map(cell).collect::<Vec<_>>().join("; ")
        }
        other => compact(other),
    }
}

/// An object or an array of objects, on one line (`key=value, ...`).
fn compact(v: &Value) -> String {
    match v {
        Value::Object(o) => o
            .iter()
            .map(|(k, x)| format!("{k}={}", cell(x)))
            .collect::<Vec<_>>()
            .join(", "),
        Value::Array(a) => a.iter().map(compact).collect::<Vec<_>>().join(" | "),
        other => cell(other),
    }
}

/// Columns per table: wider record lists are split (the first column, the
/// record's name, repeated), so no table is wider than the page.
const COLUMNS: usize = 7;

/// The audit as tables: the mix's figures (key, value), then each list of
/// records (branches, parts, channels) a row per record, and each list
/// inside a record (a branch's headroom per rate) its own table.
pub fn audit(r: &AuditReport) -> Vec<(String, Table)> {
    let v = serde_json::to_value(r).expect("the audit serializes");
    let Value::Object(o) = v else {
        return Vec::new();
    };
    let mut facts = Table::new(&["figure", "value"]);
    let mut lists = Vec::new();
    for (k, x) in &o {
        match x {
            Value::Array(a) if a.first().is_some_and(Value::is_object) => {
                records(&format!("Audit: {k}"), a, &mut lists)
            }
            Value::Array(a) if a.is_empty() => facts.push(vec![k.clone(), "none".into()]),
            _ => facts.push(vec![k.clone(), cell(x)]),
        }
    }
    let mut out = vec![("Audit: the mix".to_string(), facts)];
    out.extend(lists);
    out
}

/// Records as tables of at most [`COLUMNS`] columns, `name` first; nested
/// record lists become tables of their own, keyed by the parent's name.
fn records(title: &str, a: &[Value], out: &mut Vec<(String, Table)>) {
    let keys: Vec<String> = a[0]
        .as_object()
        .map(|m| m.keys().cloned().collect())
        .unwrap_or_default();
    let key = if keys.iter().any(|k| k == "name") {
        "name"
    } else {
        keys[0].as_str()
    }
    .to_string();
    let nested = |k: &String| {
        a.iter().any(|r| {
            r[k.as_str()]
                .as_array()
                .is_some_and(|v| v.first().is_some_and(Value::is_object))
        })
    };
    let plain: Vec<&String> = keys.iter().filter(|k| **k != key && !nested(k)).collect();
    let chunks: Vec<&[&String]> = plain.chunks(COLUMNS - 1).collect();
    for (n, cols) in chunks.iter().enumerate() {
        let mut names = vec![key.as_str()];
        names.extend(cols.iter().map(|c| c.as_str()));
        let mut t = Table::new(&names);
        for row in a {
            let mut r = vec![cell(&row[key.as_str()])];
            r.extend(cols.iter().map(|c| cell(&row[c.as_str()])));
            t.push(r);
        }
        let part = if chunks.len() > 1 {
            format!(" ({} of {})", n + 1, chunks.len())
        } else {
            String::new()
        };
        out.push((format!("{title}{part}"), t));
    }
    for k in keys.iter().filter(|k| nested(k)) {
        let inner: Vec<Value> = a
            .iter()
            .flat_map(|row| {
                let parent = row[key.as_str()].clone();
                let key = key.clone();
                row[k.as_str()]
                    .as_array()
                    .cloned()
                    .unwrap_or_default()
                    .into_iter()
                    .map(move |mut x| {
                        if let Value::Object(m) = &mut x {
                            let mut with = serde_json::Map::new();
                            with.insert(key.clone(), parent.clone());
                            with.extend(std::mem::take(m));
                            *m = with;
                        }
                        x
                    })
            })
            .collect();
        if !inner.is_empty() {
            records(&format!("{title}: {k}"), &inner, out);
        }
    }
}

/// The slot table in the paper's Table 1 form: a row per slot of the slice,
/// a column per branch, each cell the channel converted there in every
/// slice, or a rotation group (`R0`) whose member changes slice by slice;
/// and the rotation groups, a column per slice.
pub fn slot_table(s: &Schedule) -> Vec<(String, Table)> {
    let lut = CompactLut::from_schedule(s);
    let name = |c: u16| s.mix.channels[c as usize].name.clone();
    let mut cols = vec!["slot".to_string()];
    cols.extend(s.branches.iter().map(|b| b.name.clone()));
    let refs: Vec<&str> = cols.iter().map(String::as_str).collect();
    let mut t = Table::new(&refs);
    for (slot, row) in lut.slice_table.iter().enumerate() {
        let mut r = vec![slot.to_string()];
        r.extend(row.iter().map(|c| match c {
            SliceCell::Idle => "-".to_string(),
            SliceCell::Fixed(c) => name(*c),
            SliceCell::Rotate(g) => format!("R{g}"),
        }));
        t.push(r);
    }
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

/// The rotation groups: a row per group and a column per slice, or, with
/// more slices than groups (a 20 ms frame of 1 ms slices has 20), a row
/// per slice and a column per group, so the table fits the page's width.
fn rotation_table(s: &Schedule, lut: &CompactLut) -> Table {
    let name = |c: u16| s.mix.channels[c as usize].name.clone();
    let cell = |e: &Option<u16>| e.map_or("-".into(), name);
    let slices = s.grid.slices_per_frame as usize;
    let groups = &lut.rotations;
    let by_slice = slices > groups.len();
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

/// Per-channel sample counts and intervals a run measured.
pub fn intervals(s: &Schedule, r: &judge::Verdict) -> Table {
    let mut t = Table::new(&[
        "channel",
        "branch",
        "rate_hz",
        "samples",
        "interval_cycles",
        "min",
        "max",
        "jitter_cycles",
    ]);
    for (i, c) in r.channels.iter().enumerate() {
        let opt = |v: Option<u64>| v.map_or("-".into(), |x| x.to_string());
        let jitter = match (c.interval_cycles_min, c.interval_cycles_max) {
            (Some(a), Some(b)) => (b - a).to_string(),
            _ => "-".into(),
        };
        t.push(vec![
            c.name.clone(),
            c.branch.clone(),
            s.mix
                .channels
                .get(i)
                .map_or("-".into(), |m| m.rate_hz.to_string()),
            c.samples.to_string(),
            c.interval_cycles.to_string(),
            opt(c.interval_cycles_min),
            opt(c.interval_cycles_max),
            jitter,
        ]);
    }
    t
}

/// The fault campaign by class: each detector's count apart ("n of N", or
/// "cannot see"), then what no detector caught.
pub fn faults(c: &campaign::Campaign) -> Table {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// 20 slices and fewer rotation groups: a row per slice, a column per
    /// group (a column per slice, 21 wide, overflowed the report's page).
    #[test]
    fn many_slices_give_the_rotation_table_a_row_per_slice() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/skin28.toml");
        let mix = lut_gen::parse(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
        let s = lut_gen::synthesize(&mix).unwrap();
        let tables = slot_table(&s);
        let (_, rot) = tables.last().unwrap();
        let csv = rot.csv();
        let head = csv.lines().next().unwrap();
        assert!(head.starts_with("slice,R0"), "{head}");
        let groups = CompactLut::from_schedule(&s).rotations.len();
        assert!(groups < s.grid.slices_per_frame as usize);
        assert_eq!(head.split(',').count(), 1 + groups, "{head}");
        assert_eq!(csv.lines().count(), 1 + s.grid.slices_per_frame as usize);
    }

    #[test]
    fn the_audit_becomes_tables_with_every_channel() {
        let mix = lut_gen::parse(
            std::path::Path::new("t.toml"),
            "name = \"t\"\n[clock]\nhz = 4_000_000\n[frame]\nperiod_us = 1_000\nslice_us = 500\n[[branch]]\nname = \"b\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 1\n[[channel]]\nname = \"X\"\nbranch = \"b\"\nrate_hz = 2_000\n[[channel]]\nname = \"Y\"\nbranch = \"b\"\nrate_hz = 1_000\n",
        )
        .unwrap();
        let s = lut_gen::synthesize(&mix).unwrap();
        let t = audit(&AuditReport::of_schedule(&s));
        // channels split into tables of at most 7 columns, name first
        let ch: Vec<&Table> = t
            .iter()
            .filter(|x| x.0.starts_with("Audit: channels ("))
            .map(|x| &x.1)
            .collect();
        assert!(ch.len() > 1);
        assert!(ch
            .iter()
            .all(|t| t.columns.len() <= COLUMNS && t.columns[0] == "name" && t.rows.len() == 2));
        assert!(ch
            .iter()
            .any(|t| t.columns.contains(&"alias_hz".to_string())));
        // a branch's headroom per rate is a table of its own
        let hr = &t
            .iter()
            .find(|x| x.0.starts_with("Audit: branches: headroom"))
            .unwrap()
            .1;
        assert_eq!(hr.columns[0], "name");
        assert_eq!(hr.rows.len(), 2, "{hr:?}");
        let st = slot_table(&s);
        let cells: Vec<&String> = st[0].1.rows.iter().flat_map(|r| &r[1..]).collect();
        assert!(cells.iter().any(|c| *c == "X"), "{cells:?}");
    }
}
