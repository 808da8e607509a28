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
