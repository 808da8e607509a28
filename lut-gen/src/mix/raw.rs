//! The mix as TOML spells it, before any check (spans kept for messages).

use serde::Deserialize;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMix {
    pub(super) name: Option<Spanned<String>>,
    pub(super) description: Option<String>,
    pub(super) clock: Option<Spanned<RawClock>>,
    pub(super) frame: Option<Spanned<RawFrame>>,
    #[serde(default)]
    pub(super) adc_part: Vec<Spanned<RawAdcPart>>,
    #[serde(default)]
    pub(super) branch: Vec<Spanned<RawBranch>>,
    #[serde(default)]
    pub(super) channel: Vec<Spanned<RawChannel>>,
    pub(super) link: Option<Spanned<RawLink>>,
    #[serde(default)]
    pub(super) mode: Vec<Spanned<RawMode>>,
    pub(super) modes: Option<Spanned<RawModes>>,
    #[serde(default)]
    pub(super) trigger: Vec<Spanned<RawTrigger>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMode {
    pub(super) name: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawModes {
    pub(super) select: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTrigger {
    pub(super) to: Spanned<String>,
    pub(super) from: Option<Spanned<String>>,
    pub(super) when: Spanned<String>,
    pub(super) level: Spanned<i64>,
    pub(super) channels: Spanned<Vec<Spanned<String>>>,
    pub(super) for_frames: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLink {
    pub(super) kind: Spanned<String>,
    pub(super) baud: Option<Spanned<i64>>,
    pub(super) parity: Option<Spanned<String>>,
    pub(super) stop_bits: Option<Spanned<i64>>,
    pub(super) tlast: Option<Spanned<String>>,
    pub(super) ready_within: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawClock {
    pub(super) hz: Spanned<i64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFrame {
    pub(super) period_us: Spanned<i64>,
    pub(super) slice_us: Spanned<i64>,
    pub(super) slots_per_slice: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBranch {
    pub(super) name: Spanned<String>,
    pub(super) adc: Spanned<String>,
    pub(super) sclk_hz: Option<Spanned<i64>>,
    pub(super) mux: Spanned<String>,
    pub(super) mux_devices: Option<Spanned<i64>>,
    /// An external mux wired in front of the converter's own (`mux =
    /// "internal"`), and how many of its devices.
    pub(super) front_mux: Option<Spanned<String>>,
    pub(super) front_mux_devices: Option<Spanned<i64>>,
    pub(super) settle_ns: Option<Spanned<i64>>,
    pub(super) chain: Option<Spanned<i64>>,
    /// The converter's supply in volts (integer or float: TOML keeps the
    /// two apart).
    pub(super) vdd: Option<Spanned<toml::Value>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawAdcPart {
    pub(super) name: Spanned<String>,
    pub(super) bits: Spanned<i64>,
    pub(super) start: Spanned<String>,
    /// "cnv" parts: `cnv-high` (CNV held through the read) or `cnv-low`.
    pub(super) read: Option<Spanned<String>>,
    pub(super) leading_bits: Option<Spanned<i64>>,
    pub(super) trailing_bits: Option<Spanned<i64>>,
    pub(super) sclk_min_hz: Option<Spanned<i64>>,
    pub(super) sclk_max_hz: Spanned<i64>,
    pub(super) duty_min_pct: Option<Spanned<i64>>,
    pub(super) setup_ns: Option<Spanned<i64>>,
    pub(super) quiet_ns: Option<Spanned<i64>>,
    pub(super) conversion_ns: Option<Spanned<i64>>,
    pub(super) data_access_ns: Option<Spanned<i64>>,
    pub(super) max_sps: Spanned<i64>,
    pub(super) chain_max: Option<Spanned<i64>>,
    /// The command word's template (`crate::parts::Command::parse`).
    pub(super) command: Option<Spanned<String>>,
    /// Conversions ahead the command applies (0: the same one).
    pub(super) command_ahead: Option<Spanned<i64>>,
    /// The rising SCLK edge (from CS falling) whose next falling edge is the
    /// sampling instant; absent: the CS or CNV edge.
    pub(super) sample_after_rising: Option<Spanned<i64>>,
}

#[derive(Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct RawChannel {
    pub(super) name: Spanned<String>,
    pub(super) branch: Spanned<String>,
    pub(super) rate_hz: Spanned<i64>,
    pub(super) input: Option<Spanned<i64>>,
    /// The front mux's input (`branch.front_mux`) the channel is on.
    pub(super) front_input: Option<Spanned<i64>>,
    pub(super) kind: Option<String>,
    /// Integer or float: TOML keeps the two apart.
    pub(super) bandwidth_hz: Option<Spanned<toml::Value>>,
    pub(super) sync: Option<Spanned<String>>,
    pub(super) member: Option<Spanned<i64>>,
    /// `rates = { <mode> = <hz> }`: the rate in a mode, overriding `rate_hz`.
    pub(super) rates: Option<Spanned<std::collections::BTreeMap<String, Spanned<i64>>>>,
}
