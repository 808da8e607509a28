//! One source per figure: every number a `build` step summary and the
//! report's header print equals the JSON it summarises (`audit.json`,
//! `sim.json`) or the file it counts, on three mixes no feature was written
//! for: an AD7685 chain beside an AD7940 branch, a UART link, and a random
//! mix from `campaign::random_mix`.  The steps compared are the ones whose
//! figures are checked here (the fault campaign and synthesis are left out:
//! they take minutes).

use std::path::Path;

use serde_json::Value;

use crate::common_cli::slotforge;

const STEPS: &str = "audit,lut,verilog,sim,netlist,timing,figure7,schedulability";

/// [`STEPS`] but the netlist's: its synthesis and a Verilator build of the
/// gate-level netlist were half of a mix's build.  `make test` checks the
/// netlist's figures on the random mix, `make test-long` on the other two.
const STEPS_BUT_NETLIST: &str = "audit,lut,verilog,sim,timing,figure7,schedulability";

/// An AD7685 chain of three (CNV, branch 0, so the timing figure is a CNV
/// part's) beside an AD7940 branch, at 2 kHz and 250 Hz.
fn chain_mix() -> String {
    let mut t = String::from(
        "name = \"chain3\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 4_000\nslice_us = 1_000\n\
         [[branch]]\nname = \"acc\"\nadc = \"ad7685\"\nchain = 3\nmux = \"none\"\n\
         [[branch]]\nname = \"pads\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 1\nsettle_ns = 1_000\n",
    );
    for m in 0..3 {
        t += &format!(
            "[[channel]]\nname = \"ACC{m}\"\nbranch = \"acc\"\nmember = {m}\nrate_hz = 2_000\n"
        );
    }
    for i in 0..5 {
        t += &format!("[[channel]]\nname = \"P{i}\"\nbranch = \"pads\"\nrate_hz = 250\n");
    }
    t
}

/// Two AD7940 branches and a 1 Mbaud UART.
fn link_mix() -> String {
    let mut t = String::from(
        "name = \"linked\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 5_000\nslice_us = 1_000\n\
         [link]\nkind = \"uart\"\nbaud = 1_000_000\n\
         [[branch]]\nname = \"a\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 2\nsettle_ns = 2_000\n\
         [[branch]]\nname = \"b\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 1\nsettle_ns = 2_000\n",
    );
    for i in 0..9 {
        t += &format!("[[channel]]\nname = \"A{i}\"\nbranch = \"a\"\nrate_hz = 1_000\n");
    }
    for i in 0..3 {
        t += &format!("[[channel]]\nname = \"B{i}\"\nbranch = \"b\"\nrate_hz = 200\n");
    }
    t
}

/// The first random mix (from seed 7 on) that has a schedule.
fn random_mix() -> String {
    (7..100)
        .map(|seed| campaign::random_mix(seed, &campaign::Shape::default()))
        .find(|t| {
            lut_gen::parse(Path::new("random.toml"), t)
                .ok()
                .is_some_and(|m| lut_gen::synthesize(&m).is_ok())
        })
        .expect("a schedulable random mix")
}

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The number right after `before` in `text` (digits and one dot).
fn after(text: &str, before: &str) -> f64 {
    // the report marks identifiers as code; the figure is the same
    let text = &text.replace('`', "");
    let i = text
        .find(before)
        .unwrap_or_else(|| panic!("`{before}` not in: {text}"))
        + before.len();
    let n: String = text[i..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    n.trim_end_matches('.')
        .parse()
        .unwrap_or_else(|_| panic!("no number after `{before}` in: {text}"))
}

/// The number right before `after` in `text`.
fn before(text: &str, after: &str) -> f64 {
    let i = text
        .find(after)
        .unwrap_or_else(|| panic!("`{after}` not in: {text}"));
    let n: String = text[..i]
        .chars()
        .rev()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    n.parse()
        .unwrap_or_else(|_| panic!("no number before `{after}` in: {text}"))
}

/// The `result` cell of step `name`'s row in report.md.
fn summary<'a>(md: &'a str, name: &str) -> &'a str {
    let row = md
        .lines()
        .find(|l| l.starts_with(&format!("| {name} | ok |")))
        .unwrap_or_else(|| panic!("no ok row for step `{name}` in report.md"));
    row.split(" | ").nth(3).unwrap()
}

