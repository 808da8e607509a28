use link::format::{crc, modes_fit, record, slice_field, split_slice_field, MAX_CHANNEL};

#[test]
fn crc_is_modbus() {
    // The standard check value of CRC-16/MODBUS.
    assert_eq!(crc(b"123456789"), 0x4B37);
}

#[test]
fn the_slice_field_carries_two_modes_above_the_slice() {
    assert_eq!(slice_field(9, 3, 1, 0), 9);
    for bits in 1..=7u32 {
        let top = (1u64 << (16 - 2 * bits)) - 1;
        for (slice, mode, prev) in [
            (0u64, 0u8, 0u8),
            (top, (1 << bits) - 1, 0),
            (5, 1, (1 << bits) - 1),
        ] {
            let slice = slice.min(top) as u16;
            let f = slice_field(slice, mode, prev, bits);
            assert_eq!(split_slice_field(f, bits), (slice, mode, prev), "{bits}");
        }
        assert!(modes_fit(top + 1, bits) && !modes_fit(top + 2, bits));
    }
    assert!(!modes_fit(1, 8));
}

#[test]
fn first_bytes_tell_words_apart() {
    assert!(record(MAX_CHANNEL, 0xFFFF)[0] < 4);
}
