//! The plain progress lines a command prints off a terminal
//! (`src/cmd/progress.rs`): `<prefix><done> of <total><unit> (...)`, a line
//! per tenth. Shared by the progress tests of `check`, `check --map` and
//! `faults`.

/// Every `(done, total)` pair of the lines of `log` that start with `prefix`
/// and count in `unit` (e.g. `" MB read"`, `" runs"`).
pub fn counts(log: &str, prefix: &str, unit: &str) -> Vec<(f64, f64)> {
    let tail = format!("{unit} (");
    log.lines()
        .filter_map(|l| {
            let (done, rest) = l.strip_prefix(prefix)?.split_once(" of ")?;
            let total = rest.split_once(tail.as_str())?.0;
            Some((done.parse().ok()?, total.parse().ok()?))
        })
        .collect()
}

/// Asserts the progress lines are at least five, rise strictly and end at
/// their total; returns that total.
pub fn rises_to_total(log: &str, prefix: &str, unit: &str) -> f64 {
    let counts = counts(log, prefix, unit);
    assert!(counts.len() >= 5, "{log}");
    assert!(counts.windows(2).all(|w| w[0].0 < w[1].0), "{log}");
    let (done, total) = *counts.last().unwrap();
    assert_eq!(done, total, "{log}");
    total
}
