use lut_gen::seconds;

#[test]
fn seconds_are_rounded_once_to_a_picosecond() {
    assert_eq!(seconds(0, 48_000_000), "0.000000000000");
    // 1 / 48 MHz = 20.8333.. ns
    assert_eq!(seconds(1, 48_000_000), "0.000000020833");
    assert_eq!(seconds(2, 48_000_000), "0.000000041667");
    assert_eq!(seconds(48_000_000, 48_000_000), "1.000000000000");
    assert_eq!(seconds(480_000 * 1000 + 24, 48_000_000), "10.000000500000");
    assert_eq!(seconds(u64::MAX, 1), format!("{}.000000000000", u64::MAX));
}
