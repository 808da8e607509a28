use lut_gen::plan_link as plan;
use lut_gen::{merged_frame, PacketInstants, Schedule};

fn eskin(baud: u64) -> Schedule {
    let text = include_str!("../../../mixes/eskin34.toml").to_string()
        + &format!("\n[link]\nkind = \"uart\"\nbaud = {baud}\n");
    let m = lut_gen::parse(std::path::Path::new("t.toml"), &text).unwrap();
    lut_gen::synthesize(&m).unwrap()
}

#[test]
fn eskin34_words_are_the_papers_369() {
    let s = eskin(3_000_000);
    let p = plan(&s).unwrap().unwrap();
    assert_eq!(p.words_per_frame, 369);
    assert_eq!(p.bytes_per_frame, 1476);
    assert_eq!(p.baud_divider, 16);
    // 1476 bytes x 10 bits x 16 cycles of a 480,000-cycle frame
    assert!((p.utilization - 0.492).abs() < 1e-9, "{}", p.utilization);
    assert!(p.fifo_depth >= 1 && p.fifo_depth < 32, "{}", p.fifo_depth);
    // 1476 x 10 = 14,760 bits in 10 ms: 1,476,000 baud at the least,
    // and 48 MHz / 32 = 1.5 Mbaud is the slowest divider that carries it.
    assert_eq!(p.min_baud, 1_500_000.0);
}

#[test]
fn a_slow_line_is_refused_with_the_minimum_baud() {
    let s = eskin(1_000_000);
    let e = plan(&s).unwrap().unwrap_err();
    assert_eq!(e.min_baud, Some(1_500_000.0));
    assert!(e.message.contains("1500000"), "{}", e.message);
}

fn eskin_axis(keys: &str) -> Schedule {
    let text = include_str!("../../../mixes/eskin34.toml").to_string()
        + &format!("\n[link]\nkind = \"axis\"\n{keys}\n");
    let m = lut_gen::parse(std::path::Path::new("t.toml"), &text).unwrap();
    lut_gen::synthesize(&m).unwrap()
}

#[test]
fn axis_depth_grows_with_the_slaves_guarantee() {
    let fast = plan(&eskin_axis("")).unwrap().unwrap();
    assert_eq!(fast.bytes_per_frame, 1476);
    assert_eq!(fast.ready_within, Some(1));
    let slow = plan(&eskin_axis("ready_within = 200")).unwrap().unwrap();
    assert!(
        slow.fifo_depth > fast.fifo_depth,
        "{} vs {}",
        slow.fifo_depth,
        fast.fifo_depth
    );
    assert!((slow.utilization - 1476.0 * 200.0 / 480_000.0).abs() < 1e-9);
    // 1476 bytes in 480,000 cycles: at most 325 cycles per byte
    let max = fast.max_ready_within.unwrap();
    assert!(max <= 325 && max > 200, "{max}");
    assert_eq!(fast.max_ready_within, slow.max_ready_within);
}

#[test]
fn axis_with_too_slow_a_slave_is_refused_with_the_guarantee_it_needs() {
    let e = plan(&eskin_axis("ready_within = 400"))
        .unwrap()
        .unwrap_err();
    assert!(e.message.contains("accepted within"), "{}", e.message);
    assert!(e.message.contains("ready_within"), "{}", e.message);
}

#[test]
fn packet_times_are_the_sampling_instants() {
    let s = eskin(3_000_000);
    let pi = PacketInstants::new(&s);
    // slice 0 of frame 1 carries CH35 (channel 34) sampled at cycle 0 of the slice
    let ch35 = s.mix.channel_index("CH35").unwrap() as u16;
    let t = pi.cycles(1, 0, &[ch35, ch35]);
    let first = s.first_sample_cycle(ch35 as usize) + s.grid.frame_cycles;
    assert_eq!(t[0], Some(first));
    // one record only (the first skipped at start-up): the later instant
    let t1 = pi.cycles(1, 0, &[ch35]);
    assert_eq!(t1[0], t[1]);
    assert!(pi.cycles(1, 0, &[ch35, ch35, ch35])[0].is_none());
}

/// The strobe-to-instant rule of `Schedule::sampled_at`, against the
/// merged stream computed here from the completions: every strobe of
/// a steady frame maps back to its own instant.
#[test]
fn every_strobe_maps_back_to_its_instant() {
    for text in [
        include_str!("../../../mixes/eskin34.toml"),
        include_str!("../../../mixes/eskin34-axis.toml"),
        include_str!("../../../mixes/vibrotactile8k.toml"),
        include_str!("../../../mixes/induction5k-adc12.toml"),
        include_str!("../../../mixes/softslip1k.toml"),
    ] {
        let m = lut_gen::parse(std::path::Path::new("t.toml"), text).unwrap();
        let s = lut_gen::synthesize(&m).unwrap();
        let f = s.grid.frame_cycles;
        let stream = merged_frame(&s);
        assert!(!stream.is_empty());
        for (v, i, ch) in stream {
            let held = s.sample_after(s.mix.channels[ch as usize].branch);
            assert_eq!(
                s.sampled_at(ch as usize, v + f),
                Some(i + f + held),
                "{}",
                m.name
            );
        }
    }
}

#[test]
fn the_merged_stream_has_every_sample_of_a_frame() {
    let s = eskin(3_000_000);
    let m = merged_frame(&s);
    assert_eq!(m.len() as u64, s.samples_per_frame());
    assert!(
        m.windows(2).all(|w| w[0].0 < w[1].0),
        "one sample per cycle"
    );
    assert!(m.iter().all(|&(v, i, _)| v > i));
}
