//! Each converter sampled where its datasheet says, measured on the
//! waveform: an AD7940 at its CS fall, an MCP3208 at the falling SCLK edge
//! after the 6th rising one since its CS fell.  `sampled_s` of `sim
//! --samples` is that instant for every sample of either part; a sync
//! group holds at one instant (the earlier part's transaction held off by
//! the difference) on Verilator and Icarus alike, or the mix is refused
//! naming the parts.

use std::collections::BTreeMap;
use std::path::Path;

use crate::common_cli::{refused, root, slotforge};
use crate::tools;

/// A waveform's top-level signals: name -> (time in ps, value) changes.
type Wave = BTreeMap<String, Vec<(u64, u128)>>;

/// The top module's signals of a VCD as (time in ps, value) changes, by
/// name; scalars and vectors alike as integers.  Written here from the VCD
/// text, sharing nothing with the judge's reader.
fn changes(vcd: &str) -> Wave {
    let mut names: BTreeMap<String, String> = BTreeMap::new();
    let mut out: BTreeMap<String, Vec<(u64, u128)>> = BTreeMap::new();
    let (mut depth, mut t) = (0, 0u64);
    let mut put = |id: &str, v: u128, t: u64, names: &BTreeMap<String, String>| {
        if let Some(n) = names.get(id) {
            out.entry(n.clone()).or_default().push((t, v));
        }
    };
    for line in vcd.lines().map(str::trim) {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first().copied() {
            Some("$scope") => depth += 1,
            Some("$upscope") => depth -= 1,
            // only the top module's ports, not the branch views under it
            Some("$var") if depth == 1 => _ = names.insert(w[3].into(), w[4].into()),
            Some(x) if x.starts_with('#') => t = x[1..].parse().unwrap(),
            Some(x) if x.starts_with('b') => {
                // Icarus shows an undriven (x, z) bit: read as 0, no port measured here is one
                let bits = x[1..].replace(['x', 'z', 'X', 'Z'], "0");
                put(w[1], u128::from_str_radix(&bits, 2).unwrap(), t, &names)
            }
            Some(x) if x.starts_with(['0', '1']) => {
                put(&x[1..], (x.as_bytes()[0] - b'0') as u128, t, &names)
            }
            _ => {}
        }
    }
    out
}

/// The value of `sig` at time `t` (the last change at or before it).
fn at(sig: &[(u64, u128)], t: u64) -> u128 {
    sig.iter()
        .take_while(|c| c.0 <= t)
        .last()
        .map_or(0, |c| c.1)
}

/// Edges of lane `b` of `sig`: (time, new level).
fn edges(sig: &[(u64, u128)], b: usize) -> Vec<(u64, bool)> {
    let mut prev = None;
    let mut e = Vec::new();
    for &(t, v) in sig {
        let now = v >> b & 1 == 1;
        if prev.is_some_and(|p| p != now) {
            e.push((t, now));
        }
        prev = Some(now);
    }
    e
}

/// Per branch lane: the instants (ps after cycle 0) the waveform shows the
/// part holding its input: CS falling, or (`after` = Some(n)) the falling
/// SCLK after the n-th rising SCLK since CS fell.
fn measured(w: &Wave, b: usize, after: Option<usize>) -> Vec<u64> {
    held(w, b, after, false)
}

/// [`measured`] of a lane whose conversion starts at a rising edge (`cnv`:
/// a CNV part's lane of `adc_cs_n`) or a falling one.
fn held(w: &Wave, b: usize, after: Option<usize>, cnv: bool) -> Vec<u64> {
    let (clk, rst) = (&w["clk"], &w["rst"]);
    // cycle 0 begins at the first rising clock edge that samples rst low
    let t0 = clk
        .iter()
        .find(|c| c.1 == 1 && at(rst, c.0) == 0)
        .expect("reset released")
        .0;
    let cs = edges(&w["adc_cs_n"], b);
    let sclk = edges(&w["adc_sclk"], b);
    let mut out = Vec::new();
    for &(t, _) in cs.iter().filter(|e| e.1 == cnv) {
        let held = match after {
            None => Some(t),
            Some(n) => {
                let mut rises = sclk.iter().filter(|e| e.0 > t && e.1);
                let nth = rises.nth(n - 1).map(|e| e.0);
                nth.and_then(|r| sclk.iter().find(|e| e.0 > r && !e.1).map(|e| e.0))
            }
        };
        out.extend(held.map(|h| h - t0));
    }
    out
}

