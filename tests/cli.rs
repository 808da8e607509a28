//! End-to-end tests of the `slotforge` binary: exit codes, messages, files.

use std::path::{Path, PathBuf};

use predicates::prelude::*;

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::common_cli::{column, refused, slotforge, tiny};
use crate::{progress, tools};

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

/// `sim --quiet` of `frames` frames of `mix` on `backend` (and `extra`),
/// every one of them into `vcd`; the run must pass.
fn sim_to_vcd(mix: &Path, backend: &str, frames: &str, extra: &[&str], vcd: &Path) {
    slotforge()
        .args(["sim", "--quiet", "--backend", backend])
        .args(["--frames", frames, "--to", frames])
        .args(extra)
        .arg("--vcd")
        .arg(vcd)
        .arg(mix)
        .assert()
        .success();
}

/// Field `field` of every object in the JSON array `list`, as text.
fn strings<'a>(list: &'a serde_json::Value, field: &str) -> Vec<&'a str> {
    (list.as_array().unwrap().iter())
        .map(|x| x[field].as_str().unwrap())
        .collect()
}

const SMALL: &str =
    "name = \"small\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 10_000\nslice_us = 1_000\n\
[[branch]]\nname = \"a\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n\
[[channel]]\nname = \"x\"\nbranch = \"a\"\nrate_hz = 1_000\n";

#[test]
fn audit_reference_json_has_the_documented_fields() {
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
    // An over-full branch leads with demand against capacity, per slice.
    let out = slotforge().arg("audit").arg(&p).output().unwrap();
    let first = String::from_utf8_lossy(&out.stdout);
    let first = first.lines().next().unwrap_or("");
    assert!(
        first.starts_with("branch `a` needs ")
            && first.contains(" conversions per slice, its ADC fits "),
        "{first}"
    );
    let out = slotforge()
        .args(["audit", "--json"])
        .arg(&p)
        .assert()
        .code(1);
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    assert_eq!(v["feasible"], false);
    assert!(!v["errors"].as_array().unwrap().is_empty());
}

/// Exit 3, "unknown": the exact search stopped at its bound with neither a
/// schedule nor a proof. `--search-limit 2` reaches it on the mix that only
/// fits at 96 slots per slice (`missed.toml`), which the default bound
/// schedules; no files are written for a mix without a schedule.
#[test]
fn a_search_cut_short_by_search_limit_is_unknown_exit_3() {
    let missed = Path::new(env!("CARGO_MANIFEST_DIR")).join("lut-gen/tests/data/missed.toml");
    slotforge()
        .arg("audit")
        .arg(&missed)
        .args(["--search-limit", "2"])
        .assert()
        .code(3)
        .stdout(predicate::str::starts_with("mix `missed`: unknown"))
        .stdout(predicate::str::contains("bound of 2 placements"))
        .stdout(predicate::str::contains("has no jitter-free schedule").not());
    let out = slotforge()
        .args(["audit", "--json", "--search-limit", "2"])
        .arg(&missed)
        .assert()
        .code(3);
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    assert_eq!(v["feasible"], false, "{v}");
    assert_eq!(v["verdict"], "unknown", "{v}");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lut");
    slotforge()
        .arg("lut")
        .arg(&missed)
        .args(["--search-limit", "2", "-o"])
        .arg(&out)
        .assert()
        .code(3)
        .stderr(predicate::str::starts_with("unknown: mix `missed`"));
    assert!(!out.exists(), "nothing written for an unknown mix");
    // the default bound finds its schedule; a bad limit is refused in words
    slotforge().arg("audit").arg(&missed).assert().code(0);
    refused(
        &[&"lut", &missed, &"--search-limit", &"many", &"-o", &out],
        &["--search-limit", "whole number"],
    );
}

#[test]
fn bad_input_names_file_line_and_field_and_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let p = write_mix(
        dir.path(),
        &SMALL.replace("rate_hz = 1_000", "rate_hz = 1_000\nrate = 5"),
    );
    refused(&[&"audit", &p], &["mix.toml:15:", "channel[0].rate"])
        .stderr(predicate::str::contains("panicked").not());
    let p = write_mix(
        dir.path(),
        &SMALL.replace("branch = \"a\"\nrate_hz", "branch = \"nope\"\nrate_hz"),
    );
    refused(&[&"audit", &p], &["unknown branch `nope`"]);
    refused(
        &[&"audit", &dir.path().join("missing.toml")],
        &["cannot read"],
    );
}

