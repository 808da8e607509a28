//! The gateware switches modes (docs/timing.md, "Mode switches"): a mix
//! with modes runs on the rust-hdl and Verilator back ends under `mode_sel`
//! requests or a touch scene, judged cycle by cycle against the model, and
//! each frame's per-channel counts are those of the mode `mode` shows.

use engines::{Backend, SimOptions, Stimulus, VerilatedDut};
use judge::{Dut, Observer};
use lut_gen::{Pins, Schedule};
use testkit::modemix::random_mode_mix;

fn schedule_of(text: &str, name: &str) -> Option<Schedule> {
    let path =
        std::env::temp_dir().join(format!("engines-modes-{name}-{}.toml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let s = lut_gen::load(&path)
        .ok()
        .and_then(|m| lut_gen::synthesize(&m).ok());
    let _ = std::fs::remove_file(&path);
    s
}

fn schedule(name: &str) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(&testkit::mix(name)).unwrap()).unwrap()
}

/// Per frame: the `mode` pin at its first cycle and each channel's samples.
#[derive(Default)]
struct Counts {
    frame_cycles: u64,
    channels: usize,
    frames: Vec<(u8, Vec<u64>)>,
}

impl Counts {
    fn new(s: &Schedule) -> Counts {
        Counts {
            frame_cycles: s.grid.frame_cycles,
            channels: s.channels.len(),
            frames: vec![],
        }
    }
}

/// Runs `dut` under `requests` and `stimulus`, judged; returns the verdict
/// and the per-frame modes and counts.
fn run(
    s: &Schedule,
    dut: &mut dyn Dut,
    frames: u64,
    requests: &[(u64, u8)],
    stimulus: Stimulus,
) -> (judge::Verdict, Vec<(u8, Vec<u64>)>) {
    let mut rec = Recorder {
        c: 0,
        counts: Counts::new(s),
    };
    let ro = judge::RunOptions {
        stimulus,
        ..Default::default()
    };
    let mut dut = judge::ModeRequests::new(s, dut, requests);
    let v = judge::run_dut(s, &mut dut, frames, &ro, "test", Some(&mut rec));
    (v, rec.counts.frames)
}

/// Counts every cycle after reset (the cycle number the observer is given
/// counts the reset cycles too).
struct Recorder {
    c: u64,
    counts: Counts,
}

impl Observer for Recorder {
    fn cycle(&mut self, _cycle: u64, rst: bool, pins: &Pins, _miso: u64) {
        if rst {
            return;
        }
        let k = &mut self.counts;
        if self.c.is_multiple_of(k.frame_cycles) {
            k.frames.push((pins.mode, vec![0; k.channels]));
        }
        if pins.sample_valid {
            k.frames.last_mut().unwrap().1[pins.sample_channel as usize] += 1;
        }
        self.c += 1;
    }
}

/// Each frame after the first (the start-up skip; a sample can leave the
/// merger a few cycles into the next frame, so the counts are over frames
/// whose mode and the one before agree) samples each channel as its mode.
fn counts_follow_modes(s: &Schedule, frames: &[(u8, Vec<u64>)], what: &str) {
    for (f, (mode, counts)) in frames.iter().enumerate().skip(2) {
        if frames[f - 1].0 != *mode || f + 1 < frames.len() && frames[f + 1].0 != *mode {
            continue;
        }
        let ms = &s.modes[*mode as usize];
        for (c, &n) in counts.iter().enumerate() {
            assert_eq!(
                n, ms.channels[c].samples_per_frame,
                "{what}: frame {f} (mode {mode}): {} sampled {n} times",
                s.mix.channels[c].name
            );
        }
    }
}

/// The mode of each frame the contract decides from requests shown from
/// the first cycle of their frame (in force two frames later).
fn expected(s: &Schedule, requests: &[(u64, u8)], frames: u64) -> Vec<u8> {
    let mut modes = vec![0u8; frames as usize];
    for f in 2..frames {
        let shown = requests.iter().rfind(|r| r.0 <= f - 2).map_or(0, |r| r.1);
        modes[f as usize] = if (shown as usize) < s.modes.len() {
            shown
        } else {
            modes[f as usize - 1]
        };
    }
    modes
}

