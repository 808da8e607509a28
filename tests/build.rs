//! `slotforge build`: the main job writes every artefact and a report whose
//! charts' CSVs hold numbers measured in the run; a failing step is shown
//! as failed (report and exit code) while the other steps still run.

use std::path::{Path, PathBuf};

use crate::common_cli::{column, record_golden, slotforge, tiny};
use crate::tools;

#[path = "common/browser.rs"]
mod browser;

fn csv(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split(',').map(|f| f.to_string()).collect())
        .collect()
}

/// The engines of `methods.json` that ran faults, as (method, faults run,
/// seconds, caught); the report's methods table holds the same figures.
fn methods_rows(out: &Path) -> Vec<(String, u64, f64, u64, u64)> {
    let text = std::fs::read_to_string(out.join("methods.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let mut rows = Vec::new();
    for m in v.as_array().unwrap() {
        let (runs, caught) = (
            m["faults_run"].as_u64().unwrap(),
            m["caught"].as_u64().unwrap(),
        );
        let name = m["engine"].as_str().unwrap();
        let secs = m["seconds"].as_f64().unwrap();
        let row = format!("| {name} | {runs} | {caught} |");
        assert!(md.contains(&row), "{row} not in report.md's methods table");
        assert!(md.contains(&format!("| {secs:.3} | {:.3} |", secs / runs.max(1) as f64)));
        if m["not_run"].is_null() && runs > 0 {
            rows.push((format!("engine: {name}"), runs, secs, caught, runs));
        }
    }
    rows
}

/// The rows of `speed-accuracy.csv` are the columns (detectors that ran)
/// and the engines of `faults.json` of the same build: the same names,
/// counts and timings, in that order.
fn assert_chart_is_the_matrix(out: &Path) {
    let fj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("faults.json")).unwrap()).unwrap();
    let mut want: Vec<(String, u64, f64, u64, u64)> = Vec::new();
    for c in fj["columns"].as_array().unwrap() {
        if c["not_run"].is_null() {
            want.push((
                c["detector"].as_str().unwrap().to_string(),
                c["runs"].as_u64().unwrap(),
                c["seconds"].as_f64().unwrap(),
                c["detected"].as_u64().unwrap(),
                c["injected"].as_u64().unwrap(),
            ));
        }
    }
    for e in fj["engines"].as_array().unwrap() {
        want.push((
            format!("engine: {}", e["engine"].as_str().unwrap()),
            1,
            e["seconds"].as_f64().unwrap(),
            e["detected"].as_u64().unwrap(),
            e["injected"].as_u64().unwrap(),
        ));
    }
    let sa = csv(&out.join("speed-accuracy.csv"));
    assert_eq!(sa[0][0], "method");
    let got: Vec<(String, u64, f64, u64, u64)> = sa[1..]
        .iter()
        .map(|r| {
            (
                r[0].clone(),
                r[1].parse().unwrap(),
                r[2].parse().unwrap(),
                r[4].parse().unwrap(),
                r[5].parse().unwrap(),
            )
        })
        .collect();
    // the matrix's rows first, then the engines that ran the sample of the
    // quick campaign (methods.json: the same figures), then what the build
    // ran clean beside the campaign (cost only: no fault went through it)
    let sample = methods_rows(out);
    let at = want.len() + sample.len();
    assert!(got.len() >= at, "{got:?} vs {want:?} and {sample:?}");
    for (g, m) in got[want.len()..at].iter().zip(&sample) {
        assert_eq!((&g.0, g.1, g.3, g.4), (&m.0, m.1, m.3, m.1), "{g:?}");
        assert!(g.1 > 0, "{g:?}");
        assert!((g.2 - m.2).abs() < 1e-5, "{g:?} vs {m:?}");
    }
    for g in &got[at..] {
        assert!(g.0.starts_with("engine: ") || g.0 == "prove", "{g:?}");
        assert!(!sample.iter().any(|m| m.0 == g.0), "{g:?} twice");
        assert_eq!((g.1, g.3, g.4), (1, 0, 0), "{g:?}");
        assert!(g.2 > 0.0, "{g:?}");
    }
    want.extend(sample);
    for (g, w) in got.iter().zip(&want) {
        assert_eq!((&g.0, g.1, g.3, g.4), (&w.0, w.1, w.3, w.4));
        assert!((g.2 - w.2).abs() < 1e-5, "{g:?} vs {w:?}");
    }
    // the model comparison is there, with counts from the matrix
    assert!(got.iter().any(|g| g.0 == "model" && g.4 > 0), "{got:?}");
    let svg = std::fs::read_to_string(out.join("speed-accuracy.svg")).unwrap();
    assert!(svg.contains("real time"), "{svg}");
    // every method is named in a point's label with its counts; methods
    // at one point (same cost, same count) share a label naming each
    let texts: Vec<&str> = svg
        .split("</text>")
        .filter_map(|t| t.rsplit_once('>').map(|x| x.1.trim()))
        .collect();
    for w in &want {
        let counts = format!("({} of {})", w.3, w.4);
        assert!(
            texts
                .iter()
                .any(|t| t.ends_with(&counts) && t.split(" and ").any(|n| n.starts_with(&w.0))),
            "{}: no label in the chart: {texts:?}",
            w.0
        );
    }
    let at = |name: &str| want.iter().find(|w| w.0 == name).map(|w| (w.2, w.3, w.4));
    if let (Some(m), Some(e)) = (at("model"), at("engine: cycle model")) {
        if m == e {
            // one label names both (and any other method at that point:
            // "model and invariants and engine: cycle model (23 of 23)")
            let counts = format!(" ({} of {})", m.1, m.2);
            let merged = texts.iter().any(|t| {
                t.strip_suffix(&counts).is_some_and(|names| {
                    let names: Vec<&str> = names.split(" and ").collect();
                    names.contains(&"model") && names.contains(&"engine: cycle model")
                })
            });
            assert!(merged, "{texts:?}");
        }
    }
}

