//! An independent proof that a schedule keeps the mix's promises.
//!
//! This module deliberately shares no code with `synth`: it reads only the
//! mix, the grid numbers and the frame table, and checks every promise from
//! first principles (whole cycles, exact counts, equal cyclic intervals,
//! datasheet limits, sync groups).  A bug in the synthesizer therefore cannot
//! hide behind the same bug here.

use std::collections::BTreeMap;

use crate::schedule::Schedule;

/// Returns every broken promise, or `Ok(())`.
pub fn validate(s: &Schedule) -> Result<(), Vec<String>> {
    let mut bad = Vec::new();
    if !check_grid(s, &mut bad) {
        return Err(bad);
    }
    check_datasheets(s, &mut bad);
    let slots_of = slots_of(s, &mut bad);
    for (c, got) in slots_of.iter().enumerate() {
        check_channel(s, c, got, &mut bad);
    }
    check_sync(s, &slots_of, &mut bad);
    check_modes(s, &mut bad);
    if bad.is_empty() {
        Ok(())
    } else {
        Err(bad)
    }
}

/// The grid's numbers against the mix and against each other; false when the
/// table does not even have the grid's size (nothing else can be read then).
fn check_grid(s: &Schedule, bad: &mut Vec<String>) -> bool {
    let mix = &s.mix;
    let g = &s.grid;
    let nb = mix.branches.len();
    if g.clock_hz != mix.clock_hz {
        bad.push(format!(
            "grid clock {} != mix clock {}",
            g.clock_hz, mix.clock_hz
        ));
    }
    if g.frame_cycles as u128 * 1_000_000 != mix.clock_hz as u128 * mix.frame_us as u128 {
        bad.push(format!(
            "frame of {} cycles is not {} us",
            g.frame_cycles, mix.frame_us
        ));
    }
    if g.slot_cycles * g.slots_per_slice != g.slice_cycles {
        bad.push(format!(
            "{} slots of {} cycles do not make a {}-cycle slice",
            g.slots_per_slice, g.slot_cycles, g.slice_cycles
        ));
    }
    if g.slice_cycles * g.slices_per_frame != g.frame_cycles {
        bad.push("slices do not tile the frame".into());
    }
    if g.slots_per_slice * g.slices_per_frame != g.frame_slots {
        bad.push("frame_slots != slots_per_slice x slices_per_frame".into());
    }
    if let Some(forced) = mix.slots_per_slice {
        if forced != g.slots_per_slice {
            bad.push(format!(
                "mix forces {forced} slots per slice, schedule uses {}",
                g.slots_per_slice
            ));
        }
    }
    if s.frame_table.len() as u64 != g.frame_slots * nb as u64 {
        bad.push("frame table has the wrong size".into());
        return false;
    }
    true
}

