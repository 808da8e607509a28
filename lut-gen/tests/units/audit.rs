use lut_gen::for_tests::{alias_hz, least};
use lut_gen::{AuditReport, Limit};
use std::path::Path;

/// A mix in the reference design's shape, written out here so the
/// expected figures can be counted by hand: branch `fast` with `n_fast`
/// channels at 1 kHz on 4 mux devices (32 inputs), branch `slow` with 3
/// channels at 100 Hz on one device, one 2 kHz channel on `slow`.
fn mix(n_fast: usize, clock: u64, sclk: Option<u64>, bw_2k: f64) -> lut_gen::Mix {
    let mut t = format!(
        "name = \"t\"\n[clock]\nhz = {clock}\n[frame]\nperiod_us = 10_000\nslice_us = 1_000\n\
         [[branch]]\nname = \"fast\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 4\nsettle_ns = 2_000\n{}\
         [[branch]]\nname = \"slow\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n",
        sclk.map_or(String::new(), |s| format!("sclk_hz = {s}\n"))
    );
    for i in 0..n_fast {
        t += &format!("[[channel]]\nname = \"F{i}\"\nbranch = \"fast\"\nrate_hz = 1_000\n");
    }
    for i in 0..3 {
        t += &format!("[[channel]]\nname = \"S{i}\"\nbranch = \"slow\"\nrate_hz = 100\n");
    }
    t += &format!(
        "[[channel]]\nname = \"A\"\nbranch = \"slow\"\nrate_hz = 2_000\nbandwidth_hz = {bw_2k}\n"
    );
    lut_gen::parse(Path::new("t.toml"), &t).unwrap()
}

fn audit(m: &lut_gen::Mix) -> AuditReport {
    AuditReport::of_schedule(&lut_gen::synthesize(m).unwrap())
}

#[test]
fn utilization_against_the_adc_and_the_grid() {
    let m = mix(30, 48_000_000, Some(2_500_000), 900.0);
    let a = audit(&m);
    // Recount from the rates: 30 x 1000 S/s on an ADC of 100 kSPS.
    let fast = &a.branches[0];
    assert_eq!(fast.demand_sps, 30 * 1000);
    assert_eq!(fast.adc_max_sps, 100_000.0);
    assert!((fast.adc_utilization - 0.30).abs() < 1e-12);
    // 30 conversions per 1 ms slice fill a 30-slot grid.
    assert_eq!(a.slots_per_slice, 30);
    assert_eq!(fast.conversions_per_frame, 30 * 10);
    assert!((fast.utilization - 1.0).abs() < 1e-12);
    // slow: 3 x 100 + 2000 = 2300 S/s; per 10 ms frame 3 x 1 + 20 = 23 of 300 slots.
    let slow = &a.branches[1];
    assert_eq!(slow.demand_sps, 3 * 100 + 2000);
    assert!((slow.adc_utilization - 0.023).abs() < 1e-12);
    assert_eq!(slow.conversions_per_frame, 23);
    assert!((slow.utilization - 23.0 / 300.0).abs() < 1e-12);
}

#[test]
fn headroom_names_the_binding_limit() {
    let m = mix(30, 48_000_000, None, 900.0);
    let a = audit(&m);
    let at = |b: usize, r: u64| {
        a.branches[b]
            .headroom
            .iter()
            .find(|h| h.rate_hz == r)
            .unwrap()
            .clone()
    };
    // fast: 32 inputs - 30 = 2 free; ADC (100000 - 30000) / 1000 = 70;
    // the 30-slot grid is full, so the grid binds at 0.
    let h = at(0, 1000);
    assert_eq!(
        (h.by_mux_inputs, h.by_adc_throughput, h.by_slot_grid),
        (2, 70, 0)
    );
    assert_eq!((h.more_channels, h.binding), (0, Limit::SlotGrid));
    // A finer grid: 32 slots of 1500 cycles (>= the 480-cycle shortest
    // slot) leave 2 per slice, i.e. 2 more 1 kHz channels; then the
    // inputs bind.
    let f = h.finer_grid.expect("a finer grid helps");
    assert_eq!(f.slots_per_slice, 32);
    assert_eq!(48_000 % f.slots_per_slice, 0);
    assert!(f.slot_cycles >= a.branches[0].min_slot_cycles);
    assert_eq!((f.more_channels, f.binding), (2, Limit::MuxInputs));
    // ADC: 100 Hz: (100000 - 30000) / 100 = 700.
    assert_eq!(at(0, 100).by_adc_throughput, 700);
    // slow: 8 inputs - 4 = 4 free bind; its grid has 300 - 23 slots free.
    let h = at(1, 100);
    assert_eq!((h.more_channels, h.binding), (4, Limit::MuxInputs));
    assert_eq!(h.by_adc_throughput, (100_000 - 2300) / 100);
    assert!(h.by_slot_grid >= 4 && h.finer_grid.is_none());
    // With 10 fewer fast channels the synthesizer picks the fewest
    // slots, 20 per slice, which they fill: 12 free inputs, but the grid
    // binds; 32 slots per slice (24 leaves 4, 25 cannot hold 2 kHz, 30
    // leaves 10) make room for all 12.
    let a = audit(&mix(20, 48_000_000, None, 900.0));
    assert_eq!(a.slots_per_slice, 20);
    let h = &a.branches[0].headroom[1];
    assert_eq!(h.rate_hz, 1000);
    assert_eq!(
        (h.by_mux_inputs, h.more_channels, h.binding),
        (12, 0, Limit::SlotGrid)
    );
    let f = h.finer_grid.as_ref().unwrap();
    assert_eq!(
        (f.slots_per_slice, f.more_channels, f.binding),
        (32, 12, Limit::MuxInputs)
    );
}

