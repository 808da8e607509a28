//! Progress of a command that works through several items (steps, mixes,
//! frames): an indicatif bar with counts and ETA on a terminal, a plain
//! line per item when stderr is not a terminal (CI logs), nothing with
//! `--quiet`.

use std::io::IsTerminal;

pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
    plain: bool,
    len: u64,
    done: std::cell::Cell<u64>,
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
        }
    }

    /// What is being worked on now.
    pub fn message(&self, m: &str) {
        match &self.bar {
            Some(b) => b.set_message(m.to_string()),
            None if self.plain => eprintln!("[{}/{}] {m}", self.done.get() + 1, self.len),
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
/// line per tenth of the run.
pub struct CycleProgress<'a> {
    bar: Option<indicatif::ProgressBar>,
    plain: bool,
    frame_cycles: u64,
    total: u64,
    seen: u64,
    inner: Option<&'a mut dyn engines::Tracer>,
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
        }
    }

    fn tick(&mut self) {
        self.seen += 1;
        if !self.seen.is_multiple_of(65_536) {
            return;
        }
        if let Some(b) = &self.bar {
            b.set_position(self.seen / self.frame_cycles.max(1));
        } else if self.plain && self.total / self.frame_cycles.max(1) >= 10 {
            let tenth = self.total / 10;
            if self.seen % tenth < 65_536 {
                eprintln!(
                    "simulated {} of {} frames",
                    self.seen / self.frame_cycles.max(1),
                    self.total / self.frame_cycles.max(1)
                );
            }
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
/// and ETA on a terminal; off one, a plain line at every tenth (only when
/// the work is more than a few pieces: `min_total`); nothing with
/// `--quiet`.
pub struct Counter {
    what: String,
    unit: Unit,
    bar: Option<indicatif::ProgressBar>,
    plain: bool,
    min_total: u64,
    started: std::time::Instant,
    /// The last tenth printed off a terminal.
    tenth: std::sync::atomic::AtomicU64,
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
            started: std::time::Instant::now(),
            tenth: 0.into(),
        }
    }

    /// `done` of `total` are done.
    pub fn set(&self, done: u64, total: u64) {
        if let Some(b) = &self.bar {
            b.set_length(total);
            b.set_position(done);
            return;
        }
        if !self.plain || total < self.min_total || total == 0 {
            return;
        }
        let tenth = done * 10 / total;
        let last = self
            .tenth
            .fetch_max(tenth, std::sync::atomic::Ordering::Relaxed);
        if tenth > last {
            eprintln!("{}", self.line(done, total));
        }
    }

    /// The plain line: counts, elapsed time and the time left at this pace.
    fn line(&self, done: u64, total: u64) -> String {
        let secs = self.started.elapsed().as_secs_f64();
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
    use super::{Counter, Unit};

    #[test]
    fn a_plain_line_names_the_counts_and_the_time_left() {
        let c = Counter::new("fault campaign", Unit::Runs, 1, true);
        let l = c.line(3, 12);
        assert!(l.starts_with("fault campaign: 3 of 12 runs (25%, "), "{l}");
        assert!(l.ends_with(" s left)"), "{l}");
        let c = Counter::new("checking w.vcd", Unit::Bytes, 1, true);
        let l = c.line(2_500_000, 10_000_000);
        assert!(l.contains("2.5 of 10.0 MB read (25%"), "{l}");
    }
}