/// Datasheet limits, checked against the numbers the gateware will use.
fn check_datasheets(s: &Schedule, bad: &mut Vec<String>) {
    let mix = &s.mix;
    let g = &s.grid;
    for (b, plan) in s.branches.iter().enumerate() {
        let adc = &mix.branches[b].adc;
        let ns = |cycles: u64| cycles as f64 * 1e9 / mix.clock_hz as f64;
        let spi = &plan.spi;
        let sclk = mix.clock_hz as f64 / spi.sclk_div as f64;
        if sclk > adc.sclk_max_hz as f64 || sclk < adc.sclk_min_hz as f64 {
            bad.push(format!(
                "branch `{}`: SCLK {sclk:.0} Hz outside the {} limits",
                plan.name, adc.name
            ));
        }
        let (hi, lo) = (spi.sclk_half, spi.sclk_div - spi.sclk_half);
        if hi * 100 < spi.sclk_div * adc.duty_min_pct as u64
            || lo * 100 < spi.sclk_div * adc.duty_min_pct as u64
        {
            bad.push(format!(
                "branch `{}`: SCLK duty {hi}/{lo} outside {}..{} %",
                plan.name,
                adc.duty_min_pct,
                100 - adc.duty_min_pct
            ));
        }
        if ns(lo) < adc.data_access_ns as f64 {
            bad.push(format!(
                "branch `{}`: SCLK low phase shorter than data access time",
                plan.name
            ));
        }
        if ns(spi.setup_cycles) < (adc.setup_ns + adc.conversion_ns) as f64 {
            bad.push(format!(
                "branch `{}`: conversion start to first SCLK {} ns < {} ns",
                plan.name,
                ns(spi.setup_cycles),
                adc.setup_ns + adc.conversion_ns
            ));
        }
        let chain = mix.branches[b].chain as u64;
        let sclks = (adc.leading_bits + adc.bits + adc.trailing_bits) as u64 * chain;
        if spi.read_cycles != spi.setup_cycles + sclks * spi.sclk_div {
            bad.push(format!(
                "branch `{}`: conversion window is not setup + {sclks} SCLK periods",
                plan.name
            ));
        }
        if chain > adc.chain_max as u64 {
            bad.push(format!(
                "branch `{}`: {chain} parts chained, `{}` allows {}",
                plan.name, adc.name, adc.chain_max
            ));
        }
        if g.slot_cycles < spi.tick_to_complete()
            || ns(g.slot_cycles - spi.tick_to_complete()) < adc.quiet_ns as f64
        {
            bad.push(format!(
                "branch `{}`: slot leaves less than t_quiet = {} ns between conversions",
                plan.name, adc.quiet_ns
            ));
        }
        if (g.slot_cycles as f64) < mix.clock_hz as f64 / adc.max_sps as f64 {
            bad.push(format!(
                "branch `{}`: slots faster than {} samples/s",
                plan.name, adc.max_sps
            ));
        }
        if ns(g.slot_cycles - 1) < mix.branches[b].settle_ns as f64 {
            bad.push(format!(
                "branch `{}`: {} ns of settling needed, {} ns available",
                plan.name,
                mix.branches[b].settle_ns,
                ns(g.slot_cycles - 1)
            ));
        }
    }
}

/// Per-channel slot lists straight from the table.
fn slots_of(s: &Schedule, bad: &mut Vec<String>) -> Vec<Vec<u64>> {
    let mix = &s.mix;
    let g = &s.grid;
    let nb = mix.branches.len();
    let mut slots_of: Vec<Vec<u64>> = vec![Vec::new(); mix.channels.len()];
    for slot in 0..g.frame_slots {
        for b in 0..nb {
            if let Some(c) = s.frame_table[(slot * nb as u64 + b as u64) as usize] {
                let c = c as usize;
                if c >= mix.channels.len() {
                    bad.push(format!("slot {slot}: unknown channel index {c}"));
                    continue;
                }
                if mix.channels[c].branch != b {
                    bad.push(format!(
                        "slot {slot}: channel `{}` converted on the wrong branch",
                        mix.channels[c].name
                    ));
                }
                // Every channel read in this conversion (chain members).
                for (m, g) in mix.conversion_group(c).into_iter().enumerate() {
                    if let Some(g) = g {
                        if mix.channels[g].member as usize != m {
                            bad.push(format!("`{}`: wrong chain member", mix.channels[g].name));
                        }
                        slots_of[g].push(slot);
                    }
                }
            }
        }
    }
    slots_of
}

