//! `slotforge build`: the main job writes every artefact and a report whose
//! charts' CSVs hold numbers measured in the run; a failing step is shown
//! as failed (report and exit code) while the other steps still run.

use std::path::{Path, PathBuf};

use assert_cmd::Command;

#[path = "common/tools.rs"]
mod tools;

#[path = "common/browser.rs"]
mod browser;

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
    // a golden for the mix, so that no step asked for is skipped (--strict)
    let gold = d.path().join("golden");
    slotforge()
        .args(["golden", "--backend", "rusthdl", "--update", "--dir"])
        .arg(&gold)
        .arg(tiny())
        .assert()
        .success();
    let out = d.path().join("b");
    let junit = d.path().join("build.xml");
    slotforge()
        .args(["build", "--quiet", "--strict", "--golden"])
        .arg(&gold)
        .arg("-o")
        .arg(&out)
        .arg("--junit")
        .arg(&junit)
        .arg(tiny())
        .assert()
        .success();
    // JUnit: one case per step, the opt-in chart skipped with its reason
    let xml = std::fs::read_to_string(&junit).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let cases: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .collect();
    assert_eq!(cases.len(), 12, "{xml}");
    let speed = cases
        .iter()
        .find(|c| c.attribute("name") == Some("speed"))
        .unwrap();
    assert!(speed.children().any(|n| n.has_tag_name("skipped")), "{xml}");
    // the proof is opt-in too (tests/prove_cli.rs builds with it)
    let prove = cases
        .iter()
        .find(|c| c.attribute("name") == Some("prove"))
        .unwrap();
    assert!(prove.children().any(|n| n.has_tag_name("skipped")), "{xml}");
    assert!(!xml.contains("<failure"), "{xml}");
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
    // the one-cycle strobe is visible in WaveDrom's coarser steps
    let strobe = wd["signal"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == "sample_valid")
        .unwrap();
    assert!(strobe["wave"].as_str().unwrap().contains('1'), "{strobe}");
    // the report in a real browser
    if tools::require_tool("chromium") {
        let r = browser::render(&out);
        assert!(r.images >= 5, "{r:?}");
        assert!(r.links.len() > 20, "every artefact linked: {r:?}");
        assert_eq!(browser::problems(&out, &r), Vec::<String>::new());
    }
}

#[test]
fn unknown_steps_are_refused_before_anything_runs() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("b");
    slotforge()
        .args(["build", "--only", "audit,prove", "-o"])
        .arg(&out)
        .arg(tiny())
        .assert()
        .code(2)
        .stderr(predicates::str::contains(
            "--only: there is no step `prove`; the steps are audit, lut,",
        ));
    assert!(!out.exists());
    slotforge()
        .args(["build", "--junit", "/nonexistent/dir/x.xml", "-o"])
        .arg(&out)
        .arg(tiny())
        .assert()
        .code(2)
        .stderr(predicates::str::contains(
            "the folder /nonexistent/dir does not exist",
        ));
}

#[test]
fn an_interrupted_build_leaves_a_report_of_the_finished_steps() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("b");
    // the first steps take milliseconds; the fault campaign takes seconds
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_slotforge"))
        .args(["build", "--quiet", "--only", "audit,lut,faults", "-o"])
        .arg(&out)
        .arg(tiny())
        .spawn()
        .unwrap();
    let md = out.join("report.md");
    let started = std::time::Instant::now();
    loop {
        let text = std::fs::read_to_string(&md).unwrap_or_default();
        if text.contains("fault campaign) was running") {
            break;
        }
        assert!(
            started.elapsed().as_secs() < 120,
            "no report while the campaign ran: {text}"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    let _ = child.wait();
    let text = std::fs::read_to_string(&md).unwrap();
    assert!(
        text.contains("| audit | ok |") && text.contains("| slot LUT | ok |"),
        "{text}"
    );
    assert!(!text.contains("| fault campaign |"), "{text}");
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("the build was interrupted or is still running"));
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
    // golden --junit: one case per mix, the failure with its first difference
    let xml_path = d.path().join("golden.xml");
    slotforge()
        .args(["golden", "--quiet", "--backend", "rusthdl", "--junit"])
        .arg(&xml_path)
        .arg("--dir")
        .arg(&gold)
        .arg(tiny())
        .assert()
        .code(1);
    let xml = std::fs::read_to_string(&xml_path).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let failure = doc
        .descendants()
        .find(|n| n.has_tag_name("failure"))
        .expect(&xml);
    assert!(
        failure.attribute("message").is_some_and(|m| !m.is_empty()),
        "{xml}"
    );
    assert!(
        failure.text().is_some_and(|t| t.contains("sample")),
        "{xml}"
    );
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

fn skin28() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/skin28.toml")
}

#[test]
#[ignore = "long: make test-long"]
fn a_new_users_mix_builds_by_default_and_its_report_renders() {
    if !tools::require_tool("verilator") || !tools::require_tool("chromium") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("b");
    slotforge()
        .args(["build", "--quiet", "-o"])
        .arg(&out)
        .arg(skin28())
        .assert()
        .success();
    // Figure 7 for this mix's own rates; each spectrum peaks at the alias
    for (rate, alias) in [(5000.0, 2000.0), (500.0, 200.0), (50.0, 20.0)] {
        let spec = csv(&out.join(format!("figure7-{}hz-spectrum.csv", rate as u64)));
        let peak = spec[1..]
            .iter()
            .max_by(|a, b| {
                a[4].parse::<f64>()
                    .unwrap()
                    .total_cmp(&b[4].parse::<f64>().unwrap())
            })
            .unwrap();
        let f: f64 = peak[3].parse().unwrap();
        assert!(
            (f - alias).abs() <= rate / 240.0,
            "{rate} Hz: peak at {f}, want {alias}"
        );
    }
    let r = browser::render(&out);
    assert_eq!(browser::problems(&out, &r), Vec::<String>::new());
}

#[test]
#[ignore = "long: make test-long"]
fn charts_all_compares_every_method_on_the_same_faults() {
    if !tools::require_tool("verilator") || !tools::require_tool("iverilog") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("b");
    slotforge()
        .args([
            "build",
            "--quiet",
            "--charts",
            "all",
            "--only",
            "sim,speed",
            "-o",
        ])
        .arg(&out)
        .arg(tiny())
        .assert()
        .success();
    let sa = csv(&out.join("speed-accuracy.csv"));
    let row = |m: &str| {
        sa.iter()
            .find(|r| r[0] == m)
            .unwrap_or_else(|| panic!("{m}: {sa:?}"))
            .clone()
    };
    for m in [
        "slot model",
        "cycle model",
        "rusthdl",
        "verilator",
        "check",
        "icarus",
    ] {
        let speed: f64 = row(m)[3].parse().unwrap();
        assert!(speed > 0.0 && speed.is_finite(), "{m}");
    }
    // counts, not fractions; the gateware sees every fault that reaches it
    assert_eq!(row("rusthdl")[4], row("rusthdl")[5]);
    assert_eq!(row("slot model")[5], "0");
    assert_eq!(row("verilator")[5], row("check")[5]);
    let slot: f64 = row("slot model")[3].parse().unwrap();
    let rusthdl: f64 = row("rusthdl")[3].parse().unwrap();
    assert!(slot > rusthdl);
}
