//! Quality gates on the emitted Verilog, with the real tools:
//! `verilator --lint-only -Wall`, `iverilog -g2005 -Wall`, `yosys synth_ice40`.
use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::*;
use lut_gen::Schedule;

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::policy;

fn emit_to(s: &Schedule, tag: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("hdl-gates-{tag}"));
    let _ = std::fs::remove_dir_all(&dir);
    hdl::emit(s, None)
        .expect("emits")
        .write_to(&dir)
        .expect("writes");
    dir
}

fn run(dir: &Path, cmd: &mut Command) -> (bool, String) {
    let out = cmd.current_dir(dir).output().expect("tool runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), text)
}

fn gates(s: &Schedule, tag: &str) {
    let dir = emit_to(s, tag);
    gates_in(&dir, tag);
}

fn gates_in(dir: &Path, tag: &str) {
    lint_in(dir, tag);
    synth_in(dir, tag);
}

/// Verilator and Icarus on the Verilog in `dir`.
fn lint_in(dir: &Path, tag: &str) {
    if !policy::require_tools(&["verilator", "iverilog"]) {
        return;
    }
    let dir = dir.to_path_buf();
    // Verilator: clean under -Wall (the only waiver is inline: DECLFILENAME).
    let (ok, text) = run(
        &dir,
        Command::new("verilator").args(["--lint-only", "-Wall", "slotforge_top.v"]),
    );
    assert!(
        ok && !text.contains("%Warning"),
        "verilator -Wall on {tag}:\n{text}"
    );
    // Icarus: silent.
    let (ok, text) = run(
        &dir,
        Command::new("iverilog").args(["-g2005", "-Wall", "-o", "/dev/null", "slotforge_top.v"]),
    );
    assert!(
        ok && text.trim().is_empty(),
        "iverilog -g2005 -Wall on {tag}:\n{text}"
    );
}

/// Yosys on the Verilog in `dir`: synthesizes for iCE40, passes
/// check -assert, no latches.
fn synth_in(dir: &Path, tag: &str) {
    if !policy::require_tool("yosys") {
        return;
    }
    let (ok, text) = run(
        dir,
        Command::new("yosys").args([
            "-p",
            "read_verilog slotforge_top.v; synth_ice40 -top slotforge_top; check -assert; select -assert-none t:$dlatch t:$_DLATCH_* t:SB_DLATCH*; stat",
        ]),
    );
    assert!(
        ok,
        "yosys synth_ice40 on {tag}:\n{}",
        &text[text.len().saturating_sub(4000)..]
    );
    assert!(!text.contains("Latch inferred"), "latch inferred in {tag}");
    assert!(text.contains("SB_LUT4"), "no logic synthesized for {tag}");
}

/// Long: eskin34's core is in the link tests' designs below.
#[test]
#[ignore = "long: make test-long"]
fn gates_eskin34() {
    gates(&eskin34(), "eskin34");
}

#[test]
fn gates_tiny() {
    gates(&tiny(), "tiny");
}

/// Long: eight branches; the branch-count mixes go wider.
#[test]
#[ignore = "long: make test-long"]
fn gates_wide8() {
    gates(&wide(), "wide8");
}

#[test]
fn gates_three_speed() {
    gates(&two_speed(), "threespeed");
}

#[test]
#[ignore = "long: make test-long"]
fn gates_branch_count_mixes() {
    for name in ["b4", "b5", "b6", "u2", "full300", "b16", "ch1024"] {
        gates(&data_mix(name), name);
    }
}

/// Converter parts (issue 10): vibrotactile8k's AD7685 chain, a user-declared
/// 12-bit CS part, and a mix of a chain behind a mux, a lone AD7685 and an
/// AD7940 on one clock.
#[test]
fn gates_converter_parts() {
    gates(&data_mix("cnvmix"), "cnvmix");
    for preset in ["vibrotactile8k", "induction5k-adc12"] {
        let path = common::root().join(format!("mixes/{preset}.toml"));
        let s = lut_gen::synthesize(&lut_gen::load(&path).unwrap()).unwrap();
        gates(&s, preset);
    }
}

/// The link to the host (issue 14): the tiny mix with a UART, emitted
/// deterministically, linted and synthesized whole; the reference design
/// with its UART in `make test-long` (`gates_uart_link_of_eskin34`: its
/// yosys run is most of 10 s; `the_links_fifo_is_block_ram` synthesizes
/// its link stage in `make test`).
#[test]
fn gates_uart_link() {
    let tiny = std::fs::read_to_string(common::root().join("testkit/mixes/tiny.toml")).unwrap()
        + "\n[link]\nkind = \"uart\"\nbaud = 1_000_000\n";
    let mix = lut_gen::parse(Path::new("tiny-uart.toml"), &tiny).unwrap();
    uart_link_gates(&lut_gen::synthesize(&mix).unwrap(), "tiny-uart");
}

#[test]
#[ignore = "long: make test-long (the reference design's UART link synthesized)"]
fn gates_uart_link_of_eskin34() {
    let path = common::root().join("mixes/eskin34-uart.toml");
    uart_link_gates(
        &lut_gen::synthesize(&lut_gen::load(&path).unwrap()).unwrap(),
        "eskin34-uart",
    );
}

/// `s`'s Verilog has the link stage, is emitted the same twice, and
/// lints and synthesizes clean.
fn uart_link_gates(s: &Schedule, tag: &str) {
    let v = hdl::emit(s, None).unwrap();
    assert!(v.verilog().contains("module slotforge_link("));
    assert_eq!(v, hdl::emit(s, None).unwrap(), "deterministic");
    gates(s, tag);
}

fn eskin34_axis() -> Schedule {
    let path = common::root().join("mixes/eskin34-axis.toml");
    lut_gen::synthesize(&lut_gen::load(&path).unwrap()).unwrap()
}

/// The AXI4-Stream link (`kind = "axis"`): `slotforge_link`'s AXIS output
/// and the `m_axis_*` ports lint clean under Verilator -Wall and Icarus
/// -Wall (yosys in the long suite: the UART's synthesis above covers the
/// shared FIFO and packetizer); so does a FIFO of one token (an
/// always-ready slave on a small mix), whose count is one bit wide.
#[test]
fn lints_axis_link() {
    let s = eskin34_axis();
    let dir = emit_to(&s, "eskin34-axis");
    let v = std::fs::read_to_string(dir.join("slotforge_top.v")).unwrap();
    assert!(v.contains("module slotforge_link(") && v.contains("m_axis_tready"));
    lint_in(&dir, "eskin34-axis");
    let tiny = std::fs::read_to_string(common::root().join("testkit/mixes/tiny.toml")).unwrap()
        + "\n[link]\nkind = \"axis\"\ntlast = \"slice\"\nready_within = 1\n";
    let mix = lut_gen::parse(Path::new("tiny-axis1.toml"), &tiny).unwrap();
    let s = lut_gen::synthesize(&mix).unwrap();
    let dir = emit_to(&s, "tiny-axis1");
    let v = std::fs::read_to_string(dir.join("slotforge_top.v")).unwrap();
    assert!(v.contains("FIFO of 1 tokens"), "a one-token FIFO");
    lint_in(&dir, "tiny-axis1");
}

#[test]
#[ignore = "long: make test-long"]
fn gates_axis_link() {
    gates(&eskin34_axis(), "eskin34-axis");
}

#[test]
fn gates_compact_lut() {
    gates(&long_frame(), "longframe");
    gates(&long_slot(), "longslot");
    let s = eskin34();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("hdl-gates-eskin34-compact");
    let _ = std::fs::remove_dir_all(&dir);
    let e = hdl::emit_with(&s, None, hdl::LutForm::Compact).expect("emits");
    assert!(e.file("slot_rom.hex").unwrap().contains("COMPACT"));
    e.write_to(&dir).expect("writes");
    gates_in(&dir, "eskin34-compact");
}

#[test]
fn emission_is_deterministic() {
    let s = eskin34();
    let a = hdl::emit(&s, None).unwrap();
    let b = hdl::emit(&s, None).unwrap();
    assert_eq!(a, b);
    let names: Vec<&str> = a.files().iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "edalize-launcher.sh",
            "ports.json",
            "slot_rom.hex",
            "slotforge.pcf",
            "slotforge.sdc",
            "slotforge.xdc",
            "slotforge_top.core",
            "slotforge_top.v",
            "slots.hex"
        ]
    );
}

