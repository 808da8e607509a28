//! An AXI4-Stream link in an analyser's capture held to the model: at a
//! frame phase the pins fit, the cycle model runs along the capture with
//! the slave's `tready` taken from the capture (as a VCD window's check
//! takes it from the waveform), and its transmitter joins the line at a
//! whole packet (`line::join`, placing the packet's slice by its number and
//! its records' channels: the capture carries no codes).  From there every
//! cycle's `tvalid`, and on each beat `tlast` and the header and trailer
//! bytes that do not depend on the codes, must be the model's.

use lut_gen::Pins;
use lut_gen::Schedule;

use crate::capture::check::{Capture, TimedViolation};
use crate::capture::line::{LineJoin, LinkPhase, TC};
use crate::line::{Joined, LinkJoin};
use crate::model::CycleModel;

/// The clock samples of the beat ports: (time in ps, the lanes' levels).
pub(crate) type Clocked = [(u64, u64)];

/// Lane indices of the beat ports.
pub(crate) struct BeatLanes {
    pub tdata: [usize; 8],
    pub tvalid: usize,
    pub tready: usize,
    pub tlast: usize,
}

impl BeatLanes {
    fn pins(&self, v: u64) -> Pins {
        let bit = |l: usize| v >> l & 1 == 1;
        let mut p = Pins {
            axis_tvalid: bit(self.tvalid),
            axis_tready: bit(self.tready),
            axis_tlast: bit(self.tlast),
            ..Pins::default()
        };
        for (b, &l) in self.tdata.iter().enumerate() {
            p.axis_tdata |= (bit(l) as u8) << b;
        }
        p
    }
}

/// One phase's run: where it joined, what it compared, what differed.
pub(crate) struct Run {
    pub join: LineJoin,
    pub cycles: u64,
    pub beats: u64,
    pub bytes: u64,
    pub wrong: u64,
    pub violations: Vec<TimedViolation>,
}

/// The model along the capture at phase `ph`; `None` if its transmitter
/// never joined the line.
pub(crate) fn run(
    s: &Schedule,
    cap: &Capture,
    lanes: &BeatLanes,
    clocked: &Clocked,
    (ph, seen): (LinkPhase, &[usize]),
) -> Option<Run> {
    let clock = s.mix.clock_hz as i128;
    let mid = (ph.lo + ph.hi) / 2;
    let c_of = |t: u64| (t as i128 * clock - mid).div_euclid(TC);
    let first = c_of(clocked.first()?.0);
    let last = c_of(clocked.last()?.0) + 1;
    // whole frames on, in steady state and in the modes the capture shows
    let (mut m, shift) = crate::capture::line::steady_model(s, seen, (first, last));
    let cfg = m.tx_config()?;
    let mut lj = LinkJoin::new(
        cfg,
        s.grid.slices_per_frame,
        s.grid.slice_cycles,
        (first + shift) as u64,
    )
    .blind();
    let mut joined: Option<Joined> = None;
    let mut r = Run {
        join: LineJoin {
            by: "model",
            judged: true,
            why_not: None,
            header_ps: None,
            frame_counter: None,
            slice: None,
            skipped_bytes: 0,
            unjudged_ps: 0,
        },
        cycles: 0,
        beats: 0,
        bytes: 0,
        wrong: 0,
        violations: Vec::new(),
    };
    let mut header_t = 0u64;
    for &(t, v) in clocked {
        let mc = (c_of(t) + shift) as u64;
        while m.cycle() < mc {
            m.step(0);
        }
        let mut p = lanes.pins(v);
        // the mode in force, as the capture showed it (the model runs in it)
        p.mode = m.pins().mode;
        if joined.is_none() {
            let e = *m.pins();
            if let Some((tx, j)) = lj.cycle(mc, &p, &e) {
                m.set_tx(tx);
                header_t =
                    t.saturating_sub(((mc - j.header_cycle) as f64 * 1e12 / clock as f64) as u64);
                joined = Some(j);
            }
        }
        if joined.is_some() {
            compare(cap, lanes, (t, mc), &p, &m, &mut r);
        }
        m.set_tready(p.axis_tready);
        m.step(0);
    }
    let j = joined?;
    let t0 = cap.steps.first().map_or(0, |x| x.0);
    r.join.header_ps = Some(header_t);
    r.join.frame_counter = Some(j.frame);
    r.join.slice = Some(j.slice);
    r.join.skipped_bytes = j.skipped_bytes;
    r.join.unjudged_ps = header_t.saturating_sub(t0);
    Some(r)
}

/// Cycle `mc` (capture time `t`): the capture's beat ports `p` against
/// the model's.
fn compare(
    cap: &Capture,
    lanes: &BeatLanes,
    (t, mc): (u64, u64),
    p: &Pins,
    m: &CycleModel,
    r: &mut Run,
) {
    let e = m.pins();
    r.cycles += 1;
    let wrong = |lane: usize, what: String, r: &mut Run| {
        r.wrong += 1;
        if r.wrong <= 3 {
            r.violations.push(TimedViolation {
                time_ps: t,
                channel: cap.lanes[lane].channel.clone(),
                port_bit: cap.lanes[lane].port_bit(),
                rule: "link timing (beats)".into(),
                detail: format!("model cycle {mc}: {what}"),
            });
        }
    };
    if p.axis_tvalid != e.axis_tvalid {
        let what = format!(
            "tvalid is {}; the model's is {} (tready from the capture)",
            p.axis_tvalid as u8, e.axis_tvalid as u8
        );
        return wrong(lanes.tvalid, what, r);
    }
    if !(p.axis_tvalid && p.axis_tready) {
        return;
    }
    r.beats += 1;
    if p.axis_tlast != e.axis_tlast {
        let what = format!(
            "tlast is {} on a beat; the model's is {}",
            p.axis_tlast as u8, e.axis_tlast as u8
        );
        return wrong(lanes.tlast, what, r);
    }
    let fixed = m.link_byte().is_some_and(|(b, _)| match b.kind {
        link::format::WordKind::Header => true,
        link::format::WordKind::Trailer => b.index < 2,
        link::format::WordKind::Record => false,
    });
    if fixed {
        r.bytes += 1;
        if p.axis_tdata != e.axis_tdata {
            let what = format!(
                "tdata is 0x{:02x}; the model's is 0x{:02x}",
                p.axis_tdata, e.axis_tdata
            );
            wrong(lanes.tdata[0], what, r);
        }
    }
}
