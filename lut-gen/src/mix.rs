//! The channel-mix file: TOML in, a validated [`Mix`] out.
//!
//! Parsing goes through `toml::Spanned` so that every semantic error (a
//! duplicate name, a rate that gives a fractional number of samples per frame)
//! can still name the line it came from, exactly like a syntax error does.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use toml::Spanned;

use crate::parts::{AdcPart, MuxPart, Start};

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
    pub mux: MuxPart,
    pub mux_devices: u32,
    pub settle_ns: u64,
    /// Parts of `adc` daisy-chained on this branch's port (1: no chain).
    pub chain: u32,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Channel {
    pub name: String,
    /// Index into [`Mix::branches`].
    pub branch: usize,
    pub rate_hz: u64,
    /// Mux input on its branch: device = input / 8, select = input % 8.
    pub input: u32,
    pub kind: Option<String>,
    pub bandwidth_hz: Option<f64>,
    pub sync: Option<String>,
    /// Position of its part in the branch's chain: 0 is the part whose
    /// output drives the FPGA's MISO, whose word comes out first.
    pub member: u32,
}

impl Mix {
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
            if o.branch == ch.branch && o.input == ch.input {
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
            .position(|o| o.branch == ch.branch && o.input == ch.input)
            .unwrap_or(c)
    }
}

