//! What the root crate's CLI tests share: the binary, the repository, the
//! small two-branch mix, a `sim --vcd` window of it, and a refusal.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use assert_cmd::assert::Assert;
use assert_cmd::Command;
use predicates::prelude::*;

/// The `slotforge` binary under test.
pub fn slotforge() -> Command {
    Command::cargo_bin("slotforge").unwrap()
}

/// The repository's root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `slotforge ARGS` is refused: exit 2, each of `says` on stderr (the
/// `Assert` for what else a test holds it to).
pub fn refused(args: &[&dyn AsRef<OsStr>], says: &[&str]) -> Assert {
    let mut a = slotforge()
        .args(args.iter().map(|a| a.as_ref()))
        .assert()
        .code(2);
    for s in says {
        a = a.stderr(predicate::str::contains(*s));
    }
    a
}

/// A two-branch mix with a 4000-cycle frame (fast in every simulator).
pub fn tiny() -> PathBuf {
    root().join("testkit/mixes/tiny.toml")
}

/// `golden --update` of the tiny mix (rusthdl) into `dir`: a golden that
/// a later `golden` or `build` of it checks against.
pub fn record_golden(dir: &Path) {
    slotforge()
        .args(["golden", "--backend", "rusthdl", "--update", "--dir"])
        .arg(dir)
        .arg(tiny())
        .assert()
        .success();
}

/// `dir/name`: `sim --vcd` of 3 frames of the tiny mix on the rusthdl back
/// end over `[from, to)`.
pub fn sim_window(dir: &Path, name: &str, from: &str, to: &str) -> PathBuf {
    let wave = dir.join(name);
    slotforge()
        .arg("sim")
        .arg(tiny())
        .args(["--backend", "rusthdl", "--frames", "3"])
        .args(["--from", from, "--to", to, "--vcd"])
        .arg(&wave)
        .assert()
        .code(0);
    wave
}

/// The column of detector `d` in a fault campaign's JSON (`faults --json`).
pub fn column(v: &serde_json::Value, d: &str) -> serde_json::Value {
    v["columns"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["detector"] == d)
        .unwrap()
        .clone()
}
