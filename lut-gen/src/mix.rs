//! The channel-mix file: TOML in, a validated [`Mix`] out.
//!
//! Parsing goes through `toml::Spanned` so that every semantic error (a
//! duplicate name, a rate that gives a fractional number of samples per frame)
//! can still name the line it came from, exactly like a syntax error does.

use std::fmt;
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::parts::{AdcPart, MuxPart};

mod adc_part;
mod branches;
mod bulk;
mod channels;
mod check;
mod link_table;
mod modes;
mod raw;
mod words;

pub(crate) use branches::hz_words;
pub use bulk::expand_names;
pub(crate) use channels::SYNC_TOLERANCE_NS;
use check::Cx;
pub use modes::{ModeSelect, Modes, Trigger, When};
use raw::RawMix;
pub use words::toml_words;

/// A bad mix file: where, which field, and why.  Always exit code 2.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MixError {
    pub file: PathBuf,
    pub line: usize,
    pub column: usize,
    /// Dotted path of the offending field, e.g. `channel[3].rate_hz`.
    pub field: String,
    pub message: String,
}

impl fmt::Display for MixError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 && self.field.is_empty() {
            // The file itself (it cannot be read): no line, no field.
            return write!(f, "{}: {}", self.file.display(), self.message);
        }
        write!(
            f,
            "{}:{}:{}: {}: {}",
            self.file.display(),
            self.line,
            self.column,
            self.field,
            self.message
        )
    }
}

impl std::error::Error for MixError {}

/// A validated channel mix.  Every invariant the scheduler relies on
/// (whole cycles per slice and frame, whole samples per frame, unique names,
/// unique mux inputs) holds once a `Mix` exists.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Mix {
    pub name: String,
    pub description: String,
    pub clock_hz: u64,
    pub frame_us: u64,
    pub slice_us: u64,
    /// Set by the mix to force the slot grid; `None` lets the synthesizer pick.
    pub slots_per_slice: Option<u64>,
    /// Parts the mix declares itself (`[[adc_part]]`), in file order.
    pub parts: Vec<AdcPart>,
    pub branches: Vec<Branch>,
    pub channels: Vec<Channel>,
    /// The link to the host (`[link]`); `None`: the parallel sample stream
    /// is the output.  Reported by the audit's own `link` section.
    #[serde(skip)]
    pub link: Option<LinkSpec>,
    /// `[[mode]]`, `[modes]` and `[[trigger]]`; `None`: one mode, as every
    /// mix before modes (docs/mix-format.md, "Modes").
    #[serde(skip)]
    pub modes: Option<Modes>,
}

/// `[link]`: how the samples leave the FPGA (docs/packet-format.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkSpec {
    pub kind: LinkKind,
    /// `axis`: where `tlast` goes and the slave's guarantee (cycles within
    /// which it accepts an offered beat); unused for a UART.
    pub tlast: link::Tlast,
    pub ready_within: u32,
    /// Requested baud (`uart`); the divider's real baud is reported.
    pub baud: u64,
    pub parity: link::Parity,
    pub stop_bits: u8,
    /// The mix file's line of the key a refusal of the link names
    /// (`baud`; for AXI4-Stream `ready_within`, or `[link]` without it), so
    /// a line too slow for the mix is reported where the user wrote it;
    /// and its column.
    pub line: usize,
    pub column: usize,
}

/// `[link].kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkKind {
    Uart,
    Axis,
}

impl LinkKind {
    pub fn name(self) -> &'static str {
        match self {
            LinkKind::Uart => "uart",
            LinkKind::Axis => "axis",
        }
    }
}

/// Fewest clock cycles per UART bit: the checker and a host sample each
/// bit in its middle, which needs a few cycles of margin either side.
pub const MIN_BAUD_DIVIDER: u32 = 4;
/// Largest baud error (real against requested) a UART receiver tolerates
/// with margin, in percent.
pub const MAX_BAUD_ERROR_PCT: f64 = 2.0;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Branch {
    pub name: String,
    pub adc: AdcPart,
    /// Requested SCLK (the ADC's maximum when the mix leaves it out); the
    /// gateware uses the fastest SCLK at or below it that an even divider
    /// of the clock gives.
    pub sclk_hz: u64,
    /// Whether `sclk_hz` was written in the mix (else it is the default).
    pub sclk_explicit: bool,
    /// The multiplexer whose pins (`mux_sel`, `mux_en`) the branch drives:
    /// the external part, `none`, the converter's own (`internal`, no pins)
    /// or, on a `fronted` branch, the external mux in front of it.
    pub mux: MuxPart,
    pub mux_devices: u32,
    /// `mux = "internal"` with `front_mux`: the converter selects among its
    /// inputs with its command word and `mux` (`mux_devices` devices) is
    /// wired in front of some of them (`Channel::front_input`).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub fronted: bool,
    pub settle_ns: u64,
    /// Parts of `adc` daisy-chained on this branch's port (1: no chain).
    pub chain: u32,
    /// `vdd` as the mix gives it, in millivolts (`None`: not given, and
    /// `adc` has its lowest supply's figures).  `adc` is the part at this
    /// supply ([`AdcPart::at_supply`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vdd_mv: Option<u32>,
}

