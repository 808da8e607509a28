//! Progress of a command that works through several items (steps, mixes,
//! frames): an indicatif bar with counts and ETA on a terminal; off one
//! (CI logs, pipes) plain lines at the [`Pace`]: nothing for work that ends
//! within a second, then at most one line every few seconds; nothing with
//! `--quiet`.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// No plain line before this: work that ends within it says nothing.
pub const QUIET: Duration = Duration::from_secs(1);
/// At most one plain line per this.
pub const EVERY: Duration = Duration::from_secs(3);

/// Tests set this to a number of milliseconds: the clock then advances by
/// that much at each reading instead of following the wall (a controllable
/// clock for the progress tests of the CLI).
const STEP_ENV: &str = "SLOTFORGE_TEST_PROGRESS_STEP_MS";

/// Where the time since the work began comes from.
enum Clock {
    Wall(Instant),
    /// Advances by `step` at each reading (`readings` so far).
    Stepped {
        step: Duration,
        readings: AtomicU64,
    },
}

impl Clock {
    fn now(&self) -> Duration {
        match self {
            Clock::Wall(t) => t.elapsed(),
            Clock::Stepped { step, readings } => {
                *step * (readings.fetch_add(1, Ordering::Relaxed) as u32 + 1)
            }
        }
    }
}

/// When a plain line may be printed: not in the first [`QUIET`], then not
/// within [`EVERY`] of the last one.  Shared by threads (the fault
/// campaign's runs).
pub struct Pace {
    clock: Clock,
    last: Mutex<Option<Duration>>,
}

impl Pace {
    /// The wall clock, or the stepped one a test asked for.
    pub fn start() -> Pace {
        let step = std::env::var(STEP_ENV)
            .ok()
            .and_then(|v| v.parse::<u64>().ok());
        match step {
            Some(ms) => Pace::stepped(Duration::from_millis(ms)),
            None => Pace::with(Clock::Wall(Instant::now())),
        }
    }

    fn stepped(step: Duration) -> Pace {
        Pace::with(Clock::Stepped {
            step,
            readings: 0.into(),
        })
    }

    fn with(clock: Clock) -> Pace {
        Pace {
            clock,
            last: Mutex::new(None),
        }
    }

    /// The time since the start when a line is due now (and counts it as
    /// printed), `None` when it is not.
    pub fn due(&self) -> Option<Duration> {
        let now = self.clock.now();
        if now < QUIET {
            return None;
        }
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if last.is_some_and(|t| now < t + EVERY) {
            return None;
        }
        *last = Some(now);
        Some(now)
    }
}

pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
    plain: bool,
    len: u64,
    done: std::cell::Cell<u64>,
    pace: Pace,
}

impl Progress {
    pub fn new(len: u64, unit: &str, quiet: bool) -> Progress {
        let tty = std::io::stderr().is_terminal();
        let bar = (!quiet && tty && len > 1).then(|| {
            let b = indicatif::ProgressBar::new(len);
            b.set_style(
                indicatif::ProgressStyle::with_template(&format!(
                    "{{bar:30}} {{pos}}/{{len}} {unit}  {{msg}}  [{{elapsed}}, about {{eta}} left]"
                ))
                .expect("template"),
            );
            b.enable_steady_tick(std::time::Duration::from_millis(200));
            b
        });
        Progress {
            bar,
            plain: !quiet && !tty && len > 1,
            len,
            done: 0.into(),
            pace: Pace::start(),
        }
    }

    /// What is being worked on now.
    pub fn message(&self, m: &str) {
        match &self.bar {
            Some(b) => b.set_message(m.to_string()),
            None if self.plain && self.pace.due().is_some() => {
                eprintln!("[{}/{}] {m}", self.done.get() + 1, self.len)
            }
            None => {}
        }
    }

    pub fn inc(&self) {
        self.done.set(self.done.get() + 1);
        if let Some(b) = &self.bar {
            b.inc(1);
        }
    }

    /// Prints text to stdout without tearing the bar.
    pub fn println_out(&self, text: &str) {
        match &self.bar {
            Some(b) => b.suspend(|| print!("{text}")),
            None => print!("{text}"),
        }
    }

