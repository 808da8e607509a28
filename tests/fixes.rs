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

/// The standard bauds a host offers (as `lut_gen::fixes` lists them).
const STANDARD_BAUDS: [u64; 22] = [
    9_600, 19_200, 38_400, 57_600, 115_200, 230_400, 250_000, 460_800, 500_000, 576_000, 921_600,
    1_000_000, 1_152_000, 1_500_000, 2_000_000, 2_500_000, 3_000_000, 4_000_000, 6_000_000,
    8_000_000, 10_000_000, 12_000_000,
];

/// Random UART mixes made infeasible by a low baud get one fix, "raise the
/// baud", to a standard baud the clock divides within 2 %: its file audits
/// feasible, and the mix at every lower such baud (above the low one)
/// does not, so the baud offered is the lowest that works.
#[test]
fn random_link_mixes_too_slow_for_their_line_get_the_lowest_baud_that_works() {
    let dir = tempfile::tempdir().unwrap();
    let shape = campaign::Shape {
        link: Some(campaign::LinkShape::Uart),
        ..campaign::Shape::default()
    };
    let audit_code = |path: &Path| {
        slotforge()
            .arg("audit")
            .arg(path)
            .output()
            .unwrap()
            .status
            .code()
    };
    let mut tested = 0;
    for seed in 1..=60u64 {
        let text = campaign::random_mix(seed, &shape);
        let Ok(mix) = lut_gen::parse(Path::new("r.toml"), &text) else {
            continue;
        };
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        let low = [9_600, 57_600, 115_200][(seed % 3) as usize];
        let (head, tail) = text.split_once("baud = ").unwrap();
        let rest = tail.split_once('\n').unwrap().1;
        let slow = format!("{head}baud = {low}\n{rest}");
        let path = write(dir.path(), &format!("r{seed}.toml"), &slow);
        if audit_code(&path) != Some(1) {
            continue; // a mix so light that the low baud carries it
        }
        let fixes = dir.path().join(format!("r{seed}"));
        assert_eq!(
            fixes_written_audit_feasible(&path, &fixes, 1),
            1,
            "seed {seed}:\n{slow}"
        );
        let fixed = std::fs::read_to_string(fixes.join("fix-1.toml")).unwrap();
        let to: u64 = fixed
            .lines()
            .find_map(|l| l.strip_prefix("baud = "))
            .unwrap()
            .parse()
            .unwrap();
        assert!(STANDARD_BAUDS.contains(&to), "seed {seed}: {to}");
        assert!(
            fixed.contains(&format!("raise the link's baud from {low} to {to}")),
            "{fixed}"
        );
        let clock = s.grid.clock_hz as f64;
        let divides = |b: u64| {
            let div = (clock / b as f64).round();
            div >= 4.0 && (clock / div - b as f64).abs() / b as f64 <= 0.02
        };
        assert!(divides(to), "seed {seed}: {to}");
        for lower in STANDARD_BAUDS
            .into_iter()
            .filter(|&b| b > low && b < to && divides(b))
        {
            let p = write(
                dir.path(),
                &format!("r{seed}-{lower}.toml"),
                &slow.replace(&format!("baud = {low}\n"), &format!("baud = {lower}\n")),
            );
            assert_eq!(
                audit_code(&p),
                Some(1),
                "seed {seed}: {lower} baud carries the mix, {to} offered"
            );
        }
        tested += 1;
        if tested >= 4 {
            break;
        }
    }
    assert!(tested >= 3, "only {tested} random link mixes tested");
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
