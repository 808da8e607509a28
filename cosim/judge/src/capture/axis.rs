//! An AXI4-Stream link in a logic-analyser capture (`m_axis_tdata[7:0]`,
//! `m_axis_tvalid`, `m_axis_tready`, `m_axis_tlast` mapped): the ports are
//! read once per clock cycle, in the middle of each cycle (the clock's
//! edges found from the beat ports' own changes, which follow them), and
//! every beat (`tvalid && tready`) goes through the host decoder.  As on a
//! UART's line, the line is joined at its first whole packet: from its
//! header on, every packet's channels must be the schedule's for its
//! slice, CRCs good, none lost, `tlast` high on exactly the beats that end
//! a packet (`tlast = "slice"`) or a frame (`"frame"`), `link_overflow`
//! low; the beats before it were in flight when the capture began and are
//! not judged ([`LineJoin`] says how long).

use link::{AxisFormat, Tlast};
use lut_gen::Schedule;
use lut_gen::Signal;

use crate::capture::axis_hold::BeatLanes;
use crate::capture::check::{Capture, Lane};
use crate::capture::line::{
    check_order, order_violation, LineJoin, LineRead, LinkCheck, LinkPhase,
};

/// The mapped link ports: lane indices.
struct Ports {
    tdata: [usize; 8],
    tvalid: usize,
    tready: usize,
    tlast: usize,
    overflow: Option<usize>,
}

impl Ports {
    /// The lanes of `cap` carrying the beats; the ports missing if any.
    fn find(cap: &Capture) -> Result<Ports, Vec<&'static str>> {
        let at = |sig: Signal, bit: u32| {
            cap.lanes
                .iter()
                .position(|l| l.role.is_none() && l.link == Some(sig) && l.bit == bit)
        };
        let tdata: Vec<_> = (0..8).map(|b| at(Signal::AxisTdata, b)).collect();
        let mut missing = Vec::new();
        if tdata.iter().any(|t| t.is_none()) {
            missing.push("m_axis_tdata[7:0]");
        }
        let one = |sig, name, missing: &mut Vec<&'static str>| {
            at(sig, 0).unwrap_or_else(|| {
                missing.push(name);
                0
            })
        };
        let tvalid = one(Signal::AxisTvalid, "m_axis_tvalid", &mut missing);
        let tready = one(Signal::AxisTready, "m_axis_tready", &mut missing);
        let tlast = one(Signal::AxisTlast, "m_axis_tlast", &mut missing);
        if !missing.is_empty() {
            return Err(missing);
        }
        Ok(Ports {
            tdata: std::array::from_fn(|b| tdata[b].unwrap_or(0)),
            tvalid,
            tready,
            tlast,
            overflow: at(Signal::LinkOverflow, 0),
        })
    }

    /// The mask of the lanes that change at the clock's edges.
    fn mask(&self) -> u64 {
        let mut m = 1 << self.tvalid | 1 << self.tready | 1 << self.tlast;
        for &b in &self.tdata {
            m |= 1 << b;
        }
        m
    }
}

/// A beat read: (the capture's time of the cycle's middle, tdata, tlast).
type Beat = (u64, u8, bool);

