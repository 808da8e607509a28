//! `slotforge sim` (being built: see the issue tracker).

use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
}

pub fn run(_args: Args) -> u8 {
    eprintln!("error: `slotforge sim` is not available in this build yet");
    2
}
