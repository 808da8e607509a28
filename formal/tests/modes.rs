//! `prove` of mixes with modes (docs/timing.md, "Mode switches"): the
//! harness follows every sequence of mode requests (pin select: `mode_sel`
//! free in every cycle) or evaluates the triggers on the words it recorded
//! (auto select: MISO free), each mode's own table from `Schedule::modes`.

use crate::common;

use std::path::Path;
use std::time::Instant;

use formal::{Outcome, Proof, ProveOptions};

use common::TOOLS;
use common::{assert_rejected_at_its_cycle, edit, emitted, failed, rejected, root, schedule};
use testkit::tools;

fn prove(s: &lut_gen::Schedule, design: &str, out: &Path) -> Proof {
    prove_to(s, design, out, None)
}

/// The design of `s` proved whole: every property for all time, nothing
/// left uncovered.
fn proved_whole(s: &lut_gen::Schedule, out: &Path) -> Proof {
    let p = prove(s, &emitted(s), out);
    assert_whole(&p);
    p
}

/// `p` proves every property for all time and leaves nothing uncovered.
fn assert_whole(p: &Proof) {
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    assert!(p.not_covered.is_empty(), "{:?}", p.not_covered);
    for q in &p.properties {
        assert_eq!(q.result, Outcome::Proved, "{}: {}", q.name, p.summary());
    }
}

/// `prove` with the search from reset stopped at `depth` steps.
fn prove_to(s: &lut_gen::Schedule, design: &str, out: &Path, depth: Option<u64>) -> Proof {
    let mut o = ProveOptions::new(out);
    o.depth = depth;
    o.frame_counter = Some(hdl::LINK_FRAME_COUNTER.to_string());
    o.mode_decision = Some(hdl::MODE_DECISION.to_string());
    o.trigger_run = Some(hdl::TRIGGER_RUN.to_string());
    let t = Instant::now();
    let p = formal::prove(s, design, &o).expect("prove runs");
    eprintln!(
        "{} in {:.1} s\n{}",
        s.mix.name,
        t.elapsed().as_secs_f64(),
        p.summary()
    );
    p
}

/// A failed proof whose counterexample the judge rejects at the cycle
/// `prove` names, with one of `properties` among the failing ones.
fn assert_fails(s: &lut_gen::Schedule, p: &Proof, properties: &[&str]) {
    assert_eq!(p.result, Outcome::Failed, "{}", p.summary());
    let c = p.counterexample.as_ref().expect("a counterexample");
    assert!(c.reproduced, "the replay reproduces it: {}", p.summary());
    let failed = failed(p);
    assert!(
        failed.iter().any(|f| properties.contains(f)),
        "fails {failed:?}, none of {properties:?}"
    );
    assert_rejected_at_its_cycle(&rejected(s, c), p, c);
}

/// The harness of a mix with modes: `mode_sel` a free input (pin select
/// only), a `mode` property, `Clause::Mode` covered, every mode's table.
#[test]
fn the_harness_of_a_mode_mix_asserts_mode_and_frees_mode_sel() {
    let s = schedule("testkit/mixes/modes-pin.toml");
    let h = formal::generate(&s).expect("a harness");
    let names: Vec<&str> = h.inputs.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(names, ["adc_miso", "mode_sel"]);
    assert!(h
        .properties
        .iter()
        .any(|p| p.name == "mode" && p.covers == [formal::Clause::Mode]));
    assert!(h.not_covered.is_empty(), "{:?}", h.not_covered);
    assert!(h.verilog.contains(".mode_sel(mode_sel), .mode(mode)"));
    assert_eq!(
        formal::generate(&s).unwrap().verilog,
        h.verilog,
        "deterministic"
    );
    let a = schedule("testkit/mixes/modes-auto.toml");
    let h = formal::generate(&a).expect("a harness");
    let names: Vec<&str> = h.inputs.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(
        names,
        ["adc_miso"],
        "auto select: MISO is the only free input"
    );
    assert!(
        h.verilog.contains("wire held2 = na2 && !nn2;"),
        "trigger 2 is `below`"
    );
    assert!(h.properties.iter().any(|p| p.name == "mode"));
    // a mix without modes gets no mode property and keeps its ports
    let t = schedule("testkit/mixes/tiny.toml");
    let h = formal::generate(&t).unwrap();
    assert!(!h.verilog.contains("mcur") && h.properties.iter().all(|p| p.name != "mode"));
}

