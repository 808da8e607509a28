//! The link stage against the judge: the eskin34-uart preset runs clean on
//! the rust-hdl back end, and each fault built into the link's gateware
//! (a FIFO one token short, a wrong baud divider, a wrong CRC start) fails
//! the check on the link's pins, with the wrong bit's byte and packet named,
//! and the model-free decode of the line sees it too.

use judge::{run_dut, Dut, RunOptions};
use lut_gen::Pins;
use lut_gen::Schedule;

struct Sim(hdl::RtlSim);

impl Dut for Sim {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        self.0.step(rst, miso)
    }
    fn set_tready(&mut self, ready: bool) {
        self.0.set_tready(ready)
    }
}

fn preset() -> Schedule {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../mixes/eskin34-uart.toml");
    lut_gen::synthesize(&lut_gen::load(std::path::Path::new(path)).unwrap()).unwrap()
}

#[test]
fn the_link_runs_clean_and_every_link_fault_is_caught() {
    let s = preset();
    let opts = RunOptions::default();
    let clean = run_dut(
        &s,
        &mut Sim(hdl::RtlSim::new(&s).unwrap()),
        1,
        &opts,
        "test",
        None,
    );
    assert!(clean.ok, "{}", clean.summary());
    let faults = hdl::GatewareFault::link_faults(&s);
    assert_eq!(faults.len(), 3);
    for (class, f) in faults {
        let mut dut = Sim(hdl::RtlSim::with_fault(&s, f).unwrap());
        let r = run_dut(&s, &mut dut, 1, &opts, "test", None);
        assert!(!r.ok, "{class}: not caught");
        // the invariants see it too: the line decoded without the model
        // (a wrong divider or CRC start), or the overflow flag
        assert!(
            r.violations.iter().any(|v| v.rule.starts_with("link-")),
            "{class}: the invariants missed it: {}",
            r.summary()
        );
        let d = r
            .divergences
            .first()
            .unwrap_or_else(|| panic!("{class}: no divergence"));
        assert!(
            d.signal.starts_with("link_"),
            "{class}: first on {}",
            d.signal
        );
        if d.signal == "link_tx" {
            assert!(
                d.context.iter().any(|l| l.contains("of packet frame")),
                "{class}: {:?}",
                d.context
            );
        }
    }
}

use crate::tools;

/// The link in Icarus (the emitted Verilog's `slotforge_link`, its line read
/// back from Icarus's VCD); verilator and rusthdl run every preset in
/// `backends.rs`.  Icarus takes minutes per frame of this mix.
#[test]
#[ignore = "long: make test-long"]
fn the_link_runs_clean_in_icarus() {
    if !tools::require_tool("iverilog") {
        return;
    }
    let s = preset();
    let r = engines::run(
        &s,
        engines::Backend::Icarus,
        1,
        &engines::SimOptions::default(),
    )
    .unwrap();
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.samples, s.samples_per_frame() - s.startup_skips());
}

fn axis_preset() -> Schedule {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../mixes/eskin34-axis.toml");
    lut_gen::synthesize(&lut_gen::load(std::path::Path::new(path)).unwrap()).unwrap()
}

/// The beats a slave took and the merged sample stream, cycle by cycle.
#[derive(Default)]
struct Beats {
    bytes: Vec<u8>,
    samples: Vec<(u16, u16)>,
    stalls: u64,
}

impl judge::Observer for Beats {
    fn cycle(&mut self, _c: u64, rst: bool, p: &Pins, _miso: u64) {
        if rst {
            return;
        }
        if p.axis_tvalid && p.axis_tready {
            self.bytes.push(p.axis_tdata);
        }
        self.stalls += (p.axis_tvalid && !p.axis_tready) as u64;
        if p.sample_valid {
            self.samples.push((p.sample_channel, p.sample_value));
        }
    }
}

/// The beats of a Verilog engine, read back from its pins (Verilator's
/// cycles, or Icarus's VCD).
impl judge::CycleSink for Beats {
    fn cycle(&mut self, rst: Option<bool>, p: &Pins, _xz: &Pins, miso: u64, _mx: u64) {
        judge::Observer::cycle(self, 0, rst.unwrap_or(false), p, miso);
    }
}