/// `2 x AD7940, 1 x AD7685 (chain of 3)`, counted from `audit.json`'s parts.
fn parts_named(audit: &Value) -> String {
    let mut seen: Vec<(String, usize)> = Vec::new();
    for p in audit["parts"].as_array().unwrap() {
        let adc = p["adc"].as_str().unwrap().to_uppercase();
        let name = match p["chain"].as_u64().unwrap() {
            1 => adc,
            n => format!("{adc} (chain of {n})"),
        };
        match seen.iter_mut().find(|(n, _)| *n == name) {
            Some((_, k)) => *k += 1,
            None => seen.push((name, 1)),
        }
    }
    let v: Vec<String> = seen.iter().map(|(n, k)| format!("{k} x {n}")).collect();
    v.join(", ")
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

/// The audit step's summary against audit.json, and the converters'
/// maximum as one figure: each branch's is its part's, the total their
/// sum, and the audit's text prints that same value in both its tables.
fn audit_figures(a: &Value, md: &str, out: &Path) {
    // audit: the figures of audit.json, the limit as the audit rounds it
    let s = summary(md, "audit");
    assert_eq!(after(s, "feasible, "), num(&a["slots_per_slice"]), "{s}");
    assert_eq!(before(s, " samples/s of"), num(&a["aggregate_hz"]), "{s}");
    let limit = num(&a["adc_limit_hz"]);
    assert_eq!(after(s, "converters' "), limit.round(), "{s}");
    let pct = after(s, &format!("{} (", limit.round()));
    assert_eq!(
        format!("{pct:.1}"),
        format!("{:.1}", num(&a["adc_utilization"]) * 100.0)
    );
    // the converters' maximum is one figure: each branch's is its part's,
    // the total their sum, and the audit's text prints that same value
    let (branches, parts) = (
        a["branches"].as_array().unwrap(),
        a["parts"].as_array().unwrap(),
    );
    let mut sum = 0.0;
    let audit_txt = std::fs::read_to_string(out.join("audit.txt")).unwrap();
    for (b, p) in branches.iter().zip(parts) {
        assert_eq!(num(&b["adc_max_sps"]), num(&p["max_samples_hz"]));
        let words = num(&p["chain"]);
        let per = num(&p["max_conversions_hz"]) * words / num(&p["max_samples_hz"]);
        assert!((per - 1.0).abs() < 1e-12, "{p}");
        let v = format!("{:.0}", num(&p["max_samples_hz"]));
        let seen = audit_txt.split_whitespace().filter(|w| *w == v).count();
        assert!(seen >= 2, "{v} in both tables of {audit_txt}");
        sum += num(&b["adc_max_sps"]);
    }
    assert_eq!(sum, limit);
}

/// Figure 7's summary: the slowest and the fastest rate of the mix in
/// audit.json, and their ratio.
fn figure7_figures(a: &Value, md: &str) {
    // Figure 7: the slowest and the fastest rate of the mix, and their ratio
    let s = summary(md, "chart: Figure 7 for this mix's rates");
    let rates: Vec<f64> = a["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| num(&c["requested_hz"]))
        .collect();
    let (slow, fast) = (
        rates.iter().copied().fold(f64::MAX, f64::min),
        rates.iter().copied().fold(0.0, f64::max),
    );
    assert_eq!(before(s, " Hz keeps its shape"), slow, "{s}");
    assert_eq!(before(s, " Hz rate"), fast, "{s}");
    let share = format!("{:.1}", slow / fast * 100.0);
    let share = share.trim_end_matches(".0");
    assert!(s.contains(&format!("with {share} % of the data")), "{s}");
}

/// Builds `text` with `steps` (the netlist's or not) and holds every
/// figure it prints against its source.
fn figures_of(text: &str, steps: &str) {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let mix = dir.join("mix.toml");
    std::fs::write(&mix, text).unwrap();
    let out = dir.join("out");
    let run = slotforge()
        .arg("build")
        .arg(&mix)
        .arg("-o")
        .arg(&out)
        .args(["--only", steps])
        .env_remove("CI")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout).to_string();
    let stderr = String::from_utf8_lossy(&run.stderr).to_string();
    assert_eq!(run.status.code(), Some(0), "{stdout}{stderr}");
    let a = json(&out.join("audit.json"));
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();

    audit_figures(&a, &md, &out);
    let (branches, parts) = (
        a["branches"].as_array().unwrap(),
        a["parts"].as_array().unwrap(),
    );

    // the slot LUT: the frame's slots
    let s = summary(&md, "slot LUT");
    let frame_slots = num(&a["frame_cycles"]) / num(&a["slot_cycles"]);
    assert_eq!(before(s, " frame slots"), frame_slots, "{s}");

    // Verilog: the lines of the file it names
    let s = summary(&md, "Verilog, ports.json, constraints");
    let v = std::fs::read_to_string(out.join("verilog/slotforge_top.v")).unwrap();
    assert_eq!(
        before(s, " lines of Verilog"),
        v.lines().count() as f64,
        "{s}"
    );

    // the co-simulation: sim.json's frames and samples
    let sim = json(&out.join("sim.json"));
    let s = summary(&md, "co-simulation");
    assert_eq!(before(s, " frames"), num(&sim["frames"]), "{s}");
    assert_eq!(before(s, " samples"), num(&sim["samples"]), "{s}");

    // the netlist: netlist.json's source, frames and samples
    if steps.contains("netlist") {
        let nl = json(&out.join("netlist.json"));
        let s = summary(&md, "netlist simulated (iCE40, a frame)");
        assert!(s.starts_with(nl["source"].as_str().unwrap()), "{s}");
        assert_eq!(before(s, " frame,"), num(&nl["frames"]), "{s}");
        assert_eq!(before(s, " samples"), num(&nl["samples"]), "{s}");
    }

    // timing: the grid, and branch 0's strobe at read_cycles + 1 (docs/timing.md)
    let s = summary(&md, "chart: timing of a slice");
    assert_eq!(before(s, " slots of"), num(&a["slots_per_slice"]), "{s}");
    assert_eq!(after(s, " slots of "), num(&a["slot_cycles"]), "{s}");
    assert_eq!(
        after(s, "sample_valid strobe "),
        num(&parts[0]["read_cycles"]) + 1.0,
        "{s}"
    );
    let b0 = branches[0]["name"].as_str().unwrap();
    assert!(s.contains(&format!("of branch {b0} ")), "{s}");

    figure7_figures(&a, &md);

    // schedulability: this mix's utilization is the audit's; its parts named
    let s = summary(&md, "chart: where scheduling breaks");
    assert_eq!(
        format!("{:.1}", after(s, "this mix: ")),
        format!("{:.1}", num(&a["adc_utilization"]) * 100.0),
        "{s}"
    );
    let named = format!("this mix: {};", parts_named(&a));
    assert!(md.contains(&named), "`{named}` not in report.md");

    // the report's header: channels, branches, frame, samples per frame
    let head = md.lines().nth(2).unwrap();
    let channels = a["channels"].as_array().unwrap().len() as f64;
    assert_eq!(before(head, " channels on"), channels, "{head}");
    assert_eq!(after(head, "channels on "), branches.len() as f64, "{head}");
    assert_eq!(after(head, "frame "), num(&a["frame_cycles"]), "{head}");
    assert_eq!(
        before(head, " samples per frame"),
        num(&a["samples_per_frame"]),
        "{head}"
    );

    // the step count: the progress's [n/N] and the last line's
    let n = after(&stderr, "[1/");
    assert_eq!(after(&stdout, ": "), n, "{stdout}{stderr}");
    assert_eq!(n, steps.split(',').count() as f64);
}

#[test]
fn an_ad7685_chains_figures_are_its_json() {
    figures_of(&chain_mix(), STEPS_BUT_NETLIST);
}

#[test]
fn a_linked_mixs_figures_are_its_json() {
    figures_of(&link_mix(), STEPS_BUT_NETLIST);
}

#[test]
fn a_random_mixs_figures_are_its_json() {
    figures_of(&random_mix(), STEPS);
}

#[test]
#[ignore = "long: make test-long (the chain's and the linked mix's netlist figures)"]
fn the_chain_and_linked_mixs_figures_with_the_netlist_are_their_json() {
    figures_of(&chain_mix(), STEPS);
    figures_of(&link_mix(), STEPS);
}
