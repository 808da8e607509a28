//! Invariants at conversion level, from the mix alone (independent of the
//! reference model): per-channel counts per frame and exact intervals, and
//! the merged sample stream.  Used by the cycle-level [`crate::Checker`] and
//! by the slot-level model run, which has no pins.

use std::collections::VecDeque;

use lut_gen::Role;
use lut_gen::{FrameGrid, Schedule};
use serde_json::json;

use crate::model::mode_rules::ModeCheck;
use crate::model::rule::Rule;
use crate::model::verdict::{ChannelStats, ModeStats, Verdict, Violation};

/// Collects violations; shared by both layers.
#[derive(Debug, Clone)]
pub(crate) struct Recorder {
    grid: FrameGrid,
    max: usize,
    violations: Vec<Violation>,
    violation_count: u64,
    /// A check that joined mid-stream: model cycle minus capture cycle, and
    /// the model frame in which it joined (reported as frame 0).
    shift: u64,
    frame_base: u64,
}

impl Recorder {
    /// (cycle, frame, slot) of model cycle `c` as a report gives them.
    pub(crate) fn place(&self, c: u64) -> (u64, u64, u64) {
        let (frame, slot, _) = self.grid.locate(c);
        (self.cycle(c), frame - self.frame_base, slot)
    }

    /// Capture cycle of model cycle `c`: every cycle a message names.
    pub(crate) fn cycle(&self, c: u64) -> u64 {
        c - self.shift
    }

