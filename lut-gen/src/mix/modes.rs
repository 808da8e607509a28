//! Modes (`[[mode]]`, `[modes]`, `[[trigger]]`, a channel's `rates`): a
//! mix that samples its channels at other rates in other modes, switched at
//! frame starts by a pin or by triggers evaluated on the samples
//! (docs/mix-format.md, "Modes"; docs/timing.md, "Mode switches").

use std::collections::BTreeSet;

use serde::Serialize;
use toml::Spanned;

use super::bulk::{Declared, Range};
use super::check::Timing;
use super::raw::*;
use super::words::{hz_text, line_col};
use super::*;

/// How the mode in force is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ModeSelect {
    /// The input `mode_sel` names the mode (binary), sampled once per frame.
    Pin,
    /// `[[trigger]]`s evaluated on chip on each frame's samples.
    Auto,
}

impl ModeSelect {
    pub fn name(self) -> &'static str {
        match self {
            ModeSelect::Pin => "pin",
            ModeSelect::Auto => "auto",
        }
    }
}

/// `trigger.when`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum When {
    /// Any watched channel's code above `level`.
    Above,
    /// Every watched channel's code below `level`.
    Below,
}

impl When {
    pub fn name(self) -> &'static str {
        match self {
            When::Above => "above",
            When::Below => "below",
        }
    }
}

/// One `[[trigger]]`, resolved: modes and channels by index.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Trigger {
    /// The mode it switches to.
    pub to: usize,
    /// The mode it leaves; `None`: every mode but `to`.
    pub from: Option<usize>,
    pub when: When,
    /// An ADC code: the condition compares each watched sample's code with it.
    pub level: u32,
    /// Watched channels (indices into `Mix::channels`), in file order, no repeats.
    pub channels: Vec<usize>,
    /// Consecutive frames the condition must hold (at least 1).
    pub for_frames: u32,
    /// The mix file's line of the `[[trigger]]` table.
    pub line: usize,
}

impl Trigger {
    /// Whether the trigger is armed in mode `m`.
    pub fn leaves(&self, m: usize) -> bool {
        m != self.to && self.from.is_none_or(|f| f == m)
    }
}

/// The mix's modes: names (the first is the mode after reset), how the mode
/// is selected and, for `auto`, the triggers in file order (the first that
/// fires in a frame wins).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Modes {
    pub names: Vec<String>,
    pub select: ModeSelect,
    pub triggers: Vec<Trigger>,
}

impl Modes {
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }
    /// Bits of `mode_sel` and `mode`: enough for every mode's number.
    pub fn select_bits(&self) -> u32 {
        crate::schedule::bits_for(self.names.len() as u64)
    }
}

