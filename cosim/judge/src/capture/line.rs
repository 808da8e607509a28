//! The link's line in a logic-analyser capture (`link_tx` mapped): the UART
//! is decoded from the capture's samples by the `link` crate (its receiver
//! and its host decoder, the same a host runs), and every packet's samples
//! must be the schedule's channels in the schedule's order for its slice
//! (`lut_gen::merged_frame`), with good CRCs and no packet lost.
//!
//! Once the edge check has found the frame phase (`LinkPhase`), the cycle
//! model runs along the capture and predicts the line: every byte's start
//! bit must fall within the capture's resolution of the model's time (the
//! packet format has no escapes, so the timing does not depend on the
//! values), and where a branch's `adc_miso` is captured too, the model is
//! fed the bits MISO carried, so each record byte of that branch's channels
//! must be the code MISO carried.

use lut_gen::Role;
use lut_gen::Schedule;

use crate::capture::check::{Capture, Lane, TimedViolation};
use crate::model::CycleModel;

/// The frame phase the edge check found: model cycle 0 at a time in
/// `[lo, hi]`; all in units of 1 / clock_hz ps (the capture check's exact times), with
/// the sample period `t` and the skew.
#[derive(Debug, Clone, Copy)]
pub struct LinkPhase {
    pub lo: i128,
    pub hi: i128,
    pub t: i128,
    pub skew: i128,
}

/// One cycle in units.
pub(crate) const TC: i128 = 1_000_000_000_000;

/// What the line showed.
pub struct LinkCheck {
    pub violations: Vec<TimedViolation>,
    pub proved: Vec<String>,
    pub not_proved: Vec<String>,
    /// Where the line was joined (a UART line decoded from the capture).
    pub join: Option<LineJoin>,
}

/// Where a capture's line was joined: at its first whole packet.  What
/// came before (bytes in flight when the capture began) was not judged.
#[derive(Debug, Clone, PartialEq)]
pub struct LineJoin {
    /// `"model"`: the packets decoded and every character from the joined
    /// packet's header on timed against the model (and its records held
    /// to the codes MISO carried); `"decoder"` (`--no-model`): the packets
    /// decoded and judged, not timed.
    pub by: &'static str,
    /// False: the line was not judged (`why_not` says why).
    pub judged: bool,
    pub why_not: Option<String>,
    /// The capture's time of the joined packet's header (its SYNC byte's
    /// start bit), its frame counter and slice.
    pub header_ps: Option<u64>,
    pub frame_counter: Option<u8>,
    pub slice: Option<u16>,
    /// Characters read before it: skipped.
    pub skipped_bytes: u64,
    /// The capture's time before the header (the whole capture when not
    /// joined): the line there was not judged, a fault there is not seen.
    pub unjudged_ps: u64,
}

impl LineJoin {
    /// The line the text report gives it.
    pub fn text(&self) -> String {
        let (Some(h), Some(f), Some(s)) = (self.header_ps, self.frame_counter, self.slice) else {
            return format!(
                "link: NOT JUDGED: {}: nothing of the link in the capture's {:.3} us was checked",
                self.why_not.as_deref().unwrap_or("no whole packet"),
                self.unjudged_ps as f64 / 1e6,
            );
        };
        let what = match self.by {
            "model" => "every character from its header on timed against the model",
            _ => "every packet from it on decoded and judged, not timed against the model",
        };
        format!(
            "link: joined the line at its first whole packet (frame counter {f}, slice {s}; its header at {:.3} us; {what}); the line before it was not judged: its first {:.3} us and {} byte(s), in flight when the capture began, were skipped (a fault there is not seen)",
            h as f64 / 1e6,
            self.unjudged_ps as f64 / 1e6,
            self.skipped_bytes
        )
    }
}

/// The channels of each slice's packet in steady state, in order.
pub(crate) fn packet_order(s: &Schedule) -> Vec<Vec<u16>> {
    let g = &s.grid;
    let mut per_slice = vec![Vec::new(); g.slices_per_frame as usize];
    for (cycle, _, ch) in lut_gen::merged_frame(s) {
        let k = (cycle / g.slice_cycles % g.slices_per_frame) as usize;
        per_slice[k].push(ch);
    }
    per_slice
}

