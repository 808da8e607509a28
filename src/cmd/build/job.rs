//! The job's bookkeeping: each step timed and recorded, the progress
//! display (a bar with counts and ETA on a terminal, one plain line per
//! step otherwise, nothing with `--quiet`), files written atomically, and
//! the report rewritten after every step.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use lut_gen::Schedule;
use report::{Document, Section, Status};

use super::plan::Step;

/// How one step ended, with a one-line summary and optional detail.
pub enum Outcome {
    Ok(String),
    Failed(String, String),
    Skipped(String),
}

/// What a step hands back: its outcome, the files it wrote (relative to
/// the output directory), its report sections, and the time its work took
/// when that is not the time the step waited (work done in the background).
pub struct Done {
    pub outcome: Outcome,
    pub files: Vec<String>,
    pub sections: Vec<Section>,
    pub seconds: Option<f64>,
}

impl Done {
    pub fn ok(line: impl Into<String>) -> Done {
        Done {
            outcome: Outcome::Ok(line.into()),
            files: Vec::new(),
            sections: Vec::new(),
            seconds: None,
        }
    }
    pub fn failed(line: impl Into<String>, detail: impl Into<String>) -> Done {
        Done {
            outcome: Outcome::Failed(line.into(), detail.into()),
            files: Vec::new(),
            sections: Vec::new(),
            seconds: None,
        }
    }
    pub fn skipped(why: impl Into<String>) -> Done {
        Done {
            outcome: Outcome::Skipped(why.into()),
            files: Vec::new(),
            sections: Vec::new(),
            seconds: None,
        }
    }
    pub fn files(mut self, f: &[&str]) -> Done {
        self.files.extend(f.iter().map(|x| x.to_string()));
        self
    }
    /// The step's work took `seconds` (not the time the step waited for it).
    pub fn took(mut self, seconds: f64) -> Done {
        self.seconds = Some(seconds);
        self
    }
    pub fn section(mut self, s: Section) -> Done {
        self.sections.push(s);
        self
    }
}

/// The questions of the report's first screen, in the order shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Glance {
    Fits,
    Binds,
    Checked,
    Faults,
    Proved,
    Size,
    /// A mix with modes only.
    Modes,
}

impl Glance {
    const ALL: [Glance; 7] = [
        Glance::Fits,
        Glance::Binds,
        Glance::Checked,
        Glance::Modes,
        Glance::Faults,
        Glance::Proved,
        Glance::Size,
    ];

    fn question(self) -> &'static str {
        match self {
            Glance::Fits => "Does it fit?",
            Glance::Binds => "What binds, with what margin?",
            Glance::Checked => "Is the gateware checked?",
            Glance::Faults => "Does the check catch faults?",
            Glance::Proved => "Is it proved?",
            Glance::Size => "How big and fast is it?",
            Glance::Modes => "What do the modes save, and how fast do they switch?",
        }
    }
}

/// Samples per frame; a mix with modes names each mode's.
fn samples_per_frame(s: &Schedule) -> String {
    match s.mix.modes.as_ref().filter(|_| s.modes.len() > 1) {
        Some(m) => s
            .modes
            .iter()
            .zip(&m.names)
            .map(|(x, n)| format!("{} in `{n}`", x.samples_per_frame()))
            .collect::<Vec<_>>()
            .join(", "),
        None => s.samples_per_frame().to_string(),
    }
}

pub struct Job {
    pub out: PathBuf,
    pub doc: Document,
    quiet: bool,
    bar: Option<indicatif::ProgressBar>,
    /// When the first step began: the report's wall time.
    begun: Instant,
    /// Steps that run (the progress's `[n/total]`; the final line's count).
    pub total: usize,
    started: usize,
    /// Steps that were asked for but could not run (a tool missing, a
    /// measurement not possible): `--strict` and CI fail on them.
    pub degraded: Vec<String>,
}

