//! Bulk channels: `name = "T{0..47}"` in one `[[channel]]` table declares a
//! row of channels that differ only in their name and, when given, their
//! `input` and `member`, which count up from the value written.  Expanded
//! here, before any other check, so a bulk mix is validated (and scheduled)
//! exactly as if it had been written out channel by channel.

use toml::Spanned;

use super::raw::RawChannel;
use super::*;

/// One channel as declared: a plain `[[channel]]` table, or one channel of
/// a bulk table, already with its own name, input and member.
pub(super) struct Declared {
    /// Index of the `[[channel]]` table it comes from (the user's
    /// `channel[N]`).
    pub(super) table: usize,
    /// The name as written when it is a range (`T{0..47}`).
    pub(super) from: Option<String>,
    /// Its place in the range (0 for a plain table).
    pub(super) step: u32,
    pub(super) raw: RawChannel,
}

impl Declared {
    /// The field as the user wrote it: `channel[N].key`.
    pub(super) fn field(&self, key: &str) -> String {
        format!("channel[{}].{key}", self.table)
    }

    /// A message about this channel; one of a bulk table says which.
    pub(super) fn say(&self, message: impl Into<String>) -> String {
        match &self.from {
            None => message.into(),
            Some(f) => format!(
                "channel {} (from {f}): {}",
                self.raw.name.get_ref(),
                message.into()
            ),
        }
    }
}

/// A `{first..last}` range in a channel name.
#[derive(Debug, PartialEq, Eq)]
pub(super) struct Range {
    prefix: String,
    suffix: String,
    first: u32,
    last: u32,
    /// Digits to pad to (`{00..47}` gives `T00`..`T47`), 0: none.
    width: usize,
}

/// Most channels a mix may have (the sample stream's channel index is 16 bits).
pub(super) const MAX_CHANNELS: u64 = u16::MAX as u64;

const HOW: &str = "a range is written {first..last}, e.g. name = \"T{0..47}\"";

impl Range {
    /// The range in `name`, `None` when it has none; the error in the
    /// user's words when the braces are there but not a range.
    pub(super) fn parse(name: &str) -> Result<Option<Range>, String> {
        let Some(open) = name.find('{') else {
            if name.contains('}') {
                return Err(format!("`}}` without an opening `{{` in `{name}`: {HOW}"));
            }
            return Ok(None);
        };
        let Some(close) = name[open..].find('}').map(|c| open + c) else {
            return Err(format!("`{{` without a closing `}}` in `{name}`: {HOW}"));
        };
        let (prefix, inner, suffix) = (&name[..open], &name[open + 1..close], &name[close + 1..]);
        if prefix.contains('}') || suffix.contains(['{', '}']) {
            return Err(format!(
                "`{name}` has more than one range or a stray brace: one range per name, {HOW}"
            ));
        }
        let Some((a, b)) = inner.split_once("..") else {
            return Err(format!("`{{{inner}}}` in `{name}` is not a range: {HOW}"));
        };
        let number = |s: &str| -> Result<u32, String> {
            let s = s.trim();
            if s.is_empty() || !s.bytes().all(|c| c.is_ascii_digit()) {
                return Err(format!(
                    "`{s}` in `{name}` is not a whole number: {HOW} (first and last are whole numbers, 0 or more)"
                ));
            }
            s.parse::<u32>()
                .map_err(|_| format!("`{s}` in `{name}` is too large for a channel number"))
        };
        let (first, last) = (number(a)?, number(b)?);
        if first > last {
            return Err(format!(
                "`{{{inner}}}` in `{name}` counts down: write the smaller number first, `{{{}..{}}}`",
                b.trim(),
                a.trim()
            ));
        }
        let count = last as u64 - first as u64 + 1;
        if count > MAX_CHANNELS {
            return Err(format!(
                "`{name}` declares {count} channels; a mix has at most {MAX_CHANNELS}"
            ));
        }
        let a = a.trim();
        let width = if a.len() > 1 && a.starts_with('0') {
            a.len()
        } else {
            0
        };
        Ok(Some(Range {
            prefix: prefix.to_string(),
            suffix: suffix.to_string(),
            first,
            last,
            width,
        }))
    }

    pub(super) fn count(&self) -> u32 {
        self.last - self.first + 1
    }

    /// The `step`-th channel's name.
    pub(super) fn name(&self, step: u32) -> String {
        format!(
            "{}{:0w$}{}",
            self.prefix,
            self.first + step,
            self.suffix,
            w = self.width
        )
    }
}

/// `v` counted up by `step`, at the span the user wrote it.
fn counted(v: &Option<Spanned<i64>>, step: u32) -> Option<Spanned<i64>> {
    v.as_ref()
        .map(|v| Spanned::new(v.span(), v.get_ref().saturating_add(step as i64)))
}

impl Cx<'_> {
    /// Every channel the `[[channel]]` tables declare, ranges expanded, in
    /// file order.
    pub(super) fn declare_channels(&self, raw: &RawMix) -> Result<Vec<Declared>, MixError> {
        let mut out = Vec::new();
        for (table, c) in raw.channel.iter().enumerate() {
            let c = c.get_ref();
            let written = c.name.get_ref();
            let range = Range::parse(written)
                .map_err(|m| self.at(c.name.span(), format!("channel[{table}].name"), m))?;
            let Some(range) = range else {
                out.push(Declared {
                    table,
                    from: None,
                    step: 0,
                    raw: c.clone(),
                });
                continue;
            };
            if out.len() as u64 + range.count() as u64 > MAX_CHANNELS {
                return Err(self.at(
                    c.name.span(),
                    format!("channel[{table}].name"),
                    format!("`{written}` takes the mix past {MAX_CHANNELS} channels"),
                ));
            }
            for step in 0..range.count() {
                let mut one = c.clone();
                one.name = Spanned::new(c.name.span(), range.name(step));
                // Behind a front mux the block counts the front mux's inputs:
                // its output is one wire into one converter input.
                match &c.front_input {
                    Some(_) => one.front_input = counted(&c.front_input, step),
                    None => one.input = counted(&c.input, step),
                }
                one.member = counted(&c.member, step);
                out.push(Declared {
                    table,
                    from: Some(written.clone()),
                    step,
                    raw: one,
                });
            }
        }
        Ok(out)
    }
}

/// The channel names a name or bulk pattern stands for (`T{0..3}`: `T0`,
/// ..., `T3`), for a command-line list of channels; the error in the user's
/// words.
pub fn expand_names(written: &str) -> Result<Vec<String>, String> {
    Ok(match Range::parse(written)? {
        None => vec![written.to_string()],
        Some(r) => (0..r.count()).map(|s| r.name(s)).collect(),
    })
}
