//! Windows of link designs (a run seen from its middle, as `sim --from/--to`
//! writes it or a logic analyser captures it): `check` joins the link's
//! state from the line itself and passes a clean design with and without
//! the model, on every link preset and on random link mixes at random
//! offsets; a fault inside the window fails it at the fault's cycle.

use std::path::Path;

use judge::CycleSink;
use judge::WindowCheck as Judge;
use judge::{run_dut, Dut, Observer, RunOptions};
use judge::{CheckOptions, LockInfo, Pins, Verdict};
use judge::{FaultyDut, PinFault as Fault};

/// Feeds the cycles `[from, to)` of a run (counted from its first reset
/// cycle) to two judges, with and without the model, as a VCD of that
/// window would.
struct Window<'a> {
    judges: [Judge<'a>; 2],
    from: u64,
    to: u64,
}

impl Observer for Window<'_> {
    fn cycle(&mut self, cycle: u64, rst: bool, pins: &Pins, miso: u64) {
        if (self.from..self.to).contains(&cycle) {
            for j in &mut self.judges {
                j.cycle(Some(rst), pins, &Pins::default(), miso, 0);
            }
        }
    }
}

/// `dut` behind the AXIS slave a back end puts in front of it (a design
/// with an AXIS link; the design itself otherwise).
fn slaved<'a>(s: &lut_gen::Schedule, dut: impl Dut + 'a) -> Box<dyn Dut + 'a> {
    judge::with_slave(s, dut, ::link::ReadyPattern::Random { seed: 11 })
}

/// The window `[from, to)` of a run of `dut`, judged with the model and
/// without it.
fn judge_window(s: &lut_gen::Schedule, mut dut: impl Dut, (from, to): (u64, u64)) -> [Verdict; 2] {
    let opts = |model| CheckOptions {
        model,
        ..Default::default()
    };
    let mut w = Window {
        judges: [Judge::new(s, opts(true)), Judge::new(s, opts(false))],
        from,
        to,
    };
    let frames = to / s.grid.frame_cycles + 1;
    run_dut(
        s,
        &mut dut,
        frames,
        &RunOptions::default(),
        "run",
        Some(&mut w),
    );
    w.judges.map(|j| {
        let (r, lock) = j.finish("window").expect("the window locks");
        let lock: LockInfo = lock.expect("a window from the middle of a run");
        assert!(lock.checked_from < 2 * s.grid.slot_cycles, "{lock}");
        r
    })
}

fn load(path: &Path) -> lut_gen::Schedule {
    lut_gen::synthesize(&lut_gen::load(path).unwrap()).unwrap()
}

fn preset(name: &str) -> lut_gen::Schedule {
    load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("mixes")
            .join(name),
    )
}

fn rusthdl(s: &lut_gen::Schedule) -> engines::RustHdlDut {
    engines::RustHdlDut::new(s).expect("rust-hdl builds")
}

/// A seeded xorshift for the windows' offsets.
pub(crate) fn rng(seed: u64) -> impl FnMut() -> u64 {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    }
}

/// Random link mixes (the one generator, with a `[link]` drawn) whose
/// link the audit finds feasible: `n` of them from seed `seed` on.
pub(crate) fn random_link_mixes(seed: u64, n: usize) -> Vec<(u64, lut_gen::Schedule)> {
    let shape = campaign::Shape {
        link: Some(campaign::LinkShape::Either),
        ..Default::default()
    };
    (seed..)
        .filter_map(|k| {
            let text = campaign::random_mix(k, &shape);
            let mix = lut_gen::parse(Path::new("random.toml"), &text).ok()?;
            let s = lut_gen::synthesize(&mix).ok()?;
            matches!(lut_gen::plan_link(&s), Some(Ok(_))).then_some((k, s))
        })
        .take(n)
        .collect()
}

/// A window of `s` from a random offset: it opens anywhere after the
/// first half frame and lasts one to three frames.
fn random_window(s: &lut_gen::Schedule, next: &mut impl FnMut() -> u64) -> (u64, u64) {
    let f = s.grid.frame_cycles;
    let from = f / 2 + next() % (2 * f);
    (from, from + f + next() % (2 * f))
}

/// Both reports pass, and say where they joined the line: at a whole
/// packet, after skipping what was in flight.
fn assert_clean(what: &str, [m, d]: &[Verdict; 2]) {
    for (r, by) in [(m, "model"), (d, "decoder")] {
        assert!(r.ok, "{what}, {by}: {}", r.summary());
        let j = r
            .link_join
            .as_ref()
            .unwrap_or_else(|| panic!("{what}, {by}: no link join"));
        assert_eq!(j.by, by, "{what}");
        let from = j
            .checked_from_cycle
            .unwrap_or_else(|| panic!("{what}, {by}: {}", j.text()));
        assert!(from < r.cycles, "{what}, {by}: {}", j.text());
        assert!(r.summary().contains(&j.text()), "{what}: the text says it");
    }
    assert!(m.model_compared && !d.model_compared);
    let (jm, jd) = (m.link_join.as_ref().unwrap(), d.link_join.as_ref().unwrap());
    // the model joins at the header of the packet the decoder judges first
    assert_eq!(
        (jm.frame_counter, jm.slice),
        (jd.frame_counter, jd.slice),
        "{what}"
    );
    assert!(jm.header_cycle.unwrap() < jm.checked_from_cycle.unwrap());
}

