//! Issue 17's evidence: a clean simulation turned into what a logic
//! analyser records (resampled at 24 and 100 MHz with an arbitrary phase,
//! started mid-frame, no clock or reset, channels D0..Dn), converted by
//! sigrok-cli into a `.sr` session and its VCD, passes the time-level check;
//! the same capture of faulty gateware (a conversion one slot late, a mux
//! moved early, one SCLK edge missing) fails with the fault named.

use std::path::Path;

use judge::check_capture;
use judge::ModelDut;
use lut_gen::Schedule;
use lut_gen::{Pins, Role};

use analyser::{capture, check, lanes, mutate, resample_lanes, run_with_miso, Mutation};
use testkit::analyser;

use testkit::tools;

fn load(mix: &str) -> Schedule {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(mix);
    lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap()
}

fn run(s: &Schedule, dut: &mut ModelDut, frames: u64) -> Vec<Pins> {
    analyser::run(s, dut, frames)
}

fn evidence(mix: &str, frames: u64, window: (u64, u64), rates: &[(u64, u64)]) {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let s = load(mix);
    let clean = run(&s, &mut ModelDut::new(&s), frames);
    let (_, map) = lanes(&s);
    let d = tempfile::tempdir().unwrap();
    for &(ts, phase) in rates {
        let v = d.path().join(format!("clean{ts}.vcd"));
        let (sr, back) = capture(&s, &clean, window, (ts, phase), &v);
        for f in [&sr, &back] {
            let r = check(&s, &map, f);
            assert!(r.ok, "{} at {ts} ps: {}", f.display(), r.summary());
            assert!(r.edges_checked > 50, "{}", r.summary());
        }
        let mid = (window.0 + window.1) / 2;
        for (m, want) in Mutation::PINS {
            let mut bad = clean.clone();
            mutate(&s, &mut bad, m, mid);
            let v = d.path().join(format!("bad{ts}.vcd"));
            let (sr, _) = capture(&s, &bad, window, (ts, phase), &v);
            let r = check(&s, &map, &sr);
            assert!(!r.ok, "{m:?} at {ts} ps passed: {}", r.summary());
            assert!(
                r.violations[0].rule.contains(want),
                "{m:?} at {ts} ps: {}",
                r.summary()
            );
        }
    }
}

/// The tiny mix (4 MHz): 100 and 24 MHz analysers, mid-frame, odd phases.
#[test]
fn analyser_captures_of_tiny_pass_and_faults_fail() {
    evidence(
        "../../testkit/mixes/tiny.toml",
        3,
        (5_317, 11_900),
        &[(10_000, 3_717), (41_667, 29_001)],
    );
}

/// The reference design (48 MHz): a 24 MHz analyser cannot resolve its
/// cycle, yet proves every edge to ±42 ns; 100 MHz too.
#[test]
#[ignore = "long: make test-long"]
fn analyser_captures_of_eskin34_pass_and_faults_fail() {
    evidence(
        "../../mixes/eskin34.toml",
        2,
        (500_123, 800_000),
        &[(10_000, 4_321), (41_667, 17_000)],
    );
}

/// A subset of pins: branch 0's CS and SCLK only.  It still locks and
/// passes, and names what it could not check.
#[test]
fn a_subset_of_pins_names_what_it_cannot_check() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let s = load("../../testkit/mixes/tiny.toml");
    let clean = run(&s, &mut ModelDut::new(&s), 3);
    let d = tempfile::tempdir().unwrap();
    let v = d.path().join("all.vcd");
    let (sr, _) = capture(&s, &clean, (4_100, 11_000), (10_000, 1_234), &v);
    // D0 = adc_cs_n[0], D2 = adc_sclk[0] in `lanes`' order.
    let r = check(&s, "D0=adc_cs_n[0],D2=adc_sclk[0]", &sr);
    assert!(r.ok, "{}", r.summary());
    let text = r.summary();
    assert!(text.contains("branch slow: no CS lane checked"), "{text}");
    assert!(
        text.contains("branch fast: slot order by channel and mux settling"),
        "{text}"
    );
    assert!(
        text.contains("proved: branch fast: every SCLK edge"),
        "{text}"
    );
    // An unknown port or bit is an input error naming the entry.
    let e = judge::parse_map("D0=adc_cs_n[7]", &s).unwrap_err();
    assert!(
        e.contains("D0=adc_cs_n[7]") && e.contains("no bit 7"),
        "{e}"
    );
    let f = d.path().join("map.txt");
    std::fs::write(&f, "# probes\nD0 = adc_cs_n[0]\nD1 = adc_clk[0]\n").unwrap();
    let e = judge::parse_map(f.to_str().unwrap(), &s).unwrap_err();
    assert!(e.contains("map.txt:3") && e.contains("adc_clk"), "{e}");
}

