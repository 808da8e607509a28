//! `slotforge golden --rtl`: a design that behaves differently on any output
//! pin fails its golden with a useful first difference.  The mutants are the
//! emitted Verilog wrapped in a top that flips one output pin from a chosen
//! cycle on; the golden must name that pin (by role) at that cycle.

use std::path::Path;

use crate::common_cli::{record_golden, slotforge, tiny};
use crate::tools;

/// Widths of the ports of `ports.json`, by name.
fn widths(ports_json: &Path) -> Vec<(String, String, u64)> {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ports_json).unwrap()).unwrap();
    v["ports"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["name"].as_str().unwrap().to_string(),
                p["dir"].as_str().unwrap().to_string(),
                p["width"].as_u64().unwrap(),
            )
        })
        .collect()
}

/// The emitted design renamed `inner`, inside a top that XORs bit 0 of
/// `flip` with `cond` (a Verilog expression of `n`, the cycles since reset,
/// and the inner outputs).
fn wrapped(emitted: &str, ports: &[(String, String, u64)], flip: &str, cond: &str) -> String {
    let inner = emitted.replace("module slotforge_top (", "module inner (");
    let mut decl = Vec::new();
    let mut wires = String::new();
    let mut conns = Vec::new();
    let mut assigns = String::new();
    for (name, dir, w) in ports {
        let range = if *w > 1 || name.starts_with("adc_") || name.starts_with("mux_en") {
            format!("[{}:0] ", w - 1)
        } else {
            String::new()
        };
        if dir == "in" {
            decl.push(format!("input wire {range}{name}"));
            conns.push(format!(".{name}({name})"));
        } else {
            decl.push(format!("output wire {range}{name}"));
            wires.push_str(&format!("  wire {range}i_{name};\n"));
            conns.push(format!(".{name}(i_{name})"));
            if name == flip {
                assigns.push_str(&format!(
                    "  assign {name} = i_{name} ^ (({cond}) ? 1'b1 : 1'b0);\n"
                ));
            } else {
                assigns.push_str(&format!("  assign {name} = i_{name};\n"));
            }
        }
    }
    format!(
        "{inner}\n`default_nettype none\nmodule slotforge_top ({});\n{wires}  reg [31:0] n;\n  always @(posedge clk) if (rst) n <= 0; else n <= n + 1;\n  inner dut ({});\n{assigns}endmodule\n`default_nettype wire\n",
        decl.join(", "),
        conns.join(", ")
    )
}

#[test]
fn a_design_that_differs_on_any_pin_fails_its_golden_at_that_pin() {
    if !tools::require_tool("iverilog") {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let gold = d.path().join("golden");
    record_golden(&gold);
    let v = d.path().join("v");
    slotforge()
        .arg("verilog")
        .arg(tiny())
        .arg("-o")
        .arg(&v)
        .assert()
        .success();
    let emitted = std::fs::read_to_string(v.join("slotforge_top.v")).unwrap();
    let ports = widths(&v.join("ports.json"));
    // the emitted design itself passes through --rtl
    slotforge()
        .args(["golden", "--backend", "icarus", "--dir"])
        .arg(&gold)
        .arg("--rtl")
        .arg(v.join("slotforge_top.v"))
        .arg(tiny())
        .assert()
        .success();
    // (pin flipped, condition, where/signal the first difference must name)
    let k = 1000;
    let cases = [
        ("adc_cs_n", format!("n == {k}"), "fast cs_n"),
        ("adc_sclk", format!("n == {k}"), "fast sclk"),
        ("mux_sel", format!("n >= {k}"), "fast mux_sel"),
        ("mux_en", format!("n == {k}"), "fast mux_en"),
        ("sample_valid", format!("n == {k}"), "sample"),
        (
            "sample_channel",
            format!("n >= {k} && i_sample_valid"),
            "sample",
        ),
        (
            "sample_value",
            format!("n >= {k} && i_sample_valid"),
            "sample",
        ),
    ];
    for (pin, cond, names) in cases {
        let f = d.path().join(format!("{pin}.v"));
        std::fs::write(&f, wrapped(&emitted, &ports, pin, &cond)).unwrap();
        let out = slotforge()
            .args(["golden", "--backend", "icarus", "--dir"])
            .arg(&gold)
            .arg("--rtl")
            .arg(&f)
            .arg(tiny())
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{pin}: {stdout}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let first = stdout
            .lines()
            .find(|l| l.trim_start().starts_with("first: cycle"))
            .unwrap_or_else(|| panic!("{pin}: no first difference in\n{stdout}"));
        let cycle: u64 = first.split_whitespace().nth(2).unwrap().parse().unwrap();
        assert!(
            (k - 2..k + 200).contains(&cycle),
            "{pin}: first difference at cycle {cycle}: {first}"
        );
        let (scope, signal) = names.split_once(' ').unwrap_or((names, ""));
        assert!(
            first.contains(&format!(": {scope}.{signal}"))
                || (signal.is_empty() && first.contains(&format!(": {scope}."))),
            "{pin}: {first}"
        );
        assert!(
            first.contains("expected") && first.contains("actual"),
            "{first}"
        );
        assert!(stdout.contains("event(s) differ"), "{stdout}");
    }
}
