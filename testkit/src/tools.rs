//! The one rule for tests that drive external tools (verilator, g++,
//! iverilog): such a test must never pass by quietly doing nothing.
//!
//! - tool present: the test runs;
//! - tool missing and `CI` set (`CI=true`, as CI services set it): the test
//!   FAILS, naming the tool and `make tools`;
//! - tool missing outside CI: a loud multi-line warning on stderr, then the
//!   test skips (returns early).
//!
//! Shared by the tests of every crate (`testkit::tools`); whether a tool is there is `judge::tools::present`, the
//! library's one test. The decision table itself is tested in
//! `tests/tool_policy.rs`.
#![allow(dead_code)]

use std::io::Write;

/// What a test does about one tool.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decision {
    Run,
    Skip,
    Fail,
}

/// `CI` counts as set unless it is absent, empty, `0` or `false`.
pub fn ci_is_set(ci: Option<&str>) -> bool {
    match ci {
        None => false,
        Some(v) => {
            let v = v.trim();
            !(v.is_empty() || v == "0" || v.eq_ignore_ascii_case("false"))
        }
    }
}

/// The whole policy, as a pure function of (tool present?, value of `CI`).
pub fn decide(present: bool, ci: Option<&str>) -> Decision {
    if present {
        Decision::Run
    } else if ci_is_set(ci) {
        Decision::Fail
    } else {
        Decision::Skip
    }
}

/// Is `tool` on PATH (can it be spawned at all)? The library's one test.
pub use judge::tools::present as tool_present;

/// Applies the decision: `true` = run, `false` = skip (after a loud
/// warning); panics when the tool is missing under CI.
pub fn gate(tool: &str, present: bool, ci: Option<&str>, test: &str) -> bool {
    match decide(present, ci) {
        Decision::Run => true,
        Decision::Fail => panic!(
            "`{tool}` is not installed, and CI is set (CI={}): test `{test}` cannot run and must \
             not pass by skipping. Install it with `make tools` (apt-get install {tool}).",
            ci.unwrap_or("")
        ),
        Decision::Skip => {
            let bar = "=".repeat(78);
            // Straight to the stderr handle, not `eprintln!`: libtest would
            // capture that and hide it for a passing test.
            let _ = writeln!(
                std::io::stderr(),
                "\n{bar}\nWARNING: {tool} not installed: {test} SKIPPED — make tools installs it\n\
                 WARNING: this test did NOT run; with CI=true a missing {tool} fails it.\n{bar}\n"
            );
            false
        }
    }
}

/// Runs `cmd` (a tool, or a script of them) to completion and returns its
/// output; a failure panics with the command and its stderr.
pub fn run_ok(cmd: &mut std::process::Command) -> std::process::Output {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{cmd:?} failed: {err}");
    out
}

/// The name libtest gives the current test's thread.
fn current_test() -> String {
    std::thread::current()
        .name()
        .unwrap_or("(unnamed test)")
        .to_string()
}

/// `true` if `tool` is installed; see the module docs for what happens when not.
pub fn require_tool(tool: &str) -> bool {
    let ci = std::env::var("CI").ok();
    gate(tool, tool_present(tool), ci.as_deref(), &current_test())
}

/// `require_tool` for each tool in turn (every missing one is reported).
pub fn require_tools(tools: &[&str]) -> bool {
    let present: Vec<bool> = tools.iter().map(|t| require_tool(t)).collect();
    present.iter().all(|&p| p)
}