/// Checks the AXI4-Stream link's beats in `cap` against `s`.
pub(crate) fn check_axis(
    s: &Schedule,
    cap: &Capture,
    (phases, modes): (&[LinkPhase], &[Vec<usize>]),
    model: bool,
) -> LinkCheck {
    let mut out = LinkCheck {
        violations: Vec::new(),
        proved: Vec::new(),
        not_proved: Vec::new(),
        join: None,
    };
    let t0 = cap.steps.first().map_or(0, |x| x.0);
    let end = cap.steps.last().map_or(0, |x| x.0);
    let fmt = match lut_gen::plan_link(s) {
        Some(Ok(p)) => p.axis(),
        _ => None,
    };
    let unjudged = |why: String| LineJoin {
        by: "decoder",
        judged: false,
        why_not: Some(why),
        header_ps: None,
        frame_counter: None,
        slice: None,
        skipped_bytes: 0,
        unjudged_ps: end - t0,
    };
    let Some(fmt) = fmt else {
        out.join = Some(unjudged("the mix plans no AXI4-Stream link".into()));
        return out;
    };
    let ports = match Ports::find(cap) {
        Ok(p) => p,
        Err(missing) => {
            let why = format!(
                "{} not mapped: the beats cannot be read",
                missing.join(", ")
            );
            out.not_proved.push(format!("the link's samples ({why})"));
            out.join = Some(unjudged(why));
            return out;
        }
    };
    let tc = 1e12 / s.mix.clock_hz as f64;
    if tc < 2.0 * cap.period_ps as f64 {
        let why = format!(
            "a clock cycle lasts {:.1} ns, under two analyser samples ({:.1} ns each); a faster analyser reads the beats",
            tc / 1e3,
            cap.period_ps as f64 / 1e3
        );
        out.not_proved.push(format!("the link's samples ({why})"));
        out.join = Some(unjudged(why));
        return out;
    }
    let clocked = clocked(cap, &ports, tc);
    let (beats, overflow) = read_beats(&clocked, &ports);
    let lane = &cap.lanes[ports.tdata[0]];
    let read = decode(s, lane, &beats, fmt, &mut out);
    out.join = Some(read.joined(false, (t0, end)));
    judge_read(s, cap, &ports, (&read, overflow), &mut out);
    if read.packets.is_empty() {
        return out;
    }
    match (model, phases) {
        (false, _) => out.not_proved.push(
            "m_axis_*: the beats' cycles against the model (--no-model: the beats are decoded and judged, not held to the model)".into(),
        ),
        (true, []) => out.not_proved.push(
            "m_axis_*: the beats' cycles against the model (no frame phase to hold them at)".into(),
        ),
        (true, _) => hold(s, cap, (&ports, &clocked), (phases, modes), &mut out),
    }
    out
}

/// The beats held to the model at the frame phase (of those the pins fit)
/// the line fits best; the join is then the model's.
fn hold(
    s: &Schedule,
    cap: &Capture,
    (ports, clocked): (&Ports, &[(u64, u64)]),
    (phases, modes): (&[LinkPhase], &[Vec<usize>]),
    out: &mut LinkCheck,
) {
    let lanes = BeatLanes {
        tdata: ports.tdata,
        tvalid: ports.tvalid,
        tready: ports.tready,
        tlast: ports.tlast,
    };
    let best = phases
        .iter()
        .enumerate()
        .take(16)
        .filter_map(|(k, &ph)| {
            let seen = modes.get(k).map_or(&[][..], Vec::as_slice);
            crate::capture::axis_hold::run(s, cap, &lanes, clocked, (ph, seen))
        })
        .min_by_key(|r| (r.wrong, std::cmp::Reverse(r.cycles)));
    let Some(r) = best else {
        out.not_proved.push(
            "m_axis_*: the beats' cycles against the model (its transmitter found no whole packet it could join at: the beats are decoded and judged, not held to the model)".into(),
        );
        return;
    };
    if r.wrong == 0 {
        out.proved.push(format!(
            "m_axis_*: held to the model (tready from the capture) from the joined packet's header on: tvalid in every one of {} cycles, tlast on each of {} beats, and {} header and trailer bytes{}",
            r.cycles,
            r.beats,
            r.bytes,
            if phases.len() > 1 {
                format!(", at the frame phase the beats fit of the {} the pins fit alike", phases.len())
            } else {
                String::new()
            }
        ));
    }
    out.not_proved.push(
        "m_axis_tdata: the record bytes and CRCs against the codes MISO carried (not read from an analyser's capture of an AXI4-Stream link)".into(),
    );
    out.violations.extend(r.violations);
    out.join = Some(r.join);
}

