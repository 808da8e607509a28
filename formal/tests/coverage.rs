//! What `prove` covers of the pin contract, and what it says it does not
//! (`Harness::not_covered`, `Proof::not_covered`): derived from the
//! harness's properties, on every preset, the test mixes and random mixes
//! with and without a link.  No external tool: the harness only.

use crate::common;

use std::path::{Path, PathBuf};

use formal::{contract, not_covered, Clause};
use lut_gen::Layout;

use common::root;

/// `text` with `link` appended as its `[link]` table; `None` when the mix
/// has no schedule (an overloaded random draw, a link too slow for it).
fn schedule(name: &str, text: &str, link: Option<&str>) -> Option<lut_gen::Schedule> {
    let text = match link {
        Some(l) if !text.contains("\n[link]") => format!("{text}\n[link]\n{l}\n"),
        Some(_) => return None,
        None => text.to_string(),
    };
    let mix = lut_gen::parse(Path::new(name), &text).ok()?;
    let s = lut_gen::synthesize(&mix).ok()?;
    if let Some(Err(_)) = lut_gen::plan_link(&s) {
        return None;
    }
    formal::generate(&s).is_ok().then_some(s)
}

const UART: &str = "kind = \"uart\"\nbaud = 1_000_000";
const AXIS: &str = "kind = \"axis\"\ntlast = \"slice\"\nready_within = 8";

/// Every preset and test mix as it is, and each without a link given a
/// UART and an AXI4-Stream link; random mixes the same way.
pub(crate) fn mixes() -> Vec<(String, lut_gen::Schedule)> {
    let mut texts = Vec::new();
    for dir in ["mixes", "testkit/mixes"] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        files.sort();
        for f in files {
            texts.push((
                f.display().to_string(),
                std::fs::read_to_string(&f).unwrap(),
            ));
        }
    }
    let shape = common::quick_proof_shape(0);
    for seed in 1..12u64 {
        texts.push((
            format!("random mix {seed}"),
            campaign::random_mix(seed, &shape),
        ));
    }
    let mut out = Vec::new();
    for (name, text) in &texts {
        for link in [None, Some(UART), Some(AXIS)] {
            if let Some(s) = schedule(name, text, link) {
                out.push((format!("{name} + {link:?}"), s));
            }
        }
    }
    out
}

/// What the harness must leave out, read from the mix's ports: nothing of
/// the link (a UART's line or an AXI4-Stream's beats, and the packets, are
/// read: link.bytes, link.packets); only what a converter does with its
/// command word, which is the part's, never the design's (docs/timing.md,
/// "Command words").
fn expected(s: &lut_gen::Schedule) -> Vec<Clause> {
    let mut v: Vec<Clause> = (0..s.branches.len())
        .filter(|&b| s.has_command(b))
        .map(Clause::CommandEffect)
        .collect();
    if axis_bytes_left(s) {
        v.extend([Clause::AxisBeats, Clause::LinkPackets]);
    }
    v
}

/// An AXI4-Stream whose slave may wait longer than the harness splits on
/// (`formal::AXIS_BYTES_MAX_WAIT`): its beats and packets are left out.
fn axis_bytes_left(s: &lut_gen::Schedule) -> bool {
    let l = Layout::new(s);
    let wait = s.mix.link.as_ref().map_or(0, |k| k.ready_within.max(1));
    l.link && l.axis && wait > formal::AXIS_BYTES_MAX_WAIT
}

#[test]
fn not_covered_is_what_the_harness_leaves_out_for_every_kind_of_mix() {
    let all = mixes();
    let kinds = |axis: Option<bool>| {
        all.iter()
            .filter(|(_, s)| {
                let l = Layout::new(s);
                match axis {
                    None => !l.link,
                    Some(a) => l.link && l.axis == a,
                }
            })
            .count()
    };
    // enough of each kind that the test says something
    assert!(kinds(None) >= 8 && kinds(Some(false)) >= 8 && kinds(Some(true)) >= 8);
    for (name, s) in &all {
        let h = formal::generate(s).unwrap();
        assert_eq!(h.not_covered, expected(s), "{name}");
        // every clause of the contract is asserted by a property or listed
        for c in contract(s, &Layout::new(s)) {
            let asserted = h.properties.iter().any(|p| p.covers.contains(&c));
            assert_ne!(asserted, h.not_covered.contains(&c), "{name}: {c:?}");
        }
    }
}

/// The list is derived from the properties: dropping any one property from
/// the harness lists exactly the clauses it asserted, on every mix.
#[test]
fn dropping_a_property_lists_what_it_asserted() {
    for (name, s) in mixes().iter().step_by(3) {
        let h = formal::generate(s).unwrap();
        for (i, p) in h.properties.iter().enumerate() {
            let mut rest = h.properties.clone();
            rest.remove(i);
            let mut want: Vec<Clause> = h.not_covered.clone();
            want.extend(&p.covers);
            want.sort();
            let mut got = not_covered(s, &rest);
            got.sort();
            assert_eq!(got, want, "{name} without {}", p.name);
        }
    }
}

