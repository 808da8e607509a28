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
    inner: Option<&'a mut dyn cosim::Tracer>,
}

impl<'a> CycleProgress<'a> {
    /// `None` with `--quiet`.
    pub fn new(
        frames: u64,
        frame_cycles: u64,
        quiet: bool,
        inner: Option<&'a mut dyn cosim::Tracer>,
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

impl judge::run::Observer for CycleProgress<'_> {
    fn cycle(&mut self, cycle: u64, rst: bool, pins: &lut_gen::ports::Pins, miso: u64) {
        if let Some(t) = self.inner.as_deref_mut() {
            t.as_observer().cycle(cycle, rst, pins, miso);
        }
        self.tick();
    }
}

impl judge::vcd::CycleSink for CycleProgress<'_> {
    fn cycle(
        &mut self,
        rst: Option<bool>,
        pins: &lut_gen::ports::Pins,
        xz: &lut_gen::ports::Pins,
        miso: u64,
        miso_xz: u64,
    ) {
        if let Some(t) = self.inner.as_deref_mut() {
            t.as_sink().cycle(rst, pins, xz, miso, miso_xz);
        }
        self.tick();
    }
}

/// A spinner with the elapsed time for work that reports no counts (the
/// fault campaign, reading a VCD); nothing off a terminal or with `--quiet`.
pub fn spinner(what: &str, quiet: bool) -> Option<indicatif::ProgressBar> {
    (!quiet && std::io::stderr().is_terminal()).then(|| {
        let b = indicatif::ProgressBar::new_spinner();
        b.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {msg} [{elapsed}]")
                .expect("template"),
        );
        b.set_message(what.to_string());
        b.enable_steady_tick(std::time::Duration::from_millis(150));
        b
    })
}
