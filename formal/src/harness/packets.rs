//! `link.packets`: the packets on the link's bytes, parsed by the harness.
//!
//! Written from docs/packet-format.md, never from the gateware.  The
//! harness makes the packetizer's tokens itself: a boundary in the first
//! cycle of every slice (its own cycle count), a sample wherever its own
//! merged stream (`exp_valid`, `exp_ch`, `exp_val`: the MISO bits it
//! recorded) has a word.  The tokens wait in the harness's queue; each byte
//! the line carries is compared, bit by bit as it arrives (`rx_d`, `rx_i`
//! from `uart.rs`; the parser moves on at `rx_v`), with the byte the head
//! token owes: a boundary the previous packet's trailer
//! (`0x5A`, overflow count 0, CRC-16/MODBUS low then high, computed here
//! over the header, the records and the trailer's first two bytes) once a
//! header has been sent, then a header (`0xA5`, the frame counter the
//! harness counts from 0, the slice field: with modes the mode in force in
//! the slice's first cycle and the frame before's above the slice); a
//! sample its record (channel index, code, big-endian).  A character with no
//! token waiting, or more tokens waiting than the link's FIFO can hold and
//! the serializer has in hand, fails too.
//!
//! On an AXI4-Stream the bytes are the beats taken (`m_axis_tvalid &&
//! m_axis_tready`, [`beats`]): each is compared whole in the cycle it is
//! taken, and its `m_axis_tlast` with the parser's own "last byte of a
//! packet" (`link.bytes` of such a link: the beats and where `tlast` is).

use std::fmt::Write;

use lut_gen::{Layout, Schedule};

use super::{width, Clause, PropertyDef};

/// The harness's frame counter (the header's second byte), an 8-bit
/// register of the harness module: `prove` generalises it with the
/// design's (`ProveOptions::frame_counter`).
pub(crate) const FRAME_COUNTER: &str = "efc";

/// Tokens the harness's queue holds beyond the link's FIFO depth: the one
/// the serializer holds, the one whose last byte the line still carries
/// (the harness lets a token go at its last byte's eighth data bit), and
/// one to spare.
const IN_HAND: usize = 3;

/// Where the parser's bytes come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Line {
    /// The UART receiver's (`uart.rs`): compared bit by bit on `link_tx`.
    Uart,
    /// The AXI4-Stream's beats taken ([`beats`]), compared whole on
    /// `m_axis_tdata`; `tlast` on every trailer's last byte, or (`per_frame`)
    /// only on the trailer of a frame's last slice.
    Axis { per_frame: bool },
}

/// The AXI4-Stream's bytes as the parser reads them: a beat is taken when
/// `m_axis_tvalid` and `m_axis_tready` are both high, and its byte is
/// `m_axis_tdata` in that cycle (`rx_s`/`rx_d`/`rx_v` the same strobe: the
/// whole byte arrives at once, the parser moves on at the edge).
pub(super) fn beats(v: &mut String) {
    v.push_str(
        "\n  // link.bytes on the AXI4-Stream: each beat taken is the next byte.\n  \
         wire rx_s = run && m_axis_tvalid && m_axis_tready;\n  \
         wire rx_d = rx_s, rx_v = rx_s;\n  wire [7:0] rx_b = m_axis_tdata;\n",
    );
}

