//! All of this crate's integration tests in one binary: each test file is
//! a module here, so the workspace is linked once, not once per file.

#[path = "backends.rs"]
mod backends;

#[path = "command.rs"]
mod command;

#[path = "front.rs"]
mod front;

#[path = "icarus.rs"]
mod icarus;

#[path = "modes.rs"]
mod modes;

#[path = "verilator_shim.rs"]
mod verilator_shim;

// The port scan's own tests (the crate has no unit-test harness: `[lib]
// test = false`), through its `for_tests` items.
#[path = "rtl_units.rs"]
mod rtl_units;

// Shared by several test files (one copy in this binary).
use testkit::tools;