#[test]
fn pin_select_switches_on_rusthdl_and_verilator_with_each_modes_counts() {
    let s = schedule("modes-pin");
    let req = [(1, 1), (4, 0), (5, 1), (6, 0), (8, 0), (9, 1)];
    let frames = 13;
    let want = expected(&s, &req, frames);
    let mut runs = vec![];
    let mut rtl = engines::RustHdlDut::new(&s).unwrap();
    runs.push((
        "rusthdl",
        run(&s, &mut rtl, frames, &req, Stimulus::Pattern),
    ));
    let (mut ver, _) = VerilatedDut::new(&engines::verilog(&s).unwrap()).unwrap();
    runs.push((
        "verilator",
        run(&s, &mut ver, frames, &req, Stimulus::Pattern),
    ));
    for (what, (v, got)) in &runs {
        assert!(v.ok, "{what}: {}", v.summary());
        let modes: Vec<u8> = got.iter().map(|f| f.0).collect();
        assert_eq!(modes, want, "{what}: the mode of each frame");
        counts_follow_modes(&s, got, what);
    }
    assert!(want.contains(&1) && want.contains(&0));
    assert_eq!(runs[0].1 .1, runs[1].1 .1, "rusthdl and verilator agree");
}

#[test]
fn auto_select_switches_to_contact_and_back_under_touch() {
    let s = schedule("modes-auto");
    let touch = Stimulus::parse_for("touch:T0@2-12", &s).unwrap();
    let frames = 22;
    let mut rtl = engines::RustHdlDut::new(&s).unwrap();
    let (v, got) = run(&s, &mut rtl, frames, &[], touch);
    assert!(v.ok, "{}", v.summary());
    let modes: Vec<u8> = got.iter().map(|f| f.0).collect();
    // touched from frame 2: its window decides frame 4 (touch); T0 still up
    // for 3 frames of touch: hold; released at 12: below 2000 for 2 frames
    let first = |m: u8| modes.iter().position(|&x| x == m);
    assert_eq!(first(1), Some(4), "{modes:?}");
    assert_eq!(first(2), Some(8), "{modes:?}");
    assert_eq!(*modes.last().unwrap(), 0, "{modes:?}");
    assert!(modes[..4].iter().all(|&m| m == 0), "{modes:?}");
    counts_follow_modes(&s, &got, "rusthdl");
    let (mut ver, _) = VerilatedDut::new(&engines::verilog(&s).unwrap()).unwrap();
    let (vv, gv) = run(&s, &mut ver, frames, &[], touch);
    assert!(vv.ok, "verilator: {}", vv.summary());
    assert_eq!(gv, got, "rusthdl and verilator agree");
}

/// Converters with a command word in mode mixes (an MCP3208 whose rate
/// changes, an AD7689 whose word selects the conversion after next, a
/// listening AD7940): under pin requests and under a touch of the AD7689's
/// watched channel, rust-hdl and Verilator switch as the model decides and
/// pass it in every cycle (the AD7689's words across a switch, the
/// model's words after one, and a trigger window that saw the AD7689's
/// prepared conversions were each wrong).
#[test]
fn command_word_converters_switch_modes_on_rusthdl_and_verilator() {
    for (name, req, stim) in [
        ("cmd-modes", vec![(1, 1), (4, 0)], "pattern"),
        ("cmd-modes-auto", vec![], "touch:C7@1-3"),
        // two conversions a frame in `rest`, the first at slot 0: its word
        // selects `busy`'s first conversion of frame 3, decided as frame 2
        // begins (the ROM's field, loaded a slot earlier, had `rest`'s)
        ("cmd-ahead-modes", vec![(1, 1), (4, 0)], "pattern"),
    ] {
        let s = schedule(name);
        let stim = Stimulus::parse_for(stim, &s).unwrap();
        // both mixes run frames 3 to 5 in mode 1 and are back in mode 0
        // from frame 6: its seventh frame is the last the test needs
        let frames = 7;
        let mut rtl = engines::RustHdlDut::new(&s).unwrap();
        let (v, got) = run(&s, &mut rtl, frames, &req, stim);
        assert!(v.ok, "{name} rusthdl: {}", v.summary());
        let modes: Vec<u8> = got.iter().map(|f| f.0).collect();
        assert!(
            modes.contains(&1) && modes[0] == 0 && *modes.last().unwrap() == 0,
            "{name}: {modes:?}"
        );
        counts_follow_modes(&s, &got, name);
        let (mut ver, _) = VerilatedDut::new(&engines::verilog(&s).unwrap()).unwrap();
        let (vv, gv) = run(&s, &mut ver, frames, &req, stim);
        assert!(vv.ok, "{name} verilator: {}", vv.summary());
        assert_eq!(gv, got, "{name}: rusthdl and verilator agree");
    }
}

