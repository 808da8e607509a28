//! The test-only switch that turns one detector of the judge off, so that a
//! test can show what the fault campaign misses without it (the campaign's
//! figures must be able to come out worse).
//!
//! Compiled in only with the `test-switch` feature, which only test builds
//! enable (the root crate's and cosim's dev-dependencies); a release or
//! `cargo build` binary has no such switch.  With it, the environment
//! variable [`ENV`] names detectors (comma-separated) that report nothing:
//! `invariants` (every model-free check: the recorder drops its
//! violations), `model` (the cycle-by-cycle comparison), `sigrok` (the SPI
//! decode of the pins).

/// The environment variable read by test builds.
pub const ENV: &str = "SLOTFORGE_TEST_DISABLE_DETECTOR";

/// Whether `detector` is switched off (always `false` outside test builds).
#[cfg(feature = "test-switch")]
pub fn disabled(detector: &str) -> bool {
    use std::sync::OnceLock;
    static OFF: OnceLock<Vec<String>> = OnceLock::new();
    OFF.get_or_init(|| {
        std::env::var(ENV)
            .unwrap_or_default()
            .split(',')
            .map(|d| d.trim().to_string())
            .filter(|d| !d.is_empty())
            .collect()
    })
    .iter()
    .any(|d| d == detector)
}

/// Whether `detector` is switched off (always `false` outside test builds).
#[cfg(not(feature = "test-switch"))]
#[inline(always)]
pub fn disabled(_detector: &str) -> bool {
    false
}
