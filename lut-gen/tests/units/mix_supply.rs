//! Where each part holds its input, sync groups at those instants, and the
//! converter's supply (`vdd`).

use std::path::Path;

use lut_gen::for_tests::{feasible, CANDIDATE_BUDGET};
use lut_gen::SampleAt;
use lut_gen::{parse, Mix, MixError};

/// An MCP3208 beside an AD7940, optionally in one sync group (`M0`, `A0`).
fn pair(mcp: &str, sync: bool) -> String {
    let tag = if sync { "sync = \"s\"\n" } else { "" };
    format!(
        "name = \"p\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 1_000\nslice_us = 500\n\
         [[branch]]\nname = \"m\"\nadc = \"mcp3208\"\nmux = \"internal\"\n{mcp}\n\
         [[branch]]\nname = \"a\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n\
         [[channel]]\nname = \"M0\"\nbranch = \"m\"\nrate_hz = 2_000\ninput = 0\n{tag}\
         [[channel]]\nname = \"M1\"\nbranch = \"m\"\nrate_hz = 4_000\ninput = 1\n\
         [[channel]]\nname = \"A0\"\nbranch = \"a\"\nrate_hz = 2_000\n{tag}"
    )
}

fn parse_text(text: &str) -> Result<Mix, MixError> {
    parse(Path::new("m.toml"), text)
}

#[test]
fn each_part_is_sampled_where_its_datasheet_says() {
    let m = parse_text(&pair("", false)).unwrap();
    let s = lut_gen::synthesize(&m).unwrap();
    // MCP3208 at 1 MHz (48 MHz / 48): setup 5 cycles, then six periods
    assert_eq!(m.branches[0].adc.sample, SampleAt::SclkFall(6));
    assert_eq!(s.sample_after(0), 5 + 6 * 48);
    assert_eq!(s.sample_after(1), 0);
    for c in 0..m.channels.len() {
        let b = m.channels[c].branch;
        let start = s.channels[c].offset_slot * s.grid.slot_cycles;
        assert_eq!(s.first_sample_cycle(c), start + s.sample_after(b));
        // the sample that leaves after the first conversion's read
        let strobe = start + s.branches[b].spi.read_cycles + 1;
        assert_eq!(s.sampled_at(c, strobe), Some(start + s.sample_after(b)));
    }
    let a = lut_gen::AuditReport::of_schedule(&s);
    assert_eq!(a.parts[0].sample_after_cycles, 293);
    assert!((a.parts[0].sample_after_ns - 6104.2).abs() < 0.1);
    assert_eq!(a.channels[0].first_sample_cycle, s.first_sample_cycle(0));
    assert!(a.to_text().contains("+6.104us"), "{}", a.to_text());
}

#[test]
fn a_sync_group_whose_parts_sample_apart_holds_back_the_earlier_one() {
    let m = parse_text(&pair("", true)).unwrap();
    let s = lut_gen::synthesize(&m).unwrap();
    // the AD7940 (at its CS fall) waits for the MCP3208's 6th falling edge
    assert_eq!((s.holdoff(0), s.holdoff(1)), (0, 5 + 6 * 48));
    assert_eq!(s.sample_after(1), s.sample_after(0));
    assert_eq!(s.first_sample_cycle(0), s.first_sample_cycle(2));
    // the branch outside any group, and the one holding latest, wait nothing;
    // the slot holds the hold-off, the read and the quiet time
    let a = &s.branches[1].spi;
    assert!(s.grid.slot_cycles >= a.holdoff_cycles + a.read_cycles + a.quiet_cycles);
    let audit = lut_gen::AuditReport::of_schedule(&s);
    assert_eq!(audit.parts[1].holdoff_cycles, 293);
    assert!(
        audit.to_text().contains("at start after 6.104us hold-off"),
        "{}",
        audit.to_text()
    );
    // no sync group: no hold-off, and the JSON does not name one
    let free = lut_gen::synthesize(&parse_text(&pair("", false)).unwrap()).unwrap();
    assert_eq!((free.holdoff(0), free.holdoff(1)), (0, 0));
    let json = serde_json::to_string(&lut_gen::AuditReport::of_schedule(&free)).unwrap();
    assert!(!json.contains("holdoff"), "{json}");
    // two MCP3208s at one SCLK hold their inputs at one instant without one
    let two = pair("", true)
        .replace(
            "adc = \"ad7940\"\nmux = \"tmux1108\"",
            "adc = \"mcp3208\"\nmux = \"internal\"",
        )
        .replace(
            "name = \"A0\"\nbranch = \"a\"",
            "name = \"A0\"\nbranch = \"a\"\ninput = 3",
        );
    let s = lut_gen::synthesize(&parse_text(&two).unwrap()).unwrap();
    assert_eq!((s.holdoff(0), s.holdoff(1)), (0, 0));
    // ... and at two SCLKs the faster one waits: 6 periods of 1 MHz against 6 of 500 kHz
    let slow = two.replace(
        "name = \"a\"\nadc = \"mcp3208\"",
        "name = \"a\"\nadc = \"mcp3208\"\nsclk_hz = 500_000",
    );
    let s = lut_gen::synthesize(&parse_text(&slow).unwrap()).unwrap();
    assert_eq!((s.holdoff(0), s.holdoff(1)), (6 * 48, 0));
    assert_eq!(s.first_sample_cycle(0), s.first_sample_cycle(2));
}

