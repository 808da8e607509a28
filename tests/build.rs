//! `slotforge build`: the main job writes every artefact and a report whose
//! charts' CSVs hold numbers measured in the run; a failing step is shown
//! as failed (report and exit code) while the other steps still run.

use std::path::{Path, PathBuf};

use assert_cmd::Command;

#[path = "common/tools.rs"]
mod tools;

fn slotforge() -> Command {
    Command::cargo_bin("slotforge").unwrap()
}

fn tiny() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("cosim/tests/data/tiny.toml")
}

fn csv(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split(',').map(|f| f.to_string()).collect())
        .collect()
}

#[test]
fn build_writes_the_artefacts_and_a_self_contained_report() {
    if !tools::require_tool("verilator") || !tools::require_tool("iverilog") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    // a golden for the mix, so that no step is skipped (--strict)
    let gold = d.path().join("golden");
    slotforge()
        .args(["golden", "--backend", "rusthdl", "--update", "--dir"])
        .arg(&gold)
        .arg(tiny())
        .assert()
        .success();
    let out = d.path().join("b");
    slotforge()
        .args(["build", "--quiet", "--strict", "--golden"])
        .arg(&gold)
        .arg("-o")
        .arg(&out)
        .arg(tiny())
        .assert()
        .success()
        .stdout(predicates::str::contains("0 failed, 0 skipped"));
    for f in [
        "audit.txt",
        "audit.json",
        "lut/slots.hex",
        "verilog/slotforge_top.v",
        "verilog/ports.json",
        "verilog/slotforge.pcf",
        "sim.json",
        "frame0.vcd",
        "frame0.gtkw",
        "faults.json",
        "conversion.wavedrom.json",
        "report.html",
        "report.md",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.matches("<svg").count() >= 3, "charts inline");
    assert!(
        !html.contains("<script") && !html.contains("src=\"http") && !html.contains("href=\"http")
    );
    // the speed/accuracy chart is the fault campaign's matrix: one point per
    // detector that ran, its share exactly the column of faults.json
    let sa = csv(&out.join("speed-accuracy.csv"));
    let faults: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("faults.json")).unwrap()).unwrap();
    let mut drawn = 0;
    for col in faults["columns"].as_array().unwrap() {
        let d = col["detector"].as_str().unwrap();
        let row = sa.iter().find(|r| r[0] == d);
        if !col["not_run"].is_null() {
            assert!(row.is_none(), "{d} did not run but is drawn");
            continue;
        }
        let r = row.unwrap_or_else(|| panic!("{d}: {sa:?}"));
        assert_eq!(r[4], col["detected"].to_string(), "{d}");
        assert_eq!(r[5], col["injected"].to_string(), "{d}");
        let share = col["detected"].as_f64().unwrap() / col["injected"].as_f64().unwrap();
        assert_eq!(r[6], format!("{share:.3}"), "{d}");
        let speed: f64 = r[3].parse().unwrap();
        assert!(speed > 0.0 && speed.is_finite(), "{r:?}");
        drawn += 1;
    }
    assert!(drawn >= 2, "{sa:?}");
    // where scheduling breaks: both outcomes occur over the random mixes
    let sched = csv(&out.join("schedulability.csv"));
    assert!(sched.iter().any(|r| r[3] == "true") && sched.iter().any(|r| r[3] == "false"));
    // the timing diagram's table has every branch's CS edges
    let timing = std::fs::read_to_string(out.join("timing-slice.csv")).unwrap();
    assert!(timing.contains("fast cs_n") && timing.contains("slow cs_n"));
    let wd: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("conversion.wavedrom.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(wd["signal"][0]["name"], "cs_n");
}

#[test]
fn a_failing_step_fails_the_build_and_the_others_still_run() {
    if !tools::require_tool("verilator") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    // a golden that cannot match: recorded, then corrupted
    let gold = d.path().join("golden");
    slotforge()
        .args(["golden", "--backend", "rusthdl", "--update", "--dir"])
        .arg(&gold)
        .arg(tiny())
        .assert()
        .success();
    let log = gold.join("tiny/events.log");
    let text = std::fs::read_to_string(&log).unwrap();
    std::fs::write(&log, text.replacen(" sample ", " sample_x ", 1)).unwrap();
    let out = d.path().join("b");
    slotforge()
        .args(["build", "--quiet", "--golden"])
        .arg(&gold)
        .arg("-o")
        .arg(&out)
        .arg(tiny())
        .assert()
        .code(1);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("| golden comparison | FAILED |"), "{md}");
    assert!(md.contains("| fault campaign | ok |"), "{md}");
    assert!(md.contains("## Steps: FAILED"));
}