#[test]
fn ports_json_follows_the_contract() {
    let s = eskin34();
    let e = hdl::emit(&s, None).unwrap();
    let v: serde_json::Value = serde_json::from_str(e.ports_json()).unwrap();
    assert_eq!(v["top"], "slotforge_top");
    assert_eq!(v["clock"], "clk");
    assert_eq!(v["reset"]["port"], "rst");
    assert_eq!(v["reset"]["active_high"], true);
    let br = v["branches"].as_array().unwrap();
    assert_eq!(br.len(), 3);
    assert_eq!(br[0]["cs_n"], "adc_cs_n[0]");
    assert_eq!(br[1]["mux_sel"], "mux_sel[5:3]");
    assert_eq!(br[0]["mux_en"].as_array().unwrap().len(), 4);
    assert_eq!(br[1]["mux_en"][0], "mux_en[4]");
    assert_eq!(br[2]["mux_en"][0], "mux_en[6]");
    assert_eq!(v["sample"]["valid"], "sample_valid");
    assert_eq!(v["sample"]["channel"], "sample_channel");
    assert_eq!(v["sample"]["value"], "sample_value");
    let ch = v["channels"].as_array().unwrap();
    assert_eq!(ch.len(), 41);
    assert_eq!(ch[0]["index"], 0);
    assert_eq!(ch[0]["name"], "CH1");
    assert_eq!(ch[0]["branch"], "standard");
}

