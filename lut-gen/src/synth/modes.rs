//! Synthesis of a mix with modes: one slot grid that every mode fits, and
//! each mode placed on it as its own jitter-free schedule (the gateware
//! switches tables at a frame start, so frame, slices, slots and slot
//! cycles must be the same in every mode).

use super::*;

/// Every mode on the first grid (fewest slots first) that places them all.
pub(super) fn synthesize_modes(mix: &Mix, budget: u64) -> Result<Schedule, Infeasible> {
    let names = &mix.modes.as_ref().expect("a mix with modes").names;
    let plans = branch_plans(mix).map_err(|e| alone(mix, vec![e]))?;
    let min_slot = plans.iter().map(|p| p.min_slot_cycles).max().unwrap_or(1);
    // Each mode on its own first: a mode that fits no grid is the diagnosis.
    let mut own = Vec::new();
    for (m, name) in names.iter().enumerate() {
        match synthesize_one(&one_mode(mix, m), budget) {
            Ok(s) => own.push(s.grid.slots_per_slice),
            Err(why) => return Err(in_mode(mix, name, why)),
        }
    }
    let mut cut_short = false;
    for sps in candidate_slots_per_slice(mix, min_slot) {
        let modes = match on_grid(mix, sps, budget) {
            Ok(modes) => modes,
            Err(verdict) => {
                cut_short |= verdict == Verdict::Unknown;
                continue;
            }
        };
        {
            let mut top = modes[0].clone();
            top.mix = mix.in_mode(0);
            top.modes = modes;
            if let Err(problems) = crate::validate::validate(&top) {
                let internal = problems
                    .into_iter()
                    .map(|p| format!("internal error, validator rejected the schedule: {p}"))
                    .collect();
                return Err(alone(mix, internal));
            }
            return Ok(top);
        }
    }
    let each = names
        .iter()
        .zip(&own)
        .map(|(n, s)| format!("mode `{n}` alone: {s} slots per slice"))
        .collect::<Vec<_>>()
        .join(", ");
    if cut_short {
        let mut why = alone(
            mix,
            vec![format!(
                "every mode fits a grid of its own ({each}), but the search for one slot grid that places every mode stopped at its bound of {budget} placements on some grid: the mix may fit (a larger `--search-limit` decides more)"
            )],
        );
        why.verdict = Verdict::Unknown;
        return Err(why);
    }
    Err(alone(
        mix,
        vec![format!(
            "every mode fits a grid of its own ({each}), but no slot grid places every mode: the modes switch at frame starts on one grid"
        )],
    ))
}

/// Every mode's schedule at `sps` slots per slice, or the verdict of the
/// first mode that does not fit it (`Unknown`: its search was cut short).
fn on_grid(mix: &Mix, sps: u64, budget: u64) -> Result<Vec<Schedule>, Verdict> {
    let mut out = Vec::new();
    for m in 0..mix.mode_count() {
        let mut mm = one_mode(mix, m);
        mm.slots_per_slice = Some(sps);
        let mut s = synthesize_one(&mm, budget).map_err(|why| why.verdict)?;
        // The grid was forced here, not by the user.
        s.mix.slots_per_slice = mix.slots_per_slice;
        out.push(s);
    }
    Ok(out)
}

/// Mode `m` as a mix of its own: its rates, no modes.
fn one_mode(mix: &Mix, m: usize) -> Mix {
    let mut mm = mix.in_mode(m);
    mm.modes = None;
    mm
}

/// A diagnosis of the whole mix (no mode to blame).
fn alone(mix: &Mix, reasons: Vec<String>) -> Infeasible {
    Infeasible {
        mix: mix.name.clone(),
        verdict: Verdict::Infeasible,
        slots_per_slice: None,
        reasons,
        branches: Vec::new(),
        suggestions: Vec::new(),
    }
}

/// `why` one mode has no schedule, said of that mode.
fn in_mode(mix: &Mix, name: &str, mut why: Infeasible) -> Infeasible {
    why.mix = mix.name.clone();
    for r in &mut why.reasons {
        *r = format!("in mode `{name}`: {r}");
    }
    why
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shared test mix, or else the preset of that name (as `testkit::mix`).
    fn testkit(name: &str) -> Mix {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let own = root.join(format!("testkit/mixes/{name}.toml"));
        let p = if own.exists() {
            own
        } else {
            root.join(format!("mixes/{name}.toml"))
        };
        crate::load(&p).unwrap()
    }

    #[test]
    fn every_mode_is_placed_on_one_grid_at_its_rates() {
        for name in ["modes-pin", "modes-auto", "eskin34-adaptive"] {
            let mix = testkit(name);
            let s = synthesize(&mix).unwrap();
            assert_eq!(s.modes.len(), mix.mode_count(), "{name}");
            for (m, ms) in s.modes.iter().enumerate() {
                assert_eq!(ms.grid, s.grid, "{name}");
                crate::validate(ms).unwrap();
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
            crate::validate(&s).unwrap();
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
            include_str!("../../tests/data/missed.toml")
        );
        let odd = crate::parse(std::path::Path::new("missed.toml"), &text).unwrap();
        assert_eq!(on_grid(&odd, 96, 2).unwrap_err(), Verdict::Unknown);
        assert!(on_grid(&odd, 96, SEARCH_BUDGET).is_ok());
    }

    #[test]
    fn the_validator_catches_a_mode_off_the_grid_or_at_wrong_rates() {
        let mix = testkit("modes-auto");
        let s = synthesize(&mix).unwrap();
        let mut bad = s.clone();
        bad.modes[1] = bad.modes[2].clone();
        let why = crate::validate(&bad).unwrap_err();
        assert!(why.iter().any(|p| p.contains("mode `touch`")), "{why:?}");
        let mut bad = s.clone();
        bad.modes.pop();
        assert!(crate::validate(&bad).is_err());
        let mut bad = s;
        bad.modes[2].frame_table.swap(0, 2);
        assert!(crate::validate(&bad).is_err());
    }
}
