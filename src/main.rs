//! `slotforge`: a thin CLI over the lut-gen, hdl, engines and campaign crates.
//!
//! Exit codes: 0 success, 1 infeasible / divergence / difference,
//! 2 bad input (always with file, line and field where there is one).

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cmd;

#[derive(Parser)]
#[command(
    name = "slotforge",
    version,
    about = "Jitter-free slot schedules, gateware and cycle-exact checks for multi-rate SPI ADC front ends"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// The main job: audit, LUT, Verilog, co-simulation, golden, faults, synthesis estimate, and a report with charts.
    Build(cmd::build::Args),
    /// Synthesize the schedule and audit it (rates, intervals, headroom, settling, Nyquist).
    Audit(cmd::audit::Args),
    /// Write the slot LUT: slots.hex ($readmemh), slots.csv, slots.md (Table 1 form).
    Lut(cmd::lut::Args),
    /// Emit slotforge_top.v, ports.json, slots.hex and constraints.
    Verilog(cmd::verilog::Args),
    /// Simulate the design with an ADC model and check it against the reference model.
    Sim(cmd::sim::Args),
    /// Check a VCD from any simulator against the mix.
    Check(cmd::check::Args),
    /// Inject each kind of fault into a design's pins; report what the checker caught.
    Faults(cmd::faults::Args),
    /// Simulate and compare with the mix's golden event log and waveforms (golden/<mix>/).
    Golden(cmd::golden::Args),
    /// Synthesize and place the gateware for an FPGA part on its board (yosys, nextpnr): cells and Fmax.
    Synth(cmd::synth::Args),
    /// Prove the gateware meets the pin contract for all time (formal: yosys + ABC or cvc5).
    Prove(cmd::prove::Args),
    /// Host side: the raw bytes received from the link (a serial-port dump, or `-` for stdin), as samples.
    Decode(cmd::decode::Args),
    /// Host side: write a sigrok protocol decoder of the mix's packets (for PulseView, sigrok-cli).
    Sigrok(cmd::sigrok::Args),
}

fn main() -> ExitCode {
    // A closed pipe (`slotforge audit mix.toml | head`) ends the process
    // quietly, as for any Unix tool, instead of a panic in println!.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread
    // exists touches no Rust state.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    let code = match cli.command {
        Command::Build(a) => cmd::build::run(a),
        Command::Audit(a) => cmd::audit::run(a),
        Command::Lut(a) => cmd::lut::run(a),
        Command::Verilog(a) => cmd::verilog::run(a),
        Command::Sim(a) => cmd::sim::run(a),
        Command::Check(a) => cmd::check::run(a),
        Command::Faults(a) => cmd::faults::run(a),
        Command::Golden(a) => cmd::golden::run(a),
        Command::Synth(a) => cmd::synth::run(a),
        Command::Prove(a) => cmd::prove::run(a),
        Command::Decode(a) => cmd::decode::run(a),
        Command::Sigrok(a) => cmd::sigrok::run(a),
    };
    ExitCode::from(code)
}
