//! rust-hdl's stock threaded `Simulation` and `RtlSim` run the same core
//! and must produce the same waveform, cycle for cycle; and one branch's
//! SPI master in rust-hdl's simulator against a model ADC (`spi_bench`).
mod common;

#[path = "spi_bench.rs"]
mod spi_bench;

use common::*;
use hdl::{rtlsim_cycles, stock_simulation_cycles, StockRun};

fn same_waveform(name: &str, s: &lut_gen::Schedule, cycles: u64, min_samples: u64) {
    let stock: StockRun = stock_simulation_cycles(s, cycles).expect("stock simulation runs");
    let fast: StockRun = rtlsim_cycles(s, cycles).expect("RtlSim runs");
    assert_eq!(stock.cycles, cycles);
    assert_eq!(fast.cycles, cycles);
    assert_eq!(stock.reset_pins, fast.reset_pins, "{name}: reset cycle");
    // first difference, if any, reported by cycle
    for (a, b) in stock.changes.iter().zip(&fast.changes) {
        assert_eq!(a, b, "{name}: stock Simulation vs RtlSim");
    }
    assert_eq!(
        stock.changes.len(),
        fast.changes.len(),
        "{name}: number of changes"
    );
    assert_eq!(stock.samples, fast.samples);
    // the stimulus exercises the design: CS and SCLK move, samples appear
    let cs_edges = stock
        .changes
        .windows(2)
        .filter(|w| w[0].1.cs_n != w[1].1.cs_n)
        .count();
    assert!(cs_edges >= 2, "{name}: {cs_edges} CS edges");
    assert!(
        stock.samples >= min_samples,
        "{name}: {} samples in {cycles} cycles",
        stock.samples
    );
    eprintln!(
        "{name}: {cycles} cycles, {} changes, {} samples; stock {:.0} cycles/s, RtlSim {:.0} cycles/s",
        stock.changes.len(),
        stock.samples,
        stock.cycles_per_second(),
        fast.cycles_per_second()
    );
}

#[test]
fn stock_simulation_matches_rtlsim_tiny() {
    // one conversion per 12 000-cycle frame: two frames' worth of instants
    same_waveform("tiny", &tiny(), 13_000, 2);
}

#[test]
fn stock_simulation_matches_rtlsim_wide() {
    same_waveform("wide8", &wide(), 8_000, 8);
}
