use judge::{run_dut, run_model, ModelDut, RunOptions};
use std::path::Path;

/// Every fault of `s` injected into the model at cycle `at` for two
/// frames: `judge` sees each one that changed something (a fault with
/// nothing to change there, e.g. no idle slot to move a conversion into,
/// was not injected); returns how many did.
fn each_injected_fault(
    s: &lut_gen::Schedule,
    at: u64,
    judge: impl Fn(&judge::PinFault, &judge::Verdict),
) -> usize {
    use judge::{FaultyDut, PinFault};
    let mut injected = 0;
    for f in PinFault::all(s) {
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
    let all = judge::PinFault::all(&s).len();
    assert!(injected + 3 >= all, "{injected} of {all}");
}

/// Drives the checker by hand: `reset` reset cycles, then `cycles` cycles of the model's pins.
fn check_by_hand(s: &lut_gen::Schedule, reset: u64, cycles: u64) -> judge::Verdict {
    check_by_hand_with(s, reset, cycles, 0)
}

/// Like `check_by_hand`, with branch 0's `mux_sel` wrong in the first
/// `wrong_mux` reset cycles (a mux that is not steady through reset).
fn check_by_hand_with(
    s: &lut_gen::Schedule,
    reset: u64,
    cycles: u64,
    wrong_mux: u64,
) -> judge::Verdict {
    use judge::Dut;
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
    reset: lut_gen::Pins,
    m: Option<judge::CycleModel>,
}

impl judge::Dut for EagerStart {
    fn step(&mut self, rst: bool, miso: u64) -> lut_gen::Pins {
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
    assert_eq!(judge::reset_cycles(&s, 1), 1, "runs keep a short reset");
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

/// vibrotactile8k: four chained AD7685s (CNV style): the model's pins, the chain's
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
    // A `mux = "none"` branch has no mux pins: no mux fault to inject.
    assert!(judge::PinFault::all(&s)
        .iter()
        .all(|f| !f.name().contains("mux")));
    let injected = each_injected_fault(&s, at, |f, r| {
        assert!(!r.ok, "fault {} not caught", f.name());
    });
    assert!(injected >= 9, "only {injected} faults injected");
}

#[test]
fn user_declared_part_model_passes_the_checker() {
    let s = preset("mixes/induction5k-adc12");
    let mut dut = ModelDut::new(&s);
    let r = run_dut(&s, &mut dut, 2, &RunOptions::default(), "model-dut", None);
    assert!(r.ok, "{}", r.summary());
}

/// `testkit/mixes/tiny.toml` (4 MHz, 1 ms frames of two slices) over a
/// 1 Mbaud UART (4 cycles a bit): a link mix whose runs take milliseconds.
pub(crate) fn tiny_uart() -> lut_gen::Schedule {
    tiny_with_link("baud = 1_000_000\n")
}

/// `testkit/mixes/tiny.toml` with a UART link of these keys.
fn tiny_with_link(keys: &str) -> lut_gen::Schedule {
    tiny_with("kind = \"uart\"\n", keys)
}

/// `testkit/mixes/tiny.toml` with a `[link]` of this kind and keys.
fn tiny_with(kind: &str, keys: &str) -> lut_gen::Schedule {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/tiny.toml");
    let text = std::fs::read_to_string(&p).unwrap() + "\n[link]\n" + kind + keys;
    let mix = lut_gen::parse(Path::new("tiny-uart.toml"), &text).unwrap();
    let s = lut_gen::synthesize(&mix).unwrap();
    // a line that cannot carry the mix has no link to check
    assert!(matches!(lut_gen::plan_link(&s), Some(Ok(_))), "{keys}");
    s
}

/// The model's pins with `link_tx` inverted for one cycle: the cycle after
/// the first start bit's fall at or after cycle `at` (a glitch inside a bit).
struct Glitch {
    inner: ModelDut,
    at: u64,
    c: u64,
    fall: Option<u64>,
}

impl judge::Dut for Glitch {
    fn step(&mut self, rst: bool, miso: u64) -> lut_gen::Pins {
        let mut p = self.inner.step(rst, miso);
        if rst {
            return p;
        }
        if self.fall.is_none() && self.c >= self.at && !p.link_tx {
            self.fall = Some(self.c);
        }
        if self.fall.map(|f| f + 1) == Some(self.c) {
            p.link_tx = !p.link_tx;
        }
        self.c += 1;
        p
    }
}

/// The UART line is one of the invariants: with the model off, a clean run
/// passes and each of the four line faults of the campaign is caught by a
/// `link-*` rule of its own kind, at or after the fault; a one-cycle glitch
/// inside a bit breaks `link-bit-timing`, and a sample changed or dropped
/// on the sample pins alone breaks `link-samples`.
#[test]
fn the_uart_line_is_judged_without_the_model() {
    use judge::{FaultyDut, PinFault};
    let s = tiny_uart();
    let opts = RunOptions {
        check: judge::CheckOptions {
            model: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let clean = run_dut(&s, &mut ModelDut::new(&s), 3, &opts, "clean", None);
    assert!(clean.ok && !clean.model_compared, "{}", clean.summary());
    // clean at other character shapes: bits of 4 and 5 cycles, parity,
    // two stop bits
    for keys in [
        "baud = 1_000_000\nstop_bits = 2\n",
        "baud = 800_000\nparity = \"even\"\n",
        "baud = 800_000\nparity = \"odd\"\nstop_bits = 2\n",
        "baud = 1_000_000\nparity = \"odd\"\n",
    ] {
        let t = tiny_with_link(keys);
        let r = run_dut(&t, &mut ModelDut::new(&t), 3, &opts, "clean", None);
        assert!(r.ok, "{keys}: {}", r.summary());
    }
    let at = s.grid.frame_cycles + s.grid.frame_cycles / 2 + 7;
    for (f, rule) in [
        (PinFault::LinkBitFlip, "link-crc"),
        (PinFault::LinkDropByte, "link-crc"),
        (PinFault::LinkStuck { high: true }, "link-packet-missing"),
        (PinFault::LinkStuck { high: false }, "link-framing"),
    ] {
        let mut dut = FaultyDut::new(&s, ModelDut::new(&s), f, at);
        let r = run_dut(&s, &mut dut, 3, &opts, "faulty", None);
        let class = f.class();
        assert!(dut.injected(), "{class}: found nothing to change");
        eprintln!("{class}: {}", r.summary());
        assert!(!r.ok && r.divergence_count == 0, "{class}: {}", r.summary());
        let rules: Vec<&str> = r.violations.iter().map(|v| v.rule.as_str()).collect();
        assert!(rules.contains(&rule), "{class}: {rules:?}");
        for v in &r.violations {
            assert!(
                v.rule.starts_with("link-") && v.cycle >= at,
                "{class}: {v:?}"
            );
        }
    }
    // a glitch inside a bit: off the bit grid
    let mut dut = Glitch {
        inner: ModelDut::new(&s),
        at,
        c: 0,
        fall: None,
    };
    let r = run_dut(&s, &mut dut, 3, &opts, "glitch", None);
    assert_eq!(r.violations[0].rule, "link-bit-timing", "{}", r.summary());
    // the stream and the line disagree: a sample changed or dropped on the
    // sample pins only (the line carries what the gateware sent)
    for f in [PinFault::NeighbourCode, PinFault::DropSample] {
        let mut dut = FaultyDut::new(&s, ModelDut::new(&s), f, at);
        let r = run_dut(&s, &mut dut, 3, &opts, "faulty", None);
        assert!(
            r.violations.iter().any(|v| v.rule == "link-samples"),
            "{}: {}",
            f.class(),
            r.summary()
        );
    }
}

/// The AXI4-Stream beats are one of the invariants as the UART line is:
/// with the model off, clean runs pass behind the worst-case and a random
/// slave (both `tlast` placements); the campaign's two AXIS classes are
/// caught (`axis-stable`), and beats the slave takes with a changed byte,
/// a lost beat, a misplaced `tlast` or a sample changed on the sample pins
/// only are caught by the beats' decode (`link-*`, `axis-tlast`).
#[test]
fn the_axis_beats_are_judged_without_the_model() {
    use judge::with_slave;
    use judge::{FaultyDut, PinFault};
    use link::ReadyPattern::{Random, WorstCase};
    let opts = RunOptions {
        check: judge::CheckOptions {
            model: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let axis = |tlast: &str| tiny_with("kind = \"axis\"\nready_within = 8\n", tlast);
    let s = axis("");
    for (t, pattern) in [
        (&s, WorstCase),
        (&s, Random { seed: 7 }),
        (&axis("tlast = \"frame\"\n"), WorstCase),
    ] {
        let mut dut = with_slave(t, ModelDut::new(t), pattern);
        let r = run_dut(t, &mut dut, 3, &opts, "clean", None);
        assert!(r.ok && !r.model_compared, "{}", r.summary());
    }
    let at = s.grid.frame_cycles + s.grid.frame_cycles / 2 + 7;
    let rules = |mut dut: Box<dyn judge::Dut + '_>, what: &str| {
        let r = run_dut(&s, &mut dut, 3, &opts, "faulty", None);
        eprintln!("{what}: {}", r.summary());
        assert!(!r.ok && r.divergence_count == 0, "{what}: {}", r.summary());
        for v in &r.violations {
            assert!(v.cycle >= at, "{what}: {v:?}");
        }
        r.violations
            .iter()
            .map(|v| v.rule.clone())
            .collect::<Vec<String>>()
    };
    // as the campaign injects them: on the pins behind the slave
    let faulty = |f| {
        let slave = with_slave(&s, ModelDut::new(&s), WorstCase);
        Box::new(FaultyDut::new(&s, slave, f, at))
    };
    for f in [PinFault::AxisTvalidDrop, PinFault::AxisTdataChange] {
        let r = rules(faulty(f), f.class());
        assert!(r.contains(&"axis-stable".to_string()), "{r:?}");
    }
    // taken beats altered after the slave's handshake: the decode sees them
    for (what, want) in [
        ("byte", &["link-crc", "link-resync"][..]),
        ("lost", &["link-crc", "link-resync"][..]),
        ("tlast", &["axis-tlast"][..]),
    ] {
        let dut = Beat {
            inner: with_slave(&s, ModelDut::new(&s), WorstCase),
            at,
            c: 0,
            what,
            done: false,
        };
        let r = rules(Box::new(dut), what);
        assert!(
            r.iter().any(|x| want.contains(&x.as_str())),
            "{what}: {r:?}"
        );
    }
    for f in [PinFault::NeighbourCode, PinFault::DropSample] {
        let r = rules(faulty(f), f.class());
        assert!(r.contains(&"link-samples".to_string()), "{r:?}");
    }
}

/// The first beat taken (tvalid and tready high) at or after cycle `at`
/// altered: its byte changed, the beat lost (tvalid low), or its `tlast`
/// inverted.
struct Beat<'a> {
    inner: Box<dyn judge::Dut + 'a>,
    at: u64,
    c: u64,
    what: &'static str,
    done: bool,
}

impl judge::Dut for Beat<'_> {
    fn step(&mut self, rst: bool, miso: u64) -> lut_gen::Pins {
        let mut p = self.inner.step(rst, miso);
        if rst {
            return p;
        }
        if !self.done && self.c >= self.at && p.axis_tvalid && p.axis_tready {
            self.done = true;
            match self.what {
                "byte" => p.axis_tdata ^= 0x10,
                "lost" => p.axis_tvalid = false,
                _ => p.axis_tlast = !p.axis_tlast,
            }
        }
        self.c += 1;
        p
    }
}

/// A packet sent twice: the bytes of the first whole packet taken after
/// cycle `at` sent again in place of the bytes of the packet of the same
/// slice a frame later (same length: the schedule repeats every frame), so
/// framing, CRC and `tlast` stay good and only the sequence is wrong.
struct Repeat<'a> {
    inner: Box<dyn judge::Dut + 'a>,
    at: u64,
    c: u64,
    slices: usize,
    /// Packets ended (`tlast` taken) since `at`.
    ended: usize,
    beats: Vec<u8>,
    sent: usize,
}

impl judge::Dut for Repeat<'_> {
    fn step(&mut self, rst: bool, miso: u64) -> lut_gen::Pins {
        let mut p = self.inner.step(rst, miso);
        if rst {
            return p;
        }
        if self.c >= self.at && p.axis_tvalid {
            let taken = p.axis_tready;
            if self.ended == 1 && taken {
                self.beats.push(p.axis_tdata);
            } else if self.ended == 1 + self.slices && self.sent < self.beats.len() {
                // every cycle the beat is offered: tdata stays stable
                p.axis_tdata = self.beats[self.sent];
                self.sent += taken as usize;
            }
            self.ended += (taken && p.axis_tlast) as usize;
        }
        self.c += 1;
        p
    }
}

/// `link-sequence`: a packet that arrives again (its frame counter and
/// slice those of a packet already taken) is out of sequence; nothing else
/// is wrong within the run (CRCs, `tlast`, the handshake, every other
/// packet's samples; the packet it replaced would be reported lost when the
/// next one arrives, after the run's end).
#[test]
fn a_packet_sent_twice_breaks_the_sequence() {
    use link::ReadyPattern::WorstCase;
    let s = tiny_with("kind = \"axis\"\nready_within = 8\n", "");
    let opts = RunOptions {
        check: judge::CheckOptions {
            model: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut dut = Repeat {
        inner: judge::with_slave(&s, ModelDut::new(&s), WorstCase),
        at: s.grid.frame_cycles + 7,
        c: 0,
        slices: s.grid.slices_per_frame as usize,
        ended: 0,
        beats: Vec::new(),
        sent: 0,
    };
    let r = run_dut(&s, &mut dut, 3, &opts, "repeat", None);
    assert!(
        dut.sent > 0 && dut.sent == dut.beats.len(),
        "not sent again"
    );
    let rules: Vec<&str> = r.violations.iter().map(|v| v.rule.as_str()).collect();
    assert_eq!(rules, ["link-sequence"], "{}", r.summary());
    assert!(
        r.violations[0]
            .detail
            .contains("arrived again, or after a later one"),
        "{}",
        r.summary()
    );
}

/// A divergence on a mux pin compares like with like: each select value
/// with the channel it addresses (the wrong input's channel, or why there
/// is none), never the expected channel beside the actual value.
#[test]
fn a_mux_divergence_names_the_channel_of_each_value() {
    use judge::{FaultyDut, PinFault};
    let s = eskin();
    let at = s.grid.frame_cycles / 2 + 7;
    let f = PinFault::WrongMux { branch: 0 };
    let mut dut = FaultyDut::new(&s, ModelDut::new(&s), f, at);
    let r = run_dut(&s, &mut dut, 2, &RunOptions::default(), "faulty", None);
    let d = (r.divergences.iter())
        .find(|d| d.signal.starts_with("mux_sel"))
        .unwrap_or_else(|| panic!("{}", r.summary()));
    let want = d.channel.clone().unwrap();
    let actual = d.actual_channel.clone().unwrap();
    // the select bit flipped: another input, so another channel (or none)
    assert_ne!(actual, want, "{}", r.summary());
    let line = r.summary();
    let shown = |c: &str| match c.contains(' ') {
        true => c.to_string(),
        false => format!("channel {c}"),
    };
    let expected = format!(
        "expected {} ({}) actual {} ({})",
        d.expected,
        shown(&want),
        d.actual,
        shown(&actual)
    );
    assert!(line.contains(&expected), "{line}");
}