/// [`packet_order`] of a frame in mode `m` after a frame in mode `p` (a
/// mix with modes): the samples whose `sample_valid` falls in each slice
/// of it.
fn packet_order_across(s: &Schedule, (m, p): (u8, u8)) -> Vec<Vec<u16>> {
    let g = &s.grid;
    let f = g.frame_cycles;
    let (sm, sp) = (&s.modes[m as usize], &s.modes[p as usize]);
    let mut per_slice = vec![Vec::new(); g.slices_per_frame as usize];
    for (cycle, _, ch) in lut_gen::merged_run(&[sp, sp, sm, sm]) {
        if (2 * f..3 * f).contains(&cycle) {
            per_slice[((cycle - 2 * f) / g.slice_cycles) as usize].push(ch);
        }
    }
    per_slice
}

/// Decodes lane `li` of `cap` (the line) and checks it against `s`; with
/// the model and the frame phase (the one of `phases`, the candidates the
/// pins fit, that the line's characters fit), also every byte's timing
/// and the sample codes.
pub fn check_link(
    s: &Schedule,
    cap: &Capture,
    li: usize,
    phases: &[LinkPhase],
    modes: &[Vec<usize>],
    model: bool,
) -> LinkCheck {
    let lane = &cap.lanes[li];
    let mut out = LinkCheck {
        violations: Vec::new(),
        proved: Vec::new(),
        not_proved: Vec::new(),
        join: None,
    };
    let plan = match lut_gen::plan_link(s) {
        Some(Ok(p)) => p,
        _ => {
            out.not_proved
                .push("the link's samples: the mix plans no link".into());
            return out;
        }
    };
    let Some(fmt) = plan.uart() else {
        // an AXI4-Stream link's beats: `axis`
        return out;
    };
    // A bit must span at least two analyser samples to be read.
    let bit_ps = fmt.div as f64 * 1e12 / s.mix.clock_hz as f64;
    if bit_ps < 2.0 * cap.period_ps as f64 {
        out.not_proved.push(format!(
            "{} (link_tx): a UART bit lasts {:.1} ns, under two analyser samples ({:.1} ns each); a faster analyser decodes it",
            lane.channel,
            bit_ps / 1e3,
            cap.period_ps as f64 / 1e3
        ));
        return out;
    }
    let line = read_line(s, cap, li, fmt, &mut out);
    let end = cap.steps.last().map(|x| x.0).unwrap_or(0);
    let t0 = cap.steps.first().map_or(0, |x| x.0);
    out.join = Some(line.joined(model, (t0, end)));
    if line.stats.overflows > 0 {
        out.violations.push(order_violation(
            lane,
            end as f64,
            format!(
                "a trailer reports {} token(s) dropped by the FIFO",
                line.stats.overflows
            ),
        ));
    }
    check_order(s, lane, &line.packets, &mut out);
    let packets = &line.packets;
    if packets.is_empty() {
        // A capture long enough that some packet must have begun and ended
        // in it: the line is broken.  A shorter one: not judged, and said so.
        let due =
            (2 * s.grid.slice_cycles + plan.latency_cycles) as f64 * 1e12 / s.mix.clock_hz as f64;
        let what = format!(
            "no good packet decoded from the line ({} bytes read at {:.0} baud)",
            line.stats.bytes, plan.baud
        );
        if (end - t0) as f64 > due {
            out.violations.push(order_violation(lane, end as f64, what));
        } else {
            out.not_proved.push(format!(
                "{} (link_tx): the line: {what} in a capture shorter than two slices and the link's latency ({:.3} us)",
                lane.channel,
                due / 1e6
            ));
        }
        return out;
    }
    let samples: usize = packets.iter().map(|p| p.3.len()).sum();
    out.proved.push(format!(
        "{} (link_tx): {} packets and {samples} samples decoded at {:.0} baud, each packet's channels in the schedule's order for its slice, CRCs good, none lost",
        lane.channel,
        packets.len(),
        plan.baud
    ));
    let from = line.join.map_or(0, |j| j.0);
    match (model, phases) {
        (false, _) => out.not_proved.push(format!(
            "{} (link_tx): the bytes' timing and the sample codes (--no-model: the line is decoded, not held to the model)",
            lane.channel
        )),
        (true, []) => out.not_proved.push(format!(
            "{} (link_tx): the bytes' timing and the sample codes (no frame phase to time them against)",
            lane.channel
        )),
        (true, _) => hold_bytes(s, cap, li, (phases, modes), (&line.chars, from), &mut out),
    }
    out
}

