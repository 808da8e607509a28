//! `slotforge lut MIX -o DIR`: the slot LUT as `$readmemh` hex, CSV and Table 1 markdown.

use std::path::PathBuf;

use lut_gen::lut;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// Output directory (created if missing; only slots.* files are written).
    #[arg(short = 'o', long = "out")]
    pub out: PathBuf,
    #[command(flatten)]
    pub search: super::SearchLimit,
}

pub fn run(args: Args) -> u8 {
    let s = match super::schedule_within(&args.mix, args.search.nodes) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let files = [
        ("slots.hex", lut::to_hex(&s)),
        ("slots.csv", lut::to_csv(&s)),
        ("slots.md", lut::to_markdown(&s)),
    ];
    match super::write_files(&args.out, &files) {
        Ok(()) => 0,
        Err(code) => code,
    }
}
