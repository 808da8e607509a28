//! The plain progress lines a command prints off a terminal
//! (`src/cmd/progress.rs`): `<prefix><done> of <total><unit> (<pct>%, <secs>
//! s, ...)`, nothing in the first second, then at most one every few
//! seconds.  The tests run the command on a controllable clock
//! ([`STEP_ENV`]: each reading of it advances by so many milliseconds).
//! Shared by the progress tests of `check`, `check --map` and `faults`.

/// The environment variable that makes the progress's clock a stepped one.
pub const STEP_ENV: &str = "SLOTFORGE_TEST_PROGRESS_STEP_MS";

/// A second a reading: the lines' whole seconds are exact.
pub const SLOW: &str = "1000";
/// A millisecond a reading: the work ends within a second of this clock.
pub const QUICK: &str = "1";

/// Every `(done, total, secs)` of the lines of `log` that start with
/// `prefix` and count in `unit` (e.g. `" MB read"`, `" runs"`).
pub fn counts(log: &str, prefix: &str, unit: &str) -> Vec<(f64, f64, f64)> {
    let tail = format!("{unit} (");
    log.lines()
        .filter_map(|l| {
            let (done, rest) = l.strip_prefix(prefix)?.split_once(" of ")?;
            let (total, rest) = rest.split_once(tail.as_str())?;
            let secs = rest.split_once("%, ")?.1.split(' ').next()?;
            Some((done.parse().ok()?, total.parse().ok()?, secs.parse().ok()?))
        })
        .collect()
}

/// Asserts the progress lines (on the [`SLOW`] clock) are at least two,
/// rise strictly, begin after a second and are a few seconds apart;
/// returns their total.
pub fn paced(log: &str, prefix: &str, unit: &str) -> f64 {
    let counts = counts(log, prefix, unit);
    assert!(counts.len() >= 2, "{log}");
    assert!(counts.windows(2).all(|w| w[0].0 < w[1].0), "{log}");
    assert!(counts[0].2 >= 1.0, "{log}");
    assert!(counts.windows(2).all(|w| w[1].2 - w[0].2 >= 3.0), "{log}");
    let total = counts[0].1;
    assert!(counts.iter().all(|c| c.1 == total), "{log}");
    total
}
