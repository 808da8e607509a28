//! The formal harness: a Verilog module generated from the schedule alone
//! that instantiates `slotforge_top` (any Verilog on the port contract),
//! drives `rst` high in the first cycle only, leaves `adc_miso` free, and
//! asserts in every later cycle that each output equals what
//! `docs/timing.md` says it must be.
//!
//! The expected values come from a shadow position (cycle in slot, slot in
//! frame, first frame or not) and tables of the frame table (full, or
//! compact for long frames: `harness/compact.rs`); the expected sample words come
//! from the MISO bits the harness itself records at the contract's capture
//! edges.  A mix with a link to the host gets the link's properties, and
//! for AXI4-Stream the slave its guarantee allows (`harness/link.rs`).  Nothing here
//! reads `hdl`: like the judge's model, the harness is a second reading of
//! the schedule.

use std::fmt::Write;

use lut_gen::Schedule;
use lut_gen::{Layout, Role, TOP_MODULE};
use lut_gen::{SpiTiming, Start};

mod command;
mod compact;
mod contract;
mod link;
mod modes;
mod packets;
mod uart;
pub use contract::{contract, not_covered, Clause};
pub use link::{LinkBytes, AXIS_BYTES_MAX_WAIT, SLAVE_WAIT, TREADY_ANY};
pub(crate) use modes::{auto_frames, bounded_modes, trigger_runs, MODE_SEL};
pub(crate) use packets::FRAME_COUNTER;

/// The module name of the harness.
pub const HARNESS_MODULE: &str = "slotforge_formal";

/// One named property of the harness: `wire` is its `ok_*` signal.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PropertyDef {
    /// As reports name it: `conversion[standard]`, `stream.value`.
    pub name: String,
    /// The harness wire that is 1 while the property holds.
    pub wire: String,
    /// What it asserts, in the contract's words.
    pub what: String,
    /// The contract's clauses it asserts (what `prove` reports as covered).
    pub covers: Vec<Clause>,
}

/// A free input of the harness module (besides `clk`): what the engine
/// may choose in every step.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FreeInput {
    pub name: String,
    pub width: u32,
}

/// A generated harness.
#[derive(Debug, Clone)]
pub struct Harness {
    pub verilog: String,
    pub properties: Vec<PropertyDef>,
    /// The module's free inputs in port order: `adc_miso` first, then the
    /// AXI4-Stream slave's [`TREADY_ANY`] for a mix with that link.
    pub inputs: Vec<FreeInput>,
    /// Cycles of one frame (the period of the control path).
    pub frame_cycles: u64,
    /// The clauses of the mix's contract no property asserts
    /// ([`not_covered`]): a proof of this harness says nothing of them.
    pub not_covered: Vec<Clause>,
}

impl Harness {
    /// This harness asserting only the properties `keep` selects: the same
    /// module and inputs, its `ok` the conjunction of those (the others'
    /// logic stays in the text, read by nothing, and yosys drops it).
    pub(crate) fn asserting(&self, keep: impl Fn(&PropertyDef) -> bool) -> Harness {
        let properties: Vec<PropertyDef> = self
            .properties
            .iter()
            .filter(|p| keep(p))
            .cloned()
            .collect();
        let wires: Vec<&str> = properties.iter().map(|p| p.wire.as_str()).collect();
        let ok = match wires.is_empty() {
            true => "1'b1".to_string(),
            false => wires.join(" & "),
        };
        let verilog = (self.verilog.lines())
            .map(|l| match l.starts_with(OK_WIRE) {
                true => format!("{OK_WIRE}{ok};"),
                false => l.to_string(),
            })
            .collect::<Vec<String>>()
            .join("\n")
            + "\n";
        Harness {
            verilog,
            properties,
            ..self.clone()
        }
    }
}