/// The design a window is cut from: rust-hdl's model of the gateware, or
/// (where a run of many frames must stay quick) the judge's cycle model.
#[derive(Clone, Copy)]
enum Engine {
    RustHdl,
    Model,
}

fn design(s: &lut_gen::Schedule, e: Engine) -> Box<dyn Dut> {
    match e {
        Engine::RustHdl => slaved(s, rusthdl(s)),
        Engine::Model => slaved(s, judge::ModelDut::new(s)),
    }
}

fn presets(windows: usize, e: Engine) {
    for name in ["eskin34-uart.toml", "eskin34-axis.toml"] {
        let s = preset(name);
        let mut next = rng(27);
        for _ in 0..windows {
            let w = random_window(&s, &mut next);
            assert_clean(
                &format!("{name} {w:?}"),
                &judge_window(&s, design(&s, e), w),
            );
        }
    }
}

#[test]
fn windows_of_the_link_presets_pass_with_and_without_the_model() {
    presets(1, Engine::Model);
}

#[test]
#[ignore = "long: make test-long"]
fn windows_of_the_link_presets_on_rust_hdl_pass() {
    presets(4, Engine::RustHdl);
}

fn random_mixes(seed: u64, mixes: usize, windows: usize, e: Engine) {
    let found = random_link_mixes(seed, mixes);
    assert_eq!(found.len(), mixes);
    let axis = found
        .iter()
        .filter(|(_, s)| {
            s.mix
                .link
                .as_ref()
                .is_some_and(|l| l.kind == lut_gen::LinkKind::Axis)
        })
        .count();
    assert!(
        axis > 0 && axis < mixes,
        "both kinds of link drawn: {axis} AXIS of {mixes}"
    );
    for (k, s) in &found {
        let mut next = rng(*k);
        for _ in 0..windows {
            let w = random_window(s, &mut next);
            assert_clean(
                &format!("random mix {k} {w:?}"),
                &judge_window(s, design(s, e), w),
            );
        }
    }
}

#[test]
fn windows_of_random_link_mixes_pass_with_and_without_the_model() {
    random_mixes(1, 2, 1, Engine::RustHdl);
}

#[test]
fn windows_of_more_random_link_mixes_pass_on_the_model() {
    random_mixes(20, 6, 2, Engine::Model);
}

#[test]
#[ignore = "long: make test-long"]
fn windows_of_forty_random_link_mixes_pass() {
    random_mixes(100, 40, 4, Engine::RustHdl);
}

/// A fault inside a window of a link design fails it, with the model at
/// the fault's cycle and without it after the fault: a flipped UART bit,
/// an AXIS beat whose `tdata` changes while it waits, a wrong sample.
#[test]
fn a_fault_inside_a_window_fails_it_at_its_cycle() {
    let mixes = random_link_mixes(1, 4);
    let kind = |s: &lut_gen::Schedule| s.mix.link.as_ref().map(|l| l.kind);
    let uart = mixes
        .iter()
        .find(|(_, s)| kind(s) == Some(lut_gen::LinkKind::Uart));
    let axis = mixes
        .iter()
        .find(|(_, s)| kind(s) == Some(lut_gen::LinkKind::Axis));
    let (uart, axis) = (&uart.expect("a UART mix").1, &axis.expect("an AXIS mix").1);
    let reset = RunOptions::default().reset_cycles;
    for (s, fault, signal) in [
        (uart, Fault::LinkBitFlip, "link_tx"),
        (axis, Fault::AxisTdataChange, "m_axis_tdata"),
        (uart, Fault::WrongSampleBit, "sample_value"),
    ] {
        let f = s.grid.frame_cycles;
        let (from, to) = (f / 2 + 1_234, f / 2 + 1_234 + 2 * f);
        // the site, in cycles after reset: a frame into the window, well
        // after the line was joined
        let at = from + f;
        let site = at + reset - from;
        // outside the slave, as the fault campaign puts it: on the pins
        let dut = FaultyDut::new(s, slaved(s, rusthdl(s)), fault, at);
        let [m, d] = judge_window(s, dut, (from, to));
        let name = fault.class();
        for r in [&m, &d] {
            assert!(!r.ok, "{name}: not caught\n{}", r.summary());
            let j = r.link_join.as_ref().expect("joined the line");
            let joined = j.checked_from_cycle;
            assert!(joined.is_some_and(|c| c < site), "{name}: {}", r.summary());
        }
        let dv = &m.divergences[0];
        assert_eq!(dv.signal, signal, "{name}: {}", m.summary());
        // the first character, beat or sample at or after the site
        let near = s.grid.slot_cycles * 4;
        assert!(
            (site..site + near).contains(&dv.cycle),
            "{name}: the model's first divergence at capture cycle {}, the fault at {site}",
            dv.cycle
        );
        assert!(!d.violations.is_empty(), "{name}: {}", d.summary());
        for v in &d.violations {
            assert!(v.cycle >= site, "{name}: {v:?} before the fault");
        }
    }
}

