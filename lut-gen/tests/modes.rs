//! Modes over mixes nobody wrote for them: random mixes with random
//! per-mode rates and triggers. Every mode's schedule passes the
//! independent validator on one grid, and each trigger's worst latency
//! (a closed form in `lut_gen::trigger_latency`) equals a brute-force walk
//! of the frames under the switch timing of docs/timing.md.

use std::fmt::Write;
use std::path::Path;

use crate::common::testkit;
use lut_gen::{Schedule, Trigger, When};
use proptest::prelude::*;

/// Rates that are whole samples per 2 ms frame and whole cycles at 8 MHz.
const RATES: [u64; 7] = [500, 1_000, 2_000, 4_000, 5_000, 8_000, 10_000];

/// A trigger: (from: None or a mode, to, above?, level, picks among the
/// channels it may watch, for_frames).
type TriggerSpec = (Option<usize>, usize, bool, u32, Vec<usize>, u32);

#[derive(Debug, Clone)]
struct Spec {
    branches: usize,
    /// (branch, rate per mode: index into RATES, or None for 0)
    channels: Vec<(usize, Vec<Option<usize>>)>,
    modes: usize,
    triggers: Vec<TriggerSpec>,
}

fn spec() -> impl Strategy<Value = Spec> {
    (1usize..=3, 2usize..=3).prop_flat_map(|(branches, modes)| {
        let rate = prop_oneof![1 => Just(None), 4 => (0..RATES.len()).prop_map(Some)];
        let channel = (0..branches, prop::collection::vec(rate, modes));
        let trigger = (
            prop::option::of(0..modes),
            0..modes,
            any::<bool>(),
            0u32..16_384,
            prop::collection::vec(0usize..64, 1..4),
            1u32..4,
        );
        (
            prop::collection::vec(channel, 1..10),
            prop::collection::vec(trigger, 0..4),
        )
            .prop_map(move |(channels, triggers)| Spec {
                branches,
                channels,
                modes,
                triggers,
            })
    })
}

/// The mix's text, or `None` when the spec breaks a rule the generator does
/// not model (a mode that samples nothing, a trigger with nothing to watch).
fn to_toml(s: &Spec) -> Option<String> {
    let mut t = String::from(
        "name = \"modes\"\n[clock]\nhz = 8_000_000\n[frame]\nperiod_us = 2_000\nslice_us = 500\n",
    );
    for m in 0..s.modes {
        let _ = write!(t, "[[mode]]\nname = \"m{m}\"\n");
    }
    let auto = !s.triggers.is_empty();
    let _ = writeln!(
        t,
        "[modes]\nselect = \"{}\"",
        if auto { "auto" } else { "pin" }
    );
    let rate = |r: &Option<usize>| r.map_or(0, |i| RATES[i]);
    let sampled = |c: usize, m: usize| s.channels[c].1[m].is_some();
    for (k, (from, to, above, level, picks, n)) in s.triggers.iter().enumerate() {
        let from = from.filter(|f| f != to);
        let leaves = |m: usize| m != *to && from.is_none_or(|f| f == m);
        let ok: Vec<usize> = (0..s.channels.len())
            .filter(|&c| (0..s.modes).filter(|&m| leaves(m)).all(|m| sampled(c, m)))
            .collect();
        if ok.is_empty() {
            return None;
        }
        let watched: Vec<String> = picks
            .iter()
            .map(|p| format!("\"c{}\"", ok[p % ok.len()]))
            .collect();
        let _ = writeln!(t, "[[trigger]]\nto = \"m{to}\"");
        if let Some(f) = from {
            let _ = writeln!(t, "from = \"m{f}\"");
        }
        let when = if *above { "above" } else { "below" };
        let _ = writeln!(
            t,
            "when = \"{when}\"\nlevel = {level}\nchannels = [{}]\nfor_frames = {n}  # {k}",
            watched.join(", ")
        );
    }
    // a branch the reset mode leaves out but another mode uses is refused
    // (docs/mix-format.md, "Combinations refused"): not drawn
    let on = |b: usize, m: usize| s.channels.iter().any(|(cb, r)| *cb == b && r[m].is_some());
    if (0..s.branches).any(|b| !on(b, 0) && (1..s.modes).any(|m| on(b, m))) {
        return None;
    }
    for b in 0..s.branches {
        let _ = write!(t, "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 2\nsettle_ns = 500\n");
    }
    for (c, (b, rates)) in s.channels.iter().enumerate() {
        let per: Vec<String> = rates
            .iter()
            .enumerate()
            .map(|(m, r)| format!("m{m} = {}", rate(r)))
            .collect();
        let _ = write!(
            t,
            "[[channel]]\nname = \"c{c}\"\nbranch = \"b{b}\"\nrate_hz = 1_000\nrates = {{ {} }}\n",
            per.join(", ")
        );
    }
    Some(t)
}