/// The ports' levels in the middle of each clock cycle: (time, levels).
fn clocked(cap: &Capture, ports: &Ports, tc: f64) -> Vec<(u64, u64)> {
    let t0 = cap.steps.first().map_or(0, |x| x.0) as f64;
    let end = cap.steps.last().map_or(0, |x| x.0) as f64;
    let mid = middle(cap, ports.mask(), tc);
    let mut t = t0 + (mid - t0).rem_euclid(tc);
    let (mut k, mut out) = (0usize, Vec::new());
    while t <= end {
        while k + 1 < cap.steps.len() && cap.steps[k + 1].0 as f64 <= t {
            k += 1;
        }
        out.push((t as u64, cap.steps[k].1));
        t += tc;
    }
    out
}

/// The beats of the clock samples, and the first time `link_overflow` was
/// seen high, if mapped.
fn read_beats(clocked: &[(u64, u64)], ports: &Ports) -> (Vec<Beat>, Option<u64>) {
    let (mut beats, mut overflow) = (Vec::new(), None);
    let bit = |v: u64, lane: usize| v >> lane & 1 == 1;
    for &(t, v) in clocked {
        if bit(v, ports.tvalid) && bit(v, ports.tready) {
            let mut byte = 0u8;
            for (b, &l) in ports.tdata.iter().enumerate() {
                byte |= (bit(v, l) as u8) << b;
            }
            beats.push((t, byte, bit(v, ports.tlast)));
        }
        if overflow.is_none() && ports.overflow.is_some_and(|l| bit(v, l)) {
            overflow = Some(t);
        }
    }
    (beats, overflow)
}

/// The middle of a clock cycle, as a time of the capture (modulo `tc`):
/// the beat ports change at the clock's edges, which the analyser sees up
/// to a sample period late, so their changes' mean phase is half a sample
/// after an edge; half a cycle on is the middle.  The capture's first
/// sample when they never change.
fn middle(cap: &Capture, mask: u64, tc: f64) -> f64 {
    let t0 = cap.steps.first().map_or(0, |x| x.0) as f64;
    let (mut x, mut y) = (0.0f64, 0.0f64);
    for w in cap.steps.windows(2) {
        if (w[0].1 ^ w[1].1) & mask != 0 {
            let a = std::f64::consts::TAU * ((w[1].0 as f64 - t0) / tc).fract();
            x += a.cos();
            y += a.sin();
        }
    }
    if x == 0.0 && y == 0.0 {
        return t0;
    }
    let edge = y.atan2(x).rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU * tc;
    t0 + edge - cap.period_ps as f64 / 2.0 + tc / 2.0
}

/// The beats through the host decoder: packets, where the line was joined
/// (the first good packet's header), CRC, lost-packet and `tlast` faults
/// from it on.
fn decode(
    s: &Schedule,
    lane: &Lane,
    beats: &[Beat],
    fmt: AxisFormat,
    out: &mut LinkCheck,
) -> LineRead {
    let slices = s.grid.slices_per_frame;
    let mut dec = crate::line::decoder(s);
    let (mut packets, mut decoded) = (Vec::new(), Vec::new());
    let (mut join, mut crc, mut lost, mut tlast_wrong) = (None, 0u64, 0u64, 0u64);
    let mut lost_place = false;
    let mut chars = Vec::with_capacity(beats.len());
    for (i, &(t, byte, tlast)) in beats.iter().enumerate() {
        chars.push((t, byte));
        let before = *dec.stats();
        decoded.clear();
        dec.push_packets(&[byte], &mut decoded);
        let mut ends = None;
        let decoded_any = !decoded.is_empty();
        for d in decoded.drain(..) {
            if join.is_none() {
                let h = (i + 1).saturating_sub(4 * (2 + d.records.len()));
                let sync = beats.get(h).is_some_and(|b| b.1 == link::format::SYNC);
                join = Some((if sync { h } else { i + 1 }, d.frame as u8, d.slice));
            }
            ends = Some(d.slice);
            let chans = d.records.iter().map(|r| r.0).collect();
            packets.push((t as f64, d.frame, d.slice, chans, (d.mode, d.prev_mode)));
        }
        let st = *dec.stats();
        if st.crc_errors > crc {
            crc = st.crc_errors;
            out.violations.push(order_violation(
                lane,
                t as f64,
                "a packet with a bad CRC".into(),
            ));
        }
        if st.lost_packets > lost && !packets.is_empty() {
            out.violations.push(order_violation(
                lane,
                t as f64,
                format!(
                    "{} packet(s) missing before this one",
                    st.lost_packets - lost
                ),
            ));
        }
        lost = st.lost_packets;
        if join.is_some() && st.skipped_bytes > before.skipped_bytes && !lost_place {
            // once per loss of place: the decoder searches for a header again
            out.violations.push(order_violation(
                lane,
                t as f64,
                format!("byte 0x{byte:02x} is not where the packet format puts a word: the decoder lost its place and searches for a header"),
            ));
        }
        lost_place = match decoded_any {
            true => false,
            false => lost_place || st.skipped_bytes > before.skipped_bytes,
        };
        let clean = st.crc_errors == before.crc_errors && st.skipped_bytes == before.skipped_bytes;
        let wrong = crate::line::tlast_wrong(fmt, ends, slices, tlast, byte);
        if let Some(detail) = wrong.filter(|_| join.is_some() && clean) {
            tlast_wrong += 1;
            if tlast_wrong <= 3 {
                out.violations.push(crate::capture::check::TimedViolation {
                    time_ps: t,
                    channel: lane.channel.clone(),
                    port_bit: "m_axis_tlast".into(),
                    rule: "link tlast".into(),
                    detail,
                });
            }
        }
    }
    LineRead {
        packets,
        chars,
        stats: dec.finish(),
        join,
    }
}

