//! Event logs: what a design did on its pins, one line per change, in a
//! small text format a person can read in a code review.  `slotforge golden`
//! keeps one per preset (`golden/<mix>/events.log`) and compares a new run
//! with it by signal role, not by bytes.
//!
//! ```text
//! #    cycle             time  where     signal   value
//!          0      0.000000us  acoustic  mux_sel  0        # -> CH35
//!          1      0.020833us  acoustic  cs_n     0        # slot 0:0, CH35
//!       1234     25.708333us  sample    CH35     0x1a2b
//! ```
//!
//! Cycle 0 is the first cycle after reset is released (`docs/timing.md`);
//! at cycle 0 every branch lane is listed, after that only changes.  Per
//! branch (in mix order): `mux_sel`, `mux_en` (binary, one digit per device;
//! neither for a branch without a mux), `cs_n` (`cnv` for a CNV-started
//! part such as the AD7685), `sclk`; a mix with modes then `modes mode` (the
//! mode in force); then each `sample_valid` strobe as `sample <channel>
//! <code>`.  The time column (exact, rounded once to 1 ps) and the `#` notes
//! are for the reader; the comparison ignores them.

use std::fmt::Write as _;

use lut_gen::Schedule;
use lut_gen::Start;
use lut_gen::{Layout, Pins, Role};

use crate::check::Observer;
use crate::wave::CycleSink;

/// Every cycle of a run: `(rst, pins, miso)` from the first reset cycle on.
#[derive(Debug, Clone, Default)]
pub struct Trace {
    pub cycles: Vec<(bool, Pins, u64)>,
}

impl Trace {
    /// Index of cycle 0: the first cycle with reset low after the last
    /// cycle with reset high (or the first cycle, without a reset).
    pub fn cycle_zero(&self) -> Option<usize> {
        let last_reset = self.cycles.iter().rposition(|c| c.0);
        let z = last_reset.map_or(0, |i| i + 1);
        (z < self.cycles.len()).then_some(z)
    }

    /// Cycles recorded from the first reset cycle on (run cycles).
    pub fn len(&self) -> usize {
        self.cycles.len()
    }

    pub fn is_empty(&self) -> bool {
        self.cycles.is_empty()
    }
}

impl Observer for Trace {
    fn cycle(&mut self, _cycle: u64, rst: bool, pins: &Pins, miso: u64) {
        self.cycles.push((rst, *pins, miso));
    }
}

impl CycleSink for Trace {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, _xz: &Pins, miso: u64, _miso_xz: u64) {
        // an unknown reset level counts as reset (nothing is defined yet)
        self.cycles.push((rst.unwrap_or(true), *pins, miso));
    }
}

/// One line of an event log.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Event {
    pub cycle: u64,
    /// A branch name, or `sample`.
    pub scope: String,
    /// A lane's role key (`cs_n`, ...), or for `sample` the channel's name.
    pub signal: String,
    pub value: String,
    /// For the reader only (not compared).
    pub note: String,
}

/// A run's events over its first cycles after reset.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EventLog {
    pub events: Vec<Event>,
    /// Cycles covered, from cycle 0.
    pub cycles: u64,
}

/// The scope name of samples in a log.
pub const SAMPLE_SCOPE: &str = "sample";

/// The lanes a log records per branch, in order.
const LANES: [Role; 4] = [Role::MuxSel, Role::MuxEn, Role::CsN, Role::Sclk];

/// Names as one whitespace-free token.
fn token(s: &str) -> String {
    if s.is_empty() {
        return "_".into();
    }
    s.chars()
        .map(|c| {
            if c.is_whitespace() || c == '#' {
                '_'
            } else {
                c
            }
        })
        .collect()
}

/// `cycle / clock` in microseconds, exact to the picosecond.
pub fn time_us(clock_hz: u64, cycle: u64) -> String {
    let f = clock_hz as u128;
    let ps = (cycle as u128 * 1_000_000_000_000 + f / 2) / f;
    format!("{}.{:06}us", ps / 1_000_000, ps % 1_000_000)
}

/// The scope of the link's events in a log.
pub const LINK_SCOPE: &str = "link";

