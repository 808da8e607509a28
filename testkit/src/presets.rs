//! The preset mixes (`mixes/*.toml`), for tests that cover every preset.

use std::path::{Path, PathBuf};

/// Every `mixes/*.toml` under the repository root `root`, sorted.
pub fn presets(root: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root.join("mixes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    v
}