#[test]
fn build_writes_the_artefacts_and_a_self_contained_report() {
    if !tools::require_tool("verilator") || !tools::require_tool("iverilog") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    // a golden for the mix, so that no step asked for is skipped (--strict)
    let gold = d.path().join("golden");
    record_golden(&gold);
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
    // JUnit: one case per step, none skipped (--strict), none failed
    let xml = std::fs::read_to_string(&junit).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let cases: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .collect();
    assert_eq!(cases.len(), 13, "{xml}");
    // every step runs, the proof too, and the first screen says so
    assert_eq!(xml.matches("<skipped").count(), 0, "{xml}");
    assert!(!xml.contains("<failure"), "{xml}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("yes (proved in this build)"), "{md}");
    for f in [
        "audit.txt",
        "audit.json",
        "lut/slots.hex",
        "verilog/slotforge_top.v",
        "verilog/ports.json",
        "verilog/slotforge.pcf",
        "sim.json",
        "netlist.json",
        "verilog/slotforge_top.core",
        "frame0.vcd",
        "frame0.gtkw",
        "frame0.channels.txt",
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
    assert!(
        sched.iter().any(|r| r[3] == "scheduled") && sched.iter().any(|r| r[3] == "infeasible")
    );
    // the default fault campaign is the quick one (every class at one site)
    let faults = |dir: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("faults.json")).unwrap()).unwrap()
    };
    let quick = faults(&out);
    assert_eq!(
        quick["sites"].as_array().unwrap().len(),
        1,
        "{}",
        quick["sites"]
    );
    assert!(
        quick["injected"].as_u64().unwrap() >= 14,
        "every class once"
    );
    // judged by the model and the invariants; sigrok's decodes are the
    // full campaign's, and the page says so
    let sigrok = column(&quick, "sigrok");
    assert!(
        sigrok["not_run"]
            .as_str()
            .unwrap()
            .contains("quick campaign"),
        "{sigrok}"
    );
    assert_eq!(column(&quick, "model")["detected"], quick["injected"]);
    // the speed-against-accuracy chart is the fault matrix of this run
    assert_chart_is_the_matrix(&out);
    // and names every engine the default build ran, with its cost; the
    // report says what --charts all adds
    let sa = csv(&out.join("speed-accuracy.csv"));
    for m in [
        "engine: cycle model",
        "engine: verilator",
        "engine: rusthdl",
    ] {
        assert!(sa.iter().any(|r| r[0] == m), "{m}: {sa:?}");
        assert!(html.contains(m), "{m} not in the report");
    }
    // the gateware's engines ran faults, each with its catch on the chart
    for (name, runs, ..) in methods_rows(&out) {
        assert!(runs > 0, "{name}");
        assert!(html.contains(&format!("<code>{name}</code> ran {runs} of them")));
    }
    assert_eq!(methods_rows(&out).len(), 2, "rusthdl and verilator");
    assert!(html.contains("adds") && html.contains("Icarus") && html.contains("sigrok"));
    assert_reads_like_a_datasheet(&tiny(), &out);
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
        .args(["build", "--only", "audit,proof", "-o"])
        .arg(&out)
        .arg(tiny())
        .assert()
        .code(2)
        .stderr(predicates::str::contains(
            "--only: there is no step `proof`; the steps are audit, lut,",
        ));
    assert!(!out.exists());
    slotforge()
        .args(["build", "--only", "speed", "-o"])
        .arg(&out)
        .arg(tiny())
        .assert()
        .code(2)
        .stderr(predicates::str::contains("--only faults,speed"));
    assert!(!out.exists());
    slotforge()
        .args(["build", "--junit", "/nonexistent/dir/x.xml", "-o"])
        .arg(&out)
        .arg(tiny())
        .assert()
        .code(2)
        .stderr(predicates::str::contains(
            "--junit /nonexistent/dir/x.xml: no such folder",
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
    record_golden(&gold);
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
    // --only faults asks for the full campaign: every site
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("faults.json")).unwrap()).unwrap();
    assert!(v["sites"].as_array().unwrap().len() > 1, "{}", v["sites"]);
    let sigrok = v["columns"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["detector"] == "sigrok")
        .unwrap();
    let why = sigrok["not_run"].as_str().unwrap_or("");
    assert!(
        !why.contains("quick"),
        "the full campaign runs sigrok: {why}"
    );
}

