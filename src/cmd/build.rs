//! `slotforge build MIX -o DIR`: the main job.  Audit, LUT, Verilog with
//! `ports.json` and constraints, a co-simulation with the full check, the
//! golden comparison, the fault campaign, a yosys/nextpnr estimate when the
//! tools are there, and charts about this mix, tied together in
//! `report.html` (self-contained) and `report.md`.  The measuring is in the
//! `measure` crate; this module parses, calls and writes.
//!
//! Fast by default: every default step is about the mix itself; the speed
//! chart is drawn from the fault step's campaign and a sample of its faults
//! on rust-hdl and Verilator; with `--charts all` the campaign also runs the deep Verilog faults on every Verilog engine and `prove`.
//! The report is rewritten after every step, so an interrupted build
//! leaves a report of the steps that finished.
//!
//! A failing step is shown as failed in the report and in the exit code; the
//! other steps still run.  Exit 0: every step ok or skipped; 1: a step
//! failed; 2: bad input (the mix, the output directory, a step name).

mod job;
mod plan;
mod scene;
mod steps;

use std::path::PathBuf;

use job::Job;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// Output directory (created if missing; only the job's files are written).
    #[arg(short = 'o', long = "out")]
    pub out: PathBuf,
    /// Frames the co-simulation runs, fully checked (default 3; a mix with
    /// modes: its scene, and the slowest reaction after it, the audit's).
    #[arg(long, value_parser = super::whole_number)]
    pub frames: Option<u64>,
    /// The co-simulation's ADC input, as `sim --stimulus` takes it (default
    /// `pattern`). A mix with modes runs a scene that switches it and charts
    /// its data rate against the same scene with one mode: auto select by
    /// default a stroke over the channels its reset mode's triggers watch,
    /// from frame 3 for 10 frames (`stroke:NAMES@3-13`); pin select the
    /// pattern with a request of every mode in turn on `mode_sel`.
    #[arg(long, value_name = "STIMULUS")]
    pub stimulus: Option<String>,
    /// Run the fault campaign on the gateware (rust-hdl: also faults built
    /// into its slot ROM and counters; slower) instead of the model's pins.
    #[arg(long)]
    pub thorough: bool,
    /// Where the golden folders are (`<dir>/<mix name>/`).
    #[arg(long, default_value = "golden")]
    pub golden: PathBuf,
    /// Which charts: `mix` (timing, figure7, schedulability, and speed
    /// against accuracy drawn from the fault campaign, with a sample of its
    /// faults run on rust-hdl and Verilator), `all` (the campaign
    /// at every site instead of the quick one, also running the deep Verilog
    /// faults on Verilator and Icarus and `prove`: minutes), or `none`.
    #[arg(long, value_enum, default_value_t = Charts::Mix)]
    pub charts: Charts,
    /// Run only these steps (comma-separated; see `--skip`).
    #[arg(long, value_delimiter = ',', value_name = "STEP,...")]
    pub only: Vec<String>,
    /// Leave out these steps (comma-separated): audit, lut, verilog, sim,
    /// golden, faults, prove, synth, netlist, timing, figure7, schedulability,
    /// speed.
    #[arg(long, value_delimiter = ',', value_name = "STEP,...")]
    pub skip: Vec<String>,
    /// The FPGA part of the synthesis step: ice40-hx8k (IO left
    /// unconstrained), ecp5-25k or gw1n-9 (on their board's pins, as
    /// `slotforge synth --fpga` places them).
    #[arg(long, value_parser = lut_gen::Fpga::parse, default_value = "ice40-hx8k")]
    pub fpga: lut_gen::Fpga,
    /// Also write the steps as JUnit XML (one test case per step).
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// No progress display and no per-step lines (for scripts).
    #[arg(long)]
    pub quiet: bool,
    /// A step that was asked for but skipped (a tool missing, a measurement
    /// not possible) fails the build, as it always does when the CI
    /// environment variable is set. Steps left out by --only, --skip or
    /// --charts are not skipped in this sense.
    #[arg(long)]
    pub strict: bool,
}

/// Whether skipped steps fail: `--strict`, or `CI` set (not empty, `0` or `false`).
fn strict(flag: bool) -> bool {
    let ci = std::env::var("CI").unwrap_or_default();
    let ci = ci.trim();
    flag || !(ci.is_empty() || ci == "0" || ci.eq_ignore_ascii_case("false"))
}

/// `--charts` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Charts {
    Mix,
    All,
    None,
}

pub fn run(a: Args) -> u8 {
    let plan = match plan::plan(&a) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let s = match super::load_any_modes(&a.mix, super::Limits::Contract) {
        Ok(s) => s,
        Err(code) => return code,
    };
    if let Err(code) = super::junit::check_writable(a.junit.as_deref()) {
        return code;
    }
    if a.out.exists() && !a.out.is_dir() {
        eprintln!("error: {}: exists and is not a directory", a.out.display());
        return 2;
    }
    if let Err(e) = std::fs::create_dir_all(&a.out) {
        let why = lut_gen::io_words(&e);
        eprintln!("error: {}: cannot create directory: {why}", a.out.display());
        return 2;
    }
    let scene = match scene::scene(&a, &s) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let mut job = Job::new(&a, &s, plan.iter().filter(|p| p.1.runs()).count());
    steps::run_all(&mut job, &a, &s, &plan, &scene);
    if let Err(e) = job.finish() {
        eprintln!("error: {e}");
        return 2;
    }
    if let Some(j) = &a.junit {
        let cases = job
            .doc
            .steps
            .iter()
            .map(super::junit::Case::of_step)
            .collect::<Vec<_>>();
        if let Err(e) = super::junit::write(j, &format!("slotforge build {}", s.mix.name), &cases) {
            eprintln!("error: {e}");
            return 2;
        }
    }
    let failed = job
        .doc
        .steps
        .iter()
        .filter(|s| s.status == report::Status::Failed)
        .count();
    if !a.quiet {
        // the count the progress's `[n/N]` counted, and the steps not run
        let not_run = job.doc.steps.len() - job.total;
        println!(
            "{}: {} run{}, {} failed; report in {}",
            s.mix.name,
            super::counted(job.total as u64, "step"),
            if not_run > 0 {
                format!(" ({not_run} not asked for)")
            } else {
                String::new()
            },
            failed,
            a.out.join("report.html").display()
        );
    }
    if !job.degraded.is_empty() && strict(a.strict) {
        eprintln!(
            "error: {} step(s) skipped under --strict or CI: {}",
            job.degraded.len(),
            job.degraded.join(", ")
        );
        return 1;
    }
    u8::from(failed > 0)
}
