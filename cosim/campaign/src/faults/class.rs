//! The class a fault is counted in, and the level it is injected at: the
//! matrix's rows, by the names the reports and the JSON print.

use std::borrow::Cow;

use formal::DeepFault;
use hdl::GatewareFault;
use judge::PinFault;
use serde::{Serialize, Serializer};

/// Where a fault is injected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    /// Into a simulation's pins (`judge::PinFault`).
    Pins,
    /// A reset glitch the design suffers while its `rst` port stays low.
    Reset,
    /// Built into the gateware (`hdl::GatewareFault`).
    Gateware,
    /// A faulty Verilog design on the Verilog engines.
    Verilog,
}

impl Level {
    pub fn as_str(self) -> &'static str {
        match self {
            Level::Pins => "pins",
            Level::Reset => "reset",
            Level::Gateware => "gateware",
            Level::Verilog => "verilog",
        }
    }
}

impl std::fmt::Display for Level {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// A class of fault: injections of one kind, whatever their site, branch
/// or engine.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FaultClass {
    // pin faults and the reset glitch (`judge::PinFault`)
    WrongChannel,
    WrongSampleBit,
    DropSample,
    CsLate,
    SclkExtraEdge,
    MuxLate,
    TwoMuxEn,
    WrongMux,
    ResetGlitch,
    ConversionMoved,
    PhaseShift,
    SelectSwap,
    SclkSlow,
    NeighbourCode,
    WrongChannelBits,
    LateCommand,
    LinkBitFlip,
    LinkDropByte,
    LinkStuckHigh,
    LinkStuckLow,
    LinkFifoOverflow,
    AxisTvalidDrop,
    AxisTdataChange,
    ModeEarly,
    ModeStuck,
    ModeUnasked,
    // built into the gateware (`hdl::GatewareFault`)
    RomWord,
    RomSwap,
    SlotWrapEarly,
    SlotWrapLate,
    SliceCountShort,
    SliceCountLong,
    LinkFifoShort,
    LinkBaudFast,
    LinkBaudSlow,
    LinkCrcInit,
    // faulty Verilog: `formal`'s deep faults, the test mutator's mutants
    LateCounter,
    RareCollision,
    /// A mutant of the emitted Verilog, by its operator (`relop`, `stuck`).
    Mutant(String),
}

impl FaultClass {
    /// The class of a pin fault or the reset glitch.
    pub fn of_pins(f: PinFault) -> FaultClass {
        use FaultClass as C;
        match f {
            PinFault::WrongChannel => C::WrongChannel,
            PinFault::WrongSampleBit => C::WrongSampleBit,
            PinFault::DropSample => C::DropSample,
            PinFault::CsLate { .. } => C::CsLate,
            PinFault::SclkExtraEdge { .. } => C::SclkExtraEdge,
            PinFault::MuxLate { .. } => C::MuxLate,
            PinFault::TwoMuxEn { .. } => C::TwoMuxEn,
            PinFault::WrongMux { .. } => C::WrongMux,
            PinFault::ResetGlitch => C::ResetGlitch,
            PinFault::ConversionMoved { .. } => C::ConversionMoved,
            PinFault::PhaseShift { .. } => C::PhaseShift,
            PinFault::SelectSwap { .. } => C::SelectSwap,
            PinFault::SclkSlow { .. } => C::SclkSlow,
            PinFault::NeighbourCode => C::NeighbourCode,
            PinFault::WrongChannelBits { .. } => C::WrongChannelBits,
            PinFault::LateCommand { .. } => C::LateCommand,
            PinFault::LinkBitFlip => C::LinkBitFlip,
            PinFault::LinkDropByte => C::LinkDropByte,
            PinFault::LinkStuck { high: true } => C::LinkStuckHigh,
            PinFault::LinkStuck { high: false } => C::LinkStuckLow,
            PinFault::LinkOverflow => C::LinkFifoOverflow,
            PinFault::AxisTvalidDrop => C::AxisTvalidDrop,
            PinFault::AxisTdataChange => C::AxisTdataChange,
            PinFault::ModeEarly => C::ModeEarly,
            PinFault::ModeStuck => C::ModeStuck,
            PinFault::ModeUnasked => C::ModeUnasked,
        }
    }

    /// The class of a fault built into the gateware.
    pub fn of_gateware(f: GatewareFault) -> FaultClass {
        use FaultClass as C;
        match f {
            GatewareFault::RomWord { .. } => C::RomWord,
            GatewareFault::RomSwap { .. } => C::RomSwap,
            GatewareFault::SlotWrap { delta } if delta < 0 => C::SlotWrapEarly,
            GatewareFault::SlotWrap { .. } => C::SlotWrapLate,
            GatewareFault::SliceWrap { delta } if delta < 0 => C::SliceCountShort,
            GatewareFault::SliceWrap { .. } => C::SliceCountLong,
            GatewareFault::LinkFifoShort => C::LinkFifoShort,
            GatewareFault::LinkBaud { delta } if delta < 0 => C::LinkBaudFast,
            GatewareFault::LinkBaud { .. } => C::LinkBaudSlow,
            GatewareFault::LinkCrcInit => C::LinkCrcInit,
            GatewareFault::ModeStuck => C::ModeStuck,
        }
    }