/// An engine of the speed chart's sample that misses faults is data: its
/// points and the methods table show the misses, and the chart's step stays
/// ok (the fault campaign is what gates the build; here it fails, as it
/// must with the checker switched off).
#[test]
fn an_engine_that_misses_leaves_the_chart_green() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("b");
    slotforge()
        .env("SLOTFORGE_TEST_DISABLE_DETECTOR", "model,invariants,sigrok")
        .args(["build", "--quiet", "--only", "faults,speed", "-o"])
        .arg(&out)
        .arg(tiny())
        .assert()
        .code(1);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("| fault campaign | FAILED |"), "{md}");
    assert!(
        md.contains("| chart: speed against accuracy | ok |"),
        "{md}"
    );
    let rows = methods_rows(&out);
    assert!(!rows.is_empty());
    for (name, runs, _, caught, _) in &rows {
        assert!(*runs > 0 && *caught == 0, "{name}: {rows:?}");
    }
    assert_chart_is_the_matrix(&out);
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
    // a new user's default build, not CI's (under CI=true the missing
    // golden of a mix nobody recorded is a failure by design)
    slotforge()
        .env_remove("CI")
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
    // the chart's points are the campaign's and the sample's figures, and
    // every gateware engine ran faults
    assert_chart_is_the_matrix(&out);
    assert!(methods_rows(&out).iter().any(|m| m.0 == "engine: rusthdl"));
    let r = browser::render(&out);
    assert_eq!(browser::problems(&out, &r), Vec::<String>::new());
}

#[test]
#[ignore = "long: make test-long"]
fn charts_all_compares_every_method_on_the_same_faults() {
    if !tools::require_tools(&["verilator", "iverilog", "yosys", "yosys-abc", "sigrok-cli"]) {
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
            "faults,speed",
            "-o",
        ])
        .arg(&out)
        .arg(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("testkit/mixes/mutants.toml"))
        .assert()
        .success();
    assert_chart_is_the_matrix(&out);
    let sa = csv(&out.join("speed-accuracy.csv"));
    let row = |m: &str| {
        sa.iter()
            .find(|r| r[0] == m)
            .unwrap_or_else(|| panic!("{m}: {sa:?}"))
            .clone()
    };
    // the deep faults reach the Verilog engines; prove catches what the
    // simulations miss
    for m in ["engine: verilator", "engine: icarus"] {
        assert_ne!(row(m)[5], "0", "{m}");
    }
    assert_ne!(row("prove")[4], "0");
    let faults = std::fs::read_to_string(out.join("faults.json")).unwrap();
    let fj: serde_json::Value = serde_json::from_str(&faults).unwrap();
    for c in fj["classes"].as_array().unwrap() {
        if c["level"] == "verilog" {
            assert_eq!(c["detected_by"]["model"], 0, "{c}");
            assert_eq!(c["detected_by"]["prove"], c["injected"], "{c}");
        }
    }
}

