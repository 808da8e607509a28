//! Sync groups' hold-offs: all of a slot's conversions start at the slot
//! tick, but parts hold their inputs at different points of their
//! transactions (an AD7940 at CS falling, an MCP3208 about 6 us later).
//! A branch linked by sync groups to a part that holds later starts its
//! transaction later by the difference, so every group holds at one
//! instant (docs/timing.md, "Hold-off").

use crate::mix::{Mix, SYNC_TOLERANCE_NS};
use crate::parts::cycles_to_ns;

/// Per branch, the cycles its transactions wait after the slot tick.
/// `own[b]`: branch `b`'s own cycles from its transaction's start to its
/// instant (`SpiTiming::sample_cycles`). A branch in no sync group, or
/// whose group's parts already hold within [`SYNC_TOLERANCE_NS`] of the
/// latest one, waits 0 (so such a mix's gateware is what it always was).
pub(crate) fn holdoffs(mix: &Mix, own: &[u64]) -> Vec<u64> {
    let group = linked_groups(mix);
    (0..own.len())
        .map(|b| {
            let latest = (0..own.len())
                .filter(|&o| group[o] == group[b])
                .map(|o| own[o])
                .max()
                .unwrap_or(own[b]);
            let h = latest - own[b];
            match cycles_to_ns(h, mix.clock_hz) <= SYNC_TOLERANCE_NS as f64 {
                true => 0,
                false => h,
            }
        })
        .collect()
}

/// For every branch, the lowest branch linked to it by sync groups,
/// transitively (itself when in none): union-find over the groups' members.
fn linked_groups(mix: &Mix) -> Vec<usize> {
    let mut root: Vec<usize> = (0..mix.branches.len()).collect();
    fn find(root: &mut [usize], b: usize) -> usize {
        let mut r = b;
        while root[r] != r {
            r = root[r];
        }
        root[b] = r;
        r
    }
    let mut first_of: std::collections::BTreeMap<&str, usize> = Default::default();
    for c in &mix.channels {
        let Some(tag) = &c.sync else { continue };
        let first = *first_of.entry(tag.as_str()).or_insert(c.branch);
        let (a, b) = (find(&mut root, first), find(&mut root, c.branch));
        root[a.max(b)] = a.min(b);
    }
    (0..root.len()).map(|b| find(&mut root, b)).collect()
}