/// AXI4-Stream on the Verilog engines under back-pressure: the emitted
/// Verilog's `slotforge_link` behind the worst-case slave and a random one
/// (the Verilator shim's `tready` field, the Icarus testbench's driver),
/// judged cycle by cycle; beats must wait, and the beats taken decode to
/// the design's sample stream.  Verilator runs the eskin34-axis preset for
/// one frame (its model is the one `backends.rs` builds, from the cache);
/// Icarus, minutes per frame of that mix, runs the tiny AXIS mix.
#[test]
fn axis_runs_clean_on_verilator_and_icarus_under_back_pressure() {
    let patterns = [
        link::ReadyPattern::WorstCase,
        link::ReadyPattern::Random { seed: 7 },
    ];
    let mut runs = Vec::new();
    if tools::require_tools(&["verilator", "g++"]) {
        runs.push((engines::Backend::Verilator, axis_preset(), 1));
    }
    if tools::require_tool("iverilog") {
        runs.push((engines::Backend::Icarus, tiny_axis(), 2));
    }
    for (engine, s, frames) in runs {
        for tready in patterns {
            let what = format!("{} tready {}", engine.name(), tready.name());
            let opts = engines::SimOptions {
                tready,
                ..engines::SimOptions::default()
            };
            let mut beats = Beats::default();
            let r = engines::run_observed(&s, engine, frames, &opts, Some(&mut beats)).unwrap();
            assert!(r.ok, "{what}: {}", r.summary());
            assert!(r.model_compared, "{what}");
            assert!(beats.stalls > 10, "{what}: {} stalls", beats.stalls);
            let mut dec = link::Decoder::new(s.grid.slices_per_frame);
            let mut out = Vec::new();
            dec.push(&beats.bytes, &mut out);
            let got: Vec<(u16, u16)> = out.iter().map(|d| (d.channel, d.value)).collect();
            assert!(got.len() * 2 > beats.samples.len(), "{what}: {}", got.len());
            assert_eq!(got[..], beats.samples[..got.len()], "{what}");
            assert_eq!(dec.stats().crc_errors, 0, "{what}");
        }
    }
}

/// The campaign's AXIS classes on the preset under a random slave (the
/// campaign itself runs the worst case): the first waiting beat withdrawn
/// or changed breaks the model-free stability rule and diverges from the
/// model on the pin it touched.
#[test]
fn axis_pin_faults_under_back_pressure_break_the_stability_rule() {
    use judge::{FaultyDut, PinFault};
    let s = axis_preset();
    for (f, signal) in [
        (PinFault::AxisTdataChange, "m_axis_tdata"),
        (PinFault::AxisTvalidDrop, "m_axis_tvalid"),
    ] {
        let sim = Sim(hdl::RtlSim::new(&s).unwrap());
        let slave = judge::with_slave(&s, sim, link::ReadyPattern::Random { seed: 5 });
        let mut dut = FaultyDut::new(&s, slave, f, 0);
        let r = run_dut(&s, &mut dut, 1, &RunOptions::default(), "test", None);
        let class = f.class();
        assert!(dut.injected() && !r.ok, "{class}: not caught");
        assert!(
            r.violations.iter().any(|v| v.rule == "axis-stable"),
            "{class}: {:?}",
            r.violations
        );
        assert!(
            r.divergences.iter().any(|d| d.signal == signal),
            "{class}: {:?}",
            r.divergences
        );
    }
}

/// `testkit/mixes/tiny.toml` (4 MHz, 1 ms frames) with `link`
/// appended: a link mix whose runs take milliseconds.
fn tiny_with(link: &str) -> Schedule {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../testkit/mixes/tiny.toml");
    let text = std::fs::read_to_string(path).unwrap() + "\n[link]\n" + link;
    let mix = lut_gen::parse(std::path::Path::new("tiny-link.toml"), &text).unwrap();
    lut_gen::synthesize(&mix).unwrap()
}

fn tiny_uart() -> Schedule {
    tiny_with("kind = \"uart\"\nbaud = 1_000_000\n")
}

fn tiny_axis() -> Schedule {
    tiny_with("kind = \"axis\"\ntlast = \"slice\"\nready_within = 8\n")
}

/// Whether a port name is one of the link's.
fn is_link_port(name: &str) -> bool {
    name.starts_with("link_") || name.starts_with("m_axis_")
}

