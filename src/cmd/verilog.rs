//! `slotforge verilog MIX -o DIR`: the gateware and everything a tool flow needs.

use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// Output directory (created if missing; only the generated files are written).
    #[arg(short = 'o', long = "out")]
    pub out: PathBuf,
    /// Board file mapping port bits to pins (see constraints/); without it the
    /// PCF is a template listing every port bit.
    #[arg(long)]
    pub board: Option<PathBuf>,
}

pub fn run(args: Args) -> u8 {
    // the gateware's limits are the emitter's to refuse (exit 1)
    let s = match super::load_any_modes(&args.mix, super::Limits::Emitter) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let emitted = match hdl::emit(&s, args.board.as_deref()) {
        Ok(e) => e,
        Err(e @ hdl::HdlError::Unsupported(_)) => {
            eprintln!("error: {}: {e}", args.mix.display());
            return 1;
        }
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let files: Vec<(&str, String)> = emitted
        .files()
        .iter()
        .map(|(n, t)| (n.as_str(), t.clone()))
        .collect();
    match super::write_files(&args.out, &files) {
        Ok(()) => {
            for (name, _) in &files {
                println!("{}", args.out.join(name).display());
            }
            0
        }
        Err(code) => code,
    }
}
