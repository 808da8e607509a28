use lut_gen::{synthesize, synthesize_within, Mix, Verdict, SEARCH_BUDGET};

/// Three branches; b2's two 16 kHz channels and its 600 Hz one fit only
/// at 96 slots per slice (at 48 the 600 Hz progression meets every
/// residue mod 3): a proof at 48, a schedule at 96.
fn three_branches() -> Mix {
    let text = include_str!("../data/missed.toml");
    lut_gen::parse(std::path::Path::new("missed.toml"), text).unwrap()
}

/// A 150 kHz channel on a 100 kS/s AD7940 is told as the part's limit
/// first, on a clock that divides the rate and on one that does not
/// (not as a rate no slot grid spaces evenly).
#[test]
fn a_channel_faster_than_its_part_is_told_as_the_parts_limit() {
    for hz in ["48_000_000", "4_000_000"] {
        let text = format!(
            "name = \"f\"\n[clock]\nhz = {hz}\n[frame]\nperiod_us = 1_000\nslice_us = 500\n\
             [[branch]]\nname = \"a\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n\
             [[channel]]\nname = \"X\"\nbranch = \"a\"\nrate_hz = 150_000\n"
        );
        let mix = lut_gen::parse(std::path::Path::new("f.toml"), &text).unwrap();
        let e = synthesize(&mix).unwrap_err();
        let first = &e.reasons[0];
        assert!(
            first.contains("150000 Hz is faster than branch `a`'s ad7940 can convert")
                && first.contains("at most 100000 samples/s"),
            "{hz}: {e}"
        );
    }
}

#[test]
fn a_bound_that_runs_out_is_unknown_not_infeasible() {
    let mix = three_branches();
    let why = synthesize_within(&mix, 2).unwrap_err();
    assert_eq!(why.verdict, Verdict::Unknown);
    let text = why.to_string();
    assert!(text.starts_with("mix `missed`: unknown"), "{text}");
    assert!(text.contains("bound of 2 placements"), "{text}");
    assert!(!text.contains("has no jitter-free schedule"), "{text}");
    let s = synthesize_within(&mix, SEARCH_BUDGET).unwrap();
    assert_eq!(s.grid.slots_per_slice, 96);
}

#[test]
fn an_exhausted_grid_is_a_proof() {
    let mut mix = three_branches();
    mix.slots_per_slice = Some(48);
    let why = synthesize_within(&mix, SEARCH_BUDGET).unwrap_err();
    assert_eq!(why.verdict, Verdict::Infeasible);
    assert!(why.to_string().contains("no choice of offsets"), "{why}");
    assert_eq!(why.branches[2].unplaced, vec!["c1".to_string()]);
}