/// Every pin fault of the link (UART: bit flip, dropped byte, stuck high
/// and low, the overflow flag; AXI4-Stream: tvalid dropped and tdata
/// changed under back-pressure, the overflow flag) is injected into the
/// model's pins behind the campaign's slave and caught by the detector the
/// campaign credits: the model on the link's own ports (no other port
/// diverges), and the invariants: the `link-overflow` / `axis-stable` rule,
/// or for the UART line's faults the line's model-free decode (`link-*`
/// rules only).  The same run without the fault passes.
#[test]
fn every_link_pin_fault_is_caught_by_its_detector() {
    use campaign::{Detector, FaultClass, Level, TREADY};
    use judge::{FaultyDut, PinFault};
    for s in [tiny_uart(), tiny_axis()] {
        let opts = RunOptions::default();
        let at = s.grid.frame_cycles + s.grid.frame_cycles / 2 + 7;
        let clean = run_dut(
            &s,
            &mut *judge::with_slave(&s, judge::ModelDut::new(&s), TREADY),
            3,
            &opts,
            "test",
            None,
        );
        assert!(clean.ok, "clean: {}", clean.summary());
        let faults = PinFault::link(&s);
        let axis = s.mix.link.unwrap().kind == lut_gen::LinkKind::Axis;
        assert_eq!(faults.len(), if axis { 3 } else { 5 });
        for f in faults {
            let inner = judge::with_slave(&s, judge::ModelDut::new(&s), TREADY);
            let mut dut = FaultyDut::new(&s, inner, f, at);
            let r = run_dut(&s, &mut dut, 3, &opts, "test", None);
            let class = f.class();
            assert!(dut.injected(), "{class}: found nothing to change");
            assert!(!r.ok, "{class}: not caught");
            assert!(r.divergence_count > 0, "{class}: the model missed it");
            let first = &r.divergences[0];
            assert!(first.cycle >= at, "{class}: diverged before the fault");
            for d in &r.divergences {
                assert!(is_link_port(&d.signal), "{class}: {} diverged", d.signal);
            }
            let rules: Vec<&str> = r.violations.iter().map(|v| v.rule.as_str()).collect();
            let kind = FaultClass::of_pins(f);
            let sees = Detector::Invariants.blind_to(&kind, Level::Pins).is_none();
            let rule = match f {
                PinFault::LinkOverflow => Some("link-overflow"),
                PinFault::AxisTvalidDrop | PinFault::AxisTdataChange => Some("axis-stable"),
                _ => None,
            };
            match rule {
                Some(rule) => {
                    assert!(sees, "{class}: the campaign says invariants are blind");
                    // (a changed tdata restored next cycle breaks it twice)
                    assert!(
                        !rules.is_empty() && rules.iter().all(|r| *r == rule),
                        "{class}: {rules:?}"
                    );
                }
                // the UART line's own faults: its model-free decode
                None => {
                    assert!(sees, "{class}: the campaign says invariants are blind");
                    assert!(
                        !rules.is_empty() && rules.iter().all(|r| r.starts_with("link-")),
                        "{class}: {rules:?}"
                    );
                }
            }
            assert!(Detector::Sigrok.blind_to(&kind, Level::Pins).is_some());
        }
    }
}

/// The FIFO one token short overflows under the campaign's worst-case
/// slave and is caught there by the `link-overflow` rule; under an
/// always-ready slave the backlog never reaches the depth, which is why the
/// campaign does not run AXI4-Stream links with one.
#[test]
fn a_short_axis_fifo_overflows_under_the_campaigns_slave() {
    let s = tiny_axis();
    let opts = RunOptions::default();
    for (pattern, caught) in [
        (campaign::TREADY, true),
        (link::ReadyPattern::Always, false),
    ] {
        let sim = Sim(hdl::RtlSim::with_fault(&s, hdl::GatewareFault::LinkFifoShort).unwrap());
        let mut dut = judge::with_slave(&s, sim, pattern);
        let r = run_dut(&s, &mut *dut, 3, &opts, "test", None);
        let overflow = r.violations.iter().any(|v| v.rule == "link-overflow");
        assert_eq!(overflow, caught, "{}: {}", pattern.name(), r.summary());
    }
}

/// The campaign's matrix on the presets with a link (what `slotforge faults
/// mixes/eskin34-uart.toml` and `eskin34-axis.toml` print), at the
/// mid-frame site: every link class is injected, every injection caught,
/// the model catches each, the invariants the classes they can see, and
/// sigrok is declared blind to them.
#[test]
#[ignore = "long: make test-long"]
fn the_presets_campaigns_report_every_link_class_caught() {
    use campaign::{campaign_with, sites, Detector, Plan, Target};
    for s in [preset(), axis_preset()] {
        let mut plan = Plan::new(Target::Model, 3, 0);
        plan.sites = Some(
            sites(&s)
                .into_iter()
                .filter(|x| x.name == "mid-frame")
                .collect(),
        );
        let c = campaign_with(&s, &plan).unwrap();
        assert!(c.ok(), "{}: {} undetected", s.mix.name, c.undetected);
        let want: Vec<&str> = judge::PinFault::link(&s)
            .iter()
            .map(|f| f.class())
            .collect();
        for class in want {
            let k = c
                .classes
                .iter()
                .find(|k| k.name.name() == class)
                .unwrap_or_else(|| panic!("{}: {class} not in the matrix", s.mix.name));
            assert!(k.injected > 0 && k.detected == k.injected, "{class}");
            assert_eq!(k.detected_by[&Detector::Model], k.injected, "{class}");
            if !k.cannot_see.contains_key(&Detector::Invariants) {
                assert_eq!(k.detected_by[&Detector::Invariants], k.injected, "{class}");
            }
            assert!(k.cannot_see.contains_key(&Detector::Sigrok), "{class}");
        }
        assert_eq!(c.tready.is_some(), s.mix.name.ends_with("axis"));
    }
}
