//! Logic-analyser captures of link designs taken mid-run (`check --map`):
//! the UART line is joined at its first whole packet, with the model (every
//! character from that packet's header on timed against it, at the frame
//! phase the line fits) and without it (decoded and judged); what came
//! before is skipped and said to be unjudged.  Every link preset and random
//! link mixes at random offsets pass; a fault after the join fails at its
//! time; a fault before it passes inside the time reported as not judged;
//! a capture with no whole packet says the link was not judged.

use std::path::{Path, PathBuf};

use lut_gen::LinkKind;
use lut_gen::Pins;
use lut_gen::Schedule;
use testkit::analyser;
use testkit::analyser::{start_bit, two_bits_late};

use crate::link_windows::{random_link_mixes, rng};

/// Every cycle's pins after reset of `frames` frames of rust-hdl's model of
/// the gateware behind the AXIS slave a back end puts in front of it.
fn pins(s: &Schedule, frames: u64) -> Vec<Pins> {
    pins_of(
        s,
        engines::RustHdlDut::new(s).expect("rust-hdl builds"),
        frames,
    )
}

/// [`pins`] from the judge's cycle model, which the gateware equals pin for
/// pin (the engines' tests hold them so): a preset's 1.4 million cycles in
/// a fraction of rust-hdl's time.
fn model_pins(s: &Schedule, frames: u64) -> Vec<Pins> {
    pins_of(s, judge::ModelDut::new(s), frames)
}

fn pins_of<D: judge::Dut>(s: &Schedule, dut: D, frames: u64) -> Vec<Pins> {
    let mut dut = judge::with_slave(s, dut, ::link::ReadyPattern::Random { seed: 11 });
    analyser::run(s, &mut dut, frames)
}

/// What a 100 MHz analyser (first sample `phase` ps into cycle `w.0`)
/// records of cycles `w`, as sigrok-cli's VCD says it, judged with the
/// model and without it.
fn judged(
    s: &Schedule,
    pins: &[Pins],
    w: (u64, u64),
    phase: u64,
    out: &Path,
) -> [judge::TimedReport; 2] {
    judged_drifting(s, pins, w, phase, 0.0, out)
}

/// [`judged`] by an analyser `ppm` parts per million off the design's clock.
fn judged_drifting(
    s: &Schedule,
    pins: &[Pins],
    w: (u64, u64),
    phase: u64,
    ppm: f64,
    out: &Path,
) -> [judge::TimedReport; 2] {
    let (_, map) = analyser::lanes(s);
    analyser::resample_drifting(s, pins, w, (10_000, phase), ppm, out);
    let text = std::fs::read_to_string(out).unwrap().replace(
        "$enddefinitions $end\n",
        "$comment\n  Acquisition at 100 MHz\n$end\n$enddefinitions $end\n",
    );
    std::fs::write(out, text).unwrap();
    let lanes = judge::parse_map(&map, s).unwrap();
    let cap = judge::read_capture(out, lanes).unwrap();
    [true, false].map(|model| judge::check_capture_with(s, &cap, 0, model).unwrap())
}

fn kind(s: &Schedule) -> Option<LinkKind> {
    s.mix.link.as_ref().map(|l| l.kind)
}

/// The time of cycle `c` of a capture of cycles from `from` (first sample
/// `phase` ps in), in ps.
fn at_ps(s: &Schedule, c: u64, from: u64, phase: u64) -> u64 {
    ((c - from) as f64 * 1e12 / s.mix.clock_hz as f64) as u64 - phase
}

