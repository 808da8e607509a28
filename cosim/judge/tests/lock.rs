//! Captures that do not start at reset: the judge finds the frame phase from
//! the pins, says where, and checks every later cycle strictly.

use std::path::Path;

use judge::write_run;
use judge::{CheckOptions, LockError, VcdError};
use judge::{Dut, ModelDut, RunOptions};
use judge::{FaultyDut, PinFault};

fn tiny() -> lut_gen::Schedule {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/tiny.toml");
    lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap()
}

/// A VCD of cycles `[from, to)` (counted from the first reset cycle) of a run.
fn window<D: Dut>(s: &lut_gen::Schedule, dut: &mut D, from: u64, to: u64, path: &Path) {
    let frames = to / s.grid.frame_cycles + 1;
    write_run(path, s, dut, frames, &RunOptions::default(), (from, to)).unwrap();
}

fn check(s: &lut_gen::Schedule, p: &Path) -> Result<(judge::Verdict, judge::VcdInfo), VcdError> {
    judge::check_vcd_with(s, p, None, CheckOptions::default())
}

#[test]
fn window_from_mid_frame_locks_and_passes() {
    let s = tiny();
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("w.vcd");
    // Frames are 4000 cycles; the window starts in the middle of frame 1.
    window(&s, &mut ModelDut::new(&s), 5_317, 13_000, &p);
    let (r, info) = check(&s, &p).unwrap();
    assert!(r.ok, "{}", r.summary());
    let lock = info.lock.expect("locked mid-stream");
    assert!(
        lock.checked_from <= lock.locked_at + s.grid.slot_cycles,
        "{lock}"
    );
    // Everything after the join point is checked, whole frames included.
    assert_eq!(r.cycles + lock.checked_from, 13_000 - 5_317, "{lock}");
    assert_eq!(r.frames, 1, "{}", r.summary());
    assert!(r.samples > 10);
    // The frame cycle it names is the truth: capture cycle c is run cycle 5317 + c
    // (after 1 reset cycle... the window counts from the first reset cycle).
    let reset = judge::reset_cycles(&s, RunOptions::default().reset_cycles);
    let run_cycle = 5_317 + lock.locked_at - reset;
    assert_eq!(lock.frame_cycle, run_cycle % s.grid.frame_cycles, "{lock}");
}

#[test]
fn fault_inside_the_window_fails_at_its_cycle() {
    let s = tiny();
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("bad.vcd");
    let mut dut = FaultyDut::new(
        &s,
        ModelDut::new(&s),
        PinFault::MuxLate { branch: 0 },
        9_000,
    );
    window(&s, &mut dut, 5_317, 13_000, &p);
    let (r, info) = check(&s, &p).unwrap();
    assert!(!r.ok);
    assert!(info.lock.is_some());
    let dv = &r.divergences[0];
    assert!(dv.signal.starts_with("mux"), "{dv:?}");
    // Capture cycles: the fault is near run cycle 9000, window cycle ~3683.
    assert!(
        (3_000..4_800).contains(&dv.cycle),
        "divergence at capture cycle {}",
        dv.cycle
    );
    assert!(
        r.violations.iter().any(|v| v.rule == "mux-settle"),
        "{}",
        r.summary()
    );
}

#[test]
fn a_short_window_names_the_phases_it_cannot_tell_apart() {
    let s = tiny();
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("short.vcd");
    // One CS fall, at a slot start, and nothing else: two slots of the
    // frame fit it and predict the same pins throughout; the report says so.
    window(&s, &mut ModelDut::new(&s), 4_990, 5_005, &p);
    let (r, info) = check(&s, &p).unwrap();
    assert!(r.ok, "{}", r.summary());
    let lock = info.lock.unwrap();
    assert_eq!(lock.phases, 2, "{lock}");
    assert!(lock.to_string().contains("2 phases"), "{lock}");
    // Nothing changes at all: no phase can be found (an input problem).
    window(&s, &mut ModelDut::new(&s), 4_900, 4_950, &p);
    match check(&s, &p) {
        Err(VcdError::Phase { error, .. }) => {
            assert!(matches!(error, LockError::NoChanges { .. }), "{error}");
            assert!(
                error.to_string().contains("phase cannot be found"),
                "{error}"
            );
        }
        other => panic!("expected no phase, got {:?}", other.map(|r| r.0.ok)),
    }
}