// ---------------------------------------------------------------- raw form

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMix {
    name: Option<Spanned<String>>,
    description: Option<String>,
    clock: Option<Spanned<RawClock>>,
    frame: Option<Spanned<RawFrame>>,
    #[serde(default)]
    adc_part: Vec<Spanned<RawAdcPart>>,
    #[serde(default)]
    branch: Vec<Spanned<RawBranch>>,
    #[serde(default)]
    channel: Vec<Spanned<RawChannel>>,
    link: Option<Spanned<RawLink>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLink {
    kind: Spanned<String>,
    baud: Option<Spanned<i64>>,
    parity: Option<Spanned<String>>,
    stop_bits: Option<Spanned<i64>>,
    tlast: Option<Spanned<String>>,
    ready_within: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawClock {
    hz: Spanned<i64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFrame {
    period_us: Spanned<i64>,
    slice_us: Spanned<i64>,
    slots_per_slice: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBranch {
    name: Spanned<String>,
    adc: Spanned<String>,
    sclk_hz: Option<Spanned<i64>>,
    mux: Spanned<String>,
    mux_devices: Option<Spanned<i64>>,
    settle_ns: Option<Spanned<i64>>,
    chain: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAdcPart {
    name: Spanned<String>,
    bits: Spanned<i64>,
    start: Spanned<String>,
    leading_bits: Option<Spanned<i64>>,
    trailing_bits: Option<Spanned<i64>>,
    sclk_min_hz: Option<Spanned<i64>>,
    sclk_max_hz: Spanned<i64>,
    duty_min_pct: Option<Spanned<i64>>,
    setup_ns: Option<Spanned<i64>>,
    quiet_ns: Option<Spanned<i64>>,
    conversion_ns: Option<Spanned<i64>>,
    data_access_ns: Option<Spanned<i64>>,
    max_sps: Spanned<i64>,
    chain_max: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawChannel {
    name: Spanned<String>,
    branch: Spanned<String>,
    rate_hz: Spanned<i64>,
    input: Option<Spanned<i64>>,
    kind: Option<String>,
    /// Integer or float: TOML keeps the two apart.
    bandwidth_hz: Option<Spanned<toml::Value>>,
    sync: Option<Spanned<String>>,
    member: Option<Spanned<i64>>,
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
pub fn parse(file: &Path, text: &str) -> Result<Mix, MixError> {
    let cx = Cx { file, text };
    let raw: RawMix = toml::from_str(text).map_err(|e| cx.toml_error(&e))?;
    cx.validate(raw)
}

struct Cx<'a> {
    file: &'a Path,
    text: &'a str,
}

/// The clock and frame numbers every later check measures against.
struct Timing {
    clock_hz: u64,
    /// Where `clock.hz` is written, for errors that blame the clock.
    clock_span: Range<usize>,
    frame_us: u64,
    slice_us: u64,
    slots_per_slice: Option<u64>,
}

/// The channels as read, before automatic inputs are assigned.
struct ChannelDraft {
    channels: Vec<Channel>,
    /// Per branch: (input, chain member) -> the channel that has it, to name
    /// it in a clash.
    used_inputs: Vec<BTreeMap<(u32, u32), String>>,
    /// Channels without an explicit input, in file order.
    pending_auto: Vec<usize>,
    /// Sync tag -> (channel, where its `sync` is written).
    sync_groups: BTreeMap<String, Vec<(usize, Range<usize>)>>,
}

impl Cx<'_> {
    fn at(
        &self,
        span: Range<usize>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> MixError {
        let (line, column) = line_col(self.text, span.start);
        MixError {
            file: self.file.to_path_buf(),
            line,
            column,
            field: field.into(),
            message: message.into(),
        }
    }

    fn toml_error(&self, e: &toml::de::Error) -> MixError {
        let (line, column) = e
            .span()
            .map(|s| line_col(self.text, s.start))
            .unwrap_or((0, 0));
        let field = field_from_toml_message(e.message(), self.text, e.span());
        // missing and unknown fields point at their table's header too, and
        // already say what is wrong
        let named = ["missing field", "unknown field"]
            .iter()
            .any(|p| e.message().starts_with(p));
        let message = (!named)
            .then(|| header_message(self.text, e.span(), &field))
            .flatten()
            .unwrap_or_else(|| plain(e.message(), &field));
        MixError {
            file: self.file.to_path_buf(),
            line,
            column,
            field,
            message,
        }
    }

    fn positive(&self, v: &Spanned<i64>, field: &str) -> Result<u64, MixError> {
        if *v.get_ref() <= 0 {
            return Err(self.at(
                v.span(),
                field,
                format!("must be positive, got {}", v.get_ref()),
            ));
        }
        Ok(*v.get_ref() as u64)
    }

    fn nonneg(&self, v: &Option<Spanned<i64>>, field: &str, default: u64) -> Result<u64, MixError> {
        match v {
            None => Ok(default),
            Some(x) if *x.get_ref() < 0 => Err(self.at(
                x.span(),
                field,
                format!("must not be negative, got {}", x.get_ref()),
            )),
            Some(x) => Ok(*x.get_ref() as u64),
        }
    }

    /// A `[[adc_part]]` table, checked like every other field.
    fn adc_part(&self, i: usize, p: &RawAdcPart) -> Result<AdcPart, MixError> {
        let f = |k: &str| format!("adc_part[{i}].{k}");
        let name = self.adc_part_name(i, p)?;
        let bits = self.positive(&p.bits, &f("bits"))?;
        if bits > 16 {
            return Err(self.at(
                p.bits.span(),
                f("bits"),
                format!("{bits} data bits: the sample stream carries at most 16"),
            ));
        }
        let start = match p.start.get_ref().as_str() {
            "cs" => Start::Cs,
            "cnv" => Start::Cnv,
            other => return Err(self.unknown_start(i, p, other)),
        };
        let leading_bits = self.nonneg(&p.leading_bits, &f("leading_bits"), 0)?;
        let trailing_bits = self.nonneg(&p.trailing_bits, &f("trailing_bits"), 0)?;
        if leading_bits + bits + trailing_bits > 32 {
            return Err(self.at(
                p.bits.span(),
                f("bits"),
                "leading + data + trailing bits exceed 32 serial clocks per word",
            ));
        }
        if start == Start::Cs && leading_bits == 0 {
            return Err(self.at(
                p.start.span(),
                f("leading_bits"),
                "a \"cs\" part drives its first bit at CS falling, before any clock: it needs at least one leading bit (the MSB cannot be the first bit)",
            ));
        }
        let sclk_max_hz = self.positive(&p.sclk_max_hz, &f("sclk_max_hz"))?;
        let sclk_min_hz = self.nonneg(&p.sclk_min_hz, &f("sclk_min_hz"), 1)?.max(1);
        if sclk_min_hz > sclk_max_hz {
            return Err(self.at(
                p.sclk_min_hz
                    .as_ref()
                    .map(|s| s.span())
                    .unwrap_or(p.sclk_max_hz.span()),
                f("sclk_min_hz"),
                format!("{sclk_min_hz} Hz is above sclk_max_hz {sclk_max_hz} Hz"),
            ));
        }
        let duty_min_pct = self.nonneg(&p.duty_min_pct, &f("duty_min_pct"), 40)?;
        if duty_min_pct > 50 {
            return Err(self.at(
                p.duty_min_pct.as_ref().unwrap().span(),
                f("duty_min_pct"),
                format!("{duty_min_pct} %: no clock has both phases above half the period"),
            ));
        }
        let conversion_ns = self.nonneg(&p.conversion_ns, &f("conversion_ns"), 0)?;
        if start == Start::Cs && conversion_ns != 0 {
            return Err(self.at(
                p.conversion_ns.as_ref().unwrap().span(),
                f("conversion_ns"),
                "a \"cs\" part converts while it is read: conversion_ns applies to \"cnv\" parts only",
            ));
        }
        let max_sps = self.positive(&p.max_sps, &f("max_sps"))?;
        let chain_max = self.adc_part_chain(i, p, start)?;
        Ok(AdcPart {
            name,
            bits: bits as u32,
            start,
            leading_bits: leading_bits as u32,
            trailing_bits: trailing_bits as u32,
            sclk_min_hz,
            sclk_max_hz,
            duty_min_pct: duty_min_pct as u32,
            max_sps,
            setup_ns: self.nonneg(&p.setup_ns, &f("setup_ns"), 10)?,
            quiet_ns: self.nonneg(&p.quiet_ns, &f("quiet_ns"), 0)?,
            conversion_ns,
            data_access_ns: self.nonneg(&p.data_access_ns, &f("data_access_ns"), 0)?,
            data_hold_ns: 0,
            chain_max: chain_max as u32,
        })
    }

    /// `adc_part.name`: lower case, not blank, not a built-in part's.
    fn adc_part_name(&self, i: usize, p: &RawAdcPart) -> Result<String, MixError> {
        let name = p.name.get_ref().trim().to_ascii_lowercase();
        if name.is_empty() {
            return Err(self.at(
                p.name.span(),
                format!("adc_part[{i}].name"),
                "must not be empty",
            ));
        }
        if AdcPart::by_name(&name).is_some() {
            return Err(self.at(
                p.name.span(),
                format!("adc_part[{i}].name"),
                format!("`{name}` is a built-in part; give the declared part its own name"),
            ));
        }
        Ok(name)
    }

    fn unknown_start(&self, i: usize, p: &RawAdcPart, other: &str) -> MixError {
        self.at(
            p.start.span(),
            format!("adc_part[{i}].start"),
            format!("unknown start `{other}` (\"cs\": CS falling starts the conversion, \"cnv\": CNV rising)"),
        )
    }

    /// `adc_part.chain_max`: 1 unless given; only "cnv" parts chain.
    fn adc_part_chain(&self, i: usize, p: &RawAdcPart, start: Start) -> Result<u64, MixError> {
        let Some(c) = &p.chain_max else { return Ok(1) };
        let v = self.positive(c, &format!("adc_part[{i}].chain_max"))?;
        if v > 1 && start == Start::Cs {
            return Err(self.at(
                c.span(),
                format!("adc_part[{i}].chain_max"),
                "chains are read in one CNV-high window: only \"cnv\" parts chain here",
            ));
        }
        Ok(v)
    }

    fn validate(&self, raw: RawMix) -> Result<Mix, MixError> {
        let name = self.mix_name(&raw)?;
        let t = self.timing(&raw)?;
        if raw.branch.is_empty() {
            return Err(self.at(0..0, "branch", "the mix declares no [[branch]]"));
        }
        if raw.channel.is_empty() {
            return Err(self.at(
                0..0,
                "channel",
                "the mix declares no [[channel]]: nothing to sample",
            ));
        }
        let parts = self.declared_parts(&raw)?;
        let branches = self.branches(&raw, &parts, &t)?;
        let mut draft = self.channels(&raw, &branches, &t)?;
        self.assign_auto_inputs(&raw, &branches, &mut draft)?;
        let channels = draft.channels;
        self.check_chain_rates(&raw, &branches, &channels)?;
        self.check_sync_groups(&branches, &channels, &draft.sync_groups)?;
        self.check_chain_sync(&raw, &channels)?;
        self.check_branches_used(&raw, &branches, &channels)?;
        if channels.len() > u16::MAX as usize {
            return Err(self.at(0..0, "channel", "more than 65535 channels"));
        }

        let link = match &raw.link {
            None => None,
            Some(l) => Some(self.link(l, t.clock_hz)?),
        };
        Ok(Mix {
            name,
            description: raw.description.unwrap_or_default(),
            clock_hz: t.clock_hz,
            frame_us: t.frame_us,
            slice_us: t.slice_us,
            slots_per_slice: t.slots_per_slice,
            parts,
            branches,
            channels,
            link,
        })
    }

    /// `name`: present and not blank.
    fn mix_name(&self, raw: &RawMix) -> Result<String, MixError> {
        match &raw.name {
            Some(n) if !n.get_ref().trim().is_empty() => Ok(n.get_ref().clone()),
            Some(n) => Err(self.at(n.span(), "name", "must not be empty")),
            None => Err(self.at(0..0, "name", "missing: every mix has a name")),
        }
    }

    /// `[clock]` and `[frame]`: whole cycles per frame and per slice.
    fn timing(&self, raw: &RawMix) -> Result<Timing, MixError> {
        let clock = raw
            .clock
            .as_ref()
            .ok_or_else(|| self.at(0..0, "clock", "missing table [clock] with `hz`"))?;
        let clock_hz = self.positive(&clock.get_ref().hz, "clock.hz")?;
        let frame = raw.frame.as_ref().ok_or_else(|| {
            self.at(
                0..0,
                "frame",
                "missing table [frame] with `period_us` and `slice_us`",
            )
        })?;
        let fr = frame.get_ref();
        let frame_us = self.positive(&fr.period_us, "frame.period_us")?;
        let slice_us = self.positive(&fr.slice_us, "frame.slice_us")?;
        if frame_us % slice_us != 0 {
            return Err(self.at(
                fr.slice_us.span(),
                "frame.slice_us",
                format!("a {frame_us} us frame is not a whole number of {slice_us} us slices"),
            ));
        }
        let clock_span = clock.get_ref().hz.span();
        for (us, what) in [(frame_us, "frame"), (slice_us, "slice")] {
            if !(clock_hz as u128 * us as u128).is_multiple_of(1_000_000) {
                return Err(self.at(
                    clock_span.clone(),
                    "clock.hz",
                    format!(
                        "{clock_hz} Hz gives {:.3} cycles per {us} us {what}, not a whole number",
                        clock_hz as f64 * us as f64 / 1e6
                    ),
                ));
            }
        }
        let slice_cycles = clock_hz * slice_us / 1_000_000;
        let slots_per_slice = match &fr.slots_per_slice {
            None => None,
            Some(s) => {
                let v = self.positive(s, "frame.slots_per_slice")?;
                if slice_cycles % v != 0 {
                    return Err(self.at(
                        s.span(),
                        "frame.slots_per_slice",
                        format!("{v} slots do not divide a {slice_cycles}-cycle slice into whole cycles"),
                    ));
                }
                Some(v)
            }
        };
        Ok(Timing {
            clock_hz,
            clock_span,
            frame_us,
            slice_us,
            slots_per_slice,
        })
    }

    /// Every `[[adc_part]]`, each checked, names unique.
    fn declared_parts(&self, raw: &RawMix) -> Result<Vec<AdcPart>, MixError> {
        let mut parts: Vec<AdcPart> = Vec::new();
        for (i, p) in raw.adc_part.iter().enumerate() {
            let part = self.adc_part(i, p.get_ref())?;
            if parts.iter().any(|q| q.name == part.name) {
                return Err(self.at(
                    p.get_ref().name.span(),
                    format!("adc_part[{i}].name"),
                    format!("duplicate part name `{}`", part.name),
                ));
            }
            parts.push(part);
        }
        Ok(parts)
    }

    /// Every `[[branch]]`, names unique.
    fn branches(
        &self,
        raw: &RawMix,
        parts: &[AdcPart],
        t: &Timing,
    ) -> Result<Vec<Branch>, MixError> {
        let mut known_parts: Vec<String> = AdcPart::known().iter().map(|s| s.to_string()).collect();
        known_parts.extend(parts.iter().map(|p| p.name.clone()));
        let mut branches = Vec::new();
        let mut branch_names: BTreeMap<String, usize> = BTreeMap::new();
        for (i, b) in raw.branch.iter().enumerate() {
            let b = b.get_ref();
            let f = |k: &str| format!("branch[{i}].{k}");
            let bname = b.name.get_ref().clone();
            if bname.trim().is_empty() {
                return Err(self.at(b.name.span(), f("name"), "must not be empty"));
            }
            if branch_names.insert(bname.clone(), i).is_some() {
                return Err(self.at(
                    b.name.span(),
                    f("name"),
                    format!("duplicate branch name `{bname}`"),
                ));
            }
            branches.push(self.branch(i, b, bname, parts, &known_parts, t)?);
        }
        Ok(branches)
    }

    /// One `[[branch]]` past its name: ADC, chain, mux, SCLK, settling.
    fn branch(
        &self,
        i: usize,
        b: &RawBranch,
        name: String,
        parts: &[AdcPart],
        known_parts: &[String],
        t: &Timing,
    ) -> Result<Branch, MixError> {
        let f = |k: &str| format!("branch[{i}].{k}");
        let wanted = b.adc.get_ref().to_ascii_lowercase();
        let adc = AdcPart::by_name(&wanted)
            .or_else(|| parts.iter().find(|p| p.name == wanted).cloned())
            .ok_or_else(|| {
                self.at(
                    b.adc.span(),
                    f("adc"),
                    format!(
                        "unknown ADC `{}` (known: {})",
                        b.adc.get_ref(),
                        known_parts.join(", ")
                    ),
                )
            })?;
        let chain = self.branch_chain(i, b, &adc)?;
        let mux = MuxPart::by_name(b.mux.get_ref()).ok_or_else(|| {
            self.at(
                b.mux.span(),
                f("mux"),
                format!(
                    "unknown mux `{}` (known: {})",
                    b.mux.get_ref(),
                    MuxPart::known().join(", ")
                ),
            )
        })?;
        let sclk_hz = self.branch_sclk(i, b, &adc)?;
        if t.clock_hz < 2 * adc.sclk_min_hz {
            return Err(self.at(
                t.clock_span.clone(),
                "clock.hz",
                format!(
                    "{} Hz is too slow to generate the {} minimum SCLK",
                    t.clock_hz, adc.name
                ),
            ));
        }
        let mux_devices = self.branch_mux_devices(i, b, &mux)?;
        let settle_ns = match &b.settle_ns {
            None => 0,
            Some(s) if *s.get_ref() < 0 => {
                return Err(self.at(s.span(), f("settle_ns"), "must not be negative"));
            }
            Some(s) => *s.get_ref() as u64,
        };
        Ok(Branch {
            name,
            adc,
            sclk_hz,
            sclk_explicit: b.sclk_hz.is_some(),
            mux,
            mux_devices,
            settle_ns,
            chain,
        })
    }

    /// `branch.chain`: how many parts, within the part's limit.
    fn branch_chain(&self, i: usize, b: &RawBranch, adc: &AdcPart) -> Result<u32, MixError> {
        let Some(c) = &b.chain else { return Ok(1) };
        let v = self.positive(c, &format!("branch[{i}].chain"))?;
        if v > adc.chain_max as u64 {
            return Err(self.at(
                c.span(),
                format!("branch[{i}].chain"),
                format!(
                    "{v} parts in a chain: `{}` allows at most {}",
                    adc.name, adc.chain_max
                ),
            ));
        }
        Ok(v as u32)
    }

    /// `branch.sclk_hz`: the part's maximum unless given, and within its range.
    fn branch_sclk(&self, i: usize, b: &RawBranch, adc: &AdcPart) -> Result<u64, MixError> {
        let Some(s) = &b.sclk_hz else {
            return Ok(adc.sclk_max_hz);
        };
        let v = self.positive(s, &format!("branch[{i}].sclk_hz"))?;
        if v > adc.sclk_max_hz || v < adc.sclk_min_hz {
            return Err(self.at(
                s.span(),
                format!("branch[{i}].sclk_hz"),
                format!(
                    "{v} Hz is outside the {} SCLK range {}..={} Hz",
                    adc.name, adc.sclk_min_hz, adc.sclk_max_hz
                ),
            ));
        }
        Ok(v)
    }

    /// `branch.mux_devices`: 1 to 32, and only with a mux.
    fn branch_mux_devices(&self, i: usize, b: &RawBranch, mux: &MuxPart) -> Result<u32, MixError> {
        let f = |k: &str| format!("branch[{i}].{k}");
        match &b.mux_devices {
            None => Ok(1),
            Some(m) if *mux == MuxPart::NONE => Err(self.at(
                m.span(),
                f("mux_devices"),
                "a branch with mux = \"none\" has no mux devices",
            )),
            Some(m) => {
                let v = self.positive(m, &f("mux_devices"))?;
                if v > 32 {
                    return Err(self.at(
                        m.span(),
                        f("mux_devices"),
                        "at most 32 mux devices per branch",
                    ));
                }
                Ok(v as u32)
            }
        }
    }

    /// Every `[[channel]]`; explicit inputs are taken here, automatic ones
    /// later so that they fill the gaps deterministically.
    fn channels(
        &self,
        raw: &RawMix,
        branches: &[Branch],
        t: &Timing,
    ) -> Result<ChannelDraft, MixError> {
        let mut draft = ChannelDraft {
            channels: Vec::new(),
            used_inputs: vec![BTreeMap::new(); branches.len()],
            pending_auto: Vec::new(),
            sync_groups: BTreeMap::new(),
        };
        let mut channel_names = BTreeSet::new();
        for (i, c) in raw.channel.iter().enumerate() {
            let c = c.get_ref();
            let f = |k: &str| format!("channel[{i}].{k}");
            let cname = c.name.get_ref().clone();
            if cname.trim().is_empty() {
                return Err(self.at(c.name.span(), f("name"), "must not be empty"));
            }
            if !channel_names.insert(cname.clone()) {
                return Err(self.at(
                    c.name.span(),
                    f("name"),
                    format!("duplicate channel name `{cname}`"),
                ));
            }
            let channel = self.channel(i, c, cname, branches, t, &mut draft)?;
            draft.channels.push(channel);
        }
        Ok(draft)
    }

    /// One `[[channel]]` past its name.
    fn channel(
        &self,
        i: usize,
        c: &RawChannel,
        name: String,
        branches: &[Branch],
        t: &Timing,
        draft: &mut ChannelDraft,
    ) -> Result<Channel, MixError> {
        let f = |k: &str| format!("channel[{i}].{k}");
        let branch = self.channel_branch(i, c, branches)?;
        let rate_hz = self.positive(&c.rate_hz, &f("rate_hz"))?;
        let frame_us = t.frame_us;
        if !(rate_hz as u128 * frame_us as u128).is_multiple_of(1_000_000) {
            return Err(self.at(
                c.rate_hz.span(),
                f("rate_hz"),
                format!(
                    "{rate_hz} Hz gives {:.3} samples per {frame_us} us frame, not a whole number \
                     (rates must be multiples of {} Hz){}",
                    rate_hz as f64 * frame_us as f64 / 1e6,
                    hz_text(1e6 / frame_us as f64),
                    frames_that_fit(rate_hz, t.slice_us)
                ),
            ));
        }
        let member = self.channel_member(i, c, &branches[branch])?;
        let input = match &c.input {
            None => {
                draft.pending_auto.push(i);
                u32::MAX
            }
            Some(v) => {
                let b = &branches[branch];
                let used = &mut draft.used_inputs[branch];
                self.channel_input(i, v, &name, member, b, used)?
            }
        };
        let bandwidth_hz = self.channel_bandwidth(i, c)?;
        let sync = match &c.sync {
            None => None,
            Some(s) => {
                if s.get_ref().trim().is_empty() {
                    return Err(self.at(s.span(), f("sync"), "must not be empty"));
                }
                draft
                    .sync_groups
                    .entry(s.get_ref().clone())
                    .or_default()
                    .push((i, s.span()));
                Some(s.get_ref().clone())
            }
        };
        Ok(Channel {
            name,
            branch,
            rate_hz,
            input,
            kind: c.kind.clone(),
            bandwidth_hz,
            sync,
            member,
        })
    }

    /// `channel.branch`: a declared branch, by name.
    fn channel_branch(
        &self,
        i: usize,
        c: &RawChannel,
        branches: &[Branch],
    ) -> Result<usize, MixError> {
        // Branch names are unique by now, so the first match is the one.
        branches
            .iter()
            .position(|b| b.name == *c.branch.get_ref())
            .ok_or_else(|| {
                self.at(
                    c.branch.span(),
                    format!("channel[{i}].branch"),
                    format!(
                        "unknown branch `{}` (declared: {})",
                        c.branch.get_ref(),
                        branches
                            .iter()
                            .map(|b| b.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })
    }

    /// `channel.member`: which part of the branch's chain, 0 unless given.
    fn channel_member(&self, i: usize, c: &RawChannel, b: &Branch) -> Result<u32, MixError> {
        let Some(m) = &c.member else { return Ok(0) };
        let chain = b.chain;
        if *m.get_ref() < 0 || *m.get_ref() >= chain as i64 {
            return Err(self.at(
                m.span(),
                format!("channel[{i}].member"),
                format!(
                    "member {} is beyond branch `{}`: its chain of {chain} part(s) has members 0..={}",
                    m.get_ref(),
                    b.name,
                    chain - 1
                ),
            ));
        }
        Ok(*m.get_ref() as u32)
    }

    /// An explicit `channel.input`: on the branch's muxes and not taken by
    /// another channel of the same chain member.
    fn channel_input(
        &self,
        i: usize,
        v: &Spanned<i64>,
        name: &str,
        member: u32,
        b: &Branch,
        used: &mut BTreeMap<(u32, u32), String>,
    ) -> Result<u32, MixError> {
        let capacity = b.mux.inputs * b.mux_devices;
        if *v.get_ref() < 0 || *v.get_ref() >= capacity as i64 {
            return Err(self.at(
                v.span(),
                format!("channel[{i}].input"),
                format!(
                    "input {} is beyond branch `{}`: {} mux device(s) give inputs 0..={}",
                    v.get_ref(),
                    b.name,
                    b.mux_devices,
                    capacity - 1
                ),
            ));
        }
        let inp = *v.get_ref() as u32;
        if let Some(other) = used.insert((inp, member), name.to_string()) {
            let which = if b.chain > 1 {
                format!(" (chain member {member})")
            } else {
                String::new()
            };
            return Err(self.at(
                v.span(),
                format!("channel[{i}].input"),
                format!(
                    "input {inp}{which} of branch `{}` is already taken by channel `{other}`",
                    b.name
                ),
            ));
        }
        Ok(inp)
    }

    /// `channel.bandwidth_hz`: an integer or a float, positive and finite.
    fn channel_bandwidth(&self, i: usize, c: &RawChannel) -> Result<Option<f64>, MixError> {
        let Some(b) = &c.bandwidth_hz else {
            return Ok(None);
        };
        let v = match b.get_ref() {
            toml::Value::Integer(i) => *i as f64,
            toml::Value::Float(x) => *x,
            other => {
                return Err(self.at(
                    b.span(),
                    format!("channel[{i}].bandwidth_hz"),
                    format!("got {}, expected a number of Hz", value_words(other)),
                ))
            }
        };
        if !(v > 0.0 && v.is_finite()) {
            return Err(self.at(
                b.span(),
                format!("channel[{i}].bandwidth_hz"),
                format!("must be positive, got {v}"),
            ));
        }
        Ok(Some(v))
    }

    /// Channels without an input take the lowest free one of their chain
    /// member, in file order.
    fn assign_auto_inputs(
        &self,
        raw: &RawMix,
        branches: &[Branch],
        draft: &mut ChannelDraft,
    ) -> Result<(), MixError> {
        let channels = &mut draft.channels;
        for &i in &draft.pending_auto {
            let b = channels[i].branch;
            let capacity = branches[b].mux.inputs * branches[b].mux_devices;
            let m = channels[i].member;
            let used_inputs = &mut draft.used_inputs;
            let free = (0..capacity).find(|k| !used_inputs[b].contains_key(&(*k, m))).ok_or_else(|| {
                self.at(
                    raw.channel[i].get_ref().name.span(),
                    format!("channel[{i}].input"),
                    format!(
                        "branch `{}` has no free mux input left ({} device(s), {} inputs); add mux_devices",
                        branches[b].name, branches[b].mux_devices, capacity
                    ),
                )
            })?;
            used_inputs[b].insert((free, m), channels[i].name.clone());
            channels[i].input = free;
        }
        Ok(())
    }

    /// Channels of one branch on one mux input are read in one conversion
    /// (one per chain member): they share every sampling instant.
    fn check_chain_rates(
        &self,
        raw: &RawMix,
        branches: &[Branch],
        channels: &[Channel],
    ) -> Result<(), MixError> {
        for i in 0..channels.len() {
            for j in 0..i {
                let (a, c) = (&channels[j], &channels[i]);
                if a.branch == c.branch && a.input == c.input && a.rate_hz != c.rate_hz {
                    return Err(self.at(
                        raw.channel[i].get_ref().rate_hz.span(),
                        format!("channel[{i}].rate_hz"),
                        format!(
                            "`{}` ({} Hz) and `{}` ({} Hz) are chain members {} and {} of one conversion on branch `{}` (mux input {}): chained parts are sampled together, so they need one rate",
                            c.name, c.rate_hz, a.name, a.rate_hz, c.member, a.member,
                            branches[c.branch].name, c.input
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// A sync group has one rate and at most one conversion per branch.
    fn check_sync_groups(
        &self,
        branches: &[Branch],
        channels: &[Channel],
        sync_groups: &BTreeMap<String, Vec<(usize, Range<usize>)>>,
    ) -> Result<(), MixError> {
        for (tag, members) in sync_groups {
            let mut seen = BTreeMap::new();
            let rate = channels[members[0].0].rate_hz;
            for (i, span) in members {
                let c = &channels[*i];
                if c.rate_hz != rate {
                    return Err(self.at(
                        span.clone(),
                        format!("channel[{i}].sync"),
                        format!(
                            "sync group `{tag}` mixes rates ({} Hz and {} Hz): synchronized channels share every sampling instant, so they need one rate",
                            rate, c.rate_hz
                        ),
                    ));
                }
                if let Some(other) = seen.insert(c.branch, *i) {
                    if channels[other].input == c.input {
                        // Members of one chained conversion: one instant anyway.
                        continue;
                    }
                    return Err(self.at(
                        span.clone(),
                        format!("channel[{i}].sync"),
                        format!(
                            "sync group `{tag}` has `{}` and `{}` on the same branch `{}`: one ADC cannot sample both at one instant",
                            channels[other].name, c.name, branches[c.branch].name
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Members of one chained conversion are in one sync group or none.
    fn check_chain_sync(&self, raw: &RawMix, channels: &[Channel]) -> Result<(), MixError> {
        for i in 0..channels.len() {
            for j in 0..i {
                let (a, c) = (&channels[j], &channels[i]);
                if a.branch == c.branch && a.input == c.input && a.sync != c.sync {
                    let span = raw.channel[i]
                        .get_ref()
                        .sync
                        .as_ref()
                        .map(|s| s.span())
                        .unwrap_or(raw.channel[i].get_ref().name.span());
                    return Err(self.at(
                        span,
                        format!("channel[{i}].sync"),
                        format!(
                            "`{}` and `{}` are read in one chained conversion, so they are in the same sync group or none: give them the same `sync`",
                            c.name, a.name
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Every branch samples at least one channel.
    fn check_branches_used(
        &self,
        raw: &RawMix,
        branches: &[Branch],
        channels: &[Channel],
    ) -> Result<(), MixError> {
        for (bi, b) in branches.iter().enumerate() {
            if !channels.iter().any(|c| c.branch == bi) {
                let span = raw.branch[bi].get_ref().name.span();
                return Err(self.at(
                    span,
                    format!("branch[{bi}].name"),
                    format!("branch `{}` has no channels", b.name),
                ));
            }
        }
        Ok(())
    }

    /// `[link]`: the kind, and for a UART a baud the clock can divide to
    /// within [`MAX_BAUD_ERROR_PCT`].
    fn link(&self, l: &Spanned<RawLink>, clock_hz: u64) -> Result<LinkSpec, MixError> {
        let r = l.get_ref();
        let kind = match r.kind.get_ref().as_str() {
            "uart" => LinkKind::Uart,
            "axis" => return self.axis_link(l),
            other => {
                return Err(self.at(
                    r.kind.span(),
                    "link.kind",
                    format!("unknown link kind `{other}` (known: \"uart\", \"axis\")"),
                ))
            }
        };
        for (v, k) in [
            (r.tlast.as_ref().map(|x| x.span()), "link.tlast"),
            (
                r.ready_within.as_ref().map(|x| x.span()),
                "link.ready_within",
            ),
        ] {
            if let Some(sp) = v {
                return Err(self.at(
                    sp,
                    k,
                    "only an AXI4-Stream link (kind = \"axis\") has this key",
                ));
            }
        }
        let baud_raw = r
            .baud
            .as_ref()
            .ok_or_else(|| self.at(l.span(), "link.baud", "missing: a UART link needs `baud`"))?;
        let baud = self.positive(baud_raw, "link.baud")?;
        let div = link::UartFormat::divider(clock_hz, baud);
        let real = link::UartFormat::real_baud(clock_hz, div);
        if div < MIN_BAUD_DIVIDER {
            return Err(self.at(
                baud_raw.span(),
                "link.baud",
                format!(
                    "{baud} baud from a {clock_hz} Hz clock is {div} cycle(s) per bit; the link needs at least {MIN_BAUD_DIVIDER} (at most {} baud)",
                    clock_hz / MIN_BAUD_DIVIDER as u64
                ),
            ));
        }
        let err = (real - baud as f64).abs() / baud as f64 * 100.0;
        if err > MAX_BAUD_ERROR_PCT {
            return Err(self.at(
                baud_raw.span(),
                "link.baud",
                format!(
                    "the nearest divider of the {clock_hz} Hz clock ({div}) gives {real:.0} baud, {err:.2} % off {baud}; a receiver tolerates about {MAX_BAUD_ERROR_PCT} %"
                ),
            ));
        }
        let parity = match &r.parity {
            None => link::Parity::None,
            Some(p) => link::Parity::parse(p.get_ref()).ok_or_else(|| {
                self.at(
                    p.span(),
                    "link.parity",
                    format!(
                        "unknown parity `{}` (\"none\", \"even\" or \"odd\")",
                        p.get_ref()
                    ),
                )
            })?,
        };
        let stop_bits = match &r.stop_bits {
            None => 1,
            Some(s) => match *s.get_ref() {
                1 | 2 => *s.get_ref() as u8,
                v => {
                    return Err(self.at(
                        s.span(),
                        "link.stop_bits",
                        format!("{v} stop bits: 1 or 2"),
                    ))
                }
            },
        };
        Ok(LinkSpec {
            kind,
            tlast: link::Tlast::Slice,
            ready_within: 1,
            baud,
            parity,
            stop_bits,
            line: line_col(self.text, baud_raw.span().start).0,
            column: line_col(self.text, baud_raw.span().start).1,
        })
    }

    /// `[link]` with `kind = "axis"`: `tlast` (`"slice"` or `"frame"`) and
    /// `ready_within` (cycles, default 1: an always-ready slave); the UART's
    /// keys are refused.
    fn axis_link(&self, l: &Spanned<RawLink>) -> Result<LinkSpec, MixError> {
        let r = l.get_ref();
        for (v, k) in [
            (r.baud.as_ref().map(|x| x.span()), "link.baud"),
            (r.parity.as_ref().map(|x| x.span()), "link.parity"),
            (r.stop_bits.as_ref().map(|x| x.span()), "link.stop_bits"),
        ] {
            if let Some(sp) = v {
                return Err(self.at(
                    sp,
                    k,
                    "an AXI4-Stream link has no baud, parity or stop bits",
                ));
            }
        }
        let tlast = match &r.tlast {
            None => link::Tlast::Slice,
            Some(t) => link::Tlast::parse(t.get_ref()).ok_or_else(|| {
                self.at(
                    t.span(),
                    "link.tlast",
                    format!("unknown tlast `{}` (\"slice\" or \"frame\")", t.get_ref()),
                )
            })?,
        };
        let ready_within = match &r.ready_within {
            None => 1,
            Some(v) => {
                let n = self.positive(v, "link.ready_within")?;
                u32::try_from(n).map_err(|_| {
                    self.at(
                        v.span(),
                        "link.ready_within",
                        format!("{n} cycles is too many"),
                    )
                })?
            }
        };
        let key = line_col(
            self.text,
            r.ready_within.as_ref().map_or(l.span(), |v| v.span()).start,
        );
        Ok(LinkSpec {
            kind: LinkKind::Axis,
            tlast,
            ready_within,
            baud: 0,
            parity: link::Parity::None,
            stop_bits: 0,
            line: key.0,
            column: key.1,
        })
    }
}

/// 1-based line and column of a byte offset.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map(|p| offset - p).unwrap_or(offset + 1);
    (line, column)
}

/// toml's messages name the offending key for unknown fields; lift it out so
/// the field is reported the same way semantic errors report theirs.
fn field_from_toml_message(message: &str, text: &str, span: Option<Range<usize>>) -> String {
    if let Some(rest) = message.strip_prefix("unknown field `") {
        if let Some(end) = rest.find('`') {
            let key = &rest[..end];
            return format!("{}{key}", table_prefix(text, span));
        }
    }
    if let Some(rest) = message.strip_prefix("missing field `") {
        if let Some(end) = rest.find('`') {
            // The span starts at the table's header: count that header too.
            let past_header = span.map(|s| {
                let eol = text[s.start.min(text.len())..]
                    .find('\n')
                    .map(|p| s.start + p)
                    .unwrap_or(text.len());
                eol..eol
            });
            return format!("{}{}", table_prefix(text, past_header), &rest[..end]);
        }
    }
    if let Some(s) = span {
        // The key on the offending line, if the span points into a `key = value` line.
        let start = text[..s.start.min(text.len())]
            .rfind('\n')
            .map(|p| p + 1)
            .unwrap_or(0);
        let line = text[start..].lines().next().unwrap_or("");
        // A table header (`[clock]`, `[[branch]]`) names the table itself.
        let header = line.trim().trim_start_matches('[');
        if line.trim().starts_with('[') {
            if let Some(name) = header.split(']').next().filter(|n| !n.trim().is_empty()) {
                return name.trim().to_string();
            }
        }
        if let Some((k, _)) = line.split_once('=') {
            if !k.trim().is_empty() {
                return format!("{}{}", table_prefix(text, Some(s)), k.trim());
            }
        }
    }
    "(syntax)".into()
}

/// The message for an error that points at a table header, where serde's
/// words would describe its own machinery: `[[clock]]` for the one `[clock]`
/// table, or `[frame.x]`, a table the mix format does not have.
fn header_message(text: &str, span: Option<Range<usize>>, field: &str) -> Option<String> {
    let s = span?;
    let start = text[..s.start.min(text.len())]
        .rfind('\n')
        .map_or(0, |p| p + 1);
    let line = text[start..].lines().next()?.trim();
    if !line.starts_with('[') {
        return None;
    }
    if line.starts_with("[[") && !field.contains('.') {
        return Some(format!(
            "`[[{field}]]` makes a list of tables; a mix has one table, written `[{field}]`"
        ));
    }
    let (table, key) = field.rsplit_once('.')?;
    Some(format!("`[{table}]` has no table `{key}`"))
}

/// `channel[3].` for a position inside the fourth `[[channel]]` table.
fn table_prefix(text: &str, span: Option<Range<usize>>) -> String {
    let Some(span) = span else {
        return String::new();
    };
    let upto = &text[..span.start.min(text.len())];
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let mut current = String::new();
    for line in upto.lines() {
        let t = line.trim();
        if let Some(name) = t.strip_prefix("[[").and_then(|r| r.split("]]").next()) {
            let name = name.trim().to_string();
            let n = counts.entry(name.clone()).or_insert(0);
            current = format!("{name}[{n}].");
            *n += 1;
        } else if let Some(name) = t.strip_prefix('[').and_then(|r| r.split(']').next()) {
            current = format!("{}.", name.trim());
        }
    }
    current
}

/// Frame periods (whole slices, at most 10 s) in which `rate_hz` gives a
/// whole number of samples, as advice after a fractional count.
/// A frequency as people write it: `100` for 100.000, `0.5` for 0.500,
/// `33.333` where the digits do not end.
fn hz_text(hz: f64) -> String {
    let t = format!("{hz:.3}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn frames_that_fit(rate_hz: u64, slice_us: u64) -> String {
    let g = gcd(rate_hz, 1_000_000);
    let step = slice_us / gcd(slice_us, 1_000_000 / g) * (1_000_000 / g);
    let fits: Vec<String> = (1..=3)
        .map(|k| k * step)
        .filter(|t| *t <= 10_000_000)
        .map(|t| format!("{t} us"))
        .collect();
    if fits.is_empty() {
        String::new()
    } else {
        format!(
            "; frame periods that fit {rate_hz} Hz with {slice_us} us slices: {}",
            fits.join(", ")
        )
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// A TOML value as the user wrote it, for "got ..." in a message.
fn value_words(v: &toml::Value) -> String {
    match v {
        toml::Value::String(t) => format!("the text \"{t}\""),
        toml::Value::Integer(i) => format!("the number `{i}`"),
        toml::Value::Float(x) => format!("the number `{x}`"),
        toml::Value::Boolean(b) => format!("`{b}`"),
        toml::Value::Datetime(d) => format!("the date `{d}`"),
        toml::Value::Array(_) => "a list".into(),
        toml::Value::Table(_) => "a table".into(),
    }
}

/// A TOML error message in the words of the mix format, not of Rust's
/// types: `expected i64` becomes "expected a whole number", of Hz, us or ns
/// by the unit of `field`.
pub fn plain(m: &str, field: &str) -> String {
    let key = field.rsplit('.').next().unwrap_or("");
    let unit = if key.ends_with("_hz") || key == "hz" {
        " of Hz"
    } else if key.ends_with("_us") {
        " of microseconds"
    } else if key.ends_with("_ns") {
        " of nanoseconds"
    } else {
        ""
    };
    let mut out = m.to_string();
    for t in ["i64", "u64", "u32", "i32", "usize", "u16", "u8"] {
        out = out.replace(
            &format!("expected {t}"),
            &format!("expected a whole number{unit}"),
        );
    }
    for (rust, words) in [
        ("expected f64", "expected a number"),
        ("invalid type: floating point", "got the number"),
        ("invalid type: string", "got the text"),
        ("invalid type: integer", "got the number"),
        ("invalid type: boolean", "got"),
        ("invalid type: sequence", "got a list"),
        ("invalid type: map", "got a table"),
        ("expected a boolean", "expected true or false"),
        ("expected a string", "expected a name in quotes"),
        ("expected struct ", "expected the table "),
        ("expected a sequence", "expected a list"),
        (
            "number too large to fit in target type",
            "the number is too large (at most 9223372036854775807)",
        ),
        (
            "number too small to fit in target type",
            "the number is too small",
        ),
    ] {
        out = out.replace(rust, words);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
name = "t"
[clock]
hz = 48_000_000
[frame]
period_us = 10_000
slice_us = 1_000
[[branch]]
name = "a"
adc = "ad7940"
mux = "tmux1108"
[[channel]]
name = "c0"
branch = "a"
rate_hz = 1_000
bandwidth_hz = 400
"#;

    fn err(text: &str) -> MixError {
        parse(Path::new("m.toml"), text).unwrap_err()
    }

    #[test]
    fn messages_use_the_mix_format_words_not_rust_types() {
        let e = err(&GOOD.replace("rate_hz = 1_000", "rate_hz = 1000.5"));
        assert_eq!(e.field, "channel[0].rate_hz", "{e}");
        assert!(e.message.contains("expected a whole number of Hz"), "{e}");
        let e = err(&GOOD.replace("rate_hz = 1_000", "rate_hz = \"fast\""));
        assert!(
            !e.message.contains("i64") && e.message.contains("got the text"),
            "{e}"
        );
        let e = err(&GOOD.replace("slice_us = 1_000", "slice_us = 1.5"));
        assert!(e.message.contains("whole number of microseconds"), "{e}");
        // a fractional count per frame: frame periods that fit the rate
        let e = err(&GOOD.replace("rate_hz = 1_000", "rate_hz = 1_050"));
        assert!(
            e.message.contains(
                "frame periods that fit 1050 Hz with 1000 us slices: 20000 us, 40000 us, 60000 us"
            ),
            "{e}"
        );
        // the step between rates in the units people write, not 100.000
        assert!(
            e.message.contains("(rates must be multiples of 100 Hz)"),
            "{e}"
        );
        let e = err(&GOOD
            .replace("period_us = 10_000", "period_us = 30_000")
            .replace("rate_hz = 1_000", "rate_hz = 50"));
        assert!(e.message.contains("multiples of 33.333 Hz)"), "{e}");
        // a taken mux input names the channel that has it
        let two = GOOD.replace("bandwidth_hz = 400", "bandwidth_hz = 400\ninput = 2")
            + "[[channel]]\nname = \"c1\"\nbranch = \"a\"\nrate_hz = 1_000\ninput = 2\n";
        let e = err(&two);
        assert!(e.message.contains("already taken by channel `c0`"), "{e}");
    }

    #[test]
    fn good_mix_parses() {
        let m = parse(Path::new("m.toml"), GOOD).unwrap();
        assert_eq!(m.clock_hz, 48_000_000);
        assert_eq!(m.frame_cycles(), 480_000);
        assert_eq!(m.slice_cycles(), 48_000);
        assert_eq!(m.channels[0].input, 0);
        assert_eq!(m.channels[0].bandwidth_hz, Some(400.0));
        assert_eq!(m.branches[0].sclk_hz, 2_500_000);
    }

    #[test]
    fn unknown_key_names_line_and_field() {
        let e = err(&GOOD.replace("rate_hz = 1_000", "rate_hz = 1_000\nrat_hz = 3"));
        assert_eq!(e.line, 16, "{e}");
        assert_eq!(e.field, "channel[0].rat_hz", "{e}");
        assert!(e.message.contains("unknown field"), "{e}");
    }

    #[test]
    fn fractional_samples_per_frame() {
        let e = err(&GOOD.replace("rate_hz = 1_000", "rate_hz = 1_050"));
        assert_eq!(e.field, "channel[0].rate_hz");
        assert_eq!(e.line, 15);
        assert!(e.message.contains("10.500 samples"), "{e}");
    }

    #[test]
    fn fractional_cycles_per_slice() {
        let e = err(&GOOD.replace("48_000_000", "48_000_500"));
        assert_eq!(e.field, "clock.hz");
        assert_eq!(e.line, 4);
    }

    #[test]
    fn zero_and_negative_values() {
        assert_eq!(
            err(&GOOD.replace("rate_hz = 1_000", "rate_hz = 0")).field,
            "channel[0].rate_hz"
        );
        assert_eq!(
            err(&GOOD.replace("slice_us = 1_000", "slice_us = -1")).field,
            "frame.slice_us"
        );
    }

    #[test]
    fn unknown_branch_adc_mux() {
        assert_eq!(
            err(&GOOD.replace("branch = \"a\"", "branch = \"b\"")).field,
            "channel[0].branch"
        );
        assert_eq!(
            err(&GOOD.replace("ad7940", "ad9999")).field,
            "branch[0].adc"
        );
        assert_eq!(
            err(&GOOD.replace("tmux1108", "cd4051")).field,
            "branch[0].mux"
        );
    }

    #[test]
    fn duplicate_names_and_inputs() {
        let dup = format!("{GOOD}\n[[channel]]\nname = \"c0\"\nbranch = \"a\"\nrate_hz = 100\n");
        let e = err(&dup);
        assert_eq!(e.field, "channel[1].name");
        assert_eq!(e.line, 19);
        let twice = format!(
            "{}\n[[channel]]\nname = \"c1\"\nbranch = \"a\"\nrate_hz = 100\ninput = 0\n",
            GOOD.replace("bandwidth_hz = 400", "input = 0")
        );
        assert_eq!(err(&twice).field, "channel[1].input");
        let beyond = GOOD.replace("bandwidth_hz = 400", "input = 8");
        assert!(err(&beyond).message.contains("beyond"));
    }

    #[test]
    fn empty_mix() {
        let e = err(
            "name = \"x\"\n[clock]\nhz = 1000000\n[frame]\nperiod_us = 1000\nslice_us = 1000\n",
        );
        assert_eq!(e.field, "branch");
    }

    #[test]
    fn syntax_error_has_line() {
        let e = err("name = \"x\"\n[clock\n");
        assert_eq!(e.line, 2);
        // A line with no key still names something (found by proptest).
        let e = err("name = \"x\"\n=description = \"y\"\n");
        assert_eq!((e.line, e.field.as_str()), (2, "(syntax)"), "{e}");
    }

    const CHAIN: &str = r#"
name = "t"
[clock]
hz = 48_000_000
[frame]
period_us = 10_000
slice_us = 1_000
[[branch]]
name = "a"
adc = "ad7685"
chain = 2
mux = "none"
[[channel]]
name = "x"
branch = "a"
member = 0
rate_hz = 8_000
[[channel]]
name = "y"
branch = "a"
member = 1
rate_hz = 8_000
"#;

    #[test]
    fn chain_members_share_one_conversion() {
        let m = parse(Path::new("m.toml"), CHAIN).unwrap();
        assert_eq!(m.branches[0].chain, 2);
        assert_eq!(m.conversion_group(1), vec![Some(0), Some(1)]);
        assert_eq!(m.lead_of(1), 0);
    }

    #[test]
    fn chain_members_with_different_rates_are_rejected() {
        let e = err(&CHAIN.replacen("rate_hz = 8_000", "rate_hz = 4_000", 1));
        assert_eq!(e.field, "channel[1].rate_hz", "{e}");
        assert_eq!(e.line, 22, "{e}");
        assert!(
            e.message.contains("chained parts are sampled together"),
            "{e}"
        );
    }

    #[test]
    fn chain_limits_and_members() {
        let e = err(&CHAIN.replace("chain = 2", "chain = 9"));
        assert_eq!(e.field, "branch[0].chain", "{e}");
        assert!(e.message.contains("at most 8"), "{e}");
        let e = err(&CHAIN.replace("member = 1", "member = 2"));
        assert_eq!(e.field, "channel[1].member", "{e}");
        let e = err(&CHAIN.replace("member = 1", "member = 0"));
        assert_eq!(e.field, "channel[1].input", "{e}");
    }

    #[test]
    fn declared_parts_are_validated() {
        let part = "[[adc_part]]\nname = \"p\"\nbits = 12\nstart = \"cs\"\nleading_bits = 4\nsclk_max_hz = 20_000_000\nmax_sps = 1_000_000\n";
        let good = format!("{}{part}", GOOD.replace("ad7940", "p"));
        let m = parse(Path::new("m.toml"), &good).unwrap();
        assert_eq!(m.branches[0].adc.bits, 12);
        assert_eq!(m.parts.len(), 1);
        let e = err(&good.replace("start = \"cs\"", "start = \"cnvst\""));
        assert_eq!((e.field.as_str(), e.line), ("adc_part[0].start", 20), "{e}");
        let e = err(&good.replace("bits = 12", "bits = 20"));
        assert_eq!(e.field, "adc_part[0].bits", "{e}");
        let e = err(&good.replace("max_sps = 1_000_000", "max_sps = 1_000_000\nchain_max = 2"));
        assert_eq!(e.field, "adc_part[0].chain_max", "{e}");
        let e = err(&good.replace("sclk_max_hz = 20_000_000\n", ""));
        assert_eq!(e.field, "adc_part[0].sclk_max_hz", "{e}");
    }
}
