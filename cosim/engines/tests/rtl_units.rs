//! The outside Verilog's port scan (`rtl`): ports, widths and the constant
//! expressions they are written in.

use std::collections::BTreeMap;

use engines::for_tests::{eval_const, scan_ports, PortDir};

type Params = BTreeMap<String, Result<i64, String>>;

fn ports(v: &str) -> Vec<(String, Option<PortDir>, Result<u32, String>)> {
    scan_ports(v, "top")
        .unwrap()
        .into_iter()
        .map(|p| (p.name.clone(), p.dir, p.width()))
        .collect()
}

#[test]
fn ansi_ports_with_parameters() {
    let v = "// header\n`timescale 1ns/1ps\nmodule other(input a); endmodule\n\
             module top #(parameter W = 14, parameter integer N = 2 * 3, localparam C = $clog2(5))\n\
             ((* keep *) input wire clk, input rst, input [N-1:0] miso,\n\
              output reg [W-1:0] value, b, output logic signed [C:0] ch, /* c */ output wire [0:0] en);\n\
             endmodule\n";
    let p = ports(v);
    let names: Vec<_> = p.iter().map(|x| x.0.as_str()).collect();
    assert_eq!(names, ["clk", "rst", "miso", "value", "b", "ch", "en"]);
    assert_eq!(p[0].2, Ok(1));
    assert_eq!(p[2].1, Some(PortDir::Input));
    assert_eq!(p[2].2, Ok(6));
    assert_eq!(p[3].1, Some(PortDir::Output));
    assert_eq!(p[3].2, Ok(14));
    assert_eq!(
        p[4].2,
        Ok(14),
        "a bare name inherits the previous declaration"
    );
    assert_eq!(p[5].2, Ok(4));
    assert_eq!(p[6].2, Ok(1));
}

#[test]
fn non_ansi_ports_with_body_declarations() {
    let v = "module top(clk, rst, \\value , q, n);\n\
             parameter W = 7;\n  localparam V = W * 2, U = 8'h0c;\n\
             input clk; input wire rst;\n  output [V-1:0] value;\n  output q;\n  reg [U-1:0] q;\n\
             output integer n;\n\
             function [3:0] f(input [9:0] x); f = x[3:0]; endfunction\n\
             endmodule";
    let p = ports(v);
    assert_eq!(p[0], ("clk".into(), Some(PortDir::Input), Ok(1)));
    assert_eq!(p[1], ("rst".into(), Some(PortDir::Input), Ok(1)));
    assert_eq!(p[2], ("value".into(), Some(PortDir::Output), Ok(14)));
    assert_eq!(p[3], ("q".into(), Some(PortDir::Output), Ok(12)));
    assert_eq!(p[4], ("n".into(), Some(PortDir::Output), Ok(32)));
    assert!(
        p.iter().all(|x| x.0 != "x"),
        "function arguments are not ports"
    );
}

#[test]
fn unevaluable_widths_and_missing_modules_are_named() {
    let v = "module top(input [`W-1:0] a, input [X:0] b, output [(3+1)*2-1:0] c); endmodule";
    let p = ports(v);
    assert!(
        p[0].2.as_ref().unwrap_err().contains("macro `W"),
        "{:?}",
        p[0]
    );
    assert!(
        p[1].2
            .as_ref()
            .unwrap_err()
            .contains("`X` is not a parameter"),
        "{:?}",
        p[1]
    );
    assert_eq!(p[2].2, Ok(8));
    let e = scan_ports("module a(); endmodule module b; endmodule", "top").unwrap_err();
    assert!(
        e.contains("no module named top") && e.contains("a, b"),
        "{e}"
    );
    let e = scan_ports("module top(); endmodule\nmodule top(); endmodule", "top").unwrap_err();
    assert!(e.contains("defined 2 times"), "{e}");
}

#[test]
fn constant_expressions() {
    let p = Params::from([
        ("A".to_string(), Ok(5)),
        ("B".to_string(), Err("no".into())),
    ]);
    let e = |s: &str| eval_const(s, &p);
    assert_eq!(e("A ** 2 - 1"), Ok(24));
    assert_eq!(e("2 ** 3 ** 2"), Ok(512));
    assert_eq!(e("(A > 4) ? 16'hff : 'b1"), Ok(255));
    assert_eq!(e("1 << A >> 1"), Ok(16));
    assert_eq!(e("$clog2(A) + $clog2(1) + $clog2(8)"), Ok(6));
    assert_eq!(e("10 / 3 + 10 % 3 * 2"), Ok(5));
    assert!(e("B + 1").unwrap_err().contains("parameter `B`"));
    assert!(e("1 / 0").is_err());
}
