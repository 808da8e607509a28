//! The in-process simulator against docs/timing.md, cycle by cycle.
use crate::common;

use common::*;

/// Two frames of the reference mix: every pin equals docs/timing.md in every
/// cycle, every channel is sampled at exactly clock/rate intervals, and every
/// sample_value equals the word the ADC model shifted out.
#[test]
fn eskin34_two_frames() {
    let s = eskin34();
    let cycles = 2 * s.grid.frame_cycles;
    let run = run_and_compare(&s, cycles);
    // intervals per channel
    for (i, ch) in s.channels.iter().enumerate() {
        let times: Vec<u64> = run
            .instants
            .iter()
            .filter(|x| x.2 == Some(i))
            .map(|x| x.0)
            .collect();
        // docs/timing.md, "Start-up": an instant at cycle 0 is skipped
        let b = s.mix.channels[i].branch;
        let skipped = s.at(0, b) == Some(i) && s.skipped_at_startup(b, 0);
        assert_eq!(
            times.len() as u64,
            2 * ch.samples_per_frame - skipped as u64,
            "samples of channel {i}"
        );
        let first = s.first_sample_cycle(i) + if skipped { ch.interval_cycles } else { 0 };
        assert_eq!(times[0], first);
        for w in times.windows(2) {
            assert_eq!(w[1] - w[0], ch.interval_cycles, "interval of channel {i}");
        }
        let rate = s.mix.channels[i].rate_hz;
        assert_eq!(ch.interval_cycles, s.grid.clock_hz / rate);
    }
    // every conversion whose sample was emitted carries the ADC's code
    let mut codes = std::collections::BTreeMap::new();
    for (b, adc) in run.adcs.iter().enumerate() {
        for &(t, code) in &adc.conversions {
            codes.insert((t, b), code);
        }
    }
    let total: usize = run.adcs.iter().map(|a| a.conversions.len()).sum();
    assert_eq!(total as u64, 2 * s.samples_per_frame() - s.startup_skips());
    assert_eq!(
        s.startup_skips(),
        3,
        "eskin34 converts on all three branches in cycle 0"
    );
    // each sample matches the conversion of its channel (in order)
    let mut per_channel: std::collections::BTreeMap<usize, Vec<u16>> = Default::default();
    for &(t, b, ch) in &run.instants {
        per_channel
            .entry(ch.unwrap())
            .or_default()
            .push(codes[&(t, b)]);
    }
    let mut seen: std::collections::BTreeMap<usize, usize> = Default::default();
    for &(_, ch, v) in &run.samples {
        let k = seen.entry(ch as usize).or_default();
        assert_eq!(
            v,
            per_channel[&(ch as usize)][*k],
            "value of sample {k} of channel {ch}"
        );
        *k += 1;
    }
    // all but the conversions still running at the end were emitted
    assert!(run.samples.len() + s.branches.len() >= total);
}

#[test]
fn tiny_mix_matches_timing_contract() {
    let s = tiny();
    run_and_compare(&s, 3 * s.grid.frame_cycles);
}

/// A frame and its next slice: the frame's wrap, into the slice that
/// starts the next frame (the pins are compared with the reference in
/// every cycle).  Two whole frames of these mixes are `make test-long`'s
/// (`two_frames_of_the_long_mixes_match_timing_contract`).
fn frame_and_slice(s: &lut_gen::Schedule) -> u64 {
    s.grid.frame_cycles + s.grid.slice_cycles
}

#[test]
fn wide_mix_matches_timing_contract() {
    let s = wide();
    run_and_compare(&s, frame_and_slice(&s));
}

/// Three SPI timings: one shared sequencer each.
#[test]
fn three_speed_mix_matches_timing_contract() {
    let s = two_speed();
    run_and_compare(&s, frame_and_slice(&s));
}

/// Eight branches of 32 channels (256 channels, 4 mux devices each), at
/// 12 MHz: the file's 15 slots a slice in a quarter of its 48 MHz cycles
/// (`make test-long` runs two frames at 48 MHz).
#[test]
fn u2_256_channels_match_timing_contract() {
    let s = data_mix_at("u2", 12_000_000);
    assert_eq!(s.grid.slots_per_slice, data_mix("u2").grid.slots_per_slice);
    run_and_compare(&s, s.grid.frame_cycles + s.grid.slice_cycles);
}