/// `sim --backend rusthdl --vcd --samples` of `mix` for `frames`: the
/// waveform's changes and the samples CSV's (channel, sampled_s in ps).
fn run(mix: &Path, frames: u64, dir: &Path) -> (Wave, Vec<(String, u64)>) {
    run_on(mix, frames, dir, "rusthdl")
}

/// [`run`] on `backend`; the waveform is left in `dir/run.vcd`.
fn run_on(mix: &Path, frames: u64, dir: &Path, backend: &str) -> (Wave, Vec<(String, u64)>) {
    let (vcd, csv) = (dir.join("run.vcd"), dir.join("s.csv"));
    slotforge()
        .arg("sim")
        .arg(mix)
        .args([
            "--backend",
            backend,
            "--frames",
            &frames.to_string(),
            "--stimulus",
            "sine",
        ])
        .arg("--vcd")
        .arg(&vcd)
        .args(["--to", &frames.to_string()])
        .arg("--samples")
        .arg(&csv)
        .assert()
        .success();
    let rows = std::fs::read_to_string(&csv).unwrap();
    let samples = rows
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let (s, frac) = f[1].split_once('.').unwrap();
            let ps = s.parse::<u64>().unwrap() * 1_000_000_000_000 + frac.parse::<u64>().unwrap();
            (f[2].to_string(), ps)
        })
        .collect();
    (changes(&std::fs::read_to_string(&vcd).unwrap()), samples)
}

/// The sampling instants (ps) of channel `name` in `samples`.
fn sampled(samples: &[(String, u64)], name: &str) -> Vec<u64> {
    samples
        .iter()
        .filter(|s| s.0 == name)
        .map(|s| s.1)
        .collect()
}

/// Every sample's `sampled_s` is one of its branch's measured instants
/// (within the 1 ps rounding of each), and every instant but the run's
/// last few has its sample.
fn agree(samples: &[(String, u64)], on: &[&str], instants: &[u64]) {
    let mine: Vec<u64> = samples
        .iter()
        .filter(|s| on.contains(&s.0.as_str()))
        .map(|s| s.1)
        .collect();
    assert!(!mine.is_empty());
    for t in &mine {
        assert!(
            instants.iter().any(|i| i.abs_diff(*t) <= 1),
            "sampled_s {t} ps is no measured instant of {on:?}: {instants:?}"
        );
    }
    assert!(
        mine.len() + 2 >= instants.len(),
        "{} samples, {} instants",
        mine.len(),
        instants.len()
    );
}

#[test]
fn each_part_is_sampled_at_its_own_instant_on_the_waveform() {
    let dir = tempfile::tempdir().unwrap();
    let mix = root().join("testkit/mixes/cmd-mcp3208.toml");
    let (w, samples) = run(&mix, 1, dir.path());
    // branch 0: the MCP3208 (cmd); branch 1: the AD7940 (ext)
    let mcp = measured(&w, 0, Some(6));
    let cs = measured(&w, 0, None);
    let ad = measured(&w, 1, None);
    assert_eq!(mcp.len(), cs.len());
    for (h, c) in mcp.iter().zip(&cs) {
        // 5 setup cycles and six 1 MHz periods at 48 MHz: 293 cycles
        // (each edge's time rounded once to 1 ps)
        let want = (293.0f64 * 1e12 / 48e6).round() as u64;
        assert!((h - c).abs_diff(want) <= 1, "{h} {c}");
    }
    agree(&samples, &["M7", "M2", "M5"], &mcp);
    agree(&samples, &["E0", "E3"], &ad);
}

/// cmd-mcp3208 with M2 (its MCP3208) and E0 (on branch `ext`) in one sync
/// group, 2 kHz each.
fn grouped() -> String {
    let text = std::fs::read_to_string(root().join("testkit/mixes/cmd-mcp3208.toml")).unwrap();
    text.replace(
        "rate_hz = 2_000\ninput = 2\n",
        "rate_hz = 2_000\ninput = 2\nsync = \"s\"\n",
    )
    .replace(
        "rate_hz = 2_000\ninput = 0\n",
        "rate_hz = 2_000\ninput = 0\nsync = \"s\"\n",
    )
}

/// The AD7940 behind its mux, or an AD7689 choosing its own input (a CNV
/// part, sampling at CNV rising), on branch `ext`.
const EXT: [(&str, &str, bool); 2] = [
    (
        "ad7940",
        "adc = \"ad7940\"\nmux = \"tmux1108\"\nsettle_ns = 1_000",
        false,
    ),
    ("ad7689", "adc = \"ad7689\"\nmux = \"internal\"", true),
];

