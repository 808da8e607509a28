//! The engines side by side on one sample of the quick campaign's faults,
//! for `build`'s default speed chart: the quick campaign runs on the cycle
//! model only (a rust-hdl run of a 48 MHz mix takes seconds, and thirty of
//! them would take minutes), so the gateware's engines each run a fixed,
//! deterministic sample of the same pin faults at the same site, judged by
//! the same checker.  A fault an engine misses is data here, not a failed
//! campaign: [`crate::Campaign::ok`] gates the build, this does not.

use std::time::Instant;

use judge::{Dut, FaultyDut, PinFault};
use lut_gen::Schedule;
use serde::Serialize;

use super::{judge_run, parallel, slave, Runs, Site};

/// An engine of the gateware that the sample runs through.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Engine {
    /// The gateware in rust-hdl's simulator, in process.
    Rusthdl,
    /// The emitted Verilog verilated and loaded in process.
    Verilator,
}

impl Engine {
    /// The engine's name, as the campaign's engine columns name it.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Rusthdl => "rusthdl",
            Engine::Verilator => "verilator",
        }
    }

    fn dut(self, s: &Schedule) -> Result<Box<dyn Dut>, String> {
        let d: Box<dyn Dut> = match self {
            Engine::Rusthdl => Box::new(engines::RustHdlDut::new(s).map_err(|e| e.to_string())?),
            Engine::Verilator => {
                let v = engines::verilog(s).map_err(|e| e.to_string())?;
                Box::new(engines::VerilatedDut::new(&v).map_err(|e| e.to_string())?.0)
            }
        };
        Ok(slave(s, d))
    }
}

/// One engine's row of the methods table: the faults of the sample it ran,
/// those the checker caught, and the wall seconds its runs took.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodRun {
    pub engine: Engine,
    /// Injections that landed (a fault that found nothing to change is not counted).
    pub faults_run: u64,
    pub caught: u64,
    /// The faults the checker let through on this engine, by name.
    pub missed: Vec<String>,
    /// Frames per run.
    pub frames: u64,
    /// Wall seconds of all its runs (each timed on its own).
    pub seconds: f64,
    /// Why the engine did not run (its tool missing, a build that failed).
    pub not_run: Option<String>,
}

impl MethodRun {
    /// Wall seconds per judged run.
    pub fn seconds_per_run(&self) -> f64 {
        self.seconds / self.faults_run.max(1) as f64
    }
}

/// The sample: one pin fault of each class of the quick campaign (its
/// mid-frame site), in an order seeded by the mix's name, so one mix always
/// gets the same sample and different mixes different ones.
pub fn sample(s: &Schedule) -> (Site, Vec<PinFault>) {
    let site = super::sites(s)
        .into_iter()
        .find(|x| x.name == "mid-frame")
        .expect("every mix has a mid-frame site");
    let mut seen = std::collections::BTreeSet::new();
    let mut v: Vec<PinFault> = PinFault::all(s)
        .into_iter()
        .filter(|f| seen.insert(f.class()))
        .collect();
    let key = |f: &PinFault| fnv(format!("{}/{}", s.mix.name, f.name()).as_bytes());
    v.sort_by_key(key);
    (site, v)
}

fn fnv(b: &[u8]) -> u64 {
    b.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &x| {
        (h ^ x as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Runs the first `n` faults of the [`sample`] that land on the cycle
/// model on each `(engine, n)` of
/// `plan` for `frames` frames (at least 2: the site is mid-way through
/// frame 1), each judged by the checker with the model.
pub fn methods(s: &Schedule, plan: &[(Engine, usize)], frames: u64) -> Vec<MethodRun> {
    let frames = frames.max(2);
    let (site, faults) = sample(s);
    // the faults that land (change a pin) on the cycle model, whose clean
    // pins every engine shares: an engine's `n` counts faults it really ran
    let count = Runs {
        hook: None,
        done: 0.into(),
        total: faults.len() as u64,
    };
    let lands = parallel(faults.clone(), &count, |f| {
        let mut dut = FaultyDut::new(
            s,
            slave(s, Box::new(judge::ModelDut::new(s))),
            f,
            site.cycle,
        );
        judge_run(s, &mut dut, frames, false).is_ok() && dut.injected()
    });
    let faults: Vec<PinFault> = faults
        .into_iter()
        .zip(lands)
        .filter_map(|(f, l)| l.then_some(f))
        .collect();
    let mut jobs = Vec::new();
    for &(e, n) in plan {
        jobs.extend(faults.iter().take(n).map(|f| (e, *f)));
    }
    let count = Runs {
        hook: None,
        done: 0.into(),
        total: jobs.len() as u64,
    };
    // (engine, fault, caught, seconds), or the engine's error
    let runs = parallel(jobs, &count, |(e, f)| {
        let inner = e.dut(s).map_err(|why| (e, why))?;
        let mut dut = FaultyDut::new(s, inner, f, site.cycle);
        let t = Instant::now();
        let j = judge_run(s, &mut dut, frames, false).map_err(|why| (e, why))?;
        let secs = t.elapsed().as_secs_f64();
        let caught = !j.detected_by().is_empty();
        Ok((e, dut.injected().then_some((f.name(), caught, secs))))
    });
    plan.iter()
        .map(|&(engine, _)| {
            let mut row = MethodRun {
                engine,
                faults_run: 0,
                caught: 0,
                missed: vec![],
                frames,
                seconds: 0.0,
                not_run: None,
            };
            for r in &runs {
                match r {
                    Ok((e, Some((name, caught, secs)))) if *e == engine => {
                        row.faults_run += 1;
                        row.seconds += secs;
                        if *caught {
                            row.caught += 1;
                        } else {
                            row.missed.push(name.clone());
                        }
                    }
                    Err((e, why)) if *e == engine => row.not_run = Some(why.clone()),
                    _ => {}
                }
            }
            row
        })
        .collect()
}
