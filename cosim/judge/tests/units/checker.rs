use judge::for_tests::{same, History};
use judge::Pins;

/// No bit unknown (the checker's `NO_XZ`).
const NO_XZ: Pins = Pins::LOW;

/// `same` agrees with `==` for a change of every field (`NO_XZ` names
/// every field: a new one fails to compile until it is given a value
/// there, beside `same`).
#[test]
fn same_sees_every_field() {
    let a = NO_XZ;
    let changes: [fn(&mut Pins); 13] = [
        |p| p.cs_n = 1 << 15,
        |p| p.sclk = 1 << 15,
        |p| p.mux_sel = 1 << 63,
        |p| p.mux_en = 1 << 127,
        |p| p.sample_valid = true,
        |p| p.sample_channel = 1 << 15,
        |p| p.sample_value = 1 << 15,
        |p| p.link_tx = true,
        |p| p.link_overflow = true,
        |p| p.axis_tdata = 1 << 7,
        |p| p.axis_tvalid = true,
        |p| p.axis_tlast = true,
        |p| p.axis_tready = true,
    ];
    assert!(same(&a, &a));
    for (i, f) in changes.iter().enumerate() {
        let mut b = a;
        f(&mut b);
        assert!(a != b && !same(&a, &b) && !same(&b, &a), "field {i}");
    }
}

#[test]
fn history_keeps_the_last_four_oldest_first() {
    let mut h = History::default();
    for c in 0..6u64 {
        h.push((c, Pins::default(), None));
    }
    let got: Vec<u64> = h.iter().map(|e| e.0).collect();
    assert_eq!(got, [2, 3, 4, 5]);
}