/// A violation of the packets' order on the line, at `t` ps.
pub(crate) fn order_violation(lane: &Lane, t: f64, detail: String) -> TimedViolation {
    TimedViolation {
        time_ps: t as u64,
        channel: lane.channel.clone(),
        port_bit: lane.port_bit(),
        rule: "link samples (order on the line)".into(),
        detail,
    }
}

/// A decoded packet: (time, frame, slice, channels, (mode, mode of the
/// frame before): 0 without modes).
pub(crate) type LinePacket = (f64, u64, u16, Vec<u16>, (u8, u8));

/// What the host's receiver and decoder read from the line.
pub(crate) struct LineRead {
    pub(crate) packets: Vec<LinePacket>,
    /// Every character read: (the capture's time of its start bit's edge, byte).
    pub(crate) chars: Vec<(u64, u8)>,
    pub(crate) stats: link::Stats,
    /// The first good packet: the index in `chars` of its header, its
    /// frame counter and slice.
    pub(crate) join: Option<(usize, u8, u16)>,
}

impl LineRead {
    /// Where the line was joined, in a capture of times `[t0, end]` (ps).
    pub(crate) fn joined(&self, model: bool, (t0, end): (u64, u64)) -> LineJoin {
        let header = self
            .join
            .map(|(i, _, _)| self.chars.get(i).map_or(end, |c| c.0));
        LineJoin {
            by: if model { "model" } else { "decoder" },
            judged: self.join.is_some(),
            why_not: self.join.is_none().then(|| {
                format!(
                    "the capture shows no whole packet to join the line at ({} character(s) read)",
                    self.chars.len()
                )
            }),
            header_ps: header,
            frame_counter: self.join.map(|j| j.1),
            slice: self.join.map(|j| j.2),
            skipped_bytes: self.join.map_or(self.chars.len(), |j| j.0) as u64,
            unjudged_ps: header.unwrap_or(end) - t0,
        }
    }
}

/// Lane `li` of the capture as the receiver samples it, once per clock
/// cycle from the capture's first sample, with the time of each fall.
struct LineSampler {
    /// The capture's step in force.
    k: usize,
    level: bool,
    fall_ps: u64,
    /// Falls of the line seen at a cycle's sample: (sample, edge time).
    falls: std::collections::VecDeque<(u64, u64)>,
}

impl LineSampler {
    /// The line at sample `n`, time `t` (ps).
    #[inline]
    fn sample(&mut self, cap: &Capture, li: usize, n: u64, t: f64) -> bool {
        let steps = &cap.steps;
        while self.k + 1 < steps.len() && (steps[self.k + 1].0 as f64) <= t {
            if steps[self.k].1 >> li & 1 == 1 && steps[self.k + 1].1 >> li & 1 == 0 {
                self.fall_ps = steps[self.k + 1].0;
            }
            self.k += 1;
        }
        let now = steps[self.k].1 >> li & 1 == 1;
        if self.level && !now {
            self.falls.push_back((n, self.fall_ps));
        }
        self.level = now;
        now
    }

    /// The edge time of the fall at sample `start`, if one was seen there.
    fn fall_at(&mut self, start: u64) -> Option<u64> {
        while self.falls.front().is_some_and(|f| f.0 < start) {
            self.falls.pop_front();
        }
        self.falls
            .front()
            .filter(|f| f.0 == start)
            .map(|&(_, edge)| edge)
    }
}

