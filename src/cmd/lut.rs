//! `slotforge lut MIX -o DIR`: the slot LUT as `$readmemh` hex, CSV and Table 1 markdown
//! (a mix with modes: one set per mode, `slots-<mode>.*`).

use std::path::PathBuf;

use lut_gen::lut;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// Output directory (created if missing; only slots.* files, or with
    /// modes slots-<mode>.* files, are written).
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
    let files = tables(&s);
    let files: Vec<(&str, String)> = files.iter().map(|(n, t)| (n.as_str(), t.clone())).collect();
    match super::write_files(&args.out, &files) {
        Ok(()) => 0,
        Err(code) => code,
    }
}

/// The files to write: `slots.*` of the one table, or for a mix with modes
/// `slots-<mode>.*` of each mode's table (each on the same slot grid), so no
/// file shows one mode as if it were the mix.
fn tables(s: &lut_gen::Schedule) -> Vec<(String, String)> {
    let one = |tag: &str, t: &lut_gen::Schedule| {
        [
            (format!("slots{tag}.hex"), lut::to_hex(t)),
            (format!("slots{tag}.csv"), lut::to_csv(t)),
            (format!("slots{tag}.md"), lut::to_markdown(t)),
        ]
    };
    match s.mode_plan() {
        Some(m) if !s.modes.is_empty() => m
            .names
            .iter()
            .zip(&s.modes)
            .flat_map(|(name, t)| {
                // each file names its mode where it names the mix
                let mut t = t.clone();
                t.mix.name = format!("{} (mode {name})", s.mix.name);
                one(&format!("-{name}"), &t)
            })
            .collect(),
        _ => one("", s).into(),
    }
}
