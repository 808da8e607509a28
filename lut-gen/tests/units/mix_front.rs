//! An external mux in front of a converter's own (`front_mux`,
//! `front_input`): what the mix means, and the refusals in the user's words.

use std::path::Path;

use super::{err, line_of};
use lut_gen::parse;
use lut_gen::synthesize;

const AD: &str = r#"
name = "t"
[clock]
hz = 40_000_000
[frame]
period_us = 1_000
slice_us = 1_000
[[branch]]
name = "a"
adc = "ad7689"
mux = "internal"
front_mux = "tmux1108"
front_mux_devices = 2
settle_ns = 1_000
[[channel]]
name = "F{0..9}"
branch = "a"
rate_hz = 1_000
input = 4
front_input = 5
[[channel]]
name = "S"
branch = "a"
rate_hz = 2_000
input = 1
"#;

/// A bulk block behind a front mux counts its front inputs (the converter
/// input stays); the schedule's pins address the front input, the words
/// select the converter's.
#[test]
fn a_front_mux_drives_the_pins_and_the_word_selects_the_converter_input() {
    let m = parse(Path::new("m.toml"), AD).unwrap();
    let b = &m.branches[0];
    assert!(b.fronted && b.mux == lut_gen::MuxPart::TMUX1108 && b.mux_devices == 2);
    for k in 0..10 {
        assert_eq!(
            (m.channels[k].input, m.channels[k].front_input),
            (4, Some(5 + k as u32))
        );
    }
    assert_eq!(
        (m.channels[10].input, m.channels[10].front_input),
        (1, None)
    );
    let s = synthesize(&m).unwrap();
    for (c, cs) in s.channels.iter().enumerate() {
        assert_eq!(
            cs.device * 8 + cs.select,
            m.channels[c].front_input.unwrap_or(0)
        );
        assert_eq!(s.groups[c], vec![Some(c)], "one conversion per channel");
    }
    let sent = s.commands_in_frame(0);
    assert_eq!(sent.len(), 12);
    for w in &sent {
        assert_eq!(w.input, m.channels[w.selects].input);
    }
}

#[test]
fn a_front_mux_is_refused_where_the_part_or_the_branch_does_not_permit_it() {
    let cases: Vec<(String, &str, &str, &str)> = vec![
        (
            AD.replace("adc = \"ad7689\"", "adc = \"mcp3208\""),
            "branch[0].front_mux",
            "front_mux = ",
            "samples its input inside the transaction",
        ),
        (
            AD.replace(
                "adc = \"ad7689\"\nmux = \"internal\"",
                "adc = \"ad7940\"\nmux = \"tmux1108\"",
            ),
            "branch[0].front_mux",
            "front_mux = ",
            "it needs mux = \"internal\"",
        ),
        (
            AD.replace("front_mux = \"tmux1108\"", "front_mux = \"tmux9\""),
            "branch[0].front_mux",
            "front_mux = ",
            "unknown front mux `tmux9` (known: tmux1108)",
        ),
        (
            AD.replace("front_mux_devices = 2", "front_mux_devices = 33"),
            "branch[0].front_mux_devices",
            "front_mux_devices",
            "at most 32",
        ),
        (
            AD.replace("front_mux = \"tmux1108\"\n", ""),
            "branch[0].front_mux_devices",
            "front_mux_devices",
            "name it with front_mux",
        ),
        (
            AD.replace("front_input = 5", "front_input = 12"),
            "channel[0].front_input",
            "front_input",
            "front inputs 0..=15",
        ),
        (
            AD.replace("input = 4\nfront_input", "front_input"),
            "channel[0].front_input",
            "front_input",
            "with `input` as well",
        ),
        (
            AD.replace("input = 1\n", "input = 4\n"),
            "channel[1].input",
            "input = 4\n\"",
            "wired through the front mux (`F0` has front_input 5) and straight (`S` has none)",
        ),
        (
            AD.replace("input = 1\n", "input = 4\nfront_input = 9\n"),
            "channel[1].input",
            "input = 4\nfront_input = 9",
            "input 4 with front_input 9 of branch `a` is already taken by channel `F4`",
        ),
        (
            AD.replace("input = 1\n", "input = 8\n"),
            "channel[1].input",
            "input = 8",
            "converter `ad7689` has channels 0..=7",
        ),
    ];
    for (text, field, at, says) in cases {
        let e = err(&text);
        assert_eq!(e.field, field, "{e}");
        assert!(e.message.contains(says), "{e}");
        if !at.ends_with('"') {
            assert_eq!(e.line, line_of(&text, at), "{e}");
        }
    }
    // front_input on a branch without a front mux
    let plain = AD.replace("front_mux = \"tmux1108\"\nfront_mux_devices = 2\n", "");
    let e = err(&plain);
    assert_eq!(e.field, "channel[0].front_input", "{e}");
    assert!(e.message.contains("has no front mux"), "{e}");
}