#[test]
fn adc_throughput_can_bind() {
    // 30 fast channels at 1 kHz; a 2 kHz headroom counts (100000 - 30000) / 2000 = 35.
    let a = audit(&mix(30, 48_000_000, None, 900.0));
    let h = a.branches[0]
        .headroom
        .iter()
        .find(|h| h.rate_hz == 2000)
        .unwrap();
    assert_eq!(h.by_adc_throughput, 35);
    assert_eq!(least(40, 35, 50), (35, Limit::AdcThroughput));
    assert_eq!(least(2, 2, 2), (2, Limit::MuxInputs));
    assert_eq!(least(9, 9, 3), (3, Limit::SlotGrid));
}

#[test]
fn aliasing_folds_to_the_nearest_multiple() {
    let cases = [
        (600.0, 1000.0, 400.0),
        (1400.0, 1000.0, 400.0),
        (2600.0, 1000.0, 400.0),
        (500.0, 1000.0, 500.0),
        (1000.0, 1000.0, 0.0),
        (6000.0, 5000.0, 1000.0),
        (250.5, 100.0, 49.5),
        (900.0, 2000.0, 900.0),
        (1100.0, 2000.0, 900.0),
    ];
    for (f, fs, want) in cases {
        assert!((alias_hz(f, fs) - want).abs() < 1e-9, "{f} at {fs}");
    }
    // In the report: 1100 Hz on the 2 kHz channel shows at 900 Hz.
    let a = audit(&mix(30, 48_000_000, None, 1100.0));
    let c = a.channels.iter().find(|c| c.name == "A").unwrap();
    assert_eq!(c.alias_hz, Some(900.0));
    assert!(a.warnings.iter().any(|w| w.contains("shows as 900 Hz")));
    // At or below Nyquist: no alias figure.
    let a = audit(&mix(30, 48_000_000, None, 1000.0));
    let c = a.channels.iter().find(|c| c.name == "A").unwrap();
    assert_eq!(c.alias_hz, None);
    assert!(a.to_text().contains("alias"));
}

#[test]
fn inexact_sclk_is_reported_with_the_value_used() {
    // 48 MHz / 2.5 MHz = 19.2: the even divider 20 gives 2.4 MHz.
    let a = audit(&mix(30, 48_000_000, Some(2_500_000), 900.0));
    let b = &a.branches[0];
    assert_eq!((b.sclk_requested_hz, b.sclk_div), (2_500_000, 20));
    assert_eq!(b.sclk_hz, 2_400_000.0);
    assert!(b.sclk_explicit && !a.branches[1].sclk_explicit);
    assert!(a.notes.iter().any(|n| n.contains("`fast`")
        && n.contains("2500000 Hz requested")
        && n.contains("2400000 Hz used")));
    assert!(a.to_text().contains("note: branch `fast`"));
    // 50 MHz / 20 = 2.5 MHz exactly: nothing to say.
    let a = audit(&mix(30, 50_000_000, Some(2_500_000), 900.0));
    assert_eq!(a.branches[0].sclk_hz, 2_500_000.0);
    assert!(a.notes.is_empty(), "{:?}", a.notes);
}

#[test]
fn sample_channel_is_the_file_index() {
    let m = mix(5, 48_000_000, None, 900.0);
    let a = audit(&m);
    let names: Vec<&str> = a.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["F0", "F1", "F2", "F3", "F4", "S0", "S1", "S2", "A"]);
    for (i, c) in a.channels.iter().enumerate() {
        assert_eq!(c.sample_channel, i);
    }
    assert!(a.to_text().contains("its index in the mix file, 0-based"));
}

/// A chain's maximum is what its timing allows (50 MHz: 12.5 MHz SCK, a
/// 3.2 us conversion and 64 bits read take 418 cycles, so 4 x 50 MHz /
/// 418 = 478469 S/s, not 4 x 200 kSPS), and the branch table, the parts
/// table and the total print that one value.
#[test]
fn a_chains_maximum_is_one_figure() {
    let t =
        "name = \"v\"\n[clock]\nhz = 50_000_000\n[frame]\nperiod_us = 10_000\nslice_us = 1_000\n\
             [[branch]]\nname = \"a\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n\
             [[branch]]\nname = \"v\"\nadc = \"ad7685\"\nchain = 4\nmux = \"none\"\n\
             [[channel]]\nname = \"A\"\nbranch = \"a\"\nrate_hz = 1_000\n";
    let mut t = t.to_string();
    for m in 0..4 {
        t += &format!(
            "[[channel]]\nname = \"V{m}\"\nbranch = \"v\"\nmember = {m}\nrate_hz = 4_000\n"
        );
    }
    let a = audit(&lut_gen::parse(Path::new("v.toml"), &t).unwrap());
    let (b, p) = (&a.branches[1], &a.parts[1]);
    assert_eq!(b.adc_max_sps.round(), 478_469.0);
    assert_eq!(b.adc_max_sps, p.max_samples_hz);
    assert_eq!(p.max_conversions_hz * 4.0, p.max_samples_hz);
    assert_eq!(a.adc_limit_hz, a.branches[0].adc_max_sps + b.adc_max_sps);
    let text = a.to_text();
    assert!(text.contains(" 478469 "), "{text}");
    assert!(!text.contains("800000"), "{text}");
    // the ADC's headroom counts against the same figure
    let h = b.headroom.iter().find(|h| h.rate_hz == 4_000).unwrap();
    assert_eq!(h.by_adc_throughput, (478_469 - 16_000) / 4_000);
}