impl Harness {
    /// This harness with auto select's decision (`dec`, the mode the next
    /// frame runs) read from a free input `mode_sel` (taken mid-frame)
    /// instead of its triggers, as pin select's is (a value naming no mode
    /// keeps `mnext`): `formal::tied` ties the
    /// design's decision to the same wire.  `None` without that decision.
    pub(crate) fn deciding_by_input(&self, s: &Schedule) -> Option<Harness> {
        let n = modes::modes(s)?.names.len();
        // the request is taken in the middle of a frame, so the design and
        // the harness, which take a decision a cycle or so apart at the
        // frame's end, read the same one
        let g = &s.grid;
        let mid = match g.frame_slots {
            1 => format!("cyc == {}", g.slot_cycles / 2),
            k => format!("slot == {} && cyc == 0", k / 2),
        };
        let mut width = None;
        let mut lines = Vec::new();
        for l in self.verilog.lines() {
            let bits = l
                .strip_prefix("  wire [")
                .and_then(|r| r.split_once("] dec = "));
            match bits {
                Some((w, _)) if width.is_none() && !l.contains(MODE_SEL) => {
                    lines.push(format!(
                        "  reg [{w}] dsel = 0;\n  \
                         always @(posedge clk) if (run && {mid}) dsel <= {MODE_SEL};\n  \
                         wire [{w}] dec = {{1'b0, dsel}} < {n} ? dsel : mnext;"
                    ));
                    width = Some(w.to_string());
                }
                _ => lines.push(l.to_string()),
            }
        }
        let w = width?;
        let top: u32 = w.strip_suffix(":0")?.parse().ok()?;
        let text = lines.join("\n") + "\n";
        let end = text.find("\n);")?;
        let mut inputs = self.inputs.clone();
        inputs.push(FreeInput {
            name: MODE_SEL.into(),
            width: top + 1,
        });
        Some(Harness {
            verilog: format!(
                "{},\n  input [{w}] {MODE_SEL}{}",
                &text[..end],
                &text[end..]
            ),
            inputs,
            ..self.clone()
        })
    }
}

/// The line that begins the harness's conjunction of its properties.
const OK_WIRE: &str = "  wire ok = ";

/// Why a schedule has no harness.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct HarnessError(pub String);

/// Bits to hold `0..n` (at least one).
pub(crate) fn width(n: u64) -> u32 {
    (64 - n.saturating_sub(1).leading_zeros()).max(1)
}

/// The largest frame the full tables cover (one case arm per slot and
/// branch); a longer frame gets the compact tables, held to the same
/// number of case arms per branch (`harness/compact.rs`).
pub const FULL_TABLE_MAX_SLOTS: u64 = 65_536;

/// How the harness writes its per-branch slot tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableForm {
    /// One case arm per frame slot (indexed by the shadow `slot`).
    Full,
    /// One row per slot of the slice, fixed or a rotation group indexed by
    /// the slice in the frame: `lut_gen::lut::CompactLut`'s idea applied to
    /// the harness's rows, for frames beyond [`FULL_TABLE_MAX_SLOTS`].
    Compact,
}

impl TableForm {
    /// The form [`generate`] uses for `s`: full while the frame fits.
    pub fn for_schedule(s: &Schedule) -> TableForm {
        if s.grid.frame_slots <= FULL_TABLE_MAX_SLOTS {
            TableForm::Full
        } else {
            TableForm::Compact
        }
    }
}

/// One slot of a branch's table: the lead channel it converts (`None`:
/// idle) and the mux address `(device, select)` in the slot's first cycle
/// (`mux0`) and after it (`mux1`: the next instant's channel).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) struct Row {
    lead: Option<u32>,
    mux0: (u8, u8),
    mux1: (u8, u8),
}

/// Bits of a [`Row`] constant: `{act, lead, en0, sel0, en1, sel1}`.
fn row_bits(chb: u32, en_n: u32) -> u32 {
    1 + chb + 2 * (en_n + 3)
}

impl Row {
    /// `{act, lead, en0, sel0, en1, sel1}` as a Verilog constant.
    fn verilog(&self, chb: u32, en_n: u32) -> String {
        let (act, lead) = self.lead.map_or((0, 0), |l| (1, l));
        let ((d0, s0), (d1, s1)) = (self.mux0, self.mux1);
        format!(
            "{{1'b{act}, {chb}'d{lead}, {}, 3'd{s0}, {}, 3'd{s1}}}",
            en_const(d0, en_n),
            en_const(d1, en_n)
        )
    }
}

/// Device `d`'s enable as an `en_n`-bit constant.  A branch without mux
/// pins (an internal mux: one enable bit, never compared) may number its
/// inputs past the first device; its bits beyond `en_n` are dropped here,
/// as Verilog would drop them, so the constant fits its width.
pub(crate) fn en_const(d: u8, en_n: u32) -> String {
    let mask = 1u128.checked_shl(en_n).map_or(u128::MAX, |m| m - 1);
    let v = 1u128.checked_shl(u32::from(d)).unwrap_or(0) & mask;
    format!("{en_n}'d{v}")
}

