//! The reference model follows mode switches (docs/timing.md, "Mode
//! switches"): driven with `mode_sel` requests, every frame samples each
//! channel as often as its frame's mode says, and the switch lands two
//! frames after the frame whose last cycle showed the request.  Counted
//! from the pins alone (CS falls and the mux address at each), not from
//! the model's tables.

use judge::{Adc, CycleModel, Layout, Stimulus};
use lut_gen::Schedule;
use testkit::modemix::{random_pin_mode_mix, PinShape};

fn schedule(path: &std::path::Path) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(path).unwrap()).unwrap()
}

/// `mode_sel` in cycle `c`: the last request at or before `c`'s frame.
fn sel_at(requests: &[(u64, u8)], f: u64) -> u8 {
    requests
        .iter()
        .rfind(|&&(rf, _)| rf <= f)
        .map_or(0, |&(_, m)| m)
}

/// Runs `frames` frames of the model with `requests` on `mode_sel`;
/// returns, per frame, the `mode` pin at its first cycle and the CS falls
/// per channel.
fn run(s: &Schedule, frames: u64, requests: &[(u64, u8)]) -> Vec<(u8, Vec<u64>)> {
    run_with(s, frames, requests, Stimulus::Pattern)
}

fn run_with(
    s: &Schedule,
    frames: u64,
    requests: &[(u64, u8)],
    stimulus: Stimulus,
) -> Vec<(u8, Vec<u64>)> {
    let f = s.grid.frame_cycles;
    let layout = Layout::new(s);
    let mut adc = Adc::new(s, stimulus);
    let mut m = CycleModel::new(s);
    let mut out: Vec<(u8, Vec<u64>)> = Vec::new();
    let mut prev_cs = m.pins().cs_n;
    let mut miso;
    for c in 0..frames * f {
        let p = *m.pins();
        if c % f == 0 {
            out.push((p.mode, vec![0; s.channels.len()]));
        } else {
            assert_eq!(
                p.mode,
                out.last().unwrap().0,
                "mode changed inside a frame at cycle {c}"
            );
        }
        for b in 0..s.branches.len() {
            if prev_cs >> b & 1 == 1 && p.cs_n >> b & 1 == 0 {
                let ch = (0..s.channels.len())
                    .filter(|&k| s.mix.channels[k].branch == b)
                    .find(|&k| {
                        let mut q = p;
                        let cs = &s.channels[k];
                        layout.set_mux(&mut q, b, cs.device, cs.select);
                        q == p
                    })
                    .expect("the mux addresses a channel of the branch");
                out.last_mut().unwrap().1[ch] += 1;
            }
        }
        prev_cs = p.cs_n;
        miso = adc.drive(c, &p);
        m.set_mode_sel(sel_at(requests, c / f));
        m.step(miso);
    }
    out
}

/// The mode frame `g` must run in under `requests` (pin select).
fn expected_mode(s: &Schedule, requests: &[(u64, u8)], g: u64) -> usize {
    let n = s.modes.len();
    let mut mode = 0;
    for h in 2..=g {
        let v = sel_at(requests, h - 2) as usize;
        if v < n {
            mode = v;
        }
    }
    mode
}

fn check(s: &Schedule, frames: u64, requests: &[(u64, u8)]) {
    let got = run(s, frames, requests);
    for (g, (mode, counts)) in got.iter().enumerate() {
        let want = expected_mode(s, requests, g as u64);
        assert_eq!(*mode as usize, want, "frame {g}: mode pin");
        if g == 0 {
            continue; // the start-up skip
        }
        let ms = &s.modes[want];
        for (c, &n) in counts.iter().enumerate() {
            assert_eq!(
                n, ms.channels[c].samples_per_frame,
                "frame {g} (mode {want}): {} sampled {n} times",
                s.mix.channels[c].name
            );
        }
    }
}

