//! Bulk channels (`name = "T{0..47}"`): a bulk table parses to exactly the
//! mix written out channel by channel, and bad ranges are refused in the
//! user's words, naming the expanded channel.

use proptest::prelude::*;

use super::{err, line_of};
use lut_gen::{parse, Mix, MixError};
use std::path::Path;

const HEAD: &str = r#"
name = "bulk"
[clock]
hz = 48_000_000
[frame]
period_us = 10_000
slice_us = 1_000
[[branch]]
name = "grid"
adc = "ad7940"
mux = "tmux1108"
mux_devices = 8
[[channel]]
name = "first"
branch = "grid"
rate_hz = 100
"#;

/// One `[[channel]]` table; `input`/`member` only when given.
fn table(name: &str, branch: &str, input: Option<i64>, member: Option<i64>) -> String {
    let mut t = format!("[[channel]]\nname = \"{name}\"\nbranch = \"{branch}\"\nrate_hz = 1_000\nkind = \"taxel\"\nbandwidth_hz = 200\n");
    if let Some(i) = input {
        t += &format!("input = {i}\n");
    }
    if let Some(m) = member {
        t += &format!("member = {m}\n");
    }
    t
}

/// A four-part chain without a mux, declared after the channels that use it.
const CHAIN: &str = "[[branch]]\nname = \"chain\"\nadc = \"ad7685\"\nmux = \"none\"\nchain = 4\n";

fn parsed(text: &str) -> Result<Mix, MixError> {
    parse(Path::new("m.toml"), text)
}

#[test]
fn a_row_of_taxels_is_its_expansion() {
    let bulk = format!("{HEAD}{}", table("T{0..47}", "grid", Some(10), None));
    let mut long = HEAD.to_string();
    for k in 0..48 {
        long += &table(&format!("T{k}"), "grid", Some(10 + k), None);
    }
    let (b, l) = (parsed(&bulk).unwrap(), parsed(&long).unwrap());
    assert_eq!(b.channels.len(), 49);
    assert_eq!(b.channels[48].name, "T47");
    assert_eq!(b.channels[48].input, 57);
    assert_eq!(b, l);
}

#[test]
fn members_count_up_and_padding_follows_the_first_number() {
    let bulk = format!(
        "{HEAD}{}{}{CHAIN}",
        table("F{00..03}", "chain", None, Some(0)),
        table("S{1..2}x", "grid", None, None)
    );
    let m = parsed(&bulk).unwrap();
    let names: Vec<_> = m.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["first", "F00", "F01", "F02", "F03", "S1x", "S2x"]);
    let members: Vec<_> = m.channels[1..5]
        .iter()
        .map(|c| (c.input, c.member))
        .collect();
    assert_eq!(members, [(0, 0), (0, 1), (0, 2), (0, 3)]);
    // automatic inputs fill the gaps as they would written out: `first` has 0
    assert_eq!((m.channels[5].input, m.channels[6].input), (1, 2));
}

#[test]
fn bad_ranges_are_refused_in_the_users_words() {
    let cases = [
        (
            "T{5..2}",
            "counts down: write the smaller number first, `{2..5}`",
        ),
        ("T{0..47", "`{` without a closing `}`"),
        ("T0..47}", "`}` without an opening `{`"),
        ("T{a..z}", "`a` in `T{a..z}` is not a whole number"),
        ("T{-1..3}", "`-1` in `T{-1..3}` is not a whole number"),
        ("T{3}", "`{3}` in `T{3}` is not a range"),
        ("T{0..1}{0..1}", "one range per name"),
        ("T{0..99999999999}", "too large"),
        (
            "T{0..70000}",
            "declares 70001 channels; a mix has at most 65535",
        ),
    ];
    for (name, words) in cases {
        let text = format!("{HEAD}{}", table(name, "grid", None, None));
        let e = err(&text);
        let line = line_of(&text, &format!("name = \"{name}"));
        assert_eq!((e.line, e.field.as_str()), (line, "channel[1].name"), "{e}");
        assert!(e.message.contains(words), "{name}: {e}");
        assert!(
            !e.message.contains("panick") && !e.message.contains("u32"),
            "{e}"
        );
    }
}

