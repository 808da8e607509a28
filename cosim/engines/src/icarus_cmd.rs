//! The Icarus testbench's model of a converter with a command word
//! (MCP3208, AD7689, an `[[adc_part]]` with `command`), as `judge::Adc`
//! models it: the part latches DIN (`adc_mosi`) on each rising SCLK edge of
//! the read; with `ahead` 0 the input is the one the word's last bit
//! completes, in the same conversion; with `ahead` > 0 the word at the end
//! of the read selects the input of the conversion `ahead` later, and the
//! first `ahead` conversions after reset (or after a malformed word)
//! convert an input no channel is on.  The code is the stimulus' for that
//! input at the conversion's start, shifted out MSB first after the
//! leading bits, one bit per SCLK falling edge.

use std::fmt::Write as _;

use lut_gen::{CmdBit, Command, Role, Schedule};

/// An id no channel has (judge::Adc's `unselected`).
fn unselected(s: &Schedule, b: usize) -> u64 {
    s.channels.len() as u64 + 1 + b as u64
}

/// The Verilog of branch `b`'s commanded part; `mosi_lane`: its `adc_mosi`
/// bit; `table`: the lines that replace the pattern code with the
/// stimulus' (none for the pattern stimulus).
pub(crate) fn part(s: &Schedule, b: usize, mosi_lane: u32, table: &str) -> String {
    let adc = &s.mix.branches[b].adc;
    let cmd = adc.command.as_ref().expect("a part with a command word");
    let cnv = adc.start == lut_gen::Start::Cnv;
    // read with CNV low: the part drives SDO and takes DIN while CNV is low
    let low = cnv && adc.read == lut_gen::CnvRead::CnvLow;
    let ws = adc.word_sclks() as usize;
    let l = cmd.bits.len();
    let trailing = ws - adc.leading_bits as usize - adc.bits as usize;
    let (cs, sclk, miso, mosi, rst) = (
        Role::CsN.name(),
        Role::Sclk.name(),
        Role::Miso.name(),
        Role::Mosi.name(),
        Role::Reset.name(),
    );
    let (start, stop, sel, rise) = if low {
        ("posedge", "negedge", format!("!{cs}[{b}]"), "posedge")
    } else if cnv {
        ("posedge", "negedge", format!("{cs}[{b}]"), "posedge")
    } else {
        ("negedge", "posedge", format!("!{cs}[{b}]"), "posedge")
    };
    // CNV parts shift on SCK falling edges too (SCK idles low)
    let shift = "negedge";
    // after the last bit: a CS part releases the line, a CNV part's SDI
    // (tied low) comes through
    let after = if cnv && !low { "1'b0" } else { "1'bz" };
    let mask = (1u32 << adc.bits) - 1;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "  // {} with command word {} (selects the conversion {} later)\n  reg [{}:0] stream{b};\n  reg [15:0] falls{b};\n  reg drive{b} = 0;\n  reg [15:0] nin{b};\n  reg [{}:0] cw{b};\n  reg [63:0] t{b};\n  reg [63:0] id{b};\n  reg [63:0] n{b} = 0;\n  reg [15:0] code{b};\n  assign {miso}[{b}] = drive{b} ? (falls{b} >= 16'd{ws} ? {after} : stream{b}[{}-falls{b}]) : 1'bz;",
        adc.name,
        cmd.template(),
        cmd.ahead,
        ws - 1,
        l - 1,
        ws - 1
    );
    let queue = queue_decls(s, b, cmd);
    t.push_str(&queue);
    let pad = if ws > adc.bits as usize {
        format!("{}'h0, ", ws - adc.bits as usize)
    } else {
        String::new()
    };
    let code = format!("code{b}[{}:0]", adc.bits - 1);
    let fill = format!(
        "    code{b} = pattern16(t{b}, id{b}) & 16'h{mask:x};\n{table}    n{b} = n{b} + 1;\n    stream{b} = {{{pad}{code}}} << {trailing};\n"
    );
    let pop = if cmd.ahead > 0 {
        let mut p = format!("    id{b} = q{b}_0;\n{}", front_case(s, b));
        for k in 1..cmd.ahead {
            let _ = writeln!(p, "    q{b}_{} = q{b}_{k};", k - 1);
        }
        let _ = writeln!(p, "    q{b}_{} = 64'd{};", cmd.ahead - 1, unselected(s, b));
        p + &fill
    } else {
        String::new()
    };
    let push = if cmd.ahead > 0 {
        // the queue holds ahead entries: the word joins at the end
        let mut p = select(s, b, cmd, "    ");
        let _ = writeln!(p, "    q{b}_{} = id{b};", cmd.ahead - 1);
        p
    } else {
        String::new()
    };
    // read with CNV low: the read ends when the next conversion starts, and
    // SDO is driven from CNV falling
    let (ended, drive) = match low {
        true => (push.as_str(), "0"),
        false => ("", "1"),
    };
    let _ = write!(
        t,
        "  always @({start} {cs}[{b}]) if (!{rst}) begin\n{ended}    t{b} = cyc;\n    falls{b} = 0;\n    nin{b} = 0;\n    stream{b} = {ws}'h0;\n    drive{b} = {drive};\n{pop}  end\n"
    );
    let same = if cmd.ahead == 0 {
        format!(
            "    if (nin{b} == 16'd{l}) begin\n{}{fill}    end\n",
            select(s, b, cmd, "      ")
        )
    } else {
        String::new()
    };
    let _ = write!(
        t,
        "  always @({rise} {sclk}[{b}]) if ({sel}) begin\n    if (nin{b} < 16'd{l}) cw{b}[{}-nin{b}] = {mosi}[{mosi_lane}];\n    nin{b} = nin{b} + 1;\n{same}  end\n",
        l - 1
    );
    let stop_body = match low {
        true => format!("    drive{b} = 1;\n"),
        false => format!("    drive{b} = 0;\n{push}"),
    };
    let _ = write!(
        t,
        "  always @({stop} {cs}[{b}]) if (!{rst}) begin\n{stop_body}  end\n  always @({shift} {sclk}[{b}]) if ({sel}) falls{b} = falls{b} + 1;\n\n"
    );
    t
}