/// The token queue, the parser and the property `link.packets` (and, on
/// an AXI4-Stream, `link.bytes`: where `tlast` is).
pub(super) fn monitor(
    v: &mut String,
    props: &mut Vec<PropertyDef>,
    s: &Schedule,
    layout: &Layout,
    depth: usize,
    line: Line,
) {
    let (chb, vb, mb) = (layout.channel_bits, layout.value_bits, layout.mode_bits);
    let q = depth + IN_HAND;
    let qb = width(q as u64 + 1);
    let g = &s.grid;
    let scb = width(g.slice_cycles);
    let k = g.slices_per_frame;
    let slb = 16 - 2 * mb;
    // entry: {bnd, smp, mode, mode before, ch, val}
    let ew = 2 + 2 * mb + chb + vb;
    // a field the token does not own is 0 (no stale word kept in the queue)
    let modes = if mb > 0 {
        format!("lbnd ? {{mcur, mprev}} : {}'d0, ", 2 * mb)
    } else {
        String::new()
    };
    let _ = writeln!(
        v,
        "\n  // link.packets: the tokens (boundary at each slice's first cycle, sample per\n  \
         // merged word) wait here; each byte on the line is the one the head token owes.\n  \
         function [15:0] crc16_byte(input [15:0] c, input [7:0] b);\n    \
         integer i;\n    begin\n      crc16_byte = c ^ {{8'd0, b}};\n      \
         for (i = 0; i < 8; i = i + 1)\n        \
         crc16_byte = crc16_byte[0] ? (crc16_byte >> 1) ^ 16'hA001 : crc16_byte >> 1;\n    end\n  \
         endfunction\n  \
         reg [{}:0] lsc = 0;\n  always @(posedge clk) if (run) lsc <= lsc == {scb}'d{} ? {scb}'d0 : lsc + {scb}'d1;\n  \
         wire lbnd = run && lsc == {scb}'d0;\n  wire push = lbnd || (run && exp_valid);\n  \
         wire [{}:0] entry = {{lbnd, exp_valid, {modes}exp_valid ? {{exp_ch, exp_val}} : {}'d0}};",
        scb - 1,
        g.slice_cycles - 1,
        ew - 1,
        chb + vb,
    );
    // a shift queue (the head in q0, emptied entries 0): no pointer that
    // comes round only after several frames, no stale token kept
    let regs: Vec<String> = (0..q).map(|i| format!("q{i} = 0")).collect();
    let _ = writeln!(
        v,
        "  reg [{}:0] {};\n  reg [{}:0] qn = 0;\n  reg qovf = 1'b0;\n  wire [{}:0] head = q0;",
        ew - 1,
        regs.join(", "),
        qb - 1,
        ew - 1,
    );
    let (lo_val, lo_ch) = (0, vb);
    let lo_mode = vb + chb;
    let _ = writeln!(
        v,
        "  wire hbnd = head[{}], hsmp = head[{}];\n  \
         wire [15:0] hch = {};\n  wire [15:0] hval = {};",
        ew - 1,
        ew - 2,
        to16(&format!("head[{}:{lo_ch}]", lo_ch + chb - 1), chb),
        to16(&format!("head[{}:{lo_val}]", vb - 1), vb),
    );
    let field = if mb > 0 {
        format!(
            "{{head[{}:{}], head[{}:{lo_mode}], esl}}",
            lo_mode + 2 * mb - 1,
            lo_mode + mb,
            lo_mode + mb - 1
        )
    } else {
        "esl".to_string()
    };
    let _ = writeln!(
        v,
        "  // the parser: the word's byte, what the head token owes, the packet's CRC\n  \
         reg [1:0] wpos = 2'd0;\n  reg hs = 1'b0, tdone = 1'b0, hdone = 1'b0;\n  \
         reg [7:0] efc = 8'd0;\n  reg [{}:0] esl = 0;\n  reg [15:0] crc = 16'hFFFF;\n  \
         // 0 header, 1 record, 2 trailer\n  \
         wire [1:0] ekind = (hbnd && hs && !tdone && !hdone) ? 2'd2 : (hbnd && !hdone) ? 2'd0 : 2'd1;\n  \
         wire [15:0] fld = {field};\n  reg [7:0] ebyte;\n  always @* case ({{ekind, wpos}})\n    \
         4'b00_00: ebyte = 8'hA5;\n    4'b00_01: ebyte = efc;\n    \
         4'b00_10: ebyte = fld[15:8];\n    4'b00_11: ebyte = fld[7:0];\n    \
         4'b01_00: ebyte = hch[15:8];\n    4'b01_01: ebyte = hch[7:0];\n    \
         4'b01_10: ebyte = hval[15:8];\n    4'b01_11: ebyte = hval[7:0];\n    \
         4'b10_00: ebyte = 8'h5A;\n    4'b10_01: ebyte = 8'd0;\n    \
         4'b10_10: ebyte = crc[7:0];\n    default: ebyte = crc[15:8];\n  endcase\n  \
         wire wend = rx_v && wpos == 2'd3;\n  \
         wire pop = wend && (ekind == 2'd1 || (ekind == 2'd0 && !hsmp));",
        slb - 1,
    );
    let _ = writeln!(
        v,
        "  // where a pushed token lands: after the waiting ones, one lower on a pop\n  \
         wire [{}:0] qa = pop ? qn - {qb}'d1 : qn;\n  always @(posedge clk) begin",
        qb - 1
    );
    for i in 0..q {
        let next = if i + 1 < q {
            format!("q{}", i + 1)
        } else {
            format!("{ew}'d0")
        };
        let _ = writeln!(
            v,
            "    q{i} <= (push && qa == {qb}'d{i}) ? entry : pop ? {next} : q{i};"
        );
    }
    let _ = writeln!(
        v,
        "    if (push && !pop && qn == {qb}'d{q}) qovf <= 1'b1;\n    \
         else qn <= qn + (push ? {qb}'d1 : {qb}'d0) - (pop ? {qb}'d1 : {qb}'d0);\n    \
         if (rx_v) begin\n      wpos <= wpos + 2'd1;\n      \
         if (ekind == 2'd0 && wpos == 2'd0) crc <= crc16_byte(16'hFFFF, rx_b);\n      \
         else if (ekind != 2'd2 || !wpos[1]) crc <= crc16_byte(crc, rx_b);\n    end\n    \
         if (wend && ekind == 2'd2) tdone <= 1'b1;\n    \
         if (wend && ekind == 2'd0) begin\n      hdone <= 1'b1; hs <= 1'b1;\n      \
         esl <= esl == {slb}'d{} ? {slb}'d0 : esl + {slb}'d1;\n      \
         if (esl == {slb}'d{}) efc <= efc + 8'd1;\n    end\n    \
         if (pop) begin tdone <= 1'b0; hdone <= 1'b0; end\n  end\n  \
         wire ok_link_packets = !qovf && !(rx_s && qn == {qb}'d0) && (!rx_d || {});",
        k - 1,
        k - 1,
        match line {
            Line::Uart => "link_tx == ebyte[rx_i]",
            Line::Axis { .. } => "m_axis_tdata == ebyte",
        }
    );
    if let Line::Axis { per_frame } = line {
        tlast(v, props, per_frame.then(|| format!(" && esl == {slb}'d0")));
    }
    props.push(PropertyDef {
        name: "link.packets".into(),
        wire: "ok_link_packets".into(),
        covers: vec![Clause::LinkPackets],
        what: format!(
            "the line's bytes are the packets of docs/packet-format.md: per slice a header \
             (0xA5, the frame counter from 0 up by one per frame, the slice{}), a record per \
             merged word in its order (channel index, the code MISO carried), the trailer \
             (0x5A, overflow count 0, CRC-16/MODBUS computed by the harness); no byte without \
             a token, no more than {q} tokens waiting",
            if mb > 0 {
                ", the mode in force in the slice's first cycle and the frame before's"
            } else {
                ""
            }
        ),
    });
}