#[test]
fn random_mode_mixes_switch_on_rusthdl_as_the_model_decides() {
    let (mut ran, mut holds) = ((0, 0), 0);
    for seed in 1..30u64 {
        let Some(text) = random_mode_mix(seed) else {
            continue;
        };
        let Some(s) = schedule_of(&text, &seed.to_string()) else {
            continue;
        };
        let Ok(mut dut) = engines::RustHdlDut::new(&s) else {
            panic!("seed {seed}: the gateware refuses\n{text}");
        };
        let n = s.modes.len() as u64;
        let frames = 10;
        let auto = s.mode_plan().unwrap().select == lut_gen::ModeSelect::Auto;
        let (req, stim) = if auto {
            (vec![], Stimulus::parse_for("touch:c0@1-4", &s).unwrap())
        } else {
            // values up to the pin's width: one names no mode with 3 modes
            let top = 1u64 << s.mode_plan().unwrap().select_bits();
            let r: Vec<(u64, u8)> = (0..frames)
                .map(|f| (f, ((seed * 5 + f * f) % top.max(n)) as u8))
                .collect();
            (r, Stimulus::Pattern)
        };
        let (v, got) = run(&s, &mut dut, frames, &req, stim);
        assert!(v.ok, "seed {seed}: {}\n{text}", v.summary());
        let modes: Vec<u8> = got.iter().map(|f| f.0).collect();
        if auto {
            assert!(
                modes.iter().any(|&m| m != 0),
                "seed {seed}: never left m0: {modes:?}\n{text}"
            );
            ran.1 += 1;
        } else {
            assert_eq!(modes, expected(&s, &req, frames), "seed {seed}\n{text}");
            ran.0 += 1;
        }
        counts_follow_modes(&s, &got, &format!("seed {seed}"));
        // a mode that leaves a branch out: its mux holds, then moves to
        // the first instant of a later mode that uses it
        let idle = |m: &Schedule, b: usize| (0..m.grid.frame_slots).all(|u| m.at(u, b).is_none());
        if (0..s.branches.len()).any(|b| s.modes.iter().any(|m| idle(m, b))) {
            holds += 1;
        }
    }
    assert!(ran.0 >= 4 && ran.1 >= 4, "pin and auto mixes run: {ran:?}");
    assert!(holds >= 2, "{holds} mixes leave a branch out of a mode");
}

#[test]
fn sim_options_carry_requests_to_every_in_process_back_end() {
    let s = schedule("modes-pin");
    let opts = SimOptions {
        modes: vec![(1, 1), (5, 0)],
        ..SimOptions::default()
    };
    for b in [Backend::RustHdl, Backend::Verilator, Backend::Icarus] {
        let v = engines::run(&s, b, 9, &opts).unwrap();
        assert!(v.ok, "{b:?}: {}", v.summary());
    }
}

