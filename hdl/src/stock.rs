//! The same gateware under rust-hdl's stock threaded `Simulation` engine, as
//! a reference point for [`crate::RtlSim`]'s direct clock loop.
//!
//! `Simulation` runs every clock and testbench in its own thread and hands
//! the whole circuit (a `Box<Core>`) from thread to thread over rendezvous
//! channels at every event; it also runs rust-hdl's design checks
//! (`check_all`: open signals, logic loops, writes to inputs) before the run.
//! The testbench here is the literal equivalent of calling
//! [`crate::RtlSim::step`] once per cycle: set `rst`/`adc_miso`, wait for the
//! clock to go low and then high, read the outputs.

use std::sync::{Arc, Mutex};
use std::time::Instant;

use crate::rhdl::*;

use crate::core::Core;
use crate::sim::{read_pins, PinReader};
use lut_gen::Pins;

use crate::{plan, HdlError};

/// Result of one run of the gateware for a number of cycles (after one reset
/// cycle) with the [`pattern_miso`] stimulus.
#[derive(Debug, Clone, Default)]
pub struct StockRun {
    /// Cycles simulated after reset (cycle 0 is the first with `rst` low).
    pub cycles: u64,
    /// Wall time of the whole run, including the engine's thread start-up
    /// and design checks, in seconds.
    pub seconds: f64,
    /// Pins in the reset cycle.
    pub reset_pins: Pins,
    /// `(cycle, pins)` for cycle 0 and every cycle whose pins differ from
    /// the previous cycle's: the complete output waveform, compactly.
    pub changes: Vec<(u64, Pins)>,
    /// Cycles with `sample_valid` high.
    pub samples: u64,
}

impl StockRun {
    /// Simulated cycles per wall-clock second.
    pub fn cycles_per_second(&self) -> f64 {
        self.cycles as f64 / self.seconds
    }

    /// Append the pins of the next cycle (used by both engines).
    fn record(&mut self, cycle: u64, p: Pins) {
        if self.changes.last().is_none_or(|(_, q)| *q != p) {
            self.changes.push((cycle, p));
        }
        self.samples += p.sample_valid as u64;
        self.cycles = cycle + 1;
    }
}

/// The MISO stimulus of [`stock_simulation_cycles`] and [`rtlsim_cycles`]:
/// the value of `adc_miso` during cycle `cycle`, given that cycle's pins
/// (an arbitrary deterministic pattern that also follows SCLK).
pub fn pattern_miso(cycle: u64, pins: &Pins) -> u64 {
    (cycle as u8).wrapping_mul(37) as u64 ^ pins.sclk as u64
}

/// Run the gateware of `s` for one reset cycle and then `cycles` cycles
/// under rust-hdl's stock threaded `Simulation` (`Simulation::new`,
/// `add_clock`, `add_testbench`, `run`), driving [`pattern_miso`].
///
/// Slow by design (thread hand-offs per clock edge): it exists to measure
/// [`crate::RtlSim`] against and to show both give the same waveform.
pub fn stock_simulation_cycles(s: &lut_gen::Schedule, cycles: u64) -> Result<StockRun, HdlError> {
    let p = plan::plan(s)?;
    let reader = PinReader::new(&p);
    let t0 = Instant::now();
    let core = Box::new(Core::new(&p));
    let out: Arc<Mutex<StockRun>> = Arc::default();
    let tb_out = out.clone();
    let mut sim: Simulation<Core> = Simulation::new();
    // 10 ps per half period: the time unit is irrelevant here.
    sim.add_clock(10, |x: &mut Box<Core>| x.clock.next = !x.clock.val());
    sim.add_testbench(move |mut sim: Sim<Core>| {
        let mut x = sim.init()?;
        let mut run = StockRun::default();
        // One reset cycle, then `cycles` cycles: the same sequence as
        // RtlSim::step(true, 0) followed by step(false, miso) per cycle.
        x.rst.next = true;
        x.adc_miso.next = 0u64.into();
        wait_clock_false!(sim, clock, x);
        wait_clock_true!(sim, clock, x);
        run.reset_pins = read_pins(&x, &reader);
        x.rst.next = false;
        for c in 0..cycles {
            wait_clock_false!(sim, clock, x);
            wait_clock_true!(sim, clock, x);
            let pins = read_pins(&x, &reader);
            run.record(c, pins);
            // MISO during cycle c, sampled by the edge that begins c + 1.
            x.adc_miso.next = pattern_miso(c, &pins).into();
        }
        *tb_out.lock().unwrap() = run;
        sim.done(x)
    });
    sim.run(core, u64::MAX / 2)
        .map_err(|e| HdlError::Simulation(format!("{e:?}")))?;
    let mut run = std::mem::take(&mut *out.lock().unwrap());
    run.seconds = t0.elapsed().as_secs_f64();
    if run.cycles != cycles {
        return Err(HdlError::Simulation(format!(
            "testbench stopped after {} of {cycles} cycles",
            run.cycles
        )));
    }
    Ok(run)
}

/// The same run as [`stock_simulation_cycles`] (same reset, stimulus and
/// record) with [`crate::RtlSim`], for a like-for-like comparison.
pub fn rtlsim_cycles(s: &lut_gen::Schedule, cycles: u64) -> Result<StockRun, HdlError> {
    let t0 = Instant::now();
    let mut sim = crate::RtlSim::new(s)?;
    let mut run = StockRun {
        reset_pins: sim.step(true, 0),
        ..Default::default()
    };
    let mut miso = 0u64;
    for c in 0..cycles {
        let pins = sim.step(false, miso);
        run.record(c, pins);
        miso = pattern_miso(c, &pins);
    }
    run.seconds = t0.elapsed().as_secs_f64();
    Ok(run)
}