/// Both reports pass; a UART line is joined at a whole packet, by the
/// model or the decoder, the model timing every character from it on.
fn assert_clean(what: &str, s: &Schedule, [m, d]: &[judge::TimedReport; 2]) {
    for (r, by) in [(m, "model"), (d, "decoder")] {
        let text = r.summary();
        assert!(r.ok, "{what}, {by}: {text}");
        if kind(s) == Some(LinkKind::Axis) {
            // the beats read and judged from the first whole packet on
            assert!(
                text.contains("m_axis_tdata: ") && text.contains("tlast on exactly the beats"),
                "{what}: {text}"
            );
        }
        let j = r
            .link_join
            .as_ref()
            .unwrap_or_else(|| panic!("{what}: {text}"));
        assert!(j.judged && j.by == by, "{what}: {text}");
        assert_eq!(Some(j.unjudged_ps), j.header_ps, "{what}: {text}");
        assert!(text.contains(&j.text()), "{what}: {text}");
    }
    if kind(s) == Some(LinkKind::Axis) {
        // held to the model with tready from the capture
        let text = m.summary();
        assert!(
            text.contains("held to the model (tready from the capture)"),
            "{what}: {text}"
        );
        assert!(
            d.summary().contains("--no-model: the beats are decoded"),
            "{what}"
        );
    }
    if kind(s) == Some(LinkKind::Uart) {
        let text = m.summary();
        assert!(
            text.contains("from the first whole packet's header on"),
            "{what}: the model timed the line: {text}"
        );
        assert!(
            d.summary().contains("--no-model: the line is decoded"),
            "{what}"
        );
        let (jm, jd) = (m.link_join.as_ref().unwrap(), d.link_join.as_ref().unwrap());
        assert_eq!(
            jm,
            &judge::LineJoin {
                by: "model",
                ..jd.clone()
            },
            "{what}"
        );
    }
}

fn random_captures(seed: u64, mixes: usize, captures: usize) {
    let d = tempfile::tempdir().unwrap();
    let found = random_link_mixes(seed, mixes);
    let uart = found
        .iter()
        .filter(|(_, s)| kind(s) == Some(LinkKind::Uart))
        .count();
    assert!(
        uart > 0 && uart < mixes,
        "both kinds drawn: {uart} UART of {mixes}"
    );
    for (k, s) in &found {
        let f = s.grid.frame_cycles;
        let p = pins(s, 6);
        let mut next = rng(*k);
        for i in 0..captures {
            let from = f / 2 + next() % (3 * f);
            let w = (from, from + f + next() % f);
            let phase = next() % 9_000;
            let r = judged(s, &p, w, phase, &d.path().join(format!("{k}-{i}.vcd")));
            assert_clean(&format!("random mix {k} {w:?}"), s, &r);
        }
    }
}

/// Three random link mixes, two captures each; the long suite's thirty
/// mixes, four captures each, are the full draw.
#[test]
fn captures_of_random_link_mixes_at_random_offsets_pass() {
    random_captures(1, 3, 2);
}

#[test]
#[ignore = "long: make test-long"]
fn captures_of_thirty_random_link_mixes_pass() {
    random_captures(200, 30, 4);
}

/// The link presets (3 frames of each: one run serves both checks):
/// captures at random offsets pass; and a board's crystal and an
/// analyser's differ by tens of ppm, so a capture over most of a frame, the
/// analyser 100 ppm fast or slow, passes as a capture with exact clocks
/// does, the offset measured and said; at the mix's own clock the capture
/// is checked as it was taken (no offset the fit can tell from none).
/// `make test` captures the cycle model's pins (rust-hdl's 3 frames of
/// each preset were half of this test's time) and takes each offset once
/// (the UART fast and exact, the AXI4-Stream slow); `make test-long`
/// captures rust-hdl's, at every offset.
#[test]
fn captures_of_the_link_presets_at_random_offsets_and_100_ppm_off_pass() {
    link_preset_captures(
        model_pins,
        [("eskin34-uart.toml", &[0, 2]), ("eskin34-axis.toml", &[1])],
    );
}

#[test]
#[ignore = "long: make test-long (rust-hdl's pins of each link preset, at every offset)"]
fn captures_of_each_link_preset_at_every_offset_pass() {
    link_preset_captures(
        pins,
        [
            ("eskin34-uart.toml", &[0, 1, 2]),
            ("eskin34-axis.toml", &[0, 1, 2]),
        ],
    );
}

