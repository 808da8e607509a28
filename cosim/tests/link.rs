//! The link stage against the judge: the eskin34-uart preset runs clean on
//! the rust-hdl back end, and each fault built into the link's gateware
//! (a FIFO one token short, a wrong baud divider, a wrong CRC start) fails
//! the check on the link's pins, with the wrong bit's byte and packet named.

use judge::run::{run_dut, Dut, RunOptions};
use lut_gen::ports::Pins;
use lut_gen::Schedule;

struct Sim(hdl::RtlSim);

impl Dut for Sim {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        self.0.step(rst, miso)
    }
}

fn preset() -> Schedule {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../mixes/eskin34-uart.toml");
    lut_gen::synthesize(&lut_gen::load(std::path::Path::new(path)).unwrap()).unwrap()
}

#[test]
fn the_link_runs_clean_and_every_link_fault_is_caught() {
    let s = preset();
    let opts = RunOptions::default();
    let clean = run_dut(
        &s,
        &mut Sim(hdl::RtlSim::new(&s).unwrap()),
        1,
        &opts,
        "test",
        None,
    );
    assert!(clean.ok, "{}", clean.summary());
    let faults = hdl::GatewareFault::link_faults(&s);
    assert_eq!(faults.len(), 3);
    for (class, f) in faults {
        let mut dut = Sim(hdl::RtlSim::with_fault(&s, f).unwrap());
        let r = run_dut(&s, &mut dut, 1, &opts, "test", None);
        assert!(!r.ok, "{class}: not caught");
        let d = r
            .divergences
            .first()
            .unwrap_or_else(|| panic!("{class}: no divergence"));
        assert!(
            d.signal.starts_with("link_"),
            "{class}: first on {}",
            d.signal
        );
        if d.signal == "link_tx" {
            assert!(
                d.context.iter().any(|l| l.contains("of packet frame")),
                "{class}: {:?}",
                d.context
            );
        }
    }
}

#[path = "../../tests/common/tools.rs"]
mod tools;

/// The link in Icarus (the emitted Verilog's `slotforge_link`, its line read
/// back from Icarus's VCD); verilator and rusthdl run every preset in
/// `backends.rs`.  Icarus takes minutes per frame of this mix.
#[test]
#[ignore = "long: make test-long"]
fn the_link_runs_clean_in_icarus() {
    if !tools::require_tool("iverilog") {
        return;
    }
    let s = preset();
    let r = cosim::run(&s, cosim::Backend::Icarus, 1, &cosim::SimOptions::default()).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.samples, s.samples_per_frame() - s.startup_skips());
}
