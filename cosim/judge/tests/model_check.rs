use judge::run::{run_dut, run_model, ModelDut, RunOptions};
use std::path::Path;

/// Every fault of `s` injected into the model at cycle `at` for two
/// frames: `judge` sees each one that changed something (a fault with
/// nothing to change there, e.g. no idle slot to move a conversion into,
/// was not injected); returns how many did.
fn each_injected_fault(
    s: &lut_gen::Schedule,
    at: u64,
    judge: impl Fn(&judge::faults::Fault, &judge::Report),
) -> usize {
    use judge::faults::{Fault, FaultyDut};
    let mut injected = 0;
    for f in Fault::all(s) {
        let mut dut = FaultyDut::new(s, ModelDut::new(s), f, at);
        let r = run_dut(s, &mut dut, 2, &RunOptions::default(), "faulty", None);
        if dut.injected() {
            injected += 1;
            judge(&f, &r);
        }
    }
    injected
}

fn eskin() -> lut_gen::Schedule {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../mixes/eskin34.toml");
    lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap()
}

#[test]
fn model_pins_pass_the_checker() {
    let s = eskin();
    let mut dut = ModelDut::new(&s);
    let r = run_dut(&s, &mut dut, 2, &RunOptions::default(), "model-dut", None);
    eprintln!("{}", r.summary());
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.frames, 2);
    assert_eq!(
        r.samples,
        2 * 349 - 3,
        "less the three instants skipped at start-up"
    );
}

#[test]
fn slot_model_passes() {
    let s = eskin();
    let r = run_model(&s, 100, judge::Stimulus::Pattern, 20);
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.samples, 100 * 349 - 3);
}

#[test]
fn every_fault_is_caught() {
    let s = eskin();
    let at = s.grid.frame_cycles / 2 + 7;
    let injected = each_injected_fault(&s, at, |f, r| {
        assert!(!r.ok, "fault {} not caught", f.name());
        assert!(r.divergence_count > 0, "fault {}: no divergence", f.name());
        assert!(
            r.violation_count > 0,
            "fault {}: no invariant violation\n{}",
            f.name(),
            r.summary()
        );
        let d = &r.divergences[0];
        assert!(
            d.cycle + 2 * s.grid.slot_cycles >= at,
            "fault {} first divergence at {}",
            f.name(),
            d.cycle
        );
        eprintln!(
            "{}: {} divergent cycles, {} violations; first: {} at {} ({:?}), rule {}",
            f.name(),
            r.divergence_count,
            r.violation_count,
            d.signal,
            d.cycle,
            d.channel,
            r.violations[0].rule
        );
    });
    // every class but the slot-moving ones lands on every branch
    let all = judge::faults::Fault::all(&s).len();
    assert!(injected + 3 >= all, "{injected} of {all}");
}

/// Drives the checker by hand: `reset` reset cycles, then `cycles` cycles of the model's pins.
fn check_by_hand(s: &lut_gen::Schedule, reset: u64, cycles: u64) -> judge::Report {
    check_by_hand_with(s, reset, cycles, 0)
}

/// Like `check_by_hand`, with branch 0's `mux_sel` wrong in the first
/// `wrong_mux` reset cycles (a mux that is not steady through reset).
fn check_by_hand_with(
    s: &lut_gen::Schedule,
    reset: u64,
    cycles: u64,
    wrong_mux: u64,
) -> judge::Report {
    use judge::run::Dut;
    let mut dut = ModelDut::new(s);
    let mut adc = judge::Adc::new(s, judge::Stimulus::Pattern);
    let mut chk = judge::Checker::new(s, judge::CheckOptions::default());
    let mut miso = (1u64 << s.branches.len()) - 1;
    for i in 0..reset {
        let mut p = dut.step(true, miso);
        if i < wrong_mux {
            p.mux_sel ^= 1;
        }
        miso = adc.drive(0, &p);
        chk.cycle(true, &p, miso);
    }
    for c in 0..cycles {
        let p = dut.step(false, miso);
        miso = adc.drive(c, &p);
        chk.cycle(false, &p, miso);
    }
    chk.finish("by-hand")
}

/// The start-up before docs/timing.md's "Start-up" rule: the model's
/// pins from frame 1 on, replayed from cycle 0, so every branch converts in
/// cycle 0 on the mux value it took in reset.
struct EagerStart {
    s: lut_gen::Schedule,
    reset: lut_gen::ports::Pins,
    m: Option<judge::CycleModel>,
}

impl judge::run::Dut for EagerStart {
    fn step(&mut self, rst: bool, miso: u64) -> lut_gen::ports::Pins {
        if rst {
            self.m = None;
            return self.reset;
        }
        match &mut self.m {
            None => {
                let mut m = judge::CycleModel::new(&self.s);
                for _ in 0..self.s.grid.frame_cycles {
                    m.step(0);
                }
                let p = *m.pins();
                self.m = Some(m);
                p
            }
            Some(m) => {
                m.step(miso);
                *m.pins()
            }
        }
    }
}