/// The link's events in cycle `c`: a byte the line completed (at its last
/// stop bit's middle sample), a change of the overflow flag.
fn link_events(
    events: &mut Vec<Event>,
    rx: Option<&mut link::UartRx>,
    c: u64,
    p: &Pins,
    prev: Option<&Pins>,
) {
    // an AXI4-Stream beat: the byte a slave took at the edge ending `c`
    if rx.is_none() && p.axis_tvalid && p.axis_tready {
        events.push(Event {
            cycle: c,
            scope: LINK_SCOPE.into(),
            signal: "beat".into(),
            value: format!("{:#04x}", p.axis_tdata),
            note: if p.axis_tlast {
                "tlast".into()
            } else {
                String::new()
            },
        });
    }
    if let Some(b) = rx.and_then(|rx| rx.sample(p.link_tx)) {
        events.push(Event {
            cycle: c,
            scope: LINK_SCOPE.into(),
            signal: "byte".into(),
            value: format!("{:#04x}", b.byte),
            note: if b.error {
                "framing or parity error".into()
            } else {
                String::new()
            },
        });
    }
    if prev.map_or(p.link_overflow, |q| q.link_overflow != p.link_overflow) {
        events.push(Event {
            cycle: c,
            scope: LINK_SCOPE.into(),
            signal: "overflow".into(),
            value: (p.link_overflow as u8).to_string(),
            note: String::new(),
        });
    }
}

/// The scope of the mode pins' events in a log (a mix with modes only, so
/// a log of a mix without them is as before).
pub const MODE_SCOPE: &str = "modes";

/// A mix with modes: `mode`, the mode in force, at cycle 0 and at each
/// change, the mode named in the note.  `mode_sel` is an input, like MISO:
/// the stimulus, not what the design did (simulators differ in the cycle
/// they show its change in; the design samples it once a frame).
fn mode_events(events: &mut Vec<Event>, s: &Schedule, c: u64, p: &Pins, prev: Option<&Pins>) {
    let Some(plan) = s.mode_plan().filter(|m| m.names.len() > 1) else {
        return;
    };
    if prev.is_some_and(|q| q.mode == p.mode) {
        return;
    }
    events.push(Event {
        cycle: c,
        scope: MODE_SCOPE.into(),
        signal: "mode".into(),
        value: p.mode.to_string(),
        note: plan
            .names
            .get(p.mode as usize)
            .cloned()
            .unwrap_or_else(|| "no mode".into()),
    });
}

impl EventLog {
    /// The events of `trace` over `cycles` cycles from cycle 0 (fewer if the
    /// trace is shorter).
    pub fn from_trace(s: &Schedule, trace: &Trace, cycles: u64) -> EventLog {
        let l = Layout::new(s);
        let names: Vec<String> = s.mix.channels.iter().map(|c| token(&c.name)).collect();
        let branches: Vec<String> = s.branches.iter().map(|b| token(&b.name)).collect();
        let mut events = Vec::new();
        let mut prev: Option<Pins> = None;
        let Some(z) = trace.cycle_zero() else {
            return EventLog { events, cycles: 0 };
        };
        let n = (trace.len() - z).min(cycles as usize);
        // The link's line read back as a receiver would, one event per byte.
        let plan = lut_gen::plan_link(s).and_then(|p| p.ok());
        let mut rx = plan
            .as_ref()
            .and_then(|lp| lp.uart())
            .map(link::UartRx::new);
        for (c, (_, p, _)) in trace.cycles[z..z + n].iter().enumerate() {
            let c = c as u64;
            if plan.is_some() {
                link_events(&mut events, rx.as_mut(), c, p, prev.as_ref());
            }
            for (b, bname) in branches.iter().enumerate() {
                // a branch without a mux has no mux lanes to log
                for r in LANES.into_iter().filter(|&r| l.has_lane(r, b)) {
                    let v = lane_value(&l, p, r, b);
                    if prev.is_some_and(|q| lane_value(&l, &q, r, b) == v) {
                        continue;
                    }
                    let value = match r {
                        Role::MuxEn => format!("{v:0w$b}", w = l.en_n[b] as usize),
                        _ => v.to_string(),
                    };
                    let ch = || match l.selected(p, b) {
                        Ok(ch) => names[ch as usize].clone(),
                        Err(_) => "no channel".into(),
                    };
                    let note = match r {
                        Role::MuxSel | Role::MuxEn => format!("-> {}", ch()),
                        // the conversion starts: CS falls, or a CNV rises
                        Role::CsN if v == u64::from(l.starts[b] == Start::Cnv) => {
                            let (frame, slot, _) = s.grid.locate(c);
                            format!("slot {frame}:{slot}, {}", ch())
                        }
                        _ => String::new(),
                    };
                    events.push(Event {
                        cycle: c,
                        scope: bname.clone(),
                        signal: l.lane_key(r, b).to_string(),
                        value,
                        note,
                    });
                }
            }
            mode_events(&mut events, s, c, p, prev.as_ref());
            if p.sample_valid {
                let idx = p.sample_channel as usize;
                events.push(Event {
                    cycle: c,
                    scope: SAMPLE_SCOPE.into(),
                    signal: names
                        .get(idx)
                        .cloned()
                        .unwrap_or_else(|| format!("channel{idx}")),
                    value: format!("{:#06x}", p.sample_value),
                    note: String::new(),
                });
            }
            prev = Some(*p);
        }
        EventLog {
            events,
            cycles: n as u64,
        }
    }