/// The line read once per clock cycle from the capture's first sample:
/// the receiver a host runs, over the analyser's samples.  Framing, CRC and
/// lost-packet faults go to `out`.
fn read_line(
    s: &Schedule,
    cap: &Capture,
    li: usize,
    fmt: link::UartFormat,
    out: &mut LinkCheck,
) -> LineRead {
    let lane = &cap.lanes[li];
    let tc = 1e12 / s.mix.clock_hz as f64;
    let t0 = cap.steps.first().map(|x| x.0).unwrap_or(0) as f64;
    let end = cap.steps.last().map(|x| x.0).unwrap_or(0) as f64;
    let mut rx = link::UartRx::new(fmt);
    let mut dec = crate::line::decoder(s);
    let mut line = LineSampler {
        k: 0,
        level: true,
        fall_ps: 0,
        falls: Default::default(),
    };
    let mut n = 0u64;
    let mut decoded = Vec::new();
    let mut packets: Vec<LinePacket> = Vec::new();
    let mut framing = 0u64;
    let (mut crc, mut lost) = (0u64, 0u64);
    let mut chars: Vec<(u64, u8)> = Vec::new();
    let mut join = None;
    loop {
        let t = t0 + n as f64 * tc;
        if t > end {
            break;
        }
        let now = line.sample(cap, li, n, t);
        n += 1;
        let Some(b) = rx.sample(now) else {
            continue;
        };
        if let Some(edge) = line.fall_at(b.start) {
            if !b.error {
                chars.push((edge, b.byte));
            }
        }
        if b.error {
            if packets.is_empty() {
                // Out of step: the capture opened inside a character.
                continue;
            }
            framing += 1;
            if framing == 1 {
                out.violations.push(order_violation(
                    lane,
                    t,
                    format!("character 0x{:02x} with a bad stop or parity bit", b.byte),
                ));
            }
            continue;
        }
        decoded.clear();
        dec.push_packets(&[b.byte], &mut decoded);
        for d in decoded.drain(..) {
            if join.is_none() {
                // the packet's header, if its start bit was seen with the rest
                let i = chars.len().saturating_sub(4 * (2 + d.records.len()));
                let sync = chars.get(i).is_some_and(|c| c.1 == link::format::SYNC);
                join = Some((if sync { i } else { chars.len() }, d.frame as u8, d.slice));
            }
            let chans = d.records.iter().map(|r| r.0).collect();
            packets.push((t, d.frame, d.slice, chans, (d.mode, d.prev_mode)));
        }
        let st = dec.stats();
        if st.crc_errors > crc {
            crc = st.crc_errors;
            out.violations
                .push(order_violation(lane, t, "a packet with a bad CRC".into()));
        }
        if st.lost_packets > lost && !packets.is_empty() {
            out.violations.push(order_violation(
                lane,
                t,
                format!(
                    "{} packet(s) missing before this one",
                    st.lost_packets - lost
                ),
            ));
        }
        lost = st.lost_packets;
    }
    LineRead {
        packets,
        chars,
        stats: dec.finish(),
        join,
    }
}

/// Every packet's channels must be the schedule's for its slice (the first
/// three that are not are listed).
pub(crate) fn check_order(s: &Schedule, lane: &Lane, packets: &[LinePacket], out: &mut LinkCheck) {
    let order = packet_order(s);
    let mut wrong = 0;
    for (t, frame, slice, chans, modes) in packets {
        let want = match s.modes.len() > 1 {
            true => packet_order_across(s, *modes),
            false => order.clone(),
        };
        let want = want.get(*slice as usize).cloned().unwrap_or_default();
        if *chans != want {
            wrong += 1;
            if wrong <= 3 {
                out.violations.push(order_violation(
                    lane,
                    *t,
                    format!(
                        "the packet of frame {frame} slice {slice} carries channels {}; the schedule's order is {}",
                        channel_list(chans),
                        channel_list(&want)
                    ),
                ));
            }
        }
    }
}

