//! Modes in the mix: what parses, and every refusal named by line and field.

use lut_gen::{parse, ModeSelect, When};
use std::path::Path;

use super::err;
use crate::common::{testkit, testkit_path};

fn text(name: &str) -> String {
    std::fs::read_to_string(testkit_path(name)).unwrap()
}

/// The line of the first occurrence of `needle` in `text` (1-based).
fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).unwrap_or_else(|| panic!("no `{needle}`"));
    text[..at].lines().count() + usize::from(text[..at].ends_with('\n') || at == 0)
}

#[test]
fn rates_override_rate_hz_per_mode() {
    let m = testkit("modes-pin");
    let modes = m.modes.as_ref().unwrap();
    assert_eq!(modes.names, ["fast", "slow"]);
    assert_eq!(modes.select, ModeSelect::Pin);
    assert!(modes.triggers.is_empty());
    let rates: Vec<_> = m.channels.iter().map(|c| c.rates.clone()).collect();
    assert_eq!(
        rates,
        [
            vec![4_000, 1_000],
            vec![2_000, 2_000],
            vec![1_000, 0],
            vec![2_000, 2_000],
            vec![1_000, 0]
        ]
    );
    // `in_mode` is the mix at one mode's rates
    let slow = m.in_mode(1);
    assert_eq!(
        slow.channels.iter().map(|c| c.rate_hz).collect::<Vec<_>>(),
        [1_000, 2_000, 0, 2_000, 0]
    );
    assert_eq!(m.mode_count(), 2);
}

#[test]
fn triggers_resolve_modes_channels_and_patterns() {
    let m = testkit("modes-auto");
    let modes = m.modes.as_ref().unwrap();
    assert_eq!(modes.select, ModeSelect::Auto);
    let t = &modes.triggers;
    assert_eq!(t.len(), 3);
    assert_eq!(
        (t[0].from, t[0].to, t[0].when, t[0].level),
        (Some(0), 1, When::Above, 12_000)
    );
    assert_eq!(t[0].channels, [0, 1, 2, 3]);
    assert_eq!(t[0].for_frames, 1);
    assert_eq!((t[1].channels.clone(), t[1].for_frames), (vec![0], 3));
    assert_eq!((t[2].from, t[2].to, t[2].when), (None, 0, When::Below));
    assert!(t[2].leaves(1) && t[2].leaves(2) && !t[2].leaves(0));
    assert_eq!(t[0].line, line_of(&text("modes-auto"), "[[trigger]]"));
    assert_eq!(modes.select_bits(), 2);
}

#[test]
fn mixes_without_modes_have_none() {
    for name in ["tiny", "mutants", "every_slot", "cnvmix2ms"] {
        let m = testkit(name);
        assert!(
            m.modes.is_none() && m.channels.iter().all(|c| c.rates.is_empty()),
            "{name}"
        );
        assert_eq!(m.in_mode(0), m);
    }
}

/// (edit of modes-auto, field, line's text, words in the message)
fn refused(base: &str, from: &str, to: &str, field: &str, at: &str, says: &str) {
    let t = text(base);
    assert!(t.contains(from), "`{from}` not in {base}");
    let bad = t.replacen(from, to, 1);
    let e = err(&bad);
    assert_eq!(e.field, field, "{e}");
    assert_eq!(e.line, line_of(&bad, at), "{e}");
    assert!(e.message.contains(says), "{e}");
    assert!(
        e.to_string().starts_with(&format!("m.toml:{}:", e.line)),
        "{e}"
    );
}