#[test]
fn no_reset_is_too_short_and_a_short_one_excuses_nothing() {
    let s = eskin();
    let f = s.grid.frame_cycles;
    let settle = s.branches[0].settle_cycles;
    assert_eq!(settle, 96, "2 us at 48 MHz");
    assert_eq!(
        judge::run::reset_cycles(&s, 1),
        1,
        "runs keep a short reset"
    );
    // The model skips the three instants of cycle 0 (docs/timing.md,
    // "Start-up"): any reset of one cycle or more passes, however the mux
    // moved during it.
    for reset in [1, 2, 6, settle - 1, settle, 200] {
        let r = check_by_hand(&s, reset, 2 * f);
        assert!(r.ok, "reset {reset}: {}", r.summary());
        assert_eq!(r.samples, 2 * 349 - 3);
        let r = check_by_hand_with(&s, reset + 4, 2 * f, 4);
        assert!(r.ok, "reset {reset} + 4, mux moving: {}", r.summary());
    }
    let mut dut = ModelDut::new(&s);
    let ro = RunOptions {
        reset_cycles: 1,
        ..RunOptions::default()
    };
    assert!(run_dut(&s, &mut dut, 1, &ro, "model-dut", None).ok);
    // A design that converts in cycle 0 on the mux value it took in reset
    // is flagged by the invariants (mux-settle), not only by the model, for
    // every reset shorter than the settling time.
    for reset in [1u64, 6, settle - 1] {
        let mut dut = EagerStart {
            reset: judge::CycleModel::new(&s).reset_pins(),
            s: s.clone(),
            m: None,
        };
        let ro = RunOptions {
            reset_cycles: reset,
            ..RunOptions::default()
        };
        let r = run_dut(&s, &mut dut, 2, &ro, "eager", None);
        assert!(!r.ok);
        let settles: Vec<_> = r
            .violations
            .iter()
            .filter(|v| v.rule == "mux-settle")
            .collect();
        assert_eq!(settles.len(), 3, "one per branch: {}", r.summary());
        for v in settles {
            assert_eq!(v.cycle, 0, "{}", r.summary());
            assert_eq!(v.actual, Some(serde_json::json!(reset)), "{}", v.detail);
            assert!(
                v.detail
                    .contains(&format!("held through {reset} reset cycles and 0 cycles")),
                "{}",
                v.detail
            );
        }
        assert!(r.divergence_count > 0);
    }
    // With a reset as long as the settling time the eager conversion is
    // physically settled: only the model objects.
    let mut dut = EagerStart {
        reset: judge::CycleModel::new(&s).reset_pins(),
        s: s.clone(),
        m: None,
    };
    let ro = RunOptions {
        reset_cycles: settle,
        ..RunOptions::default()
    };
    let r = run_dut(&s, &mut dut, 2, &ro, "eager", None);
    assert!(r.violations.iter().all(|v| v.rule != "mux-settle"));
    assert!(r.divergence_count > 0);
}

#[test]
fn partial_frames_are_reported_and_checked_for_their_samples() {
    let s = eskin();
    let f = s.grid.frame_cycles;
    let r = check_by_hand(&s, 96, f / 2);
    assert!(r.ok, "{}", r.summary());
    assert_eq!((r.frames, r.partial_frame_cycles), (0, f / 2));
    assert!(r.samples > 0 && r.samples < s.samples_per_frame());
    let per_channel: u64 = r.channels.iter().map(|c| c.samples).sum();
    assert!(per_channel >= r.samples);
    assert!(r.summary().contains("partial frame"));
    let r = check_by_hand(&s, 96, f + 1000);
    assert!(r.ok, "{}", r.summary());
    assert_eq!((r.frames, r.partial_frame_cycles), (1, 1000));
}

fn preset(name: &str) -> lut_gen::Schedule {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../{name}.toml"));
    lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap()
}

/// Seed 000: four chained AD7685s (CNV style): the model's pins, the chain's
/// ADC model and the checker agree, every member is sampled at the same
/// instants, and every chained word reaches the sample stream.
#[test]
fn ad7685_chain_model_passes_the_checker() {
    let s = preset("mixes/vibrotactile8k");
    let mut dut = ModelDut::new(&s);
    let r = run_dut(&s, &mut dut, 2, &RunOptions::default(), "model-dut", None);
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.samples, 2 * 320);
    for c in 1..4 {
        assert_eq!(s.channels[c].offset_slot, s.channels[0].offset_slot);
        assert_eq!(s.channels[c].period_slots, s.channels[0].period_slots);
    }
    let sm = judge::SlotModel::new(&s);
    for w in sm.conversions.chunks(4) {
        assert!(w.iter().all(|c| c.instant == w[0].instant));
        let order: Vec<u16> = w.iter().map(|c| c.member).collect();
        assert_eq!(order, [0, 1, 2, 3]);
    }
    let r = run_model(&s, 10, judge::Stimulus::Sine(None), 20);
    assert!(r.ok, "{}", r.summary());
}

#[test]
fn ad7685_chain_faults_are_caught() {
    let s = preset("mixes/vibrotactile8k");
    let at = s.grid.frame_cycles / 2 + 7;
    // (The mux lanes of a `mux = "none"` branch connect to nothing: a
    // fault there shows as a divergence from the model only.)
    let injected = each_injected_fault(&s, at, |f, r| {
        assert!(!r.ok, "fault {} not caught", f.name());
    });
    assert!(injected >= 10, "only {injected} faults injected");
}

#[test]
fn user_declared_part_model_passes_the_checker() {
    let s = preset("mixes/induction5k-adc12");
    let mut dut = ModelDut::new(&s);
    let r = run_dut(&s, &mut dut, 2, &RunOptions::default(), "model-dut", None);
    assert!(r.ok, "{}", r.summary());
}
