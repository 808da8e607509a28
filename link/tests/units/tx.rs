use link::for_tests::header_state;
use link::format::{self, WordKind, END};
use link::Parity;
use link::{
    steady_state, AxisFormat, HeaderOnLine, Line, ReadyDriver, ReadyPattern, Tlast, Token,
    TxConfig, TxModel, UartFormat,
};

fn cfg(div: u32, depth: Option<usize>) -> TxConfig {
    TxConfig {
        line: Line::Uart(UartFormat {
            div,
            parity: Parity::None,
            stop_bits: 1,
        }),
        slice_cycles: 1000,
        slices_per_frame: 2,
        depth,
        mode_bits: 0,
    }
}

/// Sample the model's line at mid-bit and collect the bytes.
fn run(t: &mut TxModel, cycles: u64, samples: &[(u64, u16, u16)]) -> Vec<u8> {
    let Line::Uart(u) = t.config().line else {
        panic!("a UART")
    };
    let mut rx = link::UartRx::new(u);
    let mut out = Vec::new();
    t.clock(true, None);
    for c in 0..cycles {
        if let Some(b) = rx.sample(t.line()) {
            out.push(b.byte);
        }
        let s = samples.iter().find(|s| s.0 == c).map(|&(_, ch, v)| (ch, v));
        t.clock(false, s);
    }
    out
}

#[test]
fn packets_on_the_line_match_the_format() {
    let mut t = TxModel::new(cfg(4, Some(8)));
    let bytes = run(&mut t, 2500, &[(10, 3, 0x1234), (11, 1000, 0x3FFF)]);
    let mut want = Vec::new();
    let mut p = format::header(0, 0).to_vec();
    p.extend(format::record(3, 0x1234));
    p.extend(format::record(1000, 0x3FFF));
    p.extend([END, 0]);
    let c = format::crc(&p);
    want.extend(&p);
    want.extend([c as u8, (c >> 8) as u8]);
    let mut p2 = format::header(0, 1).to_vec();
    p2.extend([END, 0]);
    let c2 = format::crc(&p2);
    want.extend(&p2);
    want.extend([c2 as u8, (c2 >> 8) as u8]);
    want.extend(format::header(1, 0));
    assert_eq!(bytes, want);
    assert!(!t.overflow());
}

/// The bytes an AXIS slave driven by `pattern` takes, and `tlast`'s beats.
fn run_axis(pattern: ReadyPattern, tlast: Tlast, cycles: u64) -> (Vec<u8>, Vec<usize>) {
    let axis = AxisFormat {
        tlast,
        ready_within: 4,
    };
    let mut t = TxModel::new(TxConfig {
        line: Line::Axis(axis),
        ..cfg(4, Some(16))
    });
    let mut d = ReadyDriver::new(pattern, axis.ready_within);
    let (mut out, mut lasts) = (Vec::new(), Vec::new());
    let mut held: Option<(u8, bool)> = None;
    t.clock(true, None);
    for c in 0..cycles {
        let r = d.ready(t.tvalid());
        if let Some(h) = held {
            assert!(t.tvalid(), "cycle {c}: tvalid dropped under back-pressure");
            assert_eq!(
                h,
                (t.tdata(), t.tlast()),
                "cycle {c}: data changed while stalled"
            );
        }
        held = (t.tvalid() && !r).then_some((t.tdata(), t.tlast()));
        if t.tvalid() && r {
            out.push(t.tdata());
            if t.tlast() {
                lasts.push(out.len() - 1);
            }
        }
        t.set_tready(r);
        let s = [(10, 3, 0x1234), (11, 1000, 0x3FFF)]
            .iter()
            .find(|s| s.0 == c)
            .map(|&(_, ch, v)| (ch, v));
        t.clock(false, s);
    }
    assert!(!t.overflow());
    (out, lasts)
}

#[test]
fn axis_carries_the_uart_bytes_under_any_ready_pattern() {
    let mut u = TxModel::new(cfg(4, Some(8)));
    let uart = run(&mut u, 4100, &[(10, 3, 0x1234), (11, 1000, 0x3FFF)]);
    let (always, lasts) = run_axis(ReadyPattern::Always, Tlast::Slice, 4100);
    // the UART is slower: its bytes so far are a prefix of the stream
    assert!(always.starts_with(&uart) && always.len() > uart.len());
    let (rand, _) = run_axis(ReadyPattern::Random { seed: 3 }, Tlast::Slice, 4100);
    let (worst, _) = run_axis(ReadyPattern::WorstCase, Tlast::Slice, 4100);
    assert_eq!(rand, always);
    assert_eq!(worst, always);
    let uart = always;
    // tlast on every trailer's last byte: the packets of slices 0..3
    // (slices of 1000 cycles, 2 per frame; the fifth is still open)
    let trailers: Vec<usize> = (0..uart.len())
        .filter(|&i| i >= 3 && uart[i - 3] == END && i % 4 == 3)
        .collect();
    assert_eq!(lasts, trailers);
    assert_eq!(lasts.len(), 4);
    let (_, frame_lasts) = run_axis(ReadyPattern::Always, Tlast::Frame, 4100);
    assert_eq!(
        frame_lasts,
        vec![trailers[1], trailers[3]],
        "only a frame's last slice"
    );
}