/// Every trigger's worst latency by walking frames: the schedule `from`
/// runs from frame 0; every watched sample at or after `t0` is past the
/// level, every earlier one not; each frame's window (the samples whose
/// conversion completes in it) holds or not; the `for_frames`-th window in a
/// row that holds is decided on at the next frame's start and switches a
/// frame later; the latency runs to that frame's first instant of `to`.
fn walk(from: &Schedule, to: &Schedule, t: &Trigger) -> u64 {
    let f = from.grid.frame_cycles;
    // instants where the parts hold their inputs (an MCP3208 6 us into its
    // transaction), as a run measures causes and first samples
    let first_to = to
        .instants(1)
        .map(|i| i.cycle + to.sample_after(i.branch))
        .min()
        .unwrap();
    let frames = 2 + t.for_frames as u64 + 4;
    let leads: Vec<usize> = t.channels.iter().map(|&c| from.mix.lead_of(c)).collect();
    let watched: Vec<(u64, u64)> = from
        .instants(frames)
        .filter(|i| leads.contains(&i.channel))
        .map(|i| {
            let start = i.cycle;
            (
                start + from.sample_after(i.branch),
                start + from.branches[i.branch].spi.tick_to_complete(),
            )
        })
        .collect();
    let mut worst = 0;
    for &(t0, _) in watched.iter().filter(|&&(t0, _)| (f..2 * f).contains(&t0)) {
        let mut run = 0;
        let mut switched = None;
        for w in 0..frames {
            let in_w: Vec<bool> = watched
                .iter()
                .filter(|&&(_, e)| e / f == w)
                .map(|&(i, _)| i >= t0)
                .collect();
            let holds = match t.when {
                When::Above => in_w.iter().any(|&p| p),
                When::Below => !in_w.is_empty() && in_w.iter().all(|&p| p),
            };
            run = if holds { run + 1 } else { 0 };
            if run >= t.for_frames {
                switched = Some(w + 2);
                break;
            }
        }
        let sw = switched.expect("the walk reaches the switch");
        worst = worst.max(sw * f + first_to - t0);
    }
    worst
}

fn check_schedule(s: &Schedule) -> Result<(), TestCaseError> {
    let mix = &s.mix;
    let names = &mix.modes.as_ref().unwrap().names;
    prop_assert!(lut_gen::validate(s).is_ok(), "{:?}", lut_gen::validate(s));
    prop_assert_eq!(s.modes.len(), names.len());
    for (m, ms) in s.modes.iter().enumerate() {
        prop_assert_eq!(ms.grid, s.grid);
        prop_assert!(
            lut_gen::validate(ms).is_ok(),
            "mode {}: {:?}",
            m,
            lut_gen::validate(ms)
        );
        for (c, ch) in mix.channels.iter().enumerate() {
            // counted in the table, not read from the summary
            let n = (0..s.grid.frame_slots)
                .filter(|&slot| ms.at(slot, ch.branch) == Some(mix.lead_of(c)))
                .count() as u64;
            prop_assert_eq!(
                n,
                mix.samples_per_frame(ch.rates[m]),
                "mode {} `{}`",
                m,
                ch.name
            );
        }
    }
    for (k, t) in mix.modes.as_ref().unwrap().triggers.iter().enumerate() {
        let got = lut_gen::trigger_latency(s, k).unwrap();
        let walked = (0..names.len())
            .filter(|&m| t.leaves(m))
            .map(|m| walk(&s.modes[m], &s.modes[t.to], t))
            .max()
            .unwrap();
        prop_assert_eq!(got.cycles, walked, "trigger {}", k);
        // the sample the audit names is one the trigger watches
        prop_assert!(
            t.channels.contains(&got.channel),
            "trigger {}: channel {}",
            k,
            got.channel
        );
    }
    text_and_json_agree(s);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn every_mode_of_a_random_mix_is_valid_and_latency_is_the_walks(s in spec()) {
        let Some(text) = to_toml(&s) else { return Ok(()) };
        let mix = match lut_gen::parse(Path::new("modes.toml"), &text) {
            Ok(m) => m,
            // a mode that samples nothing, a branch without channels
            Err(e) => {
                prop_assert!(
                    e.message.contains("samples no channel") || e.message.contains("has no channels"),
                    "{e}\n{text}"
                );
                return Ok(());
            }
        };
        match lut_gen::synthesize(&mix) {
            Ok(sched) => check_schedule(&sched)?,
            Err(why) => {
                let says = why.to_string();
                prop_assert!(
                    says.contains("mode `m") || says.contains("no slot grid places every mode"),
                    "{says}\n{text}"
                );
            }
        }
    }
}

