//! The link of a mix with modes: each mode planned on its own, the worst
//! of them taken for the gateware, and every switch between two modes run
//! through the transmitter's model (the old mode's last frame draining
//! while the new mode's first frame fills) so the FIFO is sized for it too.

use super::*;
use link::{ReadyDriver, ReadyPattern, TxModel};

/// The FIFO across one switch.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SwitchFifo {
    pub from: String,
    pub to: String,
    /// The most tokens the FIFO holds in a run of `from` frames followed by
    /// `to` frames, each long enough to reach its steady state.
    pub backlog: usize,
}

/// The plan of a mix with modes: the worst mode's words, bytes and line
/// utilisation; the deepest FIFO and the longest latency of any mode or
/// switch; the highest minimum baud of any mode.
pub(super) fn plan_modes(s: &Schedule, spec: &LinkSpec) -> Result<LinkPlan, LinkInfeasible> {
    let modes = s.mix.modes.as_ref().expect("modes");
    let names = &modes.names;
    if !link::format::modes_fit(s.grid.slices_per_frame, modes.select_bits()) {
        // docs/packet-format.md, "Modes": two modes and the slice in 16 bits
        let detail = format!(
            "link: {} slices per frame leave no room for two {}-bit modes in a packet header's slice field",
            s.grid.slices_per_frame,
            modes.select_bits()
        );
        return Err(LinkInfeasible::new(spec, detail, None));
    }
    let mut plans = Vec::new();
    for (m, ms) in s.modes.iter().enumerate() {
        let p = plan_one(ms, spec).map_err(|e| {
            // `link.<key>: words` stays the field first, as every refusal
            let detail = match e.detail.split_once(": ") {
                Some((key, words)) => format!("{key}: in mode `{}`, {words}", names[m]),
                None => format!("in mode `{}`: {}", names[m], e.detail),
            };
            LinkInfeasible::new(spec, detail, e.min_baud)
        })?;
        plans.push(p);
    }
    let worst = (0..plans.len())
        .max_by_key(|&m| (plans[m].bytes_per_frame, std::cmp::Reverse(m)))
        .expect("two modes or more");
    let mut plan = plans[worst].clone();
    plan.worst_mode = Some(names[worst].clone());
    for p in &plans {
        plan.fifo_depth = plan.fifo_depth.max(p.fifo_depth);
        plan.latency_cycles = plan.latency_cycles.max(p.latency_cycles);
        if p.min_baud > plan.min_baud {
            plan.min_baud = p.min_baud;
        }
        if let (Some(a), Some(b)) = (plan.max_ready_within, p.max_ready_within) {
            plan.max_ready_within = Some(a.min(b));
        }
    }
    plan.latency_us = plan.latency_cycles as f64 * 1e6 / s.grid.clock_hz as f64;
    for (a, ma) in s.modes.iter().enumerate() {
        for (b, mb) in s.modes.iter().enumerate().filter(|&(b, _)| b != a) {
            let backlog = switch_backlog(ma, mb, plan.line);
            if backlog > MAX_FIFO_DEPTH {
                let detail = format!(
                    "link: a switch from mode `{}` to `{}` backs up more than {MAX_FIFO_DEPTH} tokens in the FIFO",
                    names[a], names[b]
                );
                return Err(LinkInfeasible::new(spec, detail, None));
            }
            plan.fifo_depth = plan.fifo_depth.max(backlog);
            plan.switches.push(SwitchFifo {
                from: names[a].clone(),
                to: names[b].clone(),
                backlog,
            });
        }
    }
    Ok(plan)
}

/// Frames each side of a switch: one past the frames the slower of the two
/// modes takes to reach its steady state on this line (the transmitter's
/// state at a frame start repeats: `link::steady_state`), so the run
/// enters the switch with `a`'s worst backlog and runs `b` to its own.
fn side_frames(a: &Schedule, b: &Schedule, line: Line) -> u64 {
    let settle = |m: &Schedule| measure(m, line, &merged_frame(m)).map_or(MAX_FRAMES, |x| x.frames);
    settle(a).max(settle(b)) + 1
}

/// The FIFO's largest backlog over `side_frames` frames of `a` then as
/// many of `b` (AXI4-Stream: the slowest slave the guarantee allows), from
/// reset; it stops counting just past `MAX_FIFO_DEPTH`.
pub fn switch_backlog(a: &Schedule, b: &Schedule, line: Line) -> usize {
    let side = side_frames(a, b, line);
    let frames: Vec<&Schedule> = (0..2 * side)
        .map(|f| if f < side { a } else { b })
        .collect();
    let stream = merged_run(&frames);
    let g = &a.grid;
    let cfg = TxConfig {
        line,
        slice_cycles: g.slice_cycles,
        slices_per_frame: g.slices_per_frame,
        depth: None,
        mode_bits: 0,
    };
    let mut t = TxModel::new(cfg);
    t.clock(true, None);
    let mut slave = match line {
        Line::Axis(x) => Some(ReadyDriver::new(ReadyPattern::WorstCase, x.ready_within)),
        Line::Uart(_) => None,
    };
    let end = (frames.len() as u64 + 1) * g.frame_cycles;
    // the stream is in cycle order, one sample a cycle at most: a cursor
    // (not a table by cycle, which a long frame would make gigabytes)
    let mut next = stream.iter().filter(|&&(v, _, _)| v < end).peekable();
    for c in 0..end {
        if let Some(d) = slave.as_mut() {
            let r = d.ready(t.tvalid());
            t.set_tready(r);
        }
        let v = next.next_if(|&&(v, _, _)| v <= c).map(|&(_, _, ch)| ch);
        t.clock(false, v.map(|ch| (ch, 0)));
        if t.max_backlog > MAX_FIFO_DEPTH {
            break;
        }
    }
    t.max_backlog
}

/// The merged sample stream (docs/timing.md) of consecutive frames, frame
/// `f` run by `frames[f]`: `(cycle of sample_valid, sampling instant,
/// channel)`, cycles from the first frame's start. The rule of
/// [`merged_frame`], over a run whose table changes at frame starts.
pub fn merged_run(frames: &[&Schedule]) -> Vec<(u64, u64, u16)> {
    let mut done: BTreeMap<u64, Vec<(usize, u64, Vec<u16>)>> = BTreeMap::new();
    for (f, s) in frames.iter().enumerate() {
        let base = f as u64 * s.grid.frame_cycles;
        for i in s.instants(1) {
            let e = base + i.cycle + s.branches[i.branch].spi.tick_to_complete();
            let words = s.words_of(i.channel).map(|(_, c)| c as u16).collect();
            done.entry(e)
                .or_default()
                .push((i.branch, base + i.cycle, words));
        }
    }
    let mut pending: BTreeMap<usize, VecDeque<(u16, u64)>> = BTreeMap::new();
    let mut out = Vec::new();
    let mut events = done.into_iter().peekable();
    let mut c = 0u64;
    loop {
        if pending.values().all(VecDeque::is_empty) {
            match events.peek() {
                Some(&(e, _)) => c = c.max(e),
                None => break,
            }
        }
        while let Some((_, list)) = events.next_if(|(e, _)| *e <= c) {
            for (b, t, words) in list {
                let q = pending.entry(b).or_default();
                q.extend(words.iter().map(|&w| (w, t)));
            }
        }
        if let Some((_, q)) = pending.iter_mut().find(|(_, q)| !q.is_empty()) {
            let (ch, t) = q.pop_front().expect("non-empty");
            out.push((c + 1, t, ch));
        }
        c += 1;
    }
    out
}
