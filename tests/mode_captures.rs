//! Logic-analyser captures (`check --map`) of mixes with modes, judged frame
//! by frame against the mode in force: captures resampled from the pins of
//! rust-hdl's gateware under `--modes` requests (pin select) and under a
//! touch (auto select), at random analyser offsets, pass, the switches at
//! the frames the contract puts them; the same capture with `mode_sel`
//! altered at one frame boundary fails in the frame that decision rules; a
//! map without the mode pins is refused naming what to map; random mode
//! mixes pass.

use std::path::Path;

use judge::{run_dut, ModeRequests, Observer, RunOptions, Stimulus};
use lut_gen::{Layout, Pins, Role, Schedule};
use testkit::analyser;

use crate::common_cli::{root, slotforge};
use crate::link_windows::rng;

/// Analyser lane codes for the mode ports (with `analyser::lanes`' roles).
const SEL: u32 = 200;
const MODE: u32 = 300;

/// Every cycle's pins and MISO (bit b: branch b) after reset.
#[derive(Default)]
struct Rec(Vec<(Pins, u64)>);

impl Observer for Rec {
    fn cycle(&mut self, _: u64, rst: bool, p: &Pins, miso: u64) {
        if !rst {
            self.0.push((*p, miso));
        }
    }
}

/// Every cycle's pins of `frames` frames of rust-hdl's gateware, `mode_sel`
/// driven by `requests` (frame, mode), the ADC by `stimulus`.
fn pins(s: &Schedule, frames: u64, requests: &[(u64, u8)], stimulus: &str) -> Vec<(Pins, u64)> {
    let dut = engines::RustHdlDut::new(s).expect("rust-hdl builds");
    let dut = ModeRequests::new(s, dut, requests);
    // an AXI4-Stream link's slave, ready at random within its bound
    let mut dut = judge::with_slave(s, dut, ::link::ReadyPattern::Random { seed: 5 });
    let opts = RunOptions {
        stimulus: Stimulus::parse_for(stimulus, s).unwrap(),
        ..RunOptions::default()
    };
    let mut r = Rec::default();
    run_dut(s, &mut dut, frames, &opts, "gen", Some(&mut r));
    r.0
}

/// The core's timing lanes (no link: judged elsewhere), every MISO bit
/// and the mode ports asked for, with the `--map` naming them.
fn lanes(s: &Schedule, sel: bool, mode: bool) -> (Vec<(Option<Role>, u32)>, String) {
    let (all, _) = analyser::lanes(s);
    let mut v: Vec<_> = all.into_iter().collect();
    v.extend((0..s.mix.branches.len() as u32).map(|b| (Some(Role::Miso), b)));
    let bits = Layout::new(s).mode_bits;
    for (on, base) in [(sel, SEL), (mode, MODE)] {
        if on {
            v.extend((0..bits).map(|b| (None, base + b)));
        }
    }
    let map = (v.iter().enumerate())
        .map(|(i, (r, b))| match r {
            Some(r) => format!("D{i}={}[{b}]", r.name()),
            None if *b >= MODE => format!("D{i}=mode[{}]", b - MODE),
            None if *b < analyser::AXIS_LANE => format!("D{i}=link_tx"),
            None if *b < SEL => format!(
                "D{i}={}",
                analyser::AXIS_LANES[(b - analyser::AXIS_LANE) as usize]
            ),
            None => format!("D{i}=mode_sel[{}]", b - SEL),
        })
        .collect::<Vec<_>>()
        .join(",");
    (v, map)
}

fn level(&(ref p, miso): &(Pins, u64), r: Option<Role>, b: u32) -> bool {
    match (r, b) {
        (Some(Role::Miso), b) => miso >> b & 1 == 1,
        (None, b) if b >= MODE => p.mode >> (b - MODE) & 1 == 1,
        (None, b) if b < SEL => analyser::bit(p, None, b),
        (None, b) => p.mode_sel >> (b - SEL) & 1 == 1,
        _ => analyser::bit(p, r, b),
    }
}

/// What a 100 MHz analyser (first sample `phase` ps into cycle `w.0`)
/// records of cycles `w`, judged.
fn judged(
    s: &Schedule,
    pins: &[(Pins, u64)],
    w: (u64, u64),
    phase: u64,
    (sel, mode): (bool, bool),
    out: &Path,
) -> Result<judge::TimedReport, String> {
    let (lanes, map) = lanes(s, sel, mode);
    let lv = |c: usize, r: Option<Role>, b: u32| level(&pins[c], r, b);
    analyser::resample_lanes(s, &lanes, &lv, w, 10_000, phase, out);
    let text = std::fs::read_to_string(out).unwrap().replace(
        "$enddefinitions $end\n",
        "$comment\n  Acquisition at 100 MHz\n$end\n$enddefinitions $end\n",
    );
    std::fs::write(out, text).unwrap();
    let cap = judge::read_capture(out, judge::parse_map(&map, s).unwrap()).unwrap();
    judge::check_capture(s, &cap, 0).map_err(|e| e.to_string())
}