#[test]
fn board_file_pcf_covers_every_port_bit() {
    let board = root().join("constraints/ice40-hx8k-breakout.toml");
    for (tag, s) in [("eskin34", eskin34()), ("tiny", tiny()), ("wide8", wide())] {
        let e = hdl::emit(&s, Some(&board)).expect("board file maps every bit");
        let pcf = e.file("slotforge.pcf").unwrap();
        let template = hdl::emit(&s, None).unwrap();
        let bits = template
            .file("slotforge.pcf")
            .unwrap()
            .lines()
            .filter(|l| l.starts_with("# set_io"))
            .count();
        assert_eq!(
            pcf.lines().filter(|l| l.starts_with("set_io")).count(),
            bits,
            "{tag}"
        );
        assert!(pcf.contains("set_io clk J3"));
    }
    // tiny: 1-bit vector ports are named as the tools name them
    let e = hdl::emit(&tiny(), Some(&board)).unwrap();
    let pcf = e.file("slotforge.pcf").unwrap();
    assert!(
        pcf.contains("set_io adc_cs_n ") && pcf.contains("set_io mux_en "),
        "{pcf}"
    );
}

/// Every port of `ports.json`, link ports included, has its line in every
/// constraints file of every preset: the XDC's IOSTANDARD and a pin row,
/// the PCF's `set_io` (template and board file), the SDC's clock or I/O
/// delay in its direction.
#[test]
fn every_port_is_in_every_constraints_file() {
    let board = root().join("constraints/ice40-hx8k-breakout.toml");
    let presets = testkit::presets::presets(&root());
    assert!(presets.len() >= 7, "{presets:?}");
    let mut link_ports = 0;
    for path in presets {
        let tag = path.display().to_string();
        let s = lut_gen::synthesize(&lut_gen::load(&path).unwrap()).unwrap();
        let e = hdl::emit(&s, None).unwrap();
        let with_board = hdl::emit(&s, Some(&board)).unwrap();
        let j: serde_json::Value = serde_json::from_str(e.ports_json()).unwrap();
        // the names a constraint gives a port: itself, its bits, `[*]`
        let names = |line: &str| -> Vec<String> {
            let Some((_, rest)) = line.split_once("get_ports ") else {
                return Vec::new();
            };
            let inner = match rest.strip_prefix('{') {
                Some(r) => r.split('}').next().unwrap_or(""),
                None => rest.split(']').next().unwrap_or(""),
            };
            inner
                .split_whitespace()
                .map(|n| n.split('[').next().unwrap().to_string())
                .collect()
        };
        let xdc = e.file("slotforge.xdc").unwrap();
        let sdc = e.file("slotforge.sdc").unwrap();
        let iostd = xdc.lines().find(|l| l.contains("IOSTANDARD")).unwrap();
        let iostd_names: Vec<&str> = iostd
            .split_once('{')
            .unwrap()
            .1
            .trim_end_matches("}]")
            .split(' ')
            .map(|n| n.trim_end_matches("[*]"))
            .collect();
        for p in j["ports"].as_array().unwrap() {
            let name = p["name"].as_str().unwrap();
            link_ports += name.starts_with("link_") as usize + name.starts_with("m_axis_") as usize;
            assert!(iostd_names.contains(&name), "{tag}: {name}: {iostd}");
            let pin_row = |text: &str, prefix: &str| {
                text.lines().any(|l| {
                    l.strip_prefix(prefix).is_some_and(|r| {
                        let bit = r.split_whitespace().next().unwrap_or("");
                        bit == name || bit.starts_with(&format!("{name}["))
                    })
                })
            };
            assert!(
                pin_row(e.file("slotforge.pcf").unwrap(), "# set_io "),
                "{tag}: {name} in the PCF template"
            );
            assert!(
                pin_row(with_board.file("slotforge.pcf").unwrap(), "set_io "),
                "{tag}: {name} in the board's PCF"
            );
            assert!(
                xdc.lines()
                    .filter(|l| l.contains("PACKAGE_PIN"))
                    .any(|l| names(l).iter().any(|n| n == name)),
                "{tag}: {name}: no pin row in the XDC"
            );
            let cmd = match (name, p["dir"].as_str().unwrap()) {
                ("clk", _) => "create_clock",
                (_, "in") => "set_input_delay",
                _ => "set_output_delay",
            };
            assert!(
                sdc.lines()
                    .filter(|l| l.starts_with(cmd))
                    .any(|l| names(l).iter().any(|n| n == name)),
                "{tag}: {name}: no {cmd} in the SDC:\n{sdc}"
            );
        }
    }
    assert!(link_ports >= 6, "link ports tested: {link_ports}");
}