#[test]
fn pin_requests_switch_two_frames_later_with_each_modes_counts() {
    let s = schedule(&testkit::mix("modes-pin"));
    check(&s, 12, &[(2, 1), (5, 0), (6, 1), (9, 3), (10, 0)]);
    // a request held for one frame only, and one that names no mode
    check(&s, 8, &[(1, 1), (2, 0), (4, 2)]);
}

/// `text` with its triggers dropped and modes chosen by the pin.
fn as_pin_select(text: &str) -> String {
    let mut out = String::new();
    let mut skip = false;
    for line in text.lines() {
        if line.starts_with('[') {
            skip = line.trim() == "[[trigger]]";
        }
        if !skip {
            out.push_str(&line.replace("select = \"auto\"", "select = \"pin\""));
            out.push('\n');
        }
    }
    out
}

#[test]
fn random_request_sequences_on_pin_mode_mixes() {
    let mut x = 0x2545_f491_4f6c_dd1du64;
    let dir = std::env::temp_dir();
    for name in ["modes-pin", "modes-auto", "eskin34-adaptive"] {
        let text = std::fs::read_to_string(testkit::mix(name)).unwrap();
        let path = dir.join(format!("judge-modes-{name}-{}.toml", std::process::id()));
        std::fs::write(&path, as_pin_select(&text)).unwrap();
        let s = schedule(&path);
        let _ = std::fs::remove_file(&path);
        let n = s.modes.len() as u64;
        for _ in 0..3 {
            let mut req = Vec::new();
            for f in 0..10 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                if x.is_multiple_of(3) {
                    req.push((f, (x / 3 % (n + 1)) as u8));
                }
            }
            check(&s, 10, &req);
        }
    }
}

/// One cycle of a recorded run: `rst`, the pins, `adc_miso`.
type Cycle = (bool, lut_gen::Pins, u64);

/// A run of the model under `requests`, every cycle recorded (4 reset cycles).
fn record(s: &Schedule, frames: u64, requests: &[(u64, u8)]) -> Vec<Cycle> {
    record_with(s, frames, requests, Stimulus::Pattern)
}

fn record_with(
    s: &Schedule,
    frames: u64,
    requests: &[(u64, u8)],
    stimulus: Stimulus,
) -> Vec<Cycle> {
    use judge::Dut;
    let mut dut = judge::ModeRequests::new(s, judge::ModelDut::new(s), requests);
    let mut adc = Adc::new(s, stimulus);
    let mut out = Vec::new();
    let mut miso = (1u64 << s.branches.len()) - 1;
    for _ in 0..4 {
        let p = dut.step(true, miso);
        miso = adc.drive(0, &p);
        out.push((true, p, miso));
    }
    for c in 0..frames * s.grid.frame_cycles {
        let p = dut.step(false, miso);
        miso = adc.drive(c, &p);
        out.push((false, p, miso));
    }
    out
}

fn judge_trace(s: &Schedule, trace: &[Cycle], model: bool) -> judge::Verdict {
    let mut chk = judge::Checker::new(
        s,
        judge::CheckOptions {
            model,
            ..Default::default()
        },
    );
    for (rst, p, miso) in trace {
        chk.cycle(*rst, p, *miso);
    }
    chk.finish("trace")
}

fn first_violation(v: &judge::Verdict, rule: &str) -> Option<u64> {
    v.violations
        .iter()
        .filter(|x| x.rule == rule)
        .map(|x| x.cycle)
        .min()
}

fn pin_schedule() -> Schedule {
    schedule(&testkit::mix("modes-pin"))
}

#[test]
fn a_clean_switching_run_passes_with_and_without_the_model() {
    let s = pin_schedule();
    let trace = record(&s, 10, &[(2, 1), (5, 0)]);
    for model in [true, false] {
        let v = judge_trace(&s, &trace, model);
        assert!(v.ok, "model {model}: {}", v.summary());
    }
}

