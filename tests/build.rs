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
    let out = d.path().join("b");
    slotforge()
        .args(["build", "--quiet", "-o"])
        .arg(&out)
        .arg(tiny())
        .assert()
        .success();
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
    // where scheduling breaks: both outcomes occur over the random mixes
    let sched = csv(&out.join("schedulability.csv"));
    assert!(sched.iter().any(|r| r[3] == "true") && sched.iter().any(|r| r[3] == "false"));
    // comparing the methods is opt-in
    assert!(!out.join("speed-accuracy.csv").exists());
    // the timing diagram's table has every branch's CS edges
    let timing = std::fs::read_to_string(out.join("timing-slice.csv")).unwrap();
    assert!(timing.contains("fast cs_n") && timing.contains("slow cs_n"));
    // Figure 7 uses the mix's own rates: tiny has 4, 2 and 1 kHz
    for r in ["4000", "2000", "1000"] {
        assert!(
            out.join(format!("figure7-{r}hz-spectrum.csv")).is_file(),
            "{r}"
        );
    }
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
        .args(["build", "--quiet", "--only", "golden,faults", "--golden"])
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