/// Words of Rust's types and serde's phrasing, which a user of the mix
/// format never wrote and should never read.
fn rust_words(line: &str) -> Vec<String> {
    const WORDS: [&str; 20] = [
        "i8", "i16", "i32", "i64", "u8", "u16", "u32", "u64", "usize", "f32", "f64", "Option",
        "Some", "None", "String", "Vec", "struct", "enum", "PathBuf", "sequence",
    ];
    const PHRASES: [&str; 5] = [
        "invalid type",
        "{:?}",
        "got string",
        "got integer",
        "target type",
    ];
    let mut found: Vec<String> = line
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .filter(|w| WORDS.contains(w))
        .map(String::from)
        .collect();
    found.extend(
        PHRASES
            .iter()
            .filter(|p| line.contains(*p))
            .map(|p| p.to_string()),
    );
    found
}

#[test]
fn wrong_toml_types_are_told_in_the_mix_formats_words() {
    let dir = tempfile::tempdir().unwrap();
    // (what SMALL has, what a user wrote instead, the field the message must name)
    let cases = [
        ("hz = 48_000_000", "hz = \"fast\"", "clock.hz"),
        ("hz = 48_000_000", "hz = 4.8e7", "clock.hz"),
        ("rate_hz = 1_000", "rate_hz = [1000]", "channel[0].rate_hz"),
        (
            "rate_hz = 1_000",
            "rate_hz = { hz = 1 }",
            "channel[0].rate_hz",
        ),
        (
            "rate_hz = 1_000",
            "rate_hz = 99999999999999999999",
            "channel[0].rate_hz",
        ),
        (
            "rate_hz = 1_000",
            "rate_hz = 1_000\nbandwidth_hz = \"2\"",
            "bandwidth_hz",
        ),
        (
            "rate_hz = 1_000",
            "rate_hz = 1_000\nbandwidth_hz = [2]",
            "bandwidth_hz",
        ),
        ("adc = \"ad7940\"", "adc = 7940", "branch[0].adc"),
        ("adc = \"ad7940\"", "adc = true", "branch[0].adc"),
        ("name = \"x\"", "name = { a = 1 }", "channel[0].name"),
        ("[clock]", "[[clock]]", "clock"),
        (
            "[[branch]]\nname = \"a\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n",
            "branch = 3\n",
            "branch",
        ),
        ("[frame]", "[frame.x]", "frame"),
    ];
    for (was, now, field) in cases {
        assert!(SMALL.contains(was), "{was}");
        let p = write_mix(dir.path(), &SMALL.replacen(was, now, 1));
        let out = slotforge().arg("audit").arg(&p).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{now}");
        let text = String::from_utf8_lossy(&out.stderr).to_string()
            + &String::from_utf8_lossy(&out.stdout);
        assert!(
            text.contains(field),
            "{now}: the message names {field}: {text}"
        );
        for line in text.lines() {
            let bad = rust_words(line);
            assert!(bad.is_empty(), "{now}: {bad:?} in the message: {line}");
        }
    }
}