#[test]
fn errors_name_the_expanded_channel() {
    // 48 taxels from input 40 overflow the 64 inputs at T24
    let text = format!("{HEAD}{}", table("T{0..47}", "grid", Some(40), None));
    let e = err(&text);
    assert_eq!(e.field, "channel[1].input", "{e}");
    assert_eq!(e.line, line_of(&text, "input = 40"), "{e}");
    assert!(
        e.message
            .starts_with("channel T24 (from T{0..47}): input 64 (40 + 24, counted up"),
        "{e}"
    );
    assert!(e.message.contains("inputs 0..=63"), "{e}");
    // members past the chain
    let e = err(&format!(
        "{HEAD}{}{CHAIN}",
        table("F{0..4}", "chain", None, Some(0))
    ));
    assert!(
        e.message
            .starts_with("channel F4 (from F{0..4}): member 4 (0 + 4"),
        "{e}"
    );
    // no free input left for automatic inputs
    let e = err(&format!("{HEAD}{}", table("T{0..63}", "grid", None, None)));
    assert!(
        e.message
            .starts_with("channel T63 (from T{0..63}): branch `grid` has no free mux input"),
        "{e}"
    );
    // a name the range makes twice
    let e = err(
        &format!("{HEAD}{}", table("first{0..0}", "grid", None, None))
            .replace("\"first\"", "\"first0\""),
    );
    assert!(
        e.message
            .starts_with("channel first0 (from first{0..0}): duplicate channel name"),
        "{e}"
    );
    // a field wrong in every expanded channel is blamed on the first
    let e = err(&format!(
        "{HEAD}{}",
        table("T{3..5}", "nowhere", None, None)
    ));
    assert!(
        e.message
            .starts_with("channel T3 (from T{3..5}): unknown branch `nowhere`"),
        "{e}"
    );
    assert_eq!(e.field, "channel[1].branch");
}

/// A run of channels: prefix, first number, count, digits, first input,
/// on the grid (else on the chain).
type Run = (String, u32, u32, usize, Option<i64>, bool);

/// The mix written out, and the same mix with runs of channels as ranges.
fn pair(runs: &[Run]) -> (String, String) {
    let (mut bulk, mut long) = (HEAD.to_string(), HEAD.to_string());
    for (prefix, first, count, width, input, grid) in runs {
        let branch = if *grid { "grid" } else { "chain" };
        let member = (!grid).then_some(0);
        let last = first + count - 1;
        let pad = |n: u32| format!("{n:0width$}");
        bulk += &table(
            &format!("{prefix}{{{}..{}}}", pad(*first), pad(last)),
            branch,
            *input,
            member,
        );
        for k in 0..*count {
            let name = format!("{prefix}{}", pad(first + k));
            long += &table(
                &name,
                branch,
                input.map(|i| i + k as i64),
                member.map(|m| m + k as i64),
            );
        }
    }
    if runs.iter().any(|r| !r.5) {
        (bulk + CHAIN, long + CHAIN)
    } else {
        (bulk, long)
    }
}

/// A bulk message without the expanded channel's name and counting note.
fn plain_words(m: &str) -> String {
    let m = match m.strip_prefix("channel ") {
        Some(rest) if rest.contains(" (from ") => rest.split_once("): ").map_or(m, |x| x.1),
        _ => m,
    };
    match (
        m.find(" ("),
        m.find(", counted up from the first channel's)"),
    ) {
        (Some(a), Some(b)) if a < b => format!("{}{}", &m[..a], &m[b + 38..]),
        _ => m.to_string(),
    }
}

/// Where `line` is in its `[[channel]]` table: lines past the header (the
/// tables of both forms are written alike, so a complaint about one field
/// is at the same place in each).
fn table_offset(text: &str, line: usize) -> usize {
    let start = text
        .lines()
        .enumerate()
        .filter(|(i, l)| *l == "[[channel]]" && *i < line)
        .map(|(i, _)| i + 1)
        .last()
        .unwrap_or(0);
    line - start
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn random_ranges_parse_as_their_expansion(
        runs in proptest::collection::vec(
            (0usize..4, 0u32..200, 1u32..12, 0usize..4, proptest::option::of(0i64..64), any::<bool>()),
            1..5,
        )
    ) {
        let runs: Vec<_> = runs
            .into_iter()
            .enumerate()
            .map(|(r, (p, first, count, width, input, grid))| {
                let prefix = format!("{}{r}_", ["T", "taxel", "CH", "x"][p]);
                // a chain has four members, so at most four per run there
                let count = if grid { count } else { count.min(4) };
                (prefix, first, count, width, if grid { input } else { None }, grid)
            })
            .collect();
        let (bulk, long) = pair(&runs);
        // both succeed alike or fail alike (inputs may overflow or clash)
        match (parsed(&bulk), parsed(&long)) {
            (Ok(b), Ok(l)) => prop_assert_eq!(b, l),
            (Err(b), Err(l)) => {
                // the same complaint, about the same line, once the bulk
                // message's "channel T7 (from T{0..47}): " and "(40 + 7, ...)"
                // are taken out
                prop_assert_eq!(table_offset(&bulk, b.line), table_offset(&long, l.line), "{} / {}", b, l);
                prop_assert_eq!(plain_words(&b.message), l.message.clone(), "{} / {}", b, l);
            }
            (b, l) => prop_assert!(false, "bulk {:?} against written out {:?}", b.map(|_| ()), l.map(|_| ())),
        }
    }
}
