use link::{Parity, UartFormat};

#[test]
fn eight_n_one() {
    let f = UartFormat {
        div: 16,
        parity: Parity::None,
        stop_bits: 1,
    };
    assert_eq!(f.bits(), 10);
    let bits: Vec<bool> = (0..10).map(|i| f.bit(0x01, i)).collect();
    assert_eq!(
        bits,
        [false, true, false, false, false, false, false, false, false, true]
    );
    let p = UartFormat {
        parity: Parity::Even,
        stop_bits: 2,
        ..f
    };
    assert_eq!(p.bits(), 12);
    assert!(p.bit(0x01, 9), "even parity of one 1 bit is 1");
    assert!(!p.bit(0x03, 9));
    assert_eq!(UartFormat::divider(48_000_000, 3_000_000), 16);
}