/// Numeric options refused in the user's words too (clap's own parser
/// speaks of "digits found in string" and "target type").
#[test]
fn bad_numeric_options_are_told_in_plain_words() {
    let mix = preset("eskin34.toml");
    for args in [
        vec!["sim", "--frames", "abc"],
        vec!["sim", "--frames", "99999999999999999999999"],
        vec!["faults", "--false-alarm-mixes", "1.5"],
        vec!["prove", "--depth", "x"],
        vec!["sim", "--to", "3 parsecs"],
    ] {
        let out = slotforge()
            .args(&args[..1])
            .arg(&mix)
            .args(&args[1..])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let text = String::from_utf8_lossy(&out.stderr);
        assert!(text.contains(args[1]), "{args:?}: names the option: {text}");
        for line in text.lines() {
            let bad = rust_words(line);
            assert!(bad.is_empty(), "{args:?}: {bad:?} in the message: {line}");
            assert!(!line.contains("in string"), "{args:?}: {line}");
        }
    }
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

/// A mix with modes: one table per mode, each its mode's own schedule (a
/// channel's slots per frame are its rate in that mode), none named as
/// the mix alone.
#[test]
fn lut_writes_every_modes_table() {
    let mix = testkit::mix("modes-pin");
    let s = lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap();
    let names = s.mode_plan().unwrap().names.clone();
    let d = tempfile::tempdir().unwrap();
    slotforge()
        .arg("lut")
        .arg(&mix)
        .arg("-o")
        .arg(d.path())
        .assert()
        .success();
    assert!(!d.path().join("slots.hex").exists());
    for (m, name) in names.iter().enumerate() {
        let csv = std::fs::read_to_string(d.path().join(format!("slots-{name}.csv"))).unwrap();
        let md = std::fs::read_to_string(d.path().join(format!("slots-{name}.md"))).unwrap();
        assert!(
            md.starts_with(&format!("# Slot LUT: {} (mode {name})", s.mix.name)),
            "{md}"
        );
        let hex = std::fs::read_to_string(d.path().join(format!("slots-{name}.hex"))).unwrap();
        assert!(hex.contains(&format!("(mode {name})")));
        // every converting cell of the mode's table is one of its samples (no chains here)
        let cells: usize = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').skip(4).filter(|c| !c.is_empty()).count())
            .sum();
        let want: u64 = s.modes[m]
            .channels
            .iter()
            .map(|c| c.samples_per_frame)
            .sum();
        assert!(
            cells as u64 == want && want > 0,
            "mode {name}: {cells} cells, {want} samples"
        );
    }
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

/// `slotforge faults MIX --backend B --json` with the detectors in `off`
/// switched off (the test-only switch, judge/src/switch.rs): the JSON and
/// the exit code.
fn campaign(mix: &Path, backend: &str, off: &str) -> (serde_json::Value, i32) {
    let (v, code, _) = campaign_logged(mix, backend, off);
    (v, code)
}

/// [`campaign`] with its stderr (the progress lines: not a terminal).
fn campaign_logged(mix: &Path, backend: &str, off: &str) -> (serde_json::Value, i32, String) {
    let out = slotforge()
        .env(progress::STEP_ENV, progress::SLOW)
        .args([
            "faults",
            "--json",
            "--false-alarm-mixes",
            "0",
            "--backend",
            backend,
        ])
        .arg(mix)
        .env("SLOTFORGE_TEST_DISABLE_DETECTOR", off)
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    let log = String::from_utf8_lossy(&out.stderr).into_owned();
    (v, out.status.code().unwrap(), log)
}

/// Every injection no detector caught, as (fault, site): the undetected
/// and the proved-equivalent ones.
fn injections(v: &serde_json::Value) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for c in v["classes"].as_array().unwrap() {
        for list in ["undetected", "proved_equivalent"] {
            for i in c[list].as_array().unwrap() {
                out.push(key(i));
            }
        }
    }
    out
}

fn key(i: &serde_json::Value) -> (String, String) {
    (
        i["fault"].as_str().unwrap().to_string(),
        i["site"].as_str().unwrap().to_string(),
    )
}

/// The injections detector `d` catches, measured with every other
/// detector switched off: those missed with all off (`all_off`, that
/// campaign) but caught with `d` on.
fn caught_by_alone(
    mix: &Path,
    backend: &str,
    d: &str,
    all_off: &serde_json::Value,
) -> Vec<(String, String)> {
    let others: Vec<&str> = ["model", "invariants", "sigrok"]
        .into_iter()
        .filter(|x| *x != d)
        .collect();
    let (v, _) = campaign(mix, backend, &others.join(","));
    let with_d = injections(&v);
    injections(all_off)
        .into_iter()
        .filter(|k| !with_d.contains(k))
        .collect()
}

#[test]
fn faults_report_a_matrix_of_classes_and_detectors() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let (v, code, log) = campaign_logged(&tiny(), "model", "");
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["ok"], true);
    // off a terminal, the progress is a line every few seconds, with
    // counts of all the runs (every injection and the clean run)
    let total = progress::paced(&log, "fault campaign: ", " runs");
    assert!(total > v["injected"].as_f64().unwrap(), "{log}");
    assert!(!log.contains("Target") && !log.contains("Some("), "{log}");
    assert_eq!(
        v["detectors"],
        serde_json::json!(["model", "invariants", "sigrok", "prove"])
    );
    let prove = column(&v, "prove");
    assert!(
        prove["not_run"].as_str().unwrap().contains("not run"),
        "{prove}"
    );
    assert_eq!(prove["detected"], 0);
    let classes = v["classes"].as_array().unwrap();
    let class = |n: &str| {
        classes
            .iter()
            .find(|c| c["name"] == n)
            .unwrap_or_else(|| panic!("{n} missing: {v}"))
    };
    // the faults that keep a legal-looking timeline: the invariants alone
    // catch every one (docs/faults.md lists what they cannot catch)
    for n in [
        "conversion-moved",
        "phase-shift",
        "sclk-slow",
        "neighbour-code",
    ] {
        let c = class(n);
        assert!(c["injected"].as_u64().unwrap() >= 4, "{c}");
        assert_eq!(c["detected_by"]["invariants"], c["injected"], "{c}");
    }
    // sigrok has no view of the mux pins, and says so
    for n in ["mux-late", "wrong-mux", "two-mux-en"] {
        let c = class(n);
        assert!(
            c["cannot_see"]["sigrok"].as_str().unwrap().contains("mux"),
            "{c}"
        );
        assert_eq!(c["detected_by"]["sigrok"], 0, "{c}");
    }
    // sigrok sees what reaches the SPI pins
    assert_eq!(
        class("sclk-extra-edge")["detected_by"]["sigrok"],
        class("sclk-extra-edge")["injected"]
    );
    for c in classes {
        assert!(c["undetected"].as_array().unwrap().is_empty(), "{c}");
    }
    slotforge()
        .args(["faults", "--backend", "nope"])
        .arg(tiny())
        .assert()
        .code(2);
    without_the_invariants_their_column_drops_and_the_model_column_holds(&v);
}