/// Branch `b`'s row for every slot of the frame.
fn branch_rows(s: &Schedule, b: usize) -> Vec<Row> {
    let fs = s.grid.frame_slots as usize;
    let lead: Vec<Option<u32>> = (0..fs)
        .map(|slot| s.at(slot as u64, b).map(|c| c as u32))
        .collect();
    let addr = |ch: u32| {
        let c = &s.channels[ch as usize];
        (c.device as u8, c.select as u8)
    };
    // next[slot]: the lead of the first instant in a later slot (cyclic).
    let mut next = vec![None; fs];
    let mut upcoming = None;
    for pass in 0..2 {
        for slot in (0..fs).rev() {
            if pass == 1 {
                next[slot] = upcoming;
            }
            if let Some(l) = lead[slot] {
                upcoming = Some(l);
            }
        }
    }
    let idle = (0u8, 0u8);
    (0..fs)
        .map(|slot| {
            let mux1 = next[slot].map_or(idle, addr);
            Row {
                lead: lead[slot],
                mux0: lead[slot].map_or(mux1, addr),
                mux1,
            }
        })
        .collect()
}

/// The harness module's free inputs for `s` (see [`Harness::inputs`]);
/// `s` must be within the contract's limits.
pub fn free_inputs(s: &Schedule) -> Vec<FreeInput> {
    let mut inputs = vec![FreeInput {
        name: "adc_miso".into(),
        width: s.branches.len() as u32,
    }];
    inputs.extend(link::inputs(&Layout::new(s)));
    inputs.extend(modes::inputs(s));
    inputs
}

/// Generates the harness for `s`, its slot tables in the form
/// [`TableForm::for_schedule`] picks.
pub fn generate(s: &Schedule) -> Result<Harness, HarnessError> {
    generate_with(s, TableForm::for_schedule(s))
}

/// Generates the harness for `s` with its slot tables in `form` (both forms
/// describe the same schedule; a test holds them to it).
pub fn generate_with(s: &Schedule, form: TableForm) -> Result<Harness, HarnessError> {
    generate_parts(s, form, LinkBytes::Asserted)
}

/// [`generate_with`], with the link's bytes asserted or left out.
pub fn generate_parts(
    s: &Schedule,
    form: TableForm,
    bytes: LinkBytes,
) -> Result<Harness, HarnessError> {
    Layout::fits(s).map_err(HarnessError)?;
    let g = &s.grid;
    if form == TableForm::Full && g.frame_slots > FULL_TABLE_MAX_SLOTS {
        return Err(HarnessError(format!(
            "mix `{}`: a frame of {} slots is beyond the formal harness's full tables ({FULL_TABLE_MAX_SLOTS})",
            s.mix.name, g.frame_slots
        )));
    }
    let layout = Layout::new(s);
    let nb = s.branches.len();
    if form == TableForm::Compact && (0..nb).any(|b| s.has_command(b)) {
        return Err(HarnessError(format!(
            "mix `{}`: a frame of {} slots with a command word is beyond the formal harness (its words are tabled per slot, at most {FULL_TABLE_MAX_SLOTS})",
            s.mix.name, g.frame_slots
        )));
    }
    if let Some(why) = modes::refused(s) {
        return Err(HarnessError(why));
    }
    if form == TableForm::Compact && modes::bits(s) > 0 {
        return Err(HarnessError(format!(
            "mix `{}`: a frame of {} slots with modes is beyond the formal harness (every mode's table is full, at most {FULL_TABLE_MAX_SLOTS} slots)",
            s.mix.name, g.frame_slots
        )));
    }
    if let Some(b) = (0..nb).find(|&b| modes::bits(s) > 0 && s.holdoff(b) > 0 && layout.muxed[b]) {
        return Err(HarnessError(format!(
            "branch {}: a mux that switches after a hold-off in a mix with modes is beyond the formal harness (its mode rows assume the switch at the slot tick)",
            s.branches[b].name
        )));
    }
    let total_words: u64 = (0..nb).map(|b| u64::from(s.branches[b].spi.words)).sum();
    for (b, p) in s.branches.iter().enumerate() {
        let spi = &p.spi;
        if spi.tick_to_complete() >= g.slot_cycles {
            return Err(HarnessError(format!(
                "branch {}: a conversion of {} cycles does not end within its slot of {}",
                p.name,
                spi.tick_to_complete(),
                g.slot_cycles
            )));
        }
        // The harness reads a finished conversion's words from its capture
        // register until they have left; the next capture must come later.
        let room = g.slot_cycles - spi.read_cycles + spi.setup_cycles + spi.sclk_half - 1;
        if room <= total_words {
            return Err(HarnessError(format!(
                "branch {b}: {room} cycles between a conversion's end and the next capture, \
                 fewer than the {total_words} words the merged stream may hold"
            )));
        }
    }
    let tables = (0..nb)
        .map(|b| slot_table(s, &layout, b, form))
        .collect::<Result<Vec<String>, HarnessError>>()?;
    let mut v = String::new();
    let mut props = Vec::new();
    header(&mut v, s, &layout, form);
    for (b, table) in tables.iter().enumerate() {
        branch(&mut v, &mut props, s, &layout, b, table);
    }
    merger(&mut v, &mut props, s, &layout);
    modes::decide(&mut v, &mut props, s, &layout);
    if layout.link {
        link::properties(&mut v, &mut props, s, &layout, bytes);
    }
    let _ = writeln!(v, "{OK_WIRE}{};", {
        let w: Vec<&str> = props
            .iter()
            .map(|p: &PropertyDef| p.wire.as_str())
            .collect();
        w.join(" & ")
    });
    v.push_str("  // Checked from the reset cycle's outputs on (step 0 is before any edge).\n");
    v.push_str("`ifdef FORMAL\n  always @* if (st != 2'd0) assert (ok);\n`endif\nendmodule\n");
    Ok(Harness {
        verilog: v,
        not_covered: not_covered(s, &props),
        properties: props,
        inputs: free_inputs(s),
        frame_cycles: g.frame_cycles,
    })
}

