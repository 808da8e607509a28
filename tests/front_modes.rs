//! A converter with a command word behind a front mux in a mix with modes
//! (testkit mixes `front-modes`, pin select, and `front-modes-auto`, auto
//! select watching F0, a fronted channel): an AD7689 behind two TMUX1108s
//! on its input 3 beside straight inputs, whose fronted and straight
//! channels change rates between modes, so each mode has its own front
//! pins and words and a frame's last words select the next frame's
//! conversions in the next frame's mode.  Every engine passes the model
//! under a switching scene, the Verilator waveform passes `check` with and
//! without the model, and a gateware whose front select is wrong in one
//! mode only fails from that mode's first frame (`prove` of both:
//! formal/tests/prove.rs).

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::common_cli::{root, slotforge};
use crate::tools;

fn shared(name: &str) -> PathBuf {
    root().join("testkit/mixes").join(format!("{name}.toml"))
}

/// The scene that switches the mix to `busy` (from frame 3 on) and back.
fn scene(name: &str) -> [&'static str; 2] {
    match name {
        "front-modes" => ["--modes", "1=busy,4=idle"],
        _ => ["--stimulus", "touch:F0@1-3"],
    }
}

/// Frames 3 to 5 run `busy` under either scene.
const FRAMES: &str = "6";

fn json(out: &std::process::Output) -> Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// `sim` of `mix` on `backend` under its scene, with `extra` arguments.
fn sim(mix: &Path, backend: &str, extra: &[&dyn AsRef<std::ffi::OsStr>]) -> std::process::Output {
    let name = mix.file_stem().unwrap().to_str().unwrap().to_string();
    slotforge()
        .args([
            "sim",
            "--quiet",
            "--json",
            "--frames",
            FRAMES,
            "--backend",
            backend,
        ])
        .args(scene(&name))
        .args(extra.iter().map(|a| a.as_ref()))
        .arg(mix)
        .output()
        .unwrap()
}

/// The samples a channel took in a mode, from `sim --json`.
fn samples_in(v: &Value, channel: &str, mode: &str) -> u64 {
    let ch = v["channels"].as_array().unwrap().iter();
    let ch = ch.into_iter().find(|c| c["name"] == channel).unwrap();
    let m = ch["modes"].as_array().unwrap().iter();
    m.into_iter()
        .find(|m| m["mode"] == mode)
        .map_or(0, |m| m["samples"].as_u64().unwrap())
}

/// A `sim --json` run of `name` on `backend` passed and its scene
/// switched: G12 (front input 12, device 1) is busy's alone, and the rates
/// of F0 (fronted) and C0 (straight) change.
fn assert_switched(name: &str, backend: &str, out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{name} {backend}: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    let v = json(out);
    assert!(samples_in(&v, "G12", "busy") > 0, "{name} {backend}: {v}");
    assert_eq!(samples_in(&v, "G12", "idle"), 0, "{name} {backend}");
    assert!(samples_in(&v, "C0", "idle") > 0, "{name} {backend}");
}

/// Icarus under the pin mix's 6-frame scene (three busy frames in a row):
/// its part models are the other engines' (`make test` runs those).
#[test]
#[ignore = "long: make test-long (Icarus, 6 frames: 40 s of CPU)"]
fn icarus_runs_the_pin_mixs_six_frame_scene() {
    if !tools::require_tools(&["iverilog", "vvp"]) {
        return;
    }
    let out = sim(&shared("front-modes"), "icarus", &[]);
    assert_switched("front-modes", "icarus", &out);
}

