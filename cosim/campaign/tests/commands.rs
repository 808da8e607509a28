//! Converters with a command word in the fault campaign: the classes
//! `wrong-channel-bits` and `late-command` are injected into every
//! commanded branch of the shared test mixes (an MCP3208, an AD7689 and an
//! ADS7953-like part; one AD7689 alone; in `make test-long` an MCP3208, an
//! AD7689 and a listening AD7940) and of random commanded mixes, and
//! each injection is caught by the model, by the invariants (the sample
//! held to the channel its word selected) and by sigrok's SPI decode of
//! `mosi`; clean runs pass every detector, sigrok's included.

use std::path::Path;

use campaign::{campaign_with, sites, Detector, FaultClass, Plan, Target};
use lut_gen::Schedule;

use crate::tools;

/// A random mix with an `mcp3208` and an `ad7689` branch (and a listening
/// one), channels on random inputs at random rates, from `seed`.
fn random_commanded(seed: u64, mhz: u64) -> Schedule {
    let mut draw = testkit::modemix::Draw::new(seed);
    let mut next = |n: u64| draw.below(n);
    let mut t = format!(
        "name = \"rc\"\n[clock]\nhz = {mhz}000000\n[frame]\nperiod_us = 1000\nslice_us = 500\n"
    );
    let branches = [
        ("m", "mcp3208", "internal"),
        ("l", "ad7940", "tmux1108"),
        ("a", "ad7689", "internal"),
    ];
    for (name, adc, mux) in branches {
        t += &format!("[[branch]]\nname = \"{name}\"\nadc = \"{adc}\"\nmux = \"{mux}\"\n");
    }
    let mut n = 0;
    for (name, _, _) in branches {
        let mut inputs: Vec<u64> = (0..8).collect();
        for _ in 0..2 + next(3) {
            let input = inputs.remove(next(inputs.len() as u64) as usize);
            let rate = [2000, 4000][next(2) as usize];
            t += &format!(
                "[[channel]]\nname = \"c{n}\"\nbranch = \"{name}\"\nrate_hz = {rate}\ninput = {input}\n"
            );
            n += 1;
        }
    }
    let m = lut_gen::parse(Path::new("rc.toml"), &t).unwrap();
    lut_gen::synthesize(&m).unwrap()
}

fn load(name: &str) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(&testkit::mix(name)).unwrap()).unwrap()
}

