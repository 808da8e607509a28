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
