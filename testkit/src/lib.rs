//! testkit: the test helpers several of slotforge's crates share, so no test
//! includes another crate's file by path.
//!
//! - [`tools`]: the rule for tests that drive external tools (run, skip
//!   loudly, or fail under `CI`);
//! - [`presets`]: every preset mix;
//! - [`mix`]: the shared test mixes in `testkit/mixes/` (or a preset by name);
//! - [`tb_judge`]: the verdict of the independent Icarus testbench
//!   (`tests/tb/adc_tb.v`) on its log;
//! - [`mutate`]: the Verilog mutator (mutation testing of the checkers);
//! - [`analyser`]: logic-analyser captures made from a run's pins;
//! - [`bulk`]: mixes rewritten with bulk channels (`T{0..47}`) and back;
//! - [`modemix`]: random mixes with modes, from one seeded xorshift;
//! - [`matrix`]: the feature matrix, mixes across every dimension (pairwise).

pub mod analyser;
pub mod bulk;
pub mod matrix;
pub mod modemix;
pub mod mutate;
pub mod presets;
pub mod tb_judge;
pub mod tools;

use std::path::{Path, PathBuf};

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A shared test mix, `testkit/mixes/<name>.toml`, or else the preset of
/// that name, `mixes/<name>.toml`: a preset a test also needs by name
/// (`eskin34-adaptive`) is one file, not a copy that could drift.
pub fn mix(name: &str) -> PathBuf {
    let file = format!("{name}.toml");
    let own = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("mixes")
        .join(&file);
    if own.exists() {
        own
    } else {
        root().join("mixes").join(file)
    }
}
