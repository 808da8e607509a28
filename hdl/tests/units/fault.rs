use hdl::GatewareFault;

/// Campaign reports name faults in words, not as Rust's Debug form.
#[test]
fn faults_are_named_in_words() {
    let f = GatewareFault::RomWord {
        branch: 1,
        slot: 7,
        from: 3,
    };
    assert_eq!(
        f.to_string(),
        "branch 1's ROM word for slot 7 holds slot 3's"
    );
    assert_eq!(
        GatewareFault::SlotWrap { delta: -1 }.to_string(),
        "slot counter wraps -1 slots off the frame"
    );
    for f in [
        GatewareFault::RomSwap {
            branch: 0,
            a: 1,
            b: 2,
        },
        GatewareFault::SliceWrap { delta: 1 },
        GatewareFault::LinkFifoShort,
        GatewareFault::LinkBaud { delta: -1 },
        GatewareFault::LinkCrcInit,
        GatewareFault::ModeStuck,
    ] {
        let t = f.to_string();
        assert!(!t.contains('{') && !t.contains("Link"), "{t}");
    }
}