/// The declarations of the top's mux ports; none when no branch has a mux
/// (the top then has neither port).
fn mux_wires(layout: &Layout) -> String {
    if !layout.has(Role::MuxSel) {
        return String::new();
    }
    format!(
        "\n  wire [{}:0] mux_sel;\n  wire [{}:0] mux_en;",
        layout.width(Role::MuxSel) - 1,
        layout.width(Role::MuxEn) - 1
    )
}

/// The `en` fields of branch `b`'s slot-table rows: its devices, and one
/// constant device for a branch without a mux (whose rows are never
/// compared with any pin: it has none).
fn row_en(layout: &Layout, b: usize) -> u32 {
    layout.en_n[b].max(1)
}

fn header(v: &mut String, s: &Schedule, layout: &Layout, form: TableForm) {
    let g = &s.grid;
    let nb = s.branches.len();
    let w = |r: Role| layout.width(r);
    let mut extra: String = link::inputs(layout)
        .iter()
        .map(|i| format!(",\n  input {}", i.name))
        .collect();
    extra.push_str(&modes::ports(s));
    let _ = writeln!(
        v,
        "// slotforge prove: formal harness of mix `{}`, generated from its schedule.\n\
         // rst is high in step 0 only; adc_miso is free; every output is asserted\n\
         // equal to docs/timing.md's value from the reset cycle (step 1) on.\n\
         module {HARNESS_MODULE} (\n  input clk,\n  input [{}:0] adc_miso{extra}\n);",
        s.mix.name,
        nb - 1
    );
    let _ = writeln!(
        v,
        "  // st: 0 before the reset edge, 1 the reset cycle, 2 cycle 0 on.\n  \
         reg [1:0] st = 2'd0;\n  wire rst = st == 2'd0;\n  \
         wire [{}:0] adc_cs_n, adc_sclk;{}{}\n  \
         wire sample_valid;\n  wire [{}:0] sample_channel;\n  wire [{}:0] sample_value;",
        nb - 1,
        command::port(layout).0,
        mux_wires(layout),
        w(Role::SampleChannel) - 1,
        w(Role::SampleValue) - 1
    );
    // A mix with a link has its ports after the contract's (Layout::link_ports).
    link::declare(v, s, layout);
    let link_ports = link::connections(layout) + &modes::connections(s);
    let _ = writeln!(
        v,
        "  {TOP_MODULE} dut (.clk(clk), .rst(rst), .adc_miso(adc_miso), .adc_cs_n(adc_cs_n),\n    \
         .adc_sclk(adc_sclk),{}{} .sample_valid(sample_valid),\n    \
         .sample_channel(sample_channel), .sample_value(sample_value){link_ports});",
        command::port(layout).1,
        if layout.has(Role::MuxSel) {
            " .mux_sel(mux_sel), .mux_en(mux_en),"
        } else {
            ""
        }
    );
    let (cb, sb) = (width(g.slot_cycles), width(g.frame_slots));
    let _ = writeln!(
        v,
        "  // Shadow position: cycle in slot, slot in frame, first frame after reset.\n  \
         reg [{}:0] cyc = 0;\n  reg [{}:0] slot = 0;\n  reg first = 1'b1;\n  \
         wire slot_end = cyc == {cb}'d{};\n  wire frame_end = slot_end && slot == {sb}'d{};\n  \
         always @(posedge clk) begin\n    if (st != 2'd2) st <= st + 2'd1;\n    \
         if (st == 2'd2) begin\n      cyc <= slot_end ? {cb}'d0 : cyc + {cb}'d1;\n      \
         if (slot_end) slot <= frame_end ? {sb}'d0 : slot + {sb}'d1;\n      \
         if (frame_end) first <= 1'b0;\n    end\n  end\n  wire run = st == 2'd2;",
        cb - 1,
        sb - 1,
        g.slot_cycles - 1,
        g.frame_slots - 1
    );
    if form == TableForm::Compact {
        compact::counters(v, g);
    }
    modes::declare(v, s);
}

