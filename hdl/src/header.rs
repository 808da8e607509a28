//! The header comment of `slotforge_top.v`: which module is which block and
//! where docs/timing.md specifies it, and the mix's constants as the plan
//! holds them (rust-hdl inlines them into each module's `k_*` localparams,
//! derived, so the numbers a reader looks for are here, named).
//!
//! The module names are those `names` gives rust-hdl's paths; a test over
//! every preset and random mixes finds each one this header names declared
//! in the file.

use std::fmt::Write as _;

use lut_gen::Schedule;
use lut_gen::{Layout, Role};

use crate::plan::Plan;

/// The SPI sequencer module of sequencer `i` (`names`: `seqs$i`).
pub(crate) fn spi_seq_module(i: usize) -> String {
    format!("slotforge_spi_seq{i}")
}

/// The branch unit module of branch `b` (`names`: `branches$b`).
pub(crate) fn branch_module(b: usize) -> String {
    format!("slotforge_branch{b}")
}

/// The block map: each module (per branch for a branch's own) with what it
/// does and its section of docs/timing.md.
pub(crate) fn blocks(s: &Schedule, p: &Plan) -> String {
    let mut v = String::new();
    let row = |v: &mut String, m: &str, what: &str, doc: &str| {
        let _ = writeln!(v, "//   {m:<28} {what}; {doc}");
    };
    let _ = writeln!(
        v,
        "//\n// Blocks: module, what it does; where docs/timing.md specifies it (section title)"
    );
    row(
        &mut v,
        "slotforge_top",
        "the pins at the mix's widths",
        "\"Ports\"",
    );
    row(&mut v, "slotforge_core", "wiring of the blocks below", "-");
    row(
        &mut v,
        "slotforge_timing",
        "cycle-in-slot and slot counters, slot-start strobes",
        "\"Time\"",
    );
    for (i, _) in p.seqs.iter().enumerate() {
        let users: Vec<String> = (0..p.branches.len())
            .filter(|&b| p.branches[b].seq == i)
            .map(|b| b.to_string())
            .collect();
        row(
            &mut v,
            &spi_seq_module(i),
            &format!(
                "SPI timing (CS/CNV, SCLK, capture, completion) of branch {}",
                users.join(", ")
            ),
            "\"Per branch `b`\", \"CNV-style parts and daisy chains\"",
        );
    }
    let as_logic = if p.logic { " as logic" } else { "" };
    for b in 0..p.branches.len() {
        let m = branch_module(b);
        row(
            &mut v,
            &m,
            &format!("branch {b}'s CS/SCLK pins gated by its slots, its mux pins"),
            "\"Per branch `b`\", \"Start-up\"",
        );
        row(
            &mut v,
            &format!("{m}_rom"),
            &format!("branch {b}'s column of the slot table{as_logic} (slot_rom.hex)"),
            "\"Time\" (instants)",
        );
        row(
            &mut v,
            &format!("{m}_reader"),
            &format!("branch {b}'s MISO shift register, word by word"),
            "\"Per branch `b`\" (MISO bits)",
        );
    }
    // a command unit per branch whose converter takes a command word
    let commanded = (0..p.branches.len()).filter(|&b| p.branches[b].command.is_some());
    for (i, b) in commanded.enumerate() {
        row(
            &mut v,
            &format!("slotforge_cmd{i}"),
            &format!("branch {b}'s command word on adc_mosi, its prepared conversions"),
            "\"Command words\"",
        );
    }
    for i in 0..p.seqs.iter().filter(|q| q.pulsed()).count() {
        row(
            &mut v,
            &format!("slotforge_cnv_pulse{i}"),
            "CNV high for the conversion alone (a part read with CNV low)",
            "\"Reading with CNV low\"",
        );
    }
    row(
        &mut v,
        "slotforge_merger",
        "one sample stream, lowest branch first",
        "\"Merged sample stream\"",
    );
    if p.link.is_some() {
        row(
            &mut v,
            "slotforge_link",
            "packets to the host",
            "docs/packet-format.md, \"Timing\"",
        );
    }
    row(
        &mut v,
        "slotforge_dff<W>",
        "a W-bit register (rust-hdl's DFF), one module per width",
        "-",
    );
    branch_timing(&mut v, s, p);
    v
}

/// Where each branch's SPI timing lives (and its CNV pulse, if read with
/// CNV low), one line each.
fn branch_timing(v: &mut String, s: &Schedule, p: &Plan) {
    for (b, bp) in s.branches.iter().enumerate() {
        let m = spi_seq_module(p.branches[b].seq);
        let q = &p.seqs[p.branches[b].seq];
        let _ = writeln!(
            v,
            "// SPI timing of branch {b} \"{}\": sclk_div {} sclk_half {} setup_cycles {} read_cycles {}, in module {m} (search \"module {m}(\")",
            bp.name, q.sclk_div, q.sclk_half, q.setup_cycles, q.read_cycles
        );
        if q.pulsed() {
            let n = (p.seqs[..p.branches[b].seq].iter())
                .filter(|q| q.pulsed())
                .count();
            let _ = writeln!(
                v,
                "//   read with CNV low: CNV high for the conversion's {} cycles alone, in module slotforge_cnv_pulse{n} (docs/timing.md, \"Reading with CNV low\")",
                q.pin_cycles
            );
        }
    }
}

