//! One module per subcommand; each exposes `Args` (clap) and `run(Args) -> u8`.

pub mod audit;
pub mod build;
pub mod check;
pub mod decode;
pub mod faults;
pub mod golden;
pub mod junit;
pub mod lut;
pub mod progress;
pub mod prove;
pub mod sigrok;
pub mod sim;
pub mod synth;
pub mod verilog;

use std::path::{Path, PathBuf};

/// Loads and schedules a mix, printing the error and returning the exit code on failure.
pub fn schedule(path: &Path) -> Result<lut_gen::Schedule, u8> {
    schedule_within(path, lut_gen::SEARCH_BUDGET)
}

/// [`schedule`] with the exact search capped at `budget` placements per
/// slot grid (`--search-limit`).
pub fn schedule_within(path: &Path, budget: u64) -> Result<lut_gen::Schedule, u8> {
    let mix = lut_gen::load(path).map_err(|e| {
        eprintln!("error: {e}");
        2u8
    })?;
    lut_gen::synthesize_within(&mix, budget).map_err(|e| {
        eprint!("{}: {e}", e.verdict.as_str());
        verdict_exit(e.verdict)
    })
}

/// `--search-limit N` of the commands that synthesize for their own output
/// (`audit`, `lut`).
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct SearchLimit {
    /// Placements the exact scheduling search may try per slot grid before
    /// it gives up: a mix it stops on is "unknown" (exit 3), not infeasible.
    /// Smaller answers sooner; larger decides more mixes.
    #[arg(long = "search-limit", value_name = "N", value_parser = whole_number,
          default_value_t = lut_gen::SEARCH_BUDGET)]
    pub nodes: u64,
}

/// Exit code of a mix without a schedule: 1 proved infeasible, 3 unknown
/// (the exact search's bound ran out: not a proof, as `prove`'s 3).
pub fn verdict_exit(v: lut_gen::Verdict) -> u8 {
    match v {
        lut_gen::Verdict::Infeasible => 1,
        lut_gen::Verdict::Unknown => 3,
    }
}

/// The `--netlist`/`--fpga` value parser: a part or its family
/// (`lut_gen::Fpga`); anything else names the known ones.
pub fn fpga(s: &str) -> Result<lut_gen::Fpga, String> {
    lut_gen::Fpga::parse(s)
}

/// The `--backend` value parser: the names `engines::Backend` knows.
pub fn backend(s: &str) -> Result<engines::Backend, String> {
    s.parse()
}

/// A waveform window bound: a frame number, or a time after cycle 0 (the
/// first cycle after reset) such as `3ms`, `250us`, `1.5ms`, `800ns`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bound {
    Frame(u64),
    /// Picoseconds.
    Time(u128),
}

/// Parses a `--from`/`--to` value.
pub fn bound(s: &str) -> Result<Bound, String> {
    let s = s.trim();
    if let Ok(n) = s.parse::<u64>() {
        return Ok(Bound::Frame(n));
    }
    let split = s.find(|c: char| c.is_ascii_alphabetic()).ok_or_else(|| {
        format!("`{s}` is neither a frame number nor a time with a unit (3ms, 250us)")
    })?;
    let (num, unit) = s.split_at(split);
    let scale: u128 = match unit {
        "s" => 1_000_000_000_000,
        "ms" => 1_000_000_000,
        "us" => 1_000_000,
        "ns" => 1_000,
        "ps" => 1,
        _ => {
            return Err(format!(
                "`{s}`: unknown time unit `{unit}` (s, ms, us, ns, ps)"
            ))
        }
    };
    let (int, frac) = num.split_once('.').unwrap_or((num, ""));
    let bad = || format!("`{s}` is not a time such as 3ms or 1.5ms");
    if int.is_empty() && frac.is_empty() {
        return Err(bad());
    }
    let int: u128 = if int.is_empty() {
        0
    } else {
        int.parse().map_err(|_| bad())?
    };
    let mut ps = int.checked_mul(scale).ok_or_else(bad)?;
    let mut place = scale;
    for c in frac.chars() {
        let d = c.to_digit(10).ok_or_else(bad)? as u128;
        place /= 10;
        if place == 0 {
            return Err(format!("`{s}` is finer than 1 ps"));
        }
        ps += d * place;
    }
    if ps > 1_000_000_000_000 * 1_000_000 {
        return Err(format!("`{s}` is too long"));
    }
    Ok(Bound::Time(ps))
}

impl Bound {
    /// Cycles after cycle 0: whole frames, or the time rounded to the
    /// nearest cycle.
    pub fn cycles(self, s: &lut_gen::Schedule) -> u64 {
        match self {
            Bound::Frame(n) => n.saturating_mul(s.grid.frame_cycles),
            Bound::Time(ps) => {
                let f = s.grid.clock_hz as u128;
                ((ps * f + 500_000_000_000) / 1_000_000_000_000) as u64
            }
        }
    }
}

/// Whose limits refuse a mix too large for the gateware.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Limits {
    /// The pin contract's, before anything runs ([`fits_pins`], exit 2):
    /// the checker and the engines size their pins from them.
    Contract,
    /// The emitter's, as it emits (`verilog`: exit 1, the file named).
    Emitter,
}