    /// Counts `v` (built at a model cycle) and lists it while the list has room.
    pub(crate) fn record(&mut self, mut v: Violation) {
        if crate::switch::disabled("invariants") {
            return;
        }
        self.violation_count += 1;
        if self.violations.len() < self.max {
            (v.cycle, v.frame, v.slot) = self.place(v.cycle);
            self.violations.push(v);
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Pending {
    complete: u64,
    instant: u64,
    branch: usize,
    channel: Option<u16>,
    code: Option<u16>,
    /// A commanded branch: the cycle of the conversion whose word selected
    /// `channel` (then a sample of another channel is `command-channel`).
    word_at: Option<u64>,
}

/// Model-independent checks at conversion level: per-channel counts per
/// frame and exact intervals, and the merged sample stream (every completed
/// conversion emitted once, in order, with its channel and MISO word).
#[derive(Debug, Clone)]
pub struct Invariants {
    rec: Recorder,
    names: Vec<String>,
    branch_names: Vec<String>,
    ch_branch: Vec<usize>,
    interval: Vec<u64>,
    spf: Vec<u64>,
    /// Samples per channel in frame 0: `spf` less the instants skipped at
    /// start-up (docs/timing.md, "Start-up").
    spf0: Vec<u64>,
    last: Vec<u64>,
    has_last: Vec<bool>,
    in_frame: Vec<u64>,
    samples: Vec<u64>,
    imin: Vec<u64>,
    imax: Vec<u64>,
    /// Frame whose counts are being accumulated.
    frame: u64,
    frame_cycles: u64,
    queue: VecDeque<Pending>,
    /// Emission lateness allowed after completion (cycles).
    slack: u64,
    emitted: u64,
    conversions: u64,
    /// The model cycle the check began at (0: at reset).
    origin: u64,
    /// A mix with switches: per mode, each channel's samples per frame and
    /// interval (0: not sampled), the mode rules, and the mode whose
    /// intervals hold now.
    spf_m: Vec<Vec<u64>>,
    interval_m: Vec<Vec<u64>>,
    mc: Option<Box<ModeCheck>>,
    cur_mode: usize,
    /// A mix with modes: per mode, its name and each channel's samples and
    /// least and most interval within that mode (intervals restart at a
    /// switch), so a report shows each mode's own figures.
    mode_names: Vec<String>,
    stat_m: Vec<Vec<(u64, u64, u64)>>,
    /// (frame, channel) of each prepared conversion after reset (converters
    /// with a command word: no word of ours selected it, so it is no
    /// sample), and the last cycle a conversion's channel could not be
    /// known (joined mid-stream): counts are not checked in its frame.
    prepared: Vec<(u64, usize)>,
    blind_until: Option<u64>,
}

impl Invariants {
    pub fn new(s: &Schedule, max_records: usize) -> Invariants {
        let mix = &s.mix;
        let per_mode = |f: &dyn Fn(&lut_gen::Mix, &lut_gen::Channel) -> u64| -> Vec<Vec<u64>> {
            s.modes
                .iter()
                .map(|m| m.mix.channels.iter().map(|c| f(&m.mix, c)).collect())
                .collect()
        };
        let spf_m = per_mode(&|m, c| m.samples_per_frame(c.rate_hz));
        let interval_m = per_mode(&|m, c| m.clock_hz.checked_div(c.rate_hz).unwrap_or(0));
        let n = mix.channels.len();
        let spf: Vec<u64> = mix
            .channels
            .iter()
            .map(|c| mix.samples_per_frame(c.rate_hz))
            .collect();
        let mut spf0 = spf.clone();
        for b in 0..s.branches.len() {
            if let Some(lead) = s.at(0, b) {
                if s.skipped_at_startup(b, 0) {
                    // every chain member read in that conversion
                    for (_, ch) in s.words_of(lead) {
                        spf0[ch] -= 1;
                    }
                }
            }
        }
        Invariants {
            rec: Recorder {
                grid: s.grid,
                max: max_records,
                violations: Vec::new(),
                violation_count: 0,
                shift: 0,
                frame_base: 0,
            },
            names: mix.channels.iter().map(|c| c.name.clone()).collect(),
            branch_names: mix.branches.iter().map(|b| b.name.clone()).collect(),
            ch_branch: mix.channels.iter().map(|c| c.branch).collect(),
            interval: mix
                .channels
                .iter()
                .map(|c| mix.clock_hz.checked_div(c.rate_hz).unwrap_or(0))
                .collect(),
            spf,
            spf0,
            last: vec![0; n],
            has_last: vec![false; n],
            in_frame: vec![0; n],
            samples: vec![0; n],
            imin: vec![u64::MAX; n],
            imax: vec![0; n],
            frame: 0,
            frame_cycles: mix.frame_cycles(),
            queue: VecDeque::new(),
            slack: mix.branches.iter().map(|b| b.chain as u64).sum::<u64>() + 1,
            emitted: 0,
            conversions: 0,
            origin: 0,
            spf_m,
            interval_m,
            mc: ModeCheck::new(s).map(Box::new),
            cur_mode: 0,
            mode_names: (s.mix.modes.as_ref()).map_or(vec![], |m| m.names.clone()),
            stat_m: vec![vec![(0, u64::MAX, 0); n]; s.modes.len()],
            prepared: prepared_conversions(s),
            blind_until: None,
        }
    }

    /// A conversion at cycle `t` whose channel the check cannot know (its
    /// command word was sent before the check joined): its frame's counts
    /// are not checked.
    pub fn blind(&mut self, t: u64) {
        self.blind_until = Some(t);
    }

    /// A mix with switches: cycle `c`'s `mode_sel` and `mode` (before its
    /// instants): the mode rules, and at a frame start the counts and
    /// intervals of the mode the design shows (intervals restart at a switch).
    #[inline]
    pub fn mode_cycle(&mut self, c: u64, mode_sel: u8, mode: u8) {
        let Some(mc) = &mut self.mc else {
            return;
        };
        let v = mc.cycle(c, mode_sel, mode);
        let shown = mc.shown;
        if let Some(v) = v {
            self.rec.record(v);
        }
        if shown != self.cur_mode {
            self.cur_mode = shown;
            self.interval.clone_from(&self.interval_m[shown]);
            self.has_last.iter_mut().for_each(|h| *h = false);
        }
    }

    /// The check joins a run at model cycle `origin` (in steady state, after
    /// frame 0), which is cycle `capture_cycle` of the capture: reports
    /// give capture cycles and count frames from the one joined.  That first
    /// frame is partial: its counts are checked against the maximum only.
    pub fn join_at(&mut self, origin: u64, capture_cycle: u64) {
        self.origin = origin;
        self.frame = origin / self.frame_cycles;
        self.rec.shift = origin - capture_cycle;
        self.rec.frame_base = self.frame;
        if let Some(mc) = &mut self.mc {
            mc.join(self.frame);
        }
    }

    /// (cycle, frame, slot) of model cycle `c` as reports give them.
    pub(crate) fn place(&self, c: u64) -> (u64, u64, u64) {
        self.rec.place(c)
    }

    fn name(&self, ch: Option<u16>) -> Option<String> {
        ch.and_then(|c| self.names.get(c as usize).cloned())
    }

    /// Closes every frame that ends at or before cycle `c`.
    pub fn close_frames(&mut self, c: u64) {
        while (self.frame + 1) * self.frame_cycles <= c {
            let end = (self.frame + 1) * self.frame_cycles - 1;
            let spf = match &self.mc {
                _ if self.frame == 0 => &self.spf0,
                Some(mc) => &self.spf_m[mc.shown],
                None => &self.spf,
            };
            let start = self.frame * self.frame_cycles;
            let partial = start < self.origin || self.blind_until.is_some_and(|b| start <= b);
            for (ch, &want) in spf.iter().enumerate() {
                let want = want
                    - self
                        .prepared
                        .iter()
                        .filter(|&&p| p == (self.frame, ch))
                        .count() as u64;
                let n = self.in_frame[ch];
                if (partial && n > want) || (!partial && n != want) {
                    let name = self.names[ch].clone();
                    self.rec.record(
                        Violation::new(Rule::SamplesPerFrame, end)
                            .expected(json!(want))
                            .actual(json!(self.in_frame[ch]))
                            .channel(name.clone())
                            .detail(format!(
                                "{name} sampled {} times in frame {}, expected {}{want}",
                                self.in_frame[ch],
                                self.frame - self.rec.frame_base,
                                if partial { "at most " } else { "" }
                            )),
                    );
                }
                self.in_frame[ch] = 0;
            }
            if let Some(mc) = &mut self.mc {
                mc.frame_start();
            }
            self.frame += 1;
        }
    }

    /// A sampling instant of `channel` on `branch` at cycle `t`.
    #[inline]
    pub fn instant(&mut self, t: u64, branch: usize, channel: u16) {
        let ch = channel as usize;
        if t >= (self.frame + 1) * self.frame_cycles {
            self.close_frames(t);
        }
        if ch >= self.names.len() {
            self.rec.record(
                Violation::new(Rule::Channel, t)
                    .actual(json!(ch))
                    .detail(format!("channel index {ch} is not in the mix")),
            );
            return;
        }
        if self.ch_branch[ch] != branch {
            let name = self.names[ch].clone();
            self.rec.record(
                Violation::new(Rule::Branch, t)
                    .expected(json!(self.branch_names[self.ch_branch[ch]]))
                    .actual(json!(self.branch_names[branch]))
                    .channel(name.clone())
                    .detail(format!("{name} sampled on the wrong branch")),
            );
        }
        self.in_frame[ch] += 1;
        self.samples[ch] += 1;
        let mut per = self.stat_m.get_mut(self.cur_mode).map(|m| &mut m[ch]);
        if let Some(p) = per.as_deref_mut() {
            p.0 += 1;
        }
        if self.has_last[ch] {
            let d = t - self.last[ch];
            self.imin[ch] = self.imin[ch].min(d);
            self.imax[ch] = self.imax[ch].max(d);
            if let Some(p) = per {
                (p.1, p.2) = (p.1.min(d), p.2.max(d));
            }
            if d != self.interval[ch] && self.interval[ch] != 0 {
                let name = self.names[ch].clone();
                self.rec.record(
                    Violation::new(Rule::Interval, t)
                        .expected(json!(self.interval[ch]))
                        .actual(json!(d))
                        .channel(name.clone())
                        .detail(format!("{name} sampled {d} cycles after its previous instant (cycle {}), expected {}", self.rec.cycle(self.last[ch]), self.interval[ch])),
                );
            }
        }
        self.has_last[ch] = true;
        self.last[ch] = t;
    }

    fn expire(&mut self, c: u64) {
        while let Some(p) = self.queue.front() {
            if p.complete + self.slack >= c {
                break;
            }
            let p = *p;
            self.queue.pop_front();
            self.rec.record(
                Violation::new(Rule::SampleMissing, p.complete)
                    .signal(Role::SampleValid.name().to_string())
                    .expected(json!(1))
                    .actual(json!(0))
                    .channel(self.name(p.channel))
                    .detail(format!(
                        "conversion of branch {} sampled at cycle {} completed at cycle {} but was never emitted",
                        self.branch_names[p.branch], self.rec.cycle(p.instant), self.rec.cycle(p.complete)
                    )),
            );
        }
    }

    /// A conversion completed (CS rose) at cycle `c`; `code` is the 14-bit word
    /// read from MISO (`None` if x/z was captured), `channel` the one selected
    /// at the sampling instant `instant`.
    #[inline]
    pub fn completion(
        &mut self,
        c: u64,
        branch: usize,
        channel: Option<u16>,
        code: Option<u16>,
        instant: u64,
    ) {
        self.completion_by_word(c, branch, channel, code, instant, None)
    }

    /// [`Invariants::completion`] of a commanded branch's conversion, whose
    /// `channel` the word sent in the conversion at `word_at` selected.
    #[inline]
    pub fn completion_by_word(
        &mut self,
        c: u64,
        branch: usize,
        channel: Option<u16>,
        code: Option<u16>,
        instant: u64,
        word_at: Option<u64>,
    ) {
        self.conversions += 1;
        if let (Some(mc), Some(ch), Some(v)) = (&mut self.mc, channel, code) {
            mc.track.sample(ch as usize, v);
        }
        self.expire(c);
        self.queue.push_back(Pending {
            complete: c,
            instant,
            branch,
            channel,
            code,
            word_at,
        });
    }

    /// `sample_valid` was high in cycle `c` with this channel and value.
    #[inline]
    pub fn emitted(&mut self, c: u64, channel: u16, value: u16) {
        self.emitted += 1;
        self.expire(c);
        // The merged stream sends the lowest branch's waiting word first
        // (a chain's words in member order); within a branch, in order.
        // (one word waiting, as in most cycles: no search)
        let pick = match self.queue.len() {
            1 => 0,
            _ => (self.queue.iter().enumerate())
                .filter(|(_, q)| q.complete < c)
                .min_by_key(|(i, q)| (q.branch, *i))
                .map_or(0, |(i, _)| i),
        };
        let Some(p) = self.queue.remove(pick) else {
            self.rec.record(
                Violation::new(Rule::SampleUnexpected, c)
                    .signal(Role::SampleValid.name().to_string())
                    .expected(json!(0))
                    .actual(json!(1))
                    .channel(self.name(Some(channel)))
                    .detail(format!(
                        "{} with channel {channel} value {value} but no conversion is waiting",
                        Role::SampleValid.name()
                    )),
            );
            return;
        };
        if p.complete >= c {
            self.rec.record(
                Violation::new(Rule::SampleEarly, c)
                    .signal(Role::SampleValid.name().to_string())
                    .channel(self.name(p.channel))
                    .detail(format!(
                        "sample emitted in cycle {}, before its conversion completed (cycle {})",
                        self.rec.cycle(c),
                        self.rec.cycle(p.complete)
                    )),
            );
        }
        if let (Some(ch), Some(at)) = (p.channel, p.word_at) {
            if ch != channel {
                let name = self
                    .names
                    .get(ch as usize)
                    .map(String::as_str)
                    .unwrap_or("?");
                self.rec.record(
                    Violation::new(Rule::CommandChannel, c)
                        .signal(Role::SampleChannel.name().to_string())
                        .expected(json!(ch))
                        .actual(json!(channel))
                        .channel(self.name(Some(ch)))
                        .detail(format!(
                            "{} {channel} but the command word sent in the conversion at cycle {} selected {ch} ({name}) for the conversion sampled at cycle {}",
                            Role::SampleChannel.name(),
                            self.rec.cycle(at),
                            self.rec.cycle(p.instant)
                        )),
                );
            }
        } else if let Some(ch) = p.channel {
            if ch != channel {
                self.rec.record(
                    Violation::new(Rule::SampleChannel, c)
                        .signal(Role::SampleChannel.name().to_string())
                        .expected(json!(ch))
                        .actual(json!(channel))
                        .channel(self.name(Some(ch)))
                        .detail(format!(
                            "{} {channel} but the mux selected {} ({}) at the sampling instant (cycle {})",
                            Role::SampleChannel.name(),
                            ch,
                            self.names.get(ch as usize).map(String::as_str).unwrap_or("?"),
                            self.rec.cycle(p.instant)
                        )),
                );
            }
        }
        if let Some(code) = p.code {
            if code != value {
                self.rec.record(
                    Violation::new(Rule::SampleValue, c)
                        .signal(Role::SampleValue.name().to_string())
                        .expected(json!(code))
                        .actual(json!(value))
                        .channel(self.name(p.channel))
                        .detail(format!("{} {value:#06x} but MISO carried {code:#06x} (conversion sampled at cycle {})", Role::SampleValue.name(), self.rec.cycle(p.instant))),
                );
            }
        }
    }

    /// Ends the check after `cycles` cycles: closes complete frames and flags
    /// conversions still waiting.
    ///
    /// Per-frame counts are checked on complete frames only; in a trailing
    /// partial frame a channel may not exceed its samples per frame (its
    /// samples still count in the channel statistics).
    /// `cycles` is the model cycle the check ended at; the frames returned
    /// are the complete frames checked.
    pub fn finish(&mut self, cycles: u64) -> (u64, Vec<ChannelStats>) {
        let frames = cycles / self.frame_cycles;
        self.close_frames(frames * self.frame_cycles);
        if cycles > frames * self.frame_cycles {
            let spf = match &self.mc {
                _ if frames == 0 => &self.spf0,
                // the mode the design showed at the partial frame's start
                Some(mc) => &self.spf_m[mc.shown],
                None => &self.spf,
            };
            for (ch, &most) in spf.iter().enumerate() {
                if self.in_frame[ch] > most {
                    let name = self.names[ch].clone();
                    self.rec.record(
                        Violation::new(Rule::SamplesPerFrame, cycles - 1)
                            .expected(json!(most))
                            .actual(json!(self.in_frame[ch]))
                            .channel(name.clone())
                            .detail(format!(
                                "{name} sampled {} times in the first {} cycles of frame {}, expected {most} in the whole frame",
                                self.in_frame[ch],
                                cycles % self.frame_cycles,
                                frames - self.rec.frame_base,
                            )),
                    );
                }
            }
        }
        self.expire(cycles);
        let channels = (0..self.names.len())
            .map(|c| ChannelStats {
                name: self.names[c].clone(),
                branch: self.branch_names[self.ch_branch[c]].clone(),
                samples: self.samples[c],
                interval_cycles: self.interval[c],
                interval_cycles_min: (self.imin[c] != u64::MAX).then_some(self.imin[c]),
                interval_cycles_max: (self.imin[c] != u64::MAX).then_some(self.imax[c]),
                modes: self.mode_stats(c),
            })
            .collect();
        let first_whole = self.origin.div_ceil(self.frame_cycles);
        (frames.saturating_sub(first_whole), channels)
    }

    /// Channel `c`'s figures in each mode (empty without modes).
    fn mode_stats(&self, c: usize) -> Vec<ModeStats> {
        (self.stat_m.iter().enumerate())
            .map(|(m, st)| {
                let (samples, lo, hi) = st[c];
                ModeStats {
                    mode: self
                        .mode_names
                        .get(m)
                        .cloned()
                        .unwrap_or_else(|| m.to_string()),
                    samples,
                    interval_cycles: self.interval_m[m][c],
                    interval_cycles_min: (lo != u64::MAX).then_some(lo),
                    interval_cycles_max: (lo != u64::MAX).then_some(hi),
                }
            })
            .collect()
    }

    /// Records a violation found outside the conversion-level checks.
    pub fn record(&mut self, v: Violation) {
        self.rec.record(v)
    }

    pub fn violation_count(&self) -> u64 {
        self.rec.violation_count
    }

    /// Builds the report (call [`Invariants::finish`] first).
    pub fn report(
        self,
        source: &str,
        mix: &str,
        cycles: u64,
        frames: u64,
        channels: Vec<ChannelStats>,
        samples: u64,
    ) -> Verdict {
        Verdict {
            ok: self.rec.violation_count == 0 && cycles > 0,
            mix: mix.into(),
            source: source.into(),
            cycles,
            frames,
            partial_frame_cycles: cycles - frames * self.frame_cycles,
            samples,
            channels,
            divergence_count: 0,
            divergences: Vec::new(),
            violation_count: self.rec.violation_count,
            violations: self.rec.violations,
            model_compared: false,
            link_join: None,
        }
    }

    pub fn emitted_count(&self) -> u64 {
        self.emitted
    }
}

/// (frame, channel) of the conversions after reset that are prepared, not
/// data: each commanded branch's first `ahead` conversions (the gateware
/// performs them, reads nothing of them; `Schedule::prepared_conversions`).
fn prepared_conversions(s: &Schedule) -> Vec<(u64, usize)> {
    let fc = s.grid.frame_cycles;
    let mut out = Vec::new();
    for b in 0..s.branches.len() {
        let n = s.prepared_conversions(b) as usize;
        if n == 0 {
            continue;
        }
        let performed = s
            .instants(n as u64 + 1)
            .filter(|i| i.branch == b && !(i.cycle < fc && s.skipped_at_startup(b, i.cycle)));
        out.extend(performed.take(n).map(|i| (i.cycle / fc, i.channel)));
    }
    out
}
