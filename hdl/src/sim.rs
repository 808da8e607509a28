//! A fast in-process simulator of the gateware: rust-hdl's own model of the
//! very blocks that are emitted as Verilog, driven by a direct clock loop.

use crate::rhdl::*;

use lut_gen::Pins;

use crate::core::Core;
use crate::link::{AxisLink, UartLink};
use crate::{plan, HdlError};

/// A block connected and settled with its clock low, before any edge.
/// (A macro, not a function: the blocks share the field name `clock`, not
/// a trait that reaches it.)
macro_rules! started {
    ($block:expr) => {{
        let mut b = $block;
        b.connect_all();
        b.clock.next = Clock::from(false);
        simulate(&mut *b, 1000);
        b
    }};
}

/// One rising edge of a link stage (`UartLink` or `AxisLink`, whose inputs
/// have the same names), sampling `core`'s sample stream as it is now.
macro_rules! clock_link {
    ($link:expr, $rst:expr, $core:expr, $passes:expr) => {{
        let (l, c) = ($link, $core);
        l.clock.next = Clock::from(false);
        l.rst.next = $rst;
        l.valid.next = c.sample_valid.val();
        l.ch.next = c.sample_channel.val();
        l.val.next = c.sample_value.val();
        l.slot_tick.next = c.slot_tick.val();
        // a mix with modes: the mode in force, which each header carries
        l._mode = c.mode.first().map_or(0, |m| m.val().to_u64() as u8);
        settle(l, $passes);
        l.clock.next = Clock::from(true);
        settle(l, $passes);
    }};
}

/// Cycle-accurate simulator of the emitted gateware.
///
/// Each [`RtlSim::step`] applies exactly one rising clock edge.  The two
/// arguments are the input levels that this edge samples, i.e. the levels
/// present during the cycle *before* the returned one:
///
/// - `rst`: a step with `rst = true` returns the reset values of
///   `docs/timing.md`; the first step with `rst = false` after reset returns
///   the outputs **in cycle 0**, the next one cycle 1, and so on;
/// - `miso` (bit `b` = `adc_miso[b]`): the value of `adc_miso` **during the
///   cycle returned by the previous call** (during cycle `c - 1` when this
///   call returns cycle `c`).  A caller therefore computes MISO for cycle `c`
///   from the pins of cycle `c` and passes it with the next call, exactly
///   like a testbench that sets inputs and then raises the clock.
///
/// The simulator starts before any edge (register contents undefined), so
/// begin with at least one `rst = true` step.
pub struct RtlSim {
    core: Box<Core>,
    /// The link stage (`slotforge_link`), fed the core's sample stream.
    link: Option<Box<UartLink>>,
    /// The AXI4-Stream form of the link stage, and the slave's `tready`
    /// during the cycle the last step returned ([`RtlSim::set_tready`]).
    axis: Option<Box<AxisLink>>,
    tready: bool,
    passes: u64,
    reader: PinReader,
}

/// What is needed to turn the core's fixed-maximum ports into [`Pins`].
#[derive(Debug, Clone)]
pub(crate) struct PinReader {
    nb: usize,
    lanes: u16,
    ch_mask: u16,
    /// Some branch has no multiplexer: the port's mux lanes are the core's
    /// without that branch's, moved down (`(core_sel_lo, core_en_lo,
    /// devices)` of each branch that has one, in branch order).
    pack: Option<Vec<(u32, u32, u32)>>,
    /// Bits of `mode_sel` and `mode` (0 without modes).
    mode_bits: u32,
}

impl PinReader {
    pub(crate) fn new(p: &plan::Plan) -> PinReader {
        let nb = p.branches.len();
        let pack = p.branches.iter().any(|b| !b.muxed).then(|| {
            (p.branches.iter().enumerate())
                .filter(|(_, r)| r.muxed)
                .map(|(b, r)| (3 * b as u32, r.en_offset as u32, r.devices as u32))
                .collect()
        });
        PinReader {
            nb,
            lanes: ((1u32 << nb) - 1) as u16,
            ch_mask: ((1u32 << p.channel_bits) - 1) as u16,
            pack,
            mode_bits: p.modes.as_ref().map_or(0, |m| m.bits),
        }
    }

