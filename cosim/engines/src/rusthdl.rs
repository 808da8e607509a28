//! The rust-hdl back end: `hdl::RtlSim` (rust-hdl's own model of the
//! emitted blocks) as a [`Dut`], in process.

use judge::Dut;
use lut_gen::Pins;
use lut_gen::Schedule;

use crate::error::SimError;

/// `hdl::RtlSim` as a [`Dut`].
pub struct RustHdlDut(hdl::RtlSim);

impl RustHdlDut {
    pub fn new(s: &Schedule) -> Result<RustHdlDut, SimError> {
        hdl::RtlSim::new(s)
            .map(RustHdlDut)
            .map_err(|e| SimError::Hdl(e.to_string()))
    }
}

impl Dut for RustHdlDut {
    #[inline]
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        self.0.step(rst, miso)
    }

    fn set_tready(&mut self, ready: bool) {
        self.0.set_tready(ready)
    }

    fn set_mode_sel(&mut self, sel: u8) {
        self.0.set_mode_sel(sel)
    }
}

/// The emitted Verilog of a schedule.
pub fn verilog(s: &Schedule) -> Result<String, SimError> {
    hdl::emit(s, None)
        .map(|e| e.verilog().to_string())
        .map_err(|e| SimError::Hdl(e.to_string()))
}
