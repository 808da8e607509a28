use lut_gen::for_tests::{on_grid, one_mode};
use lut_gen::{synthesize, Verdict, SEARCH_BUDGET};

use crate::common::testkit;

#[test]
fn every_mode_is_placed_on_one_grid_at_its_rates() {
    for name in ["modes-pin", "modes-auto", "eskin34-adaptive"] {
        let mix = testkit(name);
        let s = synthesize(&mix).unwrap();
        assert_eq!(s.modes.len(), mix.mode_count(), "{name}");
        for (m, ms) in s.modes.iter().enumerate() {
            assert_eq!(ms.grid, s.grid, "{name}");
            lut_gen::validate(ms).unwrap();
            for (c, ch) in mix.channels.iter().enumerate() {
                assert_eq!(
                    ms.channels[c].samples_per_frame,
                    mix.samples_per_frame(ch.rates[m]),
                    "{name} mode {m} `{}`",
                    ch.name
                );
                let seen = (0..s.grid.frame_slots)
                    .filter(|&slot| ms.at(slot, ch.branch) == Some(mix.lead_of(c)))
                    .count() as u64;
                assert_eq!(
                    seen, ms.channels[c].samples_per_frame,
                    "{name} `{}`",
                    ch.name
                );
            }
        }
        assert_eq!(s.frame_table, s.modes[0].frame_table);
        assert_eq!(s.mix, mix.in_mode(0));
        lut_gen::validate(&s).unwrap();
    }
}

#[test]
fn the_grid_is_one_that_every_mode_fits() {
    // modes-pin: `fast` needs A0 at 4 kHz (4 slots a frame) and A1, A2
    // beside it; a mode alone may take fewer slots than both together.
    let mix = testkit("modes-pin");
    let s = synthesize(&mix).unwrap();
    let mut alone = Vec::new();
    for m in 0..2 {
        alone.push(synthesize(&one_mode(&mix, m)).unwrap().grid.slots_per_slice);
    }
    assert_eq!(s.grid.slots_per_slice, *alone.iter().max().unwrap());
    // a forced grid that one mode cannot use names that mode
    let mut forced = mix.clone();
    forced.slots_per_slice = Some(1);
    let why = synthesize(&forced).unwrap_err();
    assert!(why.to_string().contains("in mode `fast`: "), "{why}");
}

/// A grid's verdict is the failing mode's: a count proves a grid too
/// small, a search cut at its bound is unknown (and so is the mix, if
/// no grid places every mode: exit 3, never "infeasible").
#[test]
fn a_grid_cut_short_is_unknown_not_infeasible() {
    let mix = testkit("modes-pin");
    assert_eq!(
        on_grid(&mix, 1, SEARCH_BUDGET).unwrap_err(),
        Verdict::Infeasible
    );
    let sps = synthesize(&mix).unwrap().grid.slots_per_slice;
    assert!(on_grid(&mix, sps, SEARCH_BUDGET).is_ok());
    // rates that are not harmonic need the exact search (the mix of
    // synth.rs' bound test, in two modes): cut at 2 placements, it
    // stops with neither a schedule nor a proof
    let text = format!(
        "{}\n[[mode]]\nname = \"a\"\n[[mode]]\nname = \"b\"\n[modes]\nselect = \"pin\"\n",
        include_str!("../data/missed.toml")
    );
    let odd = lut_gen::parse(std::path::Path::new("missed.toml"), &text).unwrap();
    assert_eq!(on_grid(&odd, 96, 2).unwrap_err(), Verdict::Unknown);
    assert!(on_grid(&odd, 96, SEARCH_BUDGET).is_ok());
}

#[test]
fn the_validator_catches_a_mode_off_the_grid_or_at_wrong_rates() {
    let mix = testkit("modes-auto");
    let s = synthesize(&mix).unwrap();
    let mut bad = s.clone();
    bad.modes[1] = bad.modes[2].clone();
    let why = lut_gen::validate(&bad).unwrap_err();
    assert!(why.iter().any(|p| p.contains("mode `touch`")), "{why:?}");
    let mut bad = s.clone();
    bad.modes.pop();
    assert!(lut_gen::validate(&bad).is_err());
    let mut bad = s;
    bad.modes[2].frame_table.swap(0, 2);
    assert!(lut_gen::validate(&bad).is_err());
}