#[test]
fn pin_select_mix_proves_for_every_sequence_of_requests() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/modes-pin.toml");
    let dir = tempfile::tempdir().unwrap();
    proved_whole(&s, dir.path());
}

/// A pin-select mix with a UART proves the whole contract, the link's
/// bytes included (the run split on `mode_sel` with the frame counters
/// generalised); a header whose two mode fields are swapped is wrong only
/// after a switch, and fails there with a trace `check` rejects.  `make
/// test` holds the same of the same two designs through the CLI
/// (`prove_cli`'s `a_pin_mode_mix_with_a_uart_proves_its_line_and_packets`
/// and `link_mutants_of_a_pin_mode_mix_fail_prove_where_check_does`).
#[test]
#[ignore = "long: make test-long (the same two proofs are prove_cli's in make test)"]
fn a_pin_mode_mix_with_a_uart_proves_its_packets_and_a_mode_field_swap_fails() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("formal/tests/data/modes-pin-uart.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = proved_whole(&s, dir.path());
    assert!(p.note.contains("split on the mode requests"), "{}", p.note);
    let swapped = edit(
        &emitted(&s),
        "hfield = {fmode, pmode, ",
        "hfield = {pmode, fmode, ",
    );
    let p = prove(&s, &swapped, dir.path());
    assert_fails(&s, &p, &["link.packets"]);
    // not before the first frame a request can switch the mode
    let c = p.counterexample.as_ref().unwrap();
    assert!(c.cycle >= s.grid.frame_cycles as i64, "{}", p.summary());
}

/// A mix of an unseen glove's kind (`formal/tests/data/glove-pin-small.toml`:
/// bulk rows of taxels on two TMUX1108s whose rate the mode sets, a second
/// branch, pin select, a UART) proves the whole contract, its link's bytes
/// for all time: the generalised run comes round at the frame start of its
/// last step (it was searched two frames only before that step was
/// compared), and a request copied into the mode registers is held as its
/// variable until the gateware computes with it.
#[test]
fn a_glove_mix_proves_its_links_bytes_for_all_time() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("formal/tests/data/glove-pin-small.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = proved_whole(&s, dir.path());
    assert!(p.note.contains("frame counters"), "{}", p.note);
}

/// The gateware's mode block as emitted for a pin-select mix.
const DECIDED: &str = "wire [0:0] decided = mode_sel[0:0];";
const SWITCH: &str = "cur <= nxt;\n          nxt <= decided;";

#[test]
fn a_gateware_that_ignores_mode_sel_fails_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/modes-pin.toml");
    let design = edit(&emitted(&s), DECIDED, "wire [0:0] decided = nxt;");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &design, dir.path());
    assert_fails(&s, &p, &["mode", "mux[fast]", "mux[slow]"]);
}

#[test]
fn a_gateware_that_switches_a_frame_early_fails_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/modes-pin.toml");
    let early = "cur <= decided;\n          nxt <= decided;";
    let design = edit(&emitted(&s), SWITCH, early);
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &design, dir.path());
    assert_fails(&s, &p, &["mode", "mux[fast]", "mux[slow]"]);
}

