//! `slotforge prove MIX [--rtl FILE.v | --netlist FAMILY] [--solver symbolic|abc|pdr|cvc5] [--axis-bytes] [--json]`
//!
//! Exit 0: every asserted property proved for all time (what the harness
//! does not assert is listed, `not_covered`); 1: a counterexample (its VCD, `.gtkw` and
//! the checker's diagnosis), or a link too slow for the mix; 2: bad input
//! or a tool that cannot run;
//! 3: bounded only (no violation within the depth, not a proof).
//!
//! A mix with modes is proved across its switches: `mode_sel` free in every
//! cycle (pin select) or the triggers evaluated on the recorded words (auto
//! select); docs/formal.md, "Mixes with modes".

use std::path::PathBuf;

use formal::{ProveOptions, Solver};

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// Prove this Verilog (a `slotforge_top` on the port contract) instead of the emitted gateware.
    #[arg(long)]
    pub rtl: Option<PathBuf>,
    /// Prove the gate-level netlist yosys writes for this FPGA family
    /// (ice40, ecp5, gowin, or a part name), with the family's cell models
    /// flattened in, under the same harness.
    #[arg(long, value_name = "FAMILY", value_parser = super::fpga, conflicts_with = "rtl")]
    pub netlist: Option<lut_gen::Fpga>,
    /// The engine: `symbolic` (exact symbolic simulation from reset until the state recurs a frame later, default), `abc` (ABC's bounded search to the recurrence bound + the two-copy recurrence miter), `pdr` (ABC IC3) or `cvc5` (k-induction through yosys-smtbmc).
    #[arg(long, default_value = "symbolic", value_parser = solver)]
    pub solver: Solver,
    /// Seconds each engine run may take (the search from reset, the recurrence check, pdr or cvc5).
    #[arg(long, value_parser = super::whole_number, default_value_t = 1800)]
    pub timeout: u64,
    /// Steps from reset the bounded search covers when the proof does not close (default: two frames).
    #[arg(long, value_parser = super::whole_number)]
    pub depth: Option<u64>,
    /// Directory for a counterexample's VCD and .gtkw (created if missing).
    #[arg(short = 'o', long = "out", default_value = "prove-out")]
    pub out: PathBuf,
    /// Also write the generated harness here.
    #[arg(long)]
    pub harness: Option<PathBuf>,
    /// Also assert an AXI4-Stream link's bytes and packets when its slave may keep a beat waiting more than 8 cycles (ready_within): the proof splits on every wait, minutes on a 48 MHz mix.
    #[arg(long)]
    pub axis_bytes: bool,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The design to prove: `--rtl`'s file, `--netlist`'s netlist with its
/// cell models, or the emitted Verilog; and whether it is slotforge's own.
fn design(
    a: &Args,
    s: &lut_gen::Schedule,
) -> Result<(String, bool, Option<measure::Netlist>), String> {
    if let Some(path) = &a.rtl {
        return engines::load_rtl(s, path)
            .map(|t| (t, false, None))
            .map_err(|e| e.to_string());
    }
    if let Some(fpga) = a.netlist {
        let dir = tempfile::Builder::new()
            .prefix("slotforge-netlist-")
            .tempdir()
            .map_err(|e| format!("--netlist: a work folder: {e}"))?;
        let n = measure::netlist(s, fpga, dir.path())?;
        return Ok((n.text.clone(), false, Some(n)));
    }
    hdl::emit(s, None)
        .map(|e| (e.verilog().to_string(), true, None))
        .map_err(|e| format!("{}: {e}", a.mix.display()))
}

fn solver(s: &str) -> Result<Solver, String> {
    s.parse()
}

pub fn run(a: Args) -> u8 {
    // A mix with modes is proved across its switches (the harness follows
    // every sequence of requests, or the triggers on the recorded words).
    let s = match super::load_any_modes(&a.mix, super::Limits::Contract) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let harness = match a
        .harness
        .as_deref()
        .map(|h| super::output_file("--harness", h))
    {
        Some(Err(e)) => {
            eprintln!("error: {e}");
            return 2;
        }
        h => h.and_then(Result::ok),
    };
    let (design, own, netlist) = match design(&a, &s) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let mut opts = ProveOptions::new(&a.out);
    opts.axis_bytes = a.axis_bytes;
    if let Some(path) = &harness {
        match formal::harness_for(&s, &opts) {
            Ok(h) => {
                let dir = path.parent().filter(|p| !p.as_os_str().is_empty());
                let dir = dir.unwrap_or(std::path::Path::new("."));
                let name = path
                    .file_name()
                    .and_then(|n| n.to_str())
                    .unwrap_or("harness.v");
                if let Err(e) = super::write_atomic(dir, name, &h.verilog) {
                    eprintln!("error: {e}");
                    return 2;
                }
            }
            Err(e) => {
                eprintln!("error: mix `{}`: {e}", s.mix.name);
                return 2;
            }
        }
    }
    opts.solver = a.solver;
    opts.timeout_s = a.timeout;
    opts.bmc_timeout_s = a.timeout;
    opts.depth = a.depth;
    opts.own_design = own;
    // slotforge's gateware names it so; an --rtl design that does too gets
    // the same generalisation (checked, so a name that means otherwise only
    // leaves the search as it was)
    opts.frame_counter = Some(hdl::LINK_FRAME_COUNTER.to_string());
    opts.mode_decision = Some(hdl::MODE_DECISION.to_string());
    opts.trigger_run = Some(hdl::TRIGGER_RUN.to_string());
    opts.netlist = netlist.map(|n| (n.fpga.name().to_string(), n.not_covered()));
    let proof = match formal::prove(&s, &design, &opts) {
        Ok(mut p) => {
            if let Some(c) = &mut p.counterexample {
                c.check = formal::check_command(&a.mix, &c.vcd);
            }
            p
        }
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&proof).expect("proof serializes")
        );
    } else {
        print!("{}", proof.summary());
    }
    proof.result.exit_code()
}
