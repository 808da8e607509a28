//! `cargo run -p measure --example synth_bench -- OUTDIR BOARD.toml MIX.toml...`
//! (`make synth-bench`): emits each mix's gateware into `OUTDIR/<mix>/`,
//! synthesizes it once and places it at nextpnr seeds 1, 2 and 3 in the
//! same run (`measure::place_and_route_seeds`), then prints LCs,
//! LUT4, DFF, BRAM, each seed's Fmax and their median; for a mix with a
//! hand-written reference design (not in the repository,
//! `measure::HAND_ANCHORS`) also the
//! ratios to it: LCs over the hand design's and median Fmax over its median.
use std::path::{Path, PathBuf};

const SEEDS: [u64; 3] = [1, 2, 3];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!("usage: synth_bench OUTDIR BOARD.toml MIX.toml...");
        std::process::exit(2);
    }
    let (out, board) = (Path::new(&args[1]), Path::new(&args[2]));
    println!(
        "{:<18} {:>6} {:>6} {:>6} {:>5} {:>8} {:>8} {:>8} {:>8} {:>6}  vs hand-written reference design",
        "mix", "LCs", "LUT4", "DFF", "BRAM", "seed1", "seed2", "seed3", "median", "/clock"
    );
    let mut failed = false;
    for m in &args[3..] {
        if let Err(e) = bench(Path::new(m), out, board) {
            eprintln!("{m}: {e}");
            failed = true;
        }
    }
    if failed {
        std::process::exit(1);
    }
}

fn bench(mix_path: &Path, out: &Path, board: &Path) -> Result<(), String> {
    let mix = lut_gen::load(mix_path).map_err(|e| e.to_string())?;
    let s = lut_gen::synthesize(&mix).map_err(|e| format!("infeasible: {e}"))?;
    let dir: PathBuf = out.join(&mix.name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let e = hdl::emit(&s, Some(board)).map_err(|e| e.to_string())?;
    e.write_to(&dir).map_err(|e| e.to_string())?;
    let pcf = dir.join("slotforge.pcf");
    let runs = measure::place_and_route_seeds(&dir, Some(&pcf), s.grid.clock_hz, &SEEDS)?;
    let med = measure::median_fmax(&runs).ok_or("no placement")?;
    let r = &runs[0];
    let mhz = s.grid.clock_hz as f64 / 1e6;
    let fm: Vec<String> = runs
        .iter()
        .map(|r| format!("{:>8.2}", r.fmax_mhz))
        .collect();
    let vs = match measure::anchor(&mix.name) {
        Some(a) => format!(
            "LCs {:.2}x of {} (goal <= 1.25x), Fmax {:.2}x of {:.0} MHz (goal >= 0.85x)",
            r.lcs as f64 / a.lcs as f64,
            a.lcs,
            med / a.fmax_mhz,
            a.fmax_mhz
        ),
        None => "-".to_string(),
    };
    println!(
        "{:<18} {:>6} {:>6} {:>6} {:>5} {} {:>8.2} {:>6.2}  {vs}",
        mix.name,
        r.lcs,
        r.lut4,
        r.dff,
        r.brams,
        fm.join(" "),
        med,
        med / mhz
    );
    Ok(())
}