    pub fn println_err(&self, text: &str) {
        match &self.bar {
            Some(b) => b.suspend(|| eprint!("{text}")),
            None => eprint!("{text}"),
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Counts a simulation's cycles into a bar (frames done, ETA), passing
/// every cycle on to `inner` when there is one.  Off a terminal it prints a
/// line at the [`Pace`].
pub struct CycleProgress<'a> {
    bar: Option<indicatif::ProgressBar>,
    plain: bool,
    frame_cycles: u64,
    total: u64,
    seen: u64,
    inner: Option<&'a mut dyn engines::Tracer>,
    pace: Pace,
}

impl<'a> CycleProgress<'a> {
    /// `None` with `--quiet`.
    pub fn new(
        frames: u64,
        frame_cycles: u64,
        quiet: bool,
        inner: Option<&'a mut dyn engines::Tracer>,
    ) -> Self {
        let tty = std::io::stderr().is_terminal();
        let bar = (!quiet && tty).then(|| {
            let b = indicatif::ProgressBar::new(frames);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:30} {pos}/{len} frames  [{elapsed}, about {eta} left]",
                )
                .expect("template"),
            );
            b
        });
        CycleProgress {
            bar,
            plain: !quiet && !tty,
            frame_cycles,
            total: frames * frame_cycles,
            seen: 0,
            inner,
            pace: Pace::start(),
        }
    }

    fn tick(&mut self) {
        self.seen += 1;
        if !self.seen.is_multiple_of(65_536) {
            return;
        }
        if let Some(b) = &self.bar {
            b.set_position(self.seen / self.frame_cycles.max(1));
        } else if self.plain && self.pace.due().is_some() {
            eprintln!(
                "simulated {} of {} frames",
                self.seen / self.frame_cycles.max(1),
                self.total / self.frame_cycles.max(1)
            );
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl judge::Observer for CycleProgress<'_> {
    fn cycle(&mut self, cycle: u64, rst: bool, pins: &lut_gen::Pins, miso: u64) {
        if let Some(t) = self.inner.as_deref_mut() {
            t.as_observer().cycle(cycle, rst, pins, miso);
        }
        self.tick();
    }
}

impl judge::CycleSink for CycleProgress<'_> {
    fn cycle(
        &mut self,
        rst: Option<bool>,
        pins: &lut_gen::Pins,
        xz: &lut_gen::Pins,
        miso: u64,
        miso_xz: u64,
    ) {
        if let Some(t) = self.inner.as_deref_mut() {
            t.as_sink().cycle(rst, pins, xz, miso, miso_xz);
        }
        self.tick();
    }
}

/// What a [`Counter`] counts.
#[derive(Clone, Copy, PartialEq)]
pub enum Unit {
    /// Runs of a fault campaign.
    Runs,
    /// Bytes of a file read.
    Bytes,
}

/// Work that reports "done of N" from any thread (the fault campaign's
/// runs, the bytes of a waveform read): an indicatif bar with the counts
/// and ETA on a terminal; off one, a plain line at the [`Pace`] (only when
/// the work is more than a few pieces: `min_total`); nothing with
/// `--quiet`.
pub struct Counter {
    what: String,
    unit: Unit,
    bar: Option<indicatif::ProgressBar>,
    plain: bool,
    min_total: u64,
    pace: Pace,
}

impl Counter {
    pub fn new(what: &str, unit: Unit, min_total: u64, quiet: bool) -> Counter {
        let tty = std::io::stderr().is_terminal();
        let bar = (!quiet && tty).then(|| {
            let counts = match unit {
                Unit::Runs => "{pos}/{len} runs",
                Unit::Bytes => "{bytes}/{total_bytes}",
            };
            let b = indicatif::ProgressBar::new(0);
            b.set_style(
                indicatif::ProgressStyle::with_template(&format!(
                    "{{msg}} {{bar:30}} {counts}  [{{elapsed}}, about {{eta}} left]"
                ))
                .expect("template"),
            );
            b.set_message(what.to_string());
            b.enable_steady_tick(std::time::Duration::from_millis(200));
            b
        });
        Counter {
            what: what.to_string(),
            unit,
            bar,
            plain: !quiet && !tty,
            min_total,
            pace: Pace::start(),
        }
    }

