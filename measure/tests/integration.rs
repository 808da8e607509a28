//! This crate's tests in one binary, but for `speed.rs` (which turns the
//! judge's checker off for its whole process, so it runs in its own).

// The modules' own tests (the crate has no unit-test harness: `[lib] test =
// false`), through its public face and its `for_tests` items.
#[path = "units/mod.rs"]
mod units;
