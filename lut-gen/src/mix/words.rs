//! toml's messages in the mix format's words, and the numbers in messages.

use std::collections::BTreeMap;
use std::ops::Range;

/// 1-based line and column of a byte offset.
pub(super) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map(|p| offset - p).unwrap_or(offset + 1);
    (line, column)
}

/// toml's messages name the offending key for unknown fields; lift it out so
/// the field is reported the same way semantic errors report theirs.
pub(super) fn field_from_toml_message(
    message: &str,
    text: &str,
    span: Option<Range<usize>>,
) -> String {
    if let Some(rest) = message.strip_prefix("unknown field `") {
        if let Some(end) = rest.find('`') {
            let key = &rest[..end];
            // a misspelt table's own header: the name as written
            let own = header_at(text, span.clone())
                .is_some_and(|h| h.trim_matches(|c| c == '[' || c == ']').trim() == key);
            if own {
                return key.to_string();
            }
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
pub(super) fn header_message(
    text: &str,
    span: Option<Range<usize>>,
    field: &str,
) -> Option<String> {
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
pub(super) fn table_prefix(text: &str, span: Option<Range<usize>>) -> String {
    let Some(span) = span else {
        return String::new();
    };
    let upto = &text[..span.start.min(text.len())];
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let mut current = String::new();
    for line in upto.lines() {
        let t = line.trim();
        // a header is whole (`[frame]`): the line the span begins in may be
        // only its `[` so far
        if !t.contains(']') {
            continue;
        }
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

/// serde's "unknown field `x`, expected one of `a`, `b`" in the mix
/// format's words: a table header the format does not have is an unknown
/// table, written as the user wrote it; either way the closest known name
/// is offered when one is near.
pub(super) fn unknown_words(message: &str, header: Option<&str>) -> Option<String> {
    let rest = message.strip_prefix("unknown field `")?;
    let (key, rest) = rest.split_once('`')?;
    let known: Vec<&str> = rest.split('`').skip(1).step_by(2).collect();
    // the header names the key itself (`[frames]`), not its table's
    let header = header.filter(|h| h.trim_matches(|c| c == '[' || c == ']').trim() == key);
    let near = known
        .iter()
        .map(|k| (distance(key, k), *k))
        .filter(|(d, k)| *d <= 2.max(k.len() / 3))
        .min();
    Some(match (header, near) {
        (Some(h), Some((_, k))) => {
            let like = h.replacen(key, k, 1);
            format!("unknown table `{h}`; did you mean `{like}`?")
        }
        (Some(h), None) => format!(
            "unknown table `{h}`; a mix has {}",
            known
                .iter()
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        (None, Some((_, k))) => format!("{}; did you mean `{k}`?", message.trim()),
        (None, None) => message.trim().to_string(),
    })
}

/// The table header (`[frames]`) on the line `span` begins in, if it is one.
pub(super) fn header_at(text: &str, span: Option<Range<usize>>) -> Option<&str> {
    let s = span?;
    let start = text[..s.start.min(text.len())]
        .rfind('\n')
        .map_or(0, |p| p + 1);
    let line = text[start..].lines().next()?.trim();
    line.starts_with('[').then_some(line)
}

/// The edit distance of two names (insertions, deletions, substitutions).
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// Frame periods (whole slices, at most 10 s) in which `rate_hz` gives a
/// whole number of samples, as advice after a fractional count.
/// A frequency as people write it: `100` for 100.000, `0.5` for 0.500,
/// `33.333` where the digits do not end.
pub(super) fn hz_text(hz: f64) -> String {
    let t = format!("{hz:.3}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

pub(super) fn frames_that_fit(rate_hz: u64, slice_us: u64) -> String {
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

pub(super) fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// A TOML value as the user wrote it, for "got ..." in a message.
pub(super) fn value_words(v: &toml::Value) -> String {
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
pub fn toml_words(m: &str, field: &str) -> String {
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
    // toml's syntax errors come on two lines ("invalid table header" and
    // "expected `.`, `]`"): one line, as every message
    let lines: Vec<&str> = out
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    lines.join(": ")
}
