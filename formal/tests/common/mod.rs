//! What the formal crate's two test binaries share.

/// The random mixes the formal tests draw (the one generator,
/// `campaign::random_mix`): a 4 MHz clock and a 1 ms frame (4,000 cycles),
/// so each proof takes seconds; one to three branches, one or two mux
/// devices, SCLK, settling and rates drawn; a branch without a mux 1 in
/// `muxless` (0: every branch has one).
pub fn quick_proof_shape(muxless: u64) -> campaign::Shape {
    campaign::Shape {
        clock_hz: 4_000_000,
        frame_us: 1_000,
        slice_us: 500,
        branches: (1, 3),
        mux_devices: (1, 2),
        sclk_hz: vec![1_000_000, 2_000_000],
        settle_ns: vec![0, 1_000, 2_000],
        channels: (2, 8),
        rates_hz: vec![1_000, 2_000, 4_000],
        muxless,
        commanded: 0,
        link: None,
    }
}
