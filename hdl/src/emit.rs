//! Verilog, port manifest, ROM image and constraint emission.
//!
//! Everything here is a pure function of the schedule (and board file):
//! no maps with random order, no timestamps, so output is byte-identical
//! across runs.

use std::fmt::Write as _;
use std::path::Path;

use lut_gen::Schedule;
use rust_hdl::prelude::*;
use serde::Deserialize;

use crate::core::{Core, CH_BITS, EN_TOTAL};
use crate::plan::{plan_with, LutForm, Plan, MAX_BRANCHES};
use crate::HdlError;

/// Name the rust-hdl `top` module gets in the emitted file.
const CORE: &str = "slotforge_core";

/// The emitted files, in memory.  `files` is ordered by name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Emitted {
    pub files: Vec<(String, String)>,
}

impl Emitted {
    /// The content of one emitted file.
    pub fn file(&self, name: &str) -> Option<&str> {
        self.files
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, t)| t.as_str())
    }

    /// `slotforge_top.v`.
    pub fn verilog(&self) -> &str {
        self.file("slotforge_top.v").unwrap_or_default()
    }

    /// `ports.json`.
    pub fn ports_json(&self) -> &str {
        self.file("ports.json").unwrap_or_default()
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

/// A board file: which package pin each port bit goes to.
///
/// ```toml
/// name = "..."
/// device = "hx8k"        # nextpnr-ice40 --hx8k
/// package = "ct256"
/// [pins]                 # explicit bits, e.g. clk = "J3", "adc_cs_n[0]" = "B6"
/// clk = "J3"
/// [pool]                 # remaining bits take these pins, in port-table order
/// pins = ["A5", "A6"]
/// ```
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Board {
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub device: String,
    pub package: String,
    #[serde(default)]
    pub pins: std::collections::BTreeMap<String, String>,
    #[serde(default)]
    pub pool: Pool,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pool {
    #[serde(default)]
    pub pins: Vec<String>,
}

impl Board {
    pub fn load(path: &Path) -> Result<Board, HdlError> {
        let err = |m: String| HdlError::Board {
            path: path.display().to_string(),
            message: m,
        };
        let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
        toml::from_str(&text).map_err(|e| err(e.to_string()))
    }
}

/// The name place-and-route tools give a port bit: yosys and nextpnr call
/// the only bit of a 1-bit vector port by the port's name.
fn pnr_name(bits: &[(String, &'static str)], bit: &str) -> String {
    if let Some(base) = bit.strip_suffix("[0]") {
        let wider = format!("{base}[1]");
        if !bits.iter().any(|(n, _)| *n == wider) {
            return base.to_string();
        }
    }
    bit.to_string()
}

/// Port bit names in port-table order (the order of docs/timing.md).
fn port_bits(s: &Schedule, p: &Plan) -> Vec<(String, &'static str)> {
    let nb = p.branches.len();
    let m: usize = p.branches.iter().map(|b| b.devices).sum();
    let w = p.channel_bits as usize;
    let mut v = vec![("clk".to_string(), "input"), ("rst".to_string(), "input")];
    let _ = s;
    for b in 0..nb {
        v.push((format!("adc_miso[{b}]"), "input"));
    }
    for b in 0..nb {
        v.push((format!("adc_cs_n[{b}]"), "output"));
    }
    for b in 0..nb {
        v.push((format!("adc_sclk[{b}]"), "output"));
    }
    for i in 0..3 * nb {
        v.push((format!("mux_sel[{i}]"), "output"));
    }
    for i in 0..m {
        v.push((format!("mux_en[{i}]"), "output"));
    }
    v.push(("sample_valid".to_string(), "output"));
    for i in 0..w {
        v.push((format!("sample_channel[{i}]"), "output"));
    }
    for i in 0..14 {
        v.push((format!("sample_value[{i}]"), "output"));
    }
    v
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
    let mut files = vec![
        ("slotforge_top.v".to_string(), verilog(s, &p)),
        ("ports.json".to_string(), ports_json(s, &p)),
        // The schedule's LUT in the one layout `slotforge lut` also writes, so
        // the two commands can share an output directory; the ROM image the
        // gateware embeds (per-branch words) is `slot_rom.hex`.
        ("slots.hex".to_string(), lut_gen::lut::to_hex(s)),
        ("slot_rom.hex".to_string(), slots_hex(s, &p)),
        ("slotforge.sdc".to_string(), sdc(s)),
        ("slotforge.xdc".to_string(), xdc(s, &p)),
        (
            "slotforge.pcf".to_string(),
            match &board {
                Some((path, b)) => pcf_board(s, &p, path, b)?,
                None => pcf_template(s, &p),
            },
        ),
    ];
    files.sort();
    Ok(Emitted { files })
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

fn verilog(s: &Schedule, p: &Plan) -> String {
    let mut core = Core::new(p);
    core.connect_all();
    let body = tidy(&rename_top(&generate_verilog(&core)))
        .replace("endmodule // top\n", &format!("endmodule // {CORE}\n"));
    let nb = p.branches.len();
    let m: usize = p.branches.iter().map(|b| b.devices).sum();
    let w = p.channel_bits as usize;
    let g = &s.grid;
    let mut v = String::new();
    let _ = writeln!(
        v,
        "// slotforge_top: acquisition gateware for mix \"{}\"",
        s.mix.name
    );
    let _ = writeln!(
        v,
        "// Generated by slotforge (hdl crate, rust-hdl 0.46) from the schedule; do not edit."
    );
    let _ = writeln!(
        v,
        "// clock {} Hz, frame {} cycles = {} slices x {} slots x {} cycles",
        g.clock_hz, g.frame_cycles, g.slices_per_frame, g.slots_per_slice, g.slot_cycles
    );
    for (b, bp) in s.branches.iter().enumerate() {
        let _ = writeln!(
            v,
            "// branch {b} \"{}\": sclk_div {} setup {} read {} cycles, {} mux device(s) at mux_en[{}:{}]",
            bp.name,
            bp.spi.sclk_div,
            bp.spi.setup_cycles,
            bp.spi.read_cycles,
            p.branches[b].devices,
            p.branches[b].en_offset + p.branches[b].devices - 1,
            p.branches[b].en_offset
        );
    }
    let _ = writeln!(
        v,
        "// Cycle-level behaviour: docs/timing.md. Port roles: ports.json."
    );
    let _ = writeln!(v, "`default_nettype none");
    let _ = writeln!(v);
    let _ = writeln!(v, "module slotforge_top (");
    let _ = writeln!(v, "    input  wire clk,");
    let _ = writeln!(v, "    input  wire rst,");
    let _ = writeln!(v, "    input  wire [{}:0] adc_miso,", nb - 1);
    let _ = writeln!(v, "    output wire [{}:0] adc_cs_n,", nb - 1);
    let _ = writeln!(v, "    output wire [{}:0] adc_sclk,", nb - 1);
    let _ = writeln!(v, "    output wire [{}:0] mux_sel,", 3 * nb - 1);
    let _ = writeln!(v, "    output wire [{}:0] mux_en,", m - 1);
    let _ = writeln!(v, "    output wire sample_valid,");
    let _ = writeln!(v, "    output wire [{}:0] sample_channel,", w - 1);
    let _ = writeln!(v, "    output wire [13:0] sample_value");
    let _ = writeln!(v, ");");
    let _ = writeln!(v);
    let _ = writeln!(
        v,
        "    // The core has fixed maximum widths ({MAX_BRANCHES} branches, {EN_TOTAL} mux enables, {CH_BITS}-bit channel);"
    );
    let _ = writeln!(v, "    // this wrapper exposes exactly the mix's bits.");
    let _ = writeln!(v, "    wire [{}:0] core_miso;", MAX_BRANCHES - 1);
    let _ = writeln!(v, "    wire [{}:0] core_cs_n;", MAX_BRANCHES - 1);
    let _ = writeln!(v, "    wire [{}:0] core_sclk;", MAX_BRANCHES - 1);
    let _ = writeln!(v, "    wire [{}:0] core_mux_sel;", 3 * MAX_BRANCHES - 1);
    let _ = writeln!(v, "    wire [{}:0] core_mux_en;", EN_TOTAL - 1);
    let _ = writeln!(v, "    wire [{}:0] core_channel;", CH_BITS - 1);
    if nb < MAX_BRANCHES {
        let _ = writeln!(
            v,
            "    assign core_miso = {{{}'h0, adc_miso}};",
            MAX_BRANCHES - nb
        );
    } else {
        let _ = writeln!(v, "    assign core_miso = adc_miso;");
    }
    let _ = writeln!(v, "    assign adc_cs_n = core_cs_n[{}:0];", nb - 1);
    let _ = writeln!(v, "    assign adc_sclk = core_sclk[{}:0];", nb - 1);
    let _ = writeln!(v, "    assign mux_sel = core_mux_sel[{}:0];", 3 * nb - 1);
    let _ = writeln!(v, "    assign mux_en = core_mux_en[{}:0];", m - 1);
    let _ = writeln!(v, "    assign sample_channel = core_channel[{}:0];", w - 1);
    let mut unused = vec![];
    if nb < MAX_BRANCHES {
        unused.push(format!("core_cs_n[{}:{nb}]", MAX_BRANCHES - 1));
        unused.push(format!("core_sclk[{}:{nb}]", MAX_BRANCHES - 1));
        unused.push(format!("core_mux_sel[{}:{}]", 3 * MAX_BRANCHES - 1, 3 * nb));
    }
    if m < EN_TOTAL {
        unused.push(format!("core_mux_en[{}:{m}]", EN_TOTAL - 1));
    }
    if w < CH_BITS {
        unused.push(format!("core_channel[{}:{w}]", CH_BITS - 1));
    }
    if !unused.is_empty() {
        let _ = writeln!(
            v,
            "    // lanes the mix does not use are constant in the core\n    wire unused_core_lanes = |{{{}}};",
            unused.join(", ")
        );
    }
    let _ = writeln!(v);
    let _ = writeln!(v, "    {CORE} core (");
    let _ = writeln!(v, "        .clock(clk),");
    let _ = writeln!(v, "        .rst(rst),");
    let _ = writeln!(v, "        .adc_miso(core_miso),");
    let _ = writeln!(v, "        .adc_cs_n(core_cs_n),");
    let _ = writeln!(v, "        .adc_sclk(core_sclk),");
    let _ = writeln!(v, "        .mux_sel(core_mux_sel),");
    let _ = writeln!(v, "        .mux_en(core_mux_en),");
    let _ = writeln!(v, "        .sample_valid(sample_valid),");
    let _ = writeln!(v, "        .sample_channel(core_channel),");
    let _ = writeln!(v, "        .sample_value(sample_value)");
    let _ = writeln!(v, "    );");
    let _ = writeln!(v, "endmodule");
    let _ = writeln!(v);
    let _ = writeln!(
        v,
        "// ---- rust-hdl core (module names: {CORE}$<path of the block>) ----"
    );
    let _ = writeln!(
        v,
        "// The contract asks for ONE self-contained file, so the core's modules cannot\n// live in files named after them: waive Verilator's file-name style rule here.\n/* verilator lint_off DECLFILENAME */"
    );
    v.push_str(&body);
    let _ = writeln!(v, "`default_nettype wire");
    v
}

// ---------------------------------------------------------------------------
// ports.json
// ---------------------------------------------------------------------------

fn ports_json(s: &Schedule, p: &Plan) -> String {
    use serde_json::json;
    let w = p.channel_bits as usize;
    let nb = p.branches.len();
    let m: usize = p.branches.iter().map(|b| b.devices).sum();
    let branches: Vec<_> = s
        .branches
        .iter()
        .enumerate()
        .map(|(b, bp)| {
            let r = &p.branches[b];
            json!({
                "name": bp.name,
                "cs_n": format!("adc_cs_n[{b}]"),
                "sclk": format!("adc_sclk[{b}]"),
                "miso": format!("adc_miso[{b}]"),
                "mux_sel": format!("mux_sel[{}:{}]", 3 * b + 2, 3 * b),
                "mux_en": (0..r.devices).map(|d| format!("mux_en[{}]", r.en_offset + d)).collect::<Vec<_>>(),
                "sclk_div": bp.spi.sclk_div,
                "setup_cycles": bp.spi.setup_cycles,
                "read_cycles": bp.spi.read_cycles,
            })
        })
        .collect();
    let channels: Vec<_> = s
        .channels
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let mc = &s.mix.channels[i];
            json!({
                "index": i,
                "name": mc.name,
                "branch": s.branches[mc.branch].name,
                "device": c.device,
                "select": c.select,
            })
        })
        .collect();
    let ports = json!([
        {"name": "clk", "dir": "in", "width": 1},
        {"name": "rst", "dir": "in", "width": 1},
        {"name": "adc_miso", "dir": "in", "width": nb},
        {"name": "adc_cs_n", "dir": "out", "width": nb},
        {"name": "adc_sclk", "dir": "out", "width": nb},
        {"name": "mux_sel", "dir": "out", "width": 3 * nb},
        {"name": "mux_en", "dir": "out", "width": m},
        {"name": "sample_valid", "dir": "out", "width": 1},
        {"name": "sample_channel", "dir": "out", "width": w},
        {"name": "sample_value", "dir": "out", "width": 14},
    ]);
    let doc = json!({
        "top": "slotforge_top",
        "mix": s.mix.name,
        "clock": "clk",
        "clock_hz": s.grid.clock_hz,
        "reset": {"port": "rst", "active_high": true, "synchronous": true},
        "branches": branches,
        "sample": {"valid": "sample_valid", "channel": "sample_channel", "value": "sample_value"},
        "channels": channels,
        "ports": ports,
    });
    let mut t = serde_json::to_string_pretty(&doc).expect("json");
    t.push('\n');
    t
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

fn period_ns(s: &Schedule) -> String {
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

fn sdc(s: &Schedule) -> String {
    format!(
        "# slotforge_top timing constraint for mix \"{}\" ({} Hz)\ncreate_clock -name clk -period {} [get_ports clk]\n",
        s.mix.name,
        s.grid.clock_hz,
        period_ns(s)
    )
}

fn xdc(s: &Schedule, p: &Plan) -> String {
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
        "set_property IOSTANDARD LVCMOS33 [get_ports {{clk rst adc_miso[*] adc_cs_n[*] adc_sclk[*] mux_sel[*] mux_en[*] sample_valid sample_channel[*] sample_value[*]}}]"
    );
    let _ = writeln!(t, "# Pin locations: uncomment and fill in for your board.");
    let bits = port_bits(s, p);
    for (bit, _) in &bits {
        let _ = writeln!(
            t,
            "# set_property PACKAGE_PIN <pin> [get_ports {{{}}}]",
            pnr_name(&bits, bit)
        );
    }
    t
}

fn pcf_template(s: &Schedule, p: &Plan) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# slotforge_top iCE40 pin constraints (template) for mix \"{}\"",
        s.mix.name
    );
    let _ = writeln!(
        t,
        "# No board file was given: replace every <pin> and uncomment, or emit with a board file."
    );
    let bits = port_bits(s, p);
    for (bit, dir) in &bits {
        let _ = writeln!(t, "# set_io {} <pin>    # {dir}", pnr_name(&bits, bit));
    }
    t
}

fn pcf_board(s: &Schedule, p: &Plan, path: &Path, b: &Board) -> Result<String, HdlError> {
    let bits = port_bits(s, p);
    let err = |m: String| HdlError::Board {
        path: path.display().to_string(),
        message: m,
    };
    for k in b.pins.keys() {
        if !bits.iter().any(|(n, _)| n == k) {
            // Pins for bits another mix has (e.g. adc_cs_n[7]) are fine; only
            // names that can never be a port bit are errors.
            let base = k.split('[').next().unwrap_or("");
            let known = [
                "clk",
                "rst",
                "adc_miso",
                "adc_cs_n",
                "adc_sclk",
                "mux_sel",
                "mux_en",
                "sample_valid",
                "sample_channel",
                "sample_value",
            ];
            if !known.contains(&base) {
                return Err(err(format!("[pins] names `{k}`, which is not a port bit")));
            }
        }
    }
    let mut used: Vec<&str> = vec![];
    let mut pool = b
        .pool
        .pins
        .iter()
        .filter(|x| !b.pins.values().any(|v| v == *x));
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# slotforge_top iCE40 pin constraints for mix \"{}\" on board \"{}\" ({} {})",
        s.mix.name, b.name, b.device, b.package
    );
    for (bit, dir) in &bits {
        let pin = match b.pins.get(bit) {
            Some(x) => x.as_str(),
            None => match pool.next() {
                Some(x) => x.as_str(),
                None => {
                    return Err(err(format!(
                        "no pin for `{bit}`: [pins] does not name it and the [pool] is exhausted ({} port bits)",
                        bits.len()
                    )))
                }
            },
        };
        if used.contains(&pin) {
            return Err(err(format!("pin {pin} is assigned twice")));
        }
        used.push(pin);
        let _ = writeln!(t, "set_io {} {pin}    # {dir}", pnr_name(&bits, bit));
    }
    Ok(t)
}
