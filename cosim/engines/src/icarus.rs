//! The Icarus back end: the emitted `slotforge_top.v` in Icarus Verilog with
//! a Verilog AD7940 per branch (`cosim/engines/tb/adc_tb.v.in`), run by `vvp` into a
//! temporary VCD that the streaming VCD checker then reads (every invariant
//! and cycle-exact equality with the reference model), like any waveform
//! handed to `slotforge check`.
//!
//! The testbench's ADCs give the same codes as cosim's cycle-level ADC model
//! ([`judge::Adc`]) for the chosen stimulus: `pattern` by the same
//! formula, the others from a table of the schedule's conversions (a
//! conversion the schedule does not expect falls back to the pattern
//! formula; the checker decodes every value from MISO in any case).  Reset
//! lasts [`judge::reset_cycles`] cycles (the run's `reset_cycles`, one
//! at the least), as in the in-process back ends.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::Path;

use lut_gen::Schedule;

use judge::edge_ps;
use judge::tools::{Tool, ToolError};
use judge::CycleSink;
use judge::Verdict;
use judge::{Analog, Stimulus};
use lut_gen::Start;
use lut_gen::{Dir, Layout, Pins, Role, AXIS_PORTS, TOP_MODULE};

use crate::error::{BackendError, SimError};
use crate::options::{SimOptions, VcdOut};

const TEMPLATE: &str = include_str!("../tb/adc_tb.v.in");

/// A generated testbench: `tb.v` and the code tables it reads (`codes<b>.hex`).
#[derive(Debug, Clone)]
pub struct Testbench {
    pub tb: String,
    pub tables: Vec<(String, String)>,
    /// Reset cycles before cycle 0.
    pub reset_cycles: u64,
}

/// The testbench for `cycles` cycles after reset with `stimulus`.
pub fn testbench(s: &Schedule, stimulus: Stimulus, reset_cycles: u64, cycles: u64) -> Testbench {
    testbench_with(
        s,
        stimulus,
        reset_cycles,
        cycles,
        link::ReadyPattern::Always,
        &[],
    )
}

/// [`testbench`] with the AXI4-Stream slave driving `tready` as `pattern`
/// (a mix with an `axis` link; ignored otherwise) and `mode_sel` showing
/// `modes` (`(frame, mode)` requests, as `judge::ModeRequests` drives it; a
/// mix with pin-selected modes).
pub fn testbench_with(
    s: &Schedule,
    stimulus: Stimulus,
    reset_cycles: u64,
    cycles: u64,
    tready: link::ReadyPattern,
    modes: &[(u64, u8)],
) -> Testbench {
    let mut g = Adcs {
        s,
        l: Layout::new(s),
        analog: Analog::new(s, stimulus),
        stimulus,
        frames: cycles.div_ceil(s.grid.frame_cycles),
        switched: (s.modes.len() > 1).then(|| switched_conversions(s, stimulus, modes, cycles)),
        text: String::new(),
        tables: Vec::new(),
    };
    for b in 0..g.l.branches {
        let _ = writeln!(g.text, "  // branch {b} ({})", s.branches[b].name);
        if s.has_command(b) {
            g.commanded(b);
        } else if s.mix.branches[b].adc.start == Start::Cnv {
            g.cnv_chain(b);
        } else {
            g.cs_part(b);
        }
    }
    if let Some(a) = lut_gen::plan_link(s)
        .and_then(|p| p.ok())
        .and_then(|p| p.axis())
    {
        g.text.push_str(&axis_slave(tready, a.ready_within));
    }
    if g.l.mode_pin {
        g.text.push_str(&mode_requests(s, &g.l, modes));
    }
    let connect = (g.l.ports())
        .map(|p| p.name)
        .chain(g.l.link_ports().iter().map(|p| p.name))
        .chain(g.l.mode_ports().iter().map(|p| p.name))
        .map(|n| format!(".{n}({n})"))
        .collect::<Vec<_>>()
        .join(",\n    ");
    let nch = s.channels.len() as u64;
    let mut tb = TEMPLATE
        .replace("@DECLS@", port_decls(&g.l).trim_end_matches('\n'))
        .replace("@CONNECT@", &connect)
        .replace("@TOP@", TOP_MODULE)
        .replace("@NB@", &g.l.branches.to_string())
        .replace("@RESET@", &reset_cycles.to_string())
        .replace("@CYCLES@", &cycles.to_string())
        .replace("@HZ@", &s.grid.clock_hz.to_string())
        .replace("@SLOT@", &s.grid.slot_cycles.to_string())
        .replace("@NCH_PLUS_64@", &(nch + 64).to_string())
        .replace("@ADCS@", &g.text);
    for r in Role::ALL {
        tb = tb.replace(&format!("@{}@", r.key()), r.name());
    }
    Testbench {
        tb,
        tables: g.tables,
        reset_cycles,
    }
}