/// Icarus, through its VCD (the mode pins read back), samples the same as
/// the in-process back ends: under pin requests, and under a touch that
/// switches an auto mix (the testbench's codes follow the model's modes).
/// The runs end two frames after the last request and after the touch
/// (Icarus is the slow engine: each frame counts).
#[test]
fn icarus_follows_requests_and_a_touch_like_the_in_process_back_ends() {
    let count = |s: &Schedule, b: Backend, opts: &SimOptions, frames: u64| {
        let mut log = judge::SampleLog::new();
        let v = engines::run_observed(s, b, frames, opts, Some(&mut log)).unwrap();
        assert!(v.ok, "{} {b:?}: {}", s.mix.name, v.summary());
        let rows: Vec<(u64, u16, u16)> = log
            .samples
            .iter()
            .map(|x| (x.cycle, x.channel, x.value))
            .collect();
        rows
    };
    let pin = schedule("modes-pin");
    let opts = SimOptions {
        modes: vec![(1, 1), (4, 0), (5, 1)],
        ..SimOptions::default()
    };
    assert_eq!(
        count(&pin, Backend::Icarus, &opts, 7),
        count(&pin, Backend::RustHdl, &opts, 7)
    );
    // a touch of two frames in 8: rest, touch from frame 4, and rest again
    // in frame 7 after two frames below the trigger (Icarus runs 8,000
    // cycles a frame of modes-auto; a touch of seven frames in 12, which
    // never left touch, took half as long again)
    let auto = schedule("modes-auto");
    let opts = SimOptions {
        stimulus: Stimulus::parse_for("touch:T1@2-4", &auto).unwrap(),
        ..SimOptions::default()
    };
    let (i, r) = (
        count(&auto, Backend::Icarus, &opts, 8),
        count(&auto, Backend::RustHdl, &opts, 8),
    );
    assert_eq!(i, r);
    // more than 8 frames at rest (9 a frame) would give
    assert!(r.len() > 8 * 9 + 20, "{}", r.len());
    let in_frame = |f: u64| {
        let c = auto.grid.frame_cycles;
        r.iter().filter(|x| x.0 / c == f).count()
    };
    assert!(in_frame(7) < in_frame(5), "back to rest in frame 7: {r:?}");
}

/// A new user's mix whose second mode leaves branch `y` out: its mux holds
/// through the frames of `b`, and moves to `a`'s first instant in the
/// second cycle of the frame before `a` returns (the frame start decides it).
const HOLD: &str = r#"name = "hold"
[clock]
hz = 4_000_000
[frame]
period_us = 1_000
slice_us = 500
[[mode]]
name = "a"
[[mode]]
name = "b"
[modes]
select = "pin"
[[branch]]
name = "x"
adc = "ad7940"
mux = "tmux1108"
mux_devices = 1
settle_ns = 1_000
[[branch]]
name = "y"
adc = "ad7940"
mux = "tmux1108"
mux_devices = 2
settle_ns = 1_000
[[channel]]
name = "X0"
branch = "x"
rate_hz = 2_000
[[channel]]
name = "Y0"
branch = "y"
rate_hz = 1_000
input = 3
rates = { b = 0 }
[[channel]]
name = "Y1"
branch = "y"
rate_hz = 1_000
input = 12
rates = { b = 0 }
"#;

#[test]
fn a_branch_a_mode_leaves_out_holds_its_mux_then_moves_on_both_engines() {
    let s = schedule_of(HOLD, "hold").unwrap();
    let req = [(1, 1), (3, 0), (4, 1), (5, 0)];
    let frames = 10;
    let want = expected(&s, &req, frames);
    let mut rtl = engines::RustHdlDut::new(&s).unwrap();
    let (v, got) = run(&s, &mut rtl, frames, &req, Stimulus::Pattern);
    assert!(v.ok, "rusthdl: {}", v.summary());
    assert_eq!(got.iter().map(|f| f.0).collect::<Vec<_>>(), want);
    let (mut ver, _) = VerilatedDut::new(&engines::verilog(&s).unwrap()).unwrap();
    let (vv, gv) = run(&s, &mut ver, frames, &req, Stimulus::Pattern);
    assert!(vv.ok, "verilator: {}", vv.summary());
    assert_eq!(gv, got);
}