/// Three faults in one capture: every class is reported, not only the
/// first; and a fault in the first conversion, while several frame phases
/// still fit, is the design's failure (the phase found after it fitted
/// every edge before), not an input problem.
#[test]
fn every_fault_class_is_reported_and_a_fault_before_lock_fails_the_design() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let s = load("../../testkit/mixes/tiny.toml");
    let clean = run(&s, &mut ModelDut::new(&s), 3);
    let (_, map) = lanes(&s);
    let d = tempfile::tempdir().unwrap();
    let (from, to, ts) = (5_317, 11_900, 10_000);
    let mut bad = clean.clone();
    mutate(&s, &mut bad, Mutation::OneSlotLate, 6_500);
    mutate(&s, &mut bad, Mutation::MuxEarly, 8_500);
    mutate(&s, &mut bad, Mutation::SclkEdgeMissing, 10_500);
    let v = d.path().join("three.vcd");
    let (sr, _) = capture(&s, &bad, (from, to), (ts, 3_717), &v);
    let r = check(&s, &map, &sr);
    let text = r.summary();
    assert!(!r.ok, "{text}");
    for class in ["conversion instant", "mux switching", "serial clock"] {
        assert!(
            r.violations.iter().any(|v| v.rule.contains(class)),
            "{class} missing: {text}"
        );
    }
    assert!(r.violations_total >= 3, "{text}");

    // Branch fast's CS and SCLK only: the seven phases that fit the first
    // CS edge look alike until the next conversion, so an SCLK edge missing
    // in the first conversion breaks them all at once.
    let mut early = clean.clone();
    mutate(&s, &mut early, Mutation::SclkEdgeMissing, from + 1);
    let v = d.path().join("early.vcd");
    let (sr, _) = capture(&s, &early, (from, to), (ts, 3_717), &v);
    let lanes = judge::parse_map("D0=adc_cs_n[0],D2=adc_sclk[0]", &s).unwrap();
    let cap = judge::read_capture(&sr, lanes).unwrap();
    let r = check_capture(&s, &cap, 0).expect("a design failure, not an input problem");
    let text = r.summary();
    assert!(!r.ok, "{text}");
    assert!(r.violations[0].rule.contains("serial clock"), "{text}");
    assert!(
        r.violations[0]
            .detail
            .contains("before the frame phase was unique"),
        "{text}"
    );
}

/// The link's line in a capture (eskin34-uart, `link_tx` on the last
/// channel): decoded, every packet's channels in the schedule's order; three
/// bits of one character inverted fail it (a bad CRC), named as the link's.
#[test]
fn the_link_line_in_a_capture_is_decoded_and_checked() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let s = load("../../mixes/eskin34-uart.toml");
    let f = s.grid.frame_cycles;
    let clean = run(&s, &mut ModelDut::new(&s), 2);
    let (lanes_v, map) = lanes(&s);
    assert!(map.contains("=link_tx[0]"), "{map}");
    let d = tempfile::tempdir().unwrap();
    let window = (f / 3 + 1_234, f + f / 2);
    let v = d.path().join("uart.vcd");
    let (sr, back) = capture(&s, &clean, window, (41_667, 9_876), &v);
    for file in [&sr, &back] {
        let r = check(&s, &map, file);
        let text = r.summary();
        assert!(r.ok, "{text}");
        assert!(
            text.contains("(link_tx): ") && text.contains("packets and"),
            "{text}"
        );
        // Timed through sigrok's `.sr` and VCD too; no MISO probed: the
        // codes are named as not checked.
        assert!(text.contains("characters' start bits within"), "{text}");
        assert!(text.contains("map adc_miso[N]"), "{text}");
    }
    let mut bad = clean.clone();
    mutate(&s, &mut bad, Mutation::LinkBitsFlipped, f);
    let v = d.path().join("uart-bad.vcd");
    let (sr, _) = capture(&s, &bad, window, (41_667, 9_876), &v);
    let r = check(&s, &map, &sr);
    let text = r.summary();
    assert!(!r.ok, "{text}");
    let link = format!("D{}", lanes_v.len() - 1);
    assert!(
        r.violations
            .iter()
            .any(|v| v.channel == link && v.rule.contains("link samples")),
        "{text}"
    );
}