/// Captures of 3 frames of each preset's pins from `pins_of`: at random
/// offsets, and at the analyser's offsets given.
fn link_preset_captures(pins_of: fn(&Schedule, u64) -> Vec<Pins>, presets: [(&str, &[usize]); 2]) {
    let d = tempfile::tempdir().unwrap();
    for (name, offsets) in presets {
        let s = preset(name);
        let p = pins_of(&s, 3);
        captures_at_random_offsets_pass(name, &s, &p, d.path());
        captures_off_by_ppm_pass(name, &s, &p, offsets, d.path());
    }
}

/// Two captures of `p` (3 frames of the preset `name`) at random offsets.
fn captures_at_random_offsets_pass(name: &str, s: &Schedule, p: &[Pins], d: &Path) {
    let f = s.grid.frame_cycles;
    let mut next = rng(27);
    for i in 0..2 {
        let from = f / 2 + next() % f;
        let w = (from, from + f / 2 + next() % (f / 2));
        let r = judged(s, p, w, next() % 9_000, &d.join(format!("{i}.vcd")));
        assert_clean(&format!("{name} {w:?}"), s, &r);
    }
}

/// The analyser's offsets: fast, slow, exact (index `i`: the capture's
/// phase is `3_000 + 2_000 * i` ps).
const PPM: [f64; 3] = [100.0, -100.0, 0.0];

/// For each `i` of `offsets`: a capture of `p` (the preset `name`) by an
/// analyser `PPM[i]` off passes, its offset measured.
fn captures_off_by_ppm_pass(name: &str, s: &Schedule, p: &[Pins], offsets: &[usize], d: &Path) {
    let f = s.grid.frame_cycles;
    for &i in offsets {
        let ppm = PPM[i];
        let w = (f / 2, 2 * f);
        let out = d.join(format!("ppm{i}.vcd"));
        let r = judged_drifting(s, p, w, 3_000 + 2_000 * i as u64, ppm, &out);
        assert_clean(&format!("{name} at {ppm} ppm"), s, &r);
        for r in &r {
            if ppm == 0.0 {
                assert_eq!(r.clock_ppm, None, "{name}: {}", r.summary());
                continue;
            }
            // the analyser fast by `ppm`: the design's clock slow by it
            let got = r.clock_ppm.expect("the clock measured");
            assert!((got + ppm).abs() < 2.0, "{name}: {got} ppm");
            assert!(r.summary().contains(&format!("{got:+.1} ppm")), "{name}");
        }
    }
}

/// A preset (`mixes/NAME`), scheduled.
fn preset(name: &str) -> Schedule {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("mixes")
        .join(name);
    lut_gen::synthesize(&lut_gen::load(&path).unwrap()).unwrap()
}

/// A 100 MHz capture of the preset `mixes/NAME` (2 frames of pins), from
/// cycle `f / 3 + after` (first sample `phase` ps in) to the middle of the
/// second frame, as `capture.vcd` in `dir`: the preset's file, its
/// schedule, the capture and both reports.
fn preset_capture(
    name: &str,
    after: u64,
    phase: u64,
    dir: &Path,
) -> (PathBuf, Schedule, PathBuf, [judge::TimedReport; 2]) {
    let mix = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("mixes")
        .join(name);
    let s = preset(name);
    let f = s.grid.frame_cycles;
    let wave = dir.join("capture.vcd");
    let reports = judged(&s, &pins(&s, 2), (f / 3 + after, f + f / 2), phase, &wave);
    (mix, s, wave, reports)
}

