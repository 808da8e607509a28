//! `slotforge golden`: every preset matches its golden on a fresh clone, a
//! golden that differs is reported with its first difference and a count
//! (exit 1), bad input exits 2, `--update` rewrites and says what changed;
//! and every VCD slotforge writes has exact times (an interval read off the
//! file equals the exact interval).

use std::path::{Path, PathBuf};

use predicates::prelude::*;

use crate::tools;

use crate::common_cli::{root, slotforge};
use crate::common_presets;

fn presets() -> Vec<PathBuf> {
    common_presets::presets(&root())
}

/// Copies `golden/<name>` into a temporary golden root.
fn golden_copy(name: &str) -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    let to = d.path().join(name);
    std::fs::create_dir_all(&to).unwrap();
    for e in std::fs::read_dir(root().join("golden").join(name)).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
    }
    d
}

/// Every preset against its golden on rusthdl (`make golden` runs them all on
/// Verilator in `make test`; `backends.rs` runs rusthdl against the model).
#[test]
#[ignore = "long: make test-long"]
fn every_preset_has_a_golden_and_matches_it_in_process() {
    goldens_match_in_process(&presets());
}

/// The reference mix (event log and Figure 6 windows) on rusthdl.
#[test]
fn reference_golden_matches_in_process() {
    goldens_match_in_process(&[root().join("mixes/eskin34.toml")]);
}

fn goldens_match_in_process(mixes: &[PathBuf]) {
    for mix in mixes {
        let name = mix.file_stem().unwrap().to_str().unwrap().to_string();
        assert!(
            root()
                .join("golden")
                .join(&name)
                .join("events.log")
                .is_file(),
            "{name} has no golden"
        );
        slotforge()
            .current_dir(root())
            .args(["golden", "--backend", "rusthdl"])
            .arg(mix)
            .assert()
            .success()
            .stdout(predicate::str::contains("same as"));
    }
}

/// The mix with modes keeps a golden that switches: its recorded scene
/// touches a watched taxel, the log holds the switch to `contact` two frames
/// after the touch (docs/timing.md, the mode of the frame after next), and
/// the model's replay of the recorded scene matches it.
#[test]
fn the_adaptive_golden_holds_a_touch_and_its_switch() {
    let log = std::fs::read_to_string(root().join("golden/eskin34-adaptive/events.log")).unwrap();
    assert!(
        log.contains("# scene --stimulus: touch:"),
        "no touch recorded"
    );
    let switches: Vec<(u64, &str)> = log
        .lines()
        .filter(|l| !l.starts_with('#'))
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            (w.get(2) == Some(&"modes") && w.get(3) == Some(&"mode"))
                .then(|| (w[0].parse().unwrap(), w[4]))
        })
        .collect();
    let frame = 480_000;
    assert_eq!(switches, [(0, "0"), (2 * frame, "1")], "the modes lines");
    slotforge()
        .current_dir(root())
        .args([
            "golden",
            "--backend",
            "model",
            "mixes/eskin34-adaptive.toml",
        ])
        .assert()
        .success()
        .stdout(predicate::str::contains("same as"));
}

#[test]
fn reference_golden_keeps_figure_6_windows() {
    let g = root().join("golden/eskin34");
    for w in ["fig6-0-1ms", "fig6-3-4ms", "fig6-8-9ms", "fig6-9-10ms"] {
        assert!(g.join(format!("{w}.vcd")).is_file(), "{w}.vcd");
        assert!(g.join(format!("{w}.gtkw")).is_file(), "{w}.gtkw");
    }
    // the window 3-4 ms of the reference mix starts 3 ms after cycle 0 (plus
    // the reset) and lasts exactly 1 ms
    let text = std::fs::read_to_string(g.join("fig6-3-4ms.vcd")).unwrap();
    let times: Vec<u64> = text
        .lines()
        .filter_map(|l| l.strip_prefix('#'))
        .map(|t| t.parse().unwrap())
        .collect();
    let (first, last) = (times[0], *times.last().unwrap());
    assert!((3_000_000_000..3_010_000_000).contains(&first), "{first}");
    // from the falling edge before the first cycle to the last rising edge
    assert!(
        (1_000_000_000 - 10_417..=1_000_000_000).contains(&(last - first)),
        "{}",
        last - first
    );
}

