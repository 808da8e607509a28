//! A counterexample as a person reads it: the MISO bits of the engine's
//! witness (and the harness's other free inputs, the AXI4-Stream slave's
//! early `tready`) replayed through harness + design in Icarus (the RTL, not the
//! AIG the engine saw, so the replay also confirms the witness), dumped as
//! a VCD with a `.gtkw`, and judged by the same checker `slotforge check`
//! runs, which must fail at the same cycle.

use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

use lut_gen::Role;
use lut_gen::Schedule;

use crate::engine::run_tool;
use crate::harness::{self, FreeInput, Harness};
use crate::ProveError;

pub mod witness;

/// Scope of the design's ports in the replay VCD (for `check --scope`).
pub const DUT_SCOPE: &str = "replay_tb.h.dut";

/// Steps the replay runs past the first failing one, so the waveform and
/// the checker see what follows.
const AFTER: u64 = 16;

/// What the replay found.
#[derive(Debug, Clone)]
pub struct Replay {
    /// First step at which the harness's assertion fails in the RTL.
    pub step: Option<u64>,
    /// Names of the properties failing at that step.
    pub failed: Vec<String>,
    pub vcd: PathBuf,
    pub gtkw: PathBuf,
}

/// The bench: every free input of the harness from one vector per step
/// (`stim.mem`, the inputs concatenated with `adc_miso` in the low bits).
fn testbench(h: &Harness, steps: u64, period_ps: u64) -> String {
    let total: u32 = h.inputs.iter().map(|i| i.width).sum();
    let mut v = String::new();
    let _ = writeln!(
        v,
        "`timescale 1ps/1ps\nmodule replay_tb;\n  reg clk = 1'b0;"
    );
    for i in &h.inputs {
        let _ = writeln!(v, "  reg [{}:0] {} = 0;", i.width - 1, i.name);
    }
    let ports: String = h
        .inputs
        .iter()
        .map(|i| format!(", .{0}({0})", i.name))
        .collect();
    // `mode_sel` is an input the judge reads with the outputs (its value
    // once an edge's timestep has closed is that cycle's): it changes in the
    // edge's timestep (nonblocking, so the edge samples the cycle before's),
    // MISO a quarter period after it (read before the next edge).
    let at_edge = |i: &FreeInput| i.name == harness::MODE_SEL;
    let concat: Vec<String> = (h.inputs.iter().rev())
        .map(|i| match at_edge(i) {
            true => format!("{}_next", i.name),
            false => i.name.clone(),
        })
        .collect();
    let (mut lo, mut edge) = (0, String::new());
    for i in &h.inputs {
        if at_edge(i) {
            let _ = writeln!(
                edge,
                "  reg [{w}:0] {n}_next = 0;\n  integer {n}_k = 0;\n  \
                 always @(posedge clk) begin\n    {n}_k = {n}_k + 1;\n    \
                 {n} <= stim[{n}_k][{}:{lo}];\n  end",
                lo + i.width - 1,
                w = i.width - 1,
                n = i.name
            );
        }
        lo += i.width;
    }
    let _ = writeln!(
        v,
        "  reg [{}:0] stim [0:{}];\n  integer i;\n{edge}  slotforge_formal h (.clk(clk){ports});\n  \
         // Rising edges at k * period (k >= 1) only: an X-to-1 start would be one.\n  \
         always begin #{} clk = 1'b0; #{} clk = 1'b1; end\n  initial begin\n    $readmemb(\"stim.mem\", stim);\n    \
         $dumpfile(\"trace.vcd\");\n    $dumpvars(1, h.dut);\n    $dumpvars(1, h);\n    \
         for (i = 0; i < {steps}; i = i + 1) begin\n      #{} {{{}}} = stim[i];\n      #{};",
        total - 1,
        steps.max(1) - 1,
        period_ps / 2,
        period_ps - period_ps / 2,
        period_ps / 4,
        concat.join(", "),
        period_ps / 2,
    );
    let wires: Vec<&str> = h.properties.iter().map(|p| p.wire.as_str()).collect();
    let fmt: Vec<&str> = wires.iter().map(|_| "%b").collect();
    let args: Vec<String> = wires.iter().map(|w| format!("h.{w}")).collect();
    let _ = writeln!(
        v,
        "      if (h.st != 2'd0 && !h.ok) $display(\"FAIL %0d {}\", i, {});\n      #{};\n    end\n    \
         $finish;\n  end\nendmodule",
        fmt.join(" "),
        args.join(", "),
        period_ps - period_ps / 4 - period_ps / 2,
    );
    v
}

