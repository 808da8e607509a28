//! Register widths of the fixed-maximum core, in one place that both the
//! planner (`plan.rs`, which checks a schedule against them) and the
//! rust-hdl blocks (`core/`, which are built at them) read.  The lane
//! counts come from the pin contract's limits (`lut_gen::limits`).

pub use lut_gen::limits::{MAX_BRANCHES, MAX_CHANNELS, MAX_DEVICES, MAX_DEVICES_PER_BRANCH};

/// Bits to count `0..n` (`n` a power of two).
const fn log2(n: usize) -> usize {
    n.trailing_zeros() as usize
}

/// Width of the cycle-in-slot counter.
pub const CNT_BITS: usize = 20;
/// Width of the slot counter (ROM address): slot in frame (full LUT) or
/// slot in slice (compact LUT).
pub const SLOT_BITS: usize = 12;
/// Width of the slice counter (compact LUT only).
pub const SLICE_BITS: usize = 10;
/// Bits of the mode number in the core (16 modes at most).
pub const MODE_BITS: usize = 4;
/// Width of the SCLK phase counter.
pub const PH_BITS: usize = 10;
/// Width of the SCLK period counter (periods per conversion, all words).
pub const NFALL_BITS: usize = 8;
/// Width of the in-word serial bit counter (up to 32 clocks per word).
pub const WORD_BIT_BITS: usize = 6;
/// Width of the chain member counter (up to 8 chained parts).
pub const MEMBER_BITS: usize = 3;
/// Width of `sample_value` in the core: the widest word the pin contract carries.
pub const VALUE_BITS: usize = lut_gen::SAMPLE_VALUE_BITS as usize;
/// Width of a channel index.
pub const CH_BITS: usize = log2(MAX_CHANNELS);
/// Width of a device index inside a branch.
pub const DEV_BITS: usize = log2(MAX_DEVICES_PER_BRANCH);
/// Per-branch mux enables (one-hot over the branch's devices).
pub const EN_BITS: usize = MAX_DEVICES_PER_BRANCH;
/// Total mux enables on the core.
pub const EN_TOTAL: usize = MAX_DEVICES;

const _: () = {
    assert!(MAX_CHANNELS.is_power_of_two() && MAX_DEVICES_PER_BRANCH.is_power_of_two());
};