/// `check --json`'s `link_join`: judged by `by`, at the header and with
/// the bytes skipped that the library's report `mj` says.
fn join_in_json(j: &serde_json::Value, by: &str, mj: &judge::LineJoin) {
    assert_eq!(j["by"], by, "{j}");
    assert_eq!(j["judged"], true, "{j}");
    assert_eq!(j["header_ps"], mj.header_ps.unwrap(), "{j}");
    assert_eq!(j["skipped_bytes"], mj.skipped_bytes, "{j}");
}

/// A report that fails a link fault at `t` ps, within `within` ps of it,
/// having joined the line before it (its first violation).
fn fails_after_the_join(r: &judge::TimedReport, t: u64, within: u64) {
    let text = r.summary();
    assert!(!r.ok, "{text}");
    let j = r.link_join.as_ref().unwrap();
    assert!(j.header_ps.unwrap() < t, "joined before the fault: {text}");
    let v = &r.violations[0];
    assert!(v.rule.contains("link"), "{text}");
    assert!(
        (t..t + within).contains(&v.time_ps),
        "fault at {t} ps: {text}"
    );
}

/// A report that passes a fault at `t` ps before its join: the line joined
/// after it, bytes skipped, and the time before said not judged.
fn unseen_before_the_join(r: &judge::TimedReport, t: u64) {
    let text = r.summary();
    let j = r.link_join.as_ref().unwrap();
    assert!(r.ok, "unseen before the join: {text}");
    assert!(j.judged && j.unjudged_ps > t, "{text}");
    assert!(j.skipped_bytes > 0, "{text}");
    assert!(text.contains("the line before it was not judged"), "{text}");
}

/// The UART mixes of the random link mixes from seed 1.
fn uart_mix() -> Schedule {
    random_link_mixes(1, 4)
        .into_iter()
        .map(|(_, s)| s)
        .find(|s| kind(s) == Some(LinkKind::Uart))
        .expect("a UART mix")
}

/// Faults inside a capture, after the join: three bits of a character
/// inverted (a bad CRC) fail it with and without the model, within the
/// packet; the line two bit times late from a start bit on (every byte
/// intact) fails with the model at that character's start bit.
#[test]
fn a_fault_after_the_join_fails_the_capture_at_its_time() {
    let s = uart_mix();
    let d = tempfile::tempdir().unwrap();
    let f = s.grid.frame_cycles;
    let clean = pins(&s, 4);
    let (w, phase) = ((f / 2 + 1_234, f / 2 + 1_234 + 2 * f), 4_321);
    let at = w.0 + f;
    let st = start_bit(&clean, at);
    let t = at_ps(&s, st as u64, w.0, phase);
    // the packet's end at the latest: a slice and the link's latency on
    let plan = lut_gen::plan_link(&s).unwrap().unwrap();
    let within = at_ps(
        &s,
        w.0 + 2 * s.grid.slice_cycles + plan.latency_cycles,
        w.0,
        phase,
    );
    let mut flipped = clean.clone();
    analyser::mutate(&s, &mut flipped, analyser::Mutation::LinkBitsFlipped, at);
    for r in judged(&s, &flipped, w, phase, &d.path().join("flip.vcd")) {
        fails_after_the_join(&r, t, within);
    }
    let div = plan.baud_divider as usize;
    let late = two_bits_late(&clean, st, div);
    let [m, dec] = judged(&s, &late, w, phase, &d.path().join("late.vcd"));
    let text = m.summary();
    assert!(!m.ok, "{text}");
    let v = &m.violations[0];
    assert!(v.rule.contains("link timing"), "{text}");
    let (lo, hi) = (t, t + at_ps(&s, w.0 + 3 * div as u64, w.0, 0));
    assert!(
        (lo..hi).contains(&v.time_ps),
        "the late start bit at {lo} ps: {text}"
    );
    // intact bytes: the decoder alone does not see a timing fault
    assert!(dec.ok, "{}", dec.summary());
}

