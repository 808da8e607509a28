//! The rules an invariant violation can break.  Each rule's name is public
//! data: reports print it and serialize it (`rule` in `--json`), and tests
//! and campaigns match on it, so the text of [`Rule::as_str`] must not change.

use std::fmt;

/// A rule of the mix's invariants or of the pin contract.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Rule {
    /// A channel's samples in one frame.
    SamplesPerFrame,
    /// A channel index outside the mix.
    Channel,
    /// A channel sampled on another branch than its own.
    Branch,
    /// Cycles between a channel's successive sampling instants.
    Interval,
    /// A completed conversion never emitted.
    SampleMissing,
    /// A sample emitted with no conversion waiting.
    SampleUnexpected,
    /// A sample emitted before its conversion completed.
    SampleEarly,
    /// A sample emitted with another channel than the one converted.
    SampleChannel,
    /// A sample emitted with another value than MISO carried.
    SampleValue,
    /// An output pin was x or z.
    XOrZ,
    /// An AXI4-Stream beat changed while stalled.
    AxisStable,
    /// An AXI4-Stream packet's TLAST misplaced.
    AxisTlast,
    /// The link's FIFO overflow flag rose.
    LinkOverflow,
    /// A packet's trailer reports tokens dropped by the link's FIFO.
    LinkOverflowCount,
    /// More than one mux select line active.
    MuxExclusive,
    /// No valid mux selection (device enable and select) at a sampling instant.
    MuxSelect,
    /// The mux had too few cycles to settle before a conversion.
    MuxSettle,
    /// SCLK not at its idle level.
    SclkIdle,
    /// CS too soon after the previous conversion.
    CsQuiet,
    /// Too few cycles between CS falling and the first SCLK edge.
    CsSetup,
    /// SCLK outside the ADC's frequency range.
    SclkFrequency,
    /// SCLK's duty cycle outside the ADC's range.
    SclkDuty,
    /// SCLK edges in a conversion window.
    SclkCount,
    /// No cycle after a released reset.
    NoCycles,
    /// Reset asserted again after it was released (checking stops).
    Reset,
    /// A slice's packet did not arrive in time.
    LinkPacketMissing,
    /// A UART bit edge off its bit period.
    LinkBitTiming,
    /// A UART frame without its stop bit.
    LinkFraming,
    /// A packet's CRC did not match.
    LinkCrc,
    /// A byte where the packet format puts none: the decoder lost its place.
    LinkResync,
    /// A packet's sequence number out of order.
    LinkSequence,
    /// A packet never came: the next good packet on the line is a later one.
    LinkPacketLost,
    /// A packet's records differ from the samples emitted in its slice.
    LinkSamples,
    /// A mix with modes: a packet's header names another mode (or mode of
    /// the frame before) than `mode` showed.
    LinkMode,
    /// The `mode` output changed inside a frame (a switch takes effect at a
    /// frame start only).
    ModeSwitch,
    /// A frame's mode is not the one the contract decides: a request
    /// ignored, or a switch without its request or trigger condition.
    ModeDecision,
    /// A command word on `adc_mosi` that the part would not take as the mix
    /// meant: a fixed bit differs, the word is short, or it selects an input
    /// the branch has no channel on.
    CommandWord,
    /// A sample whose channel differs from the one its conversion's command
    /// word selected (for a pipelined part, the word sent `ahead`
    /// conversions earlier).
    CommandChannel,
}

impl Rule {
    /// The rule's name as reports give it.
    pub fn as_str(self) -> &'static str {
        match self {
            Rule::SamplesPerFrame => "samples-per-frame",
            Rule::Channel => "channel",
            Rule::Branch => "branch",
            Rule::Interval => "interval",
            Rule::SampleMissing => "sample-missing",
            Rule::SampleUnexpected => "sample-unexpected",
            Rule::SampleEarly => "sample-early",
            Rule::SampleChannel => "sample-channel",
            Rule::SampleValue => "sample-value",
            Rule::XOrZ => "x-or-z",
            Rule::AxisStable => "axis-stable",
            Rule::AxisTlast => "axis-tlast",
            Rule::LinkOverflow => "link-overflow",
            Rule::LinkOverflowCount => "link-overflow-count",
            Rule::MuxExclusive => "mux-exclusive",
            Rule::MuxSelect => "mux-select",
            Rule::MuxSettle => "mux-settle",
            Rule::SclkIdle => "sclk-idle",
            Rule::CsQuiet => "cs-quiet",
            Rule::CsSetup => "cs-setup",
            Rule::SclkFrequency => "sclk-frequency",
            Rule::SclkDuty => "sclk-duty",
            Rule::SclkCount => "sclk-count",
            Rule::NoCycles => "no-cycles",
            Rule::Reset => "reset",
            Rule::LinkPacketMissing => "link-packet-missing",
            Rule::LinkBitTiming => "link-bit-timing",
            Rule::LinkFraming => "link-framing",
            Rule::LinkCrc => "link-crc",
            Rule::LinkResync => "link-resync",
            Rule::LinkSequence => "link-sequence",
            Rule::LinkPacketLost => "link-packet-lost",
            Rule::LinkSamples => "link-samples",
            Rule::LinkMode => "link-mode",
            Rule::ModeSwitch => "mode-switch",
            Rule::ModeDecision => "mode-decision",
            Rule::CommandWord => "command-word",
            Rule::CommandChannel => "command-channel",
        }
    }
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}
