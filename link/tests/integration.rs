//! All of this crate's integration tests in one binary.

// The modules' own tests (the crate has no unit-test harness: `[lib] test =
// false`), through its public face and its `for_tests` items.
#[path = "units/mod.rs"]
mod units;