/// A random pin-select mix with `n` modes (`m0` after reset) on a 4 MHz
/// clock and a 1 ms frame: 1 to 3 branches (every one sampled in the reset
/// mode, another mode may leave one out), channels at harmonic rates per
/// mode; `None` when no other mode samples anything or the draw has no
/// schedule.
fn random_pin_mix(seed: u64, n: usize) -> Option<lut_gen::Schedule> {
    use std::fmt::Write;
    use testkit::modemix::{Draw, RATES};
    let mut d = Draw::new(seed);
    let mut next = move |n: u64| d.below(n);
    let nb = 1 + next(3) as usize;
    let mut t = format!(
        "name = \"random-pin{n}-{seed}\"\n[clock]\nhz = 4_000_000\n[frame]\nperiod_us = 1_000\n\
         slice_us = 500\n"
    );
    for m in 0..n {
        let _ = write!(t, "[[mode]]\nname = \"m{m}\"\n");
    }
    t.push_str("[modes]\nselect = \"pin\"\n");
    for b in 0..nb {
        let _ = write!(
            t,
            "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 2\nsettle_ns = {}\n",
            [0, 1_000][next(2) as usize]
        );
    }
    let mut used = false;
    for c in 0..nb + next(6) as usize {
        let first = RATES[next(4) as usize].max(if c < nb { 1_000 } else { 0 });
        let mut rates = vec![format!("m0 = {first}")];
        for m in 1..n {
            let r = RATES[next(4) as usize];
            used |= r > 0;
            rates.push(format!("m{m} = {r}"));
        }
        let _ = write!(
            t,
            "[[channel]]\nname = \"c{c}\"\nbranch = \"b{}\"\ninput = {}\nrate_hz = {}\nrates = {{ {} }}\n",
            c % nb,
            c / nb + 8 * next(2) as usize,
            first.max(1_000),
            rates.join(", ")
        );
    }
    let mix = lut_gen::parse(Path::new("random-pin.toml"), &t).ok()?;
    used.then(|| lut_gen::synthesize(&mix).ok()).flatten()
}

/// The first feasible draw of a random `n`-mode pin-select mix.
fn first_pin_mix(n: usize) -> (u64, lut_gen::Schedule) {
    (1..200u64)
        .find_map(|seed| random_pin_mix(seed, n).map(|s| (seed, s)))
        .expect("a feasible draw")
}

/// The first feasible draw, 2 branches: 2 s (140 s before the run was
/// split on `mode_sel`).
#[test]
fn a_random_pin_select_mix_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let (seed, s) = first_pin_mix(2);
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "seed {seed}: {}", p.summary());
}

/// `testkit/mixes/modes-pin.toml` with `n` modes: the extra ones (`m2`,
/// ...) sample A0 at 2 kHz, 0 and 1 kHz in turn and leave B0 out in `m3`.
fn modes_pin_with(n: usize) -> lut_gen::Schedule {
    let text = std::fs::read_to_string(root().join("testkit/mixes/modes-pin.toml")).unwrap();
    let mut extra = String::new();
    let mut a0 = String::from("slow = 1_000");
    for m in 2..n {
        extra.push_str(&format!("[[mode]]\nname = \"m{m}\"\n\n"));
        a0.push_str(&format!(", m{m} = {}", [2_000, 0, 1_000][m % 3]));
    }
    let text = text
        .replace("[modes]", &format!("{extra}[modes]"))
        .replace("rates = { slow = 1_000 }", &format!("rates = {{ {a0} }}"))
        .replace(
            "name = \"B0\"\nbranch = \"slow\"\nrate_hz = 2_000\n",
            "name = \"B0\"\nbranch = \"slow\"\nrate_hz = 2_000\nrates = { m3 = 0 }\n",
        );
    let text = if n > 3 {
        text
    } else {
        text.replace("rates = { m3 = 0 }\n", "")
    };
    let mix = lut_gen::parse(Path::new("modes-pin-n.toml"), &text).expect("mix parses");
    lut_gen::synthesize(&mix).expect("mix is feasible")
}

/// A mode count that is not a power of two: `mode_sel` has codes that name
/// no mode, which keep the decided mode, so the mode register holds a
/// request of any age; the run split on `mode_sel` still comes round (each
/// path's mode registers constant) and proves, for three modes here and
/// five in `make test-long`.
#[test]
fn a_pin_select_mix_of_three_modes_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    pin_select_mix_proves(3);
}

#[test]
#[ignore = "long: make test-long (five modes: three prove in make test)"]
fn a_pin_select_mix_of_five_modes_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    pin_select_mix_proves(5);
}

/// The pin-select mix of `n` modes proves for all time, split on `mode_sel`.
fn pin_select_mix_proves(n: usize) {
    let s = modes_pin_with(n);
    assert_eq!(s.modes.len(), n);
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "{n} modes: {}", p.summary());
    assert!(p.not_covered.is_empty(), "{:?}", p.not_covered);
    assert!(p.note.contains("split on mode_sel"), "{}", p.note);
}

