//! `cargo run -p hdl --example emit -- MIX.toml OUTDIR [BOARD.toml]`
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: emit MIX.toml OUTDIR [BOARD.toml]");
        std::process::exit(2);
    }
    let mix = lut_gen::load(Path::new(&args[1])).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let s = lut_gen::synthesize(&mix).unwrap_or_else(|e| {
        eprintln!("{e:?}");
        std::process::exit(1)
    });
    let board = args.get(3).map(Path::new);
    // SLOTFORGE_LUT=full|logic forces the slot LUT form (measuring one against the other)
    let form = match std::env::var("SLOTFORGE_LUT").as_deref() {
        Ok("full") => hdl::LutForm::Full,
        Ok("logic") => hdl::LutForm::Logic,
        _ => hdl::LutForm::Auto,
    };
    let out = hdl::emit_with(&s, board, form).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    out.write_to(Path::new(&args[2])).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
}