impl Job {
    pub fn new(a: &super::Args, s: &Schedule, total: usize) -> Job {
        let g = &s.grid;
        let bar = (!a.quiet && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(total as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:30} {pos}/{len} steps  {msg}  [{elapsed}, about {eta} left]",
                )
                .expect("template"),
            );
            b.enable_steady_tick(std::time::Duration::from_millis(200));
            b
        });
        Job {
            out: a.out.clone(),
            doc: Document {
                title: format!("slotforge build: `{}`", s.mix.name),
                subtitle: format!(
                    "{} ({}): {} channels on {} branches, clock {} Hz, frame {} cycles = {} slices x {} slots x {} cycles; {} samples per frame. Machine: {} core(s).",
                    s.mix.description,
                    a.mix.display(),
                    s.channels.len(),
                    s.branches.len(),
                    g.clock_hz,
                    g.frame_cycles,
                    g.slices_per_frame,
                    g.slots_per_slice,
                    g.slot_cycles,
                    samples_per_frame(s),
                    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
                ),
                glance: Glance::ALL
                    .iter()
                    .filter(|&&g| g != Glance::Modes || s.modes.len() > 1)
                    .map(|g| (g.question().to_string(), "not run in this build".to_string()))
                    .collect(),
                ..Document::default()
            },
            quiet: a.quiet,
            bar,
            begun: Instant::now(),
            total,
            started: 0,
            degraded: Vec::new(),
        }
    }

    /// A hook that shows a step's runs done of N (the fault campaign's) in
    /// the bar, on a terminal; off one the step's own line says when it ends.
    pub fn runs_hook(&self, what: &str) -> Option<campaign::OnRun> {
        let b = self.bar.clone()?;
        let what = what.to_string();
        Some(campaign::OnRun(std::sync::Arc::new(move |done, n| {
            b.set_message(format!("{what}: {done} of {n} runs"))
        })))
    }

    /// Answers one question of the first screen.
    pub fn answer(&mut self, g: Glance, text: impl Into<String>) {
        if let Some(row) = self.doc.glance.iter_mut().find(|r| r.0 == g.question()) {
            row.1 = text.into();
        }
    }

    /// Records a step that was not asked for.
    pub fn not_run(&mut self, step: Step, why: &str) {
        self.doc.steps.push(report::Step {
            id: step.name().into(),
            name: step.title().into(),
            status: Status::Skipped,
            seconds: 0.0,
            summary: why.into(),
            detail: String::new(),
            files: Vec::new(),
        });
    }

    /// Runs one step, timed; the report on disk says which step was running
    /// until it ends.
    pub fn step(&mut self, step: Step, f: impl FnOnce(&mut Job) -> Done) -> Status {
        let name = step.title();
        self.started += 1;
        self.doc.note = format!(
            "This report was written while step {} of {} ({name}) was running: the build was interrupted or is still running; the steps above are complete.",
            self.started, self.total
        );
        let _ = self.write_report();
        match &self.bar {
            Some(b) => b.set_message(name.to_string()),
            None if !self.quiet => eprintln!("[{}/{}] {name} ...", self.started, self.total),
            None => {}
        }
        let t = Instant::now();
        let d = f(self);
        let seconds = d.seconds.unwrap_or_else(|| t.elapsed().as_secs_f64());
        let (status, summary, detail) = match d.outcome {
            Outcome::Ok(s) => (Status::Ok, s, String::new()),
            Outcome::Failed(s, d) => (Status::Failed, s, d),
            Outcome::Skipped(s) => {
                self.degraded.push(name.to_string());
                (Status::Skipped, s, String::new())
            }
        };
        let line = format!("{name:<34} {:<8} {seconds:>7.1}s  {summary}", status.word());
        match &self.bar {
            Some(b) => {
                b.println(line);
                b.inc(1);
            }
            None if !self.quiet || status == Status::Failed => eprintln!("{line}"),
            None => {}
        }
        self.doc.sections.extend(d.sections);
        self.doc.steps.push(report::Step {
            id: step.name().into(),
            name: name.into(),
            status,
            seconds,
            summary,
            detail,
            files: d.files,
        });
        status
    }

    /// Writes files into `<out>/<sub>` (atomically each).
    pub fn write(&self, sub: &str, files: &[(&str, String)]) -> Result<(), String> {
        let dir = if sub.is_empty() {
            self.out.clone()
        } else {
            self.out.join(sub)
        };
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for (name, text) in files {
            super::super::write_atomic(&dir, name, text)?;
        }
        Ok(())
    }

    fn write_report(&self) -> Result<(), String> {
        let files = report::files(&self.doc);
        let refs: Vec<(&str, String)> =
            files.iter().map(|(n, t)| (n.as_str(), t.clone())).collect();
        self.write("", &refs)
    }

    /// The final report: every file in the output directory linked.
    pub fn finish(&mut self) -> Result<(), String> {
        if let Some(b) = self.bar.take() {
            b.finish_and_clear();
        }
        self.doc.note.clear();
        self.doc.wall_seconds = Some(self.begun.elapsed().as_secs_f64());
        // report files are listed too: written first so the list has them
        self.write_report()?;
        let mut links = Vec::new();
        list(&self.out, Path::new(""), &mut links);
        self.doc.sections.push(Section {
            title: "Every file of this build".into(),
            links: links.into_iter().map(|f| (f, String::new())).collect(),
            ..Section::default()
        });
        self.write_report()
    }
}

/// Every file under `dir` (relative paths, sorted; hidden files left out).
fn list(root: &Path, rel: &Path, out: &mut Vec<String>) {
    let Ok(rd) = std::fs::read_dir(root.join(rel)) else {
        return;
    };
    let mut entries: Vec<_> = rd.flatten().collect();
    entries.sort_by_key(|e| e.file_name());
    for e in entries {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        let p = rel.join(&name);
        if e.path().is_dir() {
            list(root, &p, out);
        } else {
            out.push(p.to_string_lossy().into_owned());
        }
    }
}