/// The gateware's decision for three modes, and a mutant that sends a code
/// naming no mode to the reset mode instead of keeping the decided one: the
/// judge, like the gateware, keeps it, and rejects the counterexample.
#[test]
fn a_gateware_that_resets_the_mode_on_an_unused_code_fails_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = modes_pin_with(3);
    let kept = "wire [1:0] decided = (mode_sel[1:0] < 2'd3) ? mode_sel[1:0] : nxt;";
    let design = edit(&emitted(&s), kept, &kept.replace(": nxt;", ": 2'd0;"));
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &design, dir.path());
    let names: Vec<String> = p.properties.iter().map(|q| q.name.clone()).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    assert_fails(&s, &p, &names);
}

/// A bounded result of a mix with modes: no property failed, none is
/// called proved, and `not_covered` names the cycles beyond the search.
fn assert_honestly_bounded(p: &Proof) {
    assert_eq!(p.result, Outcome::Bounded, "{}", p.summary());
    assert!(p.properties.iter().all(|q| q.result == Outcome::Bounded));
    let beyond = format!(
        "every mode switch and every pin after cycle {}",
        p.depth - 2
    );
    assert!(
        p.not_covered.iter().any(|n| n.starts_with(&beyond)),
        "{:?}",
        p.not_covered
    );
    assert!(p.note.starts_with("NOT a proof"), "{}", p.note);
}

/// Auto select proves for all time: the paths split at frame starts on
/// the values of the mode and run registers (each frame's decision is a
/// function of the frame's codes), the link's bytes included (the frame
/// counters generalised on every path), so nothing is left out; a search
/// cut short is still honestly bounded. About a minute under load (14
/// frames, some 300 states at frame starts).
#[test]
#[ignore = "long: make test-long"]
fn the_auto_select_mix_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/modes-auto.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_whole_contract_proved_split_on_decisions(&p);
    let depth = 2 * s.grid.frame_cycles + 2_000;
    let p = prove_to(&s, &emitted(&s), dir.path(), Some(depth));
    assert_honestly_bounded(&p);
}

/// A trigger one code off (above 12001, not 12000) fails: MISO chosen at
/// the level's next code in frame 0 fires the harness's trigger, not the
/// design's: `mode` fails at cycle 2F (the first frame a trigger can
/// switch). About 25 s under load.
#[test]
fn an_auto_gateware_with_a_trigger_level_off_by_one_fails_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/modes-auto.toml");
    let design = edit(
        &emitted(&s),
        "wire cab0 = wab0 | (hit0_0 & (v_0 > 16'd12000));",
        "wire cab0 = wab0 | (hit0_0 & (v_0 > 16'd12001));",
    );
    let dir = tempfile::tempdir().unwrap();
    let p = prove_to(
        &s,
        &design,
        dir.path(),
        Some(2 * s.grid.frame_cycles + 2_000),
    );
    let names: Vec<String> = p.properties.iter().map(|q| q.name.clone()).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    assert_fails(&s, &p, &names);
}

/// A gateware whose trigger fires one window early (its run of 3 taken at
/// 2) fails: with the runs generalised (both count alike, so they are shown
/// equal) the decision differs after a generalisation, which gives no
/// verdict there, and the exact run finds the trace from reset, which
/// `check` rejects at the same cycle.
#[test]
fn an_auto_gateware_that_fires_a_window_early_fails_prove_past_its_generalised_runs() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/modes-auto.toml");
    let whole = prove(&s, &emitted(&s), tempfile::tempdir().unwrap().path());
    assert_whole_contract_proved_split_on_decisions(&whole);
    assert!(
        whole.note.contains("the runs generalised"),
        "{}",
        whole.note
    );
    let design = edit(
        &emitted(&s),
        "wire fire1 = (nxt == 2'd1) & (cur == nxt) & (runn1 == 2'd3);",
        "wire fire1 = (nxt == 2'd1) & (cur == nxt) & (runn1 == 2'd2);",
    );
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &design, dir.path());
    // the pins of the early mode fail with (or before) `mode` itself
    let names: Vec<&str> = p.properties.iter().map(|q| q.name.as_str()).collect();
    assert_fails(&s, &p, &names);
}

