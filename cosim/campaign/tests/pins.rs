//! Pins that exist: a branch without a multiplexer (`mux = "none"`) has no
//! mux pins in any file slotforge writes (Verilog, ports.json, PCF, the
//! waveform and its GTKWave save file), a CNV-started part's lane is named
//! `cnv`, and the save file shows every port the waveform has, the link's
//! included.  On every preset, the shared CNV mix and random mixes drawn
//! with mux-less branches, which also run clean on every engine.

use std::collections::BTreeSet;
use std::path::Path;

use judge::{run_dut, ModelDut, RunOptions};
use lut_gen::Schedule;
use lut_gen::Start;
use lut_gen::{Layout, Role};

use crate::tools;

fn load(path: &Path) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(path).unwrap()).unwrap()
}

/// Random mixes with at least one branch without a mux and one with, each
/// branch converting (what the engines can check end to end), clocked at
/// `clock_hz` (the draw of branches and channels does not depend on it).
fn muxless_random_mixes(count: usize, clock_hz: u64) -> Vec<(u64, String, Schedule)> {
    let shape = campaign::Shape {
        muxless: 2,
        clock_hz,
        ..campaign::Shape::default()
    };
    let mut v = vec![];
    for seed in 0..400u64 {
        let text = campaign::random_mix(seed, &shape);
        let Ok(mix) = lut_gen::parse(Path::new("random.toml"), &text) else {
            continue;
        };
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        let l = Layout::new(&s);
        let converts = (0..s.branches.len()).all(|b| !s.branch_instants_in_frame(b).is_empty());
        if converts && l.muxed.contains(&false) && l.muxed.contains(&true) {
            v.push((seed, text, s));
        }
        if v.len() == count {
            break;
        }
    }
    assert_eq!(
        v.len(),
        count,
        "too few random mixes with a mux-less branch"
    );
    v
}

/// The mixes under test: every preset, the CNV test mix, random mixes.
fn mixes() -> Vec<(String, Schedule)> {
    let mut v: Vec<(String, Schedule)> = testkit::presets::presets(&testkit::root())
        .iter()
        .map(|p| (p.display().to_string(), load(p)))
        .collect();
    v.push(("cnvmix2ms".into(), load(&testkit::mix("cnvmix2ms"))));
    for (seed, _, s) in muxless_random_mixes(3, campaign::Shape::default().clock_hz) {
        v.push((format!("random seed {seed}"), s));
    }
    v
}

/// The width of port `name` in the wrapper's port list (None: no such port).
fn port_width(verilog: &str, name: &str) -> Option<u32> {
    let head = verilog
        .split("module slotforge_top (")
        .nth(1)?
        .split(");")
        .next()?;
    head.lines().find_map(|l| {
        let l = l.trim().trim_end_matches(',');
        if l.rsplit(' ').next() != Some(name) {
            return None;
        }
        Some(match l.split_once('[') {
            Some((_, r)) => r.split(':').next().unwrap().parse::<u32>().unwrap() + 1,
            None => 1,
        })
    })
}