/// The judge: with the invariant checks off (a test build's
/// switch) the invariants column drops to nothing while the model column
/// holds, and the campaign misses exactly the injections only the
/// invariants caught (none on the model target: the model sees every pin).
/// `full`: the campaign with every detector on (the test above's: one
/// campaign fewer).
fn without_the_invariants_their_column_drops_and_the_model_column_holds(full: &serde_json::Value) {
    let (off, code) = campaign(&tiny(), "model", "invariants");
    assert_eq!(column(&off, "invariants")["detected"], 0, "{off}");
    assert!(column(full, "invariants")["detected"].as_u64().unwrap() > 0);
    assert_eq!(
        column(&off, "model")["detected"],
        column(full, "model")["detected"]
    );
    assert_eq!(
        column(&off, "sigrok")["detected"],
        column(full, "sigrok")["detected"]
    );
    assert!(injections(&off).is_empty(), "{off}");
    assert_eq!(code, 0);
}

/// With the model comparison and the invariants both off, only sigrok is
/// left: the campaign must report as undetected exactly the injections
/// sigrok does not catch, exit 1, and list every one.  (Two campaigns:
/// long.)
#[test]
#[ignore = "long: make test-long"]
fn with_only_sigrok_left_the_misses_are_exactly_what_it_cannot_catch() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let (full, _) = campaign(&tiny(), "model", "");
    let (off, code) = campaign(&tiny(), "model", "model,invariants");
    assert_eq!(code, 1);
    assert_eq!(off["ok"], false);
    let missed: usize = full["classes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (c["injected"].as_u64().unwrap() - c["detected_by"]["sigrok"].as_u64().unwrap())
                as usize
        })
        .sum();
    assert!(missed > 0);
    assert_eq!(injections(&off).len(), missed, "{off}");
    for c in off["classes"].as_array().unwrap() {
        let sig = c["detected_by"]["sigrok"].as_u64().unwrap();
        assert_eq!(c["detected"].as_u64().unwrap(), sig, "{c}");
        assert_eq!(
            c["undetected"].as_array().unwrap().len() as u64,
            c["injected"].as_u64().unwrap() - sig,
            "{c}"
        );
    }
}

/// On the gateware: with every detector off, each design-level fault is
/// reported undetected (the equivalence check finds the difference), never
/// dropped; with one detector on, exactly the injections it alone catches
/// come back.  Long: several campaigns and an equivalence check per fault.
#[test]
#[ignore = "long: make test-long"]
fn gateware_faults_are_undetected_not_dropped_without_detectors() {
    if !tools::require_tools(&["sigrok-cli", "yosys", "yosys-abc"]) {
        return;
    }
    let (full, code) = campaign(&tiny(), "rusthdl", "");
    assert_eq!(code, 0, "{full}");
    let (none, code) = campaign(&tiny(), "rusthdl", "model,invariants,sigrok");
    assert_eq!(code, 1);
    for c in none["classes"].as_array().unwrap() {
        let n = c["undetected"].as_array().unwrap().len()
            + c["proved_equivalent"].as_array().unwrap().len();
        assert_eq!(n as u64, c["injected"].as_u64().unwrap(), "{c}");
        assert_eq!(
            c["injected"],
            full["classes"]
                .as_array()
                .unwrap()
                .iter()
                .find(|f| f["name"] == c["name"])
                .unwrap()["injected"]
        );
        if c["level"] == "gateware" {
            // refuted, or undecided within the time limit: never proved
            for i in c["undetected"].as_array().unwrap() {
                let v = i["equivalence"]["verdict"].as_str().unwrap();
                assert!(v == "differs" || v == "undecided", "{i}");
            }
        }
    }
    for d in ["model", "invariants", "sigrok"] {
        let alone = caught_by_alone(&tiny(), "rusthdl", d, &none);
        let n = column(&full, d)["detected"].as_u64().unwrap() as usize;
        assert_eq!(alone.len(), n, "{d}: {alone:?}");
    }
}

