//! Verilog, port manifest, ROM image and constraint emission.
//!
//! Everything here is a pure function of the schedule (and board file):
//! no maps with random order, no timestamps, so output is byte-identical
//! across runs.

use std::fmt::Write as _;
use std::path::Path;

use crate::rhdl::*;
use lut_gen::Schedule;
use lut_gen::{Dir, Layout, Role, PORTS, TOP_MODULE};

use crate::board::{pcf_template, pnr_name, Board};
use crate::core::Core;
use crate::link::{AxisLink, UartLink};
use crate::plan::{plan_with, LutForm, Plan};
use crate::widths::{CH_BITS, EN_TOTAL, MAX_BRANCHES, VALUE_BITS};
use crate::HdlError;

/// Name the rust-hdl `top` module gets in the emitted file.
pub const CORE: &str = "slotforge_core";
/// Name of the link stage's module (a mix with a `[link]` only).
pub const LINK: &str = "slotforge_link";

/// The packets' frame counter in the emitted Verilog: the register's path
/// under `slotforge_top` (the instance `link` of [`LINK`], its `hframe`).
/// `prove` generalises it with its harness's own count (`formal`), so the
/// link's bytes are proved without simulating the 256 frames it needs to
/// come round; a name that no longer matches only costs that.
pub const LINK_FRAME_COUNTER: &str = "link.hframe";

/// The mode decision of a mix with auto select (the mode the next frame
/// runs, from the triggers), as a path under `slotforge_top`: `prove` cuts
/// the design there (`formal`) so that the link's properties are proved for
/// every sequence of modes apart from the triggers, which are proved on the
/// design as it is; a name that no longer matches only costs that.
pub const MODE_DECISION: &str = "core.modes_0.decided";

/// With auto select, trigger `k`'s run of windows is the register
/// `{TRIGGER_RUN}{k}` under `slotforge_top` (a trigger of one frame may
/// have none): `prove` generalises each with its harness's own at frame
/// starts (`formal`), so a run of many frames costs no more frames to
/// prove; a name that no longer matches only costs that.
pub const TRIGGER_RUN: &str = "core.modes_0.run";

/// The emitted Verilog file.
pub const VERILOG_FILE: &str = "slotforge_top.v";
/// The emitted port manifest.
pub const MANIFEST_FILE: &str = "ports.json";

/// The emitted files, in memory, ordered by name.  Only [`emit`] makes
/// one, and it always holds [`VERILOG_FILE`] and [`MANIFEST_FILE`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Emitted {
    files: Vec<(String, String)>,
}

impl Emitted {
    /// The content of one emitted file.
    pub fn file(&self, name: &str) -> Option<&str> {
        self.files
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, t)| t.as_str())
    }

    /// Every file as `(name, content)`, ordered by name.
    pub fn files(&self) -> &[(String, String)] {
        &self.files
    }

    /// `slotforge_top.v`.
    pub fn verilog(&self) -> &str {
        self.file(VERILOG_FILE)
            .expect("emit always writes the Verilog")
    }

    /// `ports.json`.
    pub fn ports_json(&self) -> &str {
        self.file(MANIFEST_FILE)
            .expect("emit always writes ports.json")
    }

    /// Write every file into `dir` (created if missing).
    pub fn write_to(&self, dir: &Path) -> Result<(), HdlError> {
        std::fs::create_dir_all(dir).map_err(|e| HdlError::Io {
            path: dir.display().to_string(),
            source: e,
        })?;
        for (name, text) in &self.files {
            let p = dir.join(name);
            std::fs::write(&p, text).map_err(|e| HdlError::Io {
                path: p.display().to_string(),
                source: e,
            })?;
        }
        Ok(())
    }
}

/// Generate every file for a schedule.  With `board`, the PCF maps port bits
/// to that board's pins; without, a template PCF lists every port bit.
pub fn emit(s: &Schedule, board: Option<&Path>) -> Result<Emitted, HdlError> {
    emit_with(s, board, LutForm::Auto)
}

