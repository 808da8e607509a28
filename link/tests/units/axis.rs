use link::{ReadyDriver, ReadyPattern};

#[test]
fn worst_case_accepts_each_beat_in_its_last_allowed_cycle() {
    let mut d = ReadyDriver::new(ReadyPattern::WorstCase, 4);
    let r: Vec<bool> = (0..8).map(|_| d.ready(true)).collect();
    assert_eq!(
        r,
        [false, false, false, true, false, false, false, true],
        "one beat per 4 cycles"
    );
}

#[test]
fn random_stays_within_the_guarantee_and_is_deterministic() {
    let run = |seed| {
        let mut d = ReadyDriver::new(ReadyPattern::Random { seed }, 3);
        (0..2000).map(|_| d.ready(true)).collect::<Vec<bool>>()
    };
    let a = run(7);
    assert_eq!(a, run(7));
    assert_ne!(a, run(8));
    let mut lows = 0;
    for &r in &a {
        lows = if r { 0 } else { lows + 1 };
        assert!(lows < 3, "a beat waited 3 cycles");
    }
    let ones = a.iter().filter(|&&r| r).count();
    assert!(ones > 1000 && ones < 1900, "{ones}");
}

#[test]
fn patterns_parse() {
    assert_eq!(
        ReadyPattern::parse("random:5"),
        Some(ReadyPattern::Random { seed: 5 })
    );
    assert_eq!(ReadyPattern::parse("random:0"), None);
    for p in ["always", "worst", "random:9"] {
        assert_eq!(ReadyPattern::parse(p).unwrap().name(), p);
    }
}
