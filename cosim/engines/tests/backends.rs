//! Every preset mix on every back end: verilator for 2 frames, model for 100, rusthdl for 2 (three presets here, the five others in `make test-long`).

use std::path::{Path, PathBuf};

use engines::{run, Backend, SimOptions};

use testkit::presets as common_presets;

fn mixes() -> Vec<PathBuf> {
    common_presets::presets(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
}

fn schedule(p: &Path) -> lut_gen::Schedule {
    lut_gen::synthesize(&lut_gen::load(p).unwrap()).unwrap()
}

/// The samples of `frames` whole frames from reset. A mix with modes (the
/// adaptive preset) switches under the stimulus: the verdict holds each
/// frame to its mode's counts (`ok`), and the total lies between `frames`
/// of its leanest mode and of its fullest.
fn assert_whole(s: &lut_gen::Schedule, samples: u64, frames: u64) {
    if s.modes.len() > 1 {
        let per = s.modes.iter().map(|m| m.samples_per_frame());
        let (lo, hi) = (per.clone().min().unwrap(), per.max().unwrap());
        let within = frames * lo - s.startup_skips()..=frames * hi;
        assert!(within.contains(&samples), "{}: {samples}", s.mix.name);
        return;
    }
    assert_eq!(samples, frames * s.samples_per_frame() - s.startup_skips());
}

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::tools;

/// The gateware is correct for any reset of one cycle or more (docs/timing.md, "Start-up").
fn one_cycle_reset() -> SimOptions {
    SimOptions {
        reset_cycles: 1,
        ..SimOptions::default()
    }
}

#[test]
fn model_backend_100_frames() {
    for p in mixes() {
        let s = schedule(&p);
        let r = run(&s, Backend::Model, 100, &SimOptions::default()).unwrap();
        assert!(r.ok, "{}: {}", p.display(), r.summary());
        assert_whole(&s, r.samples, 100);
    }
}

/// Two frames of three presets in process: the one with modes
/// (eskin34-adaptive: its mode block switching under the stimulus), one
/// with a link (eskin34-axis: the link's FIFO and AXI4-Stream master) and
/// the one on another clock (softslip1k, 12 MHz); the five others are
/// eskin34's core again, with a UART or wider branches, in `make test-long`
/// (`rusthdl_backend_2_frames_of_the_other_presets`).  rust-hdl simulates
/// every cycle of a preset's 10 ms frame (480,000 at 48 MHz): about 1.5 s
/// of CPU a preset.  Verilator runs every preset's Verilog in
/// `verilator_backend_2_frames`, and `make golden` all eight.
#[test]
fn rusthdl_backend_2_frames() {
    rusthdl_2_frames(|name| RUSTHDL_PRESETS.contains(&name));
}

#[test]
#[ignore = "long: make test-long (rusthdl_backend_2_frames on the five other presets)"]
fn rusthdl_backend_2_frames_of_the_other_presets() {
    rusthdl_2_frames(|name| !RUSTHDL_PRESETS.contains(&name));
}

/// The presets `rusthdl_backend_2_frames` runs in `make test`.
const RUSTHDL_PRESETS: [&str; 3] = ["eskin34-adaptive", "eskin34-axis", "softslip1k"];

/// Two frames on rusthdl of every preset whose name `pick` takes.
fn rusthdl_2_frames(pick: impl Fn(&str) -> bool) {
    let name = |p: &PathBuf| p.file_stem().unwrap().to_str().unwrap().to_string();
    let all = mixes();
    let names: Vec<String> = all.iter().map(name).collect();
    for n in RUSTHDL_PRESETS {
        assert!(names.iter().any(|x| x == n), "no preset {n}: {names:?}");
    }
    for p in all.into_iter().filter(|p| pick(&name(p))) {
        let s = schedule(&p);
        let r = run(&s, Backend::RustHdl, 2, &one_cycle_reset()).unwrap();
        assert!(r.ok, "{}: {}", p.display(), r.summary());
        assert_whole(&s, r.samples, 2);
        assert!(r.model_compared);
    }
}

#[test]
fn verilator_backend_2_frames() {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    for p in mixes() {
        let s = schedule(&p);
        let r = run(&s, Backend::Verilator, 2, &one_cycle_reset()).unwrap();
        assert!(r.ok, "{}: {}", p.display(), r.summary());
        assert_whole(&s, r.samples, 2);
    }
}

/// The largest mixes (issue 9): three AD7940s at 100 % (300 channels), the
/// gateware's 16 branches, and its 1,024 channels on 128 mux devices (a
/// 128-bit `mux_en`), one frame each on rusthdl and verilator with a
/// one-cycle reset.
#[test]
#[ignore = "long: make test-long"]
fn largest_mixes_one_frame() {
    let verilator = tools::require_tools(&["verilator", "g++"]);
    for name in ["full300", "b16", "ch1024"] {
        let p =
            Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../hdl/tests/data/{name}.toml"));
        let s = schedule(&p);
        let mut backends = vec![Backend::RustHdl];
        if verilator {
            backends.push(Backend::Verilator);
        }
        for b in backends {
            let r = run(&s, b, 1, &one_cycle_reset()).unwrap();
            assert!(r.ok, "{name} {b:?}: {}", r.summary());
            assert_whole(&s, r.samples, 1);
        }
    }
}

/// Converter parts (issue 10): a chain of two AD7685s behind a mux (two
/// conversion groups, members declared out of order), a lone AD7685 and an
/// AD7940 on one clock, with a sine stimulus and a one-cycle reset, on the
/// three engines that run the gateware.
///
/// The default suite runs `cnvmix2ms` (the same branches and channels in a
/// 2 ms frame) on rust-hdl and Verilator; `make test-long` adds Icarus
/// (most of the time: other tests keep Icarus in the default suite) and
/// cnvmix's 10 ms frame.
#[test]
fn cnv_chain_and_cs_parts_on_rusthdl_and_verilator() {
    cnv_chain_and_cs_parts(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/cnvmix2ms.toml"),
        false,
    );
}

#[test]
#[ignore = "long: make test-long"]
fn cnv_chain_and_cs_parts_on_every_engine() {
    cnv_chain_and_cs_parts(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/cnvmix2ms.toml"),
        true,
    );
}

#[test]
#[ignore = "long: make test-long"]
fn cnv_chain_and_cs_parts_on_every_engine_10ms_frame() {
    cnv_chain_and_cs_parts(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../hdl/tests/data/cnvmix.toml"),
        true,
    );
}

fn cnv_chain_and_cs_parts(p: &Path, icarus: bool) {
    let s = schedule(p);
    assert_eq!(s.mix.branches[0].chain, 2);
    let mut backends = vec![Backend::RustHdl];
    if tools::require_tools(&["verilator", "g++"]) {
        backends.push(Backend::Verilator);
    }
    if icarus && tools::require_tool("iverilog") {
        backends.push(Backend::Icarus);
    }
    let opts = SimOptions {
        stimulus: judge::Stimulus::Sine(None),
        ..one_cycle_reset()
    };
    for b in backends {
        let r = run(&s, b, 2, &opts).unwrap();
        assert!(r.ok, "{} on {}: {}", s.mix.name, b.name(), r.summary());
        assert_whole(&s, r.samples, 2);
    }
}