/// What the decoded beats show: the packets' order, the FIFO's overflow,
/// and what was proved of them.
fn judge_read(
    s: &Schedule,
    cap: &Capture,
    ports: &Ports,
    (read, overflow): (&LineRead, Option<u64>),
    out: &mut LinkCheck,
) {
    let lane = &cap.lanes[ports.tdata[0]];
    let from = read.join.and_then(|j| read.chars.get(j.0)).map(|c| c.0);
    if let (Some(t), Some(h)) = (overflow, from) {
        if t >= h {
            out.violations.push(order_violation(
                &cap.lanes[ports.overflow.unwrap_or(ports.tdata[0])],
                t as f64,
                "link_overflow is high: the FIFO dropped samples".into(),
            ));
        }
    }
    if read.stats.overflows > 0 {
        out.violations.push(order_violation(
            lane,
            read.packets.last().map_or(0.0, |p| p.0),
            format!(
                "a trailer reports {} token(s) dropped by the FIFO",
                read.stats.overflows
            ),
        ));
    }
    check_order(s, lane, &read.packets, out);
    if read.packets.is_empty() {
        let plan = lut_gen::plan_link(s).and_then(|p| p.ok());
        let latency = plan.map_or(0, |p| p.latency_cycles);
        let due = (2 * s.grid.slice_cycles + latency) as f64 * 1e12 / s.mix.clock_hz as f64;
        let (t0, end) = (
            cap.steps.first().map_or(0, |x| x.0),
            cap.steps.last().map_or(0, |x| x.0),
        );
        let what = format!("no good packet decoded from {} beat(s)", read.chars.len());
        if (end - t0) as f64 > due {
            out.violations.push(order_violation(lane, end as f64, what));
        } else {
            out.not_proved.push(format!(
                "m_axis_tdata: {what} in a capture shorter than two slices and the link's latency ({:.3} us)",
                due / 1e6
            ));
        }
        return;
    }
    let samples: usize = read.packets.iter().map(|p| p.3.len()).sum();
    out.proved.push(format!(
        "m_axis_tdata: {} packets and {samples} samples read from {} beats (tvalid and tready high at the middle of a clock cycle), each packet's channels in the schedule's order for its slice, CRCs good, none lost, tlast on exactly the beats that end a packet{}, from the first whole packet's header on",
        read.packets.len(),
        read.chars.len(),
        if s.mix.link.as_ref().is_some_and(|l| l.tlast == Tlast::Frame) { " of a frame's last slice" } else { "" },
    ));
}