/// [`emit`] with the slot LUT form chosen by the caller (`Auto` is [`emit`]'s
/// rule, see hdl/DESIGN.md).
pub fn emit_with(s: &Schedule, board: Option<&Path>, form: LutForm) -> Result<Emitted, HdlError> {
    let p = plan_with(s, form)?;
    let board = match board {
        Some(path) => Some((path, Board::load(path)?)),
        None => None,
    };
    // a board writes its family's constraint file; without one, the PCF
    // template lists every port bit
    let constraints = match &board {
        Some((path, b)) => b.constraints(s, path)?,
        None => ("slotforge.pcf".to_string(), pcf_template(s)),
    };
    let mut files = vec![
        (VERILOG_FILE.to_string(), verilog(s, &p)),
        (MANIFEST_FILE.to_string(), lut_gen::manifest(s)),
        // The schedule's LUT in the one layout `slotforge lut` also writes, so
        // the two commands can share an output directory; the ROM image the
        // gateware embeds (per-branch words) is `slot_rom.hex`.
        ("slots.hex".to_string(), lut_gen::lut::to_hex(s)),
        ("slot_rom.hex".to_string(), slots_hex(s, &p)),
        ("slotforge.sdc".to_string(), sdc(s)),
        ("slotforge.xdc".to_string(), xdc(s)),
        constraints,
    ];
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    let core = crate::fusesoc::core_file(s, &names, board.is_some());
    files.push((crate::fusesoc::CORE_FILE.to_string(), core));
    let launcher = crate::fusesoc::LAUNCHER.to_string();
    files.push((crate::fusesoc::LAUNCHER_FILE.to_string(), launcher));
    files.sort();
    Ok(Emitted { files })
}

/// The Verilog of the gateware with a design-level fault built in, and of
/// the clean gateware in the same LUT form, for an equivalence check of the
/// two at the ports.
pub fn verilog_pair(
    s: &Schedule,
    fault: crate::GatewareFault,
) -> Result<(String, String), HdlError> {
    let clean = plan_with(s, fault.lut_form())?;
    let mut faulty = clean.clone();
    fault.apply(&mut faulty)?;
    Ok((verilog(s, &clean), verilog(s, &faulty)))
}

// ---------------------------------------------------------------------------
// Verilog
// ---------------------------------------------------------------------------

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'$'
}

/// Rename rust-hdl's `top` / `top$...` modules to `slotforge_core...`.
fn rename_top(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len() + 4096);
    let mut i = 0;
    while i < b.len() {
        let at_start = i == 0 || !is_ident(b[i - 1]);
        if at_start
            && b[i..].starts_with(b"top")
            && (i + 3 == b.len() || b[i + 3] == b'$' || b[i + 3] == b'(')
        {
            out.push_str(CORE);
            i += 3;
            continue;
        }
        let ch = text[i..].chars().next().unwrap();
        out.push(ch);
        i += ch.len_utf8();
    }
    out
}

/// Tidy rust-hdl's text: strip trailing blanks, collapse blank runs.
fn tidy(text: &str) -> String {
    let mut out = String::new();
    let mut blank = 0;
    for line in text.lines() {
        let l = line.trim_end();
        if l.is_empty() {
            blank += 1;
            if blank > 1 {
                continue;
            }
        } else {
            blank = 0;
        }
        out.push_str(l);
        out.push('\n');
    }
    out
}

/// The wire that carries a port's lanes between the wrapper and the core,
/// and the core's width of it, for the ports the core has at its fixed
/// maximum width (the wrapper exposes exactly the mix's bits).
fn core_lanes(r: Role) -> Option<(&'static str, usize)> {
    match r {
        Role::Miso => Some(("core_miso", MAX_BRANCHES)),
        Role::CsN => Some(("core_cs_n", MAX_BRANCHES)),
        Role::Sclk => Some(("core_sclk", MAX_BRANCHES)),
        Role::MuxSel => Some((
            "core_mux_sel",
            lut_gen::MUX_SELECT_BITS as usize * MAX_BRANCHES,
        )),
        Role::MuxEn => Some(("core_mux_en", EN_TOTAL)),
        Role::SampleChannel => Some(("core_channel", CH_BITS)),
        Role::SampleValue => Some(("core_value", VALUE_BITS)),
        // only a mix with a command word has it (`core_ports`)
        Role::Mosi => Some(("core_mosi", MAX_BRANCHES)),
        Role::Clock | Role::Reset | Role::SampleValid => None,
    }
}

/// The core's name for a port: the core (`core/top.rs`) names its ports as the
/// contract does (a test compares them), except rust-hdl's own `clock`.
pub fn core_port_name(r: Role) -> &'static str {
    match r {
        Role::Clock => "clock",
        r => r.name(),
    }
}

