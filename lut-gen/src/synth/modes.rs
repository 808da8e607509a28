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
pub fn on_grid(mix: &Mix, sps: u64, budget: u64) -> Result<Vec<Schedule>, Verdict> {
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
pub fn one_mode(mix: &Mix, m: usize) -> Mix {
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
