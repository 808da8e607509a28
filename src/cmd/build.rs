//! `slotforge build MIX -o DIR`: the main job.  Audit, LUT, Verilog with
//! `ports.json` and constraints, a Verilator co-simulation with the full
//! check, the golden comparison, the fault campaign, a yosys/nextpnr
//! estimate when the tools are there, and a report that ties them together
//! (`report.html`, self-contained, and `report.md`) with charts measured in
//! this very run (each also as CSV).
//!
//! A failing step is shown as failed in the report and in the exit code; the
//! other steps still run.  Exit 0: every step ok or skipped; 1: a step
//! failed; 2: bad input (the mix, the output directory).

mod charts;

use std::path::{Path, PathBuf};
use std::time::Instant;

use cosim::{Backend, SimOptions, VcdOut};
use lut_gen::{AuditReport, Schedule};
use report::{Document, Section, Status, Step};

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// Output directory (created if missing; only the job's files are written).
    #[arg(short = 'o', long = "out")]
    pub out: PathBuf,
    /// Frames the Verilator co-simulation runs, fully checked.
    #[arg(long, default_value_t = 3)]
    pub frames: u64,
    /// Run the fault campaign on the gateware (rust-hdl: also faults built
    /// into its slot ROM and counters; slower) instead of the model's pins.
    #[arg(long)]
    pub thorough: bool,
    /// Where the golden folders are (`<dir>/<mix name>/`).
    #[arg(long, default_value = "golden")]
    pub golden: PathBuf,
    /// No progress display (for CI logs).
    #[arg(long)]
    pub quiet: bool,
    /// A skipped step (a tool missing, a measurement not possible) fails the
    /// build, as it always does when the CI environment variable is set.
    #[arg(long)]
    pub strict: bool,
}

/// Whether skipped steps fail: `--strict`, or `CI` set (not empty, `0` or `false`).
fn strict(flag: bool) -> bool {
    let ci = std::env::var("CI").unwrap_or_default();
    let ci = ci.trim();
    flag || !(ci.is_empty() || ci == "0" || ci.eq_ignore_ascii_case("false"))
}

/// How one step ended, with a one-line summary and optional detail.
pub(crate) enum Outcome {
    Ok(String),
    Failed(String, String),
    Skipped(String),
}

/// The job: its output directory, its report, its progress display.
pub(crate) struct Job {
    pub out: PathBuf,
    pub doc: Document,
    quiet: bool,
}

impl Job {
    /// Runs one step, timed, with a spinner unless quiet.
    pub fn step(&mut self, name: &str, f: impl FnOnce(&mut Job) -> Outcome) -> Status {
        let bar = if self.quiet {
            None
        } else {
            let b = indicatif::ProgressBar::new_spinner();
            b.set_style(
                indicatif::ProgressStyle::with_template("{spinner} {msg} [{elapsed}]")
                    .expect("template"),
            );
            b.set_message(name.to_string());
            b.enable_steady_tick(std::time::Duration::from_millis(120));
            Some(b)
        };
        let t = Instant::now();
        let o = f(self);
        let seconds = t.elapsed().as_secs_f64();
        let (status, summary, detail) = match o {
            Outcome::Ok(s) => (Status::Ok, s, String::new()),
            Outcome::Failed(s, d) => (Status::Failed, s, d),
            Outcome::Skipped(s) => (Status::Skipped, s, String::new()),
        };
        if let Some(b) = bar {
            b.finish_and_clear();
        }
        if !self.quiet || status == Status::Failed {
            eprintln!(
                "{:<28} {:<8} {:>7.1}s  {}",
                name,
                status.word(),
                seconds,
                summary
            );
        }
        self.doc.steps.push(Step {
            name: name.into(),
            status,
            seconds,
            summary,
            detail,
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
            super::write_atomic(&dir, name, text)?;
        }
        Ok(())
    }
}

fn tool_present(tool: &str) -> bool {
    std::process::Command::new(tool)
        .arg("-V")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok()
}

pub fn run(a: Args) -> u8 {
    let s = match super::schedule(&a.mix) {
        Ok(s) => s,
        Err(code) => return code,
    };
    if let Err(code) = super::fits_pins(&s) {
        return code;
    }
    if a.out.exists() && !a.out.is_dir() {
        eprintln!("error: {}: exists and is not a directory", a.out.display());
        return 2;
    }
    if let Err(e) = std::fs::create_dir_all(&a.out) {
        eprintln!("error: {}: cannot create directory: {e}", a.out.display());
        return 2;
    }
    let g = &s.grid;
    let mut job = Job {
        out: a.out.clone(),
        doc: Document {
            title: format!("slotforge build: {}", s.mix.name),
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
                s.samples_per_frame(),
                std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
            ),
            ..Document::default()
        },
        quiet: a.quiet,
    };
    let mut audit_section = Section {
        title: "Audit".into(),
        ..Section::default()
    };
    job.step("audit", |j| {
        let r = AuditReport::of_schedule(&s);
        let text = r.to_text();
        audit_section.pre.push(text.clone());
        match j.write("", &[("audit.txt", text), ("audit.json", r.to_json())]) {
            Ok(()) => Outcome::Ok(format!(
                "feasible, {} slots per slice, aggregate {} samples/s",
                g.slots_per_slice, r.aggregate_hz
            )),
            Err(e) => Outcome::Failed(e, String::new()),
        }
    });
    job.step("slot LUT", |j| {
        let files = [
            ("slots.hex", lut_gen::lut::to_hex(&s)),
            ("slots.csv", lut_gen::lut::to_csv(&s)),
            ("slots.md", lut_gen::lut::to_markdown(&s)),
        ];
        match j.write("lut", &files) {
            Ok(()) => Outcome::Ok(format!("{} frame slots in lut/slots.*", g.frame_slots)),
            Err(e) => Outcome::Failed(e, String::new()),
        }
    });
    job.step("Verilog, ports.json, constraints", |j| {
        match hdl::emit(&s, None) {
            Ok(e) => {
                let files: Vec<(&str, String)> = e
                    .files()
                    .iter()
                    .map(|(n, t)| (n.as_str(), t.clone()))
                    .collect();
                match j.write("verilog", &files) {
                    Ok(()) => Outcome::Ok(format!(
                        "{} lines of Verilog in verilog/",
                        e.verilog().lines().count()
                    )),
                    Err(e) => Outcome::Failed(e, String::new()),
                }
            }
            Err(e) => Outcome::Failed(format!("{e}"), String::new()),
        }
    });

