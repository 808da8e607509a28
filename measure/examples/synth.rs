//! `cargo run -p measure --example synth -- MIX.toml OUTDIR [BOARD.toml]`:
//! emits the mix's gateware into OUTDIR and runs the one place-and-route
//! flow (`measure::place_and_route`, the same as `slotforge build`'s synthesis step);
//! prints `mix clock_MHz LCs LUT4 DFF BRAM Fmax_MHz Fmax/clock`.
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: synth MIX.toml OUTDIR [BOARD.toml]");
        std::process::exit(2);
    }
    let mix = lut_gen::load(Path::new(&args[1])).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let s = lut_gen::synthesize(&mix).unwrap_or_else(|e| {
        eprint!("infeasible: {e}");
        std::process::exit(1)
    });
    let out = Path::new(&args[2]);
    let board = args.get(3).map(Path::new);
    let e = hdl::emit(&s, board).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    e.write_to(out).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let pcf = board.map(|_| out.join("slotforge.pcf"));
    match measure::place_and_route(out, pcf.as_deref(), s.grid.clock_hz, 1) {
        Ok(r) => {
            let mhz = s.grid.clock_hz as f64 / 1e6;
            println!(
                "{:<12} {:>10.3} {:>6} {:>6} {:>6} {:>10} {:>10.2} {:.2}",
                mix.name,
                mhz,
                r.lcs,
                r.lut4,
                r.dff,
                r.brams,
                r.fmax_mhz,
                r.fmax_mhz / mhz
            );
        }
        Err(e) => {
            eprintln!("{}: {e}", mix.name);
            std::process::exit(1)
        }
    }
}