/// A byte the model puts on the line: its start bit's first cycle (in the
/// capture's cycles from the phase), the byte, and for a record byte the
/// channel it carries and whether every MISO read of its conversion was
/// resolved in the capture (else the model's code is not the board's).
struct Predicted {
    cycle: i128,
    byte: u8,
    record: Option<(u16, bool)>,
}

/// The branches whose MISO is captured (bit b: branch b) and the capture's
/// lane of each.
fn miso_lanes(cap: &Capture) -> Vec<(usize, u32)> {
    (0..cap.lanes.len())
        .filter(|&i| cap.lanes[i].role == Some(Role::Miso))
        .map(|i| (i, cap.lanes[i].bit))
        .collect()
}

/// MISO of one branch as the capture shows it around the edges that read
/// it: known only where no sample in the edge's window of uncertainty (the
/// phase's spread, a sample period and the skew either side) changes it.
struct MisoReader<'a> {
    cap: &'a Capture,
    lane: usize,
    /// The first step not before the last window's start.
    k: usize,
}

impl MisoReader<'_> {
    /// The level over `[a, b]` (ps), if the capture shows it constant there.
    fn level(&mut self, a: u64, b: u64) -> Option<bool> {
        let steps = &self.cap.steps;
        while self.k + 1 < steps.len() && steps[self.k + 1].0 <= a {
            self.k += 1;
        }
        if steps.first().is_none_or(|x| x.0 > a) {
            // Before the capture began.
            return None;
        }
        let bit = |i: usize| steps[i].1 >> self.lane & 1 == 1;
        let v = bit(self.k);
        let mut i = self.k + 1;
        while i < steps.len() && steps[i].0 <= b {
            if bit(i) != v {
                return None;
            }
            i += 1;
        }
        Some(v)
    }
}

/// The modes the model is held to, `(model frame, mode)` for its frames 2
/// to `to`: model frame `k` is the phase's frame `k - shift` (`seen`'s
/// first mode before it, its last after it).
pub(crate) fn forced_modes(seen: &[usize], shift: i128, to: i128) -> Vec<(u64, usize)> {
    let Some(&first) = seen.first() else {
        return Vec::new();
    };
    (2..=to.max(2))
        .map(|k| {
            let w = k - shift;
            let m = if w < 0 {
                first
            } else {
                seen[(w as usize).min(seen.len() - 1)]
            };
            (k as u64, m)
        })
        .collect()
}

/// The cycle model at the phase's cycle `first` plus a whole number of
/// frames (returned): the least that puts `first` in frame 1 or later, in
/// steady state (with modes, frame 2: the first whose mode can be other
/// than reset's), held to the modes `seen` through the phase's `last`.
pub(crate) fn steady_model(
    s: &Schedule,
    seen: &[usize],
    (first, last): (i128, i128),
) -> (CycleModel, i128) {
    let f = s.grid.frame_cycles as i128;
    let least = if seen.is_empty() { 1 } else { 2 };
    let shift = f * (((least * f - first).max(0) + f - 1) / f).max(least);
    let mut m = CycleModel::with_modes(s, &forced_modes(seen, shift / f, (last + shift) / f));
    while (m.cycle() as i128) < first + shift {
        m.step(0);
    }
    (m, shift)
}

/// What the model predicts of the line along the capture.
struct Prediction {
    bytes: Vec<Predicted>,
}

/// Which samples' codes the capture resolved: a conversion is known when
/// every MISO read in it was (`cur`), a sample when its conversion was, and
/// a record on the line when its sample was (queued per channel, as the
/// transmitter sends them in order).  Conversions before the capture began
/// are unknown.
struct Known {
    cur: Vec<bool>,
    done: Vec<bool>,
    queued: Vec<std::collections::VecDeque<bool>>,
    record: Vec<bool>,
}

