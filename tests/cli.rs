//! End-to-end tests of the `slotforge` binary: exit codes, messages, files.

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use predicates::prelude::*;

fn slotforge() -> Command {
    Command::cargo_bin("slotforge").unwrap()
}

fn preset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("mixes")
        .join(name)
}

fn write_mix(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("mix.toml");
    std::fs::write(&p, text).unwrap();
    p
}

const SMALL: &str =
    "name = \"small\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 10_000\nslice_us = 1_000\n\
[[branch]]\nname = \"a\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n\
[[channel]]\nname = \"x\"\nbranch = \"a\"\nrate_hz = 1_000\n";

#[test]
fn audit_reference_json_has_the_spec_fields() {
    let out = slotforge()
        .args(["audit", "--json"])
        .arg(preset("eskin34.toml"))
        .assert()
        .success();
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    for key in [
        "mix",
        "feasible",
        "clock_hz",
        "frame_cycles",
        "slice_cycles",
        "slot_cycles",
        "slots_per_slice",
        "samples_per_frame",
        "aggregate_hz",
        "errors",
        "branches",
        "channels",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["feasible"], true);
    assert_eq!(v["slots_per_slice"], 30);
    assert_eq!(v["samples_per_frame"], 349);
    let ch = &v["channels"][0];
    for key in [
        "name",
        "branch",
        "requested_hz",
        "achieved_hz",
        "samples_per_frame",
        "interval_cycles",
        "jitter_cycles",
        "first_sample_cycle",
    ] {
        assert!(ch.get(key).is_some(), "channel missing {key}");
    }
    assert!(v["branches"][0]["utilization"].is_number());
}

#[test]
fn every_preset_audits_feasible() {
    for entry in std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("mixes")).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "toml") {
            slotforge()
                .arg("audit")
                .arg(&p)
                .assert()
                .success()
                .stdout(predicate::str::contains("FEASIBLE"));
        }
    }
}

#[test]
fn infeasible_mix_exits_1_with_a_diagnosis() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = SMALL.replace("mux = \"tmux1108\"", "mux = \"tmux1108\"\nmux_devices = 2");
    for i in 0..13 {
        text.push_str(&format!(
            "[[channel]]\nname = \"f{i}\"\nbranch = \"a\"\nrate_hz = 8_000\n"
        ));
    }
    let p = write_mix(dir.path(), &text);
    slotforge()
        .arg("audit")
        .arg(&p)
        .assert()
        .code(1)
        .stdout(predicate::str::contains("branch `a`"))
        .stdout(predicate::str::contains("could not place"))
        .stdout(predicate::str::contains("samples/s"));
    let out = slotforge()
        .args(["audit", "--json"])
        .arg(&p)
        .assert()
        .code(1);
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    assert_eq!(v["feasible"], false);
    assert!(!v["errors"].as_array().unwrap().is_empty());
}

#[test]
fn bad_input_names_file_line_and_field_and_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let p = write_mix(
        dir.path(),
        &SMALL.replace("rate_hz = 1_000", "rate_hz = 1_000\nrate = 5"),
    );
    slotforge()
        .arg("audit")
        .arg(&p)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("mix.toml:15:"))
        .stderr(predicate::str::contains("channel[0].rate"))
        .stderr(predicate::str::contains("panicked").not());
    let p = write_mix(
        dir.path(),
        &SMALL.replace("branch = \"a\"\nrate_hz", "branch = \"nope\"\nrate_hz"),
    );
    slotforge()
        .arg("audit")
        .arg(&p)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("unknown branch `nope`"));
    slotforge()
        .arg("audit")
        .arg(dir.path().join("missing.toml"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("cannot read"));
}

#[test]
fn lut_writes_three_files_deterministically() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    for d in [&a, &b] {
        slotforge()
            .arg("lut")
            .arg(preset("eskin34.toml"))
            .arg("-o")
            .arg(d.path())
            .assert()
            .success();
    }
    for f in ["slots.hex", "slots.csv", "slots.md"] {
        let x = std::fs::read(a.path().join(f)).unwrap();
        let y = std::fs::read(b.path().join(f)).unwrap();
        assert!(!x.is_empty());
        assert_eq!(x, y, "{f} differs between runs");
    }
    let hex = std::fs::read_to_string(a.path().join("slots.hex")).unwrap();
    assert_eq!(hex.lines().filter(|l| !l.starts_with("//")).count(), 300);
}

#[test]
fn lut_refuses_to_replace_a_file_with_a_directory() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("precious");
    std::fs::write(&target, "keep me").unwrap();
    slotforge()
        .arg("lut")
        .arg(preset("eskin34.toml"))
        .arg("-o")
        .arg(&target)
        .assert()
        .code(2);
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep me");
}