    /// `done` of `total` are done.
    pub fn set(&self, done: u64, total: u64) {
        if let Some(b) = &self.bar {
            b.set_length(total);
            b.set_position(done);
            return;
        }
        if let Some(line) = self.plain_line(done, total) {
            eprintln!("{line}");
        }
    }

    /// The plain line to print now off a terminal, if one is due.
    fn plain_line(&self, done: u64, total: u64) -> Option<String> {
        if !self.plain || total < self.min_total || total == 0 {
            return None;
        }
        let at = self.pace.due()?;
        Some(self.line(done, total, at.as_secs_f64()))
    }

    /// The plain line: counts, the time since the start (`secs`) and the
    /// time left at this pace.
    fn line(&self, done: u64, total: u64, secs: f64) -> String {
        let left = secs * (total - done.min(total)) as f64 / done.max(1) as f64;
        let counts = match self.unit {
            Unit::Runs => format!("{done} of {total} runs"),
            Unit::Bytes => format!(
                "{:.1} of {:.1} MB read",
                done as f64 / 1e6,
                total as f64 / 1e6
            ),
        };
        format!(
            "{}: {counts} ({}%, {secs:.0} s, about {left:.0} s left)",
            self.what,
            done * 100 / total.max(1)
        )
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Counter, Pace, Unit, EVERY, QUIET};
    use std::time::Duration;

    /// A counter that prints plain lines (as off a terminal) on a clock
    /// that advances by `step` at each reading.
    fn plain(what: &str, unit: Unit, step: Duration) -> Counter {
        let mut c = Counter::new(what, unit, 1, true);
        c.plain = true;
        c.pace = Pace::stepped(step);
        c
    }

    #[test]
    fn a_plain_line_names_the_counts_and_the_time_left() {
        let c = Counter::new("fault campaign", Unit::Runs, 1, true);
        let l = c.line(3, 12, 6.0);
        assert_eq!(
            l,
            "fault campaign: 3 of 12 runs (25%, 6 s, about 18 s left)"
        );
        let c = Counter::new("checking w.vcd", Unit::Bytes, 1, true);
        let l = c.line(2_500_000, 10_000_000, 1.0);
        assert!(l.contains("2.5 of 10.0 MB read (25%"), "{l}");
    }

    /// Nothing in the first second, then a line at most every few seconds,
    /// however often the work asks.
    #[test]
    fn the_pace_is_silent_for_a_second_then_one_line_per_few_seconds() {
        let pace = Pace::stepped(Duration::from_millis(100));
        let due: Vec<Duration> = (0..200).filter_map(|_| pace.due()).collect();
        assert_eq!(due.first(), Some(&QUIET), "{due:?}");
        assert!(due.windows(2).all(|w| w[1] - w[0] >= EVERY), "{due:?}");
        // 20 s of readings: at 1, 4, 7, ..., 19 s
        assert_eq!(due.len(), 7, "{due:?}");
        let quick = Pace::stepped(Duration::from_millis(99));
        assert!((0..10).all(|_| quick.due().is_none()));
    }

    /// Work that ends within a second prints nothing, however many pieces
    /// it reports; long work prints lines that rise, a few seconds apart.
    #[test]
    fn a_counter_is_silent_for_quick_work_and_paced_for_long_work() {
        let c = plain("fault campaign", Unit::Runs, Duration::from_millis(10));
        let quick: Vec<String> = (1..=90).filter_map(|i| c.plain_line(i, 90)).collect();
        assert!(quick.is_empty(), "{quick:?}");
        let c = plain("checking w.vcd", Unit::Bytes, Duration::from_millis(250));
        let total = 100_000_000;
        let lines: Vec<String> = (1..=100)
            .filter_map(|i| c.plain_line(i * 1_000_000, total))
            .collect();
        // 25 s of work: at 1, 4, ..., 25 s
        assert_eq!(lines.len(), 9, "{lines:?}");
        let secs: Vec<u64> = lines
            .iter()
            .map(|l| {
                let (_, t) = l.split_once("%, ").unwrap();
                t.split(' ').next().unwrap().parse().unwrap()
            })
            .collect();
        assert_eq!(secs, [1, 4, 7, 10, 13, 16, 19, 22, 25], "{lines:?}");
        assert!(
            lines[0].starts_with("checking w.vcd: 4.0 of 100.0 MB read (4%"),
            "{lines:?}"
        );
    }
}