/// The shared test mix `name` clocked at `hz`: the same slots, words and
/// channels in fewer cycles a frame (its `hz = ` line replaced).
fn load_at(name: &str, hz: u64) -> Schedule {
    let path = testkit::mix(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let line = text.lines().find(|l| l.starts_with("hz = ")).unwrap();
    let text = text.replace(line, &format!("hz = {hz}"));
    lut_gen::synthesize(&lut_gen::parse(&path, &text).unwrap()).unwrap()
}

/// Each run's cost is its cycles, most of them in sigrok's decodes of
/// every branch: `make test` runs cmd-small (each kind of command word,
/// 4,000 cycles a frame), cmd-solo (the AD7689 alone) and a random mix
/// at 12 MHz (a listening AD7940 beside an MCP3208 and an AD7689);
/// `make test-long` cmd-pair and two random mixes at 24 MHz.
#[test]
fn command_faults_join_the_campaign_and_every_detector_sees_them() {
    let mixes = [load("cmd-small"), load("cmd-solo"), random_commanded(5, 12)];
    command_faults_are_seen(&mixes, 3);
}

#[test]
#[ignore = "long: make test-long (cmd-pair, and random mixes at 24 MHz)"]
fn command_faults_of_cmd_pair_and_random_mixes_at_24_mhz_are_seen() {
    let mixes = [
        load("cmd-pair"),
        random_commanded(5, 24),
        random_commanded(9, 24),
    ];
    command_faults_are_seen(&mixes, 4);
}

/// The command classes of `mixes`' every commanded branch, each caught by
/// the model, the invariants and sigrok, in runs of `frames` frames.
fn command_faults_are_seen(mixes: &[Schedule], frames: u64) {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    for s in mixes {
        let mut plan = Plan::new(Target::Model, frames, 0);
        plan.sites = Some(
            sites(s)
                .into_iter()
                .filter(|x| x.name == "mid-frame")
                .collect(),
        );
        let c = campaign_with(s, &plan).unwrap();
        let name = &s.mix.name;
        assert!(
            c.ok(),
            "{name}: {:#?}",
            c.classes
                .iter()
                .filter(|k| !k.undetected.is_empty())
                .collect::<Vec<_>>()
        );
        let commanded = (0..s.branches.len()).filter(|&b| s.has_command(b)).count() as u64;
        for class in [FaultClass::WrongChannelBits, FaultClass::LateCommand] {
            let k = c
                .classes
                .iter()
                .find(|k| k.name == class)
                .unwrap_or_else(|| panic!("{name}: no {class:?}"));
            assert_eq!(k.injected, commanded, "{name} {class:?}");
            for d in [Detector::Model, Detector::Invariants, Detector::Sigrok] {
                assert_eq!(
                    k.detected_by.get(&d),
                    Some(&k.injected),
                    "{name} {class:?} {d:?}"
                );
            }
        }
    }
}

/// The emitted Verilog's word of the `k`-th command unit (`wire [..] word =
/// {MSB, ..., bit sent first};`), edited by `f` (its elements, MSB first).
fn edit_word(v: &str, k: usize, f: &dyn Fn(&mut Vec<String>)) -> String {
    let mut seen = 0;
    let lines: Vec<String> = v
        .lines()
        .map(|l| {
            let Some((head, rest)) = l.split_once("] word = {") else {
                return l.to_string();
            };
            seen += 1;
            if seen != k + 1 {
                return l.to_string();
            }
            let body = rest.strip_suffix("};").unwrap();
            let mut el: Vec<String> = body.split(", ").map(str::to_string).collect();
            f(&mut el);
            format!("{head}] word = {{{}}};", el.join(", "))
        })
        .collect();
    assert!(seen > k, "no command unit {k}");
    lines.join("\n") + "\n"
}

/// Verilog that sends the wrong channel bits (the channel bit sent last
/// inverted in every word) or each word one SCLK period late, one command unit at a
/// time, on Icarus: every detector catches each, and the clean Verilog
/// passes them all (sigrok's MOSI decode included). Each edit is an Icarus
/// run of three frames, whose cost is the mix's cycles: `make test` edits
/// every unit of cmd-small (the MCP3208's word, read in the same
/// conversion, the AD7689's and the ADS7953-like part's, two ahead: each
/// kind of word) at 2 MHz, a quarter of its 8 MHz cycles (3,000 cycles a
/// run; its slots and words are the same), `make test-long` cmd-small at
/// 8 MHz and every unit of cmd-pair (72,000 cycles a run).
#[test]
fn verilog_sending_wrong_or_late_words_fails_on_icarus() {
    let s = load_at("cmd-small", 2_000_000);
    assert_eq!(s.grid.frame_cycles, 1_000);
    wrong_or_late_words_fail_on_icarus(&s);
}

#[test]
#[ignore = "make test-long: the wrong and late words of cmd-small at 8 MHz and of every command unit of cmd-pair on Icarus"]
fn verilog_sending_wrong_or_late_words_of_every_unit_fails_on_icarus() {
    wrong_or_late_words_fail_on_icarus(&load("cmd-small"));
    wrong_or_late_words_fail_on_icarus(&load("cmd-pair"));
}

/// Wrong and late words of every command unit of `s`.
fn wrong_or_late_words_fail_on_icarus(s: &Schedule) {
    if !tools::require_tools(&["sigrok-cli", "iverilog"]) {
        return;
    }
    let v = engines::verilog(s).unwrap();
    let units = (0..s.branches.len()).filter(|&b| s.has_command(b)).count();
    assert!(units >= 2, "{}: command units", s.mix.name);
    let mut plan = Plan::new(Target::Model, 3, 0);
    plan.builtin = false;
    plan.verilog_engines = vec![engines::Backend::Icarus];
    for k in 0..units {
        let wrong = edit_word(&v, k, &|el| {
            let i = el.iter().position(|e| e.starts_with("sel[")).unwrap();
            el[i] = format!("~{}", el[i]);
        });
        let late = edit_word(&v, k, &|el| {
            el.remove(0);
            el.push("1'b0".into());
        });
        for (class, verilog) in [
            (FaultClass::WrongChannelBits, wrong),
            (FaultClass::LateCommand, late),
        ] {
            plan.verilog_faults.push(campaign::VerilogFault {
                name: format!("{class:?} unit {k}"),
                class,
                verilog,
            });
        }
    }
    let c = campaign_with(s, &plan).unwrap();
    assert_eq!(c.false_alarms.rejected, 0, "{:?}", c.false_alarms);
    for class in [FaultClass::WrongChannelBits, FaultClass::LateCommand] {
        let k = c.classes.iter().find(|k| k.name == class).unwrap();
        assert_eq!(k.injected, units as u64, "{class:?}");
        for d in [Detector::Model, Detector::Invariants, Detector::Sigrok] {
            assert_eq!(
                k.detected_by.get(&d),
                Some(&k.injected),
                "{class:?} {d:?}: {k:?}"
            );
        }
    }
}

/// A campaign judges the mix's own clean run first: on a design that fails
/// clean (here a schedule whose table moved one conversion, so the model
/// the gateware would follow breaks the mix's intervals) it injects
/// nothing and vouches for nothing; on the design as synthesized it runs.
#[test]
fn a_campaign_on_a_design_that_fails_clean_reports_no_detection() {
    let good = load("tiny");
    let mut bad = good.clone();
    let nb = bad.branches.len();
    let (from, to) = (0..bad.grid.frame_slots as usize)
        .find_map(|u| {
            let free = (u + 1..bad.grid.frame_slots as usize)
                .find(|&v| bad.frame_table[v * nb].is_none())?;
            bad.frame_table[u * nb].map(|_| (u, free))
        })
        .expect("a conversion with a free slot after it");
    bad.frame_table.swap(from * nb, to * nb);
    for (s, clean) in [(&good, true), (&bad, false)] {
        let c = campaign_with(s, &Plan::new(Target::Model, 3, 0)).unwrap();
        assert_eq!(c.clean.ok, clean, "{:?}", c.clean);
        assert_eq!(c.injected > 0, clean, "{}", c.injected);
        assert_eq!(c.ok(), clean);
        assert_eq!(c.clean.why.is_some(), !clean);
    }
}