/// A mix with modes: each branch's conversions (cycle of the CS fall, the
/// input its mux selects) as the cycle model makes them under `modes` and
/// `stimulus` over `cycles` cycles, so the code tables follow the switches.
fn switched_conversions(
    s: &Schedule,
    stimulus: Stimulus,
    modes: &[(u64, u8)],
    cycles: u64,
) -> Vec<Vec<lut_gen::SamplingInstant>> {
    struct Falls<'a> {
        l: Layout,
        analog: Analog,
        c: u64,
        cs: u16,
        /// CNV branches (their conversion starts at the pin's rise).
        cnv: u16,
        out: &'a mut Vec<Vec<lut_gen::SamplingInstant>>,
    }
    impl judge::Observer for Falls<'_> {
        fn cycle(&mut self, _: u64, rst: bool, p: &Pins, _: u64) {
            if rst {
                self.cs = p.cs_n;
                return;
            }
            for b in 0..self.l.branches {
                let (was, now) = ((self.cs ^ self.cnv) >> b & 1, (p.cs_n ^ self.cnv) >> b & 1);
                if was == 1 && now == 0 {
                    let channel = self.analog.input_id(&self.l, p, b) as usize;
                    self.out[b].push(lut_gen::SamplingInstant {
                        cycle: self.c,
                        branch: b,
                        channel,
                    });
                }
            }
            self.cs = p.cs_n;
            self.c += 1;
        }
    }
    let mut out = vec![Vec::new(); s.branches.len()];
    let mut obs = Falls {
        l: Layout::new(s),
        analog: Analog::new(s, stimulus),
        c: 0,
        cs: u16::MAX,
        cnv: (0..s.branches.len())
            .filter(|&b| s.mix.branches[b].adc.start == Start::Cnv)
            .fold(0, |m, b| m | 1 << b),
        out: &mut out,
    };
    let ro = judge::RunOptions {
        stimulus,
        ..Default::default()
    };
    let mut dut = judge::ModeRequests::new(s, judge::ModelDut::new(s), modes);
    let frames = cycles.div_ceil(s.grid.frame_cycles);
    judge::run_dut(s, &mut dut, frames, &ro, "model", Some(&mut obs));
    out
}

/// The DUT's ports as testbench signals: inputs driven (MISO pulled up,
/// as the ADC model's idle line), outputs as wires.
fn port_decls(l: &Layout) -> String {
    let mut decls = String::new();
    for p in l.ports() {
        let w = l.width(p.role);
        let range = if p.vector {
            format!("[{}:0] ", w - 1)
        } else {
            String::new()
        };
        let _ = match p.role {
            Role::Clock => writeln!(decls, "  reg {} = 0;", p.name),
            Role::Reset => writeln!(decls, "  reg {} = 1;", p.name),
            Role::Miso => writeln!(decls, "  tri1 {range}{};", p.name),
            _ => writeln!(decls, "  wire {range}{};", p.name),
        };
    }
    for p in l.link_ports() {
        let _ = match (p.dir, p.width) {
            (Dir::In, _) => writeln!(decls, "  reg {} = 1;", p.name),
            (_, 1) => writeln!(decls, "  wire {};", p.name),
            (_, w) => writeln!(decls, "  wire [{}:0] {};", w - 1, p.name),
        };
    }
    let range = match l.mode_bits {
        0 | 1 => String::new(),
        w => format!("[{}:0] ", w - 1),
    };
    for p in l.mode_ports() {
        let _ = match p.dir {
            Dir::In => writeln!(decls, "  reg {range}{} = 0;", p.name),
            Dir::Out => writeln!(decls, "  wire {range}{};", p.name),
        };
    }
    decls
}