/// `id<b>` of a word that selected converter input `i` wired to a front
/// mux: `FRONT + i` until the conversion's start reads the front pins.
const FRONT: u64 = 1 << 40;

/// At a conversion's start, a fronted input's channel from the front mux's
/// pins (one device enabled; anything else an unselected input, as
/// judge::Adc has it); nothing for a branch without a front mux.
fn front_case(s: &Schedule, b: usize) -> String {
    if !s.mix.branches[b].fronted {
        return String::new();
    }
    let l = lut_gen::Layout::new(s);
    let (lo, n, sl) = (l.en_lo[b], l.en_n[b], l.sel_lo[b]);
    let mut v = format!(
        "    if (id{b} >= 64'd{FRONT}) case ({{id{b}[3:0], {en}[{}:{lo}], {sel}[{}:{sl}]}})\n",
        lo + n - 1,
        sl + 2,
        en = Role::MuxEn.name(),
        sel = Role::MuxSel.name(),
    );
    for (c, ch) in s.mix.channels.iter().enumerate() {
        let Some(f) = ch.front_input.filter(|_| ch.branch == b) else {
            continue;
        };
        let key = ((ch.input as u64) << (n + 3)) | (1u64 << (f / 8)) << 3 | (f % 8) as u64;
        let _ = writeln!(v, "      {}'d{key}: id{b} = 64'd{c};", n + 7);
    }
    let _ = writeln!(
        v,
        "      default: id{b} = 64'd{};\n    endcase",
        unselected(s, b)
    );
    v
}

/// The pipeline's queue (`ahead` > 0): the ids of the coming conversions,
/// none selected after reset.
fn queue_decls(s: &Schedule, b: usize, cmd: &Command) -> String {
    let mut q = String::new();
    for k in 0..cmd.ahead {
        let _ = writeln!(q, "  reg [63:0] q{b}_{k} = 64'd{};", unselected(s, b));
    }
    if cmd.ahead > 0 {
        let reset: String = (0..cmd.ahead)
            .map(|k| format!("    q{b}_{k} = 64'd{};\n", unselected(s, b)))
            .collect();
        let _ = writeln!(
            q,
            "  always @(posedge {}) if ({}) begin\n{reset}  end",
            Role::Clock.name(),
            Role::Reset.name()
        );
    }
    q
}

/// `id<b>` from the word in `cw<b>` (`nin<b>` bits latched): the channel on
/// the input its channel bits name, or an unselected input when the word
/// is short or a fixed bit differs (`Command::channel_of`).
fn select(s: &Schedule, b: usize, cmd: &Command, ind: &str) -> String {
    let l = cmd.bits.len();
    let mut fixed = vec![];
    let mut chan: Vec<(u8, usize)> = vec![];
    for (k, bit) in cmd.bits.iter().enumerate() {
        let at = l - 1 - k;
        match *bit {
            CmdBit::Zero => fixed.push(format!("cw{b}[{at}] == 1'b0")),
            CmdBit::One => fixed.push(format!("cw{b}[{at}] == 1'b1")),
            CmdBit::Channel(j) => chan.push((j, at)),
        }
    }
    chan.sort();
    let key: Vec<String> = chan
        .iter()
        .rev()
        .map(|(_, at)| format!("cw{b}[{at}]"))
        .collect();
    let w = chan.len();
    let un = unselected(s, b);
    let mut v = format!("{ind}id{b} = 64'd{un};\n");
    fixed.insert(0, format!("nin{b} >= 16'd{l}"));
    let _ = writeln!(
        v,
        "{ind}if ({}) case ({{{}}})",
        fixed.join(" && "),
        key.join(", ")
    );
    for input in 0..1u32 << w {
        let mut on = s.mix.channels.iter().enumerate();
        let ch = on.find(|(_, c)| c.branch == b && c.input == input);
        match ch {
            // behind a front mux: settled by its pins at the conversion
            Some((_, c)) if c.front_input.is_some() => {
                let _ = writeln!(
                    v,
                    "{ind}  {w}'d{input}: id{b} = 64'd{};",
                    FRONT + input as u64
                );
            }
            Some((c, _)) => _ = writeln!(v, "{ind}  {w}'d{input}: id{b} = 64'd{c};"),
            None => {}
        }
    }
    let _ = writeln!(v, "{ind}  default: id{b} = 64'd{un};\n{ind}endcase");
    v
}