/// The lock takes the first conversion start on any CS lane.  The tiny
/// mix with its branches swapped: branch 0 (slow) converts in two of every
/// four slots, branch 1 (fast) in all four.  A window that opens just before
/// a conversion of fast in a slot where slow is idle locks there, so a fault
/// in that first conversion (one SCLK pulse missing) is caught; before, the
/// lock waited for branch 0's CS and never looked at it.  Without branch
/// 0's CS probed at all, the capture still locks and passes.
#[test]
fn the_lock_takes_the_first_conversion_start_on_any_lane() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let tiny = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/tiny.toml"),
    )
    .unwrap();
    let (head, rest) = tiny.split_once("[[branch]]").unwrap();
    let (fast, rest) = rest.split_once("[[branch]]").unwrap();
    let (slow, chans) = rest.split_once("[[channel]]").unwrap();
    let swapped = format!("{head}[[branch]]{slow}[[branch]]{fast}[[channel]]{chans}");
    let d = tempfile::tempdir().unwrap();
    let mix = d.path().join("swapped.toml");
    std::fs::write(&mix, swapped).unwrap();
    let s = lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap();
    assert_eq!(s.mix.branches[0].name, "slow");
    let clean = run(&s, &mut ModelDut::new(&s), 3);
    let (lanes_v, map) = lanes(&s);
    let fall = |b: u32, from: usize| {
        (from..clean.len())
            .find(|&c| clean[c].cs_n >> b & 1 == 0 && clean[c - 1].cs_n >> b & 1 == 1)
    };
    // A conversion of branch 1 (from frame 1 on) with branch 0's later.
    let f = s.grid.frame_cycles as usize;
    let (f1, f0) = (f..2 * f)
        .filter_map(|c| {
            let f1 = fall(1, c)?;
            let f0 = fall(0, f1 - 20)?;
            (f1 == c && f0 > f1 + 20).then_some((f1, f0))
        })
        .next()
        .expect("a conversion of branch 1 before branch 0's next");
    let (from, to, ts, phase) = (f1 - 20, 2 * f + f / 2, 10_000u64, 3_717u64);
    let tc = 1_000_000_000_000 / s.mix.clock_hz;
    let v = d.path().join("late.vcd");
    let (sr, _) = capture(&s, &clean, (from as u64, to as u64), (ts, phase), &v);
    let r = check(&s, &map, &sr);
    assert!(r.ok, "{}", r.summary());
    let first_at = (f1 - from) as u64 * tc;
    assert!(
        r.locked_at_ps + phase >= first_at && r.locked_at_ps <= first_at + ts,
        "locked at {} ps, branch 1's conversion starts at {first_at} ps (branch 0's at {} ps): {}",
        r.locked_at_ps,
        (f0 - from) as u64 * tc,
        r.summary()
    );
    // Branch 0's CS not probed: D0 is adc_cs_n[0] in `lanes`' order.
    assert_eq!(lanes_v[0], (Some(lut_gen::Role::CsN), 0));
    let without_cs0: Vec<&str> = map.split(',').skip(1).collect();
    let r = check(&s, &without_cs0.join(","), &sr);
    assert!(r.ok, "{}", r.summary());
    assert!(r.locked_at_ps <= first_at + ts, "{}", r.summary());

    // One SCLK low pulse of branch 1's first conversion missing.
    let mut bad = clean.clone();
    let k = (f1 + 1..f0)
        .find(|&c| bad[c].sclk >> 1 & 1 == 0 && bad[c - 1].sclk >> 1 & 1 == 1)
        .expect("an SCLK fall of branch 1's conversion before branch 0's");
    let mut c = k;
    while bad[c].sclk >> 1 & 1 == 0 {
        bad[c].sclk |= 2;
        c += 1;
    }
    let v = d.path().join("late-bad.vcd");
    let (sr, _) = capture(&s, &bad, (from as u64, to as u64), (ts, phase), &v);
    let r = check(&s, &map, &sr);
    let text = r.summary();
    assert!(!r.ok, "{text}");
    assert!(
        r.violations
            .iter()
            .any(|v| v.port_bit == "adc_sclk[1]" && v.rule.contains("serial clock")),
        "{text}"
    );
}