/// Runs the cycle model along the capture (a whole number of frames on,
/// in steady state: the capture may start before the phase's cycle 0 is a
/// frame old) and collects the bytes it puts on the line.  MISO, where it is
/// captured, is fed as read at each edge that reads it (0 where unknown).
/// A mix with modes: `seen` is the mode of each of the phase's frames as the
/// capture showed them, which the model runs in (the frames before the
/// first in its mode), not the reset mode's.
fn predict(
    s: &Schedule,
    cap: &Capture,
    (ph, seen): (LinkPhase, &[usize]),
    clock: i128,
) -> Prediction {
    let mid = (ph.lo + ph.hi) / 2;
    let t0 = cap.steps.first().map_or(0, |x| x.0) as i128 * clock;
    let end = cap.steps.last().map_or(0, |x| x.0) as i128 * clock;
    let first = (t0 - mid).div_euclid(TC) - 1;
    let last = (end - mid).div_euclid(TC) + 1;
    let (mut m, _) = steady_model(s, seen, (first, last));
    let mut readers: Vec<(u32, MisoReader)> = miso_lanes(cap)
        .into_iter()
        .map(|(lane, b)| (b, MisoReader { cap, lane, k: 0 }))
        .collect();
    let nb = s.mix.branches.len();
    let mut known = Known {
        cur: vec![false; nb],
        done: vec![false; nb],
        queued: vec![Default::default(); s.mix.channels.len()],
        record: vec![false; s.mix.channels.len()],
    };
    let cnv = crate::capture::check::cnv_mask(s);
    let sel: Vec<(u32, usize)> = (cap.lanes.iter().enumerate())
        .filter(|(_, l)| l.mode == Some(crate::capture::check::ModePin::Sel))
        .map(|(i, l)| (l.bit, i))
        .collect();
    let mut out = Vec::new();
    let mut prev = *m.pins();
    for c in first..=last {
        let p = *m.pins();
        let (was, now) = (prev.cs_n ^ cnv, p.cs_n ^ cnv);
        for b in 0..nb {
            match (was >> b & 1, now >> b & 1) {
                (1, 0) => known.cur[b] = true,
                (0, 1) => known.done[b] = known.cur[b],
                _ => {}
            }
        }
        if p.sample_valid {
            let ch = p.sample_channel as usize;
            if let Some(q) = known.queued.get_mut(ch) {
                q.push_back(known.done[s.mix.channels[ch].branch]);
            }
        }
        if prev.link_tx && !p.link_tx {
            if let Some((b, 0)) = m.link_byte() {
                let record = match (b.kind, b.sample) {
                    (link::format::WordKind::Record, Some((ch, _))) => {
                        let k = ch as usize;
                        if b.index == 0 {
                            known.record[k] = known.queued[k].pop_front().unwrap_or(false);
                        }
                        Some((ch, known.record[k]))
                    }
                    _ => None,
                };
                out.push(Predicted {
                    cycle: c,
                    byte: b.byte,
                    record,
                });
            }
        }
        prev = p;
        let mut miso = 0u64;
        let reading = m.capturing();
        if reading != 0 {
            // The edge ending cycle c, at phi + (c + 1) TC with phi in [lo, hi].
            let e = (c + 1) * TC;
            let a = (ph.lo + e - ph.skew - ph.t).div_euclid(clock).max(0) as u64;
            let b = (ph.hi + e + ph.skew + ph.t).div_euclid(clock).max(0) as u64 + 1;
            for (br, rd) in &mut readers {
                if reading >> *br & 1 == 0 {
                    continue;
                }
                match rd.level(a, b) {
                    Some(v) => miso |= (v as u64) << *br,
                    None => known.cur[*br as usize] = false,
                }
            }
        }
        if !sel.is_empty() {
            // pin select: the requests as the capture shows them mid-cycle
            let ps = ((mid + c * TC + TC / 2).div_euclid(clock)).max(0) as u64;
            let v = cap.steps[cap.steps.partition_point(|x| x.0 <= ps).max(1) - 1].1;
            let bits = sel
                .iter()
                .fold(0u8, |a, &(k, l)| a | ((v >> l & 1) as u8) << k);
            m.set_mode_sel(bits);
        }
        m.step(miso);
    }
    Prediction { bytes: out }
}