    /// The ports' `mux_sel` and `mux_en` from the core's.
    #[inline]
    fn mux(&self, sel: u64, en: u128) -> (u64, u128) {
        let Some(pack) = &self.pack else {
            return (sel, en);
        };
        let (mut s, mut e, mut at_s, mut at_e) = (0u64, 0u128, 0, 0);
        for &(sl, el, n) in pack {
            s |= ((sel >> sl) & 7) << at_s;
            e |= ((en >> el) & ((1u128 << n) - 1)) << at_e;
            at_s += 3;
            at_e += n;
        }
        (s, e)
    }
}

/// The `slotforge_top` outputs of the core as they are now.
#[inline]
pub(crate) fn read_pins(c: &Core, r: &PinReader) -> Pins {
    let (mux_sel, mux_en) = r.mux(c.mux_sel_u64(), c.mux_en_u128());
    Pins {
        cs_n: c.adc_cs_n.val().to_u64() as u16 & r.lanes,
        sclk: c.adc_sclk.val().to_u64() as u16 & r.lanes,
        // lane `i` = the `i`-th branch with a command word (the core ties
        // the rest to 0); no signal at all in a mix without one
        mosi: c.adc_mosi.first().map_or(0, |m| m.val().to_u64() as u16),
        mux_sel,
        mux_en,
        sample_valid: c.sample_valid.val(),
        sample_channel: c.sample_channel.val().to_u64() as u16 & r.ch_mask,
        sample_value: c.sample_value.val().to_u64() as u16,
        // the core has no link: the link stage's pins are read apart
        ..Pins::LOW
    }
}

impl RtlSim {
    pub fn new(schedule: &lut_gen::Schedule) -> Result<RtlSim, HdlError> {
        Self::with_form(schedule, plan::LutForm::Auto)
    }

    /// [`RtlSim::new`] with the slot LUT form chosen by the caller.
    pub fn with_form(
        schedule: &lut_gen::Schedule,
        form: plan::LutForm,
    ) -> Result<RtlSim, HdlError> {
        let p = plan::plan_with(schedule, form)?;
        Ok(Self::from_plan(&p))
    }

    /// The gateware with a design-level fault built in (see
    /// [`crate::GatewareFault`]); the LUT form is the one the fault lives in.
    pub fn with_fault(
        schedule: &lut_gen::Schedule,
        fault: crate::GatewareFault,
    ) -> Result<RtlSim, HdlError> {
        let mut p = plan::plan_with(schedule, fault.lut_form())?;
        fault.apply(&mut p)?;
        Ok(Self::from_plan(&p))
    }

    fn from_plan(p: &plan::Plan) -> RtlSim {
        let axis = p.link.filter(|lp| lp.axis.is_some());
        let link = p.link.filter(|lp| lp.axis.is_none());
        RtlSim {
            core: started!(Box::new(Core::new(p))),
            link: link.map(|lp| started!(Box::new(UartLink::new(lp)))),
            axis: axis.map(|lp| started!(Box::new(AxisLink::new(lp)))),
            tready: true,
            passes: 0,
            reader: PinReader::new(p),
        }
    }

    /// Number of branches (valid bits of `cs_n`, `sclk`, `miso`).
    pub fn branches(&self) -> usize {
        self.reader.nb
    }

    /// Evaluation passes over the design so far (a cost measure).
    pub fn passes(&self) -> u64 {
        self.passes
    }

    /// An AXI4-Stream link's `m_axis_tready` during the cycle the last
    /// [`RtlSim::step`] returned (sampled by the next step, like `miso`).
    pub fn set_tready(&mut self, ready: bool) {
        self.tready = ready;
    }

