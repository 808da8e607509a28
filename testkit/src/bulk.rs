//! Bulk channels (`name = "T{0..47}"`) by text, written apart from the mix
//! parser so a test can hold the parser's expansion against it: a mix's
//! runs of numbered channels rewritten as ranges ([`bulkify`]), and ranges
//! written out channel by channel ([`expand`]).

/// A `[[channel]]` table's key lines, split into its name, its `input` and
/// `member` (when given), and every other line as written.
struct Table {
    name: String,
    input: Option<i64>,
    member: Option<i64>,
    rest: Vec<String>,
}

impl Table {
    fn read(lines: &[&str]) -> Table {
        let mut t = Table {
            name: String::new(),
            input: None,
            member: None,
            rest: Vec::new(),
        };
        for l in lines
            .iter()
            .map(|l| l.trim())
            .filter(|l| !l.is_empty() && !l.starts_with('#'))
        {
            let (k, v) = l
                .split_once('=')
                .map(|(k, v)| (k.trim(), v.trim()))
                .unwrap_or((l, ""));
            match k {
                "name" => t.name = v.trim_matches('"').to_string(),
                "input" => t.input = Some(v.replace('_', "").parse().expect("input")),
                "member" => t.member = Some(v.replace('_', "").parse().expect("member")),
                _ => t.rest.push(l.to_string()),
            }
        }
        t
    }

    fn write(&self, name: &str, step: i64, out: &mut String) {
        out.push_str(&format!("[[channel]]\nname = \"{name}\"\n"));
        for l in &self.rest {
            out.push_str(l);
            out.push('\n');
        }
        if let Some(i) = self.input {
            out.push_str(&format!("input = {}\n", i + step));
        }
        if let Some(m) = self.member {
            out.push_str(&format!("member = {}\n", m + step));
        }
        out.push('\n');
    }

    /// `CH12` -> (`CH`, 12); names without a trailing number or with a
    /// leading zero do not join a run.
    fn numbered(&self) -> Option<(&str, i64)> {
        let digits = self.name.len()
            - self
                .name
                .trim_end_matches(|c: char| c.is_ascii_digit())
                .len();
        let (prefix, n) = self.name.split_at(self.name.len() - digits);
        (digits > 0 && (n == "0" || !n.starts_with('0'))).then(|| (prefix, n.parse().unwrap()))
    }

    /// Whether `next` continues the run this table starts, `len` long.
    fn continued_by(&self, len: i64, next: &Table) -> bool {
        let (Some((p, n)), Some((q, m))) = (self.numbered(), next.numbered()) else {
            return false;
        };
        let counts = |a: Option<i64>, b: Option<i64>| match (a, b) {
            (None, None) => true,
            (Some(a), Some(b)) => b == a + len,
            _ => false,
        };
        p == q
            && m == n + len
            && self.rest == next.rest
            && counts(self.input, next.input)
            && counts(self.member, next.member)
    }
}

/// The mix's sections: (header line or "" for the top, its lines).
fn sections(text: &str) -> Vec<(String, Vec<&str>)> {
    let mut out = vec![(String::new(), Vec::new())];
    for l in text.lines() {
        if l.trim_start().starts_with('[') {
            out.push((l.trim().to_string(), Vec::new()));
        } else {
            out.last_mut().unwrap().1.push(l);
        }
    }
    out
}

fn write_section(header: &str, lines: &[&str], out: &mut String) {
    if !header.is_empty() {
        out.push_str(header);
        out.push('\n');
    }
    for l in lines {
        out.push_str(l);
        out.push('\n');
    }
}

/// The mix with every run of two or more numbered channels (`CH1`, `CH2`,
/// ... identical apart from the number and counting `input`/`member`) as
/// one bulk table; the number of bulk tables written.
pub fn bulkify(text: &str) -> (String, usize) {
    let (mut out, mut bulk) = (String::new(), 0);
    let secs = sections(text);
    let mut i = 0;
    while i < secs.len() {
        let (header, lines) = &secs[i];
        if header != "[[channel]]" {
            write_section(header, lines, &mut out);
            i += 1;
            continue;
        }
        let first = Table::read(lines);
        let mut len = 1;
        while i + (len as usize) < secs.len()
            && secs[i + len as usize].0 == "[[channel]]"
            && first.continued_by(len, &Table::read(&secs[i + len as usize].1))
        {
            len += 1;
        }
        if len > 1 {
            let (prefix, n) = first.numbered().unwrap();
            first.write(&format!("{prefix}{{{n}..{}}}", n + len - 1), 0, &mut out);
            bulk += 1;
        } else {
            write_section(header, lines, &mut out);
        }
        i += len as usize;
    }
    (out, bulk)
}

/// The mix with every bulk table written out channel by channel (plain
/// `{first..last}` ranges, no padding).
pub fn expand(text: &str) -> String {
    let mut out = String::new();
    for (header, lines) in sections(text) {
        let t = Table::read(&lines);
        let range = (header == "[[channel]]")
            .then(|| t.name.split_once('{'))
            .flatten()
            .and_then(|(p, r)| {
                let (range, suffix) = r.split_once('}')?;
                let (a, b) = range.split_once("..")?;
                Some((
                    p.to_string(),
                    a.parse::<i64>().ok()?,
                    b.parse::<i64>().ok()?,
                    suffix.to_string(),
                ))
            });
        match range {
            Some((prefix, a, b, suffix)) => {
                for k in 0..=(b - a) {
                    t.write(&format!("{prefix}{}{suffix}", a + k), k, &mut out);
                }
            }
            None => write_section(&header, &lines, &mut out),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_become_ranges_and_back() {
        let text = "name = \"m\"\n[[channel]]\nname = \"A1\"\nrate_hz = 5\ninput = 3\n\n[[channel]]\nname = \"A2\"\nrate_hz = 5\ninput = 4\n\n[[channel]]\nname = \"B\"\nrate_hz = 5\n\n";
        let (bulk, n) = bulkify(text);
        assert_eq!(n, 1);
        assert!(
            bulk.contains("name = \"A{1..2}\"\nrate_hz = 5\ninput = 3\n"),
            "{bulk}"
        );
        assert!(!bulk.contains("A2"), "{bulk}");
        assert_eq!(expand(&bulk), expand(text));
        assert_eq!(expand(&bulk).matches("[[channel]]").count(), 3);
    }
}