/// With the analyser 100 ppm off, a start bit two bits late is still
/// failed by the model, at its time in the capture's own timebase.
#[test]
fn a_late_start_bit_fails_a_drifting_capture_at_its_time() {
    let s = uart_mix();
    let d = tempfile::tempdir().unwrap();
    let f = s.grid.frame_cycles;
    let clean = pins(&s, 4);
    let (w, phase, ppm) = ((f / 2, f / 2 + 2 * f), 2_000, 100.0);
    let st = start_bit(&clean, w.0 + f);
    let div = lut_gen::plan_link(&s).unwrap().unwrap().baud_divider as usize;
    let late = two_bits_late(&clean, st, div);
    let out = d.path().join("late.vcd");
    let [m, dec] = judged_drifting(&s, &late, w, phase, ppm, &out);
    let text = m.summary();
    assert!(!m.ok && dec.ok, "{text}");
    assert!(m.clock_ppm.is_some(), "{text}");
    let v = &m.violations[0];
    assert!(v.rule.contains("link timing"), "{text}");
    // the capture's time of the late start: the cycle's, stretched by ppm
    let t = at_ps(&s, st as u64, w.0, phase) as f64 * (1.0 + ppm * 1e-6);
    let span = at_ps(&s, w.0 + 3 * div as u64, w.0, 0) as f64;
    assert!(
        (t..t + span).contains(&(v.time_ps as f64)),
        "the late start bit at {t} ps: {text}"
    );
}

/// The line before the first whole packet is not judged and the report
/// says how long: three bits flipped in the capture's first character
/// pass, inside the time reported unjudged.  A capture shorter than a
/// packet says the link was not judged at all.
#[test]
fn the_line_before_the_join_is_reported_as_not_judged() {
    let s = uart_mix();
    let d = tempfile::tempdir().unwrap();
    let f = s.grid.frame_cycles;
    let clean = pins(&s, 3);
    let phase = 2_345;
    // a window opening inside a packet: a character starts just after it
    let from = (f / 2..f)
        .find(|&c| !clean[c as usize + 5].link_tx && clean[c as usize + 4].link_tx)
        .unwrap();
    let w = (from, from + f);
    let mut bad = clean.clone();
    analyser::mutate(&s, &mut bad, analyser::Mutation::LinkBitsFlipped, from);
    let t = at_ps(&s, from + 5, from, phase);
    for r in judged(&s, &bad, w, phase, &d.path().join("before.vcd")) {
        let j = r.link_join.as_ref().unwrap();
        if j.header_ps.is_some_and(|h| h <= t) {
            panic!("the capture's first character is a header: {}", r.summary());
        }
        unseen_before_the_join(&r, t);
    }
    // a third of a slice: no whole packet
    let w = (from, from + s.grid.slice_cycles / 3);
    for r in judged(&s, &clean, w, phase, &d.path().join("short.vcd")) {
        let text = r.summary();
        let j = r.link_join.as_ref().unwrap();
        assert!(r.ok && !j.judged && j.header_ps.is_none(), "{text}");
        assert!(text.contains("PASS (the link not judged)"), "{text}");
        assert!(text.contains("link: NOT JUDGED"), "{text}");
        assert!(j.unjudged_ps > 0, "{text}");
    }
}

/// `check --map` of a capture of the UART preset from its middle: exit 0
/// with and without `--no-model`, the `link:` line in the text, and
/// `link_join` in the JSON with what joined the line and what was skipped.
#[test]
fn check_map_reports_where_it_joined_the_line() {
    let d = tempfile::tempdir().unwrap();
    let (mix, s, wave, [m, _]) = preset_capture("eskin34-uart.toml", 999, 1_234, d.path());
    let (_, map) = analyser::lanes(&s);
    for (flags, by) in [(vec![], "model"), (vec!["--no-model"], "decoder")] {
        let run = |json: bool| {
            let mut cmd = crate::common_cli::slotforge();
            cmd.arg("check").args(&flags).args(["--map", &map]);
            if json {
                cmd.arg("--json");
            }
            cmd.arg(&mix).arg(&wave).output().unwrap()
        };
        let out = run(false);
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{flags:?}: {text}");
        assert!(
            text.contains("link: joined the line at its first whole packet"),
            "{text}"
        );
        let out = run(true);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let j = &v["link_join"];
        let mj = m.link_join.as_ref().unwrap();
        join_in_json(j, by, mj);
        assert_eq!(j["unjudged_ps"], mj.unjudged_ps, "{j}");
        assert_eq!(j["frame_counter"], mj.frame_counter.unwrap(), "{j}");
        assert!(text.contains(j["text"].as_str().unwrap()), "{j}");
    }
}