    // The co-simulation: every measurement of speed below is from this run.
    let mut speeds = charts::Speeds::default();
    let vcd = a.out.join("frame0.vcd");
    let frames = a.frames.max(1);
    job.step("co-simulation (verilator)", |j| {
        let opts = SimOptions {
            vcd: Some(VcdOut {
                path: vcd.clone(),
                from: 0,
                to: g.frame_cycles,
                gtkw: true,
            }),
            ..SimOptions::default()
        };
        let t = Instant::now();
        match cosim::run(&s, Backend::Verilator, frames, &opts) {
            Ok(r) => {
                // the build is cached after the first run: time a second one
                let t2 = Instant::now();
                let again = cosim::run(&s, Backend::Verilator, frames, &SimOptions::default());
                let secs = if again.is_ok() { t2.elapsed() } else { t.elapsed() };
                speeds.add("verilator", frames * g.frame_cycles, secs.as_secs_f64());
                let json = serde_json::to_string_pretty(&r).expect("report");
                let _ = j.write("", &[("sim.json", json)]);
                if r.ok {
                    Outcome::Ok(format!(
                        "{} frames, {} samples, every cycle equal to the model, no violation (frame 0 in frame0.vcd)",
                        r.frames, r.samples
                    ))
                } else {
                    Outcome::Failed(
                        format!("{} divergences, {} violations", r.divergence_count, r.violation_count),
                        r.summary(),
                    )
                }
            }
            Err(e) => Outcome::Failed(format!("{e}"), String::new()),
        }
    });
    job.step("golden comparison", |j| {
        let dir = a.golden.join(&s.mix.name);
        if !dir.join("events.log").exists() {
            return Outcome::Skipped(format!("no golden in {}", dir.display()));
        }
        let ga = super::golden::Args {
            mix: a.mix.clone(),
            backend: Backend::Verilator,
            rtl: None,
            update: false,
            dir: a.golden.clone(),
        };
        let mut o = super::golden::Output::default();
        let code = super::golden::execute(&ga, &mut o);
        let _ = j.write("", &[("golden.txt", format!("{}{}", o.out, o.err))]);
        let first = o.out.lines().next().unwrap_or("").to_string();
        if code == 0 {
            Outcome::Ok(first)
        } else {
            Outcome::Failed(first, format!("{}{}", o.out, o.err))
        }
    });
    let mut campaign = None;
    job.step("fault campaign", |j| {
        let target = if a.thorough {
            cosim::faults::Target::Rusthdl
        } else {
            cosim::faults::Target::Model
        };
        match cosim::faults::campaign(&s, target, 3, 5) {
            Ok(c) => {
                let json = serde_json::to_string_pretty(&c).expect("campaign");
                let _ = j.write("", &[("faults.json", json)]);
                let line = format!(
                    "{} of {} injections detected ({} undetected, {} proved equivalent) over {} classes and {} sites; {} false alarms in {} clean runs",
                    c.detected,
                    c.injected,
                    c.undetected,
                    c.proved_equivalent,
                    c.classes.len(),
                    c.sites.len(),
                    c.false_alarms.rejected,
                    c.false_alarms.runs
                );
                let ok = c.ok();
                campaign = Some(c);
                if ok {
                    Outcome::Ok(line)
                } else {
                    Outcome::Failed(line, "see faults.json".into())
                }
            }
            Err(e) => Outcome::Failed(format!("{e}"), String::new()),
        }
    });
    let mut synth = None;
    job.step("synthesis estimate (iCE40 HX8K)", |j| {
        if !tool_present("yosys") || !tool_present("nextpnr-ice40") {
            return Outcome::Skipped("yosys or nextpnr-ice40 not installed (make tools)".into());
        }
        match charts::synthesize(&s, &j.out.join("verilog"), &j.out.join("synth")) {
            Ok(r) => {
                let line = format!(
                    "{} logic cells, Fmax {:.1} MHz = {:.2}x the {:.1} MHz clock",
                    r.lcs,
                    r.fmax_mhz,
                    r.fmax_mhz * 1e6 / g.clock_hz as f64,
                    g.clock_hz as f64 / 1e6
                );
                synth = Some(r);
                Outcome::Ok(line)
            }
            Err(e) => Outcome::Failed("place and route failed".into(), e),
        }
    });
    let mut sections = vec![audit_section];
    job.step(
        "chart: speed against accuracy",
        |_| match charts::speed_accuracy(&s, &vcd, &mut speeds, campaign.as_ref()) {
            Ok((sec, line)) => {
                sections.push(sec);
                Outcome::Ok(line)
            }
            Err(e) => Outcome::Failed(e, String::new()),
        },
    );
    job.step(
        "chart: timing diagram of a slice",
        |j| match charts::timing(&s) {
            Ok((sec, wavedrom)) => {
                let _ = j.write("", &[("conversion.wavedrom.json", wavedrom)]);
                sections.push(sec);
                Outcome::Ok("one slice per branch, and WaveDrom JSON of one conversion".into())
            }
            Err(e) => Outcome::Failed(e, String::new()),
        },
    );
    job.step(
        "chart: Figure 7 (sampling rate)",
        |_| match charts::figure7(&s) {
            Ok(Some((sec, line))) => {
                sections.push(sec);
                Outcome::Ok(line)
            }
            // not a degraded step: the figure needs those rates
            Ok(None) => Outcome::Ok(
                "not applicable: the mix has no channels at 100 Hz, 1 kHz and 2 kHz".into(),
            ),
            Err(e) => Outcome::Failed(e, String::new()),
        },
    );
    job.step("chart: where scheduling breaks", |_| {
        let (sec, line) = charts::schedulability();
        sections.push(sec);
        Outcome::Ok(line)
    });
    if let Some(r) = &synth {
        sections.push(Section {
            title: "Synthesis estimate".into(),
            paragraphs: vec![format!(
                "yosys synth_ice40 and nextpnr-ice40 --hx8k (IO left unconstrained, seed 1): {} logic cells, {} block RAMs, Fmax {:.1} MHz for a {:.1} MHz clock. Logs in synth/.",
                r.lcs,
                r.brams,
                r.fmax_mhz,
                g.clock_hz as f64 / 1e6
            )],
            ..Section::default()
        });
    }
    if let Some(c) = &campaign {
        sections.push(charts::faults_section(c));
    }
    job.doc.sections = sections;
    let files = report::files(&job.doc);
    let refs: Vec<(&str, String)> = files.iter().map(|(n, t)| (n.as_str(), t.clone())).collect();
    if let Err(e) = job.write("", &refs) {
        eprintln!("error: {e}");
        return 2;
    }
    let failed = job
        .doc
        .steps
        .iter()
        .filter(|s| s.status == Status::Failed)
        .count();
    let skipped: Vec<&str> = job
        .doc
        .steps
        .iter()
        .filter(|s| s.status == Status::Skipped)
        .map(|s| s.name.as_str())
        .collect();
    println!(
        "{}: {} steps, {} failed, {} skipped{}; report in {}",
        s.mix.name,
        job.doc.steps.len(),
        failed,
        skipped.len(),
        if skipped.is_empty() {
            String::new()
        } else {
            format!(" ({})", skipped.join(", "))
        },
        Path::new(&a.out).join("report.html").display()
    );
    if !skipped.is_empty() && strict(a.strict) {
        eprintln!(
            "error: {} step(s) skipped under --strict or CI: {}",
            skipped.len(),
            skipped.join(", ")
        );
        return 1;
    }
    if failed == 0 {
        0
    } else {
        1
    }
}

/// The schedule's frame period in seconds.
pub(crate) fn frame_seconds(s: &Schedule) -> f64 {
    s.grid.frame_cycles as f64 / s.grid.clock_hz as f64
}
