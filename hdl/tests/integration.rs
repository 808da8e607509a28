//! All of this crate's integration tests in one binary: each test file is
//! a module here, so the workspace is linked once, not once per file.

#[path = "rtlsim.rs"]
mod rtlsim;

#[path = "tools.rs"]
mod tools;
