//! The Verilator build/cache/FFI path, on a stand-in module with the ports of
//! `slotforge_top` for the tiny mix (it only holds its reset values, so the
//! checker must report divergences).

use std::path::Path;

use engines::VerilatedDut;
use judge::{run_dut, RunOptions};

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::tools;

const STANDIN: &str = r#"
module slotforge_top(input clk, input rst, input [1:0] adc_miso,
  output reg [1:0] adc_cs_n, output reg [1:0] adc_sclk, output reg [5:0] mux_sel,
  output reg [2:0] mux_en, output reg sample_valid, output reg [2:0] sample_channel,
  output reg [13:0] sample_value);
  reg [15:0] n;
  always @(posedge clk) begin
    adc_cs_n <= 2'b11; adc_sclk <= 2'b11; mux_sel <= 6'd0; mux_en <= 3'b101;
    sample_valid <= 1'b0; sample_channel <= 3'd0; sample_value <= {12'd0, adc_miso};
    n <= rst ? 16'd0 : n + 16'd1;
  end
endmodule
"#;

#[test]
fn standin_builds_loads_caches_and_is_checked() {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let cache = tempfile::tempdir().unwrap();
    std::env::set_var("SLOTFORGE_CACHE", cache.path());
    let s = lut_gen::synthesize(
        &lut_gen::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/tiny.toml"),
        )
        .unwrap(),
    )
    .unwrap();
    let (mut dut, built) = VerilatedDut::new(STANDIN).unwrap();
    assert!(!built.cached);
    let r = run_dut(&s, &mut dut, 1, &RunOptions::default(), "verilator", None);
    assert!(!r.ok);
    // branch 0's first conversion after reset (docs/timing.md, "Start-up")
    let t0 = s
        .branch_instants_in_frame(0)
        .iter()
        .map(|i| i.cycle)
        .find(|&t| !s.skipped_at_startup(0, t))
        .unwrap();
    assert!(
        r.divergences
            .iter()
            .any(|d| d.signal == "adc_cs_n[0]" && d.cycle == t0),
        "{}",
        r.summary()
    );
    drop(dut);
    let (_, again) = VerilatedDut::new(STANDIN).unwrap();
    assert!(again.cached);
    assert_eq!(again.key, built.key);
}

/// Two builds of one model at once (parallel tests on an empty cache)
/// verilate and compile it once: the second waits for the first and loads
/// its library. `verilator` is a wrapper on PATH that logs each run.
#[test]
fn concurrent_builds_of_one_model_verilate_it_once() {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let cache = tempfile::tempdir().unwrap();
    let (_bin, log) =
        wrapped_first_on_path("verilator", "echo \"$*\" >> '{log}'\nexec '{real}' \"$@\"");
    std::env::set_var("SLOTFORGE_CACHE", cache.path());
    let keys: Vec<(String, bool)> = std::thread::scope(|s| {
        let h: Vec<_> = (0..2)
            .map(|_| s.spawn(|| VerilatedDut::new(STANDIN).unwrap().1))
            .collect();
        h.into_iter()
            .map(|h| h.join().unwrap())
            .map(|b| (b.key, b.cached))
            .collect()
    });
    assert_eq!(keys[0].0, keys[1].0);
    assert_eq!(keys.iter().filter(|(_, cached)| !cached).count(), 1);
    let runs = std::fs::read_to_string(&log).unwrap();
    let verilated = runs.lines().filter(|l| l.contains("--cc")).count();
    assert_eq!(verilated, 1, "verilator runs:\n{runs}");
}

/// A model's C++ files read `verilated.h` precompiled (the `.gch` built
/// once beside Verilator's runtime in the cache), not parsed again: `g++`
/// is a wrapper on PATH that adds `-H`, which prints `! FILE.gch` for a
/// precompiled header used.
#[test]
fn a_models_files_read_verilated_h_precompiled() {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let cache = tempfile::tempdir().unwrap();
    let (_bin, log) = wrapped_first_on_path("g++", "exec '{real}' -H \"$@\" 2>>'{log}'");
    std::env::set_var("SLOTFORGE_CACHE", cache.path());
    let (_, built) = VerilatedDut::new(STANDIN).unwrap();
    assert!(!built.cached);
    let includes = std::fs::read_to_string(&log).unwrap();
    let used = includes
        .lines()
        .filter(|l| l.starts_with("! ") && l.ends_with("slotforge_pch.h.gch"))
        .count();
    // the model's file and the shim
    assert_eq!(used, 2, "g++ -H:\n{includes}");
}

/// Puts a shell wrapper of `tool` first on this process's PATH: `body`
/// with `{real}` the tool it wraps and `{log}` a file beside it. Returns
/// the wrapper's directory (kept while the test runs) and the log's path.
fn wrapped_first_on_path(tool: &str, body: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let bin = tempfile::tempdir().unwrap();
    let log = bin.path().join(format!("{tool}.log"));
    let real = std::env::split_paths(&std::env::var_os("PATH").unwrap())
        .map(|d| d.join(tool))
        .find(|p| p.is_file())
        .unwrap();
    let wrapper = bin.path().join(tool);
    let body = body
        .replace("{real}", &real.display().to_string())
        .replace("{log}", &log.display().to_string());
    std::fs::write(&wrapper, format!("#!/bin/sh\n{body}\n")).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&wrapper, std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = std::env::join_paths(
        std::iter::once(bin.path().to_path_buf())
            .chain(std::env::split_paths(&std::env::var_os("PATH").unwrap())),
    )
    .unwrap();
    std::env::set_var("PATH", path);
    (bin, log)
}