#[test]
fn a_changed_golden_is_reported_with_its_first_difference() {
    let d = golden_copy("softslip1k");
    let log = d.path().join("softslip1k/events.log");
    let text = std::fs::read_to_string(&log).unwrap();
    // change the value of the first sample in the log
    let (i, line) = text
        .lines()
        .enumerate()
        .find(|(_, l)| l.contains(" sample "))
        .unwrap();
    let cycle: u64 = line.split_whitespace().next().unwrap().parse().unwrap();
    let changed: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(j, l)| {
            if j == i {
                let mut f: Vec<&str> = l.split_whitespace().collect();
                f[4] = "0x3fff";
                f.join(" ")
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(&log, changed.join("\n") + "\n").unwrap();
    slotforge()
        .args(["golden", "--backend", "rusthdl", "--dir"])
        .arg(d.path())
        .arg(root().join("mixes/softslip1k.toml"))
        .assert()
        .code(1)
        .stdout(predicate::str::contains("1 event(s) differ"))
        .stdout(predicate::str::contains(format!("first: cycle {cycle} (")))
        .stdout(predicate::str::contains("expected 0x3fff"));
    // --update puts it back and says what changed
    slotforge()
        .args(["golden", "--backend", "rusthdl", "--update", "--dir"])
        .arg(d.path())
        .arg(root().join("mixes/softslip1k.toml"))
        .assert()
        .success()
        .stdout(predicate::str::contains("1 event(s) changed"));
    assert_eq!(
        std::fs::read_to_string(&log).unwrap(),
        std::fs::read_to_string(root().join("golden/softslip1k/events.log")).unwrap()
    );
}

#[test]
fn bad_golden_input_exits_2() {
    let d = tempfile::tempdir().unwrap();
    // no golden for this mix in an empty root
    slotforge()
        .args(["golden", "--backend", "rusthdl", "--dir"])
        .arg(d.path())
        .arg(root().join("mixes/softslip1k.toml"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--update"));
    // a truncated log names the file
    let g = golden_copy("softslip1k");
    let log = g.path().join("softslip1k/events.log");
    let text = std::fs::read_to_string(&log).unwrap();
    std::fs::write(&log, &text[..text.len() / 2]).unwrap();
    slotforge()
        .args(["golden", "--backend", "rusthdl", "--dir"])
        .arg(g.path())
        .arg(root().join("mixes/softslip1k.toml"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("events.log"));
    // a bad manifest names its file and line
    let g = golden_copy("eskin34");
    std::fs::write(
        g.path().join("eskin34/golden.toml"),
        "frames = 1\nwindows = 3\n",
    )
    .unwrap();
    slotforge()
        .args(["golden", "--backend", "rusthdl", "--dir"])
        .arg(g.path())
        .arg(root().join("mixes/eskin34.toml"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("golden.toml:2"));
}

/// Times of `var`'s changes to `value` in a VCD written by slotforge.
fn change_times(vcd: &Path, scope: &str, var: &str, value: char) -> Vec<u64> {
    let text = std::fs::read_to_string(vcd).unwrap();
    let mut scopes = Vec::new();
    let mut id = None;
    for l in text.lines() {
        let f: Vec<&str> = l.split_whitespace().collect();
        match f.as_slice() {
            ["$scope", _, name, "$end"] => scopes.push(*name),
            ["$upscope", "$end"] => {
                scopes.pop();
            }
            ["$var", _, "1", code, name, "$end"]
                if scopes.last() == Some(&scope) && *name == var =>
            {
                id = Some(code.to_string())
            }
            _ => {}
        }
    }
    let id = id.unwrap_or_else(|| panic!("{scope}.{var} not in {}", vcd.display()));
    // changes to `value` from another value (not the initial dump)
    let mut t = 0;
    let mut last = None;
    let mut out = Vec::new();
    for l in text.lines() {
        if let Some(x) = l.strip_prefix('#') {
            t = x.parse().unwrap();
        } else if l.len() > 1 && l[1..] == id {
            let v = l.chars().next();
            if v == Some(value) && last.is_some_and(|p| p != value) {
                out.push(t);
            }
            last = v;
        }
    }
    out
}

/// slotforge's own VCD writer (any back end but icarus).
#[test]
fn vcd_times_are_exact_in_slotforges_writer() {
    vcd_times_are_exact(&["rusthdl"]);
}

/// Icarus writes its own VCD from the testbench's clock (a whole frame of
/// eskin34 in Icarus: `make test-long`).
#[test]
#[ignore = "long: make test-long"]
fn vcd_times_are_exact_in_icarus() {
    if tools::require_tool("iverilog") {
        vcd_times_are_exact(&["icarus"]);
    }
}

fn vcd_times_are_exact(backends: &[&str]) {
    // eskin34's `standard` branch converts its 30 channels at 1 kHz, one per
    // 1600-cycle slot: the same channel's CS falls are 48 000 cycles = 1 ms
    // apart, exactly 10^9 ps, although one slot (33 333.33 ns) is not a
    // whole number of picoseconds.
    let d = tempfile::tempdir().unwrap();
    for &backend in backends {
        let vcd = d.path().join(format!("{backend}.vcd"));
        slotforge()
            .arg("sim")
            .arg(root().join("mixes/eskin34.toml"))
            .args([
                "--backend",
                backend,
                "--frames",
                "1",
                "--from",
                "2ms",
                "--to",
                "5ms",
                "--vcd",
            ])
            .arg(&vcd)
            .assert()
            .success();
        let scope = if backend == "icarus" {
            "tb"
        } else {
            "branch_standard"
        };
        let falls = if backend == "icarus" {
            // Icarus's own VCD: the branch is bit 0 of adc_cs_n (a vector)
            let text = std::fs::read_to_string(&vcd).unwrap();
            let id = text
                .lines()
                .find(|l| l.contains(" adc_cs_n ") && l.starts_with("$var"))
                .unwrap()
                .split_whitespace()
                .nth(3)
                .unwrap()
                .to_string();
            let mut t = 0u64;
            let mut last = None;
            let mut v = Vec::new();
            for l in text.lines() {
                if let Some(x) = l.strip_prefix('#') {
                    t = x.parse().unwrap();
                } else if let Some(rest) = l.strip_prefix('b') {
                    let (val, code) = rest.split_once(' ').unwrap();
                    if code == id {
                        // branch 0 (`standard`) is bit 0: the last digit
                        let low = val.ends_with('0');
                        if last == Some(true) && low {
                            v.push(t);
                        }
                        last = Some(!low);
                    }
                }
            }
            let _ = scope;
            v
        } else {
            change_times(&vcd, scope, "cs_n", '0')
        };
        assert!(falls.len() > 60, "{backend}: {} CS falls", falls.len());
        for w in falls.windows(31) {
            assert_eq!(w[30] - w[0], 1_000_000_000, "{backend}: 1 ms apart");
        }
        // 1600 cycles = 33 333 333.33 ps: rounded once per edge, never drifting
        for w in falls.windows(2) {
            assert!(
                (33_333_333..=33_333_334).contains(&(w[1] - w[0])),
                "{backend}: {}",
                w[1] - w[0]
            );
        }
        // the window starts 2 ms after cycle 0 (plus the reset)
        assert!(falls[0] >= 2_000_000_000, "{backend}: {}", falls[0]);
    }
}

/// The tiny mix on the three engines (a 4,000-cycle frame; every preset,
/// the smallest a 120,000-cycle frame: `make test-long`); the goldens tie
/// rusthdl and Verilator to one log for every preset already.
#[test]
fn rusthdl_verilator_and_icarus_give_identical_event_logs() {
    identical_event_logs(&[root().join("testkit/mixes/tiny.toml")]);
}

#[test]
#[ignore = "long: make test-long"]
fn rusthdl_verilator_and_icarus_give_identical_event_logs_on_every_preset() {
    identical_event_logs(&presets());
}

fn identical_event_logs(mixes: &[PathBuf]) {
    use judge::{compare_events as compare, EventLog, Trace};
    let mut backends = vec![engines::Backend::RustHdl];
    if tools::require_tool("verilator") && tools::require_tool("g++") {
        backends.push(engines::Backend::Verilator);
    }
    if tools::require_tool("iverilog") {
        backends.push(engines::Backend::Icarus);
    }
    for mix in mixes {
        let s = lut_gen::synthesize(&lut_gen::load(mix).unwrap()).unwrap();
        let f = s.grid.frame_cycles;
        let logs: Vec<(engines::Backend, EventLog)> = backends
            .iter()
            .map(|&b| {
                let mut t = Trace::default();
                let r =
                    engines::run_traced(&s, b, 1, &engines::SimOptions::default(), Some(&mut t))
                        .unwrap();
                assert!(r.ok, "{} on {}: {}", s.mix.name, b.name(), r.summary());
                (b, EventLog::from_trace(&s, &t, f))
            })
            .collect();
        let (b0, first) = &logs[0];
        assert_eq!(first.cycles, f);
        assert!(first.events.iter().any(|e| e.scope == "sample"));
        for (b, log) in &logs[1..] {
            let c = compare(first, log, 1);
            assert!(
                c.same(),
                "{}: {} and {} differ in {} events, first {:?}",
                s.mix.name,
                b0.name(),
                b.name(),
                c.count,
                c.first
            );
            // identical, not merely equal on the compared fields
            assert_eq!(first, log, "{}: {} vs {}", s.mix.name, b0.name(), b.name());
        }
    }
}
