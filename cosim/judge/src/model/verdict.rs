//! The check report, serializable to `sim --json` / `check --json`
//! (the fields: docs/json.md).

use serde::Serialize;
use serde_json::Value;

use crate::model::rule::Rule;

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ChannelStats {
    pub name: String,
    pub branch: String,
    pub samples: u64,
    /// Nominal interval (clock / rate).
    pub interval_cycles: u64,
    pub interval_cycles_min: Option<u64>,
    pub interval_cycles_max: Option<u64>,
    /// A mix with modes: the same figures in each mode (intervals restart
    /// at a switch); the fields above span every mode.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub modes: Vec<ModeStats>,
}

/// A channel's figures in one mode of a run.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ModeStats {
    pub mode: String,
    pub samples: u64,
    /// Nominal interval in that mode (0: not sampled in it).
    pub interval_cycles: u64,
    pub interval_cycles_min: Option<u64>,
    pub interval_cycles_max: Option<u64>,
}

/// A difference between the design's pins and the reference model.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Divergence {
    pub cycle: u64,
    pub frame: u64,
    pub slot: u64,
    pub signal: String,
    pub expected: Value,
    pub actual: Value,
    pub branch: Option<String>,
    /// The channel of the expected value: for a mux pin, the channel the
    /// expected pins select (or why none is).
    pub channel: Option<String>,
    /// For a mux pin (`mux_sel`, `mux_en`): the channel the actual pins
    /// select, or why none is, beside `channel` (then the channel the
    /// expected pins select).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub actual_channel: Option<String>,
    /// A few cycles around the divergence: `cycle: actual | expected`.
    pub context: Vec<String>,
}

impl Divergence {
    /// "expected X actual Y, branch B, channel C": a mux pin names the
    /// channel of each value beside it (like with like), any other the
    /// expected value's channel after the branch.
    pub fn values_text(&self) -> String {
        let branch = self
            .branch
            .as_ref()
            .map(|b| format!(", branch {b}"))
            .unwrap_or_default();
        if let Some(actual) = &self.actual_channel {
            let name = |c: &str| {
                if c.starts_with("no ") || c.contains(' ') {
                    c.to_string()
                } else {
                    format!("channel {c}")
                }
            };
            let expected = name(self.channel.as_deref().unwrap_or(""));
            return format!(
                " expected {} ({expected}) actual {} ({}){branch}",
                self.expected,
                self.actual,
                name(actual)
            );
        }
        let channel = self
            .channel
            .as_ref()
            .map(|c| format!(", channel {c}"))
            .unwrap_or_default();
        format!(
            " expected {} actual {}{branch}{channel}",
            self.expected, self.actual
        )
    }
}

/// A broken invariant (independent of the model).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Violation {
    pub cycle: u64,
    pub frame: u64,
    pub slot: u64,
    pub rule: String,
    pub signal: Option<String>,
    pub expected: Option<Value>,
    pub actual: Option<Value>,
    pub channel: Option<String>,
    pub detail: String,
}

/// Built at a model cycle (`Violation::new(rule, cycle).signal(..)...`);
/// recording it turns that cycle into the report's cycle, frame and slot.
impl Violation {
    pub fn new(rule: Rule, cycle: u64) -> Violation {
        Violation {
            cycle,
            frame: 0,
            slot: 0,
            rule: rule.as_str().into(),
            signal: None,
            expected: None,
            actual: None,
            channel: None,
            detail: String::new(),
        }
    }

    pub fn signal(mut self, signal: impl Into<Option<String>>) -> Violation {
        self.signal = signal.into();
        self
    }

    pub fn expected(mut self, expected: impl Into<Option<Value>>) -> Violation {
        self.expected = expected.into();
        self
    }

    pub fn actual(mut self, actual: impl Into<Option<Value>>) -> Violation {
        self.actual = actual.into();
        self
    }

    pub fn channel(mut self, channel: impl Into<Option<String>>) -> Violation {
        self.channel = channel.into();
        self
    }

    pub fn detail(mut self, detail: impl Into<String>) -> Violation {
        self.detail = detail.into();
        self
    }
}

/// How a check that joined a run mid-stream (a window, a capture from the
/// middle of a run) joined the link: the bytes in flight when it began are
/// skipped, and the line is checked from its first whole packet on.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct LinkJoin {
    /// What joined the line: `"model"` (the model's transmitter rebuilt
    /// from the packet, every link pin compared from `checked_from_cycle`)
    /// or `"decoder"` (`--no-model`: every packet judged from the one that
    /// ended in `checked_from_cycle`).
    pub by: String,
    /// Whether the line was judged at all: false when the capture showed
    /// no whole packet to join at.
    pub judged: bool,
    /// The capture cycle from which the line is checked; null when the
    /// capture showed no whole packet to join at (the line was then not
    /// checked).
    pub checked_from_cycle: Option<u64>,
    /// The first whole packet joined at: the capture cycle its header
    /// began in, its frame counter and slice.
    pub header_cycle: Option<u64>,
    pub frame_counter: Option<u8>,
    pub slice: Option<u16>,
    /// Bytes the line carried before that packet, in flight when the
    /// capture began: skipped.
    pub skipped_bytes: u64,
    /// The capture cycles of the line not judged: from the capture's
    /// first cycle to the joined packet's header (to its end where the
    /// header's cycle is not known), or the whole capture when no packet
    /// was joined.  A fault on the line there is not seen.
    pub unjudged_cycles: u64,
}