/// The per-mix constants the design is built from, named, from the plan.
pub(crate) fn constants(s: &Schedule, p: &Plan) -> String {
    let mut v = String::new();
    let g = &s.grid;
    let _ = writeln!(
        v,
        "//\n// Constants of this mix (the modules' k_* localparams are derived from these)"
    );
    let _ = writeln!(v, "//   clock_hz           {}", g.clock_hz);
    let _ = writeln!(v, "//   slot_cycles        {}", p.slot_cycles);
    let _ = writeln!(v, "//   slots_per_slice    {}", p.slots_per_slice);
    let _ = writeln!(v, "//   slices_per_frame   {}", p.slices_per_frame);
    let _ = writeln!(v, "//   frame_slots        {}", p.frame_slots);
    let _ = writeln!(
        v,
        "//   frame_cycles       {}",
        p.frame_slots * p.slot_cycles
    );
    let _ = writeln!(v, "//   channel_bits       {}", p.channel_bits);
    let form = if p.compact {
        "compact"
    } else if p.logic {
        "logic (the full table as logic of the slot-in-slice and slice counters)"
    } else {
        "full"
    };
    let _ = writeln!(v, "//   slot_lut           {form}");
    for (i, q) in p.seqs.iter().enumerate() {
        let _ = writeln!(
            v,
            "//   {}: sclk_div {} sclk_half {} setup_cycles {} read_cycles {} sclks {} word_sclks {} leading_bits {} bits {} {}",
            spi_seq_module(i),
            q.sclk_div,
            q.sclk_half,
            q.setup_cycles,
            q.read_cycles,
            q.sclks,
            q.word_sclks,
            q.leading_bits,
            q.bits,
            if q.cnv { "cnv" } else { "cs" }
        );
    }
    let l = Layout::new(s);
    for (b, r) in p.branches.iter().enumerate() {
        let mux = if l.muxed[b] {
            let (hi, lo) = l.lane_bits(Role::MuxEn, b);
            format!("mux_devices {} at mux_en[{hi}:{lo}]", r.devices)
        } else {
            "no mux".to_string()
        };
        let _ = writeln!(
            v,
            "//   {}: {} chain {} bits {} {mux}",
            branch_module(b),
            spi_seq_module(r.seq),
            r.chain,
            r.bits
        );
    }
    v
}

/// `body` (the core's modules, named by `names`) with a comment under the
/// first line of each SPI sequencer and branch module: the numbers a reader
/// looks for there, and which localparams carry them.
pub(crate) fn annotate(body: &str, s: &Schedule, p: &Plan) -> String {
    let mut notes: Vec<(String, String)> = vec![];
    for (i, q) in p.seqs.iter().enumerate() {
        let users: Vec<String> = (0..p.branches.len())
            .filter(|&b| p.branches[b].seq == i)
            .map(|b| format!("{b} \"{}\"", s.branches[b].name))
            .collect();
        let note = format!(
            "    // SPI timing of branch {} (docs/timing.md, \"Per branch `b`\"):\n    \
             // sclk_div {} (k_ph_last = sclk_div - 1), sclk_half {} (k_ph_half = sclk_half - 1),\n    \
             // setup_cycles {}, read_cycles {}, {} SCLK periods per conversion (k_nf_end), {} per word,\n    \
             // {} leading bits then {} data bits, {}\n",
            users.join(", "),
            q.sclk_div,
            q.sclk_half,
            q.setup_cycles,
            q.read_cycles,
            q.sclks,
            q.word_sclks,
            q.leading_bits,
            q.bits,
            if q.cnv {
                "CNV style (SCK idles low)"
            } else {
                "CS style (SCLK idles high)"
            }
        );
        notes.push((spi_seq_module(i), note));
    }
    for (b, r) in p.branches.iter().enumerate() {
        let mux = if r.muxed {
            format!("{} mux device(s)", r.devices)
        } else {
            "no mux".to_string()
        };
        let note = format!(
            "    // branch {b} \"{}\": SPI timing in module {}, {mux}, {} word(s) of {} bits per conversion\n",
            s.branches[b].name,
            spi_seq_module(r.seq),
            r.chain,
            r.bits
        );
        notes.push((branch_module(b), note));
    }
    let mut out = String::with_capacity(body.len() + 4096);
    for line in body.split_inclusive('\n') {
        out.push_str(line);
        if let Some((_, note)) = notes
            .iter()
            .find(|(m, _)| line.starts_with(&format!("module {m}(")))
        {
            out.push_str(note);
        }
    }
    out
}
