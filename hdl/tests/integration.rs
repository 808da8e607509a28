//! All of this crate's integration tests in one binary: each test file is
//! a module here, so the workspace is linked once, not once per file.

#[path = "rtlsim.rs"]
mod rtlsim;

#[path = "tools.rs"]
mod tools;

// The workspace's one tool policy (missing tools fail under CI=true).
use testkit::tools as policy;

// Shared by several test files (one copy in this binary).
#[path = "common/mod.rs"]
mod common;

// The modules' own tests (the crate has no unit-test harness: `[lib] test =
// false`), through its public face and its `for_tests` items.
#[path = "units/mod.rs"]
mod units;