fn schedule(path: &Path) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(path).unwrap()).unwrap()
}

fn shared(name: &str) -> Schedule {
    schedule(&root().join("testkit/mixes").join(format!("{name}.toml")))
}

/// The time (ps) of cycle `c` in a capture of cycles from `from`, the first
/// sample `phase` ps in.
fn at_ps(s: &Schedule, c: u64, from: u64, phase: u64) -> i64 {
    ((c - from) as f64 * 1e12 / s.mix.clock_hz as f64) as i64 - phase as i64
}

/// Frames (from `from`) whose mode differs from the frame before's.
fn switch_frames(s: &Schedule, pins: &[(Pins, u64)], from: u64) -> Vec<u64> {
    let f = s.grid.frame_cycles;
    let mode = |c: u64| pins[c as usize].0.mode;
    (from / f + 1..pins.len() as u64 / f)
        .filter(|&k| mode(k * f) != mode(k * f - 1))
        .collect()
}

/// A capture of `pins` at a random offset (from 0.3 to 2.3 frames in, to
/// `frames` frames) passes, with the switches the pins made at the times
/// of their frames' starts.
fn passes_at_random_offsets(
    s: &Schedule,
    pins: &[(Pins, u64)],
    ports: (bool, bool),
    seed: u64,
    what: &str,
) {
    let f = s.grid.frame_cycles;
    let mut r = rng(seed);
    let d = tempfile::tempdir().unwrap();
    for k in 0..3 {
        let from = f * 3 / 10 + r() % (2 * f);
        let to = pins.len() as u64 - r() % (f / 2);
        let phase = r() % 10_000;
        let out = d.path().join(format!("cap{k}.vcd"));
        let rep = judged(s, pins, (from, to), phase, ports, &out)
            .unwrap_or_else(|e| panic!("{what} [{from}, {to}) +{phase} ps: {e}"));
        assert!(
            rep.ok,
            "{what} [{from}, {to}) +{phase} ps: {}",
            rep.summary()
        );
        let m = rep.modes.as_ref().expect("modes reported");
        let want: Vec<i64> = switch_frames(s, pins, from)
            .into_iter()
            .filter(|&k| k * f < to)
            .map(|k| at_ps(s, k * f, from, phase))
            .collect();
        assert_eq!(m.switches.len(), want.len(), "{what}: {}", rep.summary());
        let tc = 1e12 / s.mix.clock_hz as f64;
        for ((t, _), w) in m.switches.iter().zip(&want) {
            assert!(
                ((*t as i64 - w).abs() as f64) < tc + 10_000.0,
                "{what}: a switch at {t} ps, the pins' at {w}: {}",
                rep.summary()
            );
        }
    }
}

/// Pin select under `--modes`: captures with `mode_sel` (and with `mode`
/// alone) pass at random offsets, the switches where the pins made them;
/// `mode_sel` altered in one frame fails in the frame that decision rules.
#[test]
fn captures_of_a_pin_select_mix_follow_mode_sel() {
    let s = shared("modes-pin");
    let f = s.grid.frame_cycles;
    let p = pins(&s, 10, &[(2, 1), (5, 0), (7, 1)], "pattern");
    assert_eq!(switch_frames(&s, &p, 0), [4, 7, 9], "the requests switch");
    passes_at_random_offsets(&s, &p, (true, true), 1, "mode_sel and mode");
    passes_at_random_offsets(&s, &p, (true, false), 2, "mode_sel");
    passes_at_random_offsets(&s, &p, (false, true), 3, "mode");
    let d = tempfile::tempdir().unwrap();
    // frame 3 asks for `fast` (0) where the run asked for `slow`: the
    // decision at frame 4's start makes frame 5 fast, the design ran slow
    let mut bad = p.clone();
    for q in &mut bad[(3 * f) as usize..(4 * f) as usize] {
        q.0.mode_sel = 0;
    }
    let (from, phase) = (f / 3, 4_321);
    for ports in [(true, true), (true, false)] {
        let r = judged(
            &s,
            &bad,
            (from, 10 * f),
            phase,
            ports,
            &d.path().join("bad.vcd"),
        )
        .unwrap();
        assert!(!r.ok, "{}", r.summary());
        let t = r.violations[0].time_ps as i64;
        let (lo, hi) = (at_ps(&s, 5 * f, from, phase), at_ps(&s, 6 * f, from, phase));
        assert!(
            t >= lo && t < hi,
            "{ports:?}: first violation at {t} ps, frame 5 is [{lo}, {hi}): {}",
            r.summary()
        );
    }
}