/// Holds every character read from the line from index `from` (the first
/// whole packet's header) on against the model's bytes: its start bit
/// within the resolution of the model's start bit, and, for a record of a
/// branch whose MISO is captured, the same byte.  Of several frame phases
/// the pins fit alike, the line's characters pick the one they fit best
/// (its slices are where the packets say).
fn hold_bytes(
    s: &Schedule,
    cap: &Capture,
    li: usize,
    (phases, modes): (&[LinkPhase], &[Vec<usize>]),
    (chars, from): (&[(u64, u8)], usize),
    out: &mut LinkCheck,
) {
    let lane = &cap.lanes[li];
    let clock = s.mix.clock_hz as i128;
    let misos = miso_lanes(cap);
    let mut best: Option<(LinkPhase, Held, LinkCheck)> = None;
    for (k, &ph) in phases.iter().enumerate().take(MAX_PHASES) {
        let seen = modes.get(k).map_or(&[][..], Vec::as_slice);
        let Prediction { bytes: pred } = predict(s, cap, (ph, seen), clock);
        let mut scratch = LinkCheck {
            violations: Vec::new(),
            proved: Vec::new(),
            not_proved: Vec::new(),
            join: None,
        };
        let held = Holding {
            s,
            lane,
            ph,
            clock,
            pred: &pred,
            misos: &misos,
        }
        .hold(&chars[from.min(chars.len())..], &mut scratch);
        let better = best.as_ref().is_none_or(|(_, b, _)| {
            (held.late + held.wrong, std::cmp::Reverse(held.held))
                < (b.late + b.wrong, std::cmp::Reverse(b.held))
        });
        if better {
            best = Some((ph, held, scratch));
        }
    }
    let Some((ph, held, scratch)) = best else {
        return;
    };
    out.violations.extend(scratch.violations);
    let unc = ph.hi - ph.lo + ph.t + 2 * ph.skew;
    if held.late == 0 && held.held > 0 {
        out.proved.push(format!(
            "{} (link_tx): every one of {} characters' start bits within {:.1} ns of the schedule's time (sample period, skew and the phase's spread), from the first whole packet's header on{}",
            lane.channel,
            held.held,
            (unc / clock) as f64 / 1e3,
            if phases.len() > 1 {
                format!(", at the frame phase the line fits of the {} the pins fit alike", phases.len())
            } else {
                String::new()
            }
        ));
    }
    let branches: Vec<&str> = misos
        .iter()
        .map(|m| s.mix.branches[m.1 as usize].name.as_str())
        .collect();
    if misos.is_empty() {
        out.not_proved.push(format!(
            "{} (link_tx): the sample codes on the line (map adc_miso[N] to check them against the bits MISO carried)",
            lane.channel
        ));
    } else if held.compared > 0 && held.wrong == 0 {
        out.proved.push(format!(
            "{} (link_tx): the sample codes on the line equal the codes MISO carried: {} record bytes of branch {}",
            lane.channel,
            held.compared,
            branches.join(", ")
        ));
    }
    if held.unresolved > 0 {
        out.not_proved.push(format!(
            "{} (link_tx): {} record bytes of branch {}: their conversion's MISO reads are not all in the capture, or MISO changed within the resolution ({:.1} ns) of a read",
            lane.channel,
            held.unresolved,
            branches.join(", "),
            (unc / clock) as f64 / 1e3
        ));
    }
}

/// Frame phases the line's characters are tried at, at most.
const MAX_PHASES: usize = 16;

/// The characters read, held against the model's bytes.
struct Holding<'a> {
    s: &'a Schedule,
    lane: &'a Lane,
    ph: LinkPhase,
    clock: i128,
    pred: &'a [Predicted],
    /// The captured MISO lanes ([`miso_lanes`]).
    misos: &'a [(usize, u32)],
}

/// Counts of [`Holding::hold`].
#[derive(Default)]
struct Held {
    /// Characters in step whose start bit is off the schedule's.
    late: u64,
    /// Record bytes unlike the model's.
    wrong: u64,
    /// Characters whose start bit is the schedule's.
    held: u64,
    /// Record bytes compared with the model's.
    compared: u64,
    /// Record bytes whose code the capture did not resolve.
    unresolved: u64,
}