/// A sync group of an MCP3208 (holding 6.1 us into its transaction) and an
/// AD7940 or AD7689 (holding at its start edge): on the VCD of Verilator
/// and of Icarus, every sample of the group is where both parts hold their
/// inputs, within 1 us (the other part's transaction starts 6.1 us after the
/// slot tick, so it is); and `check` passes the run with and without the model.
/// `make test` runs each part on one engine (the AD7940 on Verilator, the
/// AD7689 on Icarus at 12 MHz: a quarter of the mix's 48 MHz cycles, whose
/// Icarus run was half of this test), `make test-long` the other two pairs
/// and the AD7689 on Icarus at 48 MHz.
#[test]
fn a_sync_group_holds_at_one_instant_on_verilator_and_icarus() {
    if !tools::require_tool("verilator") || !tools::require_tool("iverilog") {
        return;
    }
    group_holds_at_one_instant(EXT[0], "verilator", GROUPED_HZ);
    group_holds_at_one_instant(EXT[1], "icarus", "12_000_000");
}

#[test]
#[ignore = "long: make test-long (the AD7940 on Icarus, the AD7689 on Verilator, and on Icarus at 48 MHz)"]
fn a_sync_group_holds_at_one_instant_on_the_other_engine_too() {
    if !tools::require_tool("verilator") || !tools::require_tool("iverilog") {
        return;
    }
    group_holds_at_one_instant(EXT[0], "icarus", GROUPED_HZ);
    group_holds_at_one_instant(EXT[1], "verilator", GROUPED_HZ);
    group_holds_at_one_instant(EXT[1], "icarus", GROUPED_HZ);
}

/// The clock of [`grouped`] (cmd-mcp3208's).
const GROUPED_HZ: &str = "48_000_000";

/// The group of the MCP3208 and `part` holds at one instant on `backend`,
/// the mix clocked at `hz`.
fn group_holds_at_one_instant((part, ext, cnv): (&str, &str, bool), backend: &str, hz: &str) {
    const US: u64 = 1_000_000; // ps
    let dir = tempfile::tempdir().unwrap();
    let clock = format!("hz = {GROUPED_HZ}");
    assert!(grouped().contains(&clock));
    let text = (grouped().replace(EXT[0].1, ext)).replace(&clock, &format!("hz = {hz}"));
    let m = dir.path().join(format!("{part}.toml"));
    std::fs::write(&m, &text).unwrap();
    let (w, samples) = run_on(&m, 2, dir.path(), backend);
    let (mcp, other) = (measured(&w, 0, Some(6)), held(&w, 1, None, cnv));
    let (m2, e0) = (sampled(&samples, "M2"), sampled(&samples, "E0"));
    // an AD7689's first conversions after reset are prepared (no sample)
    assert!(e0.len() >= 2, "{part} on {backend}: {e0:?}");
    assert!(
        m2.ends_with(&e0),
        "{part} on {backend}: one instant per group sample: {m2:?} {e0:?}"
    );
    for t in &e0 {
        let near = |x: &[u64], by: u64| x.iter().any(|i| i.abs_diff(*t) <= by);
        assert!(
            near(&mcp, 1),
            "{part} on {backend}: {t} is no MCP3208 instant"
        );
        assert!(
            near(&other, US),
            "{part} on {backend}: the {part} holds no input within 1 us of {t}: {other:?}"
        );
    }
    let vcd = dir.path().join("run.vcd");
    for extra in [None, Some("--no-model")] {
        slotforge()
            .arg("check")
            .arg(&m)
            .arg(&vcd)
            .args(extra)
            .assert()
            .success();
    }
}

/// A hold-off that no longer fits a slice is refused naming the group and
/// the parts; two MCP3208s at one SCLK need none.
#[test]
fn a_sync_group_that_cannot_hold_off_is_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    // a slow AD7940 fits a 50 us slice, not after a 6.1 us hold-off
    let slow = grouped()
        .replace("slice_us = 500", "slice_us = 50")
        .replace("settle_ns = 1_000", "settle_ns = 1_000\nsclk_hz = 330_000");
    let m = dir.path().join("slow.toml");
    std::fs::write(&m, &slow).unwrap();
    refused(
        &[&"audit", &m],
        &[
            "sync group `s` cannot hold at one instant",
            "mcp3208",
            "ad7940",
            "6.104 us after the slot tick",
            "longer than a slice",
        ],
    );
    // the group with the AD7940 replaced by a second MCP3208: one instant
    let both = grouped().replace(EXT[0].1, "adc = \"mcp3208\"\nmux = \"internal\"");
    let m = dir.path().join("both.toml");
    std::fs::write(&m, &both).unwrap();
    let (w, samples) = run(&m, 1, dir.path());
    let (a, b) = (measured(&w, 0, Some(6)), measured(&w, 1, Some(6)));
    let (m2, e0) = (sampled(&samples, "M2"), sampled(&samples, "E0"));
    assert!(!m2.is_empty());
    assert_eq!(m2, e0, "the group's samples share their instants");
    for t in &m2 {
        // on the waveform both parts hold their inputs there, within 1 us
        let near = |x: &[u64]| x.iter().any(|i| i.abs_diff(*t) <= 1);
        assert!(near(&a) && near(&b), "{t}");
    }
}

