//! `slotforge sim --rtl FILE.v`: outside Verilog on the verilator and icarus
//! back ends.  The emitted Verilog passed as a file passes; a top off the
//! pin contract (a port renamed, removed, of the wrong width or direction,
//! an extra input, no `slotforge_top`) exits 2 naming the port, expected and
//! found; a hand-written non-ANSI wrapper around the emitted design passes,
//! and the same wrapper with one `sample_value` bit inverted diverges (exit 1).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use lut_gen::{Dir, Layout, TOP_MODULE};
use predicates::prelude::*;

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::common_cli::{slotforge, tiny};
use crate::tools;

fn schedule() -> lut_gen::Schedule {
    lut_gen::synthesize(&lut_gen::load(&tiny()).unwrap()).unwrap()
}

/// The Verilog `slotforge verilog` emits for the tiny mix.
fn emitted() -> String {
    hdl::emit(&schedule(), None).unwrap().verilog().to_string()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn sim(backend: &str, rtl: &Path) -> assert_cmd::assert::Assert {
    slotforge()
        .arg("sim")
        .arg(tiny())
        .args(["--backend", backend, "--frames", "2", "--rtl"])
        .arg(rtl)
        .assert()
}

/// The emitted design renamed to `emitted_top`, under a hand-written
/// non-ANSI `slotforge_top` (parameters in the ranges) that passes every
/// port through, or with bit 0 of `sample_value` inverted when `mutate`.
fn wrapper(mutate: bool) -> String {
    let s = schedule();
    let l = Layout::new(&s);
    let inner = emitted().replacen(&format!("module {TOP_MODULE} ("), "module emitted_top (", 1);
    assert!(inner.contains("module emitted_top ("));
    let mut w = String::new();
    let names: Vec<&str> = l.ports().map(|p| p.name).collect();
    let _ = writeln!(
        w,
        "\n// hand-written wrapper\nmodule {TOP_MODULE}({});",
        names.join(", ")
    );
    let _ = writeln!(
        w,
        "  parameter NB = {};\n  localparam SEL = 3 * NB;",
        l.branches
    );
    for p in l.ports() {
        let width = l.width(p.role);
        let range = if !p.vector {
            String::new()
        } else if p.role == lut_gen::Role::MuxSel {
            "[SEL-1:0] ".into()
        } else if width == l.branches as u32 {
            "[NB-1:0] ".into()
        } else {
            format!("[{}:0] ", width - 1)
        };
        let dir = match p.dir {
            Dir::In => "input",
            Dir::Out => "output",
        };
        let _ = writeln!(w, "  {dir} {range}{};", p.name);
        if p.dir == Dir::Out {
            let _ = writeln!(w, "  wire {range}{}_i;", p.name);
        }
    }
    let conns: Vec<String> = l
        .ports()
        .map(|p| match p.dir {
            Dir::In => format!(".{0}({0})", p.name),
            Dir::Out => format!(".{0}({0}_i)", p.name),
        })
        .collect();
    let _ = writeln!(w, "  emitted_top core({});", conns.join(", "));
    for p in l.ports().filter(|p| p.dir == Dir::Out) {
        let flip = if mutate && p.role == lut_gen::Role::SampleValue {
            " ^ 1'b1"
        } else {
            ""
        };
        let _ = writeln!(w, "  assign {0} = {0}_i{flip};", p.name);
    }
    w.push_str("endmodule\n");
    format!("{inner}{w}")
}

#[test]
fn emitted_verilog_as_rtl_passes_on_verilator_and_icarus() {
    let d = tempfile::tempdir().unwrap();
    let v = write(d.path(), "top.v", &emitted());
    if tools::require_tools(&["verilator", "g++"]) {
        sim("verilator", &v)
            .code(0)
            .stdout(predicate::str::contains("PASS"));
    }
    if tools::require_tool("iverilog") {
        sim("icarus", &v)
            .code(0)
            .stdout(predicate::str::contains("PASS"));
    }
}

#[test]
fn non_ansi_wrapper_passes_and_its_mutant_diverges() {
    let d = tempfile::tempdir().unwrap();
    let good = write(d.path(), "wrap.v", &wrapper(false));
    let bad = write(d.path(), "mutant.v", &wrapper(true));
    if tools::require_tool("iverilog") {
        sim("icarus", &good).code(0);
        sim("icarus", &bad)
            .code(1)
            .stdout(predicate::str::contains("sample_value"));
    }
    if tools::require_tools(&["verilator", "g++"]) {
        sim("verilator", &good).code(0);
        sim("verilator", &bad)
            .code(1)
            .stdout(predicate::str::contains("sample_value"));
    }
}

/// `--rtl` files off the contract: exit 2 before any tool runs, with the
/// file, the port, and expected vs found in the message.
#[test]
fn tops_off_the_contract_exit_2_naming_the_port() {
    let d = tempfile::tempdir().unwrap();
    let v = emitted();
    let l = Layout::new(&schedule());
    let en = l.width(lut_gen::Role::MuxEn);
    let cases: Vec<(&str, String, Vec<String>)> = vec![
        (
            "renamed.v",
            v.replacen("output wire sample_valid", "output wire sample_vld", 1),
            vec![
                "no port `sample_valid`".into(),
                "expected output (1 bit)".into(),
            ],
        ),
        (
            "removed.v",
            v.replacen("    output wire [1:0] adc_sclk,\n", "", 1),
            vec![
                "no port `adc_sclk`".into(),
                "expected output [1:0] (2 bits)".into(),
            ],
        ),
        (
            "width.v",
            v.replacen(
                &format!("output wire [{}:0] mux_en", en - 1),
                &format!("output wire [{en}:0] mux_en"),
                1,
            ),
            vec![
                "port `mux_en`".into(),
                format!("expected output [{}:0] ({en} bits)", en - 1),
                format!("found output [{en}:0] ({} bits)", en + 1),
            ],
        ),
        (
            "direction.v",
            v.replacen(
                "input  wire [1:0] adc_miso",
                "output wire [1:0] adc_miso",
                1,
            ),
            vec![
                "port `adc_miso`".into(),
                "expected input [1:0]".into(),
                "found output [1:0]".into(),
            ],
        ),
        (
            "extra.v",
            v.replacen(
                "    input  wire rst,\n",
                "    input  wire rst,\n    input  wire enable,\n",
                1,
            ),
            vec!["port `enable` (input) is not in the pin contract".into()],
        ),
        (
            "untop.v",
            v.replacen("module slotforge_top (", "module my_top (", 1),
            vec!["no module named slotforge_top".into(), "my_top".into()],
        ),
        (
            "macro.v",
            v.replacen(
                "output wire [13:0] sample_value",
                "output wire [`VB-1:0] sample_value",
                1,
            ),
            vec![
                "port `sample_value`".into(),
                "macro `VB".into(),
                "expected output [13:0] (14 bits)".into(),
            ],
        ),
    ];
    for (name, text, wants) in cases {
        assert_ne!(text, v, "{name}: the edit applied");
        let f = write(d.path(), name, &text);
        for backend in ["verilator", "icarus"] {
            if backend == "icarus" && !tools::tool_present("iverilog") {
                continue; // the icarus back end names the missing tool first
            }
            let a = sim(backend, &f)
                .code(2)
                .stderr(predicate::str::contains(f.display().to_string()))
                .stderr(predicate::str::contains("panicked").not());
            wants
                .iter()
                .fold(a, |a, w| a.stderr(predicate::str::contains(w.as_str())));
        }
    }
}

#[test]
fn rtl_on_back_ends_without_verilog_exits_2() {
    let d = tempfile::tempdir().unwrap();
    let v = write(d.path(), "top.v", &emitted());
    for backend in ["model", "rusthdl"] {
        sim(backend, &v)
            .code(2)
            .stderr(predicate::str::contains(format!(
                "the {backend} back end simulates no Verilog"
            )));
    }
    sim("verilator", &d.path().join("missing.v"))
        .code(2)
        .stderr(predicate::str::contains("missing.v"));
}