#[test]
fn a_hold_off_that_does_not_fit_a_slice_is_refused_naming_group_and_parts() {
    // a slow AD7940 (48 MHz / 146: 2 340 cycles with its quiet time) fits a
    // 50 us slice, but not after the MCP3208's 293-cycle hold-off
    let slow = pair("", true)
        .replace("slice_us = 500", "slice_us = 50")
        .replace(
            "mux = \"tmux1108\"\n",
            "mux = \"tmux1108\"\nsclk_hz = 330_000\n",
        );
    let e = parse_text(&slow).unwrap_err();
    assert_eq!(e.field, "channel[2].sync", "{e}");
    for w in [
        "sync group `s` cannot hold at one instant",
        "`M0` on branch `m` (mcp3208) holds its input 6.104 us after its transaction starts",
        "`A0` on branch `a` (ad7940) starts its transaction 6.104 us after the slot tick",
        "longer than a slice (50.000 us)",
    ] {
        assert!(e.message.contains(w), "{w}: {e}");
    }
    // without the group the same mix audits feasible
    let m = parse_text(&slow.replace("sync = \"s\"\n", "")).unwrap();
    assert!(lut_gen::synthesize(&m).is_ok());
}

#[test]
fn the_supply_sets_the_parts_limits_and_a_refusal_names_vdd() {
    // 2 MHz: the MCP3208's figure at 5 V, not at 2.7 V
    let fast = pair("sclk_hz = 2_000_000", false);
    let e = parse_text(&fast).unwrap_err();
    assert_eq!(e.field, "branch[0].sclk_hz", "{e}");
    for w in [
        "MCP3208 SCLK 2 MHz exceeds its 1 MHz at 2.7 V",
        "say `vdd = 5.0` on branch `m`",
    ] {
        assert!(e.message.contains(w), "{w}: {e}");
    }
    // the advice holds: with it the mix audits feasible, at 5 V's figures
    let said = pair("sclk_hz = 2_000_000\nvdd = 5.0", false);
    let m = parse_text(&said).unwrap();
    assert_eq!(m.branches[0].vdd_mv, Some(5_000));
    assert_eq!(m.branches[0].adc.max_sps, 100_000);
    let s = lut_gen::synthesize(&m).unwrap();
    let a = lut_gen::AuditReport::of_schedule(&s);
    assert!(a.feasible);
    assert_eq!((a.parts[0].vdd_v, a.parts[0].vdd_given), (Some(5.0), true));
    assert_eq!((a.parts[1].vdd_v, a.parts[1].vdd_given), (Some(2.5), false));
    assert_eq!(a.branches[0].sclk_hz, 2_000_000.0);
    let j: serde_json::Value = serde_json::from_str(&a.to_json()).unwrap();
    assert_eq!(j["parts"][0]["vdd_v"], 5.0);
    assert!(a.to_text().contains(" 5.0 "), "{}", a.to_text());
    // an integer works as well; 5 V without sclk_hz takes the 5 V maximum
    let m = parse_text(&pair("vdd = 5", false)).unwrap();
    assert_eq!(m.branches[0].sclk_hz, 2_000_000);
    // between the columns the lower one holds
    let e = parse_text(&pair("sclk_hz = 2_000_000\nvdd = 4.0", false)).unwrap_err();
    assert!(e.message.contains("exceeds its 1 MHz at 4.0 V"), "{e}");
    assert!(!e.message.contains("say `vdd"), "{e}");
}

#[test]
fn the_vdd_advice_is_given_only_when_the_mix_then_audits() {
    // 4 x 30 kHz = 120 kS/s: more than the MCP3208 gives at 5 V either
    let busy = pair("sclk_hz = 2_000_000", false)
        .replace("rate_hz = 2_000\ninput = 0", "rate_hz = 60_000\ninput = 0")
        .replace("rate_hz = 4_000\ninput = 1", "rate_hz = 60_000\ninput = 1");
    let e = parse_text(&busy).unwrap_err();
    assert_eq!(e.field, "branch[0].sclk_hz", "{e}");
    assert!(e.message.contains("exceeds"), "{e}");
    assert!(e.message.contains("allows 2 MHz from 5.0 V"), "{e}");
    assert!(!e.message.contains("say `vdd"), "{e}");
}