/// `link.bytes` of an AXI4-Stream: a beat taken has `m_axis_tlast` high
/// exactly when it is a trailer's last byte (the CRC's high byte), with
/// `per_frame` only the trailer of a frame's last slice (the parser's slice
/// count `esl` has then come round to 0: it moves on at each header).
fn tlast(v: &mut String, props: &mut Vec<PropertyDef>, first_slice: Option<String>) {
    let per_frame = first_slice.is_some();
    let _ = writeln!(
        v,
        "  wire elast = ekind == 2'd2 && wpos == 2'd3{};\n  \
         wire ok_link_bytes = !rx_d || m_axis_tlast == elast;",
        first_slice.unwrap_or_default()
    );
    props.push(PropertyDef {
        name: "link.bytes".into(),
        wire: "ok_link_bytes".into(),
        covers: vec![Clause::AxisBeats],
        what: format!(
            "every beat taken (m_axis_tvalid && m_axis_tready) is the next byte of the packet \
             stream (link.packets), for any slave that takes each beat within its guarantee, \
             and m_axis_tlast is high on it exactly when it is the last byte of a {}",
            if per_frame {
                "frame's last packet (tlast = \"frame\")"
            } else {
                "packet (tlast = \"slice\")"
            }
        ),
    });
}

/// `bits` of `expr` zero-extended to a record's 16-bit field (a 16-bit
/// code as it is: Verilog has no zero-width constant).
fn to16(expr: &str, bits: u32) -> String {
    match 16 - bits {
        0 => expr.to_string(),
        pad => format!("{{{pad}'d0, {expr}}}"),
    }
}