/// An MCP3208 at 2 MHz is refused at its lowest supply naming `vdd`; the
/// advice, applied as printed, audits feasible and the audit shows 5.0 V.
#[test]
fn the_vdd_advice_works_as_printed() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("testkit/mixes/cmd-mcp3208.toml")).unwrap();
    let fast = text.replace(
        "adc = \"mcp3208\"\n",
        "adc = \"mcp3208\"\nsclk_hz = 2_000_000\n",
    );
    let m = dir.path().join("fast.toml");
    std::fs::write(&m, &fast).unwrap();
    let out = refused(
        &[&"audit", &m],
        &[
            "branch[0].sclk_hz",
            "exceeds its 1 MHz at 2.7 V",
            "fast.toml:",
        ],
    );
    let err = String::from_utf8_lossy(&out.get_output().stderr).to_string();
    let said = err
        .split("say `")
        .nth(1)
        .and_then(|h| h.split('`').next())
        .unwrap_or_else(|| panic!("no advice: {err}"));
    assert_eq!(said, "vdd = 5.0");
    assert!(err.contains("on branch `cmd`"), "{err}");
    let fixed = fast.replace(
        "sclk_hz = 2_000_000\n",
        &format!("sclk_hz = 2_000_000\n{said}\n"),
    );
    std::fs::write(&m, &fixed).unwrap();
    let out = slotforge()
        .arg("audit")
        .arg(&m)
        .arg("--json")
        .assert()
        .success();
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    assert_eq!(v["feasible"], true);
    assert_eq!(v["parts"][0]["vdd_v"], 5.0);
    assert_eq!(v["parts"][0]["vdd_given"], true);
    assert_eq!(v["parts"][1]["vdd_given"], false);
    assert_eq!(v["branches"][0]["sclk_hz"], 2_000_000.0);
    let text = slotforge().arg("audit").arg(&m).assert().success();
    let t = String::from_utf8_lossy(&text.get_output().stdout).to_string();
    assert!(t.contains("VDD") && t.contains("+3.104us"), "{t}");
}

/// Random mixes of an MCP3208 (at a random SCLK and supply), a listening
/// AD7940 and an AD7689, channels on random inputs at random rates: every
/// `sampled_s` is an instant the waveform shows its part holding its input.
#[test]
fn random_mixes_are_sampled_where_the_waveform_says() {
    let dir = tempfile::tempdir().unwrap();
    for seed in 1..=4u64 {
        let mut draw = testkit::modemix::Draw::new(seed);
        let mut next = |n: u64| draw.below(n);
        let (vdd, sclk) =
            [("", 1_000_000), ("vdd = 5.0\n", 2_000_000), ("", 500_000)][(seed % 3) as usize];
        let mut t = format!(
            "name = \"r{seed}\"\n[clock]\nhz = 24000000\n[frame]\nperiod_us = 1000\nslice_us = 500\n\
             [[branch]]\nname = \"m\"\nadc = \"mcp3208\"\nmux = \"internal\"\nsclk_hz = {sclk}\n{vdd}\
             [[branch]]\nname = \"l\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n\
             [[branch]]\nname = \"a\"\nadc = \"ad7689\"\nmux = \"internal\"\n"
        );
        let mut names: Vec<Vec<String>> = vec![Vec::new(); 3];
        for (b, branch) in ["m", "l", "a"].iter().enumerate() {
            let mut inputs: Vec<u64> = (0..8).collect();
            for _ in 0..2 + next(3) {
                let input = inputs.remove(next(inputs.len() as u64) as usize);
                let rate = [2000, 4000][next(2) as usize];
                let name = format!("{branch}{input}");
                t += &format!(
                    "[[channel]]\nname = \"{name}\"\nbranch = \"{branch}\"\nrate_hz = {rate}\ninput = {input}\n"
                );
                names[b].push(name);
            }
        }
        let m = dir.path().join(format!("r{seed}.toml"));
        std::fs::write(&m, &t).unwrap();
        let (w, samples) = run(&m, 2, dir.path());
        let on = |b: usize| names[b].iter().map(String::as_str).collect::<Vec<_>>();
        agree(&samples, &on(0), &held(&w, 0, Some(6), false));
        agree(&samples, &on(1), &held(&w, 1, None, false));
        // the AD7689's first two conversions are prepared, never data
        let a = held(&w, 2, None, true);
        agree(&samples, &on(2), &a);
    }
}

