//! All of this crate's integration tests in one binary: each test file is
//! a module here, so the workspace is linked once, not once per file.

#[path = "build.rs"]
mod build;

#[path = "bulk.rs"]
mod bulk;

#[path = "capture.rs"]
mod capture;

#[path = "cli.rs"]
mod cli;

#[path = "docs.rs"]
mod docs;

#[path = "figures.rs"]
mod figures;
#[path = "fixes.rs"]
mod fixes;

#[path = "fusesoc.rs"]
mod fusesoc;

#[path = "front_modes.rs"]
mod front_modes;

#[path = "golden.rs"]
mod golden;

#[path = "golden_rtl.rs"]
mod golden_rtl;

#[path = "hints.rs"]
mod hints;

#[path = "host_sigrok.rs"]
mod host_sigrok;

#[path = "icarus.rs"]
mod icarus;

#[path = "instants.rs"]
mod instants;

#[path = "link.rs"]
mod link;

#[path = "matrix.rs"]
mod matrix;

#[path = "link_bytes.rs"]
mod link_bytes;
#[path = "link_captures.rs"]
mod link_captures;
#[path = "link_windows.rs"]
mod link_windows;

#[path = "mode_captures.rs"]
mod mode_captures;
#[path = "modes_cli.rs"]
mod modes_cli;

#[path = "netlist.rs"]
mod netlist;

#[path = "prove_cli.rs"]
mod prove_cli;

#[path = "rtl.rs"]
mod rtl;

#[path = "samples.rs"]
mod samples;

#[path = "sigrok.rs"]
mod sigrok;

#[path = "sim_cli.rs"]
mod sim_cli;

#[path = "synth_cli.rs"]
mod synth_cli;

#[path = "tool_policy.rs"]
mod tool_policy;

#[path = "tree.rs"]
mod tree;

// Shared by several test files (one copy in this binary).
use testkit::tools;

// Shared by several test files (one copy in this binary).
use testkit::presets as common_presets;

// Shared by several test files (one copy in this binary).
#[path = "common/progress.rs"]
mod progress;

// Shared by several test files (one copy in this binary).
#[path = "common/cli.rs"]
mod common_cli;
