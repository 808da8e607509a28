//! The equivalence check behind "proved equivalent" (`campaign::equiv`): it
//! must prove what is equivalent and refute what is not, or the campaign's
//! "proved equivalent" column would excuse misses.

use std::path::PathBuf;

use campaign::{check_equivalence as check, Equivalence};
use hdl::GatewareFault;

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::tools;

fn schedule(name: &str) -> lut_gen::Schedule {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../testkit/mixes")
        .join(name);
    lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap()
}

fn verdict(mix: &str, f: GatewareFault) -> Equivalence {
    verdict_of(&schedule(mix), f)
}

fn verdict_of(s: &lut_gen::Schedule, f: GatewareFault) -> Equivalence {
    let (gold, gate) = hdl::verilog_pair(s, f).unwrap();
    assert_ne!(gold, gate, "the fault changes the Verilog");
    let dir = tempfile::tempdir().unwrap();
    check(&gold, &gate, dir.path()).unwrap()
}

/// One channel converted in every slot: a frame one slot short changes the
/// slot counter but no output, for any input, ever: proved.
#[test]
fn a_frame_one_slot_short_is_proved_equivalent_when_every_slot_is_alike() {
    if !tools::require_tools(&["yosys", "yosys-abc"]) {
        return;
    }
    let v = verdict("every_slot.toml", GatewareFault::SlotWrap { delta: -1 });
    assert!(matches!(v, Equivalence::Proved { .. }), "{v:?}");
}

/// A slot-ROM word of another channel changes which input is converted:
/// refuted with a counterexample, never proved.  (With yosys's
/// `miter -ignore_gold_x` this was "proved": the flow must not use it.)
/// ABC's time grows with the frame's slots and the counterexample's depth
/// (a slot's cycles): `make test` edits a mix of two slots, 500 cycles a
/// frame (1.3 s of `pdr`), `make test-long` `tiny`'s eight (4,000 cycles,
/// 5 s).
#[test]
fn a_wrong_rom_word_is_not_equivalent() {
    wrong_rom_word_differs(&parse(TWO_SLOTS));
}

#[test]
#[ignore = "long: make test-long (tiny's slot ROM)"]
fn a_wrong_rom_word_of_tiny_is_not_equivalent() {
    wrong_rom_word_differs(&schedule("tiny.toml"));
}

/// Two channels of one AD7940 branch, one conversion each in a 125 us
/// frame at 4 MHz: two slots.
const TWO_SLOTS: &str = r#"name = "two-slots"
[clock]
hz = 4_000_000
[frame]
period_us = 125
slice_us = 125
[[branch]]
name = "b"
adc = "ad7940"
mux = "tmux1108"
settle_ns = 1_000
[[channel]]
name = "A0"
branch = "b"
rate_hz = 8_000
[[channel]]
name = "A1"
branch = "b"
rate_hz = 8_000
"#;

fn parse(text: &str) -> lut_gen::Schedule {
    lut_gen::synthesize(&lut_gen::parse(std::path::Path::new("two-slots.toml"), text).unwrap())
        .unwrap()
}

/// The first conversion slot of branch 0 given another channel's word.
fn wrong_rom_word_differs(s: &lut_gen::Schedule) {
    if !tools::require_tools(&["yosys", "yosys-abc"]) {
        return;
    }
    let conv: Vec<(u64, usize)> = (0..s.grid.frame_slots)
        .filter_map(|u| s.at(u, 0).map(|c| (u, c)))
        .collect();
    let (u, ch) = conv[0];
    let (from, _) = *conv.iter().find(|(_, c)| *c != ch).unwrap();
    let f = GatewareFault::RomWord {
        branch: 0,
        slot: u,
        from,
    };
    let v = verdict_of(s, f);
    assert!(matches!(v, Equivalence::Differs { .. }), "{v:?}");
}

/// ABC's answers as the campaign reads them.
#[test]
fn abc_output_is_read_as_proved_differs_or_undecided() {
    use campaign::equivalence_verdict as verdict;
    assert!(matches!(
        verdict("Property proved.  Time = 0.02 sec\n", 0.1),
        Equivalence::Proved { .. }
    ));
    assert_eq!(
        verdict(
            "Output 0 of miter \"miter\" was asserted in frame 3.  Time = 0.02 sec\n",
            0.1
        ),
        Equivalence::Differs { frame: Some(3) }
    );
    assert!(matches!(
        verdict(
            "Reached timeout (60 seconds) in frame 239.\nProperty UNDECIDED.\n",
            60.0
        ),
        Equivalence::Undecided { .. }
    ));
}
