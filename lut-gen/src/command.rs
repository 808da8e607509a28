//! The command words a schedule sends to converters that take one on DIN
//! (`adc_mosi`), and the pipeline they imply.
//!
//! A branch's conversions repeat every frame in slot order.  The word sent
//! with conversion `k` selects the channel of conversion `k + ahead` (the
//! part's `Command::ahead`), counted cyclically through the frame, so in a
//! steady run every conversion converts the channel the frame table names.
//! After reset the first `ahead` conversions of the branch were selected by
//! no word of ours: they are prepared, never read as data.

use crate::schedule::Schedule;

/// The command one conversion of a branch sends.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CommandSent {
    /// The frame slot of the conversion that carries the word.
    pub slot: u64,
    /// The channel (index into `Mix::channels`) the word selects, and its
    /// input number on the converter's multiplexer.
    pub selects: usize,
    pub input: u32,
    /// The word, first bit first (one bit per SCLK period).
    pub word: Vec<bool>,
}

impl Schedule {
    /// Whether branch `b`'s converter takes a command word (the branch then
    /// drives an `adc_mosi` bit).
    pub fn has_command(&self, b: usize) -> bool {
        self.mix.branches[b].adc.command.is_some()
    }

    /// Conversions of branch `b` after reset that are prepared, not data:
    /// the part's `ahead` (0 for a part without a command word).
    pub fn prepared_conversions(&self, b: usize) -> u32 {
        self.mix.branches[b]
            .adc
            .command
            .as_ref()
            .map_or(0, |c| c.ahead)
    }

    /// The words branch `b` sends in one frame, in slot order: one per
    /// conversion; empty for a branch without a command word.
    pub fn commands_in_frame(&self, b: usize) -> Vec<CommandSent> {
        let Some(cmd) = &self.mix.branches[b].adc.command else {
            return Vec::new();
        };
        let convs: Vec<(u64, usize)> = (0..self.grid.frame_slots)
            .filter_map(|s| self.at(s, b).map(|c| (s, c)))
            .collect();
        let n = convs.len();
        (0..n)
            .map(|k| {
                let (slot, _) = convs[k];
                let (_, selects) = convs[(k + cmd.ahead as usize) % n];
                let input = self.mix.channels[selects].input;
                CommandSent {
                    slot,
                    selects,
                    input,
                    word: cmd.word(input),
                }
            })
            .collect()
    }

    /// Whether branch `b`'s conversion number `k` after reset (0: its
    /// first) is prepared rather than read as data.
    pub fn is_prepared(&self, b: usize, k: u64) -> bool {
        k < self.prepared_conversions(b) as u64
    }
}

#[cfg(test)]
mod tests {
    use crate::{parse, synthesize};
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
            let a = crate::AuditReport::of_schedule(&s);
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
        let plain = crate::load(Path::new(&format!(
            "{}/../testkit/mixes/tiny.toml",
            env!("CARGO_MANIFEST_DIR")
        )))
        .unwrap();
        let j = crate::AuditReport::of_schedule(&synthesize(&plain).unwrap()).to_json();
        assert!(!j.contains("\"command\""));
    }

    #[test]
    fn listening_parts_send_nothing() {
        for name in ["tiny", "cnvmix2ms"] {
            let path = format!(
                "{}/../testkit/mixes/{name}.toml",
                env!("CARGO_MANIFEST_DIR")
            );
            let m = crate::load(Path::new(&path)).unwrap();
            let s = synthesize(&m).unwrap();
            for b in 0..s.branch_count() {
                assert!(!s.has_command(b));
                assert!(s.commands_in_frame(b).is_empty());
                assert!(!s.is_prepared(b, 0));
            }
        }
    }
}