/// An auto-select mix with a UART proved whole: every property, the
/// link's bytes too, in two runs: the rest split on the trigger decisions,
/// the link's with the decisions tied to one free input and the frame
/// counters generalised; nothing left uncovered.
fn assert_whole_contract_proved_split_on_decisions(p: &Proof) {
    assert_whole(p);
    for how in [
        "in two runs",
        "split on the trigger decisions",
        "tied to one free input",
        "split on the tied mode decision",
        "frame counter generalised",
    ] {
        assert!(p.note.contains(how), "{how}: {}", p.note);
    }
    // an auto mix has no mode requests to split on
    assert!(!p.note.contains("mode requests"), "{}", p.note);
}

/// The preset (48 MHz, 10 ms frames, auto select over a UART) proves the
/// whole contract, its link's bytes included.
#[test]
#[ignore = "long: make test-long"]
fn the_adaptive_preset_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("mixes/eskin34-adaptive.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_whole_contract_proved_split_on_decisions(&p);
}

/// An unseen glove of the auto kind (`formal/tests/data/glove-auto-uart.toml`:
/// 24 taxels whose rate a touch raises, a release held for 5 frames, a
/// second branch, a 3 Mbaud UART, 48 MHz, 10 ms frames) proves the whole
/// contract, its link's bytes included (about 2 minutes).
#[test]
#[ignore = "long: make test-long"]
fn an_unseen_auto_glove_with_a_uart_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("formal/tests/data/glove-auto-uart.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_whole_contract_proved_split_on_decisions(&p);
}

/// Whether some mode of `s` samples no channel of some branch: that branch
/// idles in it and keeps the data, channel and mux of its last conversion
/// for as long as the requests stay there.
fn leaves_a_branch_idle(s: &lut_gen::Schedule) -> bool {
    s.modes.iter().any(|m| {
        (0..s.mix.branches.len())
            .any(|b| !(m.mix.channels.iter()).any(|c| c.branch == b && c.rate_hz > 0))
    })
}

/// A random three-mode pin-select mix where a mode leaves a branch idle:
/// the idle branch holds MISO data of any age, so the states at frame
/// starts recur only up to a renaming of their variables (not a shift by
/// whole frames); the split run must still come round and prove.
#[test]
fn a_random_three_mode_pin_mix_with_an_idle_branch_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let (seed, s) = (1..200u64)
        .find_map(|seed| {
            random_pin_mix(seed, 3)
                .filter(leaves_a_branch_idle)
                .map(|s| (seed, s))
        })
        .expect("a feasible draw with an idle branch");
    eprintln!("seed {seed}");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "seed {seed}: {}", p.summary());
    assert!(p.not_covered.is_empty(), "{:?}", p.not_covered);
    assert!(p.note.contains("split on mode_sel"), "{}", p.note);
}

/// A converter with a command word behind a front mux in a mix with modes
/// (`testkit` mixes `front-modes`, pin select, and `front-modes-auto`,
/// auto select on a fronted channel): the harness asserts the front pins
/// from each mode's table and the words across every switch (a frame's
/// last words select the next frame's conversions in the next frame's
/// mode), and the gateware proves for every sequence of requests or
/// codes; with the front select's bit 0 inverted while `mode` shows `busy`
/// only, it fails on the fronted branch's mux, and with a frame's last
/// words taken from the mode in force rather than the next frame's, on
/// its words. Two proofs and two counterexamples: minutes.
#[test]
#[ignore = "long: make test-long"]
fn a_fronted_mix_with_modes_proves_and_a_front_select_wrong_in_one_mode_fails() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    for name in ["front-modes", "front-modes-auto"] {
        let s = schedule(&format!("testkit/mixes/{name}.toml"));
        let dir = tempfile::tempdir().unwrap();
        let p = prove(&s, &emitted(&s), dir.path());
        assert_eq!(p.result, Outcome::Proved, "{name}: {}", p.summary());
        for prop in ["mux[cfg]", "mosi[cfg]", "mode"] {
            assert!(
                (p.properties.iter()).any(|q| q.name == prop && q.result == Outcome::Proved),
                "{name} {prop}: {}",
                p.summary()
            );
        }
    }
    let s = schedule("testkit/mixes/front-modes.toml");
    let good = emitted(&s);
    let line = good
        .lines()
        .find(|l| l.trim_start().starts_with("assign mux_sel = core_mux_sel["))
        .unwrap();
    let bad = edit(&good, line, &line.replace(';', " ^ {5'd0, mode};"));
    let dir = tempfile::tempdir().unwrap();
    assert_fails(&s, &prove(&s, &bad, dir.path()), &["mux[cfg]"]);
    // a frame's last words from the mode in force instead of the next
    // frame's: right within a mode, wrong across a switch only
    let stale = edit(&good, "nxm = nxt_0[0:0];", "nxm = cur;");
    let dir = tempfile::tempdir().unwrap();
    assert_fails(&s, &prove(&s, &stale, dir.path()), &["mosi[cfg]"]);
}