/// Random fronted mixes (a seed loop): every one that parses and
/// schedules has its pins on the front input and its words on the
/// converter's, and a straight channel never shares a converter input with a
/// fronted one.
#[test]
fn random_fronted_mixes_keep_pins_and_words_apart() {
    let mut state = 0x2545_f491_u64;
    let mut next = |n: u64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state % n
    };
    let mut scheduled = 0;
    for _ in 0..40 {
        let devices = 1 + next(3);
        let mut t = format!(
            "name = \"r\"\n[clock]\nhz = 40_000_000\n[frame]\nperiod_us = 2_000\nslice_us = 1_000\n\
             [[branch]]\nname = \"a\"\nadc = \"ad7689\"\nmux = \"internal\"\nfront_mux = \"tmux1108\"\n\
             front_mux_devices = {devices}\nsettle_ns = {}\n",
            100 * next(20)
        );
        let fronted_input = next(8);
        let n = 1 + next(6);
        for k in 0..n {
            let (input, front) = if k % 2 == 0 {
                (
                    fronted_input,
                    format!("front_input = {}\n", next(8 * devices)),
                )
            } else {
                ((fronted_input + 1 + k) % 8, String::new())
            };
            t += &format!(
                "[[channel]]\nname = \"c{k}\"\nbranch = \"a\"\nrate_hz = {}\ninput = {input}\n{front}",
                [500, 1_000, 2_000][next(3) as usize]
            );
        }
        let Ok(m) = parse(Path::new("r.toml"), &t) else {
            continue;
        };
        let s = synthesize(&m).unwrap();
        scheduled += 1;
        for (c, ch) in m.channels.iter().enumerate() {
            let cs = &s.channels[c];
            assert_eq!(
                cs.device * 8 + cs.select,
                ch.front_input.unwrap_or(0),
                "{t}"
            );
            let straight = m
                .channels
                .iter()
                .any(|o| o.input == ch.input && o.front_input.is_none());
            assert!(!(straight && ch.front_input.is_some()), "{t}");
        }
        for w in s.commands_in_frame(0) {
            assert_eq!(w.input, m.channels[w.selects].input, "{t}");
        }
        assert!(lut_gen::validate(&s).is_ok(), "{t}");
    }
    assert!(scheduled >= 10, "only {scheduled} random mixes scheduled");
}

/// The audit names both: the converter input a channel is on and, behind a
/// front mux, the pins that address it (its `dev.sel` cell and JSON fields).
#[test]
fn the_audit_shows_the_converter_input_and_the_front_pins() {
    let m = parse(Path::new("m.toml"), AD).unwrap();
    let s = synthesize(&m).unwrap();
    let a = lut_gen::AuditReport::of_schedule(&s);
    let text = a.to_text();
    for (c, ch) in a.channels.iter().enumerate() {
        let mc = &m.channels[c];
        assert_eq!(ch.adc_input, Some(mc.input));
        assert_eq!(ch.front_mux, mc.front_input.is_some());
        let cell = match mc.front_input {
            Some(f) => format!("in{}/{}.{}", mc.input, f / 8, f % 8),
            None => format!("in{}", mc.input),
        };
        let row = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(&ch.name))
            .unwrap();
        assert!(row.split_whitespace().any(|w| w == cell), "{row}");
    }
}