/// gtkwave's save file for the replay: the design's pins, then the
/// harness's property wires.
fn gtkw(s: &Schedule, h: &Harness, vcd: &Path) -> String {
    let mut g = String::new();
    let _ = writeln!(g, "[dumpfile] \"{}\"\n[timestart] 0\n@28", vcd.display());
    for r in [Role::Clock, Role::Reset] {
        let _ = writeln!(g, "{DUT_SCOPE}.{}", r.name());
    }
    let layout = lut_gen::Layout::new(s);
    for r in [Role::Miso, Role::CsN, Role::Sclk] {
        let _ = writeln!(g, "{DUT_SCOPE}.{}[{}:0]", r.name(), layout.width(r) - 1);
    }
    let _ = writeln!(g, "@22");
    for r in [Role::MuxSel, Role::MuxEn]
        .into_iter()
        .filter(|&r| layout.has(r))
    {
        let _ = writeln!(g, "{DUT_SCOPE}.{}[{}:0]", r.name(), layout.width(r) - 1);
    }
    let _ = writeln!(g, "@28\n{DUT_SCOPE}.sample_valid\n@24");
    for r in [Role::SampleChannel, Role::SampleValue] {
        let _ = writeln!(g, "{DUT_SCOPE}.{}[{}:0]", r.name(), layout.width(r) - 1);
    }
    for p in layout.link_ports() {
        let (fmt, range) = if p.width == 1 {
            ("@28", String::new())
        } else {
            ("@22", format!("[{}:0]", p.width - 1))
        };
        let _ = writeln!(g, "{fmt}\n{DUT_SCOPE}.{}{range}", p.name);
    }
    let _ = writeln!(g, "@28");
    for p in &h.properties {
        let _ = writeln!(g, "replay_tb.h.{}", p.wire);
    }
    g
}

/// Replays `miso` (one value per step) into `out_dir/trace.vcd`.
pub fn replay(
    s: &Schedule,
    h: &Harness,
    design: &str,
    miso: &[u64],
    work: &Path,
    out_dir: &Path,
) -> Result<Replay, ProveError> {
    let steps = miso.len() as u64 + AFTER;
    // The other free inputs from the same witness (absent: 0, the slave
    // then takes each beat at its deadline).
    let mut values = vec![miso.to_vec()];
    for i in h.inputs.iter().skip(1) {
        let from_witness = work.join("cex.aiw").exists();
        values.push(if from_witness {
            witness::input(work, &i.name, i.width)?
        } else {
            Vec::new()
        });
    }
    let mut mem = String::new();
    for step in 0..steps as usize {
        for (i, vals) in h.inputs.iter().zip(&values).rev() {
            let x = vals.get(step).copied().unwrap_or(0);
            let _ = write!(mem, "{:0w$b}", x, w = i.width as usize);
        }
        mem.push('\n');
    }
    let period_ps = (1_000_000_000_000u64 / s.grid.clock_hz).max(4) / 4 * 4;
    let write = |name: &str, text: &str| {
        std::fs::write(work.join(name), text)
            .map_err(|e| ProveError::Tool(format!("{}: {e}", work.join(name).display())))
    };
    write("stim.mem", &mem)?;
    write("replay_tb.v", &testbench(h, steps, period_ps))?;
    run_tool(
        work,
        "iverilog",
        &[
            "-g2005",
            "-o",
            "replay.vvp",
            "replay_tb.v",
            "harness.v",
            "design.v",
        ],
        Duration::from_secs(300),
    )?;
    let _ = design;
    let log = run_tool(
        work,
        "vvp",
        &["-n", "replay.vvp"],
        Duration::from_secs(3600),
    )?;
    let mut step = None;
    let mut failed = Vec::new();
    for line in log.lines() {
        if let Some(rest) = line.strip_prefix("FAIL ") {
            let f: Vec<&str> = rest.split_whitespace().collect();
            step = f.first().and_then(|x| x.parse().ok());
            for (p, bit) in h.properties.iter().zip(f.iter().skip(1)) {
                if *bit != "1" {
                    failed.push(p.name.clone());
                }
            }
            break;
        }
    }
    std::fs::create_dir_all(out_dir)
        .map_err(|e| ProveError::Output(format!("{}: cannot create: {e}", out_dir.display())))?;
    let vcd = out_dir.join("counterexample.vcd");
    let gtkw_path = out_dir.join("counterexample.gtkw");
    std::fs::rename(work.join("trace.vcd"), &vcd)
        .or_else(|_| std::fs::copy(work.join("trace.vcd"), &vcd).map(|_| ()))
        .map_err(|e| ProveError::Output(format!("{}: cannot write: {e}", vcd.display())))?;
    std::fs::write(&gtkw_path, gtkw(s, h, &vcd))
        .map_err(|e| ProveError::Output(format!("{}: cannot write: {e}", gtkw_path.display())))?;
    Ok(Replay {
        step,
        failed,
        vcd,
        gtkw: gtkw_path,
    })
}
