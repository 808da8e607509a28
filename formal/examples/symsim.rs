//! Runs the symbolic engine on an AIGER file and prints its verdict and
//! figures: `CHOICES=I,J cargo run --release -p formal --example symsim --
//! DESIGN.aag PERIOD [MAX_STEPS [SECONDS]]` (a work directory kept with
//! `SLOTFORGE_FORMAL_KEEP=1 slotforge prove MIX` holds `design.aag`;
//! `CHOICES` are the indices of inputs that are an environment's choices,
//! `tready_any` in its `design.aim`; `WAIT` the latch indices of its
//! `waited`, least significant first).

use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, period, rest @ ..] = &args[..] else {
        eprintln!("usage: symsim DESIGN.aag PERIOD [MAX_STEPS [SECONDS]]");
        std::process::exit(2);
    };
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| {
        eprintln!("{path}: {e}");
        std::process::exit(1)
    });
    let g = formal::parse_aiger(&text).unwrap_or_else(|e| {
        eprintln!("{path}: {e}");
        std::process::exit(1)
    });
    let num = |s: &str, what: &str| -> u64 {
        s.parse().unwrap_or_else(|_| {
            eprintln!("{what}: not a whole number: {s}");
            std::process::exit(2)
        })
    };
    let period = num(period, "PERIOD");
    let max = rest
        .first()
        .map_or(16 * period + 2, |s| num(s, "MAX_STEPS"));
    let secs = rest.get(1).map_or(1800, |s| num(s, "SECONDS"));
    let t0 = Instant::now();
    let deadline = t0 + Duration::from_secs(secs);
    // CHOICES=i,j: input indices that are an environment's choices
    let choices: Vec<usize> = std::env::var("CHOICES")
        .map(|c| c.split(',').map(|x| num(x, "CHOICES") as usize).collect())
        .unwrap_or_default();
    // SPLITS=i,j: input indices the run is split on (mode_sel)
    let splits: Vec<usize> = std::env::var("SPLITS")
        .map(|c| c.split(',').map(|x| num(x, "SPLITS") as usize).collect())
        .unwrap_or_default();
    // WAIT=j,k: latch indices of a slave's wait count, least significant first
    let wait: Vec<usize> = std::env::var("WAIT")
        .map(|c| c.split(',').map(|x| num(x, "WAIT") as usize).collect())
        .unwrap_or_default();
    let (found, st) = formal::prove_aig(
        &g,
        &choices,
        &wait,
        &splits,
        std::env::var_os("CASES").is_some(),
        period,
        2,
        max,
        Some(deadline),
    );
    let verdict = match &found {
        formal::Found::Violated { step, .. } => format!("violated at step {step}"),
        other => format!("{other:?}"),
    };
    println!("{verdict}");
    println!("{st:?}");
    println!("{:.1} s", t0.elapsed().as_secs_f64());
}
