//! The link to the host, planned from the schedule: the UART divider, the
//! bytes a frame puts on the wire, the FIFO's exact worst-case backlog and
//! the worst latency to the wire, and whether the line can carry the mix
//! (with the minimum baud that would when it cannot).
//!
//! The packet format and the transmitter's cycle model live in the `link`
//! crate (their one home); this module feeds that model the merged sample
//! stream the schedule implies (docs/timing.md, "Merged sample stream").

use std::collections::{BTreeMap, VecDeque};

use link::format;
use link::{AxisFormat, UartFormat};
use link::{Line, SteadyState, TxConfig};
use serde::Serialize;

use crate::mix::{LinkKind, LinkSpec};
use crate::schedule::Schedule;

mod memo;
mod switch;
pub use switch::{merged_run, switch_backlog, SwitchFifo};

/// The most tokens the gateware's FIFO holds.
pub const MAX_FIFO_DEPTH: usize = 1024;
/// Frames the backlog measurement may run before it calls the stream
/// undrainable.
const MAX_FRAMES: u64 = 32;

/// What the audit and the gateware know about a mix's link.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinkPlan {
    pub kind: &'static str,
    pub baud_requested: u64,
    pub baud_divider: u32,
    pub baud: f64,
    pub parity: &'static str,
    pub stop_bits: u8,
    pub bits_per_byte: u32,
    /// Header, records and trailer words (the paper's "packets") per frame.
    pub words_per_frame: u64,
    pub bytes_per_frame: u64,
    /// Line bits per frame over the line's bits per frame.
    pub utilization: f64,
    /// The FIFO's exact worst-case backlog (tokens), the depth the gateware gets.
    pub fifo_depth: usize,
    /// Worst cycles from a sampling instant to the last bit of its packet.
    pub latency_cycles: u64,
    pub latency_us: f64,
    /// The lowest baud (a divider of the clock) that carries the mix.
    pub min_baud: f64,
    /// AXI4-Stream only: where `tlast` goes, the slave's guarantee the FIFO
    /// depth is computed for (every beat accepted within `ready_within`
    /// cycles), and the weakest guarantee that would still carry the mix.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tlast: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ready_within: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_ready_within: Option<u32>,
    /// The line the transmitter drives (UART or AXIS).
    #[serde(skip)]
    pub line: Line,
    /// A mix with modes: the mode whose frame carries the most bytes (the
    /// figures above are its, but `latency_*` and `min_baud` are the worst
    /// mode's and `fifo_depth` the most of every mode and switch), and the
    /// FIFO across each switch between two modes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_mode: Option<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub switches: Vec<SwitchFifo>,
}

/// Why the link cannot carry the mix.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkInfeasible {
    /// `line N: link.<key>: words` (`audit` names the file too, with [`LinkInfeasible::at`]).
    pub message: String,
    /// Where the refused key is in the mix file, and what is wrong with
    /// it (`link.<key>: words`).
    pub line: usize,
    pub column: usize,
    pub detail: String,
    pub min_baud: Option<f64>,
}

impl LinkInfeasible {
    fn new(spec: &LinkSpec, detail: String, min_baud: Option<f64>) -> LinkInfeasible {
        LinkInfeasible {
            message: format!("line {}: {detail}", spec.line),
            line: spec.line,
            column: spec.column,
            detail,
            min_baud,
        }
    }

    /// The refusal as the mix parser's errors read:
    /// `file:line:col: link.<key>: words`.
    pub fn at(&self, file: &std::path::Path) -> String {
        format!(
            "{}:{}:{}: {}",
            file.display(),
            self.line,
            self.column,
            self.detail
        )
    }
}

impl LinkPlan {
    /// The UART's character; `None` for an AXI4-Stream link.
    pub fn uart(&self) -> Option<UartFormat> {
        match self.line {
            Line::Uart(u) => Some(u),
            Line::Axis(_) => None,
        }
    }

    /// The AXI4-Stream format; `None` for a UART.
    pub fn axis(&self) -> Option<AxisFormat> {
        match self.line {
            Line::Axis(a) => Some(a),
            Line::Uart(_) => None,
        }
    }

    /// The transmitter the gateware builds (FIFO of [`LinkPlan::fifo_depth`]).
    pub fn tx_config(&self, s: &Schedule) -> TxConfig {
        TxConfig {
            line: self.line,
            slice_cycles: s.grid.slice_cycles,
            slices_per_frame: s.grid.slices_per_frame,
            depth: Some(self.fifo_depth),
            mode_bits: s.mix.modes.as_ref().map_or(0, |m| m.select_bits()),
        }
    }
}