#[test]
fn faults_are_all_caught_on_the_reference_mix() {
    let out = slotforge()
        .args(["faults", "--json", "--false-alarm-mixes", "4"])
        .arg(preset("eskin34.toml"))
        .assert()
        .success();
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    assert_eq!(v["ok"], true);
    let sites = v["sites"].as_array().unwrap();
    let names: Vec<&str> = sites.iter().map(|s| s["name"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        ["frame-start", "slice-boundary", "mid-frame", "last-slot"]
    );
    let classes = v["classes"].as_array().unwrap();
    let class = |n: &str| {
        classes
            .iter()
            .find(|c| c["name"] == n)
            .unwrap_or_else(|| panic!("{n}"))
    };
    // stream faults and reset glitches at every site; branch faults at
    // every site of each of the 3 branches; two-mux-en on the two
    // multi-device branches
    for n in [
        "wrong-channel",
        "wrong-sample-bit",
        "drop-sample",
        "reset-glitch",
    ] {
        assert_eq!(class(n)["injected"], 4, "{n}");
    }
    for n in ["cs-late", "sclk-extra-edge", "mux-late", "wrong-mux"] {
        assert_eq!(class(n)["injected"], 12, "{n}");
    }
    assert_eq!(class("two-mux-en")["injected"], 8);
    for c in classes {
        assert_eq!(c["injected"], c["detected"], "{c}");
        assert!(c["missed"].as_array().unwrap().is_empty());
    }
    assert_eq!(v["false_alarms"]["rejected"], 0);
    assert_eq!(v["false_alarms"]["mixes"], 4);
    slotforge()
        .args(["faults", "--backend", "nope"])
        .arg(preset("eskin34.toml"))
        .assert()
        .code(2);
}

#[test]
fn gateware_faults_are_caught_at_every_site() {
    let tiny = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("cosim/tests/data/tiny.toml");
    let out = slotforge()
        .args([
            "faults",
            "--backend",
            "rusthdl",
            "--json",
            "--false-alarm-mixes",
            "3",
        ])
        .arg(&tiny)
        .assert()
        .success();
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    let classes = v["classes"].as_array().unwrap();
    for n in [
        "rom-word",
        "rom-swap",
        "slot-wrap-early",
        "slot-wrap-late",
        "reset-glitch",
    ] {
        let c = classes
            .iter()
            .find(|c| c["name"] == n)
            .unwrap_or_else(|| panic!("{n} missing: {v}"));
        assert!(c["injected"].as_u64().unwrap() >= 1, "{c}");
        assert_eq!(c["injected"], c["detected"], "{c}");
    }
    let rom = classes.iter().find(|c| c["name"] == "rom-word").unwrap();
    // every branch at every site
    assert!(rom["injected"].as_u64().unwrap() >= 2 * 3, "{rom}");
    assert_eq!(v["ok"], true);
}

/// A mix of `nb` AD7940 branches with `per` channels each at 1 kHz (10 ms frame).
fn big_mix(nb: usize, per: usize, devices: usize) -> String {
    let mut t = String::from(
        "name = \"big\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 10_000\nslice_us = 1_000\n",
    );
    for b in 0..nb {
        t += &format!(
            "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = {devices}\n"
        );
    }
    for b in 0..nb {
        for i in 0..per {
            t += &format!(
                "[[channel]]\nname = \"b{b}c{i}\"\nbranch = \"b{b}\"\nrate_hz = 100\ninput = {i}\n"
            );
        }
    }
    t
}

#[test]
fn verilog_refuses_mixes_beyond_the_gateware_limits() {
    let d = tempfile::tempdir().unwrap();
    let limits = [
        (
            big_mix(17, 1, 1),
            "17 branches: the gateware supports 1 to 16",
        ),
        (
            big_mix(5, 205, 26),
            "1025 channels: the gateware supports 1 to 1024",
        ),
        (
            big_mix(5, 1, 26),
            "130 mux devices in total: the gateware supports at most 128",
        ),
    ];
    for (text, msg) in limits {
        let p = write_mix(d.path(), &text);
        slotforge().arg("audit").arg(&p).assert().code(0);
        slotforge()
            .arg("verilog")
            .arg(&p)
            .arg("-o")
            .arg(d.path().join("out"))
            .assert()
            .code(1)
            .stderr(predicate::str::contains(msg));
    }
    // the largest mixes of the test data emit
    for name in ["full300", "b16", "ch1024"] {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("hdl/tests/data/{name}.toml"));
        slotforge()
            .arg("verilog")
            .arg(&p)
            .arg("-o")
            .arg(d.path().join(name))
            .assert()
            .code(0);
    }
}