impl Cx<'_> {
    /// `[[mode]]` and `[modes]`: the names and the select kind, or `None`
    /// for a mix without modes (then neither `rates` nor `[[trigger]]` may appear).
    pub(super) fn mode_names(
        &self,
        raw: &RawMix,
    ) -> Result<Option<(Vec<String>, ModeSelect)>, MixError> {
        if raw.mode.is_empty() {
            if let Some(m) = &raw.modes {
                return Err(self.at(
                    m.get_ref().select.span(),
                    "modes.select",
                    "[modes] without any [[mode]]: declare the modes first (`[[mode]]` with a `name`, the first is the mode after reset)",
                ));
            }
            if let Some(t) = raw.trigger.first() {
                return Err(self.at(
                    t.span(),
                    "trigger[0]",
                    "a [[trigger]] without any [[mode]] to switch to",
                ));
            }
            return Ok(None);
        }
        let mut names: Vec<String> = Vec::new();
        for (i, m) in raw.mode.iter().enumerate() {
            let n = m.get_ref().name.get_ref();
            let field = format!("mode[{i}].name");
            if n.trim().is_empty() {
                return Err(self.at(m.get_ref().name.span(), field, "must not be empty"));
            }
            if names.contains(n) {
                return Err(self.at(
                    m.get_ref().name.span(),
                    field,
                    format!("duplicate mode name `{n}`"),
                ));
            }
            names.push(n.clone());
        }
        if names.len() < 2 {
            return Err(self.at(
                raw.mode[0].get_ref().name.span(),
                "mode[0].name",
                "a single mode never switches: declare at least two [[mode]] tables, or none",
            ));
        }
        let Some(sel) = &raw.modes else {
            return Err(self.at(
                raw.mode[0].span(),
                "modes.select",
                "missing: a mix with [[mode]] says how the mode is chosen, `[modes] select = \"pin\"` or `\"auto\"`",
            ));
        };
        let s = &sel.get_ref().select;
        let select = match s.get_ref().as_str() {
            "pin" => ModeSelect::Pin,
            "auto" => ModeSelect::Auto,
            other => {
                return Err(self.at(
                    s.span(),
                    "modes.select",
                    format!("`{other}` is not a mode select: use \"pin\" (the `mode_sel` input) or \"auto\" (the [[trigger]] tables)"),
                ))
            }
        };
        Ok(Some((names, select)))
    }

    /// A channel's rate in every mode: `rates` overrides `rate_hz`; 0 is
    /// "not sampled in that mode".
    pub(super) fn channel_rates(
        &self,
        d: &Declared,
        rate_hz: u64,
        names: Option<&[String]>,
        t: &Timing,
    ) -> Result<Vec<u64>, MixError> {
        let Some(rates) = &d.raw.rates else {
            return Ok(names.map_or(Vec::new(), |n| vec![rate_hz; n.len()]));
        };
        let Some(names) = names else {
            return Err(self.at(
                rates.span(),
                d.field("rates"),
                d.say("`rates` gives a rate per mode, but the mix declares no [[mode]]"),
            ));
        };
        let mut out = vec![rate_hz; names.len()];
        for (key, v) in rates.get_ref() {
            let field = d.field(&format!("rates.{key}"));
            let Some(m) = names.iter().position(|n| n == key) else {
                return Err(self.at(
                    v.span(),
                    field,
                    d.say(format!(
                        "unknown mode `{key}` (the modes are {})",
                        quoted(names)
                    )),
                ));
            };
            let hz = self
                .nonneg(&Some(v.clone()), &field, 0)
                .map_err(|e| MixError {
                    message: d.say(e.message),
                    ..e
                })?;
            if !(hz as u128 * t.frame_us as u128).is_multiple_of(1_000_000) {
                return Err(self.at(
                    v.span(),
                    field,
                    d.say(format!(
                        "{hz} Hz gives {:.3} samples per {} us frame, not a whole number (rates must be multiples of {} Hz; 0: not sampled in mode `{key}`)",
                        hz as f64 * t.frame_us as f64 / 1e6,
                        t.frame_us,
                        hz_text(1e6 / t.frame_us as f64)
                    )),
                ));
            }
            out[m] = hz;
        }
        Ok(out)
    }

    /// Chained members and sync groups share every instant in every mode,
    /// so they share each mode's rate.
    pub(super) fn check_mode_rates(
        &self,
        decl: &[Declared],
        channels: &[Channel],
        names: &[String],
    ) -> Result<(), MixError> {
        for i in 0..channels.len() {
            for j in 0..i {
                let (a, c) = (&channels[j], &channels[i]);
                let chained = a.same_conversion(c);
                let synced = a.sync.is_some() && a.sync == c.sync;
                let Some(m) = (0..names.len()).find(|&m| a.rates[m] != c.rates[m]) else {
                    continue;
                };
                if !chained && !synced {
                    continue;
                }
                let d = &decl[i];
                let span = d
                    .raw
                    .rates
                    .as_ref()
                    .map_or(d.raw.rate_hz.span(), |r| r.span());
                let why = if chained {
                    "are read in one chained conversion"
                } else {
                    "are in one sync group"
                };
                return Err(self.at(
                    span,
                    d.field("rates"),
                    d.say(format!(
                        "`{}` ({} Hz) and `{}` ({} Hz) in mode `{}`: they {why}, so they need one rate in every mode",
                        c.name, c.rates[m], a.name, a.rates[m], names[m]
                    )),
                ));
            }
        }
        Ok(())
    }

    /// Every mode samples something (a switch takes effect at its first
    /// sample, and a mode of silence is no schedule).
    pub(super) fn check_modes_sample(
        &self,
        raw: &RawMix,
        names: &[String],
        channels: &[Channel],
    ) -> Result<(), MixError> {
        match (0..names.len()).find(|&m| channels.iter().all(|c| c.rates[m] == 0)) {
            None => Ok(()),
            Some(m) => Err(self.at(
                raw.mode[m].get_ref().name.span(),
                format!("mode[{m}].name"),
                format!(
                    "mode `{}` samples no channel (every rate is 0 in it)",
                    names[m]
                ),
            )),
        }
    }

    /// Every branch a mode uses runs in the reset mode.  A converter whose
    /// word selects a later conversion (`command_ahead`,
    /// the AD7689's 2) sends, in a frame's last conversions, the words of
    /// the next frame's first ones: the next frame's mode is decided while
    /// this one runs, the one after it is not.  So every mode converts such
    /// a branch at least `ahead` times per frame.  Behind a front mux the
    /// same holds: the front pins follow each mode's table, the words each
    /// mode's conversions, and a frame's last words the next frame's mode.
    pub(super) fn check_mode_commands(
        &self,
        raw: &RawMix,
        names: &[String],
        branches: &[Branch],
        channels: &[Channel],
        t: &Timing,
    ) -> Result<(), MixError> {
        for (b, br) in branches.iter().enumerate() {
            // a mode that uses a branch the reset mode leaves out: the
            // branch's mux would have no reset value to hold
            let on = |m: usize| channels.iter().any(|c| c.branch == b && c.rates[m] > 0);
            if let Some(m) = (1..names.len()).find(|&m| !on(0) && on(m)) {
                return Err(self.at(raw.branch[b].get_ref().name.span(), format!("branch[{b}].name"), format!(
                    "branch `{}`: the reset mode `{}` does not use it but mode `{}` does: its pins would have no reset value to hold (give it a channel in `{}`)",
                    br.name, names[0], names[m], names[0]
                )));
            }
            let Some(cmd) = &br.adc.command else { continue };
            let span = raw.branch[b].get_ref().adc.span();
            let ahead = cmd.ahead as u64;
            for (m, name) in names.iter().enumerate() {
                let per_frame: u64 = (channels.iter().filter(|c| c.branch == b && c.member == 0))
                    .map(|c| c.rates[m] * t.frame_us / 1_000_000)
                    .sum();
                if ahead > 0 && per_frame < ahead {
                    return Err(self.at(span, format!("branch[{b}].adc"), format!(
                        "branch `{}`: the {} word selects the conversion {ahead} ahead, but mode `{name}` converts it {per_frame} time(s) per frame: across a switch its last words would select conversions of a frame whose mode is not decided yet; give the branch at least {ahead} conversions per frame in every mode",
                        br.name, br.adc.name
                    )));
                }
            }
        }
        Ok(())
    }

    /// Every `[[trigger]]`, resolved and checked against the modes' rates.
    pub(super) fn triggers(
        &self,
        raw: &RawMix,
        names: &[String],
        select: ModeSelect,
        branches: &[Branch],
        channels: &[Channel],
    ) -> Result<Vec<Trigger>, MixError> {
        if select == ModeSelect::Pin {
            if let Some(t) = raw.trigger.first() {
                return Err(self.at(
                    t.span(),
                    "trigger[0]",
                    "[modes] select = \"pin\" takes the mode from the `mode_sel` input: a [[trigger]] is for select = \"auto\"",
                ));
            }
            return Ok(Vec::new());
        }
        if raw.trigger.is_empty() {
            let at = raw
                .modes
                .as_ref()
                .map_or(0..0, |m| m.get_ref().select.span());
            return Err(self.at(
                at,
                "modes.select",
                "select = \"auto\" needs at least one [[trigger]] to switch modes",
            ));
        }
        raw.trigger
            .iter()
            .enumerate()
            .map(|(i, t)| self.trigger(i, t, names, branches, channels))
            .collect()
    }

    fn trigger(
        &self,
        i: usize,
        t: &Spanned<RawTrigger>,
        names: &[String],
        branches: &[Branch],
        channels: &[Channel],
    ) -> Result<Trigger, MixError> {
        let (line, _) = line_col(self.text, t.span().start);
        let r = t.get_ref();
        let f = |k: &str| format!("trigger[{i}].{k}");
        let mode = |v: &Spanned<String>, k: &str| {
            names.iter().position(|n| n == v.get_ref()).ok_or_else(|| {
                self.at(
                    v.span(),
                    f(k),
                    format!(
                        "unknown mode `{}` (the modes are {})",
                        v.get_ref(),
                        quoted(names)
                    ),
                )
            })
        };
        let to = mode(&r.to, "to")?;
        let from = r.from.as_ref().map(|v| mode(v, "from")).transpose()?;
        if from == Some(to) {
            return Err(self.at(
                r.to.span(),
                f("to"),
                format!(
                    "`from` and `to` are both `{}`: a trigger leaves one mode for another",
                    names[to]
                ),
            ));
        }
        let when = match r.when.get_ref().as_str() {
            "above" => When::Above,
            "below" => When::Below,
            w => return Err(self.at(r.when.span(), f("when"), format!("`{w}` is not a condition: use \"above\" (any watched channel above `level`) or \"below\" (all of them below)"))),
        };
        let watched = self.watched(&r.channels, &f("channels"), channels)?;
        let for_frames = match &r.for_frames {
            None => 1,
            Some(v) if (1..=i64::from(u16::MAX)).contains(v.get_ref()) => *v.get_ref() as u32,
            Some(v) => {
                return Err(self.at(
                    v.span(),
                    f("for_frames"),
                    format!("must be 1 to {}, got {}", u16::MAX, v.get_ref()),
                ))
            }
        };
        let level = *r.level.get_ref();
        for &c in &watched {
            let part = &branches[channels[c].branch].adc;
            let top = (1i64 << part.bits) - 1;
            if !(0..=top).contains(&level) {
                return Err(self.at(
                    r.level.span(),
                    f("level"),
                    format!(
                        "{level} is outside the code range of `{}` ({}, {} bits: 0 to {top})",
                        channels[c].name, part.name, part.bits
                    ),
                ));
            }
        }
        let trigger = Trigger {
            to,
            from,
            when,
            level: level as u32,
            channels: watched,
            for_frames,
            line,
        };
        for m in (0..names.len()).filter(|&m| trigger.leaves(m)) {
            if let Some(&c) = trigger
                .channels
                .iter()
                .find(|&&c| channels[c].rates[m] == 0)
            {
                return Err(self.at(r.channels.span(), f("channels"), format!(
                    "`{}` is not sampled in mode `{}` (rate 0), which this trigger leaves: a trigger watches samples, so its channels must be sampled in every mode it leaves{}",
                    channels[c].name, names[m],
                    if trigger.from.is_none() { " (without `from`, every mode but `to`)" } else { "" }
                )));
            }
        }
        Ok(trigger)
    }

    /// `trigger.channels`: names or bulk patterns (`T{0..29}`), resolved.
    fn watched(
        &self,
        list: &Spanned<Vec<Spanned<String>>>,
        field: &str,
        channels: &[Channel],
    ) -> Result<Vec<usize>, MixError> {
        let mut out = Vec::new();
        let mut seen = BTreeSet::new();
        for (k, n) in list.get_ref().iter().enumerate() {
            let field = format!("{field}[{k}]");
            let written = n.get_ref();
            let names = match Range::parse(written).map_err(|m| self.at(n.span(), &field, m))? {
                None => vec![written.clone()],
                Some(r) => (0..r.count()).map(|s| r.name(s)).collect(),
            };
            for name in names {
                let Some(c) = channels.iter().position(|c| c.name == name) else {
                    return Err(self.at(n.span(), &field, format!("no channel named `{name}`")));
                };
                if seen.insert(c) {
                    out.push(c);
                }
            }
        }
        if out.is_empty() {
            return Err(self.at(list.span(), field, "watches no channel: name at least one"));
        }
        Ok(out)
    }
}

/// `` `a`, `b` `` for a message.
fn quoted(names: &[String]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}