#[test]
fn a_branch_without_a_mux_has_no_mux_pins() {
    let mut muxless_seen = 0;
    for (name, s) in mixes() {
        let l = Layout::new(&s);
        let e = hdl::emit(&s, None).unwrap();
        let (sel, en) = (l.width(Role::MuxSel), l.width(Role::MuxEn));
        let muxed = l.muxed.iter().filter(|&&m| m).count() as u32;
        assert_eq!(sel, 3 * muxed, "{name}");
        let devices: u32 = (0..l.branches)
            .filter(|&b| l.muxed[b])
            .map(|b| s.branches[b].mux_devices.max(1))
            .sum();
        assert_eq!(en, devices, "{name}");
        let v = e.verilog();
        assert_eq!(port_width(v, "mux_sel"), (sel > 0).then_some(sel), "{name}");
        assert_eq!(port_width(v, "mux_en"), (en > 0).then_some(en), "{name}");
        // ports.json: a branch's mux keys exactly when it has a mux
        let j: serde_json::Value = serde_json::from_str(e.ports_json()).unwrap();
        for (b, br) in j["branches"].as_array().unwrap().iter().enumerate() {
            assert_eq!(br.get("mux_sel").is_some(), l.muxed[b], "{name} branch {b}");
            assert_eq!(br.get("mux_en").is_some(), l.muxed[b], "{name} branch {b}");
            let cnv = l.starts[b] == Start::Cnv;
            assert_eq!(br.get("cnv").is_some(), cnv, "{name} branch {b}");
            assert_eq!(br.get("cs_n").is_some(), !cnv, "{name} branch {b}");
            muxless_seen += !l.muxed[b] as usize;
        }
        let listed: Vec<&str> = j["ports"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["name"].as_str().unwrap())
            .collect();
        assert_eq!(listed.contains(&"mux_sel"), sel > 0, "{name}");
        // the PCF template and the XDC: one row per port bit
        let pcf = e.file("slotforge.pcf").unwrap();
        let xdc = e.file("slotforge.xdc").unwrap();
        for (port, w) in [("mux_sel", sel), ("mux_en", en)] {
            let rows = |t: &str, at: &str| {
                t.lines()
                    .filter(|r| r.contains(&format!("{at}{port}")))
                    .count() as u32
            };
            assert_eq!(rows(pcf, "set_io "), w, "{name}: {port} in the PCF");
            assert_eq!(rows(xdc, "get_ports {"), w, "{name}: {port} in the XDC");
        }
    }
    assert!(
        muxless_seen >= 5,
        "mux-less branches tested: {muxless_seen}"
    );
}

/// The VCD header's variables as `scope.name` (ranges dropped).
fn vcd_vars(vcd: &str) -> BTreeSet<String> {
    let mut scopes: Vec<&str> = vec![];
    let mut v = BTreeSet::new();
    for line in vcd
        .lines()
        .take_while(|l| !l.starts_with("$enddefinitions"))
    {
        let f: Vec<&str> = line.split_whitespace().collect();
        match f.first() {
            Some(&"$scope") => scopes.push(f[2]),
            Some(&"$upscope") => {
                scopes.pop();
            }
            Some(&"$var") => {
                v.insert(format!("{}.{}", scopes.join("."), f[4]));
            }
            _ => {}
        }
    }
    v
}

/// The signals a GTKWave save file shows, as `scope.name` (ranges dropped).
fn gtkw_signals(gtkw: &str) -> BTreeSet<String> {
    gtkw.lines()
        .filter(|l| l.starts_with("slotforge_top."))
        .map(|l| l.split('[').next().unwrap().to_string())
        .collect()
}

