//! Issue 17, end to end: `check` on captures that are not a simulator's VCD
//! from reset: FST (GTKWave's `vcd2fst` writes it, `wellen` reads it).

use std::path::{Path, PathBuf};
use std::process::Command as Process;

use predicates::prelude::*;

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::common_cli::{sim_window, slotforge, tiny};
use crate::{progress, tools};

fn vcd2fst(vcd: &Path) -> PathBuf {
    let fst = vcd.with_extension("fst");
    let st = Process::new("vcd2fst").arg(vcd).arg(&fst).output().unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    fst
}

#[test]
fn check_reads_fst_from_reset_and_mid_run() {
    if !tools::require_tool("vcd2fst") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    for (from, to) in [("0", "2"), ("0.37ms", "2.6ms")] {
        let fst = vcd2fst(&sim_window(d.path(), "w.vcd", from, to));
        let out = slotforge()
            .arg("check")
            .arg(tiny())
            .arg(&fst)
            .arg("--json")
            .assert()
            .code(0);
        let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
        assert_eq!(v["ok"], true, "{v}");
        assert!(v["samples"].as_u64().unwrap() > 15, "{v}");
        assert_eq!(v["lock"].is_null(), from == "0", "{v}");
    }
    // A fault in the FST fails: the mid-run window with one sample_value bit
    // flipped, through vcd2fst.
    let vcd = sim_window(d.path(), "bad.vcd", "0.37ms", "2.6ms");
    let text = std::fs::read_to_string(&vcd).unwrap();
    let id = text
        .lines()
        .find(|l| l.starts_with("$var") && l.contains(" sample_value "))
        .and_then(|l| l.split_whitespace().nth(3))
        .unwrap()
        .to_string();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let changes: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].starts_with('b') && lines[i].ends_with(&format!(" {id}")))
        .collect();
    let i = changes[changes.len() / 2];
    let (val, rest) = lines[i].split_once(' ').unwrap();
    let flipped = if val.ends_with('0') { "1" } else { "0" };
    lines[i] = format!("{}{flipped} {rest}", &val[..val.len() - 1]);
    std::fs::write(&vcd, lines.join("\n") + "\n").unwrap();
    slotforge()
        .arg("check")
        .arg(tiny())
        .arg(vcd2fst(&vcd))
        .assert()
        .code(1)
        .stdout(predicate::str::contains("sample_value"));
    // Not a waveform at all: exit 2, no panic.
    let junk = d.path().join("junk.fst");
    std::fs::write(&junk, [0u8, 1, 2, 3, 4, 5, 6, 7, 8, 9]).unwrap();
    slotforge()
        .arg("check")
        .arg(tiny())
        .arg(&junk)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("junk.fst"))
        .stderr(predicate::str::contains("panicked").not());
}

#[test]
fn golden_keeps_and_verifies_fst_windows() {
    if !tools::require_tool("vcd2fst") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let g = d.path().join("tiny");
    std::fs::create_dir_all(&g).unwrap();
    std::fs::write(
        g.join("golden.toml"),
        "frames = 1\n\n[[window]]\nfile = \"w.fst\"\nfrom = \"0.3ms\"\nto = \"1.2ms\"\n",
    )
    .unwrap();
    let golden = |update: bool| {
        let mut c = slotforge();
        c.arg("golden")
            .arg(tiny())
            .args(["--backend", "rusthdl", "--dir"]);
        c.arg(d.path());
        if update {
            c.arg("--update");
        }
        c.assert()
    };
    golden(true).code(0);
    let fst = g.join("w.fst");
    let head = std::fs::read(&fst).unwrap();
    assert!(!head[0].is_ascii_graphic(), "w.fst is not an FST");
    golden(false)
        .code(0)
        .stdout(predicate::str::contains("window w.fst same"));
    // The golden FST window is itself a capture `check` passes, mid-run.
    slotforge()
        .arg("check")
        .arg(tiny())
        .arg(&fst)
        .assert()
        .code(0)
        .stderr(predicate::str::contains("locked on the frame phase"));
    // Another window in its place differs.
    let other = vcd2fst(&sim_window(d.path(), "o.vcd", "0.4ms", "1.3ms"));
    std::fs::copy(other, &fst).unwrap();
    golden(false)
        .code(1)
        .stdout(predicate::str::contains("window w.fst DIFFERS"));
}

#[test]
fn check_map_errors_name_the_entry_and_exit_2() {
    let d = tempfile::tempdir().unwrap();
    let cap = d.path().join("cap.vcd");
    std::fs::write(
        &cap,
        judge::wire_header("1 ns", "libsigrok", &["D0"]) + "#0\n0!\n",
    )
    .unwrap();
    slotforge()
        .arg("check")
        .arg(tiny())
        .arg(&cap)
        .args(["--map", "D0=adc_cs_n[9]"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("D0=adc_cs_n[9]"))
        .stderr(predicate::str::contains("no bit 9"));
    let map = d.path().join("probes.map");
    std::fs::write(&map, "# probes\nD0 = adc_cs_n[0]\nD1 = spi_clk[0]\n").unwrap();
    slotforge()
        .arg("check")
        .arg(tiny())
        .arg(&cap)
        .arg("--map")
        .arg(&map)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("probes.map:3"))
        .stderr(predicate::str::contains("spi_clk"));
    // A channel the capture lacks, and a capture with no conversion start.
    slotforge()
        .arg("check")
        .arg(tiny())
        .arg(&cap)
        .args(["--map", "D0=adc_cs_n[0],D5=adc_sclk[0]"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("D5"));
    slotforge()
        .arg("check")
        .arg(tiny())
        .arg(&cap)
        .args(["--map", "D0=adc_cs_n[0]", "--skew", "2ns"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("cap.vcd"))
        .stderr(predicate::str::contains("panicked").not());
}

/// `check --map` off a terminal tells how far it read a capture of several
/// MB (bytes of the file), a line every few seconds; nothing when the
/// reading ends within a second, nothing with `--quiet`.
#[test]
fn check_map_shows_its_progress_in_plain_lines_off_a_terminal() {
    let d = tempfile::tempdir().unwrap();
    let cap = d.path().join("big.vcd");
    let mut text = "$comment Acquisition with 1/8 channels at 24 MHz $end\n".to_string()
        + &judge::wire_header("1 ns", "libsigrok", &["D0"])
        + "#0\n1!\n";
    // CS toggling every 10 us: a long capture the checker can lock onto or not
    let mut t = 0u64;
    while text.len() < 3 << 20 {
        t += 10_000;
        text.push_str(&format!("#{t}\n{}!\n", (t / 10_000) % 2));
    }
    std::fs::write(&cap, &text).unwrap();
    let size = text.len() as f64 / 1e6;
    let run = |quiet: bool, step: &str| {
        let mut c = slotforge();
        c.env(progress::STEP_ENV, step)
            .arg("check")
            .arg(tiny())
            .arg(&cap)
            .args(["--map", "D0=adc_cs_n[0]"]);
        if quiet {
            c.arg("--quiet");
        }
        let out = c.output().unwrap();
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let log = run(false, progress::SLOW);
    let prefix = format!("reading {}: ", cap.display());
    let total = progress::paced(&log, &prefix, " MB read");
    assert!((total - size).abs() < 0.05, "{total} of {size} MB: {log}");
    assert!(!run(false, progress::QUICK).contains("MB read"));
    assert!(!run(true, progress::SLOW).contains("MB read"));
}