#[test]
fn bad_modes_are_named_by_line_and_field() {
    let auto = "modes-auto";
    refused(
        auto,
        "rates = { touch = 8_000",
        "rates = { tuch = 8_000",
        "channel[0].rates.tuch",
        "rates = { tuch",
        "unknown mode `tuch` (the modes are `rest`, `touch`, `hold`)",
    );
    refused(
        auto,
        "rates = { touch = 8_000",
        "rates = { touch = 8_500",
        "channel[0].rates.touch",
        "rates = { touch = 8_500",
        "not a whole number",
    );
    refused(
        auto,
        "rates = { hold = 0 }",
        "rates = { hold = -5 }",
        "channel[1].rates.hold",
        "hold = -5",
        "must not be negative",
    );
    refused(
        auto,
        "select = \"auto\"",
        "select = \"pin\"",
        "trigger[0]",
        "[[trigger]]",
        "select = \"auto\"",
    );
    refused(
        auto,
        "select = \"auto\"",
        "select = \"bus\"",
        "modes.select",
        "select = \"bus\"",
        "not a mode select",
    );
    refused(
        auto,
        "level = 12_000",
        "level = 16_384",
        "trigger[0].level",
        "level = 16_384",
        "outside the code range of `T0` (ad7940, 14 bits: 0 to 16383)",
    );
    refused(
        auto,
        "level = 12_000",
        "level = -1",
        "trigger[0].level",
        "level = -1",
        "outside the code range",
    );
}

#[test]
fn bad_trigger_fields_are_named_by_line_and_field() {
    let auto = "modes-auto";
    refused(
        auto,
        "to = \"touch\"",
        "to = \"tap\"",
        "trigger[0].to",
        "to = \"tap\"",
        "unknown mode `tap`",
    );
    refused(
        auto,
        "from = \"rest\"",
        "from = \"touch\"",
        "trigger[0].to",
        "to = \"touch\"",
        "both `touch`",
    );
    refused(
        auto,
        "when = \"above\"",
        "when = \"over\"",
        "trigger[0].when",
        "when = \"over\"",
        "not a condition",
    );
    refused(
        auto,
        "channels = [\"T0\"]",
        "channels = [\"T9\"]",
        "trigger[1].channels[0]",
        "channels = [\"T9\"]",
        "no channel named `T9`",
    );
    refused(
        auto,
        "channels = [\"T0\"]",
        "channels = [\"T{3..1}\"]",
        "trigger[1].channels[0]",
        "channels = [\"T{3..1}\"]",
        "counts down",
    );
    refused(
        auto,
        "channels = [\"T0\"]",
        "channels = []",
        "trigger[1].channels",
        "channels = []",
        "watches no channel",
    );
    refused(
        auto,
        "for_frames = 3",
        "for_frames = 0",
        "trigger[1].for_frames",
        "for_frames = 0",
        "must be 1 to",
    );
}

#[test]
fn bad_triggers_are_named_by_line_and_field() {
    let auto = "modes-auto";
    // a watched channel not sampled in a mode its trigger leaves
    // (V is sampled in `touch`, the one mode trigger[1] leaves: accepted)
    assert!(parse(
        Path::new("m"),
        &text(auto).replacen("channels = [\"T0\"]", "channels = [\"V\"]", 1)
    )
    .is_ok());
    let t = text(auto).replacen("rates = { hold = 0 }", "rates = { rest = 0 }", 1);
    let t = t.replacen(
        "channels = [\"T{0..3}\"]",
        "channels = [\"TEMP\", \"V\"]",
        1,
    );
    let e = err(&t);
    assert_eq!(
        (e.field.as_str(), e.line),
        (
            "trigger[0].channels",
            line_of(&t, "channels = [\"TEMP\", \"V\"]")
        ),
        "{e}"
    );
    assert!(
        e.message
            .contains("`V` is not sampled in mode `rest` (rate 0), which this trigger leaves"),
        "{e}"
    );
    // without `from` a trigger leaves every mode but `to`
    refused(
        auto,
        "channels = [\"T{0..3}\"]\nfor_frames = 2",
        "channels = [\"V\"]\nfor_frames = 2",
        "trigger[2].channels",
        "channels = [\"V\"]\nfor_frames = 2",
        "`V` is not sampled in mode `hold` (rate 0), which this trigger leaves",
    );
}