/// `cyc` within any of the half-open ranges.
fn ranges(cb: u32, rs: &[(u64, u64)]) -> String {
    if rs.is_empty() {
        return "1'b0".into();
    }
    let t: Vec<String> = rs
        .iter()
        .map(|&(a, b)| format!("(cyc >= {cb}'d{a} && cyc < {cb}'d{b})"))
        .collect();
    t.join(" || ")
}

/// Branch `b`'s slot table in `form`: the body that sets `tab{b}` from the
/// shadow position.
fn slot_table(
    s: &Schedule,
    layout: &Layout,
    b: usize,
    form: TableForm,
) -> Result<String, HarnessError> {
    let rows = branch_rows(s, b);
    let (chb, en_n) = (layout.channel_bits, row_en(layout, b));
    let word = |r: &Row| r.verilog(chb, en_n);
    if modes::bits(s) > 0 {
        return Ok(modes::table(s, b, &modes::rows(s, b), &word));
    }
    match form {
        TableForm::Full => Ok(full_table(s, b, &rows, &word)),
        TableForm::Compact => compact::table(s, b, &rows, &word, row_bits(chb, en_n)),
    }
}

/// One case arm per frame slot; the most common row is the default arm.
fn full_table(s: &Schedule, b: usize, rows: &[Row], word: &dyn Fn(&Row) -> String) -> String {
    let sb = width(s.grid.frame_slots);
    let rows: Vec<String> = rows.iter().map(word).collect();
    let default = most_common(&rows);
    let mut v = String::from("  always @* case (slot)\n");
    for (slot, row) in rows.iter().enumerate() {
        if *row != default {
            let _ = writeln!(v, "    {sb}'d{slot}: tab{b} = {row};");
        }
    }
    let _ = writeln!(v, "    default: tab{b} = {default};\n  endcase");
    v
}

/// The most frequent of `rows` (ties: the least text), for a default arm.
pub(crate) fn most_common(rows: &[String]) -> String {
    let mut counts = std::collections::BTreeMap::new();
    for r in rows {
        *counts.entry(r.as_str()).or_insert(0usize) += 1;
    }
    counts
        .iter()
        .max_by_key(|(r, n)| (**n, std::cmp::Reverse(**r)))
        .map(|(r, _)| r.to_string())
        .unwrap_or_default()
}

/// Bit positions of a branch's slot-table row `{act, lead, en0, sel0, en1, sel1}`
/// (lowest bit of each field; `act` is one bit).
struct RowFields {
    sel1: u32,
    en1: u32,
    sel0: u32,
    en0: u32,
    lead: u32,
    act: u32,
}

impl RowFields {
    fn new(chb: u32, en_n: u32) -> RowFields {
        let sel0 = 3 + en_n;
        let en0 = sel0 + 3;
        let lead = en0 + en_n;
        RowFields {
            sel1: 0,
            en1: 3,
            sel0,
            en0,
            lead,
            act: lead + chb,
        }
    }
}

fn branch(
    v: &mut String,
    props: &mut Vec<PropertyDef>,
    s: &Schedule,
    layout: &Layout,
    b: usize,
    table: &str,
) {
    let p = &s.branches[b];
    let spi = &p.spi;
    let n = spi.sclks();
    let cnv = spi.style == Start::Cnv;
    let _ = writeln!(
        v,
        "\n  // Branch {b} `{}`: setup {}, SCLK period {} (half {}), {n} SCLKs, read {} cycles, {}.",
        p.name,
        spi.setup_cycles,
        spi.sclk_div,
        spi.sclk_half,
        spi.read_cycles,
        if cnv { "CNV active high, SCK idles low" } else { "CS active low, SCLK idles high" }
    );
    // Slot table: {act, lead, en0, sel0, en1, sel1}.
    let _ = writeln!(
        v,
        "  reg [{}:0] tab{b};",
        row_bits(layout.channel_bits, row_en(layout, b)) - 1
    );
    v.push_str(table);
    branch_conversion(v, s, layout, b);
    branch_expectations(v, s, layout, b);
    branch_properties(props, b, &p.name, layout.muxed[b]);
    command::mosi(v, props, s, layout, b);
}

