use hdl::for_tests::{LinkParams, Twin};

/// The twin of a mode mix's link (2 mode bits, UART), driven with a
/// slot tick, sparse samples and a `mode` input that changes at frame
/// starts: its line decodes clean with the modes, and every header
/// names its frame's mode and the one before (docs/packet-format.md,
/// "Modes").
#[test]
fn headers_carry_the_mode_input() {
    let p = LinkParams {
        slice_cycles: 800,
        slots_per_slice: 4,
        slices_per_frame: 3,
        div: 2,
        parity: 0,
        stop_bits: 1,
        depth: 16,
        crc_init: link::format::CRC_INIT,
        axis: None,
        mode_bits: 2,
    };
    let modes = [0u8, 2, 2, 1, 3, 0, 0, 1];
    let mut r = Twin::new(p);
    let fmt = link::UartFormat {
        div: 2,
        parity: link::Parity::None,
        stop_bits: 1,
    };
    let mut rx = link::UartRx::new(fmt);
    let mut dec = link::Decoder::with_modes(p.slices_per_frame, p.mode_bits);
    let mut got = Vec::new();
    let slot = p.slice_cycles / p.slots_per_slice;
    let frame = p.slice_cycles * p.slices_per_frame;
    let mut bounds = 0u64;
    for c in 0..modes.len() as u64 * frame + 2000 {
        if let Some(b) = rx.sample(r.line()) {
            dec.push_packets(&[b.byte], &mut got);
        }
        // the mode of the frame whose slice this cycle may start
        bounds += r.boundary() as u64;
        let f = (bounds.saturating_sub(1) / p.slices_per_frame) as usize;
        let mode = modes[f.min(modes.len() - 1)];
        let valid = bounds > 0 && c % 151 == 5;
        let input = (valid, (c % 5) as u32, c as u32 & 0xffff, mode);
        r.edge(input, c % slot == slot - 1);
    }
    let st = dec.finish();
    assert!(st.clean(), "{st:?}");
    let got: Vec<_> = got
        .into_iter()
        .filter(|k| (k.frame as usize) < modes.len())
        .collect();
    assert!(got.len() >= modes.len() * 3 - 1, "{} packets", got.len());
    for k in &got {
        let f = k.frame as usize;
        let before = if f == 0 { 0 } else { modes[f - 1] };
        assert_eq!(
            (k.mode, k.prev_mode),
            (modes[f], before),
            "frame {f} slice {}",
            k.slice
        );
    }
}