/// One front device, one output: its channels name one converter input.
#[test]
fn a_front_device_feeds_one_converter_input() {
    let text = format!(
        "{AD}[[channel]]\nname = \"X\"\nbranch = \"a\"\nrate_hz = 1_000\ninput = 2\nfront_input = 15\n"
    );
    let e = err(&text);
    let msg = e.to_string();
    assert!(msg.contains("channel[2].front_input"), "{msg}");
    assert!(
        msg.contains("front mux device 1 of branch `a` (front inputs 8..=15) has one output, wired to converter input 4 by `F3`"),
        "{msg}"
    );
    assert!(
        msg.contains(&format!("m.toml:{}:", line_of(&text, "front_input = 15"))),
        "{msg}"
    );
}

/// The audit's free inputs on a fronted branch, counted by hand: `AD` wires
/// devices 0 and 1 (F0..F9 on front inputs 5..14) to converter input 4 and S
/// straight to input 1: 6 converter inputs free, 5 + 1 front inputs free.
#[test]
fn the_audit_counts_free_places_behind_and_beside_the_front_mux() {
    let s = synthesize(&parse(Path::new("m.toml"), AD).unwrap()).unwrap();
    let a = lut_gen::AuditReport::of_schedule(&s);
    assert_eq!(a.branches[0].free_mux_inputs, 6 + 5 + 1);
    // one device without a channel takes a free converter input for its 8
    let one = AD.replace("front_mux_devices = 2", "front_mux_devices = 3");
    let s = synthesize(&parse(Path::new("m.toml"), &one).unwrap()).unwrap();
    let a = lut_gen::AuditReport::of_schedule(&s);
    assert_eq!(a.branches[0].free_mux_inputs, 6 + 5 + 1 + 7);
}

/// With `[[mode]]` tables a fronted AD7689 is accepted when every mode
/// converts it at least `command_ahead` (2) times per frame: each mode's
/// schedule has its own front pins; a mode that converts it once is
/// refused as any such converter's (its last word would select a frame
/// whose mode is not decided yet), naming the branch and the mode.
#[test]
fn a_front_mux_in_a_mix_with_modes_takes_each_modes_table() {
    let modes = AD.replace(
        "[[branch]]",
        "[[mode]]\nname = \"calm\"\n[[mode]]\nname = \"busy\"\n[modes]\nselect = \"pin\"\n[[branch]]",
    );
    let text = modes.replace(
        "rate_hz = 2_000\n",
        "rate_hz = 2_000\nrates = { busy = 4_000 }\n",
    );
    let m = parse(Path::new("m.toml"), &text).unwrap();
    let s = synthesize(&m).unwrap();
    let per = |k: usize| {
        (0..s.grid.frame_slots)
            .filter(|&u| s.modes[k].at(u, 0).is_some())
            .count()
    };
    assert_eq!((per(0), per(1)), (12, 14));
    // the pins of a fronted conversion address its front input in every mode
    for ms in &s.modes {
        for c in (0..s.grid.frame_slots).filter_map(|u| ms.at(u, 0)) {
            let f = m.channels[c].front_input.unwrap_or(0);
            assert_eq!(
                (ms.channels[c].device, ms.channels[c].select),
                (f / 8, f % 8)
            );
        }
    }
    let once = modes
        .replace(
            "rate_hz = 1_000\n",
            "rate_hz = 1_000\nrates = { busy = 0 }\n",
        )
        .replace("rate_hz = 2_000\n", "rate_hz = 1_000\n");
    let e = err(&once).to_string();
    assert!(
        e.contains("branch `a`")
            && e.contains("mode `busy`")
            && e.contains("whose mode is not decided yet"),
        "{e}"
    );
}