    /// `mode_sel` during the cycle the last [`RtlSim::step`] returned
    /// (sampled by the next step, like `miso`; ignored without the pin).
    pub fn set_mode_sel(&mut self, sel: u8) {
        // the wrapper's port is as wide as the modes need
        let bits = self.reader.mode_bits;
        if let Some(s) = self.core.mode_sel.first_mut() {
            s.next = (sel as u64 & ((1 << bits) - 1)).into();
        }
    }

    /// Apply one rising clock edge; see the type's documentation.
    pub fn step(&mut self, rst: bool, miso: u64) -> Pins {
        let miso = miso & self.reader.lanes as u64;
        // The link samples the core's outputs of the cycle this edge ends.
        if let Some(l) = self.axis.as_deref_mut() {
            l.tready.next = self.tready;
            clock_link!(l, rst, &*self.core, &mut self.passes);
        }
        if let Some(l) = self.link.as_deref_mut() {
            clock_link!(l, rst, &*self.core, &mut self.passes);
        }
        let c = &mut *self.core;
        // Falling edge: no logic reacts to it, so it only has to reach every
        // flip-flop's clock (done directly by `drive_clock`); evaluation
        // passes are needed only when an input changes and its new value
        // has to propagate to the flip-flops' D inputs.
        c.drive_clock(false);
        let sel_moved = (c.mode_sel.first()).is_some_and(|s| s.next != s.val());
        if c.rst.val() != rst || c.adc_miso.val().to_u64() != miso || sel_moved {
            c.rst.next = rst;
            c.adc_miso.next = miso.into();
            let ok = settle(c, &mut self.passes);
            debug_assert!(ok, "combinational logic did not settle");
        }
        // Rising edge: every flip-flop and ROM sees it in the next pass.
        c.drive_clock(true);
        let ok = settle(c, &mut self.passes);
        debug_assert!(ok, "combinational logic did not settle");
        let mut pins = read_pins(c, &self.reader);
        if let Some(m) = c.mode.first() {
            pins.mode = m.val().to_u64() as u8;
        }
        if let Some(l) = &self.link {
            pins.link_tx = l.tx.val();
            pins.link_overflow = l.ovf.val();
        }
        if let Some(l) = &self.axis {
            pins.axis_tdata = l.tdata.val().to_u64() as u8;
            pins.axis_tvalid = l.tvalid.val();
            pins.axis_tlast = l.tlast.val();
            pins.link_overflow = l.ovf.val();
        }
        pins
    }
}

/// `rust_hdl::simulate`, counting passes.
fn settle<B: Block>(uut: &mut B, passes: &mut u64) -> bool {
    for _ in 0..1000 {
        uut.update_all();
        *passes += 1;
        if !uut.has_changed() {
            return true;
        }
    }
    false
}

/// Every flip-flop of the core as it stands after the first rising edge
/// with `rst` high (its reset value: the value the design gives it in
/// reset), by the module path rust-hdl names its `DFF` module with
/// (`top$branches$0$r_cs_n`), as a Verilog literal (`1'h1`).  The emitter
/// makes it each register's initial value, so the pins show their reset
/// levels from power-on, before any clock edge.
pub(crate) fn reset_values(p: &plan::Plan) -> std::collections::BTreeMap<String, String> {
    let mut sim = RtlSim::from_plan(p);
    sim.step(true, 0);
    let mut probe = RegisterValues::default();
    sim.core.accept("top", &mut probe);
    probe.values
}

/// A probe that reads each block's `q` (a `DFF`'s output) by block path.
#[derive(Default)]
struct RegisterValues {
    path: Vec<String>,
    values: std::collections::BTreeMap<String, String>,
}

impl Probe for RegisterValues {
    fn visit_start_scope(&mut self, name: &str, _node: &dyn Block) {
        self.path.push(name.to_string());
    }

    fn visit_atom(&mut self, name: &str, signal: &dyn Atom) {
        if name == "q" {
            let v = format!("{:x}", signal.verilog());
            self.values.insert(self.path.join("$"), v);
        }
    }

    fn visit_end_scope(&mut self, _name: &str, _node: &dyn Block) {
        self.path.pop();
    }
}