    /// The class of one of `formal`'s deep faults (whatever frame it lands in).
    pub fn of_deep(f: DeepFault) -> FaultClass {
        match f {
            DeepFault::LateCounter { .. } => FaultClass::LateCounter,
            DeepFault::RareCollision => FaultClass::RareCollision,
        }
    }

    /// Its name in the reports and the JSON.
    pub fn name(&self) -> Cow<'static, str> {
        use FaultClass as C;
        Cow::Borrowed(match self {
            C::WrongChannel => "wrong-channel",
            C::WrongSampleBit => "wrong-sample-bit",
            C::DropSample => "drop-sample",
            C::CsLate => "cs-late",
            C::SclkExtraEdge => "sclk-extra-edge",
            C::MuxLate => "mux-late",
            C::TwoMuxEn => "two-mux-en",
            C::WrongMux => "wrong-mux",
            C::ResetGlitch => "reset-glitch",
            C::ConversionMoved => "conversion-moved",
            C::PhaseShift => "phase-shift",
            C::SelectSwap => "select-swap",
            C::SclkSlow => "sclk-slow",
            C::NeighbourCode => "neighbour-code",
            C::WrongChannelBits => "wrong-channel-bits",
            C::LateCommand => "late-command",
            C::LinkBitFlip => "link-bit-flip",
            C::LinkDropByte => "link-drop-byte",
            C::LinkStuckHigh => "link-stuck-high",
            C::LinkStuckLow => "link-stuck-low",
            C::LinkFifoOverflow => "link-fifo-overflow",
            C::AxisTvalidDrop => "axis-tvalid-drop",
            C::AxisTdataChange => "axis-tdata-change",
            C::ModeEarly => "mode-early",
            C::ModeStuck => "mode-stuck",
            C::ModeUnasked => "mode-unasked",
            C::RomWord => "rom-word",
            C::RomSwap => "rom-swap",
            C::SlotWrapEarly => "slot-wrap-early",
            C::SlotWrapLate => "slot-wrap-late",
            C::SliceCountShort => "slice-count-short",
            C::SliceCountLong => "slice-count-long",
            C::LinkFifoShort => "link-fifo-short",
            C::LinkBaudFast => "link-baud-fast",
            C::LinkBaudSlow => "link-baud-slow",
            C::LinkCrcInit => "link-crc-init",
            C::LateCounter => "late-counter",
            C::RareCollision => "rare-collision",
            C::Mutant(op) => return Cow::Owned(format!("mutant:{op}")),
        })
    }

    /// A fault on the mux pins (select and enable), which sigrok's SPI
    /// decode does not read.
    pub fn on_mux_pins(&self) -> bool {
        use FaultClass as C;
        matches!(self, C::MuxLate | C::TwoMuxEn | C::WrongMux | C::SelectSwap)
    }

    /// The level a fault of this class given as Verilog is counted at: a
    /// gateware class's Verilog is that gateware fault
    /// ([`crate::faults::gateware_as_verilog`]); the rest are Verilog faults.
    pub fn level_as_verilog(&self) -> Level {
        use FaultClass as C;
        match self {
            C::RomWord
            | C::RomSwap
            | C::SlotWrapEarly
            | C::SlotWrapLate
            | C::SliceCountShort
            | C::SliceCountLong
            | C::LinkFifoShort
            | C::LinkBaudFast
            | C::LinkBaudSlow
            | C::LinkCrcInit
            | C::ModeStuck => Level::Gateware,
            _ => Level::Verilog,
        }
    }

    /// A fault of the `mode` output (a mix with modes).
    pub fn on_mode_pin(&self) -> bool {
        use FaultClass as C;
        matches!(self, C::ModeEarly | C::ModeStuck | C::ModeUnasked)
    }

    /// A fault of the link to the host (UART or AXI4-Stream), at its pins
    /// or built into its stage.
    pub fn on_link(&self) -> bool {
        use FaultClass as C;
        matches!(
            self,
            C::LinkBitFlip
                | C::LinkDropByte
                | C::LinkStuckHigh
                | C::LinkStuckLow
                | C::LinkFifoOverflow
                | C::AxisTvalidDrop
                | C::AxisTdataChange
                | C::LinkFifoShort
                | C::LinkBaudFast
                | C::LinkBaudSlow
                | C::LinkCrcInit
        )
    }
}

impl std::fmt::Display for FaultClass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(&self.name())
    }
}

/// Serialized by its name, as the reports print it.
impl Serialize for FaultClass {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.name())
    }
}
