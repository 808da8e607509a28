//! Samples out of a run: one CSV row per `sample_valid` strobe,
//!
//! ```text
//! cycle,sampled_s,channel,value
//! 322,0.000000000000,CH1,8192
//! ```
//!
//! `cycle` counts from cycle 0, the first cycle after reset is released
//! (`docs/timing.md`), and is the cycle in which `sample_valid` is high:
//! the conversion's sampling instant (its CS fall) plus the read and, when
//! branches finish together, the cycles it waited behind lower branches
//! (one sample leaves per cycle), so strobes of one channel are its exact
//! interval apart within `branches - 1` cycles.  `sampled_s` is the
//! sampling instant itself (`Schedule::sampled_at`), in seconds after
//! cycle 0, rounded once to 1 ps (12 decimals; no accumulated drift): the
//! same number `slotforge decode` writes for the same sample, so the two
//! CSVs join on it; empty for a strobe no instant of its channel precedes
//! (a faulty design's).  `channel` is the channel's name (the mix's name
//! for the index on `sample_channel`); `value` is the ADC code on
//! `sample_value`.
//!
//! [`SampleLog`] collects the samples while a run goes (it is an
//! [`Observer`] and a [`CycleSink`], so any back end can feed it) and keeps
//! only the samples, not every cycle; [`SampleLog::from_trace`] reads them
//! from a recorded [`Trace`] instead.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use lut_gen::Pins;
use lut_gen::Schedule;

use crate::check::Observer;
use crate::logs::events::Trace;
use crate::wave::CycleSink;

/// The CSV's first line.
pub const HEADER: &str = "cycle,sampled_s,channel,value";

/// One `sample_valid` strobe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sample {
    /// Cycles after cycle 0.
    pub cycle: u64,
    /// `sample_channel`: the channel's index in the mix.
    pub channel: u16,
    /// `sample_value`: the ADC code.
    pub value: u16,
}

/// The samples of a run, numbered from cycle 0 (after the last reset cycle).
#[derive(Debug, Clone, Default)]
pub struct SampleLog {
    pub samples: Vec<Sample>,
    /// Run cycles seen so far (from the first reset cycle on).
    seen: u64,
    /// Run cycle of cycle 0, once reset is low.
    zero: Option<u64>,
    /// A mix with modes: the `mode` pin's changes (cycle, mode) from cycle 0.
    modes: Vec<(u64, u8)>,
}

impl SampleLog {
    pub fn new() -> SampleLog {
        SampleLog::default()
    }

    /// The samples of a recorded run.
    pub fn from_trace(t: &Trace) -> SampleLog {
        let mut log = SampleLog::new();
        for (rst, pins, _) in &t.cycles {
            log.push(*rst, pins);
        }
        log
    }

    fn push(&mut self, rst: bool, p: &Pins) {
        let k = self.seen;
        self.seen += 1;
        if rst {
            // cycle 0 follows the last reset cycle
            self.zero = None;
            self.samples.clear();
            self.modes.clear();
            return;
        }
        let zero = *self.zero.get_or_insert(k);
        if self.modes.last().map_or(p.mode != 0, |m| m.1 != p.mode) {
            self.modes.push((k - zero, p.mode));
        }
        if p.sample_valid {
            self.samples.push(Sample {
                cycle: k - zero,
                channel: p.sample_channel,
                value: p.sample_value,
            });
        }
    }

    /// The CSV text (header and one row per sample).
    pub fn to_csv(&self, s: &Schedule) -> String {
        let mut o = String::with_capacity(32 * (self.samples.len() + 1));
        o.push_str(HEADER);
        o.push('\n');
        for x in &self.samples {
            let name = s
                .mix
                .channels
                .get(x.channel as usize)
                .map_or_else(|| format!("channel{}", x.channel), |c| csv_field(&c.name));
            let sampled = self
                .sampled_at(s, x)
                .map(|t| lut_gen::seconds(t, s.grid.clock_hz))
                .unwrap_or_default();
            let _ = writeln!(o, "{},{sampled},{name},{}", x.cycle, x.value);
        }
        o
    }

    /// The `mode` pin in cycle `c` (0 before any change).
    fn mode_at(&self, c: u64) -> usize {
        let i = self.modes.partition_point(|m| m.0 <= c);
        if i == 0 {
            0
        } else {
            self.modes[i - 1].1 as usize
        }
    }

    /// The sampling instant of `x`: its mode's schedule, or (a sample that
    /// left after its frame ended) the frame before's mode's.
    fn sampled_at(&self, s: &Schedule, x: &Sample) -> Option<u64> {
        let ch = x.channel as usize;
        if s.modes.len() < 2 {
            return s.sampled_at(ch, x.cycle);
        }
        let f = s.grid.frame_cycles;
        let start = x.cycle / f * f;
        let here = s.modes.get(self.mode_at(x.cycle))?;
        let own = here.sampled_at(ch, x.cycle).filter(|&t| t >= start);
        let before = || {
            let m = if start == 0 {
                0
            } else {
                self.mode_at(start - 1)
            };
            s.modes
                .get(m)?
                .sampled_at(ch, x.cycle)
                .filter(|&t| t < start)
        };
        own.or_else(before).or_else(|| here.sampled_at(ch, x.cycle))
    }

    /// Writes the CSV to `path` atomically: to a new temporary file beside
    /// it (never an existing one), then renamed over `path`.
    pub fn write_csv(&self, s: &Schedule, path: &Path) -> std::io::Result<()> {
        write_atomic(path, self.to_csv(s).as_bytes())
    }
}

impl Observer for SampleLog {
    fn cycle(&mut self, _cycle: u64, rst: bool, pins: &Pins, _miso: u64) {
        self.push(rst, pins);
    }
}

impl CycleSink for SampleLog {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, _xz: &Pins, _miso: u64, _miso_xz: u64) {
        // an unknown reset level counts as reset, as in `Trace`
        self.push(rst.unwrap_or(true), pins);
    }
}

fn csv_field(x: &str) -> String {
    if x.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", x.replace('"', "\"\""))
    } else {
        x.to_string()
    }
}

/// Writes `bytes` to a temporary file created new in `path`'s directory
/// and renames it to `path`; the temporary file is removed on failure.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    if path.is_dir() {
        return Err(std::io::Error::other(format!(
            "{}: is a directory",
            path.display()
        )));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let base = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "samples".into());
    let mut n = 0u32;
    let (tmp, mut f) = loop {
        let tmp = dir.join(format!(".{base}.{}.{n}.tmp", std::process::id()));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(f) => break (tmp, f),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && n < 1000 => n += 1,
            Err(e) => return Err(e),
        }
    };
    let r = f
        .write_all(bytes)
        .and_then(|()| f.sync_all())
        .and_then(|()| std::fs::rename(&tmp, path));
    if r.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    r
}
