//! One module per subcommand; each exposes `Args` (clap) and `run(Args) -> u8`.

pub mod audit;
pub mod check;
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