/// The link's bytes are held to the model's time and, with MISO captured,
/// to the codes MISO carried (the tiny mix with a 1 Mbaud UART, a 100 MHz
/// analyser, the 1 ps VCD read directly to keep it fast): clean passes and
/// says so; the line from one start bit on two bit times late (every byte
/// intact, CRCs good) fails on timing; MISO of branch 0 inverted over one
/// slot (the line unchanged) fails on the codes.
#[test]
fn the_link_bytes_are_timed_and_carry_the_codes_miso_carried() {
    let tiny = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/tiny.toml"),
    )
    .unwrap();
    let d = tempfile::tempdir().unwrap();
    let mix = d.path().join("tiny-uart.toml");
    std::fs::write(
        &mix,
        format!("{tiny}\n[link]\nkind = \"uart\"\nbaud = 1_000_000\n"),
    )
    .unwrap();
    let s = lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap();
    let f = s.grid.frame_cycles as usize;
    let (pins, miso) = run_with_miso(&s, &mut ModelDut::new(&s), 3);
    let (mut lanes_v, mut map) = lanes(&s);
    let link = format!("D{}", lanes_v.len() - 1);
    let branches = lut_gen::Layout::new(&s).branches;
    for b in 0..branches as u32 {
        map += &format!(",D{}=adc_miso[{b}]", lanes_v.len());
        lanes_v.push((Some(Role::Miso), b));
    }
    let window = ((f / 2 + 123) as u64, (2 * f + f / 2) as u64);
    let (ts, phase) = (10_000, 4_321);
    let judged = |pins: &[Pins], miso: &[u64], name: &str| {
        let level = |c: usize, r: Option<Role>, b: u32| match r {
            Some(Role::Miso) => miso[c] >> b & 1 == 1,
            _ => analyser::bit(&pins[c], r, b),
        };
        let v = d.path().join(name);
        resample_lanes(&s, &lanes_v, &level, window, ts, phase, &v);
        // The sample rate, as sigrok-cli's VCD says it.
        let text = std::fs::read_to_string(&v).unwrap().replace(
            "$enddefinitions $end\n",
            "$comment\n  Acquisition at 100 MHz\n$end\n$enddefinitions $end\n",
        );
        std::fs::write(&v, text).unwrap();
        check(&s, &map, &v)
    };
    let r = judged(&pins, &miso, "clean.vcd");
    let text = r.summary();
    assert!(r.ok, "{text}");
    assert!(text.contains("characters' start bits within"), "{text}");
    assert!(text.contains("equal the codes MISO carried"), "{text}");

    // The line two bit times late from the first start bit after frame 1.
    let div = lut_gen::plan_link(&s).unwrap().unwrap().baud_divider as usize;
    let st = analyser::start_bit(&pins, f as u64);
    let late = analyser::two_bits_late(&pins, st, div);
    let r = judged(&late, &miso, "late.vcd");
    let text = r.summary();
    assert!(!r.ok, "{text}");
    assert!(
        r.violations
            .iter()
            .any(|v| v.channel == link && v.rule.contains("link timing")),
        "{text}"
    );
    assert!(!text.contains("bad CRC"), "{text}");

    // MISO of branch 0 inverted over one slot from frame 1 on.
    let mut bad = miso.clone();
    for m in &mut bad[f..f + s.grid.slot_cycles as usize] {
        *m ^= 1;
    }
    let r = judged(&pins, &bad, "miso.vcd");
    let text = r.summary();
    assert!(!r.ok, "{text}");
    assert!(
        r.violations
            .iter()
            .any(|v| v.channel == link && v.rule.contains("link samples (values)")),
        "{text}"
    );
}

/// A board's crystal and an analyser's differ by tens of ppm: captures of
/// mixes without a link by 100 and 24 MHz analysers 3 to 500 ppm fast or
/// slow, over two frames from odd offsets, pass; the offset measured is
/// said, and its stated uncertainty covers its real error over the capture
/// (an offset the fit puts under half a sample period over the capture is
/// not scaled).
#[test]
fn captures_by_an_analyser_off_the_design_clock_pass() {
    let d = tempfile::tempdir().unwrap();
    let ppms = [100.0, -100.0, 37.0, -250.0, 10.0, 500.0, -3.0];
    for mix in [
        "../../testkit/mixes/tiny.toml",
        "../../mixes/softslip1k.toml",
        "../../mixes/vibrotactile8k.toml",
    ] {
        let s = load(mix);
        let f = s.grid.frame_cycles;
        let clean = run(&s, &mut ModelDut::new(&s), 3);
        for (i, ppm) in ppms.into_iter().enumerate() {
            let i = i as u64;
            let w = (f / 7 * i + 13 * i, f / 7 * i + 2 * f);
            let ts = [10_000, 41_667][i as usize % 2];
            let out = d.path().join(format!("{i}.vcd"));
            let r = analyser::check_drifting(&s, &clean, w, (ts, 777 * i + 1), ppm, &out);
            let what = format!("{mix} at {ppm} ppm, {ts} ps");
            assert!(r.ok, "{what}: {}", r.summary());
            let span_ps = (w.1 - w.0) as f64 * 1e12 / s.mix.clock_hz as f64;
            // the analyser fast by `ppm`: the design's clock slow by it
            let Some(got) = r.clock_ppm else {
                // checked as taken: the drift stays within a sample period
                assert!(ppm.abs() * 1e-6 * span_ps < ts as f64, "{what}");
                continue;
            };
            let err_ps = (got + ppm).abs() * 1e-6 * span_ps;
            assert!(
                err_ps <= r.clock_uncertainty_ps as f64 + 1.0,
                "{what}: {got} ppm, {err_ps:.0} ps off, said {} ps",
                r.clock_uncertainty_ps
            );
            assert!(r.summary().contains(&format!("{got:+.1} ppm")), "{what}");
        }
    }
}