#[test]
fn the_test_mixes_schedules_and_latencies_hold() {
    for name in ["modes-pin", "modes-auto", "eskin34-adaptive"] {
        let s = lut_gen::synthesize(&testkit(name)).unwrap();
        check_schedule(&s).unwrap();
    }
}

#[test]
fn a_trigger_that_needs_more_frames_reacts_a_frame_later_per_frame() {
    let mix = testkit("modes-auto");
    let s = lut_gen::synthesize(&mix).unwrap();
    let base = lut_gen::trigger_latency(&s, 1).unwrap();
    let mut more = mix.clone();
    more.modes.as_mut().unwrap().triggers[1].for_frames += 2;
    let s2 = lut_gen::synthesize(&more).unwrap();
    let later = lut_gen::trigger_latency(&s2, 1).unwrap();
    assert_eq!(later.cycles, base.cycles + 2 * s.grid.frame_cycles);
    // and a pin's worst reaction is two frames and the new mode's first instant
    let pin = lut_gen::synthesize(&testkit("modes-pin")).unwrap();
    let first = pin.modes[1].instants(1).map(|i| i.cycle).min().unwrap();
    assert_eq!(
        lut_gen::pin_latency(&pin, 1),
        2 * pin.grid.frame_cycles + first
    );
}

/// A part that holds its input inside its transaction (the MCP3208, 6 us
/// after CS falls): the worst reaction runs to that instant, not to the
/// conversion's start (a run measured 4.006 ms against 4.000 ms).
#[test]
fn a_reaction_runs_to_the_instant_the_part_holds_its_input() {
    let text = r#"
name = "mcp-modes"
[clock]
hz = 24_000_000
[frame]
period_us = 2_000
slice_us = 1_000
[[mode]]
name = "rest"
[[mode]]
name = "busy"
[modes]
select = "pin"
[[branch]]
name = "a"
adc = "mcp3208"
mux = "internal"
[[channel]]
name = "A0"
branch = "a"
rate_hz = 2_000
rates = { rest = 1_000 }
input = 0
"#;
    let mix = lut_gen::parse(Path::new("mcp-modes.toml"), text).unwrap();
    let s = lut_gen::synthesize(&mix).unwrap();
    let after = s.sample_after(0);
    assert!(after > 100, "the MCP3208 holds its input {after} cycles in");
    let start = s.modes[1].instants(1).map(|i| i.cycle).min().unwrap();
    assert_eq!(
        lut_gen::pin_latency(&s, 1),
        2 * s.grid.frame_cycles + start + after
    );
    assert_eq!(lut_gen::first_instant(&s.modes[1]), Some(start + after));
}

/// The merged stream over a run of one mode is the steady frame's, frame
/// after frame; across a switch it has every sample of both modes' frames.
#[test]
fn the_merged_run_agrees_with_the_steady_frame() {
    let s = lut_gen::synthesize(&testkit("modes-auto")).unwrap();
    let f = s.grid.frame_cycles;
    let steady = lut_gen::merged_frame(&s.modes[1]);
    let run = lut_gen::merged_run(&[&s.modes[1], &s.modes[1], &s.modes[1]]);
    let middle: Vec<_> = run
        .iter()
        .filter(|&&(_, t, _)| (f..2 * f).contains(&t))
        .map(|&(v, t, c)| (v - f, t - f, c))
        .collect();
    assert_eq!(middle, steady);
    let across = lut_gen::merged_run(&[&s.modes[0], &s.modes[1]]);
    let count = |m: &Schedule| m.samples_per_frame() as usize;
    assert_eq!(across.len(), count(&s.modes[0]) + count(&s.modes[1]));
}