/// The row's `act` and `lead` fields, and when branch `b` converts.
fn branch_conversion(v: &mut String, s: &Schedule, layout: &Layout, b: usize) {
    let (cb, sb) = (width(s.grid.slot_cycles), width(s.grid.frame_slots));
    let chb = layout.channel_bits;
    let row = RowFields::new(chb, row_en(layout, b));
    // the conversion's window: its hold-off after the slot tick, then the read
    let (h, r) = (s.holdoff(b), s.branches[b].spi.tick_to_complete());
    let skip = s.skipped_at_startup(b, 0);
    let from = match h {
        0 => String::new(),
        _ => format!("cyc >= {cb}'d{h} && "),
    };
    let _ = writeln!(
        v,
        "  wire act{b} = tab{b}[{}];\n  wire [{}:0] lead{b} = tab{b}[{}:{}];\n  \
         // Instants at cycle 0 whose mux cannot have settled are skipped (Start-up).\n  \
         wire conv{b} = run && act{b}{};\n  wire busy{b} = conv{b} && {from}cyc < {cb}'d{r};",
        row.act,
        chb - 1,
        row.act - 1,
        row.lead,
        if skip {
            format!(" && !(first && slot == {sb}'d0)")
        } else {
            String::new()
        }
    );
}

/// SCLK's low and high phases within the slot, and the cycles MISO is
/// captured in (the last cycle of each low phase; a CNV part's first bit
/// is out before the first SCLK).
struct SclkPhases {
    /// `[from, to)` cycle ranges of the slot.
    low: Vec<(u64, u64)>,
    high: Vec<(u64, u64)>,
    /// `cyc == ...` conditions of the capture cycles.
    capture: Vec<String>,
}

fn sclk_phases(spi: &SpiTiming, cb: u32) -> SclkPhases {
    // counted from the slot tick: the hold-off, then the setup
    let (su, d, h) = (
        spi.holdoff_cycles + spi.setup_cycles,
        spi.sclk_div,
        spi.sclk_half,
    );
    let n = spi.sclks();
    let caps = if spi.style == Start::Cnv { n } else { n - 1 };
    let mut low = Vec::new();
    let mut high = Vec::new();
    let mut capc = Vec::new();
    for i in 0..n {
        let fall = su + i * d;
        low.push((fall, fall + h));
        high.push((fall + h, fall + d));
        if i < caps {
            capc.push(format!("cyc == {cb}'d{}", fall + h - 1));
        }
    }
    SclkPhases {
        low,
        high,
        capture: capc,
    }
}

/// What branch `b`'s pins must be in every cycle, the MISO bits it
/// captures, and the wires comparing the two.
fn branch_expectations(v: &mut String, s: &Schedule, layout: &Layout, b: usize) {
    let spi = &s.branches[b].spi;
    let cb = width(s.grid.slot_cycles);
    let en_n = row_en(layout, b);
    let row = RowFields::new(layout.channel_bits, en_n);
    let (r, n) = (spi.tick_to_complete(), spi.sclks());
    let hold = spi.holdoff_cycles;
    let SclkPhases {
        low,
        high,
        capture: capc,
    } = sclk_phases(spi, cb);
    let (cs_exp, sclk_exp) = if spi.style == Start::Cnv {
        (
            // read with CNV low: CNV is high for the conversion alone
            if spi.pin_cycles < spi.read_cycles {
                match hold {
                    0 => format!("conv{b} && cyc < {cb}'d{}", spi.pin_cycles),
                    _ => format!(
                        "conv{b} && cyc >= {cb}'d{hold} && cyc < {cb}'d{}",
                        hold + spi.pin_cycles
                    ),
                }
            } else {
                format!("busy{b}")
            },
            format!("conv{b} && ({})", ranges(cb, &high)),
        )
    } else {
        (
            format!("!busy{b}"),
            format!("!(conv{b} && ({}))", ranges(cb, &low)),
        )
    };
    let ok_mux = if layout.muxed[b] {
        let (sel_hi, sel_lo) = layout.lane_bits(Role::MuxSel, b);
        let (en_hi, en_lo) = layout.lane_bits(Role::MuxEn, b);
        format!("mux_sel[{sel_hi}:{sel_lo}] == exp_sel{b} && mux_en[{en_hi}:{en_lo}] == exp_en{b}")
    } else {
        "1'b1".to_string() // no mux pins; its property is not listed
    };
    let (lo1, lo_e1, lo0, lo_e0) = (row.sel1, row.en1, row.sel0, row.en0);
    let (e0, e1) = ((lo_e0 + en_n - 1, lo_e0), (lo_e1 + en_n - 1, lo_e1));
    if modes::bits(s) > 0 {
        // across frames: the mode in force's rows, the next frame's first instant
        let _ = writeln!(
            v,
            "  wire [{}:0] m0{b} = {{tab{b}[{}:{}], tab{b}[{}:{lo0}]}};\n  \
             wire [{}:0] m1{b} = {{tab{b}[{}:{}], tab{b}[{}:{lo1}]}};",
            en_n + 2,
            e0.0,
            e0.1,
            lo0 + 2,
            en_n + 2,
            e1.0,
            e1.1,
            lo1 + 2
        );
        modes::mux(v, s, b, &modes::rows(s, b), en_n);
        let _ = writeln!(
            v,
            "  wire [{}:0] exp_en{b} = exp_m{b}[{}:3];\n  wire [2:0] exp_sel{b} = exp_m{b}[2:0];",
            en_n - 1,
            en_n + 2
        );
    } else {
        // the mux holds this slot's instant until the conversion starts
        let held = match hold {
            0 => format!("cyc == {cb}'d0"),
            _ => format!("cyc <= {cb}'d{hold}"),
        };
        let _ = writeln!(
            v,
            "  wire [{}:0] exp_en{b} = {held} ? tab{b}[{}:{}] : tab{b}[{}:{}];\n  \
             wire [2:0] exp_sel{b} = {held} ? tab{b}[{}:{lo0}] : tab{b}[{}:{lo1}];",
            en_n - 1,
            e0.0,
            e0.1,
            e1.0,
            e1.1,
            lo0 + 2,
            lo1 + 2
        );
    }
    let _ = writeln!(
        v,
        "  wire exp_cs{b} = {cs_exp};\n  wire exp_sclk{b} = {sclk_exp};\n  \
         wire cap{b} = conv{b} && ({});\n  \
         reg [{}:0] w{b} = 0;\n  always @(posedge clk) if (cap{b}) w{b} <= {{w{b}[{}:0], adc_miso[{b}]}};\n  \
         wire ok_cs{b} = adc_cs_n[{b}] == exp_cs{b};\n  wire ok_sclk{b} = adc_sclk[{b}] == exp_sclk{b};\n  \
         wire ok_mux{b} = {ok_mux};",
        capc.join(" || "),
        n - 1,
        n.saturating_sub(2),
    );
    command::done(v, s, b, &format!("conv{b} && cyc == {cb}'d{r}"));
}