/// The mix's link plan; `None` without `[link]`.
pub fn plan(s: &Schedule) -> Option<Result<LinkPlan, LinkInfeasible>> {
    let spec = s.mix.link?;
    Some(memo::plan(s, |s| match s.modes.is_empty() {
        true => plan_one(s, &spec),
        false => switch::plan_modes(s, &spec),
    }))
}

/// One schedule's link (a mix without modes, or one mode).
pub fn plan_one(s: &Schedule, spec: &LinkSpec) -> Result<LinkPlan, LinkInfeasible> {
    match spec.kind {
        LinkKind::Uart => plan_spec(s, spec),
        LinkKind::Axis => plan_axis(s, spec),
    }
}

fn axis_of(spec: &LinkSpec, ready_within: u32) -> Line {
    Line::Axis(AxisFormat {
        tlast: spec.tlast,
        ready_within,
    })
}

/// An AXI4-Stream link: one byte per beat, the FIFO sized for the slowest
/// slave the guarantee allows (every beat taken in its `ready_within`-th
/// cycle), refused with the weakest guarantee that fits when it cannot.
fn plan_axis(s: &Schedule, spec: &LinkSpec) -> Result<LinkPlan, LinkInfeasible> {
    let g = &s.grid;
    let n = spec.ready_within;
    let bytes = format::bytes_per_frame(s.samples_per_frame(), g.slices_per_frame);
    let stream = merged_frame(s);
    let top = (g.frame_cycles / bytes).min(u32::MAX as u64) as u32;
    let max_n = slowest_line(top, 1, |d| measure(s, axis_of(spec, d), &stream).is_some());
    let refuse = |why: String| {
        let detail = match max_n {
            Some(m) => format!("{why}; this mix needs every beat accepted within {m} cycles (tready duty >= 1/{m})"),
            None => format!("{why}; not even an always-ready slave carries this mix"),
        };
        LinkInfeasible::new(spec, detail, None)
    };
    let line_cycles = bytes * n as u64;
    if line_cycles > g.frame_cycles {
        return Err(refuse(format!(
            "link.ready_within: {bytes} bytes per frame, one per {n} cycles at worst, need {line_cycles} cycles, the frame has {}",
            g.frame_cycles
        )));
    }
    let m = measure(s, axis_of(spec, n), &stream).ok_or_else(|| {
        refuse(format!(
            "link.ready_within: the FIFO's backlog exceeds {MAX_FIFO_DEPTH} tokens when every beat waits {n} cycles"
        ))
    })?;
    Ok(LinkPlan {
        kind: spec.kind.name(),
        baud_requested: 0,
        baud_divider: 0,
        baud: 0.0,
        parity: "none",
        stop_bits: 0,
        bits_per_byte: 8,
        words_per_frame: format::words_per_frame(s.samples_per_frame(), g.slices_per_frame),
        bytes_per_frame: bytes,
        utilization: line_cycles as f64 / g.frame_cycles as f64,
        fifo_depth: m.backlog.max(1),
        latency_cycles: m.latency_cycles,
        latency_us: m.latency_cycles as f64 * 1e6 / g.clock_hz as f64,
        min_baud: f64::NAN,
        tlast: Some(spec.tlast.name()),
        ready_within: Some(n),
        max_ready_within: max_n,
        line: axis_of(spec, n),
        worst_mode: None,
        switches: Vec::new(),
    })
}

fn uart_of(spec: &LinkSpec, div: u32) -> UartFormat {
    UartFormat {
        div,
        parity: spec.parity,
        stop_bits: spec.stop_bits,
    }
}