/// Every figure of the text's mode table, trigger lines and switch line
/// equals the JSON's (one value behind both).
fn text_and_json_agree(s: &Schedule) {
    let r = lut_gen::AuditReport::of_schedule(s);
    let text = r.to_text();
    let json: serde_json::Value = serde_json::from_str(&r.to_json()).unwrap();
    let modes = json["modes"].as_array().unwrap();
    assert_eq!(modes.len(), s.modes.len());
    let table: Vec<Vec<&str>> = text
        .lines()
        .skip_while(|l| !l.starts_with("#   mode"))
        .skip(1)
        .take(modes.len())
        .map(|l| l.split_whitespace().collect())
        .collect();
    for (m, row) in modes.iter().zip(&table) {
        assert_eq!(row[0], m["number"].to_string());
        assert_eq!(row[1], m["name"].as_str().unwrap());
        assert_eq!(row[2], m["samples_per_frame"].to_string());
        assert_eq!(row[3], m["aggregate_hz"].to_string());
        assert_eq!(
            row[4],
            format!("{:.1}", m["adc_utilization"].as_f64().unwrap() * 100.0)
        );
        let binds = format!("`{}`:", m["binding_branch"].as_str().unwrap());
        assert_eq!(row[6], binds);
    }
    // the rates table: one row per channel, one column per mode
    for (c, ch) in s.mix.channels.iter().enumerate() {
        let line = text
            .lines()
            .skip_while(|l| !l.starts_with("rate Hz"))
            .nth(1 + c)
            .unwrap();
        let cols: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(cols[0], ch.name);
        for (m, mode) in modes.iter().enumerate() {
            assert_eq!(cols[1 + m], mode["channels"][c]["rate_hz"].to_string());
            assert_eq!(mode["channels"][c]["rate_hz"], ch.rates[m]);
        }
    }
    let triggers = json["triggers"]
        .as_array()
        .map_or(&[][..], |v| v.as_slice());
    for (k, t) in triggers.iter().enumerate() {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("trigger {k}:")))
            .unwrap();
        let want = format!("worst latency {} cycles", t["latency_cycles"]);
        assert!(line.contains(&want), "{line} / {want}");
        assert_eq!(
            t["latency_cycles"],
            lut_gen::trigger_latency(s, k).unwrap().cycles
        );
    }
    if let Some(sw) = json["link"]["switches"].as_array() {
        let line = text
            .lines()
            .find(|l| l.starts_with("link across switches"))
            .unwrap();
        for x in sw {
            let want = format!(
                "{}->{} {}",
                x["from"].as_str().unwrap(),
                x["to"].as_str().unwrap(),
                x["backlog"]
            );
            assert!(line.contains(&want), "{line} / {want}");
            assert!(x["backlog"].as_u64().unwrap() <= json["link"]["fifo_depth"].as_u64().unwrap());
        }
    }
}

#[test]
fn the_audits_text_and_json_agree_on_modes() {
    for name in ["modes-pin", "modes-auto", "eskin34-adaptive"] {
        text_and_json_agree(&lut_gen::synthesize(&testkit(name)).unwrap());
    }
}

/// The FIFO across a switch is at least each side's own steady backlog,
/// and a "switch" to the same mode is its steady state.
#[test]
fn a_switch_needs_at_least_either_modes_fifo() {
    for name in ["modes-auto", "eskin34-adaptive"] {
        let s = lut_gen::synthesize(&testkit(name)).unwrap();
        let plan = lut_gen::plan_link(&s).unwrap().unwrap();
        let own: Vec<usize> = s
            .modes
            .iter()
            .map(|m| lut_gen::plan_link(m).unwrap().unwrap().fifo_depth)
            .collect();
        for (a, ma) in s.modes.iter().enumerate() {
            let same = lut_gen::switch_backlog(ma, ma, plan.line);
            assert_eq!(same.max(1), own[a], "{name} mode {a}");
            for (b, mb) in s.modes.iter().enumerate() {
                let x = lut_gen::switch_backlog(ma, mb, plan.line);
                // the run starts with `a` frames to its steady state
                assert!(x.max(1) >= own[a], "{name} {a}->{b}");
                assert!(x <= plan.fifo_depth, "{name} {a}->{b}");
            }
        }
        assert_eq!(plan.switches.len(), s.modes.len() * (s.modes.len() - 1));
    }
}