fn verilog(s: &Schedule, p: &Plan) -> String {
    let mut core = Core::new(p);
    core.connect_all();
    let raw = initial_values(&generate_verilog(&core), &crate::sim::reset_values(p));
    let mut body =
        tidy(&rename_top(&raw)).replace("endmodule // top\n", &format!("endmodule // {CORE}\n"));
    link_module(&mut body, p);
    // the core's and the link's modules with readable names (no `$`)
    let body = crate::header::annotate(&crate::names::readable(&body), s, p);
    let l = Layout::new(s);
    let mut v = String::new();
    header(&mut v, s, p);
    port_list(&mut v, &l);
    let wired = core_wires(&mut v, p, &l);
    let modes = mode_wires(&mut v, &l);
    core_instance(&mut v, &l, &wired, &modes);
    link_instance(&mut v, p);
    let _ = writeln!(v, "endmodule");
    let _ = writeln!(v);
    let _ = writeln!(
        v,
        "// ---- rust-hdl core: {CORE} and its blocks (the map at the top of this file) ----"
    );
    let _ = writeln!(
        v,
        "// The contract asks for ONE self-contained file, so the core's modules cannot\n// live in files named after them: waive Verilator's file-name style rule here.\n/* verilator lint_off DECLFILENAME */"
    );
    v.push_str(&body);
    let _ = writeln!(v, "`default_nettype wire");
    v
}

/// rust-hdl's text with each flip-flop's `initial` value made its reset
/// value (`values`, by module path): rust-hdl starts every `DFF` at 0, so
/// before the first clock edge a CS would be low and a CNV high.  With its
/// reset value from power-on, every pin shows its reset level before reset
/// is even applied (docs/ports.md, "Power-on").
fn initial_values(text: &str, values: &std::collections::BTreeMap<String, String>) -> String {
    let mut out = text.to_string();
    for (path, lit) in values {
        if lit.ends_with("'h0") {
            continue;
        }
        let Some(at) = out.find(&format!("module {path}(d,q,clock);")) else {
            continue;
        };
        let zero = format!("q = {}'h0;", lit.split('\'').next().unwrap_or("1"));
        let end = out[at..].find("endmodule").map_or(out.len(), |e| at + e);
        let Some(k) = out[at..end].find(&zero) else {
            continue;
        };
        let k = at + k;
        out.replace_range(k..k + zero.len(), &format!("q = {lit};"));
    }
    out
}

/// The wrapper's header comment: the mix, the map of the blocks to
/// docs/timing.md, and the per-mix constants (`crate::header`).
fn header(v: &mut String, s: &Schedule, p: &Plan) {
    let _ = writeln!(
        v,
        "// {TOP_MODULE}: acquisition gateware for mix \"{}\"",
        s.mix.name
    );
    let _ = writeln!(
        v,
        "// Generated by slotforge (hdl crate, rust-hdl 0.46) from the schedule; do not edit."
    );
    v.push_str(&crate::header::blocks(s, p));
    v.push_str(&crate::header::constants(s, p));
    let _ = writeln!(
        v,
        "// Cycle-level behaviour: docs/timing.md. Port roles: ports.json."
    );
    let _ = writeln!(v, "`default_nettype none");
    let _ = writeln!(v);
}

/// The wrapper's port list: the contract's ports at the mix's widths, then
/// the link's.
fn port_list(v: &mut String, l: &Layout) {
    let _ = writeln!(v, "module {TOP_MODULE} (");
    let link_ports = l.link_ports();
    let core_ports = l.ports().count();
    let nports = core_ports + link_ports.len() + l.mode_ports().len();
    for (i, port) in l.ports().enumerate() {
        let dir = match port.dir {
            Dir::In => "input ",
            Dir::Out => "output",
        };
        let range = if port.vector {
            format!("[{}:0] ", l.width(port.role) - 1)
        } else {
            String::new()
        };
        let sep = if i + 1 < nports { "," } else { "" };
        let _ = writeln!(v, "    {dir} wire {range}{}{sep}", port.name);
    }
    for (i, port) in link_ports.iter().enumerate() {
        let sep = if core_ports + i + 1 < nports { "," } else { "" };
        let range = if port.width > 1 {
            format!("[{}:0] ", port.width - 1)
        } else {
            String::new()
        };
        let _ = writeln!(
            v,
            "    {} wire {range}{}{sep}",
            port.dir.verilog(),
            port.name
        );
    }
    for (i, port) in l.mode_ports().iter().enumerate() {
        let sep = if i + 1 < l.mode_ports().len() {
            ","
        } else {
            ""
        };
        let range = if l.mode_bits > 1 {
            format!("[{}:0] ", l.mode_bits - 1)
        } else {
            String::new()
        };
        let _ = writeln!(
            v,
            "    {} wire {range}{}{sep}",
            port.dir.verilog(),
            port.name
        );
    }
    let _ = writeln!(v, ");");
    let _ = writeln!(v);
}