/// Converters with a command word in a pin-select mix (an MCP3208 whose
/// rate changes between modes, an AD7689 whose word selects the conversion
/// after next, so a frame's last words select the next frame's first
/// conversions in the mode decided for it): every property proved, the
/// words on `adc_mosi` included, for every sequence of requests.
#[test]
fn command_word_converters_in_a_pin_mode_mix_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/cmd-modes.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    for name in ["mosi[mcp]", "mosi[cfg]", "mode"] {
        let q = p.properties.iter().find(|q| q.name == name);
        assert!(q.is_some_and(|q| q.result == Outcome::Proved), "{name}");
    }
    assert!(
        p.not_covered
            .iter()
            .all(|n| n.contains("converts the input each word selects")),
        "only the parts' own behaviour is left out: {:?}",
        p.not_covered
    );
}

/// An AD7689 converted twice a frame in the reset mode, first at slot 0:
/// that conversion's word selects the first conversion of the frame after
/// the next, in the mode decided at the edge that begins its own frame.
/// The gateware that loaded it from the slot ROM's field (set a slot
/// earlier, before the decision) was proved wrong here (`mosi[b]`, a
/// trace `check` rejected at the same cycle); every property proves now.
#[test]
fn a_frames_first_word_takes_the_mode_decided_as_the_frame_begins() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/cmd-ahead-modes.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    for name in ["mosi[b]", "mode"] {
        let q = p.properties.iter().find(|q| q.name == name);
        assert!(q.is_some_and(|q| q.result == Outcome::Proved), "{name}");
    }
}

/// The AD7689's word for the second conversion of a frame that runs mode
/// `fast`, sent in the frame before, selects the wrong input: only a run
/// that switches to `fast` sends it, and `mosi[cfg]` fails there. About a
/// minute (the failing run is two frames long, then replayed).
#[test]
#[ignore = "long: make test-long"]
fn a_wrong_command_word_across_a_switch_fails_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/cmd-modes.toml");
    let design = edit(
        &emitted(&s),
        // the command unit's table: next mode `fast` (1), its conversion 1
        "2'd3: fchn = 3'd2;",
        "2'd3: fchn = 3'd3;",
    );
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &design, dir.path());
    assert_fails(&s, &p, &["mosi[cfg]"]);
}

/// The same converters with auto select (triggers on the MCP3208's words).
#[test]
#[ignore = "long: make test-long"]
fn command_word_converters_in_an_auto_mode_mix_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/cmd-modes-auto.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    assert!(p.properties.iter().all(|q| q.result == Outcome::Proved));
}

/// An unseen mix of both command-word converters with auto select and a
/// UART (`formal/tests/data/sleeve-auto-cmd.toml`: an MCP3208 and an
/// AD7689 whose channels change rate between modes, triggers on the
/// AD7689's): every asserted property proved in the two runs, the link's
/// bytes among them; not covered only what the converters themselves do
/// with the words (MISO is free), one item a branch.
#[test]
#[ignore = "long: make test-long"]
fn an_unseen_auto_mix_of_both_command_word_converters_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("formal/tests/data/sleeve-auto-cmd.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    for q in &p.properties {
        assert_eq!(q.result, Outcome::Proved, "{}: {}", q.name, p.summary());
    }
    for name in [
        "link.bytes",
        "link.packets",
        "mode",
        "mosi[mcp]",
        "mosi[cfg]",
    ] {
        assert!(p.properties.iter().any(|q| q.name == name), "{name}");
    }
    assert_eq!(p.not_covered.len(), 2, "{:?}", p.not_covered);
    for (n, part) in p.not_covered.iter().zip(["mcp3208", "ad7689"]) {
        assert!(
            n.contains(part) && n.contains("the part's own behaviour"),
            "{n}"
        );
    }
    assert!(
        p.note.contains("split on the trigger decisions"),
        "{}",
        p.note
    );
}

