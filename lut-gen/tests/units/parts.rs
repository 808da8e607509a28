use lut_gen::{volts, AdcPart, CmdBit, Command, SpiTiming};

#[test]
fn ad7940_at_48mhz() {
    let t = SpiTiming::derive(&AdcPart::ad7940(), 48_000_000, 2_500_000, 1).unwrap();
    assert_eq!(t.sclk_div, 20); // 2.4 MHz: 19.2 rounded up to even
    assert_eq!(t.setup_cycles, 1);
    assert_eq!(t.quiet_cycles, 3); // 50 ns = 2.4 cycles
    assert_eq!(t.read_cycles, 321);
    assert_eq!(t.min_period_cycles, 480); // the 100 kSPS limit dominates
    assert_eq!(t.captures().count(), 15);
}

#[test]
fn ad7685_chain_of_four_at_48mhz() {
    let p = AdcPart::ad7685();
    let t = SpiTiming::derive(&p, 48_000_000, p.sclk_max_hz, 4).unwrap();
    assert_eq!(t.sclk_div, 4); // 12 MHz
    assert_eq!(t.conv_cycles, 154); // 3.2 us = 153.6 cycles
    assert_eq!(t.setup_cycles, 155);
    assert_eq!(t.read_cycles, 155 + 64 * 4);
    assert_eq!(t.captures().count(), 64);
    assert_eq!(t.min_period_cycles, 412); // read + quiet: longer than 200 kSPS
                                          // so the chain gives 4 x 48 MHz / 412 samples/s, not 4 x 200 kSPS
    assert_eq!(t.max_samples_hz(48_000_000).floor(), 466_019.0);
}

#[test]
fn mcp3208_word_reads_b11_at_rising_edge_8() {
    let p = AdcPart::mcp3208();
    let t = SpiTiming::derive(&p, 48_000_000, p.sclk_max_hz, 1).unwrap();
    assert_eq!(t.sclk_div, 48); // 1 MHz
    assert_eq!(t.sclks(), 20);
    // B11 is serial bit 8, read at rising edge 8; B0 at edge 19.
    let caps: Vec<(u64, u64)> = t.captures().collect();
    assert_eq!(caps.first().unwrap().1, 1);
    assert_eq!(caps.last().unwrap().1, 19);
    let c = p.command.unwrap();
    assert_eq!(c.ahead, 0);
    assert_eq!(c.channels(), 8);
    // held at the falling SCLK after rising edge 6: setup (100 ns = 5
    // cycles) and six periods, 6.104 us after CS falls
    assert_eq!(t.sample_cycles, 5 + 6 * 48);
    let at5v = AdcPart::mcp3208().at_supply(Some(5_000));
    let t5 = SpiTiming::derive(&at5v, 48_000_000, at5v.sclk_max_hz, 1).unwrap();
    assert_eq!((t5.sclk_div, t5.sample_cycles), (24, 5 + 6 * 24));
    // Start, single-ended, then D2 D1 D0 = 1 0 1 for channel 5.
    assert_eq!(c.word(5), vec![true, true, true, false, true]);
}

#[test]
fn supplies_pick_the_datasheet_column_at_or_below_the_vdd() {
    let m = AdcPart::mcp3208();
    assert_eq!(m.sclk_max_hz, 1_000_000);
    assert_eq!(m.at_supply(None), m);
    assert_eq!(m.at_supply(Some(4_999)).sclk_max_hz, 1_000_000);
    let hi = m.at_supply(Some(5_000));
    assert_eq!((hi.sclk_max_hz, hi.max_sps), (2_000_000, 100_000));
    assert_eq!(m.vdd_range_mv(), Some((2_700, 5_500)));
    let a = AdcPart::ad7685().at_supply(Some(5_000));
    assert_eq!((a.max_sps, a.conversion_ns), (250_000, 2_200));
    for p in AdcPart::known() {
        let p = AdcPart::by_name(p).unwrap();
        // without a vdd, every built-in part is its lowest supply's
        assert_eq!(p.at_supply(None), p, "{}", p.name);
    }
    assert_eq!(volts(5_000), "5.0");
    assert_eq!(volts(2_700), "2.7");
    assert_eq!(volts(3_300), "3.3");
    assert_eq!(volts(2_750), "2.75");
}

#[test]
fn ad7689_cfg_word() {
    let c = AdcPart::ad7689().command.unwrap();
    assert_eq!(c.ahead, 2);
    assert_eq!(c.bits.len(), 14);
    assert_eq!(c.template(), "1111CCC1001001");
    let w: String = c
        .word(6)
        .iter()
        .map(|&b| if b { '1' } else { '0' })
        .collect();
    assert_eq!(w, "11111101001001");
}

#[test]
fn every_word_reads_back_as_its_channel() {
    for p in AdcPart::known() {
        let Some(c) = AdcPart::by_name(p).unwrap().command else {
            continue;
        };
        for ch in 0..c.channels() {
            assert_eq!(c.channel_of(&c.word(ch)), Some(ch), "{p} {ch}");
            let mut w = c.word(ch);
            // Flipping a fixed bit is not a channel; a channel bit is another one.
            for i in 0..w.len() {
                w[i] = !w[i];
                let got = c.channel_of(&w);
                match c.bits[i] {
                    CmdBit::Channel(k) => assert_eq!(got, Some(ch ^ (1 << k))),
                    _ => assert_eq!(got, None),
                }
                w[i] = !w[i];
            }
            assert_eq!(c.channel_of(&w[..w.len() - 1]), None);
        }
    }
}

#[test]
fn templates_are_checked() {
    assert!(Command::parse("1100", 0).is_err());
    assert!(Command::parse("11CCCCC", 0).is_err());
    assert!(Command::parse("1x CCC", 0).is_err());
    let c = Command::parse("1_0cc", 1).unwrap();
    assert_eq!(c.template(), "10CC");
    assert_eq!(c.word(2), vec![true, false, true, false]);
}

#[test]
fn slow_clock_is_rejected() {
    assert!(SpiTiming::derive(&AdcPart::ad7940(), 400_000, 250_000, 1).is_err());
}