/// The wires between the wrapper's ports and the core's fixed-maximum
/// lanes; returns the ports so wired (role, wire, the core's width).
fn core_wires(v: &mut String, p: &Plan, l: &Layout) -> Vec<(Role, &'static str, usize)> {
    let _ = writeln!(
        v,
        "    // The core has fixed maximum widths ({MAX_BRANCHES} branches, {EN_TOTAL} mux enables, {CH_BITS}-bit channel);"
    );
    let _ = writeln!(v, "    // this wrapper exposes exactly the mix's bits.");
    let wired: Vec<(Role, &str, usize)> = core_ports(l)
        .filter_map(|port| core_lanes(port.role).map(|(wire, cw)| (port.role, wire, cw)))
        .collect();
    for &(_, wire, cw) in &wired {
        let _ = writeln!(v, "    wire [{}:0] {wire};", cw - 1);
    }
    // the core's slot starts, which the link counts for its slice boundary
    let _ = writeln!(v, "    wire core_slot_tick;");
    let mut unused = vec![];
    if p.link.is_none() {
        unused.push("core_slot_tick".to_string());
    }
    for &(r, wire, cw) in &wired {
        if p.link.is_some() && matches!(r, Role::SampleChannel | Role::SampleValue) {
            // the link reads the core's full-width channel and code
            let (name, w) = (r.name(), l.width(r) as usize);
            let _ = writeln!(v, "    assign {name} = {wire}[{}:0];", w - 1);
            continue;
        }
        let (name, w) = (r.name(), l.width(r) as usize);
        match r.port().dir {
            Dir::In if w < cw => {
                let _ = writeln!(v, "    assign {wire} = {{{}'h0, {name}}};", cw - w);
            }
            Dir::In => {
                let _ = writeln!(v, "    assign {wire} = {name};");
            }
            Dir::Out => {
                let used = core_bits(r, p, l);
                let part = |(hi, lo): (usize, usize)| format!("{wire}[{hi}:{lo}]");
                match used.as_slice() {
                    [] => {}
                    [one] => {
                        let _ = writeln!(v, "    assign {name} = {};", part(*one));
                    }
                    many => {
                        let cat: Vec<String> = many.iter().rev().map(|&x| part(x)).collect();
                        let _ = writeln!(v, "    assign {name} = {{{}}};", cat.join(", "));
                    }
                }
                unused.extend(gaps(&used, cw).into_iter().map(part));
            }
        }
    }
    if !unused.is_empty() {
        let _ = writeln!(
            v,
            "    // lanes the mix does not use are constant in the core\n    wire unused_core_lanes = |{{{}}};",
            unused.join(", ")
        );
    }
    wired
}

/// The core's bits that carry output port `r`'s bits, as `(msb, lsb)` runs
/// from the port's bit 0 up: the core keeps every branch's mux lanes at
/// fixed places (`3b` for a select, the plan's `en_offset` for enables, one
/// constant device for a branch without a mux), the port has only the lanes
/// of branches that have a mux.
fn core_bits(r: Role, p: &Plan, l: &Layout) -> Vec<(usize, usize)> {
    let runs: Vec<(usize, usize)> = match r {
        Role::MuxSel => (0..l.branches)
            .filter(|&b| l.muxed[b])
            .map(|b| {
                let k = lut_gen::MUX_SELECT_BITS as usize;
                (k * b + k - 1, k * b)
            })
            .collect(),
        Role::MuxEn => (0..l.branches)
            .filter(|&b| l.muxed[b])
            .map(|b| {
                let (o, n) = (p.branches[b].en_offset, p.branches[b].devices);
                (o + n - 1, o)
            })
            .collect(),
        r if l.width(r) > 0 => vec![(l.width(r) as usize - 1, 0)],
        _ => vec![],
    };
    let mut merged: Vec<(usize, usize)> = vec![];
    for (hi, lo) in runs {
        match merged.last_mut() {
            Some(last) if last.0 + 1 == lo => last.0 = hi,
            _ => merged.push((hi, lo)),
        }
    }
    merged
}