/// `testkit/mixes/modes-auto.toml` (three modes, auto select) with an
/// AXI4-Stream link whose slave takes every beat within `ready_within`
/// cycles (above 8: its bytes are not asserted, the rest is).
fn auto_axis(ready_within: u32) -> lut_gen::Schedule {
    with_axis("testkit/mixes/modes-auto.toml", ready_within)
}

/// The mix `file` (under the repository) with its link, if any, replaced
/// by an AXI4-Stream whose slave takes every beat within `ready_within`
/// cycles, `tlast` at each frame's end.
fn with_axis(file: &str, ready_within: u32) -> lut_gen::Schedule {
    let text = std::fs::read_to_string(root().join(file)).unwrap();
    let (head, tail) = match text.find("[link]") {
        Some(at) => {
            let end = text[at + 1..]
                .find("\n[")
                .map_or(text.len(), |i| at + 1 + i);
            (&text[..at], &text[end..])
        }
        None => (text.as_str(), ""),
    };
    let text = format!(
        "{head}\n[link]\nkind = \"axis\"\ntlast = \"frame\"\nready_within = {ready_within}\n{tail}"
    );
    let mix = lut_gen::parse(Path::new("with-axis.toml"), &text).expect("parses");
    lut_gen::synthesize(&mix).expect("feasible")
}

/// A pin-select mix with an AXI4-Stream whose slave may wait (`ready_within
/// = 2`) proves the whole contract, the beats and their packets for all
/// time: the run split on the slave's choices and `mode_sel` with the frame
/// counters generalised comes round, so no byte is left to a bounded search.
#[test]
fn a_pin_mode_mix_with_an_axi_stream_proves_its_beats_for_all_time() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = with_axis("testkit/mixes/modes-pin.toml", 2);
    let dir = tempfile::tempdir().unwrap();
    let p = proved_whole(&s, dir.path());
    assert!(
        p.note.contains("under every slave the guarantee allows"),
        "{}",
        p.note
    );
}

/// The same crossing with auto select (modes-auto's triggers, `ready_within
/// = 2`) proves whole too: the link's properties with the mode decisions
/// tied to one free input and the slave's choices split on, in the run's
/// note (before its held requests were shared by the paths, this run did
/// not come round and the whole harness's took about two minutes).
#[test]
fn an_auto_mix_with_an_axi_stream_proves_its_beats_with_the_decisions_tied() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = auto_axis(2);
    let dir = tempfile::tempdir().unwrap();
    let p = proved_whole(&s, dir.path());
    for says in [
        "tied to one free input",
        "tready_any",
        "link.bytes, link.packets",
    ] {
        assert!(p.note.contains(says), "{says}: {}", p.note);
    }
}

/// A wrong CRC polynomial in that mix's gateware fails `link.packets` with
/// a trace from reset that `check` rejects.
#[test]
#[ignore = "long: make test-long (the whole harness's run after the tied one's violation)"]
fn an_auto_mix_with_an_axi_stream_and_a_wrong_crc_fails() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = auto_axis(2);
    let dir = tempfile::tempdir().unwrap();
    let wrong = edit(
        &emitted(&s),
        "((x >> 1) ^ 16'ha001)",
        "((x >> 1) ^ 16'h8005)",
    );
    let p = prove(&s, &wrong, dir.path());
    assert_fails(&s, &p, &["link.packets"]);
}