    /// The log as text (see the module documentation).
    pub fn render(&self, s: &Schedule, header: &[String]) -> String {
        let g = &s.grid;
        let mut t = String::new();
        let _ = writeln!(t, "# slotforge event log of mix \"{}\"", s.mix.name);
        let _ = writeln!(
            t,
            "# clock {} Hz; frame {} cycles = {} slices x {} slots x {} cycles",
            g.clock_hz, g.frame_cycles, g.slices_per_frame, g.slots_per_slice, g.slot_cycles
        );
        let _ = writeln!(
            t,
            "# cycles 0..{} (cycle 0 = the first rising clock edge after reset is released)",
            self.cycles
        );
        for h in header {
            let _ = writeln!(t, "# {h}");
        }
        let _ = writeln!(
            t,
            "# at cycle 0 every lane, then changes; samples as `sample <channel> <code>`; notes after `#` are not compared"
        );
        let _ = writeln!(
            t,
            "#{:>9} {:>16}  {:<10} {:<8} value",
            "cycle", "time", "where", "signal"
        );
        for e in &self.events {
            let line = format!(
                "{:>10} {:>16}  {:<10} {:<8} {:<8}",
                e.cycle,
                time_us(g.clock_hz, e.cycle),
                e.scope,
                e.signal,
                e.value
            );
            if e.note.is_empty() {
                let _ = writeln!(t, "{}", line.trim_end());
            } else {
                let _ = writeln!(t, "{line} # {}", e.note);
            }
        }
        let _ = writeln!(t, "# end at cycle {}", self.cycles);
        t
    }

    /// Parses a log written by [`EventLog::render`]; errors name the line.
    pub fn parse(text: &str) -> Result<EventLog, String> {
        let mut events = Vec::new();
        let mut cycles = None;
        for (i, line) in text.lines().enumerate() {
            let lineno = i + 1;
            if let Some(rest) = line.strip_prefix("# end at cycle ") {
                cycles = Some(
                    rest.trim()
                        .parse::<u64>()
                        .map_err(|_| format!("line {lineno}: bad end cycle `{rest}`"))?,
                );
                continue;
            }
            let (body, note) = match line.split_once('#') {
                Some((b, n)) => (b, n.trim()),
                None => (line, ""),
            };
            let f: Vec<&str> = body.split_whitespace().collect();
            if f.is_empty() {
                continue;
            }
            if f.len() != 5 {
                return Err(format!(
                    "line {lineno}: expected `cycle time where signal value`, found {} field(s)",
                    f.len()
                ));
            }
            let cycle = f[0]
                .parse::<u64>()
                .map_err(|_| format!("line {lineno}: bad cycle `{}`", f[0]))?;
            events.push(Event {
                cycle,
                scope: f[2].into(),
                signal: f[3].into(),
                value: f[4].into(),
                note: note.into(),
            });
        }
        let cycles = cycles.ok_or("the log has no `# end at cycle N` line (truncated?)")?;
        Ok(EventLog { events, cycles })
    }
}

