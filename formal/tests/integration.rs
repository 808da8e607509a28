//! All of this crate's integration tests in one binary: each test file is
//! a module here, so the workspace is linked once, not once per file.

#[path = "coverage.rs"]
mod coverage;

#[path = "modes.rs"]
mod modes;

#[path = "prove.rs"]
mod prove;

// Shared by the test files (one copy in this binary).
mod common;

#[path = "harness_lint.rs"]
mod harness_lint;