/// `prove` of `design` cut at `timeout_s` seconds per run.
fn prove_within(s: &lut_gen::Schedule, design: &str, out: &Path, timeout_s: u64) -> Proof {
    let mut o = ProveOptions::new(out);
    o.timeout_s = timeout_s;
    o.bmc_timeout_s = timeout_s;
    o.frame_counter = Some(hdl::LINK_FRAME_COUNTER.to_string());
    o.mode_decision = Some(hdl::MODE_DECISION.to_string());
    o.trigger_run = Some(hdl::TRIGGER_RUN.to_string());
    let p = formal::prove(s, design, &o).expect("prove runs");
    eprintln!("{}", p.summary());
    p
}

/// Auto select with an AXI4-Stream slave proves for all time, in two runs:
/// the slave's choices and the trigger decisions together never came
/// round (a FIFO fill per path of codes: bounded at the time limit), so
/// the FIFO's and the beats' properties are proved with the design's mode
/// decision free (every sequence of modes), the rest on the design as it
/// is. Nothing about modes is left uncovered (the bytes, beyond
/// `ready_within = 8`, are listed as before).
#[test]
fn an_auto_mix_with_an_axi_stream_proves_in_two_runs() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = auto_axis(9);
    let dir = tempfile::tempdir().unwrap();
    let p = prove_within(&s, &emitted(&s), dir.path(), 120);
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    for q in &p.properties {
        assert_eq!(q.result, Outcome::Proved, "{}: {}", q.name, p.summary());
    }
    assert!(
        p.note.contains("in two runs") && p.note.contains("mode decision a free input"),
        "{}",
        p.note
    );
    let left: Vec<&String> = (p.not_covered.iter())
        .filter(|n| !n.contains("m_axis_tdata"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// A serializer that ignores `tready` (it waits a cycle after each beat:
/// half the rate) overflows its FIFO: the run with the mode decision cut
/// finds it, and since a violation there may be of the cut's extra
/// behaviours only, the whole harness decides: a trace from reset that
/// `link.overflow` fails, which `check` rejects too, earlier (its model
/// of the link is exact to the cycle: the beat after the first comes a
/// cycle late at cycle 12, which the contract allows). 331-350 s on two
/// cores beside other work (2026-11-30; about two minutes when written).
/// Each run may take 300 s: with 120, the whole harness's run (its
/// symbolic part's SAT checks; the explicit search gives up at step 56)
/// stopped at its time limit at step 2,050 while a CI ran beside it.
#[test]
#[ignore = "long: make test-long (the whole harness's run after the cut one's violation)"]
fn an_auto_axi_stream_gateware_that_ignores_tready_fails_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = auto_axis(9);
    let design = edit(
        &emitted(&s),
        "wire ready = !busy | tready;",
        "wire ready = !busy;",
    );
    let dir = tempfile::tempdir().unwrap();
    let p = prove_within(&s, &design, dir.path(), 300);
    assert_eq!(p.result, Outcome::Failed, "{}", p.summary());
    let c = p.counterexample.as_ref().expect("a counterexample");
    assert!(c.reproduced, "the replay reproduces it: {}", p.summary());
    assert!(failed(&p).contains(&"link.overflow"), "{}", p.summary());
    let first = formal::first_rejected(&rejected(&s, c));
    assert!(first.is_some_and(|k| k <= c.cycle as u64), "{first:?}");
}

/// A small auto-select mix with a UART (`formal/tests/data/auto-uart-small.toml`:
/// two modes, one trigger each way, 4 MHz, 1 ms frames) proves whole in two
/// runs, its link's with the decisions tied to one free input.
#[test]
fn a_small_auto_mix_with_a_uart_proves_with_its_decisions_tied() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("formal/tests/data/auto-uart-small.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_whole_contract_proved_split_on_decisions(&p);
}

/// The same mix's gateware with a wrong CRC polynomial (0x8005 unreflected
/// for CRC-16/MODBUS's reflected 0xA001) fails `link.packets`: the tied run finds it, and
/// since a violation there may be of its extra sequences only, the whole
/// harness decides, with a counterexample `check` rejects at its cycle.
#[test]
fn a_small_auto_mix_with_a_wrong_crc_fails_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("formal/tests/data/auto-uart-small.toml");
    let design = edit(&emitted(&s), "& 16'ha001);", "& 16'h8005);");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &design, dir.path());
    assert_fails(&s, &p, &["link.packets"]);
}