/// Every in-process engine, and Verilator in the run whose waveform
/// `check` then passes with and without the model (one Verilator run a
/// mix); Icarus is `make test-long`'s (the slowest engine, 7 s a frame).
#[test]
fn a_fronted_converter_switches_modes_on_every_engine_and_its_waveform_passes_check() {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    for name in ["front-modes", "front-modes-auto"] {
        let mix = shared(name);
        for backend in ["model", "rusthdl"] {
            assert_switched(name, backend, &sim(&mix, backend, &[]));
        }
        let vcd = d.path().join(format!("{name}.vcd"));
        let out = sim(&mix, "verilator", &[&"--to", &FRAMES, &"--vcd", &vcd]);
        assert_switched(name, "verilator", &out);
        for extra in [&[][..], &["--no-model"]] {
            let o = slotforge()
                .args(["check", "--quiet"])
                .args(extra)
                .arg(&mix)
                .arg(&vcd)
                .output()
                .unwrap();
            assert!(
                o.status.success(),
                "{name} check {extra:?}: {}",
                String::from_utf8_lossy(&o.stdout)
            );
        }
    }
}

/// The emitted Verilog of `front-modes` with the front select's bit 0
/// inverted while `mode` shows busy (mode 1) only: the run under the
/// scene fails; `check` finds `mux_sel` diverging first in frame 3, the
/// scene's first busy frame (the idle frames before it are right), and
/// `--no-model` finds it too (a fronted conversion converts another
/// front input than its word's channel's, or none).  With a frame's last
/// words taken from the mode in force, not the next frame's, the words
/// diverge in the idle frame before the switch.
#[test]
fn a_front_select_wrong_in_one_mode_only_fails_check_in_that_modes_first_frame() {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let mix = shared("front-modes");
    let s = lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap();
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("v");
    let o = slotforge()
        .arg("verilog")
        .arg(&mix)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success());
    let text = std::fs::read_to_string(out.join("slotforge_top.v")).unwrap();
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("assign mux_sel = core_mux_sel["))
        .unwrap();
    let bad_rtl = d.path().join("bad.v");
    let bad_line = line.replace(';', " ^ {5'd0, mode};");
    std::fs::write(&bad_rtl, text.replacen(line, &bad_line, 1)).unwrap();
    let vcd = d.path().join("bad.vcd");
    let run = sim(
        &mix,
        "verilator",
        &[&"--rtl", &bad_rtl, &"--to", &FRAMES, &"--vcd", &vcd],
    );
    assert_eq!(
        run.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&run.stdout)
    );
    let check = |extra: &[&str]| {
        let o = slotforge()
            .args(["check", "--json"])
            .args(extra)
            .arg(&mix)
            .arg(&vcd)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{extra:?}");
        json(&o)
    };
    let v = check(&[]);
    let first = &v["divergences"][0];
    let f = s.grid.frame_cycles;
    let cycle = first["cycle"].as_u64().unwrap();
    assert!(
        (3 * f..4 * f).contains(&cycle),
        "{first}: frame 3 is [{}, {})",
        3 * f,
        4 * f
    );
    assert!(
        first["signal"].as_str().unwrap().starts_with("mux_sel"),
        "{first}"
    );
    let v = check(&["--no-model"]);
    let bad = v["violations"].as_array().unwrap();
    assert!(!bad.is_empty(), "{v}");
    let cycle = bad[0]["cycle"].as_u64().unwrap();
    assert!(cycle >= 3 * f, "{}: before the first busy frame", bad[0]);
    // a frame's last words from the mode in force, not the next frame's:
    // the idle frame before the switch sends idle's words for busy's first
    // conversions, so `adc_mosi` diverges in frame 2, before any busy frame
    let stale_rtl = d.path().join("stale.v");
    let from = "nxm = nxt_0[0:0];";
    assert_eq!(text.matches(from).count(), 1);
    std::fs::write(&stale_rtl, text.replacen(from, "nxm = cur;", 1)).unwrap();
    let run = sim(
        &mix,
        "verilator",
        &[&"--rtl", &stale_rtl, &"--to", &FRAMES, &"--vcd", &vcd],
    );
    assert_eq!(run.status.code(), Some(1));
    let v = check(&[]);
    let first = &v["divergences"][0];
    let cycle = first["cycle"].as_u64().unwrap();
    assert!(
        (2 * f..3 * f).contains(&cycle),
        "{first}: frame 2 is [{}, {})",
        2 * f,
        3 * f
    );
    assert!(
        first["signal"].as_str().unwrap().starts_with("adc_mosi"),
        "{first}"
    );
    check(&["--no-model"]);
}
