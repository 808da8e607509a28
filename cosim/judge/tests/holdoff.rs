//! Pin faults on a branch a sync group holds back: each fault lands on the
//! branch's real conversion (its CS fall, SCLK, words and mux switch come
//! the hold-off after the slot tick), so the model and the model-free
//! invariants both catch it.

use judge::{FaultyDut, ModelDut, PinFault};
use lut_gen::Schedule;

/// testkit's cmd-mcp3208 with its MCP3208's M2 and E0 of branch `ext` (an
/// AD7940 behind a TMUX1108, or an AD7689) in one sync group: `ext` starts
/// its transactions 6.1 us after the slot tick, where the MCP3208 holds.
fn grouped(ext: &str) -> Schedule {
    let text = std::fs::read_to_string(testkit::mix("cmd-mcp3208")).unwrap();
    let text = text
        .replace(
            "rate_hz = 2_000\ninput = 2\n",
            "rate_hz = 2_000\ninput = 2\nsync = \"s\"\n",
        )
        .replace(
            "rate_hz = 2_000\ninput = 0\n",
            "rate_hz = 2_000\ninput = 0\nsync = \"s\"\n",
        )
        .replace(
            "adc = \"ad7940\"\nmux = \"tmux1108\"\nsettle_ns = 1_000",
            ext,
        );
    let mix = lut_gen::parse(std::path::Path::new("grouped.toml"), &text).unwrap();
    lut_gen::synthesize(&mix).unwrap()
}

fn judged(s: &Schedule, f: PinFault, at: u64, model: bool) -> (bool, judge::Verdict) {
    let opts = judge::RunOptions {
        check: judge::CheckOptions {
            model,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut dut = FaultyDut::new(s, ModelDut::new(s), f, at);
    let v = judge::run_dut(s, &mut dut, 3, &opts, "faulty", None);
    (dut.injected(), v)
}

#[test]
fn every_pin_fault_of_a_held_off_branch_is_injected_and_caught() {
    for ext in [
        "adc = \"ad7940\"\nmux = \"tmux1108\"\nsettle_ns = 1_000",
        "adc = \"ad7689\"\nmux = \"internal\"",
    ] {
        let s = grouped(ext);
        let held = (0..s.branches.len()).find(|&b| s.holdoff(b) > 0);
        let b = held.unwrap_or_else(|| panic!("{ext}: no branch is held off"));
        let at = s.grid.frame_cycles / 3 + 11;
        let faults: Vec<PinFault> = PinFault::all(&s)
            .into_iter()
            .filter(|f| f.branch() == Some(b))
            .collect();
        assert!(faults.len() >= 6, "{ext}: {faults:?}");
        for f in faults {
            let (injected, v) = judged(&s, f, at, true);
            assert!(injected, "{ext}: {f:?} was not injected");
            assert!(!v.ok, "{ext}: {f:?} missed by the model");
            // the branch does nothing between its slot tick and its
            // hold-off's end: a fault there is not the fault named
            let first = v.divergences[0].cycle;
            assert!(
                first % s.grid.slot_cycles >= s.holdoff(b),
                "{ext}: {f:?} first differs at cycle {first}, inside the hold-off"
            );
            let (_, v) = judged(&s, f, at, false);
            // a mux switching two cycles early only breaks an invariant
            // when the mux settles for longer (as on an unheld branch)
            let visible = match f {
                PinFault::MuxLate { .. } => s.branches[b].settle_cycles > 2,
                _ => true,
            };
            assert!(
                !visible || !v.ok,
                "{ext}: {f:?} missed by the invariants\n{}",
                v.summary()
            );
        }
    }
}