/// The lean link on iCE40, on both presets and a small mix of
/// another line shape: the FIFO's tokens and their read register are a
/// block RAM (no token flip-flops), and a UART's CRC is bit-serial (no
/// byte-wide CRC function).
#[test]
fn the_links_fifo_is_block_ram() {
    if !policy::require_tool("yosys") {
        return;
    }
    let tiny = std::fs::read_to_string(common::root().join("testkit/mixes/tiny.toml")).unwrap()
        + "\n[link]\nkind = \"uart\"\nbaud = 1_000_000\nparity = \"odd\"\nstop_bits = 2\n";
    let tiny =
        lut_gen::synthesize(&lut_gen::parse(Path::new("tiny-uart.toml"), &tiny).unwrap()).unwrap();
    let uart = common::root().join("mixes/eskin34-uart.toml");
    let uart = lut_gen::synthesize(&lut_gen::load(&uart).unwrap()).unwrap();
    for (s, tag, axis) in [
        (uart, "lean-uart", false),
        (eskin34_axis(), "lean-axis", true),
        (tiny, "lean-tiny", false),
    ] {
        let dir = emit_to(&s, tag);
        let v = std::fs::read_to_string(dir.join("slotforge_top.v")).unwrap();
        assert_eq!(v.contains("function [15:0] crc8"), axis, "{tag}");
        let (ok, text) = run(
            &dir,
            Command::new("yosys").args([
                "-p",
                "read_verilog slotforge_top.v; synth_ice40 -top slotforge_link; stat",
            ]),
        );
        assert!(ok, "{tag}: {}", &text[text.len().saturating_sub(3000)..]);
        let count = |cell: &str| -> usize {
            text.lines()
                .filter(|l| l.split_whitespace().next() == Some(cell))
                .filter_map(|l| l.split_whitespace().nth(1)?.parse().ok())
                .next_back()
                .unwrap_or(0)
        };
        // 28-bit tokens: two 16-bit-wide block RAMs
        assert_eq!(count("SB_RAM40_4K"), 2, "{tag}: {text}");
        // the last `stat` (synth_ice40 prints one of its own)
        let last = &text[text.rfind("Number of cells").unwrap_or(0)..];
        let dffs: usize = last
            .lines()
            .filter(|l| l.trim_start().starts_with("SB_DFF"))
            .filter_map(|l| l.split_whitespace().nth(1)?.parse::<usize>().ok())
            .sum();
        // a read-first emulation (a write register and bypass) would add 28+
        assert!(dffs > 0 && dffs < 100, "{tag}: {dffs} flip-flops");
    }
}

/// Modes (issue 29): a pin-select mix, an auto mix with three modes and a
/// UART, the adaptive reference design, and an AD7689 behind a front mux
/// with modes (pin and auto select: its command unit's per-mode words):
/// the mode block, every mode's table on the ROM address and the mode
/// ports lint and synthesize clean. The adaptive reference design is
/// linted here and synthesized in `make test-long` (`gates_eskin34_adaptive`:
/// its yosys run is half of this test's time).
///
/// `make test` synthesizes one mix of each select, one of them fronted
/// (`modes-pin`, `front-modes-auto`) and lints the other two;
/// `gates_modes_of_the_other_selects` synthesizes those in `make test-long`.
#[test]
fn gates_modes() {
    for name in ["modes-pin", "front-modes-auto"] {
        gates(&mode_mix(name), name);
    }
    for name in ["modes-auto", "front-modes", "eskin34-adaptive"] {
        lint_in(&emit_to(&mode_mix(name), &format!("{name}-lint")), name);
    }
}

/// Long: the auto-select mix and the fronted pin-select mix synthesized.
#[test]
#[ignore = "long: make test-long (two more mode mixes synthesized)"]
fn gates_modes_of_the_other_selects() {
    for name in ["modes-auto", "front-modes"] {
        gates(&mode_mix(name), name);
    }
}

/// Long: the adaptive reference design (34 channels, two modes) linted and
/// synthesized.
#[test]
#[ignore = "long: make test-long"]
fn gates_eskin34_adaptive() {
    gates(&mode_mix("eskin34-adaptive"), "eskin34-adaptive");
}

/// The schedule of the shared mix `name`.
fn mode_mix(name: &str) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(&testkit::mix(name)).unwrap()).unwrap()
}
