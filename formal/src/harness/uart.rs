//! `link.bytes` for a UART link: the harness's own receiver of `link_tx`.
//!
//! Written from docs/packet-format.md ("UART") and the mix's `[link]`
//! options, never from the gateware: a character starts where an idle line
//! goes low; its start bit, 8 data bits LSB first, the parity bit (if any)
//! and its stop bits each last the divider's `div` cycles, each bit the same
//! level over all of them; the line is high during reset.  A low level
//! between characters starts a character, so "idle high" is the same rule.
//! Each received byte is strobed (`rx_v`, `rx_b`) for the packet monitor
//! (`packets.rs`), which also compares each data bit in its first cycle
//! (`rx_d`, `rx_i`; `rx_s` a start bit), so a wrong byte fails at its first
//! wrong bit, the cycle `check` rejects.

use std::fmt::Write;

use lut_gen::Schedule;

use super::{width, Clause, PropertyDef};

/// The character's shape, from the link plan (the figures the audit prints).
pub(super) struct Char {
    pub div: u64,
    /// 0 none, 1 even, 2 odd.
    pub parity: u8,
    pub stop_bits: u64,
}

impl Char {
    pub(super) fn of(s: &Schedule) -> Option<Char> {
        let p = lut_gen::plan_link(s)?.ok()?;
        (p.kind == "uart").then_some(())?;
        Some(Char {
            div: u64::from(p.baud_divider.max(1)),
            parity: match p.parity {
                "even" => 1,
                "odd" => 2,
                _ => 0,
            },
            stop_bits: u64::from(p.stop_bits),
        })
    }

    /// Bits per character: start, 8 data, parity, stop.
    fn bits(&self) -> u64 {
        1 + 8 + u64::from(self.parity != 0) + self.stop_bits
    }
}

/// The receiver and the property `link.bytes`; defines `rx_v`/`rx_b`.
pub(super) fn receiver(v: &mut String, props: &mut Vec<PropertyDef>, c: &Char) {
    let (d, nb) = (c.div, c.bits());
    let (cw, bw) = (width(d), width(nb));
    let par_bit = if c.parity != 0 { 9 } else { nb }; // nb: no such bit
    let par_exp = match c.parity {
        1 => "^ush",
        _ => "~^ush",
    };
    let _ = writeln!(
        v,
        "\n  // link.bytes: the UART's characters on link_tx (start bit, 8 data bits LSB\n  \
         // first, parity {}, {} stop bit(s), each bit {d} cycles; idle high).\n  \
         reg ubusy = 1'b0;\n  reg [{}:0] ubit = 0;\n  reg [{}:0] ucnt = 0;\n  \
         reg [7:0] ush = 8'd0;\n  reg ulev = 1'b1;\n  reg rx_v = 1'b0;\n  reg [7:0] rx_b = 8'd0;\n  \
         wire u_in = run && (ubusy || !link_tx);\n  \
         wire [{}:0] ub = ubusy ? ubit : {bw}'d0;\n  wire [{}:0] uc = ubusy ? ucnt : {cw}'d0;\n  \
         // a character starts (rx_s); data bit rx_i is on the line (rx_d, its first cycle)\n  \
         wire rx_s = run && !ubusy && !link_tx;\n  \
         wire rx_d = u_in && uc == {cw}'d0 && ub >= {bw}'d1 && ub <= {bw}'d8;\n  \
         wire [{}:0] rx_i1 = ub - {bw}'d1;\n  wire [2:0] rx_i = rx_i1[2:0];\n  \
         always @(posedge clk) begin\n    \
         rx_v <= u_in && uc == {cw}'d0 && ub == {bw}'d8;\n    rx_b <= {{link_tx, ush[7:1]}};\n    \
         if (u_in && uc == {cw}'d0 && ub >= {bw}'d1 && ub <= {bw}'d8) begin\n      \
         ulev <= link_tx; ush <= {{link_tx, ush[7:1]}};\n    end\n    \
         if (u_in) begin\n      \
         if (uc == {cw}'d{}) begin\n        ucnt <= {cw}'d0;\n        \
         if (ub == {bw}'d{}) ubusy <= 1'b0; else begin ubusy <= 1'b1; ubit <= ub + {bw}'d1; end\n      \
         end else begin\n        ubusy <= 1'b1; ubit <= ub; ucnt <= uc + {cw}'d1;\n      end\n    end\n  end\n  \
         wire ok_link_bytes = st == 2'd1 ? link_tx : !u_in || (ub == {bw}'d0 ? !link_tx :\n    \
         ub <= {bw}'d8 ? (uc == {cw}'d0 || link_tx == ulev) :\n    \
         ub == {bw}'d{par_bit} ? link_tx == {par_exp} : link_tx);",
        ["none", "even", "odd"][usize::from(c.parity)],
        c.stop_bits,
        bw - 1,
        cw - 1,
        bw - 1,
        cw - 1,
        bw - 1,
        d - 1,
        nb - 1,
    );
    props.push(PropertyDef {
        name: "link.bytes".into(),
        wire: "ok_link_bytes".into(),
        covers: vec![Clause::UartCharacters],
        what: format!(
            "link_tx carries whole UART characters: a start bit, 8 data bits LSB first, {}{} \
             stop bit{}, each bit {d} cycles at one level; high during reset and between \
             characters",
            match c.parity {
                1 => "an even parity bit, ",
                2 => "an odd parity bit, ",
                _ => "",
            },
            c.stop_bits,
            if c.stop_bits == 1 { "" } else { "s" }
        ),
    });
}