impl Holding<'_> {
    fn violation(&self, t: u64, rule: &str, detail: String) -> TimedViolation {
        TimedViolation {
            time_ps: t,
            channel: self.lane.channel.clone(),
            port_bit: self.lane.port_bit(),
            rule: rule.into(),
            detail,
        }
    }

    /// Whether channel `ch`'s branch has its MISO captured.
    fn captured(&self, ch: u16) -> bool {
        let b = self.s.mix.channels[ch as usize].branch;
        self.misos.iter().any(|m| m.1 as usize == b)
    }

    /// The model's start bit nearest the edge at `x` (units), among those
    /// from `used` on (not one matched before).
    fn nearest(&self, x: i128, used: usize) -> Option<usize> {
        let (pred, mid) = (self.pred, (self.ph.lo + self.ph.hi) / 2);
        let c = (x - mid).div_euclid(TC);
        let i = pred[used..].partition_point(|p| p.cycle < c) + used;
        [i.checked_sub(1), Some(i)]
            .into_iter()
            .flatten()
            .filter(|&j| j >= used && j < pred.len())
            .min_by_key(|&j| (pred[j].cycle * TC + mid - x).abs())
    }

    fn hold(&self, chars: &[(u64, u8)], out: &mut LinkCheck) -> Held {
        let (ph, clock, pred) = (self.ph, self.clock, self.pred);
        let unc = ph.hi - ph.lo + ph.t + 2 * ph.skew;
        let mid = (ph.lo + ph.hi) / 2;
        let mut n = Held::default();
        let mut used = 0usize;
        // From the first whole packet's header on, the line is in step:
        // every character must start at one of the schedule's start bits.
        for &(edge_ps, byte) in chars {
            let x = edge_ps as i128 * clock;
            let near = self.nearest(x, used);
            let fits = near.filter(|&j| {
                let ct = pred[j].cycle * TC;
                ph.lo + ct <= x + ph.skew && ph.hi + ct >= x - ph.t - ph.skew
            });
            let Some(j) = fits else {
                n.late += 1;
                if n.late <= 3 {
                    let want = near.map_or("none near".to_string(), |j| {
                        format!(
                            "{:.3} us",
                            ((pred[j].cycle * TC + mid) / clock) as f64 / 1e6
                        )
                    });
                    out.violations.push(self.violation(
                        edge_ps,
                        "link timing (start bit)",
                        format!(
                            "character 0x{byte:02x} starts at {:.3} us; the schedule's nearest start bit is at {want}, not within the capture's resolution ({:.1} ns)",
                            edge_ps as f64 / 1e6,
                            (unc / clock) as f64 / 1e3
                        ),
                    ));
                }
                continue;
            };
            used = j + 1;
            n.held += 1;
            self.hold_record(&pred[j], edge_ps, byte, &mut n, out);
        }
        n
    }

    /// A record byte of a branch whose MISO is captured must be the
    /// model's, where the capture resolved its code.
    fn hold_record(
        &self,
        p: &Predicted,
        edge_ps: u64,
        byte: u8,
        n: &mut Held,
        out: &mut LinkCheck,
    ) {
        let Some((ch, resolved)) = p.record else {
            return;
        };
        if !self.captured(ch) {
            return;
        }
        if !resolved {
            n.unresolved += 1;
            return;
        }
        n.compared += 1;
        if byte != p.byte {
            n.wrong += 1;
            if n.wrong <= 3 {
                out.violations.push(self.violation(
                    edge_ps,
                    "link samples (values)",
                    format!(
                        "a byte of channel {}'s record is 0x{byte:02x}; the code MISO carried gives 0x{:02x}",
                        self.s.mix.channels[ch as usize].name, p.byte
                    ),
                ));
            }
        }
    }
}

/// Channel numbers as a report lists them: `3, 4, 7` (or "none").
fn channel_list<T: std::fmt::Display>(chans: &[T]) -> String {
    if chans.is_empty() {
        return "none".into();
    }
    chans
        .iter()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