/// `mode_sel` from `(frame, mode)` requests: from the first cycle of the
/// frame on (0 before the first, and in reset), as `judge::ModeRequests`.
fn mode_requests(s: &Schedule, l: &Layout, modes: &[(u64, u8)]) -> String {
    let name = lut_gen::MODE_PORTS[0].name;
    let mut reqs = modes.to_vec();
    reqs.sort_by_key(|r| r.0);
    let mask = (1u32 << l.mode_bits) - 1;
    let mut t = format!(
        "  // mode_sel: the requests (frame, mode), each from its frame's first cycle\n  // (set mid-cycle, so the cycle counter is current and the edge that ends\n  // the cycle samples it)\n  always @(negedge {}) if (!{} && started) begin\n    {name} <= 0;\n",
        Role::Clock.name(),
        Role::Reset.name()
    );
    for (f, m) in reqs {
        let _ = writeln!(
            t,
            "    if (cyc >= 64'd{}) {name} <= {}'d{};",
            f * s.grid.frame_cycles,
            l.mode_bits,
            m as u32 & mask
        );
    }
    t.push_str("  end\n\n");
    t
}

/// The testbench's ADC models as they are written: the Verilog text and
/// the code tables it reads.
struct Adcs<'a> {
    s: &'a Schedule,
    l: Layout,
    analog: Analog,
    stimulus: Stimulus,
    /// Frames the run covers (the code tables' extent).
    frames: u64,
    /// A mix with modes: each branch's conversions as the model makes them
    /// under the run's requests and stimulus (the modes switch).
    switched: Option<Vec<Vec<lut_gen::SamplingInstant>>>,
    text: String,
    tables: Vec<(String, String)>,
}

