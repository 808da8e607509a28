use hdl::for_tests::{plan_with, FrontWord};
use hdl::LutForm;

use crate::common::from_toml;

#[test]
fn every_modes_table_sits_at_its_mode_on_the_address() {
    for name in ["modes-pin", "modes-auto", "eskin34-adaptive"] {
        let s = lut_gen::synthesize(&lut_gen::load(&testkit::mix(name)).unwrap()).unwrap();
        let p = plan_with(&s, LutForm::Auto).unwrap();
        let mp = p.modes.as_ref().unwrap();
        assert_eq!(mp.count, s.modes.len(), "{name}");
        for (b, rom) in p.branches.iter().enumerate() {
            let top = rom.word_bits() - 1;
            let conv_bit = top - 1;
            for (m, ms) in s.modes.iter().enumerate() {
                let mut left = false;
                for u in (0..s.grid.frame_slots).rev() {
                    let w = rom.words[(m << mp.slot_bits) | u as usize];
                    let at = ms.at(u, b);
                    assert_eq!(
                        w >> conv_bit & 1 == 1,
                        at.is_some(),
                        "{name} b{b} m{m} u{u}"
                    );
                    left |= at.is_some();
                    assert_eq!(w >> top & 1 == 0, left, "{name} b{b} m{m} u{u}: w bit");
                }
                let used = (0..s.grid.frame_slots).any(|u| ms.at(u, b).is_some());
                assert_eq!(!rom.modes.as_ref().unwrap().first[m].is_empty(), used);
            }
        }
    }
    let s = lut_gen::synthesize(&lut_gen::load(&testkit::mix("tiny")).unwrap()).unwrap();
    let p = plan_with(&s, LutForm::Auto).unwrap();
    assert!(p.modes.is_none() && p.branches.iter().all(|r| r.modes.is_none()));
}

/// `front-modes`: each mode's words select the conversion two later in
/// its own frame, or the next frame's `j`-th; the front pins are the
/// mux field (one first instant per mode), not an index.
#[test]
fn a_fronted_branch_has_each_modes_words_and_its_front_pins_in_the_rom() {
    let s = lut_gen::synthesize(&lut_gen::load(&testkit::mix("front-modes")).unwrap()).unwrap();
    let p = plan_with(&s, LutForm::Auto).unwrap();
    let rom = &p.branches[0];
    let f = rom.front.as_ref().unwrap().modes.as_ref().unwrap();
    let m = rom.modes.as_ref().unwrap();
    assert!(!m.indexed(), "the mux field holds the front pins");
    assert_ne!(f.words[0], f.words[1], "the modes' words differ");
    for (k, ms) in s.modes.iter().enumerate() {
        let convs: Vec<usize> = (0..s.grid.frame_slots)
            .filter_map(|u| ms.at(u, 0))
            .collect();
        let n = convs.len();
        assert_eq!(f.words[k].len(), n);
        for (i, w) in f.words[k].iter().enumerate() {
            let want = match convs.get(i + 2) {
                Some(&c) => FrontWord::Here(s.mix.channels[c].input),
                None => FrontWord::Next((i + 2 - n) as u32),
            };
            assert_eq!(*w, want, "mode {k} conversion {i}");
        }
        let input = |&c: &usize| s.mix.channels[c].input;
        assert_eq!(f.first[k], convs[..2].iter().map(input).collect::<Vec<_>>());
        let c = &s.channels[convs[0]];
        assert_eq!(
            m.first[k],
            vec![(c.select, c.device)],
            "mode {k}'s first front pins"
        );
    }
}

const MIX: &str = r#"
name = "left-out"
[clock]
hz = 4_000_000
[frame]
period_us = 1_000
slice_us = 500
[[mode]]
name = "a"
[[mode]]
name = "b"
[modes]
select = "pin"
[[branch]]
name = "x"
adc = "ad7940"
mux = "tmux1108"
mux_devices = 1
settle_ns = 1_000
[[branch]]
name = "y"
adc = "ad7940"
mux = "tmux1108"
mux_devices = 1
settle_ns = 1_000
[[channel]]
name = "X0"
branch = "x"
rate_hz = 2_000
[[channel]]
name = "Y0"
branch = "y"
rate_hz = 1_000
rates = { a = 0 }
"#;

#[test]
fn a_branch_the_reset_mode_leaves_out_is_refused_with_its_name() {
    // refused up front by the mix check (the plan's own refusal stays
    // as a backstop for a schedule built by hand)
    let e = lut_gen::parse(std::path::Path::new("m.toml"), MIX)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("branch `y`") && e.contains("reset mode `a`"),
        "{e}"
    );
    // in the reset mode, and left out of the other: built
    let s = from_toml(
        "m.toml",
        &MIX.replace("rates = { a = 0 }", "rates = { b = 0 }"),
    );
    assert!(plan_with(&s, LutForm::Auto).is_ok());
    assert!(plan_with(&s, LutForm::Compact).is_err());
}