/// The reference design's full campaign: nothing undetected, the invariants
/// alone catch every legal-timeline fault.
#[test]
#[ignore = "long: make test-long"]
fn faults_on_the_reference_mix() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let (v, code) = campaign(&preset("eskin34.toml"), "model", "");
    assert_eq!(code, 0, "{v}");
    for c in v["classes"].as_array().unwrap() {
        assert!(c["undetected"].as_array().unwrap().is_empty(), "{c}");
        if [
            "conversion-moved",
            "phase-shift",
            "sclk-slow",
            "neighbour-code",
            "select-swap",
        ]
        .contains(&c["name"].as_str().unwrap())
        {
            assert_eq!(c["detected_by"]["invariants"], c["injected"], "{c}");
        }
    }
    let names = strings(&v["classes"], "name");
    assert!(names.contains(&"select-swap"), "{names:?}");
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

/// `formal`'s deep faults (a counter that misbehaves after the run's last
/// frame, a merger collision no stimulus drives) on both Verilog engines:
/// every simulation column misses them, so without `prove` they are
/// undetected and `faults` exits 1; with `--prove` the prove column
/// catches every one.  (Proofs and Verilator builds: long.)
#[test]
#[ignore = "long: make test-long"]
fn deep_faults_escape_every_simulation_column_and_prove_catches_them() {
    if !tools::require_tools(&["verilator", "iverilog", "yosys", "yosys-abc", "sigrok-cli"]) {
        return;
    }
    let mix = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("testkit/mixes/mutants.toml");
    let run = |prove: bool| {
        let mut cmd = slotforge();
        cmd.args([
            "faults",
            "--json",
            "--false-alarm-mixes",
            "0",
            "--engines",
            "verilator,icarus",
        ]);
        if prove {
            cmd.arg("--prove");
        }
        let out = cmd.arg(&mix).output().unwrap();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
        (v, out.status.code().unwrap())
    };
    let deep = |v: &serde_json::Value| -> Vec<serde_json::Value> {
        v["classes"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| c["level"] == "verilog")
            .cloned()
            .collect()
    };
    let (without, code) = run(false);
    assert_eq!(code, 1, "{without}");
    let classes = deep(&without);
    assert_eq!(classes.len(), 2, "{without}");
    for c in &classes {
        for d in ["model", "invariants", "sigrok"] {
            assert_eq!(c["detected_by"][d], 0, "{d}: {c}");
        }
        assert_eq!(
            c["undetected"].as_array().unwrap().len() as u64,
            c["injected"].as_u64().unwrap(),
            "{c}"
        );
    }
    let (with, code) = run(true);
    assert_eq!(code, 0, "{with}");
    for c in deep(&with) {
        assert_eq!(c["detected_by"]["prove"], c["injected"], "{c}");
        assert_eq!(c["detected_by"]["model"], 0, "{c}");
    }
    // pin faults: prove cannot see them, and says why
    let pins = with["classes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["level"] == "pins")
        .unwrap()
        .clone();
    assert!(pins["cannot_see"]["prove"]
        .as_str()
        .unwrap()
        .contains("simulation"));
}

/// A mix with modes is planned by `audit` and `lut` and built by `verilog`
/// (with its mode ports; `build` charts it, tests/build.rs).
#[test]
fn a_mix_with_modes_is_planned_and_built() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let d = tempfile::tempdir().unwrap();
    for name in ["modes-pin", "modes-auto"] {
        let mix = root.join("testkit/mixes").join(format!("{name}.toml"));
        slotforge().arg("audit").arg(&mix).assert().success();
        let out = d.path().join(name);
        // `golden`, `synth`, `prove`, `build` and `check --map` take it
        // (tests/modes_cli.rs, formal/tests, tests/build.rs, tests/mode_captures.rs)
        assert!(!out.join("slotforge_top.v").exists());
        slotforge()
            .args(["verilog", "-o"])
            .arg(&out)
            .arg(&mix)
            .assert()
            .success();
        let v = std::fs::read_to_string(out.join("slotforge_top.v")).unwrap();
        assert!(v.contains("output wire") && v.contains(" mode\n"), "{name}");
        assert_eq!(
            v.contains("input wire mode_sel"),
            name == "modes-pin",
            "{name}"
        );
    }
}

