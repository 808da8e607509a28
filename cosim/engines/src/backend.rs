//! The back ends behind one call: [`run`] dispatches to each engine.

use judge::CycleSink;
use judge::Trace;
use judge::Verdict;
use judge::{reset_cycles, run_dut, run_model, Dut, ModelDut, Observer, RunOptions};
use judge::{write_gtkw, VcdWriter};
use lut_gen::Pins;
use lut_gen::Schedule;

use crate::error::SimError;
use crate::options::{Backend, SimOptions};
use crate::rusthdl::{verilog, RustHdlDut};
use crate::verilator::VerilatedDut;

/// Simulates `frames` frames on `backend` with the ADC model and checks them.
pub fn run(
    s: &Schedule,
    backend: Backend,
    frames: u64,
    opts: &SimOptions,
) -> Result<Verdict, SimError> {
    no_rtl_in_process(backend, opts)?;
    match backend {
        // The slot-level model has one frame template: a mix that switches
        // modes runs the cycle-level model, which follows the switches.
        Backend::Model if s.modes.len() > 1 => run_traced(s, backend, frames, opts, None),
        Backend::Model => {
            if let Some(v) = &opts.vcd {
                // The slot-level model has no pins: the cycle model draws the window.
                let f = s.grid.frame_cycles;
                let window = v.to.max(v.from + 1).div_ceil(f).min(frames.max(1));
                in_process(s, &mut ModelDut::new(s), window, opts, "model", None)?;
            }
            Ok(run_model(s, frames, opts.stimulus, opts.check.max_records))
        }
        _ => run_traced(s, backend, frames, opts, None),
    }
}

/// `--rtl` needs a Verilog simulator.
fn no_rtl_in_process(backend: Backend, opts: &SimOptions) -> Result<(), SimError> {
    match (&opts.rtl, backend) {
        (Some(path), Backend::Model | Backend::RustHdl) => {
            Err(SimError::Rtl(crate::rtl::RtlError {
                file: path.clone(),
                port: None,
                message: format!(
                "the {} back end simulates no Verilog; outside Verilog runs on verilator or icarus",
                backend.name()
            ),
            }))
        }
        _ => Ok(()),
    }
}

/// Like [`run`], and every cycle's pins go to `trace` too (the `model` back
/// end then runs the cycle-level model, which has pins).
pub fn run_traced(
    s: &Schedule,
    backend: Backend,
    frames: u64,
    opts: &SimOptions,
    trace: Option<&mut Trace>,
) -> Result<Verdict, SimError> {
    run_observed(
        s,
        backend,
        frames,
        opts,
        trace.map(|t| t as &mut dyn Tracer),
    )
}

/// What can watch every cycle of any back end: the in-process ones call it
/// as an [`Observer`], Icarus (through its VCD) as a [`CycleSink`].  Every
/// type that is both is one ([`Trace`], [`judge::SampleLog`]).
pub trait Tracer: Observer + CycleSink {
    fn as_observer(&mut self) -> &mut dyn Observer;
    fn as_sink(&mut self) -> &mut dyn CycleSink;
}

impl<T: Observer + CycleSink> Tracer for T {
    fn as_observer(&mut self) -> &mut dyn Observer {
        self
    }
    fn as_sink(&mut self) -> &mut dyn CycleSink {
        self
    }
}

/// Like [`run_traced`] with any [`Tracer`] (e.g. one that keeps only the
/// samples, not every cycle).
pub fn run_observed(
    s: &Schedule,
    backend: Backend,
    frames: u64,
    opts: &SimOptions,
    trace: Option<&mut dyn Tracer>,
) -> Result<Verdict, SimError> {
    no_rtl_in_process(backend, opts)?;
    match backend {
        Backend::Model => in_process(s, &mut ModelDut::new(s), frames, opts, "model", obs(trace)),
        Backend::RustHdl => {
            let mut dut = RustHdlDut::new(s)?;
            in_process(s, &mut dut, frames, opts, "rusthdl", obs(trace))
        }
        Backend::Verilator => {
            let text = match &opts.rtl {
                Some(path) => crate::rtl::load_rtl(s, path)?,
                None => verilog(s)?,
            };
            let (mut dut, _) = VerilatedDut::new(&text)?;
            in_process(s, &mut dut, frames, opts, "verilator", obs(trace))
        }
        Backend::Icarus => crate::icarus::run(s, frames, opts, trace.map(|t| t.as_sink())),
    }
}

/// A tracer as the observer of an in-process run.
fn obs(t: Option<&mut dyn Tracer>) -> Option<&mut dyn Observer> {
    t.map(|t| t.as_observer())
}

/// Two observers of one run.
struct Tee<'a>(Option<&'a mut dyn Observer>, Option<&'a mut dyn Observer>);

impl Observer for Tee<'_> {
    fn cycle(&mut self, cycle: u64, rst: bool, pins: &Pins, miso: u64) {
        if let Some(o) = self.0.as_deref_mut() {
            o.cycle(cycle, rst, pins, miso);
        }
        if let Some(o) = self.1.as_deref_mut() {
            o.cycle(cycle, rst, pins, miso);
        }
    }
}

/// Runs an in-process design, fully checked, writing `opts.vcd`'s window.
fn in_process(
    s: &Schedule,
    dut: &mut dyn Dut,
    frames: u64,
    opts: &SimOptions,
    source: &str,
    trace: Option<&mut dyn Observer>,
) -> Result<Verdict, SimError> {
    let reset = reset_cycles(s, opts.reset_cycles);
    let ro = RunOptions {
        stimulus: opts.stimulus,
        check: opts.check,
        reset_cycles: reset,
    };
    let mut writer = match &opts.vcd {
        None => None,
        Some(v) => {
            let (from, to) = v.run_cycles(reset);
            if v.gtkw {
                write_gtkw(&v.path.with_extension("gtkw"), &v.path, s)
                    .map_err(|e| SimError::Io(format!("{}: {e}", v.path.display())))?;
            }
            Some(
                VcdWriter::create(&v.path, s, from, to)
                    .map_err(|e| SimError::Io(format!("{}: {e}", v.path.display())))?,
            )
        }
    };
    let mut tee = Tee(
        writer.as_mut().map(|w| w as &mut dyn Observer),
        trace.map(|t| &mut *t as &mut dyn Observer),
    );
    let obs = (tee.0.is_some() || tee.1.is_some()).then_some(&mut tee as &mut dyn Observer);
    let dut = judge::ModeRequests::new(s, dut, &opts.modes);
    let mut dut = judge::with_slave(s, dut, opts.tready);
    let report = run_dut(s, &mut *dut, frames, &ro, source, obs);
    if let Some(w) = writer {
        w.finish().map_err(|e| SimError::Io(e.to_string()))?;
    }
    Ok(report)
}
