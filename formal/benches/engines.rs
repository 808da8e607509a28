//! `cargo bench -p formal --bench engines [-- MIX]`: proves one mix's
//! emitted gateware with the `symbolic` engine and with the `abc`
//! recurrence miter, one after the other in this run, and prints each
//! engine's wall time, the process's peak memory after each, and the ratio.
//! Default mix: `mixes/softslip1k.toml` (a 120,000-cycle frame; the abc
//! engine takes minutes on it, the 48 MHz presets need gigabytes).

use std::path::Path;
use std::time::Instant;

use formal::{Outcome, ProveOptions, Solver};

/// Peak resident memory so far, MB, of this process and of its finished
/// children (yosys, yosys-abc), from getrusage.
fn peak_mb() -> (f64, f64) {
    let peak = |who| {
        // SAFETY: getrusage only writes the struct it is given.
        let mut u: libc::rusage = unsafe { std::mem::zeroed() };
        unsafe { libc::getrusage(who, &mut u) };
        u.ru_maxrss as f64 / 1024.0
    };
    (peak(libc::RUSAGE_SELF), peak(libc::RUSAGE_CHILDREN))
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let rel = std::env::args()
        .skip(1)
        .find(|a| a.ends_with(".toml"))
        .unwrap_or_else(|| "mixes/softslip1k.toml".into());
    let mix = lut_gen::load(&root.join(&rel)).expect("mix loads");
    let s = lut_gen::synthesize(&mix).expect("mix is feasible");
    let design = hdl::emit(&s, None).expect("emits").verilog().to_string();
    println!(
        "{rel}: {} cycles a frame; each engine proves the emitted gateware for all time",
        s.grid.frame_cycles
    );
    let mut secs = Vec::new();
    for solver in [Solver::Symbolic, Solver::Abc] {
        let dir = tempfile::tempdir().expect("temporary directory");
        let mut o = ProveOptions::new(dir.path());
        o.solver = solver;
        let t = Instant::now();
        let p = formal::prove(&s, &design, &o).expect("prove runs");
        let wall = t.elapsed().as_secs_f64();
        assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
        // the abc engine runs in yosys-abc, the symbolic one in this
        // process; both peaks only grow, so each line bounds the run so far
        let (own, children) = peak_mb();
        println!(
            "{:<9} proved, depth {}: {wall:.1} s wall, engine {:.1} s; peak so far: this process {own:.0} MB, children {children:.0} MB",
            solver.name(),
            p.depth,
            p.solver_seconds,
        );
        secs.push(p.solver_seconds);
    }
    println!(
        "engine time, abc / symbolic: {:.1}x",
        secs[1] / secs[0].max(1e-9)
    );
}
