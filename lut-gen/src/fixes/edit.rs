//! Edits of the user's own mix text: a fix is written as the file the
//! user would have written (comments, order and layout kept), so that the
//! file a fix offers is exactly the text that was re-synthesized.

use toml_edit::{value, DocumentMut, Item, Table};

/// One change to a mix file, in the mix format's own terms.
#[derive(Debug, Clone, PartialEq)]
pub enum Edit {
    /// `[frame].slice_us = us`.
    SliceUs(u64),
    /// Leave the slot grid to the synthesizer (drop `[frame] slots_per_slice`).
    FreeGrid,
    /// Channel `name` on branch `to`, its mux input chosen by the loader
    /// (the lowest free one) and its chain member the first.
    MoveChannel { name: String, to: String },
    /// Channel `name` at `hz`.
    Rate { name: String, hz: u64 },
    /// Branch `name` with `devices` mux devices.
    MuxDevices { name: String, devices: u32 },
    /// A new branch `name` with every setting of branch `like`.
    BranchLike { name: String, like: String },
    /// `[link].baud`.
    Baud(u64),
    /// Branch `name`'s converter supply, `vdd`, in millivolts.
    Vdd { name: String, mv: u32 },
}

/// `text` with `edits` applied, or `None` when the text is not TOML or a
/// table an edit names is missing (the candidate is then not offered).
pub fn apply(text: &str, edits: &[Edit]) -> Option<String> {
    let mut doc: DocumentMut = text.parse().ok()?;
    let named: Vec<&str> = (edits.iter())
        .filter_map(|e| match e {
            Edit::MoveChannel { name, .. } | Edit::Rate { name, .. } => Some(name.as_str()),
            _ => None,
        })
        .collect();
    write_out_rows(&mut doc, &named)?;
    for e in edits {
        apply_one(&mut doc, e)?;
    }
    Some(doc.to_string())
}

fn apply_one(doc: &mut DocumentMut, e: &Edit) -> Option<()> {
    match e {
        Edit::SliceUs(us) => {
            doc.get_mut("frame")?
                .as_table_like_mut()?
                .insert("slice_us", value(*us as i64));
        }
        Edit::FreeGrid => {
            doc.get_mut("frame")?
                .as_table_like_mut()?
                .remove("slots_per_slice")?;
        }
        Edit::MoveChannel { name, to } => {
            let t = named(doc, "channel", name)?;
            t.insert("branch", value(to.as_str()));
            t.remove("input");
            t.remove("member");
        }
        Edit::Rate { name, hz } => {
            named(doc, "channel", name)?.insert("rate_hz", value(*hz as i64));
        }
        Edit::MuxDevices { name, devices } => {
            named(doc, "branch", name)?.insert("mux_devices", value(*devices as i64));
        }
        Edit::BranchLike { name, like } => {
            let mut t: Table = named(doc, "branch", like)?.clone();
            t.insert("name", value(name.as_str()));
            // a copy keeps its place after the original's siblings
            t.set_position(usize::MAX);
            doc.get_mut("branch")?.as_array_of_tables_mut()?.push(t);
        }
        Edit::Vdd { name, mv } => {
            named(doc, "branch", name)?.insert("vdd", value(*mv as f64 / 1000.0));
        }
        Edit::Baud(baud) => {
            doc.get_mut("link")?
                .as_table_like_mut()?
                .insert("baud", value(*baud as i64));
        }
    }
    Some(())
}

/// Every bulk row (`name = "P{0..7}"`) holding one of `names`, written out
/// in place as the channels it stands for (each counter it has counted up
/// as the loader counts it), so that an edit can change one of them: the
/// mix is the same, its rows now one table each.
fn write_out_rows(doc: &mut DocumentMut, names: &[&str]) -> Option<()> {
    let Some(aot) = doc
        .get_mut("channel")
        .and_then(Item::as_array_of_tables_mut)
    else {
        return Some(());
    };
    let rows: Vec<(Table, Vec<String>)> = (aot.iter())
        .map(|t| {
            let written = t.get("name").and_then(Item::as_str).unwrap_or("");
            let each = crate::mix::expand_names(written).unwrap_or_default();
            (t.clone(), each)
        })
        .collect();
    if !rows
        .iter()
        .any(|(_, each)| each.len() > 1 && each.iter().any(|n| names.contains(&n.as_str())))
    {
        return Some(());
    }
    aot.clear();
    for (t, each) in rows {
        if each.len() < 2 || !each.iter().any(|n| names.contains(&n.as_str())) {
            aot.push(t);
            continue;
        }
        // behind a front mux the row counts `front_input`, else `input`
        let counted = if t.contains_key("front_input") {
            "front_input"
        } else {
            "input"
        };
        for (step, name) in each.iter().enumerate() {
            let mut one = t.clone();
            one.insert("name", value(name.as_str()));
            for key in [counted, "member"] {
                if let Some(v) = t.get(key).and_then(Item::as_integer) {
                    one.insert(key, value(v + step as i64));
                }
            }
            aot.push(one);
        }
    }
    Some(())
}

/// The `[[array]]` table whose `name` is `name`.
fn named<'a>(doc: &'a mut DocumentMut, array: &str, name: &str) -> Option<&'a mut Table> {
    doc.get_mut(array)?
        .as_array_of_tables_mut()?
        .iter_mut()
        .find(|t| t.get("name").and_then(Item::as_str) == Some(name))
}