/// `sim` of the pin-select mix under `--modes 2=slow,7=fast`, 14 frames,
/// on `backend`: its JSON.
fn pin_modes_sim(backend: &str) -> serde_json::Value {
    let pin = Path::new(env!("CARGO_MANIFEST_DIR")).join("testkit/mixes/modes-pin.toml");
    let o = slotforge()
        .args(["sim", "--quiet", "--json", "--frames", "14"])
        .args(["--modes", "2=slow,7=fast", "--backend", backend])
        .arg(&pin)
        .assert()
        .success();
    serde_json::from_slice(&o.get_output().stdout).unwrap()
}

/// Icarus counts the pin-select mix's samples per channel as the model
/// does (`make test` replays the mix's golden scene on Icarus:
/// `modes_cli::golden_of_a_mode_mix_replays_its_scene_on_every_back_end`).
#[test]
#[ignore = "long: make test-long (14 frames on Icarus)"]
fn icarus_simulates_the_pin_mixs_mode_switches_as_the_model_does() {
    let model = pin_modes_sim("model");
    assert_eq!(
        pin_modes_sim("icarus")["channels"],
        model["channels"],
        "icarus"
    );
}

/// `sim --backend model` follows mode switches: `--modes` drives `mode_sel`
/// of a pin-select mix, `touch:` switches an auto mix; every frame is judged
/// against its mode; its VCD passes `check`.  A mode the mix does not have
/// is refused with the reason.  rust-hdl and Verilator count the pin mix's
/// samples as the model does (Icarus: the long twin above).
#[test]
fn the_model_back_end_simulates_mode_switches() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let pin = root.join("testkit/mixes/modes-pin.toml");
    let auto = root.join("testkit/mixes/modes-auto.toml");
    let d = tempfile::tempdir().unwrap();
    let sim = |mix: &Path, args: &[&str]| {
        slotforge()
            .args(["sim", "--quiet", "--json", "--frames", "14"])
            .args(args)
            .arg(mix)
            .assert()
    };
    let a = sim(&pin, &["--modes", "2=slow,7=fast"]).success();
    for backend in ["rusthdl", "verilator"] {
        assert_eq!(
            pin_modes_sim(backend)["channels"],
            serde_json::from_slice::<serde_json::Value>(&a.get_output().stdout).unwrap()
                ["channels"],
            "{backend}"
        );
    }
    let v: serde_json::Value = serde_json::from_slice(&a.get_output().stdout).unwrap();
    // frames 0-3 and 9-13 fast, 4-8 slow: A0 4 a frame in fast, 1 in slow,
    // less its instant at cycle 0 skipped at start-up; A2 only in fast
    let ch = |v: &serde_json::Value, n: &str| {
        let c = v["channels"].as_array().unwrap().iter();
        c.filter(|c| c["name"] == n)
            .map(|c| c["samples"].as_u64().unwrap())
            .sum::<u64>()
    };
    assert_eq!(ch(&v, "A0"), 9 * 4 + 5 - 1, "{v}");
    assert_eq!(ch(&v, "A2"), 9, "{v}");
    let a = sim(&auto, &["--stimulus", "touch:T{0..3}@3-9"]).success();
    let v: serde_json::Value = serde_json::from_slice(&a.get_output().stdout).unwrap();
    // 1 a frame at rest, 8 when touched
    assert!(ch(&v, "T1") > 14 + 7, "{v}");
    for (mix, args, why) in [
        (&pin, vec!["--modes", "2=warp"], "no mode `warp`"),
        (&pin, vec!["--modes", "two=slow"], "not a frame number"),
        (&auto, vec!["--modes", "2=touch"], "triggers"),
        (
            &auto,
            vec!["--stimulus", "touch:X@1-2"],
            "no channel named `X`",
        ),
    ] {
        sim(mix, &args)
            .code(2)
            .stderr(predicate::str::contains(why));
    }
    // the run's VCD carries mode_sel and mode: `check` judges it with and
    // without the model
    let vcd = d.path().join("w.vcd");
    sim(
        &pin,
        &["--modes", "2=slow,7=fast", "--vcd", vcd.to_str().unwrap()],
    )
    .success();
    for extra in [&[][..], &["--no-model"][..]] {
        slotforge()
            .args(["check", "--json"])
            .args(extra)
            .arg(&pin)
            .arg(&vcd)
            .assert()
            .success();
    }
}

/// `faults` on a mix with modes runs its switching scenario on the model
/// and counts the `mode` output's classes (the gateware's campaign:
/// tests/modes_cli.rs).
#[test]
fn faults_on_a_mode_mix_run_on_the_model_with_the_mode_classes() {
    let pin = Path::new(env!("CARGO_MANIFEST_DIR")).join("testkit/mixes/modes-pin.toml");
    let a = slotforge()
        .args([
            "faults",
            "--quiet",
            "--json",
            "--frames",
            "4",
            "--false-alarm-mixes",
            "0",
        ])
        .arg(&pin)
        .assert()
        .success();
    let v: serde_json::Value = serde_json::from_slice(&a.get_output().stdout).unwrap();
    let names = strings(&v["classes"], "name");
    for class in ["mode-early", "mode-stuck", "mode-unasked"] {
        assert!(names.contains(&class), "{names:?}");
    }
}

