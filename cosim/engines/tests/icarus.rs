//! The `icarus` back end: the emitted Verilog in Icarus with a Verilog
//! AD7940 model (cosim/engines/tb/adc_tb.v.in); its VCD must pass the checker, and
//! its ADCs must give the codes of cosim's own ADC model.

use std::path::{Path, PathBuf};

use engines::{Backend, SimOptions, Stimulus, VcdOut};
use judge::Pins;
use judge::{read_cycles, CycleSink};
use judge::{run_dut, Observer, RunOptions};

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::tools;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../testkit/mixes")
        .join(name)
}

fn schedule(p: &Path) -> lut_gen::Schedule {
    lut_gen::synthesize(&lut_gen::load(p).unwrap()).unwrap()
}

/// `(cycle after reset, channel, value)` of every sample.
#[derive(Default)]
struct Samples {
    c: u64,
    v: Vec<(u64, u16, u16)>,
}

impl CycleSink for Samples {
    fn cycle(&mut self, rst: Option<bool>, p: &Pins, _: &Pins, _: u64, _: u64) {
        if rst == Some(false) {
            if p.sample_valid {
                self.v.push((self.c, p.sample_channel, p.sample_value));
            }
            self.c += 1;
        }
    }
}

impl Observer for Samples {
    fn cycle(&mut self, _: u64, rst: bool, p: &Pins, _: u64) {
        CycleSink::cycle(self, Some(rst), p, p, 0, 0);
    }
}

#[test]
fn icarus_backend_matches_cosims_adc_model_on_a_small_mix() {
    if !tools::require_tool("iverilog") {
        return;
    }
    let s = schedule(&data("tiny.toml"));
    let d = tempfile::tempdir().unwrap();
    for stimulus in [Stimulus::Pattern, Stimulus::Sine(None)] {
        let wave = d.path().join("wave.vcd");
        let opts = SimOptions {
            stimulus,
            vcd: Some(VcdOut {
                path: wave.clone(),
                from: 0,
                to: 3 * s.grid.frame_cycles,
                gtkw: false,
            }),
            ..SimOptions::default()
        };
        let r = engines::run(&s, Backend::Icarus, 3, &opts).unwrap();
        assert!(r.ok, "{stimulus:?}: {}", r.summary());
        assert_eq!(r.source, "icarus");
        assert!(r.model_compared);
        assert_eq!(r.frames, 3);
        assert_eq!(r.samples, 3 * s.samples_per_frame() - s.startup_skips());
        // the same sample stream (cycles, channels, codes) as the in-process ADC model
        let mut ic = Samples::default();
        read_cycles(&s, &wave, None, &mut ic).unwrap();
        let mut rh = Samples::default();
        let mut dut = engines::RustHdlDut::new(&s).unwrap();
        let ro = RunOptions {
            stimulus,
            ..RunOptions::default()
        };
        let rr = run_dut(&s, &mut dut, 3, &ro, "rusthdl", Some(&mut rh));
        assert!(rr.ok);
        assert_eq!(
            ic.v.len() as u64,
            3 * s.samples_per_frame() - s.startup_skips()
        );
        assert_eq!(
            ic.v, rh.v,
            "{stimulus:?}: Icarus's ADC codes differ from cosim's"
        );
    }
}

#[test]
fn icarus_backend_vcd_windows() {
    if !tools::require_tool("iverilog") {
        return;
    }
    let s = schedule(&data("tiny.toml"));
    let d = tempfile::tempdir().unwrap();
    let f = s.grid.frame_cycles;
    for (from, to, checks) in [(0, 2, true), (1, 2, false)] {
        let wave = d.path().join(format!("w{from}{to}.vcd"));
        let opts = SimOptions {
            vcd: Some(VcdOut {
                path: wave.clone(),
                from: from * f,
                to: to * f,
                gtkw: false,
            }),
            ..SimOptions::default()
        };
        let r = engines::run(&s, Backend::Icarus, 3, &opts).unwrap();
        assert!(r.ok, "{}", r.summary());
        let cycles = judge::parse_vcd(&s, &wave, None).unwrap();
        let reset = judge::reset_cycles(&s, opts.reset_cycles);
        if checks {
            // a window from frame 0 has the reset and checks on its own
            assert_eq!(cycles, reset + (to - from) * f);
            let r = judge::check_vcd(&s, &wave, None).unwrap();
            assert!(r.ok, "{}", r.summary());
            assert_eq!(r.frames, to - from);
        } else {
            assert_eq!(cycles, (to - from) * f);
        }
    }
}

#[test]
#[ignore = "long: make test-long"]
fn icarus_backend_eskin34_one_frame() {
    if !tools::require_tool("iverilog") {
        return;
    }
    let s = schedule(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../mixes/eskin34.toml"));
    // a one-cycle reset (docs/timing.md, "Start-up")
    let opts = SimOptions {
        reset_cycles: 1,
        ..SimOptions::default()
    };
    let r = engines::run(&s, Backend::Icarus, 1, &opts).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.frames, 1);
    assert_eq!(r.samples, s.samples_per_frame() - s.startup_skips());
}
