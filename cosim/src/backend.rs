//! The back ends behind one call: [`run`] dispatches to each engine.

use judge::run::{reset_cycles, run_dut, run_model, Dut, ModelDut, Observer, RunOptions};
use judge::vcdout::{write_gtkw, VcdWriter};
use judge::Report;
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
) -> Result<Report, SimError> {
    if let (Some(path), Backend::Model | Backend::RustHdl) = (&opts.rtl, backend) {
        return Err(SimError::Rtl(crate::rtl::RtlError {
            file: path.clone(),
            port: None,
            message: format!(
                "the {} back end simulates no Verilog; outside Verilog runs on verilator or icarus",
                backend.name()
            ),
        }));
    }
    match backend {
        Backend::Model => {
            if let Some(v) = &opts.vcd {
                // The slot-level model has no pins: the cycle model draws the window.
                let window = v.to_frame.max(v.from_frame + 1).min(frames.max(1));
                in_process(s, &mut ModelDut::new(s), window, opts, "model")?;
            }
            Ok(run_model(s, frames, opts.stimulus, opts.check.max_records))
        }
        Backend::RustHdl => in_process(s, &mut RustHdlDut::new(s)?, frames, opts, "rusthdl"),
        Backend::Verilator => {
            let text = match &opts.rtl {
                Some(path) => crate::rtl::load_rtl(s, path)?,
                None => verilog(s)?,
            };
            let (mut dut, _) = VerilatedDut::new(&text)?;
            in_process(s, &mut dut, frames, opts, "verilator")
        }
        Backend::Icarus => crate::icarus::run(s, frames, opts),
    }
}

/// Runs an in-process design, fully checked, writing `opts.vcd`'s window.
fn in_process(
    s: &Schedule,
    dut: &mut dyn Dut,
    frames: u64,
    opts: &SimOptions,
    source: &str,
) -> Result<Report, SimError> {
    let reset = reset_cycles(s, opts.reset_cycles);
    let ro = RunOptions {
        stimulus: opts.stimulus,
        check: opts.check,
        reset_cycles: reset,
    };
    let mut writer = match &opts.vcd {
        None => None,
        Some(v) => {
            let f = s.grid.frame_cycles;
            let from = if v.from_frame == 0 {
                0
            } else {
                reset + v.from_frame * f
            };
            let to = reset + v.to_frame.max(v.from_frame + 1) * f;
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
    let obs = writer.as_mut().map(|w| w as &mut dyn Observer);
    let report = run_dut(s, dut, frames, &ro, source, obs);
    if let Some(w) = writer {
        w.finish().map_err(|e| SimError::Io(e.to_string()))?;
    }
    Ok(report)
}