/// The AXI4-Stream mixes of the random link mixes from seed 1.
fn axis_mix() -> Schedule {
    random_link_mixes(1, 6)
        .into_iter()
        .map(|(_, s)| s)
        .find(|s| kind(s) == Some(LinkKind::Axis))
        .expect("an AXI4-Stream mix")
}

/// The cycles of `p` from `at` on with a beat (tvalid and tready high).
fn beats(p: &[Pins], at: u64) -> impl Iterator<Item = usize> + '_ {
    (at as usize..p.len()).filter(|&c| p[c].axis_tvalid && p[c].axis_tready)
}

/// Faults on an AXI4-Stream link inside a capture, after the join: a
/// flipped `tdata` bit (a bad CRC) and a dropped `tlast` fail it, with
/// and without the model, at the beat's time (within a packet for the
/// CRC, which shows at the trailer).
#[test]
fn an_axis_fault_after_the_join_fails_the_capture_at_its_time() {
    let s = axis_mix();
    let d = tempfile::tempdir().unwrap();
    let f = s.grid.frame_cycles;
    let clean = pins(&s, 4);
    let (w, phase) = ((f / 2 + 777, f / 2 + 777 + 2 * f), 3_210);
    let at = w.0 + f;
    let plan = lut_gen::plan_link(&s).unwrap().unwrap();
    let within = at_ps(
        &s,
        w.0 + 2 * s.grid.slice_cycles + plan.latency_cycles,
        w.0,
        0,
    );
    // tdata bit 2 flipped: in a packet's seventh beat (a record's, or the
    // trailer's CRC), a bad CRC; in its header's SYNC, the decoder loses
    // its place
    let sync = beats(&clean, at)
        .find(|&c| clean[c].axis_tdata == link::format::SYNC)
        .unwrap();
    for (k, what) in [(6, "bad CRC"), (0, "lost its place")] {
        let c = beats(&clean, sync as u64).nth(k).unwrap();
        let mut flipped = clean.clone();
        flipped[c].axis_tdata ^= 4;
        let t = at_ps(&s, c as u64, w.0, phase);
        for r in judged(&s, &flipped, w, phase, &d.path().join("flip.vcd")) {
            fails_after_the_join(&r, t, within);
            let text = r.summary();
            assert!(r.link_join.as_ref().unwrap().judged, "{text}");
            assert!(r.violations[0].detail.contains(what), "{what}: {text}");
        }
    }
    // a packet's last beat without tlast
    let c = beats(&clean, at).find(|&c| clean[c].axis_tlast).unwrap();
    let mut dropped = clean.clone();
    dropped[c].axis_tlast = false;
    let t = at_ps(&s, c as u64, w.0, phase);
    let tc = at_ps(&s, w.0 + 1, w.0, 0);
    for r in judged(&s, &dropped, w, phase, &d.path().join("tlast.vcd")) {
        let text = r.summary();
        assert!(!r.ok, "{text}");
        let v = &r.violations[0];
        assert_eq!(v.rule, "link tlast", "{text}");
        assert_eq!(v.port_bit, "m_axis_tlast", "{text}");
        assert!(
            v.time_ps.abs_diff(t) <= tc,
            "tlast dropped at {t} ps: {text}"
        );
    }
}