impl Adcs<'_> {
    /// The conversions of branch `b` the gateware makes: less those skipped
    /// at start-up (docs/timing.md, "Start-up").
    fn conversions(&self, b: usize) -> Box<dyn Iterator<Item = lut_gen::SamplingInstant> + '_> {
        if let Some(sw) = &self.switched {
            return Box::new(sw[b].iter().copied());
        }
        let s = self.s;
        let f = s.grid.frame_cycles;
        // the conversion starts (CS fall, CNV rise) its hold-off after the tick
        Box::new(
            s.instants(self.frames)
                .filter(move |i| {
                    i.branch == b && !(i.cycle < f && s.skipped_at_startup(b, i.cycle))
                })
                .map(move |i| lut_gen::SamplingInstant {
                    cycle: i.cycle + s.holdoff(b),
                    ..i
                }),
        )
    }

    /// Adds branch `b`'s code table `codes<b>.hex` of `lines` lines, and
    /// declares it in the testbench.
    fn add_table(&mut self, b: usize, hex: String, lines: u64) {
        let name = format!("codes{b}.hex");
        self.tables.push((name.clone(), hex));
        let _ = writeln!(
            self.text,
            "  reg [63:0] tab{b} [0:{}];\n  initial $readmemh(\"{name}\", tab{b});",
            lines - 1
        );
    }

    /// Branch `b`'s part with a command word (`crate::icarus_cmd`), and
    /// for a stimulus other than the pattern its table of codes: each
    /// conversion's channel, or the unselected input of a prepared one.
    fn commanded(&mut self, b: usize) {
        let s = self.s;
        let mut table = String::new();
        if self.stimulus != Stimulus::Pattern {
            let bits = s.mix.branches[b].adc.bits;
            let mut hex = String::new();
            let mut len = 0u64;
            let conv: Vec<_> = self.conversions(b).collect();
            for (k, i) in conv.iter().enumerate() {
                let id = if s.is_prepared(b, k as u64) {
                    s.channels.len() as u64 + 1 + b as u64
                } else {
                    i.channel as u64
                };
                let code =
                    self.analog
                        .code_bits(id, i.cycle + s.branches[b].spi.sample_cycles, bits);
                let _ = writeln!(hex, "{:04x}{:08x}{:04x}", id as u16, i.cycle as u32, code);
                len += 1;
            }
            if len > 0 {
                self.add_table(b, hex, len);
                table = format!(
                    "    if (n{b} < {len} && tab{b}[n{b}][63:48] == id{b}[15:0] && tab{b}[n{b}][47:16] == t{b}[31:0])\n      code{b} = tab{b}[n{b}][15:0];\n"
                );
            }
        }
        let lane = self.l.mosi_lo[b].expect("a commanded branch has an adc_mosi bit");
        let text = crate::icarus_cmd::part(s, b, lane, &table);
        self.text.push_str(&text);
    }

    /// Branch `b`'s part with an active-low CS (AD7940 style).
    fn cs_part(&mut self, b: usize) {
        let _ = writeln!(
            self.text,
            "  reg [15:0] word{b};\n  reg [4:0] falls{b};\n  reg out{b};\n  reg drive{b} = 0;\n  \
             reg [63:0] n{b} = 0;\n  reg [63:0] id{b};\n  reg [13:0] code{b};\n  \
             assign {miso}[{b}] = drive{b} ? out{b} : 1'bz;",
            miso = Role::Miso.name()
        );
        let id_case = id_case(&self.l, &self.analog, b);
        let table = self.cs_table(b);
        let _ = write!(
            self.text,
            "  always @(negedge {cs}[{b}]) if (!{rst}) begin\n{id_case}    \
             code{b} = pattern(cyc, id{b});\n{table}    n{b} = n{b} + 1;\n    \
             word{b} = {{2'b00, code{b}{mask}}};\n    falls{b} = 0;\n    out{b} = word{b}[15];\n    drive{b} = 1;\n  end\n  \
             always @(posedge {cs}[{b}]) drive{b} = 0;\n  \
             always @(negedge {sclk}[{b}]) if (!{cs}[{b}]) begin\n    \
             falls{b} = falls{b} + 1;\n    if (falls{b} >= 16) drive{b} = 0; else out{b} = word{b}[15 - falls{b}];\n  end\n\n",
            // A CS part narrower than 14 bits: its extra leading bits are zeros.
            mask = match self.s.mix.branches[b].adc.bits {
                w if w < 14 => format!(" & 14'h{:x}", (1u32 << w) - 1),
                _ => String::new(),
            },
            cs = Role::CsN.name(),
            sclk = Role::Sclk.name(),
            rst = Role::Reset.name(),
        );
    }

    /// A CS part's code table, and the lines that look a conversion's code
    /// up in it (none for the pattern, which the testbench computes).
    fn cs_table(&mut self, b: usize) -> String {
        if self.stimulus == Stimulus::Pattern {
            return String::new();
        }
        let mut hex = String::new();
        let mut len = 0u64;
        let bits = self.s.mix.branches[b].adc.bits;
        for i in self.conversions(b) {
            let held = i.cycle + self.s.branches[b].spi.sample_cycles;
            let code = self.analog.code_bits(i.channel as u64, held, bits) & 0x3fff;
            let _ = writeln!(
                hex,
                "{:04x}{:08x}{:04x}",
                i.channel as u16, i.cycle as u32, code
            );
            len += 1;
        }
        if len == 0 {
            return String::new();
        }
        self.add_table(b, hex, len);
        format!(
            "    if (n{b} < {len} && tab{b}[n{b}][63:48] == id{b}[15:0] && tab{b}[n{b}][47:16] == cyc[31:0])\n      \
             code{b} = tab{b}[n{b}][13:0];\n"
        )
    }

    /// Branch `b`'s parts in CNV chain mode (AD7685 style, no busy indicator),
    /// as `judge::Adc` models them: at the CNV rising edge every part of
    /// the chain samples its own input (the chain member's channel); while CNV
    /// is high the stream of all words leaves MSB first, member 0's first, one
    /// bit per SCK falling edge, zeros after the last (the first part's SDI is
    /// tied low); CNV low releases the line (pulled up).
    fn cnv_chain(&mut self, b: usize) {
        let part = &self.s.mix.branches[b].adc;
        let chain = self.s.mix.branches[b].chain as usize;
        let len = part.word_sclks() as usize * chain;
        // read with CNV low (never chained): SDO driven while CNV is low,
        // released after the last bit
        let low = part.read == lut_gen::CnvRead::CnvLow;
        let (after, at_rise, at_fall, reading) = match low {
            true => ("1'bz", 0, 1, "!"),
            false => ("1'b0", 1, 0, ""),
        };
        let _ = writeln!(
            self.text,
            "  // {chain} x {} in CNV {} mode: {len} serial bits per conversion\n  reg [{}:0] stream{b};\n  reg [15:0] falls{b};\n  reg drive{b} = 0;\n  reg [63:0] n{b} = 0;\n  reg [63:0] id{b};\n  reg [63:0] mid{b};\n  reg [15:0] code{b};\n  assign {miso}[{b}] = drive{b} ? (falls{b} >= 16'd{len} ? {after} : stream{b}[{}-falls{b}]) : 1'bz;",
            part.name,
            if low { "read-low" } else { "chain" },
            len - 1,
            len - 1,
            miso = Role::Miso.name()
        );
        let id_case = id_case(&self.l, &self.analog, b);
        let table = self.cnv_table(b);
        let members: String = (0..chain).map(|m| self.cnv_member(b, m, table)).collect();
        let _ = write!(
            self.text,
            "  always @(posedge {cs}[{b}]) if (!{rst}) begin\n{id_case}    stream{b} = {len}'h0;\n{members}    falls{b} = 0;\n    drive{b} = {at_rise};\n  end\n  always @(negedge {cs}[{b}]) drive{b} = {at_fall};\n  always @(negedge {sclk}[{b}]) if ({reading}{cs}[{b}]) falls{b} = falls{b} + 1;\n\n",
            cs = Role::CsN.name(),
            sclk = Role::Sclk.name(),
            rst = Role::Reset.name(),
        );
    }

    /// A CNV chain's table of the codes the model's stimulus gives, one
    /// line per word; its length, if there is one.
    fn cnv_table(&mut self, b: usize) -> Option<u64> {
        if self.stimulus == Stimulus::Pattern {
            return None;
        }
        let part = &self.s.mix.branches[b].adc;
        let mask = (1u32 << part.bits) - 1;
        let mut hex = String::new();
        let mut words = 0u64;
        for i in self.conversions(b) {
            for (_, c) in self.s.words_of(i.channel) {
                let held = i.cycle + self.s.branches[b].spi.sample_cycles;
                let code = self.analog.code_bits(c as u64, held, part.bits) as u32 & mask;
                let _ = writeln!(hex, "{:04x}{:08x}{:04x}", c as u16, i.cycle as u32, code);
                words += 1;
            }
        }
        (words > 0).then(|| {
            self.add_table(b, hex, words);
            words
        })
    }

    /// Chain member `m`'s sample: its input id (the member's channel, or
    /// an unconnected input), its code, and its word shifted into the stream.
    fn cnv_member(&self, b: usize, m: usize, table: Option<u64>) -> String {
        let s = self.s;
        let part = &s.mix.branches[b].adc;
        let ws = part.word_sclks() as usize;
        let len = ws * s.mix.branches[b].chain as usize;
        let trailing = ws - part.leading_bits as usize - part.bits as usize;
        let mask = (1u32 << part.bits) - 1;
        let mut members = String::new();
        // judge::Adc: the member's channel, or an unconnected input
        let _ = writeln!(members, "    case (id{b})");
        for lead in (0..s.groups.len()).filter(|&c| s.mix.channels[c].branch == b) {
            let mid = match s.groups[lead].get(m) {
                Some(Some(c)) => *c as u64,
                _ => lead as u64 + 100 + m as u64,
            };
            let _ = writeln!(members, "      64'd{lead}: mid{b} = 64'd{mid};");
        }
        let fallback = if m == 0 {
            format!("id{b}")
        } else {
            format!("id{b} + 64'd{}", 100 + m)
        };
        let _ = writeln!(
            members,
            "      default: mid{b} = {fallback};\n    endcase\n    code{b} = pattern16(cyc, mid{b}) & 16'h{mask:x};"
        );
        if let Some(words) = table {
            let _ = writeln!(
                members,
                "    if (n{b} < {words} && tab{b}[n{b}][63:48] == mid{b}[15:0] && tab{b}[n{b}][47:16] == cyc[31:0])\n      code{b} = tab{b}[n{b}][15:0];\n    n{b} = n{b} + 1;"
            );
        }
        let pad = len - part.bits as usize;
        let code = if pad > 0 {
            format!("{{{pad}'h0, code{b}[{}:0]}}", part.bits - 1)
        } else {
            format!("code{b}[{}:0]", part.bits - 1)
        };
        let _ = writeln!(
            members,
            "    stream{b} = (stream{b} << {ws}) | ({code} << {trailing});"
        );
        members
    }
}

