//! All of this crate's integration tests in one binary: each test file is
//! a module here, so the workspace is linked once, not once per file.

#[path = "capture_mixes.rs"]
mod capture_mixes;

#[path = "commands.rs"]
mod commands;

#[path = "equiv.rs"]
mod equiv;

#[path = "link.rs"]
mod link;

#[path = "methods.rs"]
mod methods;

#[path = "mutants.rs"]
mod mutants;

#[path = "pins.rs"]
mod pins;

#[path = "readable.rs"]
mod readable;

#[path = "random_mixes.rs"]
mod random_mixes;

#[path = "gateware_commands.rs"]
mod gateware_commands;

// Shared by several test files (one copy in this binary).
use testkit::tools;

#[path = "modes.rs"]
mod modes;

// The modules' own tests (the crate has no unit-test harness: `[lib] test =
// false`), through its public face and its `for_tests` items.
#[path = "units/mod.rs"]
mod units;
