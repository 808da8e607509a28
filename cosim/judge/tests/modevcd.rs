//! A switching run as a VCD (docs/timing.md, "Mode switches"): the writer
//! dumps `mode_sel` and `mode`, the reader takes them back, and `check`
//! judges the file with and without the model, from reset and in windows
//! at random offsets; the same file with `mode_sel` altered in a frame's
//! last cycle fails where the contract says.

use std::path::Path;

use judge::{CheckOptions, Dut, ModeRequests, ModelDut, RunOptions, Stimulus};
use lut_gen::{Pins, Schedule};

fn schedule(path: &Path) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(path).unwrap()).unwrap()
}

/// `mode_sel` recorded as 0 in run cycle `at` (the design saw the request).
struct Withdrawn<D> {
    dut: D,
    at: u64,
    c: Option<u64>,
}

impl<D: Dut> Dut for Withdrawn<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        let mut p = self.dut.step(rst, miso);
        self.c = if rst {
            None
        } else {
            Some(self.c.map_or(0, |c| c + 1))
        };
        if self.c == Some(self.at) {
            p.mode_sel = 0;
        }
        p
    }
}

fn check(s: &Schedule, p: &Path, model: bool) -> judge::Verdict {
    let opts = CheckOptions {
        model,
        ..Default::default()
    };
    judge::check_vcd_with(s, p, None, opts).unwrap().0
}

fn first(v: &judge::Verdict, rule: &str) -> Option<u64> {
    v.violations
        .iter()
        .filter(|x| x.rule == rule)
        .map(|x| x.cycle)
        .min()
}

const REQUESTS: [(u64, u8); 2] = [(2, 1), (5, 0)];

#[test]
fn a_switching_runs_vcd_carries_the_mode_ports_and_passes() {
    let s = schedule(&testkit::mix("modes-pin"));
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("run.vcd");
    let mut dut = ModeRequests::new(&s, ModelDut::new(&s), &REQUESTS);
    let full = (0, u64::MAX);
    let w = judge::write_run(&p, &s, &mut dut, 10, &RunOptions::default(), full).unwrap();
    assert!(w.ok, "{}", w.summary());
    let text = std::fs::read_to_string(&p).unwrap();
    for port in ["mode_sel", "mode"] {
        assert!(
            text.lines()
                .any(|l| l.starts_with("$var") && l.split_whitespace().nth(4) == Some(port)),
            "no {port} in the VCD's header"
        );
    }
    for model in [true, false] {
        let v = check(&s, &p, model);
        assert!(v.ok, "model {model}: {}", v.summary());
        assert_eq!(v.frames, 10, "{}", v.summary());
    }
}

#[test]
fn mode_sel_altered_in_a_vcd_fails_at_the_frame_it_decides() {
    let s = schedule(&testkit::mix("modes-pin"));
    let f = s.grid.frame_cycles;
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("bad.vcd");
    // the request for mode 1 (shown from frame 2) withdrawn in frame 3's
    // last cycle: frame 5 must run mode 0, the design runs mode 1
    let inner = ModeRequests::new(&s, ModelDut::new(&s), &REQUESTS);
    let mut dut = Withdrawn {
        dut: inner,
        at: 4 * f - 1,
        c: None,
    };
    let full = (0, u64::MAX);
    judge::write_run(&p, &s, &mut dut, 10, &RunOptions::default(), full).unwrap();
    let v = check(&s, &p, false);
    assert_eq!(first(&v, "mode-decision"), Some(5 * f), "{}", v.summary());
    let v = check(&s, &p, true);
    let d = v
        .divergences
        .iter()
        .find(|d| d.signal == "mode")
        .expect("mode diverges");
    assert_eq!(d.cycle, 5 * f, "{}", v.summary());
}

/// Windows at random offsets of switching runs (pin select under requests,
/// auto select under a touch) pass without the model, and with it where the
/// judge can join; the frames they hold are counted in each one's mode.
#[test]
fn windows_at_random_offsets_of_switching_runs_pass() {
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let d = tempfile::tempdir().unwrap();
    for (name, requests, scene) in [
        ("modes-pin", &REQUESTS[..], None),
        ("modes-auto", &[][..], Some("touch:T0,T2@2-6")),
    ] {
        let s = schedule(&testkit::mix(name));
        let f = s.grid.frame_cycles;
        let stimulus = match scene {
            Some(k) => Stimulus::parse_for(k, &s).unwrap(),
            None => Stimulus::default(),
        };
        let opts = RunOptions {
            stimulus,
            ..RunOptions::default()
        };
        for _ in 0..3 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let from = x % (6 * f);
            let to = from + 3 * f + x % f;
            let p = d.path().join(format!("{name}-{from}.vcd"));
            let mut dut = ModeRequests::new(&s, ModelDut::new(&s), requests);
            judge::write_run(&p, &s, &mut dut, to / f + 2, &opts, (from, to)).unwrap();
            for model in [false, true] {
                let v = check(&s, &p, model);
                assert!(
                    v.ok,
                    "{name} window {from}..{to}, model {model}: {}",
                    v.summary()
                );
                assert!(v.frames >= 2, "{}", v.summary());
            }
        }
    }
}