/// Auto select under a touch: the capture's `mode` pins say each frame's
/// mode, the triggers on the samples its MISO carried judge each switch;
/// it passes at random offsets through the switch to contact and back.  The
/// same capture with MISO low through the touch (the design switched
/// without its condition) fails at the switch's frame.
#[test]
fn captures_of_an_auto_mix_under_a_touch_pass() {
    let s = shared("modes-auto");
    let f = s.grid.frame_cycles;
    let p = pins(&s, 20, &[], "touch:T0@8-12");
    let sw = switch_frames(&s, &p, 0);
    assert!(sw.len() >= 2, "the touch switches and back: {sw:?}");
    passes_at_random_offsets(&s, &p, (false, true), 4, "touch");
    let d = tempfile::tempdir().unwrap();
    let (from, phase) = (f / 2, 1_234);
    let r = judged(
        &s,
        &p,
        (from, 20 * f),
        phase,
        (false, true),
        &d.path().join("c.vcd"),
    )
    .unwrap();
    let said = r.summary();
    assert!(r.ok, "{said}");
    assert!(said.contains("proved: the switch decisions of 1"), "{said}");
    let mut bad = p.clone();
    for q in &mut bad[(8 * f) as usize..(12 * f) as usize] {
        q.1 = 0;
    }
    let r = judged(
        &s,
        &bad,
        (from, 20 * f),
        phase,
        (false, true),
        &d.path().join("b.vcd"),
    )
    .unwrap();
    assert!(!r.ok, "{}", r.summary());
    let v = &r.violations[0];
    assert!(v.rule.contains("mode decision"), "{}", r.summary());
    let at = at_ps(&s, sw[0] * f, from, phase);
    assert!(
        (v.time_ps as i64 - at).abs() < 1_000_000,
        "{} vs {at}: {}",
        v.time_ps,
        r.summary()
    );
}

/// Without the mode pins, a capture of a mode mix is refused, the message
/// naming the ports to map; `check --map` says so with exit 2.
#[test]
fn a_mode_mix_capture_without_mode_pins_is_refused_naming_them() {
    let d = tempfile::tempdir().unwrap();
    for (name, want) in [
        ("modes-pin", "mode_sel[0] (the requests) or mode[0]"),
        ("modes-auto", "mode[1:0]"),
    ] {
        let s = shared(name);
        let p = pins(&s, 4, &[], "pattern");
        let out = d.path().join(format!("{name}.vcd"));
        let e = judged(
            &s,
            &p,
            (100, 4 * s.grid.frame_cycles),
            0,
            (false, false),
            &out,
        )
        .unwrap_err();
        assert!(e.contains(want) && e.contains("map"), "{name}: {e}");
        let (_, map) = lanes(&s, false, false);
        let mix = root().join("testkit/mixes").join(format!("{name}.toml"));
        let a = slotforge()
            .arg("check")
            .arg(&mix)
            .arg(&out)
            .arg("--map")
            .arg(&map)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&a.stderr);
        assert_eq!(a.status.code(), Some(2), "{err}");
        assert!(err.contains(want), "{err}");
    }
}

/// Random mode mixes (campaign's, 2 to 4 modes, pin or auto select, modes
/// that leave branches out): random requests or a touch of the watched
/// channel, captured at random offsets, pass.  `make test` takes the
/// first three mixes of the draw, `make test-long` the next three.
#[test]
fn captures_of_random_mode_mixes_pass() {
    random_mode_mixes_pass(0..3);
}

#[test]
#[ignore = "long: make test-long (the draw's fourth to sixth mixes)"]
fn captures_of_more_random_mode_mixes_pass() {
    random_mode_mixes_pass(3..6);
}