/// A step that cannot measure is shown as skipped, never passed silently,
/// and fails the build under `--strict` (and under CI): here the speed
/// chart, which draws the fault campaign of the same build, with the
/// faults step left out.  No simulation runs: seconds.
#[test]
fn a_skipped_step_fails_strict_and_ci() {
    let d = tempfile::tempdir().unwrap();
    let build = |dir: &str, strict: bool, ci: &str| {
        let out = d.path().join(dir);
        let mut cmd = slotforge();
        // synthesis with no yosys on the PATH: the step is skipped
        let empty = d.path().join("no-tools");
        std::fs::create_dir_all(&empty).unwrap();
        cmd.args(["build", "--quiet", "--only", "synth", "-o"])
            .arg(&out)
            .arg("--junit")
            .arg(out.with_extension("xml"))
            .arg(tiny())
            .env("PATH", &empty)
            .env("CI", ci);
        if strict {
            cmd.arg("--strict");
        }
        let o = cmd.output().unwrap();
        let xml = std::fs::read_to_string(out.with_extension("xml")).unwrap();
        (o, xml)
    };
    let (o, xml) = build("strict", true, "false");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains("skipped") && err.contains("synthesis"),
        "{err}"
    );
    assert!(xml.contains("<skipped"), "{xml}");
    let (o, _) = build("ci", false, "true");
    assert!(!o.status.success(), "CI=true fails a skipped step too");
    // outside CI and without --strict the skip is reported, not fatal
    let (o, xml) = build("plain", false, "false");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        xml.contains("<skipped") && xml.contains("not installed"),
        "{xml}"
    );
}

/// Lower-case words joined by underscores (`adc_limit_hz`, `slot_rom.hex`)
/// in `text` outside code spans and link targets: what a reader should
/// never see as prose, a header or a row label.
fn snake_outside_code(md: &str) -> Vec<String> {
    let mut found = Vec::new();
    for line in md.lines() {
        // link targets are addresses, not text
        let mut plain = String::new();
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            plain.push_str(&rest[..i]);
            rest = rest[i..].split_once(')').map_or("", |x| x.1);
        }
        plain.push_str(rest);
        for (k, part) in plain.split('`').enumerate() {
            if k % 2 == 1 {
                continue; // a code span
            }
            for w in part.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')) {
                let snake = w.contains('_')
                    && w.starts_with(|c: char| c.is_ascii_lowercase())
                    && !w.ends_with('_')
                    && w.chars()
                        .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
                if snake {
                    found.push(format!("{w} in: {line}"));
                }
            }
        }
    }
    found
}

/// The Markdown tables of `md`: (caption, header cells, rows).
fn md_tables(md: &str) -> Vec<(String, Vec<String>, Vec<Vec<String>>)> {
    let cells = |l: &str| -> Vec<String> {
        l.trim()
            .trim_matches('|')
            .split(" | ")
            .map(|c| c.trim().to_string())
            .collect()
    };
    let lines: Vec<&str> = md.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i + 1 < lines.len() {
        if lines[i].starts_with('|') && lines[i + 1].starts_with("|---") {
            let caption = lines[..i]
                .iter()
                .rev()
                .find(|l| !l.trim().is_empty())
                .map_or(String::new(), |l| l.to_string());
            let head = cells(lines[i]);
            let mut rows = Vec::new();
            i += 2;
            while i < lines.len() && lines[i].starts_with('|') {
                rows.push(cells(lines[i]));
                i += 1;
            }
            out.push((caption, head, rows));
        } else {
            i += 1;
        }
    }
    out
}

