use link::Parity;
use link::{UartFormat, UartRx};

#[test]
fn reads_back_what_the_format_sends() {
    let f = UartFormat {
        div: 5,
        parity: Parity::Odd,
        stop_bits: 2,
    };
    let mut rx = UartRx::new(f);
    let mut got = Vec::new();
    for _ in 0..7 {
        rx.sample(true);
    }
    for byte in [0x00u8, 0xA5, 0xFF] {
        for i in 0..f.bits() {
            for _ in 0..f.div {
                if let Some(b) = rx.sample(f.bit(byte, i)) {
                    got.push((b.byte, b.error));
                }
            }
        }
    }
    assert_eq!(got, [(0x00, false), (0xA5, false), (0xFF, false)]);
}