#[test]
fn a_full_fifo_counts_and_flags_the_overflow() {
    // 6 samples in 6 cycles against a FIFO of 2 (the boundary token sits
    // in it too): overflow, never silent.
    let samples: Vec<_> = (1..7).map(|c| (c, c as u16, 0)).collect();
    let mut t = TxModel::new(cfg(4, Some(2)));
    let bytes = run(&mut t, 1100, &samples);
    assert!(t.overflow());
    let trailer = bytes.iter().position(|&b| b == END).expect("a trailer");
    assert!(
        bytes[trailer + 1] > 0,
        "the trailer carries the overflow count"
    );
}

/// A transmitter rebuilt from each header on the line (what a check
/// joining mid-run sees) drives the same pins as the one that ran from
/// reset, from that cycle on, on a UART and on AXIS under back-pressure,
/// with and without modes switching between frames.
#[test]
fn a_transmitter_rebuilt_at_a_header_drives_the_same_pins() {
    let axis = Line::Axis(AxisFormat {
        tlast: Tlast::Frame,
        ready_within: 4,
    });
    let lines = [cfg(4, Some(64)).line, axis];
    for (line, mode_bits) in lines.into_iter().flat_map(|l| [(l, 0), (l, 2)]) {
        let cfg = TxConfig {
            line,
            mode_bits,
            ..cfg(4, Some(64))
        };
        // frames of 2000 cycles; with modes, a new mode most frames
        let mode = |c: u64| {
            if mode_bits == 0 {
                0
            } else {
                (c / 2000 * 5 % 3) as u8
            }
        };
        let sample = |c: u64| (c % 1000 < 300 && c % 97 == 5).then_some((c as u16 % 7, c as u16));
        let mut t = TxModel::new(cfg);
        t.clock(false, None);
        let mut slave = ReadyDriver::new(ReadyPattern::Random { seed: 9 }, 4);
        let mut rebuilt: Vec<TxModel> = Vec::new();
        let mut tokens: Vec<(u64, Token)> = Vec::new();
        for c in 0..7000u64 {
            if let Some((b, 0)) = t.on_line() {
                if b.kind == WordKind::Header && b.index == 0 && b.loaded_at == c {
                    let at = (b.packet.0 as u64 * 2 + b.packet.1 as u64) * 1000;
                    let (mode, prev_mode, overflows, overflow_flag) = header_state(&t);
                    let h = HeaderOnLine {
                        first: c,
                        frame: b.packet.0,
                        slice: b.packet.1,
                        mode,
                        prev_mode,
                        overflows,
                        overflow_flag,
                        boundary_sample: sample(at),
                        queued: tokens.iter().filter(|k| k.0 > at).map(|k| k.1).collect(),
                    };
                    rebuilt.push(TxModel::at_header(cfg, &h));
                }
            }
            let r = slave.ready(t.tvalid());
            for m in std::iter::once(&mut t).chain(rebuilt.iter_mut()) {
                m.set_tready(r);
            }
            for (i, m) in rebuilt.iter().enumerate() {
                let pins = |m: &TxModel| (m.line(), m.tvalid(), m.tdata(), m.tlast(), m.overflow());
                assert_eq!(pins(m), pins(&t), "cycle {c}: header {i}");
                assert_eq!(m.on_line(), t.on_line(), "cycle {c}: header {i}");
            }
            let tok = Token {
                boundary: c % 1000 == 0,
                sample: sample(c),
                mode: mode(c),
            };
            if tok.boundary || tok.sample.is_some() {
                tokens.push((c, tok));
            }
            for m in std::iter::once(&mut t).chain(rebuilt.iter_mut()) {
                m.set_mode(mode(c));
                m.clock(false, sample(c));
            }
        }
        assert!(rebuilt.len() >= 6, "{line:?}: {} headers", rebuilt.len());
    }
}

#[test]
fn measure_finds_the_backlog_of_a_burst() {
    // Three samples in a row on an idle line: the first is popped the
    // cycle after its push, the other two wait behind it.
    let frame = [(500, 400, 0), (501, 400, 1), (502, 400, 2)];
    let m = steady_state(cfg(4, None), &frame, 16).expect("drains");
    assert_eq!(m.backlog, 2);
    assert!(m.latency_cycles > 0);
}
