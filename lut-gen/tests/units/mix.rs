use super::{err, line_of};
use lut_gen::parse;
use std::path::Path;

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
    let e =
        err("name = \"x\"\n[clock]\nhz = 1000000\n[frame]\nperiod_us = 1000\nslice_us = 1000\n");
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

/// The line of the first occurrence of `needle` in `text` (1-based).

#[test]
fn converters_with_a_command_word_use_their_own_mux() {
    let cmd = GOOD
        .replace("adc = \"ad7940\"", "adc = \"mcp3208\"")
        .replace("mux = \"tmux1108\"", "mux = \"internal\"")
        .replace("bandwidth_hz = 400", "bandwidth_hz = 400\ninput = 7");
    let m = parse(Path::new("m.toml"), &cmd).unwrap();
    assert!(m.branches[0].mux.is_internal());
    assert_eq!(m.branches[0].mux.inputs, 8);
    assert_eq!(m.channels[0].input, 7);
    // An input beyond the converter's channels, in its words.
    let bad = cmd.replace("input = 7", "input = 8");
    let e = err(&bad);
    assert_eq!(
        (e.field.as_str(), e.line),
        ("channel[0].input", line_of(&bad, "input = 8"))
    );
    assert!(
        e.message.contains("converter `mcp3208` has channels 0..=7"),
        "{e}"
    );
    // A listening part has no mux of its own; a commanded one needs it.
    let e = err(&GOOD.replace("mux = \"tmux1108\"", "mux = \"internal\""));
    assert_eq!(e.field, "branch[0].mux");
    assert!(
        e.message.contains("`ad7940` has no multiplexer of its own"),
        "{e}"
    );
    let e = err(&cmd.replace("mux = \"internal\"", "mux = \"tmux1108\""));
    assert_eq!(e.field, "branch[0].mux");
    assert!(e.message.contains("write mux = \"internal\""), "{e}");
    let e = err(&cmd.replace("mux = \"internal\"", "mux = \"internal\"\nmux_devices = 2"));
    assert_eq!(e.field, "branch[0].mux_devices");
}

#[test]
fn a_declared_part_may_take_a_command_word() {
    let part = "[[adc_part]]\nname = \"ads7953\"\nbits = 12\nstart = \"cs\"\nleading_bits = 4\n\
                sclk_max_hz = 20_000_000\nmax_sps = 1_000_000\ncommand = \"0001_1_CCCC_00000\"\n\
                command_ahead = 2\n";
    let mix = |p: &str| {
        format!("{GOOD}{p}")
            .replace("adc = \"ad7940\"", "adc = \"ads7953\"")
            .replace("mux = \"tmux1108\"", "mux = \"internal\"")
    };
    let m = parse(Path::new("m.toml"), &mix(part)).unwrap();
    let c = m.branches[0].adc.command.as_ref().unwrap();
    assert_eq!((c.ahead, c.channels()), (2, 16));
    assert_eq!(c.template(), "00011CCCC00000");
    for (from, to, field, says) in [
        (
            "\"0001_1_CCCC_00000\"",
            "\"00011\"",
            "adc_part[0].command",
            "no channel bit",
        ),
        (
            "\"0001_1_CCCC_00000\"",
            "\"0001_x_CCCC\"",
            "adc_part[0].command",
            "`x` is not a bit",
        ),
        (
            "command_ahead = 2",
            "command_ahead = 9",
            "adc_part[0].command_ahead",
            "at most 4",
        ),
        (
            "command = \"0001_1_CCCC_00000\"\n",
            "",
            "adc_part[0].command_ahead",
            "declare `command`",
        ),
    ] {
        let text = mix(&part.replace(from, to));
        let e = err(&text);
        assert_eq!(e.field, field, "{e}");
        assert!(e.message.contains(says), "{e}");
        let key = field.rsplit('.').next().unwrap();
        assert_eq!(e.line, line_of(&text, &format!("{key} =")), "{e}");
    }
}