/// The properties of branch `b`, called `name`.
fn branch_properties(props: &mut Vec<PropertyDef>, b: usize, name: &str, muxed: bool) {
    props.push(PropertyDef {
        name: format!("conversion[{name}]"),
        wire: format!("ok_cs{b}"),
        covers: vec![Clause::Conversion(b)],
        what: "the conversion pin is active exactly in each scheduled conversion window \
               (every channel every interval at its phase, nothing else)"
            .into(),
    });
    props.push(PropertyDef {
        name: format!("sclk[{name}]"),
        wire: format!("ok_sclk{b}"),
        covers: vec![Clause::Sclk(b)],
        what: "SCLK count, period, phase and idle level of every conversion as the part needs"
            .into(),
    });
    if !muxed {
        return; // a branch without a mux has no mux pins to assert
    }
    props.push(PropertyDef {
        name: format!("mux[{name}]"),
        wire: format!("ok_mux{b}"),
        covers: vec![Clause::Mux(b)],
        what: "mux select and device enable address the next instant's channel, switching only \
               right after a conversion starts (settled before it, steady through its capture)"
            .into(),
    });
}

fn merger(v: &mut String, props: &mut Vec<PropertyDef>, s: &Schedule, layout: &Layout) {
    let nb = s.branches.len();
    let _ = writeln!(
        v,
        "\n  // Merged stream: a finished conversion's words wait per branch; the lowest\n  \
         // waiting branch's next word leaves in the next cycle (its value: the MISO bits\n  \
         // recorded above, whatever they were)."
    );
    for b in 0..nb {
        merger_queue(v, s, layout, b);
    }
    merger_output(v, nb, layout);
    merger_properties(props);
}

