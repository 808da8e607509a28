//! All of this crate's integration tests in one binary: each test file is
//! a module here, so the crate is linked once, not once per file.

// Shared by several test files (one copy in this binary).
#[path = "common.rs"]
mod common;

#[path = "modes.rs"]
mod modes;

#[path = "properties.rs"]
mod properties;

#[path = "reference.rs"]
mod reference;

// The modules' own tests (the crate has no unit-test harness: `[lib] test =
// false`), through its public face and its `for_tests` items.
#[path = "units/mod.rs"]
mod units;