#[test]
fn a_vdd_outside_the_part_or_not_volts_is_refused_where_written() {
    for (vdd, field, says) in [
        (
            "vdd = 6.0",
            "branch[0].vdd",
            "outside the mcp3208 supply range 2.7..=5.5 V",
        ),
        ("vdd = 1.8", "branch[0].vdd", "outside"),
        (
            "vdd = \"5V\"",
            "branch[0].vdd",
            "expected the supply in volts",
        ),
    ] {
        let e = parse_text(&pair(vdd, false)).unwrap_err();
        assert_eq!(e.field, field, "{e}");
        assert!(e.message.contains(says), "{says}: {e}");
        assert!(e.line > 0, "{e}");
    }
    let declared = pair("", false).replace("adc = \"ad7940\"", "adc = \"p\"\nvdd = 3.3")
        + "[[adc_part]]\nname = \"p\"\nbits = 12\nstart = \"cs\"\nleading_bits = 4\nsclk_max_hz = 20_000_000\nmax_sps = 1_000_000\n";
    let e = parse_text(&declared).unwrap_err();
    assert_eq!(e.field, "branch[1].vdd", "{e}");
    assert!(e.message.contains("leave vdd out"), "{e}");
}

#[test]
fn a_declared_part_says_where_it_samples() {
    let part = "[[adc_part]]\nname = \"p\"\nbits = 12\nstart = \"cs\"\nleading_bits = 4\nsclk_max_hz = 20_000_000\nmax_sps = 1_000_000\n";
    let text = |extra: &str, mux: &str| {
        pair("", false).replace(
            "adc = \"ad7940\"\nmux = \"tmux1108\"",
            &format!("adc = \"p\"\nmux = \"{mux}\""),
        ) + &format!("{part}{extra}\n")
    };
    let m = parse_text(&text("sample_after_rising = 3", "none")).unwrap();
    assert_eq!(m.branches[1].adc.sample, SampleAt::SclkFall(3));
    let t = m.branches[1].timing(m.clock_hz).unwrap();
    assert_eq!(t.sample_cycles, t.setup_cycles + 3 * t.sclk_div);
    for (extra, mux, field, says) in [
        (
            "sample_after_rising = 16",
            "none",
            "adc_part[0].sample_after_rising",
            "inside the word",
        ),
        (
            "sample_after_rising = 0",
            "none",
            "adc_part[0].sample_after_rising",
            "positive",
        ),
        (
            "sample_after_rising = 3",
            "tmux1108",
            "branch[1].mux",
            "external mux",
        ),
    ] {
        let e = parse_text(&text(extra, mux)).unwrap_err();
        assert_eq!(e.field, field, "{e}");
        assert!(e.message.contains(says), "{says}: {e}");
    }
    let cnv = text("sample_after_rising = 3", "none")
        .replace("start = \"cs\"", "start = \"cnv\"\nconversion_ns = 1_000");
    let e = parse_text(&cnv.replace("leading_bits = 4\n", "")).unwrap_err();
    assert_eq!(e.field, "adc_part[0].sample_after_rising", "{e}");
}

#[test]
fn an_overfull_branch_at_its_lowest_supply_is_offered_the_vdd_it_fits_at() {
    // 8 x 8 kHz = 64 kS/s: over the MCP3208's 50 kS/s at 2.7 V, within 5 V's
    let mut text = pair("", false);
    for i in 2..8 {
        text += &format!(
            "[[channel]]\nname = \"M{i}\"\nbranch = \"m\"\nrate_hz = 8_000\ninput = {i}\n"
        );
    }
    let text = text
        .replace("rate_hz = 2_000\ninput = 0", "rate_hz = 8_000\ninput = 0")
        .replace("rate_hz = 4_000\ninput = 1", "rate_hz = 8_000\ninput = 1");
    let m = parse_text(&text).unwrap();
    let why = lut_gen::synthesize(&m).unwrap_err();
    let found = lut_gen::search_fixes(Path::new("m.toml"), &text, &m, &why);
    let fix = found
        .fixes
        .iter()
        .find(|f| matches!(f.changes[0], lut_gen::Change::Supply { .. }))
        .expect("the supply offered");
    assert!(
        fix.says
            .contains("say `vdd = 5.0` on branch `m` if its mcp3208 runs at 5.0 V"),
        "{}",
        fix.says
    );
    assert!(fix.text.contains("vdd = 5.0"), "{}", fix.text);
    assert!(feasible(Path::new("m.toml"), &fix.text, CANDIDATE_BUDGET).is_some());
}