fn plan_spec(s: &Schedule, spec: &LinkSpec) -> Result<LinkPlan, LinkInfeasible> {
    let g = &s.grid;
    let div = UartFormat::divider(g.clock_hz, spec.baud);
    let uart = uart_of(spec, div);
    let words = format::words_per_frame(s.samples_per_frame(), g.slices_per_frame);
    let bytes = format::bytes_per_frame(s.samples_per_frame(), g.slices_per_frame);
    let line_cycles = bytes * uart.char_cycles();
    let stream = merged_frame(s);
    let min = min_divider(s, spec, &stream, bytes);
    let min_baud = min.map(|d| UartFormat::real_baud(g.clock_hz, d));
    let refuse = |why: String| {
        let detail = match min_baud {
            Some(b) => format!("{why}; the minimum baud that carries this mix is {b:.0}"),
            None => format!("{why}; no baud from this clock carries this mix"),
        };
        LinkInfeasible::new(spec, detail, min_baud)
    };
    if line_cycles > g.frame_cycles {
        return Err(refuse(format!(
            "link.baud: {bytes} bytes per frame need {line_cycles} cycles of a {:.0}-baud line, the frame has {}",
            UartFormat::real_baud(g.clock_hz, div),
            g.frame_cycles
        )));
    }
    let m = measure(s, Line::Uart(uart), &stream).ok_or_else(|| {
        refuse(format!(
            "link.baud: the FIFO's backlog exceeds {MAX_FIFO_DEPTH} tokens at {:.0} baud",
            UartFormat::real_baud(g.clock_hz, div)
        ))
    })?;
    Ok(LinkPlan {
        kind: spec.kind.name(),
        baud_requested: spec.baud,
        baud_divider: div,
        baud: UartFormat::real_baud(g.clock_hz, div),
        parity: spec.parity.name(),
        stop_bits: spec.stop_bits,
        bits_per_byte: uart.bits(),
        words_per_frame: words,
        bytes_per_frame: bytes,
        utilization: line_cycles as f64 / g.frame_cycles as f64,
        fifo_depth: m.backlog.max(1),
        latency_cycles: m.latency_cycles,
        latency_us: m.latency_cycles as f64 * 1e6 / g.clock_hz as f64,
        min_baud: min_baud.unwrap_or(f64::NAN),
        tlast: None,
        ready_within: None,
        max_ready_within: None,
        line: Line::Uart(uart),
        worst_mode: None,
        switches: Vec::new(),
    })
}

/// The backlog and latency at one divider, if the FIFO stays within its limit.
fn measure(s: &Schedule, line: Line, stream: &[(u64, u64, u16)]) -> Option<SteadyState> {
    let cfg = TxConfig {
        line,
        slice_cycles: s.grid.slice_cycles,
        slices_per_frame: s.grid.slices_per_frame,
        depth: None,
        // the header's size does not depend on the modes it carries
        mode_bits: 0,
    };
    link::steady_state(cfg, stream, MAX_FRAMES).filter(|m| m.backlog <= MAX_FIFO_DEPTH)
}

/// The largest divider (lowest baud) whose line carries the frame's bytes
/// and whose backlog fits the FIFO.
fn min_divider(
    s: &Schedule,
    spec: &LinkSpec,
    stream: &[(u64, u64, u16)],
    bytes: u64,
) -> Option<u32> {
    let per_char = uart_of(spec, 1).bits() as u64;
    let top = (s.grid.frame_cycles / (bytes * per_char)).min(u32::MAX as u64) as u32;
    slowest_line(top, crate::mix::MIN_BAUD_DIVIDER, |d| {
        measure(s, Line::Uart(uart_of(spec, d)), stream).is_some()
    })
}

/// The largest cycles-per-unit `d <= top` (and `>= least`) that `fits`,
/// from the slowest line that carries the frame's bytes: a line that is
/// just fast enough may still need more FIFO than the gateware has, so step
/// towards faster lines until the backlog fits.
fn slowest_line(top: u32, least: u32, fits: impl Fn(u32) -> bool) -> Option<u32> {
    let mut d = top;
    for _ in 0..64 {
        if d < least {
            return None;
        }
        if fits(d) {
            return Some(d);
        }
        d -= (d / 16).max(1);
    }
    None
}

/// The merged sample stream of one frame in steady state (docs/timing.md):
/// `(cycle of sample_valid, sampling instant, channel)` for every sample
/// whose instant is in the frame, in output order.  A sample of the frame's
/// end may leave after the frame ends.
pub fn merged_frame(s: &Schedule) -> Vec<(u64, u64, u16)> {
    let f = s.grid.frame_cycles;
    // completions of the previous, this and the next frame, by cycle
    let mut done: BTreeMap<u64, Vec<(usize, u64, Vec<u16>)>> = BTreeMap::new();
    for i in s.instants(3) {
        let e = i.cycle + s.branches[i.branch].spi.tick_to_complete();
        let words: Vec<u16> = s.words_of(i.channel).map(|(_, c)| c as u16).collect();
        done.entry(e).or_default().push((i.branch, i.cycle, words));
    }
    let mut pending: BTreeMap<usize, VecDeque<(u16, u64)>> = BTreeMap::new();
    let mut out = Vec::new();
    let mut c = 0u64;
    let events: Vec<u64> = done.keys().copied().collect();
    let mut next_ev = 0;
    loop {
        if pending.values().all(|q| q.is_empty()) {
            match events.get(next_ev) {
                Some(&e) => c = c.max(e),
                None => break,
            }
        }
        while next_ev < events.len() && events[next_ev] <= c {
            for (b, t, words) in &done[&events[next_ev]] {
                let q = pending.entry(*b).or_default();
                q.extend(words.iter().map(|&w| (w, *t)));
            }
            next_ev += 1;
        }
        if let Some((_, q)) = pending.iter_mut().find(|(_, q)| !q.is_empty()) {
            let (ch, t) = q.pop_front().expect("non-empty");
            if (f..2 * f).contains(&t) {
                out.push((c + 1 - f, t - f, ch));
            }
        }
        c += 1;
    }
    out
}