/// The AXI4-Stream slave of `link::ReadyDriver` in Verilog: `tready` for
/// each cycle from the pattern and `tvalid` of that cycle, set just after
/// the edge that begins the cycle; high during reset, the pattern restarting.
fn axis_slave(pattern: link::ReadyPattern, within: u32) -> String {
    let [_, tv, _, tr, _] = AXIS_PORTS.map(|p| p.name);
    let (seed, r) = match pattern {
        link::ReadyPattern::Always => (1, "1'b1".to_string()),
        link::ReadyPattern::WorstCase => (1, "due".to_string()),
        link::ReadyPattern::Random { seed } => (seed.max(1), "xs[0] | due".to_string()),
    };
    let step = if matches!(pattern, link::ReadyPattern::Random { .. }) {
        "      xs = xs ^ (xs << 13);\n      xs = xs ^ (xs >> 17);\n      xs = xs ^ (xs << 5);\n"
    } else {
        ""
    };
    format!(
        "  // AXI4-Stream slave ({}): every beat accepted within {within} cycle(s)\n  reg [31:0] xs = 32'd{seed};\n  reg [31:0] waited = 32'd0;\n  reg due;\n  always @(posedge {clk}) begin\n    #1;\n    if ({rst}) begin\n      xs = 32'd{seed};\n      waited = 32'd0;\n      {tr} = 1'b1;\n    end else begin\n      due = waited + 32'd1 >= 32'd{within};\n{step}      {tr} = {r};\n      waited = ({tv} & !{tr}) ? waited + 32'd1 : 32'd0;\n    end\n  end\n\n",
        pattern.name(),
        clk = Role::Clock.name(),
        rst = Role::Reset.name(),
    )
}

