use judge::for_tests::write_atomic;
use judge::{Observer, Pins, SampleLog};

#[test]
fn cycle_zero_follows_the_last_reset_cycle() {
    let mut log = SampleLog::new();
    let idle = Pins::default();
    let valid = Pins {
        sample_valid: true,
        sample_channel: 1,
        sample_value: 7,
        ..Pins::default()
    };
    for (rst, p) in [
        (true, valid),
        (false, valid),
        (true, idle),
        (true, idle),
        (false, idle),
        (false, valid),
    ] {
        Observer::cycle(&mut log, 0, rst, &p, 0);
    }
    let got: Vec<_> = log
        .samples
        .iter()
        .map(|s| (s.cycle, s.channel, s.value))
        .collect();
    assert_eq!(got, [(1, 1, 7)]);
}

#[test]
fn atomic_write_replaces_only_the_target() {
    let dir = std::env::temp_dir().join(format!("slotforge-samples-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("s.csv");
    write_atomic(&p, b"one\n").unwrap();
    write_atomic(&p, b"two\n").unwrap();
    assert_eq!(std::fs::read_to_string(&p).unwrap(), "two\n");
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
    assert!(write_atomic(&dir, b"x").is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}