/// Where the samples of each packet were taken, for a host that knows the
/// mix: per slice, `(channel, sampling instant)` of every sample the packet
/// of that slice carries in steady state, in output order, the instant in
/// cycles from the start of the packet's frame (negative for a sample of
/// the previous frame's end that left in this frame's first slice).
#[derive(Debug, Clone)]
pub struct PacketInstants {
    /// (channel, conversion start, cycles to the sampling instant after it)
    per_slice: Vec<Vec<(u16, i64, i64)>>,
    frame_cycles: u64,
    clock_hz: u64,
}

impl PacketInstants {
    pub fn new(s: &Schedule) -> PacketInstants {
        let g = &s.grid;
        let mut per_slice = vec![Vec::new(); g.slices_per_frame as usize];
        for (v, i, ch) in merged_frame(s) {
            let w = v / g.slice_cycles;
            let k = (w % g.slices_per_frame) as usize;
            let shift = (w / g.slices_per_frame * g.frame_cycles) as i64;
            // the part holds its input this long after the slot tick
            let held = s.sample_after(s.mix.channels[ch as usize].branch);
            per_slice[k].push((ch, i as i64 - shift, held as i64));
        }
        PacketInstants {
            per_slice,
            frame_cycles: g.frame_cycles,
            clock_hz: g.clock_hz,
        }
    }

    /// The sampling instant, in cycles after cycle 0, of each record of the
    /// packet of `(frame, slice)` carrying `channels` in order.  A channel
    /// with `m` records in the packet gets the last `m` of its instants in
    /// the slice, so a sample skipped at start-up (docs/timing.md) shifts
    /// none of the others; `None` where the schedule has no instant left
    /// for a record (or it would fall before cycle 0).
    pub fn cycles(&self, frame: u64, slice: u16, channels: &[u16]) -> Vec<Option<u64>> {
        self.cycles_after(self, frame, slice, channels)
    }

    /// [`PacketInstants::cycles`] of a mix with modes: the packet's frame
    /// runs this mode and the frame before ran `prev`'s, whose samples the
    /// packet carries over (docs/packet-format.md, "Modes").
    pub fn cycles_after(
        &self,
        prev: &PacketInstants,
        frame: u64,
        slice: u16,
        channels: &[u16],
    ) -> Vec<Option<u64>> {
        let (Some(own), Some(before)) = (
            self.per_slice.get(slice as usize),
            prev.per_slice.get(slice as usize),
        ) else {
            return vec![None; channels.len()];
        };
        // a conversion belongs to the frame it starts in
        let list: Vec<(u16, i64, i64)> = before
            .iter()
            .filter(|e| e.1 < 0)
            .chain(own.iter().filter(|e| e.1 >= 0))
            .copied()
            .collect();
        let base = (frame * self.frame_cycles) as i64;
        let mut seen: BTreeMap<u16, usize> = BTreeMap::new();
        channels
            .iter()
            .map(|&c| {
                let m = channels.iter().filter(|&&x| x == c).count();
                let have: Vec<i64> = list
                    .iter()
                    .filter(|e| e.0 == c)
                    .map(|e| e.1 + e.2)
                    .collect();
                let i = seen.entry(c).or_insert(0);
                let k = (have.len() + *i).checked_sub(m);
                *i += 1;
                k.and_then(|k| have.get(k))
                    .and_then(|&t| u64::try_from(base + t).ok())
            })
            .collect()
    }

    /// The clock the instants count.
    pub fn clock_hz(&self) -> u64 {
        self.clock_hz
    }
}
