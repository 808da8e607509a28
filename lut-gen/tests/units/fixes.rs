use std::path::Path;

use lut_gen::for_tests::{cost, feasible};
use lut_gen::{search_fixes as search, search_fixes_unloadable as search_unloadable};
use lut_gen::{Change, FixSearch, Infeasible, Mix};

fn infeasible(text: &str) -> (Mix, Infeasible) {
    let mix = lut_gen::parse(Path::new("t.toml"), text).unwrap();
    match lut_gen::synthesize(&mix) {
        Err(why) => (mix, why),
        Ok(_) => panic!("the test mix is feasible:\n{text}"),
    }
}

const HEAD: &str =
    "name = \"t\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 2_000\nslice_us = 1_000\n";

fn branch(name: &str, devices: u32) -> String {
    format!("[[branch]]\nname = \"{name}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = {devices}\n")
}

fn channels(prefix: &str, branch: &str, n: usize, rate: u64) -> String {
    (0..n)
        .map(|i| {
            format!(
                "[[channel]]\nname = \"{prefix}{i}\"\nbranch = \"{branch}\"\nrate_hz = {rate}\n"
            )
        })
        .collect()
}

/// The mix: 44 taxels at 2.5 kHz overfill their branch, and the
/// slow branch, with room in its slots, has too few free mux inputs.
fn over_full_taxels() -> String {
    format!(
        "{HEAD}{}{}{}{}",
        branch("taxels", 6),
        branch("slow", 1),
        channels("T", "taxels", 44, 2_500),
        channels("S", "slow", 6, 500)
    )
}

/// The case: the branch with room in its slots has too few free
/// mux inputs, so the move that is offered also adds a device, and the
/// fixed text is feasible.
#[test]
fn a_move_to_a_branch_without_free_inputs_brings_its_mux_devices() {
    let text = over_full_taxels();
    let (mix, why) = infeasible(&text);
    let found = search(Path::new("t.toml"), &text, &mix, &why);
    assert!(!found.fixes.is_empty(), "{found}");
    for f in &found.fixes {
        assert!(
            feasible(Path::new("fix.toml"), &f.text, lut_gen::SEARCH_BUDGET).is_some(),
            "{}",
            f.says
        );
        if let [Change::MoveChannels {
            to,
            mux_devices,
            channels,
            ..
        }] = &f.changes[..]
        {
            assert_eq!(to, "slow");
            assert!(mux_devices.is_some() || channels.len() <= 2, "{}", f.says);
        }
    }
    let costs: Vec<_> = found
        .fixes
        .iter()
        .map(|f| cost(&f.changes, f.parts_added, f.channels_changed))
        .collect();
    let mut sorted = costs.clone();
    sorted.sort();
    assert_eq!(costs, sorted, "cheapest first");
}

/// One channel faster than its ADC converts: only a lower rate helps, and
/// the rate offered is the fastest that fits.
#[test]
fn a_rate_too_high_for_the_adc_is_lowered_to_one_that_fits() {
    let text = format!("{HEAD}{}{}", branch("a", 1), channels("F", "a", 1, 400_000));
    let (mix, why) = infeasible(&text);
    let found = search(Path::new("t.toml"), &text, &mix, &why);
    let lowered: Vec<u64> = found
        .fixes
        .iter()
        .filter_map(|f| match f.changes[..] {
            [Change::LowerRate { to_hz, .. }] => Some(to_hz),
            _ => None,
        })
        .collect();
    assert!(!lowered.is_empty(), "{found}");
    for f in &found.fixes {
        assert!(feasible(Path::new("fix.toml"), &f.text, lut_gen::SEARCH_BUDGET).is_some());
    }
}