#[test]
fn mode_sel_altered_at_a_frame_boundary_fails_two_frames_later() {
    let s = pin_schedule();
    let f = s.grid.frame_cycles;
    let trace = record(&s, 10, &[(2, 1), (5, 0)]);
    // The request for `slow` shown from frame 2 on: withdraw it in the last
    // cycle of frame 3, so frame 5 must run `fast` again, which the design
    // (deciding on what it saw) does not.
    let mut bad = trace.clone();
    bad[4 + (4 * f - 1) as usize].1.mode_sel = 0;
    let v = judge_trace(&s, &bad, false);
    assert!(!v.ok);
    assert_eq!(
        first_violation(&v, "mode-decision"),
        Some(5 * f),
        "{}",
        v.summary()
    );
    let v = judge_trace(&s, &bad, true);
    assert!(!v.ok);
    let d = v
        .divergences
        .iter()
        .find(|d| d.signal == "mode")
        .expect("mode diverges");
    assert_eq!(d.cycle, 5 * f, "{}", v.summary());
}

#[test]
fn a_switch_inside_a_frame_or_without_a_request_fails_at_its_cycle() {
    let s = pin_schedule();
    let f = s.grid.frame_cycles;
    let trace = record(&s, 10, &[(2, 1), (5, 0)]);
    // `mode` already shows `slow` 3 cycles before frame 4 begins
    let mut early = trace.clone();
    for c in 4 * f - 3..4 * f {
        early[4 + c as usize].1.mode = 1;
    }
    for model in [false, true] {
        let v = judge_trace(&s, &early, model);
        assert_eq!(
            first_violation(&v, "mode-switch"),
            Some(4 * f - 3),
            "{}",
            v.summary()
        );
    }
    // a design that ignores the request: `mode` stays `fast` (its samples
    // then follow `fast` too, so the counts are `fast`'s)
    let ignored = record(&s, 10, &[]);
    let mut claimed = ignored.clone();
    for (k, (_, p, _)) in claimed.iter_mut().enumerate().skip(4) {
        p.mode_sel = trace[k].1.mode_sel;
    }
    let v = judge_trace(&s, &claimed, false);
    assert_eq!(
        first_violation(&v, "mode-decision"),
        Some(4 * f),
        "{}",
        v.summary()
    );
    // and one that switches with no request: the counts of its frames are
    // the mode it shows, but the mode is not the one decided
    let mut unasked = record(&s, 10, &[(2, 1)]);
    for (_, p, _) in unasked.iter_mut() {
        p.mode_sel = 0;
    }
    let v = judge_trace(&s, &unasked, false);
    assert_eq!(
        first_violation(&v, "mode-decision"),
        Some(4 * f),
        "{}",
        v.summary()
    );
    assert_eq!(
        first_violation(&v, "samples-per-frame"),
        None,
        "{}",
        v.summary()
    );
}

/// Auto select under a touch: the model leaves the reset mode two frames
/// after the touch begins (a one-frame `above` trigger on a channel sampled
/// in every frame), every frame's counts are its mode's, the run is clean
/// with and without the model, and the same pins with the mode claimed
/// before any touch fail at that frame.
#[test]
fn a_touch_switches_auto_mixes_and_back_with_each_modes_counts() {
    for (name, touched, from, to, frames) in [
        ("modes-auto", "T0,T2", 4u64, 14u64, 24u64),
        ("eskin34-adaptive", "CH7,CH11", 2, 5, 10),
    ] {
        let s = schedule(&testkit::mix(name));
        let f = s.grid.frame_cycles;
        let text = format!("touch:{touched}@{from}-{to}");
        let k = Stimulus::parse_for(&text, &s).unwrap();
        let got = run_with(&s, frames, &[], k);
        let modes: Vec<u8> = got.iter().map(|g| g.0).collect();
        assert!(
            modes[..(from + 2) as usize].iter().all(|&m| m == 0),
            "{name}: {modes:?}"
        );
        assert_ne!(modes[(from + 2) as usize], 0, "{name}: {modes:?}");
        for (g, (mode, counts)) in got.iter().enumerate().skip(1) {
            let ms = &s.modes[*mode as usize];
            for (c, &n) in counts.iter().enumerate() {
                assert_eq!(n, ms.channels[c].samples_per_frame, "{name} frame {g}");
            }
        }
        let trace = record_with(&s, frames, &[], k);
        for model in [true, false] {
            let v = judge_trace(&s, &trace, model);
            assert!(v.ok, "{name}, model {model}: {}", v.summary());
        }
        // the design claims the contact mode before any contact
        let mut unasked = trace.clone();
        let want = modes[(from + 2) as usize];
        for (_, p, _) in unasked.iter_mut().skip(4 + 2 * f as usize).take(f as usize) {
            p.mode = want;
        }
        let v = judge_trace(&s, &unasked, false);
        assert_eq!(
            first_violation(&v, "mode-decision"),
            Some(2 * f),
            "{name}: {}",
            v.summary()
        );
    }
}