/// `decode`'s `sampled_s` is the part's instant too: an MCP3208 mix with a
/// UART decodes to the samples `sim --samples` wrote, with their
/// `sampled_s` (each MCP3208 sample 6.104 us after a slot's start).
#[test]
fn decode_gives_each_part_its_instant() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("testkit/mixes/cmd-mcp3208.toml")).unwrap();
    let m = dir.path().join("uart.toml");
    std::fs::write(&m, text + "\n[link]\nkind = \"uart\"\nbaud = 3_000_000\n").unwrap();
    let (line, sim, dec) = (
        dir.path().join("line.bin"),
        dir.path().join("s.csv"),
        dir.path().join("d.csv"),
    );
    slotforge()
        .arg("sim")
        .arg(&m)
        .args(["--backend", "rusthdl", "--frames", "3", "--link-bytes"])
        .arg(&line)
        .arg("--samples")
        .arg(&sim)
        .assert()
        .success();
    slotforge()
        .arg("decode")
        .arg(&m)
        .arg(&line)
        .arg("-o")
        .arg(&dec)
        .assert()
        .success();
    let rows = |p: &Path, ch: usize, v: usize, t: usize| -> Vec<(String, String, String)> {
        let text = std::fs::read_to_string(p).unwrap();
        let f = |l: &str| l.split(',').map(str::to_string).collect::<Vec<_>>();
        text.lines()
            .skip(1)
            .map(|l| {
                let r = f(l);
                (r[ch].clone(), r[v].clone(), r[t].clone())
            })
            .collect()
    };
    let (s, d) = (rows(&sim, 2, 3, 1), rows(&dec, 2, 3, 4));
    assert!(d.len() > 20, "{d:?}");
    let mut mcp = 0;
    for r in &d {
        assert!(s.contains(r), "decoded {r:?} is no sample of the run");
        if r.0.starts_with('M') {
            // slots of 6000 cycles at 48 MHz: 293 cycles into one
            let cycles: f64 = r.2.parse::<f64>().unwrap() * 48e6;
            assert_eq!(cycles.round() as u64 % 6000, 293, "{r:?}");
            mcp += 1;
        }
    }
    assert!(mcp > 5);
}

/// The emitted Verilog of the MCP3208 + AD7940 group with the hold-off
/// removed (the AD7940's sequencer and mux load at the slot tick again):
/// its run fails `check`, with and without the model, where the emitted
/// gateware's passes (above).
#[test]
fn a_verilog_mutant_without_the_hold_off_fails_check() {
    if !tools::require_tool("verilator") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let m = dir.path().join("g.toml");
    std::fs::write(&m, grouped()).unwrap();
    let out = dir.path().join("v");
    slotforge()
        .arg("verilog")
        .arg(&m)
        .arg("-o")
        .arg(&out)
        .assert()
        .success();
    let v = std::fs::read_to_string(out.join("slotforge_top.v")).unwrap();
    let cut = [
        (
            "spi_seq1_start2 = hold_off0_fire2;",
            "spi_seq1_start2 = timing_start2;",
        ),
        (
            "branch1_start0 = hold_off0_start0;",
            "branch1_start0 = timing_start0;",
        ),
    ];
    let mut mutant = v.clone();
    for (from, to) in cut {
        assert!(mutant.contains(from), "no `{from}` in the emitted Verilog");
        mutant = mutant.replace(from, to);
    }
    let rtl = dir.path().join("mutant.v");
    std::fs::write(&rtl, mutant).unwrap();
    let vcd = dir.path().join("mutant.vcd");
    slotforge()
        .arg("sim")
        .arg(&m)
        .arg("--rtl")
        .arg(&rtl)
        .args([
            "--backend",
            "verilator",
            "--frames",
            "1",
            "--quiet",
            "--vcd",
        ])
        .arg(&vcd)
        .assert()
        .code(1);
    for extra in [None, Some("--no-model")] {
        let o = slotforge()
            .arg("check")
            .arg(&m)
            .arg(&vcd)
            .args(extra)
            .assert()
            .code(1);
        let text = String::from_utf8_lossy(&o.get_output().stdout).to_string();
        assert!(text.contains("FAIL"), "{extra:?}: {text}");
    }
}
