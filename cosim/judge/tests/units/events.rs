use judge::compare_events as compare;
use judge::for_tests::{time_us, Event};
use judge::EventLog;

fn ev(cycle: u64, scope: &str, signal: &str, value: &str) -> Event {
    Event {
        cycle,
        scope: scope.into(),
        signal: signal.into(),
        value: value.into(),
        note: String::new(),
    }
}

#[test]
fn compare_finds_changed_missing_and_extra_events() {
    let a = EventLog {
        events: vec![
            ev(0, "b", "cs_n", "1"),
            ev(5, "b", "cs_n", "0"),
            ev(9, "sample", "CH1", "0x0001"),
        ],
        cycles: 10,
    };
    assert!(compare(&a, &a, 3).same());
    let mut b = a.clone();
    b.events[1].value = "1".into();
    b.events.remove(2);
    b.events.push(ev(7, "b", "sclk", "0"));
    let c = compare(&a, &b, 5);
    assert_eq!(c.count, 3);
    assert_eq!(c.first[0].cycle, 5);
    assert_eq!(c.first[0].expected.as_deref(), Some("0"));
    assert_eq!(c.first[0].actual.as_deref(), Some("1"));
    assert_eq!(c.first[1].expected, None);
    assert_eq!(c.first[2].actual, None);
    let short = EventLog {
        cycles: 9,
        ..a.clone()
    };
    assert!(!compare(&a, &short, 1).same());
}

#[test]
fn time_is_exact() {
    assert_eq!(time_us(48_000_000, 48_000), "1000.000000us");
    assert_eq!(time_us(48_000_000, 1), "0.020833us");
}
