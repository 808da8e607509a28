//! One module per subcommand; each exposes `Args` (clap) and `run(Args) -> u8`.

pub mod audit;
pub mod check;
pub mod faults;
pub mod lut;
pub mod sim;
pub mod verilog;

use std::path::Path;

/// Loads and schedules a mix, printing the error and returning the exit code on failure.
pub fn schedule(path: &Path) -> Result<lut_gen::Schedule, u8> {
    let mix = lut_gen::load(path).map_err(|e| {
        eprintln!("error: {e}");
        2u8
    })?;
    lut_gen::synthesize(&mix).map_err(|e| {
        eprint!("infeasible: {e}");
        1u8
    })
}

/// The `--backend` value parser: the names `cosim::Backend` knows.
pub fn backend(s: &str) -> Result<cosim::Backend, String> {
    s.parse()
}

/// Checks that a schedule fits the pin contract's limits (the checker and
/// the engines size their pins from them), else prints why: exit 2.
pub fn fits_pins(s: &lut_gen::Schedule) -> Result<(), u8> {
    lut_gen::ports::Layout::fits(s).map_err(|m| {
        eprintln!("error: mix `{}`: {m}", s.mix.name);
        2u8
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
        eprintln!("error: {}: cannot create directory: {e}", dir.display());
        2u8
    })?;
    for (name, text) in files {
        let path = dir.join(name);
        let tmp = dir.join(format!(".{name}.tmp"));
        std::fs::write(&tmp, text)
            .and_then(|()| std::fs::rename(&tmp, &path))
            .map_err(|e| {
                let _ = std::fs::remove_file(&tmp);
                eprintln!("error: {}: cannot write: {e}", path.display());
                2u8
            })?;
    }
    Ok(())
}
