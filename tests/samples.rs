//! `slotforge sim --stimulus sine:HZ --samples F.csv`: the CSV has the
//! documented header and one row per sample of the run, and a tone above a channel's
//! Nyquist frequency shows in its samples at the aliased frequency; every
//! back end writes the same samples.

use std::collections::BTreeMap;
use std::path::Path;

use predicates::prelude::*;

use crate::common_cli::{root, slotforge};
use crate::tools;

/// Runs `sim --json ... --samples`; returns the report and the CSV text.
fn sim_samples(
    mix: &Path,
    backend: &str,
    frames: u64,
    stimulus: &str,
    dir: &Path,
) -> (serde_json::Value, String) {
    let csv = dir.join(format!("{backend}.csv"));
    let out = slotforge()
        .arg("sim")
        .arg(mix)
        .args(["--backend", backend, "--frames", &frames.to_string()])
        .args(["--stimulus", stimulus, "--json", "--samples"])
        .arg(&csv)
        .assert()
        .success();
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    (v, std::fs::read_to_string(&csv).unwrap())
}

/// Per channel: (cycle, sampled_s, value) in row order.
fn by_channel(csv: &str) -> BTreeMap<String, Vec<(u64, f64, f64)>> {
    let mut m: BTreeMap<String, Vec<(u64, f64, f64)>> = BTreeMap::new();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 4, "{line}");
        m.entry(f[2].to_string()).or_default().push((
            f[0].parse().unwrap(),
            f[1].parse().unwrap(),
            f[3].parse().unwrap(),
        ));
    }
    m
}

/// The frequency (1 Hz steps, 0..=fs/2) of the largest DFT magnitude of
/// the samples' deviation from their mean, with their own times.
fn dominant_hz(x: &[(u64, f64, f64)], fs: u64) -> u64 {
    let mean = x.iter().map(|s| s.2).sum::<f64>() / x.len() as f64;
    let power = |f: u64| {
        let w = 2.0 * std::f64::consts::PI * f as f64;
        let (re, im) = x.iter().fold((0.0, 0.0), |(re, im), &(_, t, v)| {
            (
                re + (v - mean) * (w * t).cos(),
                im - (v - mean) * (w * t).sin(),
            )
        });
        re * re + im * im
    };
    (1..=fs / 2)
        .max_by(|&a, &b| power(a).total_cmp(&power(b)))
        .unwrap()
}

/// Ten frames of eskin34 under a 600 Hz sine on the cycle-level model:
/// the CSV, its strobes and instants, and the alias.  Every back end
/// writes the model's samples (`every_back_end_writes_the_same_samples`,
/// on the tiny mix); the gateware's 4.8 million cycles here in rust-hdl
/// (8 s of CPU, the model's 0.3 s) are `make test-long`'s, which holds
/// its CSV to the model's.
#[test]
fn a_600_hz_sine_aliases_in_the_samples() {
    aliases_in_the_samples_of("model");
}

#[test]
#[ignore = "long: make test-long (the same on rust-hdl's gateware, its CSV the model's)"]
fn a_600_hz_sine_aliases_in_the_samples_of_the_gateware() {
    let model = aliases_in_the_samples_of("model");
    assert_eq!(aliases_in_the_samples_of("rusthdl"), model);
}