/// A `case` setting `id<b>` to the input id cosim's ADC model gives each
/// (enable, select) of branch `b`'s mux pins (every enable pattern for up to
/// six devices, else the one-hot ones; others as `(0, 0)`).
fn id_case(l: &Layout, analog: &Analog, b: usize) -> String {
    if !l.muxed[b] {
        // no mux: the converter always sees its one input
        let id = analog.input_id(l, &Pins::default(), b);
        return format!("    id{b} = 64'd{id};\n");
    }
    let (lo, n) = (l.en_lo[b], l.en_n[b]);
    let id_of = |en: u64, sel: u32| {
        let p = Pins {
            mux_sel: (sel as u64) << l.sel_lo[b],
            mux_en: (en as u128) << lo,
            ..Pins::default()
        };
        analog.input_id(l, &p, b)
    };
    let ens: Vec<u64> = if n <= 6 {
        (0..1u64 << n).collect()
    } else {
        (0..n).map(|d| 1u64 << d).collect()
    };
    let mut s = format!(
        "    case ({{{en}[{}:{lo}], {sel}[{}:{}]}})\n",
        lo + n - 1,
        l.sel_lo[b] + 2,
        l.sel_lo[b],
        en = Role::MuxEn.name(),
        sel = Role::MuxSel.name(),
    );
    for &en in &ens {
        for sel in 0..8u32 {
            let key = (en << 3) | sel as u64;
            let _ = writeln!(s, "      {}'d{key}: id{b} = 64'd{};", n + 3, id_of(en, sel));
        }
    }
    let _ = writeln!(
        s,
        "      default: id{b} = 64'd{};\n    endcase",
        id_of(0, 0)
    );
    s
}