/// `[[adc_part]] read`: a "cnv" part read with CNV low (its pin active for
/// the conversion alone), refused with the field and line where it cannot
/// be (a "cs" part, a chain, no conversion time, an unknown word).
#[test]
fn a_declared_cnv_part_may_be_read_with_cnv_low() {
    let part = "[[adc_part]]\nname = \"ad7686\"\nbits = 16\nstart = \"cnv\"\nread = \"cnv-low\"\n\
                conversion_ns = 1_600\nsetup_ns = 22\nsclk_max_hz = 20_000_000\nmax_sps = 500_000\n";
    let mix = |p: &str| format!("{GOOD}{p}").replace("adc = \"ad7940\"", "adc = \"ad7686\"");
    let m = parse(Path::new("m.toml"), &mix(part)).unwrap();
    let adc = &m.branches[0].adc;
    assert_eq!(adc.read, lut_gen::CnvRead::CnvLow);
    let t = lut_gen::SpiTiming::derive(adc, 48_000_000, adc.sclk_max_hz, 1).unwrap();
    // CNV falls when the conversion ends, before the read
    assert_eq!(t.pin_cycles, t.conv_cycles);
    assert!(t.pin_cycles < t.setup_cycles && t.setup_cycles < t.read_cycles);
    let held = parse(
        Path::new("m.toml"),
        &mix(&part.replace("read = \"cnv-low\"\n", "")),
    )
    .unwrap();
    assert_eq!(held.branches[0].adc.read, lut_gen::CnvRead::CnvHigh);
    for (from, to, field, says) in [
        (
            "\"cnv-low\"",
            "\"low\"",
            "adc_part[0].read",
            "unknown read `low`",
        ),
        (
            "start = \"cnv\"\nread = \"cnv-low\"\nconversion_ns = 1_600",
            "start = \"cs\"\nleading_bits = 1\nread = \"cnv-low\"",
            "adc_part[0].read",
            "\"cnv\" parts only",
        ),
        (
            "conversion_ns = 1_600\n",
            "",
            "adc_part[0].conversion_ns",
            "give its conversion_ns",
        ),
        (
            "max_sps = 500_000\n",
            "max_sps = 500_000\nchain_max = 2\n",
            "adc_part[0].chain_max",
            "not chained",
        ),
    ] {
        let text = mix(&part.replace(from, to));
        let e = err(&text);
        assert_eq!(e.field, field, "{e}");
        assert!(e.message.contains(says), "{e}");
    }
}

/// A TOML syntax error is one line: file, line, column, the table, and
/// toml's two lines joined.
#[test]
fn a_syntax_error_is_one_line_with_file_line_and_column() {
    let e = err(&GOOD.replace("[clock]", "[clock"));
    let text = e.to_string();
    assert_eq!(text.lines().count(), 1, "{text}");
    assert!(
        text.starts_with("m.toml:3:7: clock: invalid table header: expected"),
        "{text}"
    );
}

/// A misspelt table is named as the user wrote it, at its header's line,
/// with the closest table the format has; a misspelt key gets its closest
/// key too.
#[test]
fn a_misspelt_table_is_named_as_written_with_the_closest_one() {
    let e = err(&GOOD.replace("[frame]", "[frames]"));
    assert_eq!((e.line, e.field.as_str()), (5, "frames"), "{e}");
    assert_eq!(
        e.message,
        "unknown table `[frames]`; did you mean `[frame]`?"
    );
    let e = err(&GOOD.replace("[[channel]]", "[[chanel]]"));
    assert_eq!((e.line, e.field.as_str()), (12, "chanel"), "{e}");
    assert!(e.message.ends_with("did you mean `[[channel]]`?"), "{e}");
    let e = err(&GOOD.replace("adc = ", "adx = "));
    assert_eq!(e.field, "branch[0].adx", "{e}");
    assert!(e.message.ends_with("; did you mean `adc`?"), "{e}");
    // nothing near: the tables the format has
    let e = err(&GOOD.replace("[frame]", "[zzzzzzzz]"));
    assert!(e.message.contains("a mix has `name`"), "{e}");
}
