use judge::{LinkBytes, Observer, Pins};
use lut_gen::Schedule;

fn schedule(link: &str) -> Schedule {
    let text = include_str!("../../../../mixes/eskin34.toml").to_string() + link;
    let m = lut_gen::parse(std::path::Path::new("t.toml"), &text).unwrap();
    lut_gen::synthesize(&m).unwrap()
}

fn feed(b: &mut LinkBytes, rst: bool, p: Pins) {
    Observer::cycle(b, 0, rst, &p, 0);
}

#[test]
fn a_uart_line_gives_its_characters_and_a_reset_starts_again() {
    let s = schedule("\n[link]\nkind = \"uart\"\nbaud = 3_000_000\n");
    let mut b = LinkBytes::new(&s).unwrap();
    // the format the collector reads with: the mix's planned link
    let plan = lut_gen::plan_link(&s).unwrap().unwrap();
    let fmt = plan.uart().expect("a UART");
    let idle = Pins {
        link_tx: true,
        ..Pins::default()
    };
    let send = |b: &mut LinkBytes, byte: u8| {
        for i in 0..fmt.bits() {
            for _ in 0..fmt.div {
                let level = fmt.bit(byte, i);
                feed(
                    b,
                    false,
                    Pins {
                        link_tx: level,
                        ..Pins::default()
                    },
                );
            }
        }
    };
    feed(&mut b, true, idle);
    feed(&mut b, false, idle);
    send(&mut b, 0x5A);
    send(&mut b, 0xA5);
    assert_eq!(b.bytes, [0x5A, 0xA5]);
    assert_eq!(b.framing_errors, 0);
    feed(&mut b, true, idle);
    assert!(b.bytes.is_empty());
    // half a character is not a byte yet
    feed(&mut b, false, idle);
    for _ in 0..fmt.div * 3 {
        feed(&mut b, false, Pins::default());
    }
    assert!(b.bytes.is_empty());
}

#[test]
fn axis_beats_count_only_when_accepted() {
    let s = schedule("\n[link]\nkind = \"axis\"\n");
    let mut b = LinkBytes::new(&s).unwrap();
    let beat = |tdata, tvalid, tready| Pins {
        axis_tdata: tdata,
        axis_tvalid: tvalid,
        axis_tready: tready,
        ..Pins::default()
    };
    for (d, v, r) in [
        (1, true, true),
        (2, true, false),
        (2, true, true),
        (3, false, true),
    ] {
        feed(&mut b, false, beat(d, v, r));
    }
    assert_eq!(b.bytes, [1, 2]);
    assert!(LinkBytes::new(&schedule("")).is_none(), "no link, no bytes");
}
