//! `slotforge-fuzz <mix|vcd> [--count N] [--seed S] [--timeout-secs T]`
//!
//! Exit 0: no panic, no hang; 1: some input panicked or hung (saved under
//! `fuzz/crashes/`); 2: bad arguments or seeds.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;
use slotforge_fuzz::{load_seeds, run, workspace_root, Config, Target};

#[derive(Parser)]
#[command(
    name = "slotforge-fuzz",
    about = "Structure-aware fuzzing of the mix parser (mix) or the VCD reader (vcd)"
)]
struct Args {
    /// `mix` (lut_gen::parse/load) or `vcd` (judge::check_vcd).
    target: Target,
    /// Inputs to run.
    #[arg(long, default_value_t = 100_000)]
    count: u64,
    /// Run seed: input i depends only on (seed, i).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// An input running longer than this is a hang.
    #[arg(long, default_value_t = 5.0)]
    timeout_secs: f64,
    /// Where panicking and hanging inputs are saved.
    #[arg(long)]
    crashes: Option<PathBuf>,
    /// Stop after this many hangs.
    #[arg(long, default_value_t = 5)]
    max_hangs: u64,
}

fn main() -> ExitCode {
    let a = Args::parse();
    let root = workspace_root();
    let seeds = match load_seeds(a.target, &root) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    eprintln!(
        "fuzzing {} with {} seed file(s), {} inputs, seed {}, timeout {} s",
        a.target.name(),
        seeds.len(),
        a.count,
        a.seed,
        a.timeout_secs
    );
    let cfg = Config {
        target: a.target,
        count: a.count,
        seed: a.seed,
        timeout: Duration::from_secs_f64(a.timeout_secs),
        crashes: a.crashes.unwrap_or_else(|| root.join("fuzz/crashes")),
        verbose: true,
        max_hangs: a.max_hangs,
    };
    let sum = run(&cfg, seeds);
    println!("{sum}");
    if sum.crashes.is_empty() {
        ExitCode::SUCCESS
    } else {
        for c in &sum.crashes {
            println!(
                "{}: {} ({})",
                c.kind,
                c.file.display(),
                c.message.lines().next().unwrap_or("")
            );
        }
        // Hung workers may still be spinning: do not wait for them.
        std::process::exit(1)
    }
}