impl Branch {
    /// Inputs a channel's `input` may name: the converter's channels on a
    /// branch with its own multiplexer (fronted or not), else the mux's.
    pub fn input_capacity(&self) -> u32 {
        match (&self.adc.command, self.fronted) {
            (Some(c), true) => c.channels(),
            _ => self.mux.inputs * self.mux_devices,
        }
    }

    /// The supply whose datasheet figures `adc` has, in millivolts: `vdd`
    /// as given, or the part's lowest (`None`: a part without a supply
    /// table).
    pub fn supply_mv(&self) -> Option<u32> {
        self.vdd_mv
            .or_else(|| self.adc.vdd_range_mv().map(|(lo, _)| lo))
    }

    /// The SPI timing of this branch's port at `clock_hz`.
    pub fn timing(
        &self,
        clock_hz: u64,
    ) -> Result<crate::parts::SpiTiming, crate::parts::TimingError> {
        crate::parts::SpiTiming::derive(&self.adc, clock_hz, self.sclk_hz, self.chain)
    }

    /// The most samples per second this branch's converter (its whole
    /// chain) delivers: [`crate::parts::SpiTiming::max_samples_hz`]; when
    /// the clock cannot drive the part, the datasheet's rate times the chain.
    pub fn max_samples_hz(&self, clock_hz: u64) -> f64 {
        self.timing(clock_hz)
            .map_or(self.adc.max_sps as f64 * self.chain as f64, |t| {
                t.max_samples_hz(clock_hz)
            })
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Channel {
    pub name: String,
    /// Index into [`Mix::branches`].
    pub branch: usize,
    pub rate_hz: u64,
    /// Mux input on its branch: device = input / 8, select = input % 8; on
    /// a converter with a command word, its channel.
    pub input: u32,
    /// On a `fronted` branch, the front mux's input the channel is wired
    /// to (device = front_input / 8, select = front_input % 8); `input` is
    /// then the converter's channel the front mux's output drives.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub front_input: Option<u32>,
    pub kind: Option<String>,
    pub bandwidth_hz: Option<f64>,
    pub sync: Option<String>,
    /// Position of its part in the branch's chain: 0 is the part whose
    /// output drives the FPGA's MISO, whose word comes out first.
    pub member: u32,
    /// The rate in each mode (`Modes::names` order; 0: not sampled in
    /// it); empty for a mix without modes.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub rates: Vec<u64>,
}

impl Channel {
    /// Whether `o` is read in the same conversion (same branch, same
    /// converter input, same front mux input).
    pub fn same_conversion(&self, o: &Channel) -> bool {
        self.branch == o.branch && self.input == o.input && self.front_input == o.front_input
    }
}

impl Mix {
    /// The input channel `c`'s mux pins address (device = it / 8, select =
    /// it % 8): its `input`, or on a `fronted` branch its `front_input` (0
    /// for a channel wired straight to the converter: the front mux's pins
    /// are then of no consequence and rest at its first input).
    pub fn pin_input(&self, c: usize) -> u32 {
        let ch = &self.channels[c];
        if self.branches[ch.branch].fronted {
            ch.front_input.unwrap_or(0)
        } else {
            ch.input
        }
    }

    pub fn frame_cycles(&self) -> u64 {
        self.clock_hz * self.frame_us / 1_000_000
    }
    pub fn slice_cycles(&self) -> u64 {
        self.clock_hz * self.slice_us / 1_000_000
    }
    pub fn slices_per_frame(&self) -> u64 {
        self.frame_us / self.slice_us
    }
    /// Samples of `rate_hz` in one frame (whole by validation).
    pub fn samples_per_frame(&self, rate_hz: u64) -> u64 {
        rate_hz * self.frame_us / 1_000_000
    }
    /// Modes in the mix (1 for a mix without modes).
    pub fn mode_count(&self) -> usize {
        self.modes.as_ref().map_or(1, |m| m.names.len())
    }

    /// The mix as it runs in mode `m`: every channel's `rate_hz` is its
    /// rate in that mode (0: not sampled). A mix without modes is itself.
    pub fn in_mode(&self, m: usize) -> Mix {
        let mut mix = self.clone();
        for c in &mut mix.channels {
            if let Some(&r) = c.rates.get(m) {
                c.rate_hz = r;
            }
        }
        mix
    }

    pub fn branch_index(&self, name: &str) -> Option<usize> {
        self.branches.iter().position(|b| b.name == name)
    }
    pub fn channel_index(&self, name: &str) -> Option<usize> {
        self.channels.iter().position(|c| c.name == name)
    }

    /// The channels converted together with `c` (same branch, same mux
    /// input), by chain member: `chain` entries, `None` for a member no
    /// channel reads.
    pub fn conversion_group(&self, c: usize) -> Vec<Option<usize>> {
        let ch = &self.channels[c];
        let mut g = vec![None; self.branches[ch.branch].chain as usize];
        for (i, o) in self.channels.iter().enumerate() {
            if o.same_conversion(ch) {
                g[o.member as usize] = Some(i);
            }
        }
        g
    }

    /// The channel that stands for `c`'s conversion group in the frame
    /// table: the group's first channel in file order.
    pub fn lead_of(&self, c: usize) -> usize {
        let ch = &self.channels[c];
        self.channels
            .iter()
            .position(|o| o.same_conversion(ch))
            .unwrap_or(c)
    }
}

// ---------------------------------------------------------------- loading

/// Reads and validates a mix file.
pub fn load(path: &Path) -> Result<Mix, MixError> {
    let text = std::fs::read_to_string(path).map_err(|e| MixError {
        file: path.to_path_buf(),
        line: 0,
        column: 0,
        field: String::new(),
        message: format!("cannot read: {}", crate::io_words(&e)),
    })?;
    parse(path, &text)
}

/// Parses and validates mix text; `file` is only used in messages.
///
/// A refusal that a higher supply would lift (an SCLK above the part's
/// figure at its lowest supply, no `vdd`) suggests the `vdd` only after
/// the mix with it (and any further `vdd` the mix then needs) has been
/// parsed, scheduled and audited feasible.
pub fn parse(file: &Path, text: &str) -> Result<Mix, MixError> {
    let (r, hint) = parse_once(file, text);
    match (r, hint) {
        (Err(mut e), Some(h)) => {
            if let Some(said) = supply_advice(file, text, h) {
                e.message.push_str(&said);
            }
            Err(e)
        }
        (r, _) => r,
    }
}

/// Parses and validates once: the result, and the supply a refusal hints at.
fn parse_once(file: &Path, text: &str) -> (Result<Mix, MixError>, Option<check::SupplyHint>) {
    let cx = Cx {
        file,
        text,
        hint: Default::default(),
    };
    let r = toml::from_str::<RawMix>(text)
        .map_err(|e| cx.toml_error(&e))
        .and_then(|raw| cx.validate(raw));
    let hint = cx.hint.borrow_mut().take();
    (r, hint)
}

/// The advice for a supply hint, when the mix with that `vdd` (and any
/// further ones its branches then need, at most one per branch) audits
/// feasible: `; say ...`.
fn supply_advice(file: &Path, text: &str, first: check::SupplyHint) -> Option<String> {
    let mut hints = vec![first];
    loop {
        let edits: Vec<(String, u32)> =
            hints.iter().map(|h| (h.branch.clone(), h.vdd_mv)).collect();
        let edited = crate::fixes::with_vdd(text, &edits)?;
        match parse_once(file, &edited) {
            (Ok(_), _) => {
                crate::fixes::feasible(file, &edited, crate::fixes::CANDIDATE_BUDGET)?;
                break;
            }
            (Err(_), Some(h)) if !hints.iter().any(|x| x.branch == h.branch) => hints.push(h),
            _ => return None,
        }
    }
    let said: Vec<String> = hints
        .iter()
        .map(|h| {
            let v = crate::parts::volts(h.vdd_mv);
            format!(
                "say `vdd = {v}` on branch `{}` if its {} runs at {v} V",
                h.branch, h.part
            )
        })
        .collect();
    Some(format!(
        "; {} (the mix then audits feasible)",
        said.join(", and ")
    ))
}