/// The runs of a `width`-bit core wire that `used` (ascending runs) leaves out.
fn gaps(used: &[(usize, usize)], width: usize) -> Vec<(usize, usize)> {
    let mut v = vec![];
    let mut next = 0;
    for &(hi, lo) in used {
        if lo > next {
            v.push((lo - 1, next));
        }
        next = hi + 1;
    }
    if next < width {
        v.push((width - 1, next));
    }
    v
}

/// The contract's ports the core has: all but `adc_mosi` for a mix without
/// a command word (the core then has no such port: `Core::adc_mosi`).
pub fn core_ports(l: &Layout) -> impl Iterator<Item = &'static lut_gen::Port> + '_ {
    PORTS
        .iter()
        .filter(|p| p.role != Role::Mosi || l.width(Role::Mosi) > 0)
}

/// A mix with modes: the core's `mode` at the core's width, the wrapper's
/// port its low bits; returns the core's mode ports' connections.
fn mode_wires(v: &mut String, l: &Layout) -> Vec<(String, String)> {
    let mb = l.mode_bits as usize;
    if mb == 0 {
        return vec![];
    }
    let w = crate::widths::MODE_BITS;
    let _ = writeln!(
        v,
        "    // the mode in force (docs/timing.md, \"Mode switches\")\n    wire [{}:0] core_mode;",
        w - 1
    );
    let low = if mb > 1 {
        format!("[{}:0]", mb - 1)
    } else {
        "[0]".into()
    };
    let _ = writeln!(v, "    assign mode = core_mode{low};");
    if mb < w {
        let _ = writeln!(v, "    wire unused_core_mode = |core_mode[{}:{mb}];", w - 1);
    }
    let mut out = vec![];
    if l.mode_pin {
        let sel = if mb < w {
            format!("{{{}'h0, mode_sel}}", w - mb)
        } else {
            "mode_sel".into()
        };
        out.push(("mode_sel_0".to_string(), sel));
    }
    out.push(("mode_0".to_string(), "core_mode".to_string()));
    out
}