/// The report of a mix no one wrote it for reads like a datasheet: no
/// snake_case outside code, every table once and whole (no "(1 of 2)"
/// parts, no row without its key, no channel listed twice, no table wider
/// than the page), and every file it links exists.
fn assert_reads_like_a_datasheet(mix: &Path, out: &Path) {
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let what = mix.display();
    assert_eq!(snake_outside_code(&md), Vec::<String>::new(), "{what}");
    let tables = md_tables(&md);
    assert!(tables.len() >= 6, "{what}: {} tables", tables.len());
    let text = std::fs::read_to_string(mix).unwrap();
    let parsed = slotforge_mix(mix, &text);
    for (cap, head, rows) in &tables {
        assert!(
            !cap.contains(" of 2)") && !cap.contains(" of 3)"),
            "{what}: split table {cap}"
        );
        assert!(head.len() <= 10, "{what}: {cap}: {} columns", head.len());
        assert!(rows.iter().all(|r| r.len() == head.len()), "{what}: {cap}");
        assert!(
            rows.iter().all(|r| !r[0].is_empty()),
            "{what}: {cap}: a row without its key"
        );
    }
    // the steps table ends with the build's wall time beside the sum of
    // the rows above it (steps may overlap: never a "total" of them)
    let (_, _, steps) = tables
        .iter()
        .find(|t| t.1.first().map(String::as_str) == Some("step"))
        .expect("the steps table");
    let (last, rows) = steps.split_last().unwrap();
    assert_eq!(
        last[0], "the whole build, start to end (wall clock)",
        "{what}"
    );
    let wall: f64 = last[2].parse().unwrap();
    let sum: f64 = rows.iter().map(|r| r[2].parse::<f64>().unwrap()).sum();
    let said: f64 = last[3]
        .strip_prefix("the steps' own times add up to ")
        .and_then(|r| r.split(" s").next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{what}: {last:?}"));
    assert!(
        (said - sum).abs() <= 0.005 * rows.len() as f64 + 0.01,
        "{what}: {said} vs {sum}"
    );
    assert!(
        wall > 0.0
            && wall
                >= rows
                    .iter()
                    .map(|r| r[2].parse::<f64>().unwrap())
                    .fold(0.0, f64::max)
                    - 0.01,
        "{what}: {last:?}"
    );
    assert!(!rows.iter().any(|r| r[0] == "total"), "{what}");
    // each channel is a row once (the audit's channel table)
    for name in &parsed {
        let n = tables
            .iter()
            .flat_map(|t| &t.2)
            .filter(|r| r[0] == *name)
            .count();
        assert_eq!(n, 1, "{what}: channel {name} is a row {n} times");
    }
    // each channel's wiring reads as the CLI's audit writes it (`dev.sel`,
    // or `in<k>` for a converter's own input)
    let (_, head, rows) = tables
        .iter()
        .find(|t| t.1.get(2).is_some_and(|h| h.starts_with("mux")))
        .expect("the channel table");
    assert!(head[2].contains("converter's input"), "{what}: {head:?}");
    for c in audit_json(mix)["channels"].as_array().unwrap() {
        let cli = match (c["adc_input"].as_u64(), c["front_mux"].as_bool()) {
            (None, _) => format!("{}.{}", c["device"], c["select"]),
            (Some(k), Some(true)) => format!("in{k}/{}.{}", c["device"], c["select"]),
            (Some(k), _) => format!("in{k}"),
        };
        let row = rows.iter().find(|r| r[0] == c["name"].as_str().unwrap());
        assert_eq!(
            row.map(|r| r[2].trim_matches('`')),
            Some(cli.as_str()),
            "{what}: {c}"
        );
    }
    // the first screen answers first: fit, binds, checked, proved, size
    let first = &tables[0];
    assert_eq!(first.1, ["question", "answer"], "{what}");
    for q in [
        "Does it fit?",
        "What binds",
        "Is the gateware checked?",
        "Is it proved?",
        "How big",
    ] {
        assert!(first.2.iter().any(|r| r[0].starts_with(q)), "{what}: {q}");
    }
    // every link of report.md resolves, beside the report
    assert!(md_link_targets(&md).len() >= 5, "{what}: links");
    for target in md_link_targets(&md) {
        assert!(
            !target.starts_with('#') && out.join(&target).is_file(),
            "{what}: report.md links `{target}`, which is not a file beside it"
        );
    }
    // every file the report links is there
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    for href in html
        .split("href=\"")
        .skip(1)
        .filter_map(|x| x.split('"').next())
    {
        if !href.starts_with('#') {
            assert!(
                out.join(href).is_file(),
                "{what}: links {href}, which is missing"
            );
        }
    }
}

/// `slotforge audit --json MIX`.
fn audit_json(mix: &Path) -> serde_json::Value {
    let out = slotforge()
        .args(["audit", "--json"])
        .arg(mix)
        .output()
        .unwrap();
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The target of every Markdown link and image in `md` (`[text](target)`).
fn md_link_targets(md: &str) -> Vec<String> {
    md.split("](")
        .skip(1)
        .filter_map(|rest| rest.split_once(')').map(|(t, _)| t.to_string()))
        .collect()
}

/// The channel names of a mix (upper or lower case: the report lists them
/// as data).
fn slotforge_mix(path: &Path, text: &str) -> Vec<String> {
    let m = lut_gen::parse(path, text).unwrap();
    m.channels.iter().map(|c| c.name.clone()).collect()
}

#[test]
fn reports_of_unseen_mixes_read_like_datasheets() {
    let d = tempfile::tempdir().unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut mixes: Vec<PathBuf> = std::fs::read_dir(root.join("testkit/mixes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    mixes.sort();
    mixes.push(root.join("mixes/eskin34-uart.toml"));
    mixes.push(skin28());
    for seed in [3, 11] {
        let p = d.path().join(format!("random{seed}.toml"));
        std::fs::write(&p, campaign::random_mix(seed, &campaign::Shape::default())).unwrap();
        mixes.push(p);
    }
    for (i, mix) in mixes.iter().enumerate() {
        let out = d.path().join(format!("b{i}"));
        slotforge()
            .args(["build", "--quiet", "--only", "audit,lut,verilog", "-o"])
            .arg(&out)
            .arg(mix)
            .assert()
            .success();
        assert_reads_like_a_datasheet(mix, &out);
    }
}

/// A mix with modes builds: the co-simulation runs the default scene (a
/// stroke over the watched taxels) on the gateware, and the report charts
/// the data rate with modes and without; the step's summary, the first
/// screen and the section say the numbers of the chart's CSV, and every
/// reaction measured is within the audit's worst; the preset's golden holds.
#[test]
fn a_mix_with_modes_is_charted_over_a_stroke() {
    if !tools::require_tool("verilator") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("b");
    let mix = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("mixes/eskin34-adaptive.toml");
    slotforge()
        .args(["build", "--quiet", "--only", "audit,sim,golden", "-o"])
        .arg(&out)
        .arg(&mix)
        .assert()
        .success();
    let rows = csv(&out.join("modes-rate.csv"));
    assert_eq!(rows[0][3], "bytes_with_modes");
    let sum = |c: usize| -> u64 { rows[1..].iter().map(|r| r[c].parse::<u64>().unwrap()).sum() };
    let (with, without) = (sum(3), sum(4));
    let pct = 100.0 * (1.0 - with as f64 / without as f64);
    let words =
        format!("{with} link bytes with modes against {without} with one mode: {pct:.1} % less");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    // the step's line, the first screen and the section
    assert!(md.matches(&words).count() >= 3, "{words}\n{md}");
    assert!(md.contains("stroke:CH{1..25}@3-13"), "the default scene");
    let modes: Vec<&str> = rows[1..].iter().map(|r| r[2].as_str()).collect();
    assert_eq!(modes.first(), Some(&"idle"));
    assert_eq!(modes.last(), Some(&"idle"));
    assert!(modes.contains(&"contact"));
    // every reaction: measured (column 5) within the audit's worst (6)
    let (_, _, reactions) = md_tables(&md)
        .into_iter()
        .find(|t| t.0.contains("Switches and reactions"))
        .expect("the reactions table");
    assert_eq!(reactions.len(), 2, "{reactions:?}");
    for r in &reactions {
        let (got, worst): (f64, f64) = (r[4].parse().unwrap(), r[5].parse().unwrap());
        assert!(0.0 < got && got <= worst, "{r:?}");
    }
    // the golden step takes a mix with modes: the preset's golden holds
    let row = md
        .lines()
        .find(|l| l.starts_with("| golden comparison |"))
        .unwrap();
    assert!(
        row.contains("| ok |") && row.contains("same as golden"),
        "{row}"
    );
    if tools::require_tool("chromium") {
        let r = browser::render(&out);
        assert_eq!(browser::problems(&out, &r), Vec::<String>::new());
    }
}