/// Channel `c`'s count, intervals and summary against the slots it was
/// sampled in (`got`).
fn check_channel(s: &Schedule, c: usize, got: &[u64], bad: &mut Vec<String>) {
    let mix = &s.mix;
    let g = &s.grid;
    let ch = &mix.channels[c];
    let want = (ch.rate_hz as u128 * mix.frame_us as u128 / 1_000_000) as usize;
    if got.len() != want {
        bad.push(format!(
            "`{}`: {} samples per frame, {} expected",
            ch.name,
            got.len(),
            want
        ));
        return;
    }
    if want == 0 {
        // Not sampled (in this mode): no slot, and a summary that says so.
        if s.channels.get(c).is_none_or(|cs| cs.samples_per_frame != 0) {
            bad.push(format!("`{}`: summary of an unsampled channel", ch.name));
        }
        return;
    }
    if !mix.clock_hz.is_multiple_of(ch.rate_hz) {
        bad.push(format!("`{}`: clock/rate is not whole", ch.name));
        return;
    }
    let interval = mix.clock_hz / ch.rate_hz;
    for i in 0..got.len() {
        let next = if i + 1 < got.len() {
            got[i + 1]
        } else {
            got[0] + g.frame_slots
        };
        let cycles = (next - got[i]) * g.slot_cycles;
        if cycles != interval {
            bad.push(format!(
                "`{}`: interval from slot {} is {cycles} cycles, {interval} expected",
                ch.name, got[i]
            ));
            break;
        }
    }
    if let Some(cs) = s.channels.get(c) {
        if Some(&cs.offset_slot) != got.first()
            || cs.interval_cycles != interval
            || cs.samples_per_frame != want as u64
        {
            bad.push(format!(
                "`{}`: channel summary disagrees with the table",
                ch.name
            ));
        }
        // The pins address the front mux's input on a fronted branch.
        let pin = match (mix.branches[ch.branch].fronted, ch.front_input) {
            (true, f) => f.unwrap_or(0),
            (false, _) => ch.input,
        };
        if cs.device * 8 + cs.select != pin {
            bad.push(format!(
                "`{}`: mux address disagrees with input {}",
                ch.name, pin
            ));
        }
    } else {
        bad.push(format!("`{}`: missing from the channel summary", ch.name));
    }
}

/// Members of a sync group share every sampling instant.
fn check_sync(s: &Schedule, slots_of: &[Vec<u64>], bad: &mut Vec<String>) {
    let mix = &s.mix;
    let mut groups: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (c, ch) in mix.channels.iter().enumerate() {
        if let Some(t) = &ch.sync {
            groups.entry(t).or_default().push(c);
        }
    }
    for (tag, members) in groups {
        for w in members.windows(2) {
            if slots_of[w[0]] != slots_of[w[1]] {
                bad.push(format!(
                    "sync `{tag}`: `{}` and `{}` do not share sampling instants",
                    mix.channels[w[0]].name, mix.channels[w[1]].name
                ));
            }
            // within a shared slot, each part holds its input its hold-off
            // plus its own time after the slot tick
            let after = |c: usize| s.sample_after(mix.channels[c].branch);
            let apart = crate::parts::cycles_to_ns(after(w[0]).abs_diff(after(w[1])), mix.clock_hz);
            if apart > crate::mix::SYNC_TOLERANCE_NS as f64 {
                bad.push(format!(
                    "sync `{tag}`: `{}` and `{}` are sampled {apart:.0} ns apart",
                    mix.channels[w[0]].name, mix.channels[w[1]].name
                ));
            }
        }
    }
}

/// A mix with modes: one schedule per mode, each valid on its own, all on
/// this schedule's grid (a switch changes tables at a frame start, never
/// the grid), the first being this schedule's own table.
fn check_modes(s: &Schedule, bad: &mut Vec<String>) {
    let want = s.mix.modes.as_ref().map_or(0, |m| m.names.len());
    if s.modes.len() != want {
        bad.push(format!("{} mode schedules for {want} modes", s.modes.len()));
        return;
    }
    for (m, ms) in s.modes.iter().enumerate() {
        let name = &s.mix.modes.as_ref().unwrap().names[m];
        if ms.grid != s.grid {
            bad.push(format!(
                "mode `{name}`: its slot grid differs from the reset mode's"
            ));
        }
        for ch in &ms.mix.channels {
            if ch.rates.get(m) != Some(&ch.rate_hz) {
                bad.push(format!(
                    "mode `{name}`: `{}` is not at its rate in the mode",
                    ch.name
                ));
            }
        }
        if !ms.modes.is_empty() {
            bad.push(format!(
                "mode `{name}`: a mode's schedule has modes of its own"
            ));
        }
        if let Err(more) = validate(ms) {
            bad.extend(more.into_iter().map(|p| format!("mode `{name}`: {p}")));
        }
    }
    if let Some(first) = s.modes.first() {
        if first.frame_table != s.frame_table || first.channels != s.channels {
            bad.push("the reset mode's schedule is not the schedule's own table".into());
        }
    }
}