/// The core instance, its ports on the wires or straight on the wrapper's.
fn core_instance(
    v: &mut String,
    l: &Layout,
    wired: &[(Role, &'static str, usize)],
    modes: &[(String, String)],
) {
    let _ = writeln!(v);
    let _ = writeln!(v, "    {CORE} core (");
    for port in core_ports(l) {
        let to = wired
            .iter()
            .find(|(r, ..)| *r == port.role)
            .map_or(port.name, |(_, wire, _)| *wire);
        let _ = writeln!(v, "        .{}({to}),", core_port_name(port.role));
    }
    if modes.is_empty() {
        let _ = writeln!(v, "        .slot_tick(core_slot_tick)\n    );");
        return;
    }
    let _ = writeln!(v, "        .slot_tick(core_slot_tick),");
    let ends: Vec<String> = modes
        .iter()
        .map(|(p, w)| format!("        .{p}({w})"))
        .collect();
    let _ = writeln!(v, "{}\n    );", ends.join(",\n"));
}

/// The link instance (UART or AXI4-Stream), when the mix has a link.
fn link_instance(v: &mut String, p: &Plan) {
    // a mix with modes: the core's mode in force, at the link's width
    let mode = match p.link.map_or(0, |lp| lp.mode_bits) {
        0 => String::new(),
        mb if mb as usize == crate::widths::MODE_BITS => "\n        .mode(core_mode),".into(),
        mb => format!("\n        .mode(core_mode[{}:0]),", mb - 1),
    };
    if p.link.is_some_and(|lp| lp.axis.is_some()) {
        let [td, tv, tl, tr, ovf] = lut_gen::AXIS_PORTS.map(|p| p.name);
        let _ = writeln!(v);
        let _ = writeln!(
            v,
            "    // the link to the host: packets of the merged sample stream as AXI4-Stream beats (docs/packet-format.md)"
        );
        let _ = writeln!(
            v,
            "    {LINK} link (\n        .clock({}),\n        .rst({}),\n        .valid({}),\n        .ch(core_channel),\n        .val(core_value),\n        .slot_tick(core_slot_tick),{mode}\n        .tready({tr}),\n        .tdata({td}),\n        .tvalid({tv}),\n        .tlast({tl}),\n        .ovf({ovf})\n    );",
            Role::Clock.name(),
            Role::Reset.name(),
            Role::SampleValid.name()
        );
    } else if p.link.is_some() {
        let [tx, ovf] = lut_gen::LINK_PORTS.map(|p| p.name);
        let _ = writeln!(v);
        let _ = writeln!(
            v,
            "    // the link to the host: packets of the merged sample stream (docs/packet-format.md)"
        );
        let _ = writeln!(
            v,
            "    {LINK} link (\n        .clock({}),\n        .rst({}),\n        .valid({}),\n        .ch(core_channel),\n        .val(core_value),\n        .slot_tick(core_slot_tick),{mode}\n        .tx({tx}),\n        .ovf({ovf})\n    );",
            Role::Clock.name(),
            Role::Reset.name(),
            Role::SampleValid.name()
        );
    }
}

/// The link's module, generated by rust-hdl, when the mix has a link.
fn link_module(v: &mut String, p: &Plan) {
    if let Some(lp) = p.link {
        let _ = writeln!(v, "\n// ---- link stage (hdl/src/link.rs) ----");
        v.push_str(&link_text(lp));
    }
}

/// The link's module for `lp`; with modes, its `mode` input (the core's
/// mode in force, which each header carries: docs/packet-format.md).
pub fn link_text(lp: crate::link::LinkParams) -> String {
    let text = if lp.axis.is_some() {
        let mut link = AxisLink::new(lp);
        link.connect_all();
        generate_verilog(&link)
    } else {
        let mut link = UartLink::new(lp);
        link.connect_all();
        generate_verilog(&link)
    };
    let mut text = text
        .replace("module top(", &format!("module {LINK}("))
        .replace("endmodule // top", &format!("endmodule // {LINK}"));
    if lp.mode_bits > 0 {
        // rust-hdl's port list has no field for a width only mode mixes have
        let decl = "    input wire  slot_tick;\n";
        let port = format!("{decl}    input wire  [{}:0] mode;\n", lp.mode_bits - 1);
        text = text
            .replacen(",slot_tick,", ",slot_tick,mode,", 1)
            .replacen(decl, &port, 1);
    }
    tidy(&text)
}

// ---------------------------------------------------------------------------
// slots.hex
// ---------------------------------------------------------------------------

fn slots_hex(s: &Schedule, p: &Plan) -> String {
    let mut t = String::new();
    let r0 = &p.branches[0];
    let aw = r0.addr_bits;
    let (cw, dw) = (r0.ch_bits, r0.dev_bits);
    let wb = r0.word_bits();
    let digits = wb.div_ceil(4);
    let _ = writeln!(
        t,
        "// slotforge slot ROM image for mix \"{}\" ($readmemh)",
        s.mix.name
    );
    let _ = writeln!(
        t,
        "// {} branches x {} words of {wb} bits (frame of {} slots padded to 2^{aw}); address = branch * {} + slot",
        p.branches.len(),
        1u64 << aw,
        p.frame_slots,
        1u64 << aw
    );
    let _ = writeln!(
        t,
        "// word[{}] = branch converts in this slot, [{}:{}] channel index converted,",
        wb - 1,
        wb - 2,
        3 + dw
    );
    let _ = writeln!(
        t,
        "// [{}:{dw}] mux select and [{}:0] mux device of the branch's first instant at this slot or later (cyclic)",
        dw + 2,
        dw - 1
    );
    let _ = cw;
    if p.compact {
        let _ = writeln!(
            t,
            "// COMPACT form ({} slots per slice x {} slices): per branch a slice table (address = slot in slice;",
            p.slots_per_slice, p.slices_per_frame
        );
        let _ = writeln!(
            t,
            "// top bit set: the rest is a rotation group g, else the word itself) and a rotation table (address = g << slice_bits | slice)"
        );
        let _ = writeln!(
            t,
            "// whose words are as above except that the mux field is the branch's first instant after the slot"
        );
        for (b, r) in p.branches.iter().enumerate() {
            let c = r.compact.as_ref().expect("compact plan");
            let sw = 1 + wb.max(c.group_bits);
            let _ = writeln!(t, "// branch {b}: {} slice table", s.branches[b].name);
            let sd = sw.div_ceil(4);
            for w in &c.slice_words {
                let _ = writeln!(t, "{w:0sd$x}");
            }
            let _ = writeln!(
                t,
                "// branch {b}: {} rotation table (slice_bits {})",
                s.branches[b].name, c.slice_bits
            );
            for w in &c.rot_words {
                let _ = writeln!(t, "{w:0digits$x}");
            }
        }
        return t;
    }
    for (b, r) in p.branches.iter().enumerate() {
        let _ = writeln!(t, "// branch {b}: {}", s.branches[b].name);
        for w in &r.words {
            let _ = writeln!(t, "{w:0digits$x}");
        }
    }
    t
}

// ---------------------------------------------------------------------------
// Constraints
// ---------------------------------------------------------------------------

pub(crate) fn period_ns(s: &Schedule) -> String {
    let ns = 1e9 / s.grid.clock_hz as f64;
    let mut t = format!("{ns:.3}");
    while t.ends_with('0') {
        t.pop();
    }
    if t.ends_with('.') {
        t.pop();
    }
    t
}

/// Every port of the top as a constraint names it (`adc_cs_n[*]` for a
/// vector), with its direction: the contract's ports and the link's, so
/// that no port is left out of a constraints file.
fn port_patterns(s: &Schedule) -> Vec<(String, Dir)> {
    let l = Layout::new(s);
    let pattern = |name: &str, vector: bool| {
        if vector {
            format!("{name}[*]")
        } else {
            name.to_string()
        }
    };
    let mut v: Vec<(String, Dir)> = l
        .ports()
        .map(|p| (pattern(p.name, p.vector), p.dir))
        .collect();
    v.extend(
        l.link_ports()
            .iter()
            .map(|p| (pattern(p.name, p.width > 1), p.dir)),
    );
    let mode_bits = l.mode_port_bits().len() / l.mode_ports().len().max(1);
    v.extend(
        l.mode_ports()
            .iter()
            .map(|p| (pattern(p.name, mode_bits > 1), p.dir)),
    );
    v
}

/// The clock, and every other port's timing against it: all of them are
/// sampled or driven on `clk`'s rising edge.  The delays are 0 ns, for the
/// board's own to replace.
fn sdc(s: &Schedule) -> String {
    let mut t = format!(
        "# slotforge_top timing constraint for mix \"{}\" ({} Hz)\ncreate_clock -name clk -period {} [get_ports clk]\n",
        s.mix.name,
        s.grid.clock_hz,
        period_ns(s)
    );
    let _ = writeln!(
        t,
        "# Every other port is synchronous to clk; replace 0 with your board's delays (ns)."
    );
    let ports = port_patterns(s);
    for (cmd, dir) in [("set_input_delay", Dir::In), ("set_output_delay", Dir::Out)] {
        let names: Vec<&str> = ports
            .iter()
            .filter(|(n, d)| *d == dir && n != "clk")
            .map(|(n, _)| n.as_str())
            .collect();
        if !names.is_empty() {
            let _ = writeln!(t, "{cmd} -clock clk 0 [get_ports {{{}}}]", names.join(" "));
        }
    }
    t
}

fn xdc(s: &Schedule) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# slotforge_top constraints for Xilinx Vivado, mix \"{}\"",
        s.mix.name
    );
    let _ = writeln!(
        t,
        "create_clock -name clk -period {} [get_ports clk]",
        period_ns(s)
    );
    let _ = writeln!(
        t,
        "set_property IOSTANDARD LVCMOS33 [get_ports {{{}}}]",
        port_patterns(s)
            .into_iter()
            .map(|p| p.0)
            .collect::<Vec<_>>()
            .join(" ")
    );
    let _ = writeln!(t, "# Pin locations: uncomment and fill in for your board.");
    let bits = Layout::new(s).bits();
    for (bit, _) in &bits {
        let _ = writeln!(
            t,
            "# set_property PACKAGE_PIN <pin> [get_ports {{{}}}]",
            pnr_name(&bits, bit)
        );
    }
    t
}