#[test]
fn modes_auto_returns_to_rest_after_the_release() {
    let s = schedule(&testkit::mix("modes-auto"));
    let k = Stimulus::parse_for("stroke:T{0..3}@3-15", &s).unwrap();
    let got = run_with(&s, 30, &[], k);
    let modes: Vec<u8> = got.iter().map(|g| g.0).collect();
    let names = &s.mode_plan().unwrap().names;
    let seen: Vec<&str> = modes
        .iter()
        .enumerate()
        .filter(|&(g, m)| g == 0 || modes[g - 1] != *m)
        .map(|(_, &m)| names[m as usize].as_str())
        .collect();
    // rest, touched, T0 held for 3 frames (hold), the others (touch again
    // is not armed from hold), released: rest
    assert_eq!(seen.first(), Some(&"rest"), "{modes:?}");
    assert!(seen.contains(&"touch"), "{seen:?}");
    assert_eq!(seen.last(), Some(&"rest"), "{seen:?}");
    assert_eq!(*modes.last().unwrap(), 0);
}

#[test]
fn scenes_name_the_mixs_channels() {
    let s = schedule(&testkit::mix("modes-auto"));
    for bad in [
        "touch:T9@1-2",
        "touch:T0@2-1",
        "stroke:T0",
        "touch:T{0..}@1-3",
    ] {
        assert!(Stimulus::parse_for(bad, &s).is_err(), "{bad}");
    }
    assert!(Stimulus::parse_for("sine:600", &s).is_ok());
}

/// The random mixes: 2 or 3 modes (pin select), 2 branches and up to 10
/// channels at harmonic rates per mode (0: not sampled).
const RANDOM_MODES: PinShape = PinShape {
    header: "[clock]\nhz = 8_000_000\n[frame]\nperiod_us = 1_000\nslice_us = 500\n",
    mux_devices: 2,
    more_channels: 9,
};

#[test]
fn random_mode_mixes_follow_random_requests() {
    let dir = std::env::temp_dir();
    let mut ran = 0;
    for seed in 1..40u64 {
        let Some(text) = random_pin_mode_mix(seed, &RANDOM_MODES) else {
            continue;
        };
        let path = dir.join(format!(
            "judge-random-modes-{seed}-{}.toml",
            std::process::id()
        ));
        std::fs::write(&path, &text).unwrap();
        let s = lut_gen::load(&path)
            .ok()
            .and_then(|m| lut_gen::synthesize(&m).ok());
        let _ = std::fs::remove_file(&path);
        let Some(s) = s else {
            continue;
        };
        let n = s.modes.len() as u64;
        let req: Vec<(u64, u8)> = (0..8)
            .map(|f| (f, ((seed * 7 + f * f * 3) % (n + 1)) as u8))
            .collect();
        check(&s, 8, &req);
        let trace = record(&s, 8, &req);
        for model in [true, false] {
            let v = judge_trace(&s, &trace, model);
            assert!(v.ok, "seed {seed}, model {model}: {}\n{text}", v.summary());
        }
        ran += 1;
    }
    assert!(ran >= 10, "only {ran} random mixes scheduled");
}