fn tool_missing(tool: &str) -> BackendError {
    BackendError::MissingTool {
        tool: tool.into(),
        hint:
            "the icarus back end needs Icarus Verilog: `apt-get install iverilog`, or `make tools`"
                .into(),
    }
}

/// Runs `tool` through the tool runner: missing, it is named with how to
/// install it; failing, its output is the log of `step`.
fn spawn(tool: Tool, step: &str) -> Result<(), BackendError> {
    let out = tool.run().map_err(not_run)?;
    if out.success {
        Ok(())
    } else {
        Err(BackendError::Build {
            step: step.into(),
            log: out.stdout + &out.stderr,
        })
    }
}

/// Why a tool gave no answer, as the back end says it.
fn not_run(e: ToolError) -> BackendError {
    match e {
        ToolError::Missing(tool) => tool_missing(&tool),
        e => BackendError::Io(e.to_string()),
    }
}

/// Simulates `frames` frames of the emitted gateware (`hdl::emit`, every
/// file it writes) in Icarus and checks the VCD.  `opts.vcd` gets the
/// requested window of Icarus's own VCD (scope `tb`; no `.gtkw`).
///
/// With `trace`, every cycle of Icarus's VCD also goes there.
pub fn run(
    s: &Schedule,
    frames: u64,
    opts: &SimOptions,
    trace: Option<&mut dyn CycleSink>,
) -> Result<Verdict, SimError> {
    let io = |e: std::io::Error| SimError::Io(format!("icarus back end: {e}"));
    // Name the missing tool before doing any work.
    for tool in ["iverilog", "vvp"] {
        Tool::new(tool).arg("-V").run().map_err(not_run)?;
    }
    let dir = tempfile::Builder::new()
        .prefix("slotforge-icarus-")
        .tempdir()
        .map_err(io)?;
    let d = dir.path();
    let reset = judge::reset_cycles(s, opts.reset_cycles);
    let cycles = frames * s.grid.frame_cycles;
    let tb = testbench_with(s, opts.stimulus, reset, cycles, opts.tready, &opts.modes);
    match &opts.rtl {
        // outside Verilog (checked against the contract) in the emitted file's place
        Some(path) => {
            std::fs::write(d.join(hdl::VERILOG_FILE), crate::rtl::load_rtl(s, path)?).map_err(io)?
        }
        None => hdl::emit(s, None)
            .and_then(|e| e.write_to(d))
            .map_err(|e| SimError::Hdl(e.to_string()))?,
    }
    std::fs::write(d.join("tb.v"), &tb.tb).map_err(io)?;
    for (name, text) in &tb.tables {
        std::fs::write(d.join(name), text).map_err(io)?;
    }
    spawn(
        Tool::new("iverilog")
            .args([
                "-g2005",
                "-s",
                "tb",
                "-o",
                "sim.vvp",
                "tb.v",
                hdl::VERILOG_FILE,
            ])
            .current_dir(d),
        "iverilog (compiling the emitted Verilog and the testbench)",
    )?;
    spawn(
        Tool::new("vvp").args(["-n", "sim.vvp"]).current_dir(d),
        "vvp (running the simulation)",
    )?;
    let wave = d.join("wave.vcd");
    let (mut report, _) = judge::check_vcd_with(s, &wave, Some("tb"), opts.check)
        .map_err(|e| SimError::Io(format!("icarus back end: reading its VCD: {e}")))?;
    report.source = "icarus".into();
    if let Some(sink) = trace {
        judge::read_cycles(s, &wave, Some("tb"), sink)
            .map_err(|e| SimError::Io(format!("icarus back end: reading its VCD: {e}")))?;
    }
    if let Some(v) = &opts.vcd {
        write_window(s, &wave, v, reset, frames)
            .map_err(|e| SimError::Io(format!("{}: {e}", v.path.display())))?;
    }
    Ok(report)
}