/// Three AD7940s at 100 %: 300 channels at 1 kHz (issue 9), two frames.
#[test]
fn full300_matches_timing_contract() {
    let s = data_mix("full300");
    assert_eq!(s.channels.len(), 300);
    run_and_compare(&s, 2 * s.grid.frame_cycles);
}

/// The gateware's 16 branches (32 channels each, 4 mux devices each: all
/// 64 enables), two frames.
#[test]
fn b16_matches_timing_contract() {
    let s = data_mix("b16");
    assert_eq!(s.branches.len(), lut_gen::limits::MAX_BRANCHES);
    run_and_compare(&s, 2 * s.grid.frame_cycles);
}

/// The gateware's 1,024 channels: 16 branches x 64 channels on 8 mux
/// devices each, all 128 enables (`mux_en` wider than 64 bits), one frame.
#[test]
fn ch1024_matches_timing_contract() {
    let s = data_mix("ch1024");
    assert_eq!(s.channels.len(), lut_gen::limits::MAX_CHANNELS);
    let devices: u32 = s.branches.iter().map(|b| b.mux_devices).sum();
    assert_eq!(devices as usize, lut_gen::limits::MAX_DEVICES);
    run_and_compare(&s, s.grid.frame_cycles + s.grid.slice_cycles);
}

/// The reference mix with the compact slot LUT (slice table + rotation
/// groups + slice counter) instead of the full frame table: same pins.
#[test]
fn eskin34_compact_lut_matches_timing_contract() {
    let s = eskin34();
    run_and_compare_with(&s, frame_and_slice(&s), hdl::LutForm::Compact);
}

/// The reference mix (three branches, the merger's queue form) and 16
/// branches with the slot decoding by logic instead of the ROM (where
/// `Auto` keeps the ROM): same pins.
#[test]
fn logic_slot_decoding_matches_timing_contract() {
    let s = eskin34();
    run_and_compare_with(&s, frame_and_slice(&s), hdl::LutForm::Logic);
    let s = data_mix("b16");
    run_and_compare_with(&s, s.grid.frame_cycles, hdl::LutForm::Logic);
}

/// A frame of more slots than the full-frame ROM takes: compact LUT.  At
/// 6 MHz: the same 8,000 slots in three quarters of the file's 8 MHz
/// cycles (`make test-long` runs two frames at 8 MHz).  SCLK keeps its
/// divider of 4: with 2 (4 MHz) the master reads MISO in the cycle SCLK
/// fell, which [`Adc`] holds undefined (t4 counted from the cycle's start;
/// `sim`'s model, which times it from the edge, passes that mix).
#[test]
fn long_frame_needs_and_uses_the_compact_lut() {
    let s = data_mix_at("longframe", 6_000_000);
    assert_eq!(s.grid.frame_slots, long_frame().grid.frame_slots);
    assert!(s.grid.frame_slots > hdl::MAX_FRAME_SLOTS);
    assert!(hdl::RtlSim::with_form(&s, hdl::LutForm::Full).is_err());
    run_and_compare(&s, frame_and_slice(&s));
}

/// Two whole frames of the mixes `make test` runs for a frame and a slice
/// (u2 and the long frame at their files' clocks).
#[test]
#[ignore = "long: make test-long (two frames of six mixes)"]
fn two_frames_of_the_long_mixes_match_timing_contract() {
    for s in [long_frame(), data_mix("u2")] {
        run_and_compare(&s, 2 * s.grid.frame_cycles);
    }
    for form in [hdl::LutForm::Compact, hdl::LutForm::Logic] {
        let s = eskin34();
        run_and_compare_with(&s, 2 * s.grid.frame_cycles, form);
    }
    for s in [wide(), two_speed()] {
        run_and_compare(&s, 2 * s.grid.frame_cycles);
    }
}

/// A slot longer than 65536 cycles (the slot counter is 20 bits).
#[test]
fn long_slot_matches_timing_contract() {
    let s = long_slot();
    assert!(s.grid.slot_cycles > 1 << 16);
    run_and_compare(&s, 3 * s.grid.frame_cycles);
}