/// The draw's mixes numbered `which` (of those that schedule and fit),
/// each captured as [`captures_of_random_mode_mixes_pass`] says; the mixes
/// before them are drawn (with their requests) but not run, so each mix
/// is the one it is in a draw of all six.
fn random_mode_mixes_pass(which: std::ops::Range<usize>) {
    let d = tempfile::tempdir().unwrap();
    let mut r = rng(29);
    let mut done = 0;
    for seed in 0..40u64 {
        if done == which.end {
            break;
        }
        let Some(text) = testkit::modemix::random_mode_mix(seed) else {
            continue;
        };
        let path = d.path().join(format!("m{seed}.toml"));
        std::fs::write(&path, &text).unwrap();
        let Ok(s) = lut_gen::load(&path)
            .map_err(|_| ())
            .and_then(|m| lut_gen::synthesize(&m).map_err(|_| ()))
        else {
            continue;
        };
        if Layout::fits(&s).is_err() {
            continue;
        }
        let plan = s.mode_plan().unwrap();
        let n = plan.names.len() as u64;
        let pin = plan.select == lut_gen::ModeSelect::Pin;
        let req: Vec<(u64, u8)> = match pin {
            true => (1..5).map(|k| (2 * k, (r() % n) as u8)).collect(),
            false => vec![],
        };
        done += 1;
        if done <= which.start {
            continue;
        }
        let p = match pin {
            true => pins(&s, 12, &req, "pattern"),
            false => pins(&s, 12, &[], "touch:c0@3-6"),
        };
        passes_at_random_offsets(
            &s,
            &p,
            (pin, !pin),
            seed,
            &format!("random mode mix {seed}:\n{text}"),
        );
    }
    assert_eq!(done, which.end, "{} random mode mixes", which.end);
}

/// A capture that begins after a switch (in a mode other than the reset
/// mode) passes, its link too: the link's model runs in the modes the
/// capture shows, not from the reset mode (a UART line here, the same mix
/// with an AXI4-Stream link in `make test-long`); the same capture with the
/// UART line held idle for two slices after the join fails on the line.
#[test]
fn a_capture_beginning_in_another_mode_passes_its_link_too() {
    let d = tempfile::tempdir().unwrap();
    let uart = shared("modes-auto");
    let p = pins(&uart, 24, &[], "touch:T0@8-12");
    captures_after_the_switch_pass(&uart, &p, d.path());
    // the UART line idle for two slices after the join: packets go missing
    let (s, f) = (&uart, uart.grid.frame_cycles);
    let from = switch_frames(s, &p, 0)[0] * f + f / 3;
    let mut bad = p.clone();
    let at = (from + f / 2) as usize;
    for q in &mut bad[at..at + 2 * s.grid.slice_cycles as usize] {
        q.0.link_tx = true;
    }
    let out = d.path().join("bad.vcd");
    let r = judged(s, &bad, (from, 24 * f), 3_210, (false, true), &out).unwrap();
    assert!(!r.ok, "{}", r.summary());
    assert!(
        r.violations.iter().any(|v| v.rule.contains("link")),
        "{}",
        r.summary()
    );
}

#[test]
#[ignore = "long: make test-long (the AXI4-Stream form of the mix)"]
fn a_capture_beginning_in_another_mode_passes_its_axi_stream_link_too() {
    let text = std::fs::read_to_string(root().join("testkit/mixes/modes-auto.toml")).unwrap();
    let text = text.replace(
        "kind = \"uart\"\nbaud = 2_000_000",
        "kind = \"axis\"\ntlast = \"slice\"\nready_within = 8",
    );
    let d = tempfile::tempdir().unwrap();
    let axis_file = d.path().join("modes-auto-axis.toml");
    std::fs::write(&axis_file, text).unwrap();
    let axis = schedule(&axis_file);
    assert_eq!(axis.mix.link.as_ref().unwrap().kind.name(), "axis");
    let p = pins(&axis, 24, &[], "touch:T0@8-12");
    captures_after_the_switch_pass(&axis, &p, d.path());
}

/// Captures of `p` (24 frames of `s` under the touch) from four cycles
/// after its first switch pass, the link joined by the model.
fn captures_after_the_switch_pass(s: &Schedule, p: &[(Pins, u64)], d: &Path) {
    let f = s.grid.frame_cycles;
    let sw = switch_frames(s, p, 0);
    assert!(sw.len() >= 2, "the touch switches and back: {sw:?}");
    let starts = [
        sw[0] * f + f / 3,
        sw[0] * f + 1_234,
        (sw[0] + 1) * f + 777,
        sw[1] * f - f / 2,
    ];
    for (k, from) in starts.into_iter().enumerate() {
        let out = d.join(format!("c{k}.vcd"));
        let r = judged(s, p, (from, 24 * f), 3_210, (false, true), &out).unwrap();
        let said = r.summary();
        assert!(
            r.ok,
            "{} from cycle {from}: {said}",
            s.mix.link.as_ref().unwrap().kind.name()
        );
        let j = r.link_join.as_ref().expect("the link joined");
        assert_eq!(j.by, "model", "{said}");
        assert!(
            said.contains("start bits within") || said.contains("held to the model"),
            "{said}"
        );
    }
}