#[test]
fn bad_pin_modes_are_named_by_line_and_field() {
    let pin = "modes-pin";
    refused(
        pin,
        "[[mode]]\nname = \"slow\"\n",
        "",
        "mode[0].name",
        "name = \"fast\"",
        "a single mode never switches",
    );
    refused(
        pin,
        "name = \"slow\"\n\n[modes]",
        "name = \"fast\"\n\n[modes]",
        "mode[1].name",
        "name = \"fast\"\n\n[modes]",
        "duplicate mode name `fast`",
    );
    refused(
        pin,
        "[modes]\nselect = \"pin\"\n",
        "",
        "modes.select",
        "[[mode]]",
        "missing",
    );
    // a sync group shares every mode's rate
    let t = text(pin).replacen(
        "rates = { slow = 0 }",
        "rates = { slow = 1_000 }\nsync = \"s\"",
        1,
    );
    let t = t.replacen(
        "rates = { slow = 0 }",
        "rates = { slow = 0 }\nsync = \"s\"",
        1,
    );
    let e = err(&t);
    let b1 = t.rfind("rates = { slow = 0 }").unwrap();
    assert_eq!(
        (e.field.as_str(), e.line),
        ("channel[4].rates", t[..b1].lines().count() + 1),
        "{e}"
    );
    assert!(
        e.message
            .contains("`B1` (0 Hz) and `A2` (1000 Hz) in mode `slow`: they are in one sync group"),
        "{e}"
    );
}

#[test]
fn modes_keys_without_modes_are_refused() {
    let pin = text("modes-pin");
    let none = pin.replace(
        "[[mode]]\nname = \"fast\"\n\n[[mode]]\nname = \"slow\"\n\n",
        "",
    );
    let e = err(&none);
    assert_eq!(
        (e.field.as_str(), e.line),
        ("modes.select", line_of(&none, "select = \"pin\"")),
        "{e}"
    );
    assert!(e.message.contains("without any [[mode]]"), "{e}");
    let none = none.replace("[modes]\nselect = \"pin\"\n", "");
    let e = err(&none);
    assert_eq!(
        (e.field.as_str(), e.line),
        (
            "channel[0].rates",
            line_of(&none, "rates = { slow = 1_000 }")
        ),
        "{e}"
    );
    assert!(e.message.contains("declares no [[mode]]"), "{e}");
    let auto = text("modes-auto").replace("[[mode]]\nname = \"rest\"\n\n[[mode]]\nname = \"touch\"\n\n[[mode]]\nname = \"hold\"\n\n[modes]\nselect = \"auto\"\n", "");
    let e = err(&auto);
    assert_eq!(e.field, "trigger[0]", "{e}");
    let e = err(&text("modes-auto").replace("[[trigger]]", "[[trigga]]"));
    assert!(e.message.contains("trigga"), "{e}");
}

#[test]
fn auto_without_triggers_and_chains_across_modes_are_refused() {
    let t = text("modes-auto");
    let cut = t.find("[[trigger]]").unwrap();
    let end = t.find("[[branch]]").unwrap();
    let bare = format!("{}{}", &t[..cut], &t[end..]);
    let e = err(&bare);
    assert_eq!(
        (e.field.as_str(), e.line),
        ("modes.select", line_of(&bare, "select = \"auto\"")),
        "{e}"
    );
    assert!(e.message.contains("at least one [[trigger]]"), "{e}");
}

#[test]
fn a_mode_that_samples_nothing_is_named() {
    // modes-pin's `slow` without A0, A1 and B0: nothing left to sample
    let t = text("modes-pin")
        .replace("rates = { slow = 1_000 }", "rates = { slow = 0 }")
        .replace(
            "rate_hz = 2_000\n",
            "rate_hz = 2_000\nrates = { slow = 0 }\n",
        );
    let e = err(&t);
    assert_eq!(
        (e.field.as_str(), e.line),
        ("mode[1].name", line_of(&t, "name = \"slow\"")),
        "{e}"
    );
    assert!(e.message.contains("mode `slow` samples no channel"), "{e}");
}