/// With the model, the beats' cycles are held to it (tready from the
/// capture): the stream one cycle late from a beat on (tvalid low in that
/// cycle) fails the model's report at that beat.
#[test]
fn an_axis_beat_a_cycle_late_fails_against_the_model() {
    let s = axis_mix();
    let d = tempfile::tempdir().unwrap();
    let f = s.grid.frame_cycles;
    let clean = pins(&s, 4);
    let (w, phase) = ((f / 2 + 321, f / 2 + 321 + 2 * f), 6_543);
    let c = beats(&clean, w.0 + f).next().unwrap();
    let mut late = clean.clone();
    for k in c..late.len() {
        let o = if k == c { None } else { Some(&clean[k - 1]) };
        late[k].axis_tvalid = o.is_some_and(|o| o.axis_tvalid);
        late[k].axis_tdata = o.map_or(0, |o| o.axis_tdata);
        late[k].axis_tlast = o.is_some_and(|o| o.axis_tlast);
    }
    let t = at_ps(&s, c as u64, w.0, phase);
    let tc = at_ps(&s, w.0 + 1, w.0, 0);
    let [m, _] = judged(&s, &late, w, phase, &d.path().join("late.vcd"));
    let text = m.summary();
    assert!(!m.ok, "{text}");
    let v = m
        .violations
        .iter()
        .find(|v| v.rule == "link timing (beats)")
        .unwrap_or_else(|| panic!("{text}"));
    assert!(v.time_ps.abs_diff(t) <= 2 * tc, "late from {t} ps: {text}");
}

/// On an AXI4-Stream link the beats before the first whole packet are not
/// judged: a flipped `tdata` bit in the capture's first beat passes, inside
/// the time reported unjudged.
#[test]
fn axis_beats_before_the_join_are_reported_as_not_judged() {
    let s = axis_mix();
    let d = tempfile::tempdir().unwrap();
    let f = s.grid.frame_cycles;
    let clean = pins(&s, 3);
    let phase = 1_234;
    // a window opening inside a packet: its first beat is not a header
    let from = (f / 2..f)
        .find(|&c| {
            let p = &clean[c as usize + 3];
            p.axis_tvalid && p.axis_tready && p.axis_tdata != link::format::SYNC
        })
        .unwrap();
    let w = (from, from + f);
    let mut bad = clean.clone();
    bad[from as usize + 3].axis_tdata ^= 0x10;
    let t = at_ps(&s, from + 3, from, phase);
    for r in judged(&s, &bad, w, phase, &d.path().join("before.vcd")) {
        unseen_before_the_join(&r, t);
    }
}

/// `check --map` of a capture of the AXI4-Stream preset: the map names the
/// `m_axis_*` ports and `link_overflow`; exit 0, `link_join` in the JSON.
#[test]
fn check_map_reads_an_axis_links_beats() {
    let d = tempfile::tempdir().unwrap();
    let (mix, s, wave, reports) = preset_capture("eskin34-axis.toml", 555, 4_321, d.path());
    let (_, map) = analyser::lanes(&s);
    assert!(map.contains("m_axis_tdata[7]") && map.contains("link_overflow"));
    for (flags, m) in [(vec![], &reports[0]), (vec!["--no-model"], &reports[1])] {
        let mut cmd = crate::common_cli::slotforge();
        cmd.arg("check")
            .args(&flags)
            .args(["--map", &map, "--json"]);
        let out = cmd.arg(&mix).arg(&wave).output().unwrap();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(out.status.code(), Some(0), "{flags:?}: {v}");
        let mj = m.link_join.as_ref().unwrap();
        join_in_json(&v["link_join"], mj.by, mj);
    }
    // link_tx is not a port of an AXI4-Stream mix: the message says which are
    let e = judge::parse_map("D0=link_tx", &s).unwrap_err();
    assert!(
        e.contains("AXI4-Stream") && e.contains("m_axis_tdata[7:0]"),
        "{e}"
    );
}