/// `sim --backend BACKEND` of eskin34 under `sine:600` for ten frames: its
/// samples CSV, after every check of its rows.
fn aliases_in_the_samples_of(backend: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let (v, csv) = sim_samples(
        &root().join("mixes/eskin34.toml"),
        backend,
        10,
        "sine:600",
        dir.path(),
    );
    assert_eq!(v["ok"], true);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "cycle,sampled_s,channel,value");
    // one row per sample of the run: 349 per frame, less the three instants
    // at cycle 0 (CH1, CH26, CH35: slot 0 of each branch) that the gateware
    // skips at start-up because their mux has not settled
    assert_eq!(v["samples"], 3490 - 3);
    assert_eq!(lines.len() - 1, 3490 - 3);
    let ch = by_channel(&csv);
    for (name, rate) in [("CH1", 1000u64), ("CH35", 2000), ("CH26", 100)] {
        let x = &ch[name];
        assert_eq!(
            x.len() as u64,
            rate / 10 - 1,
            "{name}: 10 frames of 10 ms, less the start-up skip"
        );
        // The row's cycle is the sample_valid strobe: a fixed latency after
        // the sampling instant plus 0..=2 cycles of waiting behind lower
        // branches' samples (one sample leaves per cycle), so strobes are
        // the exact interval apart within 2 cycles; sampled_s is the
        // instant itself, the exact interval apart, before the strobe by the
        // AD7940's read (321 cycles at 48 MHz), one cycle and the wait.
        for w in x.windows(2) {
            assert!(
                (w[1].0 - w[0].0).abs_diff(48_000_000 / rate) <= 2,
                "{name}: {w:?}"
            );
            let dt = (w[1].1 - w[0].1) * rate as f64;
            assert!((dt - 1.0).abs() < 1e-9, "{name}: {w:?}");
        }
        for s in x {
            let lag = s.0 as f64 - s.1 * 48e6;
            assert!(
                (322.0 - 1e-3..=324.0 + 1e-3).contains(&lag),
                "{name}: {s:?}"
            );
        }
    }
    // 600 Hz sampled at 1 kHz shows as 400 Hz; at 2 kHz it is below Nyquist.
    assert_eq!(dominant_hz(&ch["CH1"], 1000), 400);
    assert_eq!(dominant_hz(&ch["HUM"], 1000), 400);
    assert_eq!(dominant_hz(&ch["CH35"], 2000), 600);
    assert_eq!(dominant_hz(&ch["CH36"], 2000), 600);
    csv
}

#[test]
fn every_back_end_writes_the_same_samples() {
    let dir = tempfile::tempdir().unwrap();
    let tiny = root().join("testkit/mixes/tiny.toml");
    let (v, reference) = sim_samples(&tiny, "rusthdl", 3, "sine:1.5e3", dir.path());
    assert_eq!(
        lines_of(&reference),
        1 + v["samples"].as_u64().unwrap() as usize
    );
    let (_, model) = sim_samples(&tiny, "model", 3, "sine:1.5e3", dir.path());
    assert_eq!(model, reference, "model (cycle level) vs rusthdl");
    if tools::require_tool("verilator") {
        let (_, verilated) = sim_samples(&tiny, "verilator", 3, "sine:1.5e3", dir.path());
        assert_eq!(verilated, reference, "verilator vs rusthdl");
    }
    if tools::require_tool("iverilog") {
        // Icarus's ADC codes come from a table computed by the judge's model.
        let (_, icarus) = sim_samples(&tiny, "icarus", 3, "sine:1.5e3", dir.path());
        assert_eq!(icarus, reference, "icarus vs rusthdl");
    }
}

fn lines_of(s: &str) -> usize {
    s.lines().count()
}

#[test]
fn bad_stimulus_and_samples_paths_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let tiny = root().join("testkit/mixes/tiny.toml");
    for (stim, msg) in [
        ("sine:", "is not a frequency"),
        ("sine:abc", "is not a frequency"),
        ("sine:0", "positive"),
        ("sine:-5", "positive"),
        ("sine:inf", "positive"),
        ("square", "unknown stimulus"),
    ] {
        slotforge()
            .arg("sim")
            .arg(&tiny)
            .args(["--stimulus", stim])
            .assert()
            .code(2)
            .stderr(predicate::str::contains(msg))
            .stderr(predicate::str::contains("panicked").not());
    }
    // The mix itself, a directory, the run's own VCD: refused, untouched.
    let before = std::fs::read_to_string(&tiny).unwrap();
    for target in [tiny.clone(), dir.path().to_path_buf()] {
        slotforge()
            .arg("sim")
            .arg(&tiny)
            .arg("--samples")
            .arg(&target)
            .assert()
            .code(2);
    }
    let vcd = dir.path().join("w.vcd");
    slotforge()
        .arg("sim")
        .arg(&tiny)
        .args(["--backend", "rusthdl", "--vcd"])
        .arg(&vcd)
        .arg("--samples")
        .arg(&vcd)
        .assert()
        .code(2);
    assert_eq!(std::fs::read_to_string(&tiny).unwrap(), before);
    // A missing directory: exit 2 and no stray temporary file.
    slotforge()
        .arg("sim")
        .arg(&tiny)
        .arg("--samples")
        .arg(dir.path().join("no/such/dir/s.csv"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--samples"));
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}
