//! `audit`'s fixes for a mix that does not fit: every fix offered is a mix
//! file the binary itself audits feasible, on mixes the feature was not
//! written for (random mixes that overload a branch, a rate beyond the ADC,
//! more channels than mux inputs), and a mix no fix helps says so.

use std::path::{Path, PathBuf};

use crate::common_cli::slotforge;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// `audit MIX --fixes DIR --json`: the fixes listed, each file written,
/// and each file audited feasible (exit 0) by the binary.
fn fixes_written_audit_feasible(mix: &Path, dir: &Path, code: i32) -> usize {
    let out = slotforge()
        .args(["audit", "--json", "--fixes"])
        .arg(dir)
        .arg(mix)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(code),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fixes = if code == 2 {
        // a file the loader refuses: no report, the fixes on stderr
        std::fs::read_dir(dir).map(|d| d.count()).unwrap_or(0)
    } else {
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let list = v["fixes"].as_array().expect("fixes listed").clone();
        for (i, f) in list.iter().enumerate() {
            let file = dir.join(format!("fix-{}.toml", i + 1));
            assert_eq!(
                f["file"].as_str(),
                Some(file.display().to_string().as_str())
            );
            assert!(!f["says"].as_str().unwrap().is_empty());
        }
        list.len()
    };
    for n in 1..=fixes {
        let file = dir.join(format!("fix-{n}.toml"));
        let out = slotforge().arg("audit").arg(&file).output().unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{} does not audit feasible:\n{}\n{}",
            file.display(),
            String::from_utf8_lossy(&out.stdout),
            std::fs::read_to_string(&file).unwrap()
        );
    }
    fixes
}

const HEAD: &str =
    "name = \"u\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 10_000\nslice_us = 1_000\n";

fn branch(name: &str, adc: &str, devices: u32) -> String {
    format!("[[branch]]\nname = \"{name}\"\nadc = \"{adc}\"\nmux = \"tmux1108\"\nmux_devices = {devices}\n")
}

fn channels(prefix: &str, branch: &str, n: usize, rate: u64) -> String {
    (0..n)
        .map(|i| {
            format!(
                "[[channel]]\nname = \"{prefix}{i}\"\nbranch = \"{branch}\"\nrate_hz = {rate}\n"
            )
        })
        .collect()
}

/// Hand-made mixes of each kind, none of them the unit tests' mixes.
#[test]
fn unseen_infeasible_mixes_get_fixes_that_audit_feasible() {
    let dir = tempfile::tempdir().unwrap();
    let over = format!(
        "{HEAD}{}{}{}{}{}",
        branch("skin", "ad7940", 7),
        branch("temp", "ad7940", 1),
        channels("P", "skin", 52, 2_000),
        channels("V", "skin", 2, 4_000),
        channels("K", "temp", 7, 100)
    );
    let fast = format!(
        "{HEAD}{}{}",
        branch("vib", "ad7940", 1),
        channels("A", "vib", 2, 60_000)
    );
    let full = format!(
        "{HEAD}{}{}",
        branch("row", "ad7940", 2),
        channels("R", "row", 19, 1_000)
    );
    for (name, text, code) in [("over", &over, 1), ("fast", &fast, 1), ("full", &full, 2)] {
        let mix = write(dir.path(), &format!("{name}.toml"), text);
        let n = fixes_written_audit_feasible(&mix, &dir.path().join(name), code);
        assert!(n >= 1, "{name}: no fix offered");
    }
}

/// Random mixes (the campaign's generator overloads some branches on
/// purpose): every infeasible one gets a fix, and every fix file audits
/// feasible.
#[test]
fn random_infeasible_mixes_get_fixes_that_audit_feasible() {
    let dir = tempfile::tempdir().unwrap();
    let shape = campaign::Shape {
        branches: (1, 2),
        mux_devices: (3, 4),
        channels: (30, 60),
        ..campaign::Shape::default()
    };
    let mut infeasible = 0;
    for seed in 1..=200u64 {
        let text = campaign::random_mix(seed, &shape);
        let path = dir.path().join(format!("r{seed}.toml"));
        let Ok(mix) = lut_gen::parse(&path, &text) else {
            continue;
        };
        if lut_gen::synthesize(&mix).is_ok() {
            continue;
        }
        infeasible += 1;
        if infeasible > 6 {
            break;
        }
        std::fs::write(&path, &text).unwrap();
        let n = fixes_written_audit_feasible(&path, &dir.path().join(format!("r{seed}")), 1);
        assert!(n >= 1, "seed {seed}: no fix offered for\n{text}");
    }
    assert!(infeasible >= 3, "only {infeasible} infeasible random mixes");
}

/// A mix no change within reach fixes says so, offers none, writes none.
#[test]
fn a_mix_no_fix_helps_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = format!(
        "{HEAD}{}{}",
        branch("a", "ad7940", 1),
        branch("b", "ad7940", 1)
    );
    for (n, b) in [("x", "a"), ("y", "b")] {
        text.push_str(&format!(
            "[[channel]]\nname = \"{n}\"\nbranch = \"{b}\"\nrate_hz = 400_000\nsync = \"s\"\n"
        ));
    }
    let mix = write(dir.path(), "none.toml", &text);
    let out = slotforge()
        .args(["audit", "--fixes"])
        .arg(dir.path().join("out"))
        .arg(&mix)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("no fix found"), "{stdout}");
    assert!(!stdout.contains("what makes it fit"), "{stdout}");
    assert!(!dir.path().join("out/fix-1.toml").exists());
}

/// A folder holding fix files already is refused before anything is
/// written; the user's files are untouched.
#[test]
fn fix_files_the_user_has_are_never_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let over = format!(
        "{HEAD}{}{}",
        branch("a", "ad7940", 1),
        channels("F", "a", 1, 400_000)
    );
    let mix = write(dir.path(), "m.toml", &over);
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    std::fs::write(out_dir.join("fix-1.toml"), "mine").unwrap();
    let out = slotforge()
        .args(["audit", "--fixes"])
        .arg(&out_dir)
        .arg(&mix)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("holds fix files already (fix-1.toml)") && err.contains("nothing written"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(out_dir.join("fix-1.toml")).unwrap(),
        "mine"
    );
}