/// Converters with a command word on the judge's side: `sim --backend
/// model` of the shared commanded mix writes a VCD with `adc_mosi` that
/// `check` passes with and without the model; the same VCD with one
/// `adc_mosi` change inverted fails on that lane, the bit and word named
/// (and, without the model, as a sample held to another channel than its
/// word selected, or a word the part would not take).
#[test]
fn a_commanded_mix_is_simulated_on_the_model_and_checked() {
    let mix = Path::new(env!("CARGO_MANIFEST_DIR")).join("testkit/mixes/cmd-pair.toml");
    let d = tempfile::tempdir().unwrap();
    let vcd = d.path().join("w.vcd");
    sim_to_vcd(&mix, "model", "4", &[], &vcd);
    let check = |wave: &Path, extra: &[&str]| {
        slotforge()
            .args(["check", "--json"])
            .args(extra)
            .arg(&mix)
            .arg(wave)
            .assert()
    };
    for extra in [&[][..], &["--no-model"]] {
        let a = check(&vcd, extra).success();
        let v: serde_json::Value = serde_json::from_slice(&a.get_output().stdout).unwrap();
        assert!(v["samples"].as_u64().unwrap() > 50, "{v}");
    }
    // Invert the value of the 40th change of adc_mosi (a whole run of cycles).
    let text = std::fs::read_to_string(&vcd).unwrap();
    let id = text
        .lines()
        .find(|l| l.contains(" adc_mosi [1:0]"))
        .and_then(|l| l.split_whitespace().nth(3))
        .unwrap()
        .to_string();
    let mut n = 0;
    let bad: Vec<String> = text
        .lines()
        .map(|l| {
            match l
                .strip_prefix('b')
                .and_then(|r| r.strip_suffix(&format!(" {id}")))
            {
                Some(bits) if n < 40 => {
                    n += 1;
                    if n == 40 {
                        let v = u8::from_str_radix(bits, 2).unwrap() ^ 0b10;
                        return format!("b{v:b} {id}");
                    }
                    l.to_string()
                }
                _ => l.to_string(),
            }
        })
        .collect();
    assert_eq!(n, 40);
    let flipped = d.path().join("bad.vcd");
    std::fs::write(&flipped, bad.join("\n") + "\n").unwrap();
    let a = check(&flipped, &[]).code(1);
    let v: serde_json::Value = serde_json::from_slice(&a.get_output().stdout).unwrap();
    let dv = &v["divergences"][0];
    assert_eq!(dv["signal"], "adc_mosi[1]", "{v}");
    assert!(
        dv["context"][0].as_str().unwrap().contains("command word"),
        "{v}"
    );
    let a = check(&flipped, &["--no-model"]).code(1);
    let v: serde_json::Value = serde_json::from_slice(&a.get_output().stdout).unwrap();
    let rules = strings(&v["violations"], "rule");
    assert!(rules.iter().any(|r| r.starts_with("command-")), "{rules:?}");
}

/// A pin-select run's VCD (Verilator, the whole run) carries `mode_sel` and
/// `mode`: `check` passes it with and without the model, and fails it with
/// one request taken out of the file (the switch it asked for is then
/// unasked), at that frame's start.
#[test]
fn a_vcd_with_mode_switches_passes_check_and_fails_with_a_request_removed() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let pin = root.join("testkit/mixes/modes-pin.toml");
    let d = tempfile::tempdir().unwrap();
    let vcd = d.path().join("w.vcd");
    let modes = ["--modes", "2=slow,6=fast,7=slow,8=fast"];
    sim_to_vcd(&pin, "verilator", "12", &modes, &vcd);
    let check = |file: &Path, extra: &[&str]| {
        slotforge()
            .arg("check")
            .arg(&pin)
            .arg(file)
            .args(extra)
            .assert()
    };
    check(&vcd, &[]).success();
    check(&vcd, &["--no-model"]).success();
    // `mode_sel`'s id code: its `$var` line
    let text = std::fs::read_to_string(&vcd).unwrap();
    let id = text
        .lines()
        .find(|l| l.ends_with(" mode_sel $end"))
        .and_then(|l| l.split_whitespace().nth(3))
        .unwrap()
        .to_string();
    let rise = format!("1{id}");
    let mut lines: Vec<&str> = text.lines().collect();
    let at = lines.iter().position(|l| *l == rise).unwrap();
    lines.remove(at);
    let bad = d.path().join("bad.vcd");
    std::fs::write(&bad, lines.join("\n") + "\n").unwrap();
    check(&bad, &[])
        .code(1)
        .stdout(predicate::str::contains("cycle 16000"));
    check(&bad, &["--no-model"])
        .code(1)
        .stdout(predicate::str::contains("mode-decision"));
}

