//! The link's line in a logic-analyser capture (`link_tx` mapped): the UART
//! is decoded from the capture's samples by the `link` crate (its receiver
//! and its host decoder, the same a host runs), and every packet's samples
//! must be the schedule's channels in the schedule's order for its slice
//! (`lut_gen::hostlink::merged_frame`), with good CRCs and no packet lost.
//! The values are the ADC's, which the schedule does not predict.

use lut_gen::Schedule;

use crate::timed::{Capture, TimedViolation};

/// What the line showed.
pub struct LinkCheck {
    pub violations: Vec<TimedViolation>,
    pub proved: Option<String>,
    pub not_proved: Vec<String>,
}

/// The channels of each slice's packet in steady state, in order.
fn packet_order(s: &Schedule) -> Vec<Vec<u16>> {
    let g = &s.grid;
    let mut per_slice = vec![Vec::new(); g.slices_per_frame as usize];
    for (cycle, _, ch) in lut_gen::hostlink::merged_frame(s) {
        let k = (cycle / g.slice_cycles % g.slices_per_frame) as usize;
        per_slice[k].push(ch);
    }
    per_slice
}

/// Decodes lane `li` of `cap` (the line) and checks it against `s`.
pub fn check_link(s: &Schedule, cap: &Capture, li: usize) -> LinkCheck {
    let lane = &cap.lanes[li];
    let mut out = LinkCheck {
        violations: Vec::new(),
        proved: None,
        not_proved: Vec::new(),
    };
    let plan = match lut_gen::hostlink::plan(s) {
        Some(Ok(p)) => p,
        _ => {
            out.not_proved
                .push("the link's samples: the mix plans no link".into());
            return out;
        }
    };
    let Some(fmt) = plan.uart() else {
        out.not_proved.push(format!(
            "{} (link_tx): the mix's link is AXI4-Stream, which has no serial line; its beats are checked cycle by cycle in a VCD of the design's ports",
            lane.channel
        ));
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
    let violation = |t: f64, detail: String| TimedViolation {
        time_ps: t as u64,
        channel: lane.channel.clone(),
        port_bit: lane.port_bit(),
        rule: "link samples (order on the line)".into(),
        detail,
    };
    // The line read once per clock cycle from the capture's first sample:
    // the receiver a host runs, over the analyser's samples.
    let tc = 1e12 / s.mix.clock_hz as f64;
    let t0 = cap.steps.first().map(|x| x.0).unwrap_or(0) as f64;
    let end = cap.steps.last().map(|x| x.0).unwrap_or(0) as f64;
    let mut rx = link::rx::UartRx::new(fmt);
    let mut dec = link::Decoder::new(s.grid.slices_per_frame);
    let mut k = 0usize;
    let mut n = 0u64;
    let mut decoded = Vec::new();
    // (time, frame, slice, channels) of every packet decoded.
    let mut packets: Vec<(f64, u64, u16, Vec<u16>)> = Vec::new();
    let mut framing = 0u64;
    let (mut crc, mut lost) = (0u64, 0u64);
    loop {
        let t = t0 + n as f64 * tc;
        if t > end {
            break;
        }
        while k + 1 < cap.steps.len() && (cap.steps[k + 1].0 as f64) <= t {
            k += 1;
        }
        n += 1;
        let Some(b) = rx.sample(cap.steps[k].1 >> li & 1 == 1) else {
            continue;
        };
        if b.error {
            framing += 1;
            if framing == 1 {
                out.violations.push(violation(
                    t,
                    format!("character 0x{:02x} with a bad stop or parity bit", b.byte),
                ));
            }
            continue;
        }
        decoded.clear();
        dec.push(&[b.byte], &mut decoded);
        for d in &decoded {
            match packets.last_mut() {
                Some(p) if p.1 == d.frame && p.2 == d.slice => p.3.push(d.channel),
                _ => packets.push((t, d.frame, d.slice, vec![d.channel])),
            }
        }
        let st = dec.stats();
        if st.crc_errors > crc {
            crc = st.crc_errors;
            out.violations
                .push(violation(t, "a packet with a bad CRC".into()));
        }
        if st.lost_packets > lost && !packets.is_empty() {
            out.violations.push(violation(
                t,
                format!(
                    "{} packet(s) missing before this one",
                    st.lost_packets - lost
                ),
            ));
        }
        lost = st.lost_packets;
    }
    let st = dec.finish();
    if st.overflows > 0 {
        out.violations.push(violation(
            end,
            format!(
                "a trailer reports {} token(s) dropped by the FIFO",
                st.overflows
            ),
        ));
    }
    let order = packet_order(s);
    let mut wrong = 0;
    for (t, frame, slice, chans) in &packets {
        let want = order.get(*slice as usize).cloned().unwrap_or_default();
        if *chans != want {
            wrong += 1;
            if wrong <= 3 {
                out.violations.push(violation(
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
    if packets.is_empty() {
        out.violations.push(violation(
            end,
            format!(
                "no good packet decoded from the line ({} bytes read at {:.0} baud)",
                st.bytes, plan.baud
            ),
        ));
    }
    let samples: usize = packets.iter().map(|p| p.3.len()).sum();
    out.proved = Some(format!(
        "{} (link_tx): {} packets and {samples} samples decoded at {:.0} baud, each packet's channels in the schedule's order for its slice, CRCs good, none lost",
        lane.channel,
        packets.len(),
        plan.baud
    ));
    out.not_proved
        .push("the link's sample values: the ADC's, not the schedule's".into());
    out
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