/// The save file shows every port and branch lane the VCD has, and
/// nothing else; a mux-less branch's group has no mux lane; a CNV lane is
/// `cnv`.  On every preset (the link presets among them), the CNV mix and
/// random mux-less mixes.
#[test]
fn the_save_file_shows_every_port_the_waveform_has() {
    let dir = tempfile::tempdir().unwrap();
    let mut link_mixes = 0;
    for (i, (name, s)) in mixes().into_iter().enumerate() {
        let l = Layout::new(&s);
        let vcd = dir.path().join(format!("w{i}.vcd"));
        let f = s.grid.frame_cycles;
        let mut dut = ModelDut::new(&s);
        // only the waveform's header matters here (an AXI4-Stream mix's
        // verdict needs a slave driving tready, which this run has not)
        let opts = RunOptions::default();
        judge::write_run(&vcd, &s, &mut dut, 1, &opts, (0, f.min(5000))).unwrap();
        let gtkw = vcd.with_extension("gtkw");
        judge::write_gtkw(&gtkw, &vcd, &s).unwrap();
        let (vcd_text, gtkw_text) = (
            std::fs::read_to_string(&vcd).unwrap(),
            std::fs::read_to_string(&gtkw).unwrap(),
        );
        // the lane ports (adc_cs_n, ..., mux_en) are shown per branch, in
        // the branch groups checked below; every other variable as it is
        let mut want = vcd_vars(&vcd_text);
        for r in Role::LANES.into_iter().filter(|&r| l.has(r)) {
            assert!(
                want.remove(&format!("slotforge_top.{}", r.name())),
                "{name}"
            );
        }
        assert_eq!(gtkw_signals(&gtkw_text), want, "{name}");
        for p in l.link_ports() {
            assert!(
                gtkw_text.contains(&format!("slotforge_top.{}", p.name)),
                "{name}"
            );
        }
        link_mixes += l.link as usize;
        for (b, br) in s.branches.iter().enumerate() {
            let sc = format!("slotforge_top.branch_{}.", br.name);
            let has = |k: &str| gtkw_text.contains(&format!("{sc}{k}"));
            assert_eq!(has("mux_sel"), l.muxed[b], "{name} {}", br.name);
            assert_eq!(has("mux_en"), l.muxed[b], "{name} {}", br.name);
            let cnv = l.starts[b] == Start::Cnv;
            assert_eq!((has("cnv"), has("cs_n")), (cnv, !cnv), "{name} {}", br.name);
            for r in l.lanes(b) {
                assert!(has(l.lane_key(r, b)), "{name} {}: {}", br.name, r.name());
            }
        }
    }
    assert!(link_mixes >= 2, "the UART and AXI4-Stream presets");
}

/// Random mixes with mux-less branches run clean on every engine: the
/// judge reads the pins of tops without those mux lanes. The engines' time
/// is the mixes' cycles (Icarus, the slowest engine, was half of it): here
/// the draws run at 12 MHz, a quarter of the generator's 48 MHz and of
/// its cycles (a seed draws the same branches and channels at any clock,
/// and the pins a mux-less branch has, or lacks, do not depend on it), and
/// Icarus runs the first mix; `make test-long` runs them at 48 MHz, Icarus
/// on each.
#[test]
fn random_muxless_mixes_run_clean_on_every_engine() {
    muxless_mixes_run_clean(1, 12_000_000);
}

#[test]
#[ignore = "make test-long: at 48 MHz, Icarus on every random mux-less mix, not only the first"]
fn random_muxless_mixes_run_clean_on_every_engine_icarus_on_each() {
    muxless_mixes_run_clean(usize::MAX, campaign::Shape::default().clock_hz);
}

/// Two random mux-less mixes at `clock_hz` on the model, RustHDL and
/// Verilator, and the first `on_icarus` of them on Icarus too.
fn muxless_mixes_run_clean(on_icarus: usize, clock_hz: u64) {
    use engines::{Backend, SimOptions};
    let tools_there = tools::require_tools(&["verilator", "g++", "iverilog", "vvp"]);
    let mixes = muxless_random_mixes(2, clock_hz);
    for (i, (seed, text, s)) in mixes.into_iter().enumerate() {
        let r = run_dut(
            &s,
            &mut ModelDut::new(&s),
            2,
            &RunOptions::default(),
            "model",
            None,
        );
        assert!(r.ok, "seed {seed}:\n{text}\n{}", r.summary());
        let mut backends = vec![Backend::RustHdl];
        if tools_there {
            backends.push(Backend::Verilator);
            if i < on_icarus {
                backends.push(Backend::Icarus);
            }
        }
        for be in backends {
            let v = engines::run(&s, be, 2, &SimOptions::default()).unwrap();
            assert!(v.ok, "seed {seed} {}:\n{text}\n{}", be.name(), v.summary());
            assert_eq!(
                v.samples,
                2 * s.samples_per_frame() - s.startup_skips(),
                "seed {seed} {}",
                be.name()
            );
        }
    }
}
