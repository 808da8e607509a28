//! The mix's checks: the context errors are made in, the top-level
//! order of the checks, and `[clock]`, `[frame]` and `[[adc_part]]`.

use std::ops::Range;
use std::path::Path;

use toml::Spanned;

use super::raw::*;
use super::words::*;
use super::*;
use crate::parts::AdcPart;

/// What every check needs to make an error: the file's name, and its text to
/// turn a span into a line and column.
pub(super) struct Cx<'a> {
    pub(super) file: &'a Path,
    pub(super) text: &'a str,
    /// Set by a refusal a higher supply would lift (`branch_sclk`): the
    /// `vdd` that `parse` tries before it suggests it.
    pub(super) hint: std::cell::RefCell<Option<SupplyHint>>,
}

/// A `vdd` a branch could say, for `parse` to try on the mix.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct SupplyHint {
    pub(super) branch: String,
    pub(super) vdd_mv: u32,
    pub(super) part: String,
}

/// The clock and frame numbers every later check measures against.
pub(super) struct Timing {
    pub(super) clock_hz: u64,
    /// Where `clock.hz` is written, for errors that blame the clock.
    pub(super) clock_span: Range<usize>,
    pub(super) frame_us: u64,
    pub(super) slice_us: u64,
    pub(super) slots_per_slice: Option<u64>,
}

impl Cx<'_> {
    pub(super) fn at(
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

    pub(super) fn toml_error(&self, e: &toml::de::Error) -> MixError {
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
            .or_else(|| unknown_words(e.message(), header_at(self.text, e.span())))
            .unwrap_or_else(|| toml_words(e.message(), &field));
        MixError {
            file: self.file.to_path_buf(),
            line,
            column,
            field,
            message,
        }
    }

    pub(super) fn positive(&self, v: &Spanned<i64>, field: &str) -> Result<u64, MixError> {
        if *v.get_ref() <= 0 {
            return Err(self.at(
                v.span(),
                field,
                format!("must be positive, got {}", v.get_ref()),
            ));
        }
        Ok(*v.get_ref() as u64)
    }

    pub(super) fn nonneg(
        &self,
        v: &Option<Spanned<i64>>,
        field: &str,
        default: u64,
    ) -> Result<u64, MixError> {
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

    pub(super) fn validate(&self, raw: RawMix) -> Result<Mix, MixError> {
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
        let decl = self.declare_channels(&raw)?;
        let mut draft = self.channels(&decl, &branches, &t)?;
        self.assign_auto_inputs(&decl, &branches, &mut draft)?;
        let mut channels = draft.channels;
        self.check_front_wiring(&decl, &branches, &channels)?;
        self.check_chain_rates(&decl, &branches, &channels)?;
        let slice_cycles = (t.slice_us as u128 * t.clock_hz as u128 / 1_000_000) as u64;
        self.check_sync_groups(
            &decl,
            &branches,
            &channels,
            &draft.sync_groups,
            (t.clock_hz, slice_cycles),
        )?;
        self.check_chain_sync(&decl, &channels)?;
        self.check_branches_used(&raw, &branches, &channels)?;
        if channels.len() > u16::MAX as usize {
            return Err(self.at(0..0, "channel", "more than 65535 channels"));
        }

        let modes = self.modes(&raw, &decl, &branches, &mut channels, &t)?;
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
            modes,
        })
    }

    /// `[[mode]]`, `[modes]`, each channel's `rates` and the `[[trigger]]`s.
    fn modes(
        &self,
        raw: &RawMix,
        decl: &[super::bulk::Declared],
        branches: &[Branch],
        channels: &mut [Channel],
        t: &Timing,
    ) -> Result<Option<Modes>, MixError> {
        let named = self.mode_names(raw)?;
        let names = named.as_ref().map(|(n, _)| n.as_slice());
        for (c, d) in channels.iter_mut().zip(decl) {
            c.rates = self.channel_rates(d, c.rate_hz, names, t)?;
        }
        let Some((names, select)) = named else {
            return Ok(None);
        };
        self.check_mode_rates(decl, channels, &names)?;
        self.check_modes_sample(raw, &names, channels)?;
        self.check_mode_commands(raw, &names, branches, channels, t)?;
        let triggers = self.triggers(raw, &names, select, branches, channels)?;
        Ok(Some(Modes {
            names,
            select,
            triggers,
        }))
    }

    /// `name`: present and not blank.
    pub(super) fn mix_name(&self, raw: &RawMix) -> Result<String, MixError> {
        match &raw.name {
            Some(n) if !n.get_ref().trim().is_empty() => Ok(n.get_ref().clone()),
            Some(n) => Err(self.at(n.span(), "name", "must not be empty")),
            None => Err(self.at(0..0, "name", "missing: every mix has a name")),
        }
    }

    /// `[clock]` and `[frame]`: whole cycles per frame and per slice.
    pub(super) fn timing(&self, raw: &RawMix) -> Result<Timing, MixError> {
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
    pub(super) fn declared_parts(&self, raw: &RawMix) -> Result<Vec<AdcPart>, MixError> {
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
}