/// Copies the window `v` of Icarus's VCD to `v.path` (a window from cycle 0
/// includes the reset cycles; a later one starts with the values at its
/// first cycle).  Times stay the run's own, exact ([`edge_ps`]).
fn write_window(
    s: &Schedule,
    wave: &Path,
    v: &VcdOut,
    reset: u64,
    frames: u64,
) -> std::io::Result<()> {
    let hz = s.grid.clock_hz;
    let (k0, k1) = v.run_cycles(reset);
    if k0 == 0 && k1 >= reset + frames * s.grid.frame_cycles {
        std::fs::copy(wave, &v.path)?;
        return Ok(());
    }
    // The testbench's clock toggles at edge n = 1, 2, ...: rising edge k
    // (from the first reset edge) is edge 2k + 1, so a window of cycles
    // [k0, k1) spans times [edge 2 k0, edge 2 k1).
    let (t0, t1) = (edge_ps(hz, 2 * k0), edge_ps(hz, 2 * k1));
    let mut rd = BufReader::new(File::open(wave)?);
    let mut w = BufWriter::new(File::create(&v.path)?);
    let mut line = String::new();
    // header
    loop {
        line.clear();
        if rd.read_line(&mut line)? == 0 {
            return Err(std::io::Error::other("VCD ends in its header"));
        }
        w.write_all(line.as_bytes())?;
        if line.contains("$enddefinitions") {
            break;
        }
    }
    let mut last: std::collections::BTreeMap<String, String> = Default::default();
    let mut inside = t0 == 0;
    loop {
        line.clear();
        if rd.read_line(&mut line)? == 0 {
            break;
        }
        let l = line.trim_end();
        if let Some(t) = l.strip_prefix('#') {
            let t: u64 = t
                .parse()
                .map_err(|_| std::io::Error::other(format!("bad time `{l}`")))?;
            if t >= t1 {
                writeln!(w, "#{t1}")?;
                break;
            }
            if !inside && t >= t0 {
                inside = true;
                writeln!(w, "#{t0}\n$dumpvars")?;
                for v in last.values() {
                    writeln!(w, "{v}")?;
                }
                writeln!(w, "$end")?;
            }
            if inside && (t0 == 0 || t > t0) {
                writeln!(w, "#{t}")?;
            }
        } else if l.starts_with('$') || l.is_empty() {
            if inside && t0 == 0 {
                writeln!(w, "{l}")?;
            }
        } else if inside {
            writeln!(w, "{l}")?;
        } else {
            let id = match l.split_once(' ') {
                Some((_, id)) => id,
                None => &l[1..],
            };
            last.insert(id.to_string(), l.to_string());
        }
    }
    w.flush()
}