/// The mix loaded and scheduled, its limits checked, and its link to the
/// host checked ([`link_fits`]): what every command that emits, simulates,
/// checks or proves starts with (a mix with modes too: each follows the
/// switches).  On failure the
/// message is printed and the exit code returned.
pub fn load_any_modes(path: &Path, limits: Limits) -> Result<lut_gen::Schedule, u8> {
    let s = match limits {
        Limits::Contract => schedule_on_pins(path)?,
        Limits::Emitter => schedule(path)?,
    };
    link_fits(&s, path)?;
    Ok(s)
}

/// [`schedule`], then the contract's limits checked ([`fits_pins`]).
pub fn schedule_on_pins(path: &Path) -> Result<lut_gen::Schedule, u8> {
    let s = schedule(path)?;
    fits_pins(&s)?;
    Ok(s)
}

/// Checks that a schedule fits the pin contract's limits (the checker and
/// the engines size their pins from them), else prints why: exit 2.
pub fn fits_pins(s: &lut_gen::Schedule) -> Result<(), u8> {
    lut_gen::Layout::fits(s).map_err(|m| {
        eprintln!("error: mix `{}`: {m}", s.mix.name);
        2u8
    })
}

/// Refuses, before any run, a mix whose link to the host cannot carry it
/// (the audit's "infeasible"): the key named as the parser names a bad
/// one, `file:line:col: link.<key>: ...`, with the minimum that fits; exit 1.
pub fn link_fits(s: &lut_gen::Schedule, file: &Path) -> Result<(), u8> {
    match lut_gen::plan_link(s) {
        Some(Err(e)) => {
            eprintln!("error: {}", e.at(file));
            Err(1)
        }
        _ => Ok(()),
    }
}

/// A file the user named for one output (`--vcd`, `--samples`,
/// `--link-bytes`, `--junit`, `--harness`, `decode -o`): checked before any
/// work and never a folder created for it.  Refused (the message names
/// `flag` and the path) when it is a folder or its folder does not exist
/// ("no such folder"); otherwise returned absolute, so a file written
/// beside it (a `.gtkw`) finds it from anywhere.
pub fn output_file(flag: &str, path: &Path) -> Result<PathBuf, String> {
    let refuse = |why: &str| format!("{flag} {}: {why}", path.display());
    if path.is_dir() {
        return Err(refuse("is a folder, not a file"));
    }
    let name = path.file_name().ok_or_else(|| refuse("not a file name"))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match dir.canonicalize() {
        Ok(d) if d.is_dir() => Ok(d.join(name)),
        Ok(_) => Err(refuse("a part of the path is a file, not a folder")),
        Err(e) => Err(refuse(&lut_gen::write_words(&e))),
    }
}

/// Writes `text` to `dir/name` through a temporary file and a rename, so an
/// interrupted run never leaves a half-written file.
pub fn write_atomic(dir: &Path, name: &str, text: &str) -> Result<(), String> {
    let path = dir.join(name);
    let tmp = dir.join(format!(".{name}.tmp"));
    let written = std::fs::write(&tmp, text);
    put_in_place(&tmp, &path, written)
}

/// Renames the temporary file `tmp`, once `written` says it is complete,
/// to `path`; on any failure `tmp` is removed and the message names `path`.
pub fn put_in_place(tmp: &Path, path: &Path, written: std::io::Result<()>) -> Result<(), String> {
    written
        .and_then(|()| std::fs::rename(tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(tmp);
            let why = lut_gen::write_words(&e);
            format!("{}: cannot write: {why}", path.display())
        })
}

/// Writes generated files into `dir` (created if missing).  Each file is
/// written to a temporary name and renamed, so an interrupted run never
/// leaves a half-written file, and nothing else in `dir` is touched.
pub fn write_files(dir: &Path, files: &[(&str, String)]) -> Result<(), u8> {
    if dir.exists() && !dir.is_dir() {
        eprintln!("error: {}: exists and is not a directory", dir.display());
        return Err(2);
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        let why = lut_gen::io_words(&e);
        eprintln!("error: {}: cannot create directory: {why}", dir.display());
        2u8
    })?;
    for (name, text) in files {
        write_atomic(dir, name, text).map_err(|e| {
            eprintln!("error: {e}");
            2u8
        })?;
    }
    Ok(())
}

/// Converts `vcd` to FST at `fst` through `fst-writer` (`judge::fst`),
/// written beside it under a temporary name and renamed, so a failure
/// leaves no partial FST.
pub fn vcd_to_fst(vcd: &Path, fst: &Path) -> std::io::Result<()> {
    let tmp = fst.with_extension("fst.part");
    let r = judge::fst_from_vcd(vcd, &tmp);
    if let Err(e) = r {
        let _ = std::fs::remove_file(&tmp);
        return Err(std::io::Error::other(e));
    }
    std::fs::rename(&tmp, fst)
}

/// A whole-number option (`--frames 3`), refused in the user's words:
/// clap's own parser would say "invalid digit found in string".
pub fn whole_number(v: &str) -> Result<u64, String> {
    let t = v.trim().replace('_', "");
    if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
        return Err("expected a whole number, like 3".into());
    }
    t.parse()
        .map_err(|_| format!("too large: at most {}", u64::MAX))
}

pub(crate) use judge::counted;

#[cfg(test)]
mod counted_tests {
    use super::counted;

    #[test]
    fn one_is_singular_and_every_other_count_plural() {
        assert_eq!(counted(1, "clean run"), "1 clean run");
        assert_eq!(counted(0, "clean run"), "0 clean runs");
        assert_eq!(counted(2, "site"), "2 sites");
        assert_eq!(counted(3, "random mix"), "3 random mixes");
        assert_eq!(counted(1, "random mix"), "1 random mix");
    }
}
