//! All of this crate's integration tests in one binary: each test file is
//! a module here, so the workspace is linked once, not once per file.

#[path = "capture.rs"]
mod capture;

#[path = "command.rs"]
mod command;

#[path = "fuzz_regressions.rs"]
mod fuzz_regressions;

#[path = "lock.rs"]
mod lock;

#[path = "model_check.rs"]
mod model_check;

#[path = "vcd.rs"]
mod vcd;

#[path = "modes.rs"]
mod modes;

#[path = "modevcd.rs"]
mod modevcd;

#[path = "modelink.rs"]
mod modelink;

#[path = "cnvlow.rs"]
mod cnvlow;

#[path = "holdoff.rs"]
mod holdoff;

// The rooms' own tests (the crate has no unit-test harness: `[lib] test =
// false`), through its public face and its `for_tests` items.
#[path = "units/mod.rs"]
mod units;
