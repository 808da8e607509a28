use lut_gen::{parse, synthesize};
use std::path::Path;

fn mix(adc: &str, rates: &[u64]) -> String {
    let mut t = format!(
        "name = \"cmd\"\n[clock]\nhz = 48000000\n[frame]\nperiod_us = 1000\nslice_us = 1000\n\
         [[branch]]\nname = \"b\"\nadc = \"{adc}\"\nmux = \"internal\"\n"
    );
    for (i, r) in rates.iter().enumerate() {
        t += &format!(
            "[[channel]]\nname = \"c{i}\"\nbranch = \"b\"\nrate_hz = {r}\ninput = {}\n",
            7 - i
        );
    }
    t
}

/// Replaying the frame's words through the part's pipeline converts, at
/// every conversion past the prepared ones, the channel the table names.
#[test]
fn every_conversion_converts_the_channel_its_word_selected() {
    for (adc, rates) in [
        ("mcp3208", vec![1000u64, 2000, 4000]),
        ("ad7689", vec![1000, 1000, 2000, 4000, 8000]),
        ("ad7689", vec![2000]),
    ] {
        let m = parse(Path::new("cmd.toml"), &mix(adc, &rates)).unwrap();
        let s = synthesize(&m).unwrap();
        let cmd = m.branches[0].adc.command.clone().unwrap();
        let sent = s.commands_in_frame(0);
        let n = sent.len();
        assert_eq!(n as u64, rates.iter().sum::<u64>() / 1000);
        // Three frames of conversions: what each one converts.
        let mut selected: Vec<Option<u32>> = Vec::new();
        for k in 0..3 * n {
            let w = &sent[k % n];
            let c = s.at(w.slot, 0).unwrap();
            selected.push(cmd.channel_of(&w.word));
            if !s.is_prepared(0, k as u64) {
                let got = selected[k - cmd.ahead as usize];
                assert_eq!(got, Some(m.channels[c].input), "{adc} conversion {k}");
            }
        }
        assert_eq!(s.prepared_conversions(0), cmd.ahead);
    }
}

/// The audit reports each commanded branch's word and pipeline from the
/// same part the schedule sends, in text and JSON.
#[test]
fn the_audit_names_the_word_and_the_prepared_conversions() {
    for adc in ["mcp3208", "ad7689"] {
        let m = parse(Path::new("cmd.toml"), &mix(adc, &[1000, 2000])).unwrap();
        let s = synthesize(&m).unwrap();
        let a = lut_gen::AuditReport::of_schedule(&s);
        let c = a.branches[0].command.as_ref().unwrap();
        assert_eq!(c.prepared_conversions, s.prepared_conversions(0));
        let t = a.to_text();
        assert!(
            t.contains(&format!("sends {} on adc_mosi", c.template)),
            "{t}"
        );
        assert_eq!(
            t.contains("the first 2 conversion(s) after reset are prepared"),
            adc == "ad7689",
            "{t}"
        );
        let j: serde_json::Value = serde_json::from_str(&a.to_json()).unwrap();
        assert_eq!(j["branches"][0]["command"]["ahead"], c.ahead);
    }
    let plain = crate::common::testkit("tiny");
    let j = lut_gen::AuditReport::of_schedule(&synthesize(&plain).unwrap()).to_json();
    assert!(!j.contains("\"command\""));
}

#[test]
fn listening_parts_send_nothing() {
    for name in ["tiny", "cnvmix2ms"] {
        let m = crate::common::testkit(name);
        let s = synthesize(&m).unwrap();
        for b in 0..s.branch_count() {
            assert!(!s.has_command(b));
            assert!(s.commands_in_frame(b).is_empty());
            assert!(!s.is_prepared(b, 0));
        }
    }
}