impl LinkJoin {
    /// The line the text report gives it.
    pub fn text(&self) -> String {
        let (Some(c), Some(f), Some(s)) = (self.checked_from_cycle, self.frame_counter, self.slice)
        else {
            return format!(
                "link: NOT JUDGED: the capture's {} cycles show no whole packet to join the line at ({} byte(s) read): nothing on the line was checked",
                self.unjudged_cycles, self.skipped_bytes
            );
        };
        let what = match (self.header_cycle, self.by.as_str()) {
            (Some(h), "model") => format!("its header at capture cycle {h}; every link pin compared with the model from capture cycle {c}"),
            (Some(h), _) => format!("its header at capture cycle {h}, read by capture cycle {c}; every packet judged from it on"),
            (None, _) => format!("read by capture cycle {c}; every packet judged from it on"),
        };
        format!(
            "link: joined the line at its first whole packet (frame counter {f}, slice {s}; {what}); the line before it was not judged: its first {} cycle(s) and {} byte(s), in flight when the capture began, were skipped (a fault there is not seen)",
            self.unjudged_cycles, self.skipped_bytes
        )
    }
}

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Verdict {
    pub ok: bool,
    pub mix: String,
    /// `model`, `rusthdl`, `verilator` or `vcd`.
    pub source: String,
    /// Cycles checked after reset.
    pub cycles: u64,
    /// Complete frames checked.
    pub frames: u64,
    /// Cycles checked after the last complete frame (a partial frame: its
    /// samples are counted and checked, its per-frame counts only against
    /// the maximum).
    pub partial_frame_cycles: u64,
    /// Samples emitted on `sample_valid` (model backend: conversions).
    pub samples: u64,
    pub channels: Vec<ChannelStats>,
    /// Cycles in which some pin differed from the model (all of them, not only those listed).
    pub divergence_count: u64,
    pub divergences: Vec<Divergence>,
    pub violation_count: u64,
    pub violations: Vec<Violation>,
    /// Whether the pins were compared against the cycle-level model.
    pub model_compared: bool,
    /// A check that joined a link design's run mid-stream: where it
    /// joined the line (absent from reset, or without a link).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link_join: Option<LinkJoin>,
}

impl Verdict {
    /// The frames the window holds, in words, from `frames` and
    /// `partial_frame_cycles` (the JSON's fields): whole frames, and a
    /// partial one said as such.
    pub fn frames_held(&self) -> String {
        let whole = match self.frames {
            1 => "1 whole frame".to_string(),
            n => format!("{n} whole frames"),
        };
        match (self.frames, self.partial_frame_cycles) {
            (_, 0) => whole,
            (0, p) => format!("a partial frame of {}", counted(p, "cycle")),
            (_, p) => format!("{whole} and a partial frame of {}", counted(p, "cycle")),
        }
    }

    /// A short human summary, with the first divergence and violations.
    pub fn summary(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} [{}]: {}, {}, {}, {}, {}: {}",
            self.mix,
            self.source,
            counted(self.cycles, "cycle"),
            self.frames_held(),
            counted(self.samples, "sample"),
            counted(self.divergence_count, "divergent cycle"),
            counted(self.violation_count, "violation"),
            verdict_word(self.ok, self.link_join.as_ref().map(|j| j.judged))
        );
        if let Some(j) = &self.link_join {
            let _ = writeln!(s, "{}", j.text());
        }
        if let Some(d) = self.divergences.first() {
            let _ = writeln!(
                s,
                "first divergence: cycle {} (frame {}, slot {}): {}{}",
                d.cycle,
                d.frame,
                d.slot,
                d.signal,
                d.values_text()
            );
            for l in &d.context {
                let _ = writeln!(s, "    {l}");
            }
        }
        for v in self.violations.iter().take(10) {
            let _ = writeln!(
                s,
                "violation: cycle {} (frame {}, slot {}): {}{}: {}",
                v.cycle,
                v.frame,
                v.slot,
                v.rule,
                v.signal
                    .as_ref()
                    .map(|x| format!(" on {x}"))
                    .unwrap_or_default(),
                v.detail
            );
        }
        if self.violations.len() > 10 {
            let _ = writeln!(s, "... {} more violations", self.violation_count - 10);
        }
        s
    }
}

/// The first line's verdict, for a window and for a capture alike: a pass
/// whose link was never joined says so rather than reading as a whole pass.
pub(crate) fn verdict_word(ok: bool, link_judged: Option<bool>) -> &'static str {
    match (ok, link_judged) {
        (false, _) => "FAIL",
        (true, Some(false)) => "PASS (the link not judged)",
        (true, _) => "PASS",
    }
}

/// `n` of a countable noun, singular or plural as `n` needs ("1 frame",
/// "2 frames", "3 random mixes"): every count a user reads says it so.
pub fn counted(n: u64, noun: &str) -> String {
    match n {
        1 => format!("1 {noun}"),
        _ if noun.ends_with('x') || noun.ends_with('s') => format!("{n} {noun}es"),
        _ => format!("{n} {noun}s"),
    }
}
