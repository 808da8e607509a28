//! `slotforge lut`.

use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
}

pub fn run(args: Args) -> u8 {
    match super::schedule(&args.mix) {
        Ok(_) => 0,
        Err(c) => c,
    }
}
