//! Shared by several test files of this binary (one copy here).

use std::path::{Path, PathBuf};

/// A shared test mix, `testkit/mixes/<name>.toml`, or else the preset of
/// that name, `mixes/<name>.toml` (as `testkit::mix`, which lut-gen's tests
/// cannot use: testkit is built on lut-gen).
pub fn testkit_path(name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let own = root.join(format!("testkit/mixes/{name}.toml"));
    if own.exists() {
        own
    } else {
        root.join(format!("mixes/{name}.toml"))
    }
}

/// [`testkit_path`]'s mix, loaded.
pub fn testkit(name: &str) -> lut_gen::Mix {
    lut_gen::load(&testkit_path(name)).unwrap()
}
