//! lut-gen's tests of its modules' parts, one file per source file they
//! test (they were that file's unit tests; `mix_*` were `src/mix/*_tests.rs`).

mod audit;
mod audit_modes;
mod command;
mod fixes;
mod fixes_edit;
mod fpga;
mod hostlink;
mod hostlink_memo;
mod mix;
mod mix_bulk;
mod mix_front;
mod mix_modes;
mod mix_supply;
mod oswords;
mod parts;
mod ports;
mod ports_mode;
mod schedule;
mod synth;
mod synth_modes;

/// The mix tests' bad input: `text` parsed as the mix file `m.toml`, its error.
fn err(text: &str) -> lut_gen::MixError {
    lut_gen::parse(std::path::Path::new("m.toml"), text).unwrap_err()
}

/// The line (from 1) of `needle`'s first occurrence in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    text[..text.find(needle).expect(needle)].lines().count() + 1
}