/// The issue's own steps, on the emitted Verilog: a Verilator window of the
/// UART preset from frame 1 to 3 passes `check` with and without the
/// model, and the report says where the line was joined (text and JSON).
#[test]
fn a_verilator_window_of_the_uart_preset_passes_check() {
    if !crate::tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let wave = d.path().join("w.vcd");
    let mix = Path::new(env!("CARGO_MANIFEST_DIR")).join("mixes/eskin34-uart.toml");
    crate::common_cli::slotforge()
        .arg("sim")
        .arg(&mix)
        .args([
            "--backend",
            "verilator",
            "--frames",
            "3",
            "--from",
            "1",
            "--to",
            "3",
            "--vcd",
        ])
        .arg(&wave)
        .assert()
        .code(0);
    for (flags, by) in [(vec![], "model"), (vec!["--no-model"], "decoder")] {
        let out = crate::common_cli::slotforge()
            .arg("check")
            .args(&flags)
            .arg(&mix)
            .arg(&wave)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{flags:?}: {text}");
        assert!(
            text.contains("link: joined the line at its first whole packet"),
            "{text}"
        );
        let out = crate::common_cli::slotforge()
            .arg("check")
            .args(&flags)
            .arg("--json")
            .arg(&mix)
            .arg(&wave)
            .output()
            .unwrap();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["ok"], true);
        let j = &v["link_join"];
        assert_eq!(j["by"], by, "{j}");
        assert!(j["checked_from_cycle"].as_u64().unwrap() < v["cycles"].as_u64().unwrap());
        assert!(j["skipped_bytes"].is_u64() && j["slice"].is_u64(), "{j}");
        // from frame 1: the first whole packet is of frame 1 (counter 1)
        assert_eq!(j["frame_counter"], 1, "{j}");
    }
}

/// The line before the first whole packet is not judged, and the report
/// says how much of it: a flipped UART bit there passes unseen, inside the
/// cycles the join reports as not judged (text and JSON fields); a window
/// too short to hold a whole packet says the link was not judged at all.
#[test]
fn the_line_before_the_join_is_reported_as_not_judged() {
    let mixes = random_link_mixes(1, 4);
    let kind = |s: &lut_gen::Schedule| s.mix.link.as_ref().map(|l| l.kind);
    let (_, s) = mixes
        .iter()
        .find(|(_, s)| kind(s) == Some(lut_gen::LinkKind::Uart))
        .expect("a UART mix");
    let reset = RunOptions::default().reset_cycles;
    let f = s.grid.frame_cycles;
    let (from, to) = (f / 2 + 777, f / 2 + 777 + f);
    // the first character that starts in the window: in flight, before
    // the first whole packet
    let dut = FaultyDut::new(s, slaved(s, rusthdl(s)), Fault::LinkBitFlip, from);
    let site = reset; // capture cycles: the window's first cycle
    for r in judge_window(s, dut, (from, to)) {
        let j = r.link_join.as_ref().expect("joined");
        assert!(r.ok, "{}", r.summary());
        assert!(j.judged, "{}", r.summary());
        assert!(
            j.unjudged_cycles > site,
            "the fault at capture cycle {site} lies in the unjudged part: {}",
            r.summary()
        );
        assert_eq!(Some(j.unjudged_cycles), j.header_cycle, "{}", r.summary());
        assert!(j.header_cycle < j.checked_from_cycle, "{}", r.summary());
        let text = r.summary();
        assert!(
            text.contains(&format!(
                "its first {} cycle(s) and {} byte(s)",
                j.unjudged_cycles, j.skipped_bytes
            )) && text.contains("not judged"),
            "{text}"
        );
    }
    // A window of a third of a slice: no whole packet in it.
    let (from, to) = (f / 2 + 777, f / 2 + 777 + s.grid.slice_cycles / 3);
    let dut = slaved(s, judge::ModelDut::new(s));
    for r in judge_window(s, dut, (from, to)) {
        let j = r.link_join.as_ref().expect("a link join report");
        assert!(
            !j.judged && j.checked_from_cycle.is_none(),
            "{}",
            r.summary()
        );
        // every cycle of the window the lock checked, and at most the window
        assert!(
            (r.cycles..=to - from).contains(&j.unjudged_cycles),
            "{} of {} cycles: {}",
            j.unjudged_cycles,
            to - from,
            r.summary()
        );
        let text = r.summary();
        assert!(text.contains("PASS (the link not judged)"), "{text}");
        assert!(text.contains("link: NOT JUDGED"), "{text}");
    }
}