/// Branch `b`'s lane of role `r` in `p`.
fn lane_value(l: &Layout, p: &Pins, r: Role, b: usize) -> u64 {
    let (hi, lo) = l.lane_bits(r, b);
    let w = hi - lo + 1;
    ((p.value(r) >> lo) as u64) & if w >= 64 { u64::MAX } else { (1 << w) - 1 }
}

/// One difference between two logs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Difference {
    pub cycle: u64,
    pub scope: String,
    pub signal: String,
    /// `None`: no such event on that side.
    pub expected: Option<String>,
    pub actual: Option<String>,
    /// The note of either side (the channel involved, the slot).
    pub note: String,
}

/// How two logs differ.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Comparison {
    /// Events that differ, are missing or are extra.
    pub count: usize,
    /// The earliest differences, in order (at most a few).
    pub first: Vec<Difference>,
    pub expected_cycles: u64,
    pub actual_cycles: u64,
}

impl Comparison {
    pub fn same(&self) -> bool {
        self.count == 0 && self.expected_cycles == self.actual_cycles
    }
}

/// A difference at `at`'s (cycle, where, signal).
fn differ(
    at: &Event,
    expected: Option<&String>,
    actual: Option<&String>,
    note: &str,
) -> Difference {
    Difference {
        cycle: at.cycle,
        scope: at.scope.clone(),
        signal: at.signal.clone(),
        expected: expected.cloned(),
        actual: actual.cloned(),
        note: note.to_string(),
    }
}

/// Compares `actual` with `expected` by (cycle, where, signal) and value.
pub fn compare(expected: &EventLog, actual: &EventLog, keep: usize) -> Comparison {
    // Only the cycles both cover are compared event by event; a different
    // length is reported on its own.
    let upto = expected.cycles.min(actual.cycles);
    let key = |e: &Event| (e.cycle, e.scope.clone(), e.signal.clone());
    fn sorted(l: &EventLog, upto: u64) -> Vec<&Event> {
        let mut v: Vec<&Event> = l.events.iter().filter(|e| e.cycle < upto).collect();
        v.sort_by(|x, y| (x.cycle, &x.scope, &x.signal).cmp(&(y.cycle, &y.scope, &y.signal)));
        v
    }
    let (a, b) = (sorted(expected, upto), sorted(actual, upto));
    let mut cmp = Comparison {
        expected_cycles: expected.cycles,
        actual_cycles: actual.cycles,
        ..Comparison::default()
    };
    let (mut i, mut j) = (0, 0);
    let push = |cmp: &mut Comparison, d: Difference| {
        cmp.count += 1;
        if cmp.first.len() < keep {
            cmp.first.push(d);
        }
    };
    while i < a.len() || j < b.len() {
        let ord = match (a.get(i), b.get(j)) {
            (Some(x), Some(y)) => key(x).cmp(&key(y)),
            (Some(_), None) => std::cmp::Ordering::Less,
            _ => std::cmp::Ordering::Greater,
        };
        match ord {
            std::cmp::Ordering::Equal => {
                let (x, y) = (a[i], b[j]);
                if x.value != y.value {
                    let note = if x.note.is_empty() { &y.note } else { &x.note };
                    push(&mut cmp, differ(x, Some(&x.value), Some(&y.value), note));
                }
                i += 1;
                j += 1;
            }
            std::cmp::Ordering::Less => {
                let x = a[i];
                push(&mut cmp, differ(x, Some(&x.value), None, &x.note));
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                let y = b[j];
                push(&mut cmp, differ(y, None, Some(&y.value), &y.note));
                j += 1;
            }
        }
    }
    cmp
}

impl Difference {
    /// One line for a person: cycle, time, frame and slot, the signal,
    /// expected and actual, and the channel involved.
    pub fn describe(&self, s: &Schedule) -> String {
        let (frame, slot, off) = s.grid.locate(self.cycle);
        let side = |v: &Option<String>| v.clone().unwrap_or_else(|| "(no event)".into());
        let mut t = format!(
            "cycle {} ({}), frame {frame} slot {slot} +{off}: {}.{} expected {}, actual {}",
            self.cycle,
            time_us(s.grid.clock_hz, self.cycle),
            self.scope,
            self.signal,
            side(&self.expected),
            side(&self.actual)
        );
        if !self.note.is_empty() {
            let _ = write!(t, " ({})", self.note);
        }
        t
    }
}
