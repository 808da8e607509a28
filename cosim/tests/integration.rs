//! All of this crate's integration tests in one binary: each test file is
//! a module here, so the workspace is linked once, not once per file.

#[path = "backends.rs"]
mod backends;

#[path = "capture_mixes.rs"]
mod capture_mixes;

#[path = "equiv.rs"]
mod equiv;

#[path = "icarus.rs"]
mod icarus;

#[path = "link.rs"]
mod link;

#[path = "mutants.rs"]
mod mutants;

#[path = "random_mixes.rs"]
mod random_mixes;

#[path = "verilator_shim.rs"]
mod verilator_shim;

// Shared by several test files (one copy in this binary).
#[path = "../../tests/common/tools.rs"]
mod tools;
