use link::format::{self, header, record, trailer, END};
use link::{Decoded, Decoder, Stats};

fn packet(frame: u8, slice: u16, recs: &[(u16, u16)]) -> Vec<u8> {
    let mut p = header(frame, slice).to_vec();
    for &(c, v) in recs {
        p.extend(record(c, v));
    }
    p.extend([END, 0]);
    let c = format::crc(&p);
    p.extend(&trailer(0, c)[2..]);
    p
}

fn decode(bytes: &[u8]) -> (Vec<Decoded>, Stats) {
    let mut d = Decoder::new(10);
    let mut out = Vec::new();
    d.push(bytes, &mut out);
    (out, d.finish())
}

#[test]
fn clean_stream() {
    let mut s = packet(0, 0, &[(1, 0xA5A5), (2, 0x5A5A)]);
    s.extend(packet(0, 1, &[]));
    s.extend(packet(0, 2, &[(3, 7)]));
    let (out, st) = decode(&s);
    assert_eq!(out.len(), 3);
    assert_eq!(out[2].slice, 2);
    assert!(st.clean(), "{st:?}");
    assert_eq!(st.packets, 3);
}

#[test]
fn losses_are_counted_not_hidden() {
    let mut s = vec![0x13, 0xA5, 0x00, 0x99]; // mid-packet start: garbage
    s.extend(packet(255, 9, &[(1, 1)]));
    let mut bad = packet(0, 0, &[(2, 2)]);
    bad[6] ^= 0x40; // a flipped bit
    s.extend(bad);
    s.extend(packet(0, 2, &[(3, 3)])); // slice 1 lost
    let mut cut = packet(0, 3, &[(4, 4)]);
    cut.truncate(7);
    s.extend(cut);
    let (out, st) = decode(&s);
    assert_eq!(
        out.iter().map(|d| d.channel).collect::<Vec<_>>(),
        [1, 3],
        "{st:?}"
    );
    assert_eq!(out[1].frame, 256, "frame counter unwrapped");
    assert_eq!(st.crc_errors, 1);
    assert_eq!(st.lost_packets, 2);
    assert_eq!(st.in_flight, 7);
    assert!(st.resyncs >= 1 && st.skipped_bytes >= 4);
}

#[test]
fn a_stream_ending_inside_a_packet_is_clean_with_its_bytes_in_flight() {
    let mut s = packet(0, 0, &[(1, 1), (2, 2)]);
    s.extend(packet(0, 1, &[(3, 3)]));
    let whole = s.len();
    s.extend(packet(0, 2, &[(4, 4), (5, 5)]));
    for end in whole..s.len() {
        let (out, st) = decode(&s[..end]);
        assert_eq!(out.len(), 3, "{end}");
        assert!(st.clean(), "{end}: {st:?}");
        assert_eq!(st.in_flight as usize, end - whole, "{end}");
    }
    // a flipped byte in the middle is a loss, the end still in flight
    let mut bad = s[..s.len() - 1].to_vec();
    bad[9] ^= 0x01;
    let (_, st) = decode(&bad);
    assert!(!st.clean() && st.crc_errors == 1, "{st:?}");
    assert_eq!(st.in_flight as usize, s.len() - 1 - whole);
}

#[test]
fn packets_come_out_whole_empty_ones_too() {
    let mut s = packet(3, 9, &[(1, 0xA5A5)]);
    s.extend(packet(4, 0, &[]));
    let mut d = Decoder::new(10);
    let mut out = Vec::new();
    d.push_packets(&s, &mut out);
    assert_eq!(out.len(), 2);
    assert_eq!((out[0].frame, out[0].slice), (3, 9));
    assert_eq!(out[0].records, [(1, 0xA5A5)]);
    assert_eq!((out[1].frame, out[1].slice), (4, 0));
    assert!(out[1].records.is_empty());
}

#[test]
fn a_mode_mixs_headers_give_the_modes_and_the_slice() {
    let mut s = Vec::new();
    for (frame, slice, mode, prev) in [
        (0u8, 2u16, 0u8, 0u8),
        (1, 0, 2, 0),
        (1, 1, 2, 0),
        (1, 2, 2, 0),
        (2, 0, 1, 2),
    ] {
        let mut p = packet(frame, format::slice_field(slice, mode, prev, 2), &[(1, 9)]);
        // the CRC covers the header as sent
        let n = p.len();
        let c = format::crc(&p[..n - 2]);
        p[n - 2..].copy_from_slice(&c.to_le_bytes());
        s.extend(p);
    }
    let mut d = Decoder::with_modes(3, 2);
    let mut out = Vec::new();
    d.push_packets(&s, &mut out);
    let got: Vec<(u64, u16, u8, u8)> = out
        .iter()
        .map(|p| (p.frame, p.slice, p.mode, p.prev_mode))
        .collect();
    assert_eq!(
        got,
        [
            (0, 2, 0, 0),
            (1, 0, 2, 0),
            (1, 1, 2, 0),
            (1, 2, 2, 0),
            (2, 0, 1, 2)
        ]
    );
    assert!(d.finish().clean());
    // without the mode bits the same headers name slices out of range
    let mut plain = Decoder::new(3);
    plain.push_packets(&s, &mut Vec::new());
    assert!(!plain.finish().clean());
}

#[test]
fn any_garbage_never_panics() {
    let mut x: u32 = 12345;
    let junk: Vec<u8> = (0..20_000)
        .map(|_| {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
            (x >> 16) as u8
        })
        .collect();
    let (_, st) = decode(&junk);
    assert_eq!(st.bytes, 20_000);
}
