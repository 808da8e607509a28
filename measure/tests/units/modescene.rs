//! The mode scene on the preset, the shared mode mixes and random auto
//! mixes: the switches follow the scene, every reaction measured is within
//! the audit's worst, and the summary's numbers are the chart's.

use engines::{Backend, SimOptions, Stimulus};
use lut_gen::Schedule;
use measure::{mode_scene, mode_section, one_mode, ModeScene};

fn schedule(text: &str) -> Schedule {
    let m = lut_gen::parse(std::path::Path::new("t.toml"), text).unwrap();
    lut_gen::synthesize(&m).unwrap()
}

fn preset(name: &str) -> Schedule {
    schedule(&std::fs::read_to_string(testkit::mix(name)).unwrap())
}

fn run(s: &Schedule, scene: &str, requests: &[(u64, u8)], frames: u64) -> ModeScene {
    let opts = SimOptions {
        stimulus: Stimulus::parse_for(scene, s).unwrap(),
        modes: requests.to_vec(),
        ..SimOptions::default()
    };
    mode_scene(s, Backend::Model, frames, &opts).unwrap()
}

/// The summary, the first screen's answer and the chart's table say the
/// same numbers: the totals and the saving are the table's columns summed,
/// each switch is a change of the table's mode, and no reaction measured
/// is longer than the audit's worst.
fn consistent(s: &Schedule, m: &ModeScene, scene: &str) {
    assert!(m.problems(s).is_empty(), "{:?}", m.problems(s));
    let (sec, line, glance) = mode_section(s, m, scene, "model");
    let t = &sec.figures[0].table;
    let sum = |col: usize| -> u64 { t.rows.iter().map(|r| r[col].parse::<u64>().unwrap()).sum() };
    let (with, without) = (sum(3), sum(4));
    assert_eq!(m.totals(), (with, Some(without)));
    let pct = 100.0 * (1.0 - with as f64 / without as f64);
    let unit = if m.bytes { "link bytes" } else { "samples" };
    let words =
        format!("{with} {unit} with modes against {without} with one mode: {pct:.1} % less");
    assert!(
        line.contains(&words) && glance.contains(&words),
        "{line}\n{glance}\n{words}"
    );
    let switches: Vec<u64> = t
        .rows
        .windows(2)
        .filter(|w| w[0][2] != w[1][2])
        .map(|w| w[1][0].parse().unwrap())
        .collect();
    let reacted: Vec<u64> = m.reactions.iter().map(|r| r.frame).collect();
    assert_eq!(switches, reacted, "{line}");
    for r in &m.reactions {
        assert!(r.measured() > 0 && r.measured() <= r.predicted, "{r:?}");
        // the reaction's table row has the same milliseconds as the struct
        let ms = format!("{:.3}", r.measured() as f64 * 1e3 / s.grid.clock_hz as f64);
        assert!(sec.tables[0].1.rows.iter().any(|row| row[4] == ms), "{ms}");
    }
}

#[test]
fn a_stroke_over_the_adaptive_preset_switches_to_contact_and_back() {
    let s = preset("eskin34-adaptive");
    let scene = "stroke:CH7,CH11,CH15,CH20,CH25,CH29@3-9";
    let m = run(&s, scene, &[], 24);
    consistent(&s, &m, scene);
    let names: Vec<usize> = m.reactions.iter().map(|r| r.to).collect();
    assert_eq!(names, vec![1, 0], "contact, then idle");
    // pressed from frame 3: decided from window 3 at the edge of frame 4
    assert_eq!(m.reactions[0].frame, 5);
    // every frame after the first samples as many as its mode's schedule
    for f in &m.with_modes[1..] {
        assert_eq!(
            f.samples,
            s.modes[f.mode as usize].samples_per_frame(),
            "{f:?}"
        );
    }
    let flat = one_mode(&s).unwrap();
    for f in &m.without.as_ref().unwrap().1[1..] {
        assert_eq!(f.samples, flat.samples_per_frame(), "{f:?}");
    }
    assert!(m.saving_pct().unwrap() > 10.0);
}

#[test]
fn the_mode_mixes_and_random_auto_mixes_react_within_the_audits_worst() {
    let auto = preset("modes-auto");
    let m = run(&auto, "touch:T0,T1@2-8", &[], 16);
    consistent(&auto, &m, "touch:T0,T1@2-8");
    assert!(m.reactions.len() >= 2, "{:?}", m.reactions);
    let pin = preset("modes-pin");
    let m = run(&pin, "pattern", &[(2, 1), (6, 0)], 12);
    consistent(&pin, &m, "pattern");
    assert_eq!(
        m.reactions.iter().map(|r| r.frame).collect::<Vec<_>>(),
        vec![4, 8]
    );
    assert!(m.reactions.iter().all(|r| r.trigger.is_none()));
    let mut switched = 0;
    for seed in 1..8u64 {
        let s = schedule(&random_auto_mix(seed));
        let m = run(&s, "touch:c0@2-5", &[], 12);
        consistent(&s, &m, "touch:c0@2-5");
        switched += m.reactions.len();
    }
    assert!(switched >= 7, "the touches switched {switched} times");
}

#[test]
fn a_reaction_longer_than_the_audits_worst_is_a_problem() {
    let s = preset("modes-auto");
    let mut m = run(&s, "touch:T0@2-6", &[], 10);
    assert!(m.problems(&s).is_empty());
    let r = &mut m.reactions[0];
    r.predicted = r.measured() - 1;
    let p = m.problems(&s);
    assert!(
        p.len() == 1 && p[0].contains("longer than the audit's worst"),
        "{p:?}"
    );
}

/// Two modes on a UART: c0 (watched) at 1 kHz in both, the other channels
/// at random harmonic rates, up when c0 is above a random level, back when
/// it is below 2000 for 1 to 3 frames.
fn random_auto_mix(seed: u64) -> String {
    use std::fmt::Write;
    let mut draw = testkit::modemix::Draw::new(seed);
    let mut next = |n: u64| draw.below(n);
    let mut t = format!(
        "name = \"r{seed}\"\n[clock]\nhz = 8_000_000\n[frame]\nperiod_us = 1_000\nslice_us = 500\n\
         [[mode]]\nname = \"low\"\n[[mode]]\nname = \"high\"\n[modes]\nselect = \"auto\"\n\
         [[trigger]]\nto = \"high\"\nwhen = \"above\"\nlevel = {}\nchannels = [\"c0\"]\n\
         [[trigger]]\nto = \"low\"\nwhen = \"below\"\nlevel = 2000\nchannels = [\"c0\"]\nfor_frames = {}\n\
         [[branch]]\nname = \"b\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 2\nsettle_ns = 500\n",
        4000 + next(8000),
        1 + next(3)
    );
    for c in 0..2 + next(6) {
        let (lo, hi) = if c == 0 {
            (1_000, 1_000)
        } else {
            (1_000, [1_000, 2_000, 4_000][next(3) as usize])
        };
        let _ = write!(
            t,
            "[[channel]]\nname = \"c{c}\"\nbranch = \"b\"\ninput = {c}\nrate_hz = {hi}\nrates = {{ low = {lo} }}\n"
        );
    }
    t + "[link]\nkind = \"uart\"\nbaud = 2_000_000\n"
}