/// Branch `b`'s waiting words: how many its conversion leaves, and the
/// channel and value of each.
fn merger_queue(v: &mut String, s: &Schedule, layout: &Layout, b: usize) {
    let chb = layout.channel_bits;
    let vb = layout.value_bits;
    let spi = &s.branches[b].spi;
    let maxw = spi.words as u64;
    let nwb = width(maxw + 1);
    // every mode's leads (one schedule without modes)
    let all = std::slice::from_ref(s);
    let scheds = if s.modes.is_empty() {
        all
    } else {
        &s.modes[..]
    };
    let mut leads: Vec<usize> = (scheds.iter())
        .flat_map(|ms| (0..s.grid.frame_slots).filter_map(move |slot| ms.at(slot, b)))
        .collect();
    leads.sort_unstable();
    leads.dedup();
    // Words per lead, channel and value of each (lead, word index).
    let _ = writeln!(
        v,
        "  reg [{}:0] nw{b};\n  reg [{}:0] wch{b};\n  reg [{}:0] wval{b};\n  reg [{}:0] pw{b} = 0, wi{b} = 0;\n  \
         reg [{}:0] pc{b} = 0;\n  wire [{}:0] pw_e{b} = done{b} ? nw{b} : pw{b};\n  \
         wire [{}:0] wi_e{b} = done{b} ? {nwb}'d0 : wi{b};\n  wire [{}:0] pc_e{b} = done{b} ? lead{b} : pc{b};\n  \
         wire av{b} = pw_e{b} != {nwb}'d0;",
        nwb - 1,
        chb - 1,
        vb - 1,
        nwb - 1,
        chb - 1,
        nwb - 1,
        nwb - 1,
        chb - 1,
    );
    let _ = writeln!(v, "  always @* case (lead{b})");
    for &l in &leads {
        let _ = writeln!(
            v,
            "    {chb}'d{l}: nw{b} = {nwb}'d{};",
            s.words_of(l).count()
        );
    }
    let _ = writeln!(v, "    default: nw{b} = {nwb}'d0;\n  endcase");
    merger_words(v, s, chb, nwb, b, &leads);
}

/// The channel and value of each (lead, word index) of branch `b`: the
/// word's bits sit in the shift register by their position in the frame.
fn merger_words(v: &mut String, s: &Schedule, chb: u32, nwb: u32, b: usize, leads: &[usize]) {
    let spi = &s.branches[b].spi;
    let n = spi.sclks();
    let _ = writeln!(
        v,
        "  always @* begin\n    wch{b} = 0; wval{b} = 0;\n    case ({{pc_e{b}, wi_e{b}}})"
    );
    for &l in leads {
        for (i, (m, c)) in s.words_of(l).enumerate() {
            let end = m as u64 * spi.word_sclks as u64 + spi.leading_bits as u64 + spi.bits as u64;
            let lo = n - end;
            let hi = lo + spi.bits as u64 - 1;
            let _ = writeln!(
                v,
                "      {{{chb}'d{l}, {nwb}'d{i}}}: begin wch{b} = {chb}'d{c}; wval{b} = w{b}[{hi}:{lo}]; end"
            );
        }
    }
    let _ = writeln!(v, "      default: ;\n    endcase\n  end");
}

/// The expected stream: the lowest waiting branch's next word each cycle,
/// and the wires comparing it with the design's.
fn merger_output(v: &mut String, nb: usize, layout: &Layout) {
    let _ = writeln!(
        v,
        "  reg exp_valid = 1'b0;\n  reg [{}:0] exp_ch = 0;\n  reg [{}:0] exp_val = 0;\n  \
         always @(posedge clk) if (run) begin",
        layout.channel_bits - 1,
        layout.value_bits - 1
    );
    for b in 0..nb {
        let _ = writeln!(
            v,
            "    pw{b} <= pw_e{b}; wi{b} <= wi_e{b}; pc{b} <= pc_e{b};"
        );
    }
    let avs: Vec<String> = (0..nb).map(|b| format!("av{b}")).collect();
    let _ = writeln!(v, "    exp_valid <= {};", avs.join(" || "));
    for b in 0..nb {
        let kw = if b == 0 { "if" } else { "else if" };
        let _ = writeln!(
            v,
            "    {kw} (av{b}) begin\n      exp_ch <= wch{b}; exp_val <= wval{b};\n      \
             pw{b} <= pw_e{b} - 1'b1; wi{b} <= wi_e{b} + 1'b1;\n    end"
        );
    }
    v.push_str("  end\n");
    let _ = writeln!(
        v,
        "  wire ok_valid = sample_valid == exp_valid;\n  wire ok_channel = sample_channel == exp_ch;\n  \
         wire ok_value = sample_value == exp_val;"
    );
}

fn merger_properties(props: &mut Vec<PropertyDef>) {
    for (name, wire, clause, what) in [
        (
            "stream.valid",
            "ok_valid",
            Clause::StreamValid,
            "one word leaves per finished conversion word, in the model's order: no drop, no duplicate, no overflow",
        ),
        (
            "stream.channel",
            "ok_channel",
            Clause::StreamChannel,
            "each word carries the channel index of its conversion (chain member)",
        ),
        (
            "stream.value",
            "ok_value",
            Clause::StreamValue,
            "each word carries the data bits MISO carried at the capture edges, for any input",
        ),
    ] {
        props.push(PropertyDef {
            name: name.into(),
            wire: wire.into(),
            what: what.into(),
            covers: vec![clause],
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths() {
        assert_eq!(width(1), 1);
        assert_eq!(width(2), 1);
        assert_eq!(width(3), 2);
        assert_eq!(width(1600), 11);
        assert_eq!(width(1024), 10);
    }
}