#[test]
fn pins_that_fit_no_phase_are_an_input_problem() {
    let s = tiny();
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("w.vcd");
    window(&s, &mut ModelDut::new(&s), 5_317, 9_000, &p);
    // Another mix's pins: the same ports, every mux select bit 0 inverted.
    let t = std::fs::read_to_string(&p).unwrap();
    let sel_id = t
        .lines()
        .find(|l| l.contains(" mux_sel ") && l.starts_with("$var"))
        .and_then(|l| l.split_whitespace().nth(3))
        .unwrap()
        .to_string();
    let q = d.path().join("other.vcd");
    let body: String = t
        .lines()
        .map(|l| match l.strip_suffix(&format!(" {sel_id}")) {
            Some(v) if l.starts_with('b') => {
                let mut bits: Vec<u8> = v[1..].bytes().collect();
                let last = bits.len() - 1;
                bits[last] ^= 1;
                format!("b{} {sel_id}\n", String::from_utf8(bits).unwrap())
            }
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::write(&q, body).unwrap();
    match check(&s, &q) {
        Err(VcdError::Phase { error, .. }) => {
            assert!(matches!(error, LockError::Impossible { .. }), "{error}")
        }
        other => panic!("expected no phase, got {:?}", other.map(|r| r.0.ok)),
    }
}

#[test]
fn a_window_from_reset_is_checked_from_reset() {
    let s = tiny();
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("w.vcd");
    window(&s, &mut ModelDut::new(&s), 0, 8_000, &p);
    let (r, info) = check(&s, &p).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert!(info.lock.is_none());
}

#[test]
fn a_window_without_clock_or_reset_is_checked() {
    let s = tiny();
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("w.vcd");
    window(&s, &mut ModelDut::new(&s), 5_317, 13_000, &p);
    // Drop `clk` and `rst` (codes `!` and `"` in slotforge's VCDs).
    let t = std::fs::read_to_string(&p).unwrap();
    let q = d.path().join("bare.vcd");
    let kept: String = t
        .lines()
        .filter(|l| {
            !matches!(*l, "0!" | "1!" | "0\"" | "1\"")
                && !l.contains(" clk ")
                && !l.contains(" rst ")
        })
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&q, kept).unwrap();
    let (r, info) = check(&s, &q).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert!(!info.clock_dumped);
    assert!(info.lock.is_some());
    assert!(r.cycles > 7_000, "{}", r.summary());
}

/// A window from the middle of a run of a UART mix, checked with the model
/// off (`check --no-model`): the line's decode joins in step at the first
/// good packet and passes clean; each of the line faults inside the window
/// fails it on a `link-*` rule, after the fault.
#[test]
fn uart_line_in_a_window_is_judged_without_the_model() {
    let s = crate::model_check::tiny_uart();
    let d = tempfile::tempdir().unwrap();
    let (from, to, at) = (5_317, 17_000, 9_000);
    let opts = CheckOptions {
        model: false,
        ..Default::default()
    };
    // clean, joined wherever the window opens: inside a character, inside
    // a packet, between packets
    for start in (0..6).map(|k| from + 653 * k) {
        let p = d.path().join("clean.vcd");
        window(&s, &mut ModelDut::new(&s), start, to, &p);
        let (r, info) = judge::check_vcd_with(&s, &p, None, opts).unwrap();
        assert!(info.lock.is_some());
        assert!(r.ok && !r.model_compared, "from {start}: {}", r.summary());
    }
    for f in [
        PinFault::LinkBitFlip,
        PinFault::LinkDropByte,
        PinFault::LinkStuck { high: true },
        PinFault::LinkStuck { high: false },
    ] {
        let p = d.path().join(format!("{}.vcd", f.class()));
        let mut dut = FaultyDut::new(&s, ModelDut::new(&s), f, at);
        window(&s, &mut dut, from, to, &p);
        let (r, _) = judge::check_vcd_with(&s, &p, None, opts).unwrap();
        let class = f.class();
        eprintln!("{class}: {}", r.summary());
        assert!(!r.ok, "{class}: not caught");
        for v in &r.violations {
            // capture cycles: the fault is at window cycle at - from (+ reset)
            assert!(
                v.rule.starts_with("link-") && v.cycle + from >= at,
                "{class}: {v:?}"
            );
        }
    }
}

/// Every cycle a message of a window's check names is a capture cycle, as
/// its header is: the instants and conversions a detail refers to lie before
/// the violation, inside the capture (the model's own cycles would lie a
/// frame or more after it).
#[test]
fn a_windows_messages_count_cycles_from_the_capture() {
    let s = tiny();
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("bad.vcd");
    for fault in [
        PinFault::WrongMux { branch: 0 },
        PinFault::PhaseShift { branch: 0 },
    ] {
        let mut dut = FaultyDut::new(&s, ModelDut::new(&s), fault, 9_000);
        window(&s, &mut dut, 5_317, 17_000, &p);
        let (r, _) = check(&s, &p).unwrap();
        assert!(!r.ok, "{fault:?}");
        let cited = regex_lite_cycles(&r.summary());
        assert!(!cited.is_empty(), "{}", r.summary());
        for (at, named) in cited {
            assert!(
                named <= at,
                "{fault:?}: cycle {named} named at cycle {at}: {}",
                r.summary()
            );
        }
    }
}

/// (violation cycle, each `cycle N` its detail names) from a summary's
/// `violation: cycle C (...): ...` lines.
fn regex_lite_cycles(summary: &str) -> Vec<(u64, u64)> {
    let mut out = Vec::new();
    for line in summary.lines() {
        let Some(rest) = line.strip_prefix("violation: cycle ") else {
            continue;
        };
        let at: u64 = rest.split(' ').next().unwrap().parse().unwrap();
        let detail = rest.split_once("): ").map_or("", |x| x.1);
        for part in detail.split("cycle ").skip(1) {
            let n: String = part.chars().take_while(char::is_ascii_digit).collect();
            if let Ok(n) = n.parse() {
                out.push((at, n));
            }
        }
    }
    out
}