/// An external mux in front of the AD7689's own (`testkit` mix
/// `cmd-front`): the Verilator run's VCD passes `check` with and without the
/// model; the emitted Verilog with the front select's bit 0 inverted fails
/// with the model at cycle 0 on `mux_sel` (the reset value is already
/// wrong), and without it at the first fronted conversion it moves onto
/// another channel's front input: the sample claims the schedule's channel,
/// the word and the front pins at the instant selected the other one.
#[test]
fn a_fronted_mix_passes_check_and_a_wrong_front_select_fails_at_its_cycle() {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let mix = Path::new(env!("CARGO_MANIFEST_DIR")).join("testkit/mixes/cmd-front.toml");
    let s = lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap();
    let d = tempfile::tempdir().unwrap();
    let run = |rtl: Option<&Path>, vcd: &Path| {
        let mut c = slotforge();
        c.args([
            "sim",
            "--quiet",
            "--backend",
            "verilator",
            "--frames",
            "2",
            "--vcd",
        ])
        .arg(vcd);
        if let Some(r) = rtl {
            c.arg("--rtl").arg(r);
        }
        c.arg(&mix).assert()
    };
    let check = |wave: &Path, extra: &[&str]| {
        let a = slotforge()
            .args(["check", "--json"])
            .args(extra)
            .arg(&mix)
            .arg(wave)
            .assert();
        let out = a.get_output().stdout.clone();
        (
            a,
            serde_json::from_slice::<serde_json::Value>(&out).unwrap(),
        )
    };
    let good = d.path().join("good.vcd");
    run(None, &good).success();
    for extra in [&[][..], &["--no-model"]] {
        let (a, v) = check(&good, extra);
        a.success();
        assert!(v["samples"].as_u64().unwrap() > 20, "{v}");
    }
    let out = d.path().join("v");
    slotforge()
        .arg("verilog")
        .arg(&mix)
        .arg("-o")
        .arg(&out)
        .assert()
        .success();
    let text = std::fs::read_to_string(out.join("slotforge_top.v")).unwrap();
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("assign mux_sel = core_mux_sel["))
        .unwrap();
    let bad_rtl = d.path().join("bad.v");
    std::fs::write(
        &bad_rtl,
        text.replacen(line, &line.replace(";", " ^ 6'd1;"), 1),
    )
    .unwrap();
    let bad = d.path().join("bad.vcd");
    run(Some(&bad_rtl), &bad).code(1);
    let (a, v) = check(&bad, &[]);
    a.code(1);
    assert_eq!(v["divergences"][0]["cycle"], 0, "{v}");
    assert!(
        v["divergences"][0]["signal"]
            .as_str()
            .unwrap()
            .starts_with("mux_sel"),
        "{v}"
    );
    let (a, v) = check(&bad, &["--no-model"]);
    a.code(1);
    let first = &v["violations"][0];
    assert_eq!(first["rule"], "command-channel", "{v}");
    // The schedule's first data conversion of branch cfg (0; past an
    // instant at cycle 0 the mux cannot have settled for, and the prepared
    // ones) whose front input with bit 0 inverted is another channel's on
    // the same converter input.
    let g = &s.grid;
    let m = &s.mix;
    let convs = (0..g.frame_slots).filter_map(|u| s.at(u, 0).map(|c| (u, c)));
    let skipped = (s.at(0, 0).is_some() && s.branches[0].settle_cycles > 1) as usize;
    let mut data = convs.skip(skipped + s.prepared_conversions(0) as usize);
    let moved = data.find_map(|(u, c)| {
        let f = m.channels[c].front_input? ^ 1;
        let on = |o: &lut_gen::Channel| o.input == m.channels[c].input && o.front_input == Some(f);
        Some((u * g.slot_cycles, m.channels.iter().position(on)?))
    });
    let (instant, other) = moved.unwrap();
    let cycle = first["cycle"].as_u64().unwrap();
    assert!(
        cycle > instant && cycle < instant + g.slot_cycles,
        "{first} vs instant {instant}"
    );
    assert_eq!(first["channel"], m.channels[other].name.as_str(), "{first}");
}