/// The sentences name the pins and the figures the audit reports: the UART
/// clause (asserted by `link.bytes`, whose text has the same bit time)
/// carries the divider and baud of `lut_gen::plan_link`.
#[test]
fn the_sentences_name_the_pins_and_the_audits_baud() {
    for (name, s) in mixes() {
        let h = formal::generate(&s).unwrap();
        // a converter's own behaviour with its command word: named by its part
        for c in &h.not_covered {
            if let Clause::CommandEffect(b) = *c {
                let t = c.sentence(&s);
                let part = &s.mix.branches[b].adc.name;
                assert!(t.contains(part.as_str()), "{name}: {t}");
            }
        }
        let said: Vec<String> = (h.not_covered.iter())
            .filter(|c| !matches!(c, Clause::CommandEffect(_)))
            .map(|c| c.sentence(&s))
            .collect();
        let Some(Ok(plan)) = lut_gen::plan_link(&s) else {
            assert!(said.is_empty(), "{name}: {said:?}");
            continue;
        };
        match plan.uart() {
            Some(_) => {
                // the line is read: link.bytes at the audit's bit time
                assert!(said.is_empty(), "{name}: {said:?}");
                let bytes = (h.properties.iter())
                    .find(|p| p.name == "link.bytes")
                    .unwrap_or_else(|| panic!("{name}: no link.bytes"));
                let want = format!("each bit {} cycles", plan.baud_divider);
                assert!(bytes.what.contains(&want), "{name}: {}", bytes.what);
                let t = Clause::UartCharacters.sentence(&s);
                let want = format!("{want} ({:.0} baud)", plan.baud);
                assert!(t.contains(&want), "{name}: {want} not in {t}");
                assert!(Clause::LinkPackets.sentence(&s).contains("CRC"));
            }
            None if axis_bytes_left(&s) => {
                assert!(said[0].contains("m_axis_tlast"), "{name}: {said:?}");
                assert!(said[1].contains("m_axis_tdata"), "{name}: {said:?}");
                // and why: the slave's wait, past what a proof splits on
                let wait = s.mix.link.as_ref().unwrap().ready_within;
                let why = format!(
                    "not asserted: the slave may keep a beat waiting up to \
                     ready_within = {wait} cycles"
                );
                assert!(said.iter().all(|t| t.contains(&why)), "{name}: {said:?}");
            }
            None => {
                // the beats are read: link.bytes names tlast
                assert!(said.is_empty(), "{name}: {said:?}");
                let bytes = (h.properties.iter())
                    .find(|p| p.name == "link.bytes")
                    .unwrap_or_else(|| panic!("{name}: no link.bytes"));
                assert!(
                    bytes.what.contains("m_axis_tlast"),
                    "{name}: {}",
                    bytes.what
                );
            }
        }
    }
}

/// Random mixes drawn with their own link (the generator's `LinkShape`,
/// both kinds, baud and AXI4-Stream options drawn with the mix): nothing
/// of the link is listed for either kind (their harnesses have
/// `link.bytes` and `link.packets`), and the AXI4-Stream's clauses, were
/// they listed, would name its own stream (`m_axis_*`), nothing of
/// `link_tx`.
#[test]
fn not_covered_names_each_link_kinds_own_stream() {
    let shape = campaign::Shape {
        link: Some(campaign::LinkShape::Either),
        ..Default::default()
    };
    let (mut uart, mut axis) = (0, 0);
    for seed in 1..60u64 {
        let text = campaign::random_mix(seed, &shape);
        let Some(s) = schedule(&format!("link mix {seed}"), &text, None) else {
            continue;
        };
        let l = Layout::new(&s);
        if !l.link {
            continue;
        }
        let h = formal::generate(&s).unwrap();
        assert_eq!(h.not_covered, expected(&s), "mix {seed}");
        for name in ["link.bytes", "link.packets"] {
            assert_eq!(
                h.properties.iter().any(|p| p.name == name),
                !axis_bytes_left(&s),
                "mix {seed}: {name}"
            );
        }
        if l.axis {
            axis += 1;
            let beats = Clause::AxisBeats.sentence(&s) + &Clause::LinkPackets.sentence(&s);
            assert!(
                beats.contains("m_axis_tlast") && beats.contains("m_axis_tdata"),
                "mix {seed}: {beats}"
            );
            assert!(
                !beats.contains("link_tx") && !beats.contains("UART"),
                "mix {seed}: {beats}"
            );
        } else {
            uart += 1;
        }
    }
    assert!(
        uart >= 5 && axis >= 5,
        "both kinds drawn: {uart} UART, {axis} AXIS"
    );
}