/// More channels than mux inputs: the loader refuses the file; the fix is
/// the devices the branch needs, and the fixed file loads and fits.
#[test]
fn too_many_channels_for_the_mux_get_the_devices_they_need() {
    let text = format!("{HEAD}{}{}", branch("a", 1), channels("C", "a", 11, 500));
    assert!(lut_gen::parse(Path::new("t.toml"), &text).is_err());
    let found = search_unloadable(Path::new("t.toml"), &text);
    assert_eq!(found.fixes.len(), 1, "{found}");
    assert_eq!(
        found.fixes[0].changes,
        vec![Change::AddMuxDevices {
            branch: "a".into(),
            from: 1,
            to: 2
        }]
    );
    assert!(found.fixes[0]
        .says
        .contains("give branch `a` 2 mux devices instead of 1"));
}

/// A mix that nothing within reach fixes says so and offers nothing.
#[test]
fn a_mix_no_fix_helps_offers_none() {
    // every channel is in one sync group across two branches at a rate
    // neither ADC reaches: no move, split or single lowered rate applies
    let mut text = format!("{HEAD}{}{}", branch("a", 1), branch("b", 1));
    text.push_str("[[channel]]\nname = \"x\"\nbranch = \"a\"\nrate_hz = 400_000\nsync = \"s\"\n");
    text.push_str("[[channel]]\nname = \"y\"\nbranch = \"b\"\nrate_hz = 400_000\nsync = \"s\"\n");
    let (mix, why) = infeasible(&text);
    let found = search(Path::new("t.toml"), &text, &mix, &why);
    assert!(found.fixes.is_empty(), "{found}");
    assert!(found.to_string().contains("no fix found"), "{found}");
}

/// The wording: the first fix of the over-full branch moves its
/// channels and says to where, with the devices the move needs.
#[test]
fn the_first_fix_keeps_every_rate() {
    let text = over_full_taxels();
    let (mix, why) = infeasible(&text);
    let found = search(Path::new("t.toml"), &text, &mix, &why);
    assert_eq!(
        found.fixes[0].says,
        "move `T40`, `T41`, `T42`, `T43` (2500 Hz) from branch `taxels` to branch `slow`, and give `slow` 2 mux devices instead of 1 for the inputs"
    );
}

/// A forced grid on which the channels collide: the fix frees the grid
/// (the mix fits at 96 slots per slice, not the 48 forced).
#[test]
fn a_forced_grid_that_cannot_hold_the_mix_is_freed() {
    let text = include_str!("../data/missed.toml")
        .replace("slice_us = ", "slots_per_slice = 48\nslice_us = ");
    let (mix, why) = infeasible(&text);
    let found = search(Path::new("m.toml"), &text, &mix, &why);
    assert_eq!(
        found.fixes[0].changes,
        vec![Change::Grid {
            slice_us: None,
            dropped_slots_per_slice: Some(48)
        }],
        "{found}"
    );
    assert_eq!(found.fixes[0].slots_per_slice, 96);
    let keys = found.fixes[0].text.lines().filter(|l| !l.starts_with('#'));
    assert!(!keys.into_iter().any(|l| l.contains("slots_per_slice")));
}

/// A mix written with bulk rows is the mix written out: its fixes are the
/// same, and each fixed text (the rows it touches written out) is feasible.
#[test]
fn a_bulk_row_gets_the_fixes_of_its_channels_written_out() {
    let rows = format!(
        "{HEAD}{}{}[[channel]]\nname = \"P{{0..43}}\"\nbranch = \"taxels\"\nrate_hz = 2_500\n[[channel]]\nname = \"S{{0..5}}\"\nbranch = \"slow\"\nrate_hz = 500\n",
        branch("taxels", 6),
        branch("slow", 1)
    );
    let written = over_full_taxels().replace("name = \"T", "name = \"P");
    let found = |text: &str| {
        let (mix, why) = infeasible(text);
        search(Path::new("t.toml"), text, &mix, &why)
    };
    let (a, b) = (found(&rows), found(&written));
    assert!(!a.fixes.is_empty(), "{a}");
    let words = |f: &FixSearch| f.fixes.iter().map(|x| x.says.clone()).collect::<Vec<_>>();
    assert_eq!(words(&a), words(&b));
    for f in &a.fixes {
        let mix = lut_gen::parse(Path::new("fix.toml"), &f.text).unwrap();
        assert!(lut_gen::synthesize(&mix).is_ok(), "{}", f.text);
    }
}
