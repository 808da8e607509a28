//! The runners of `build`'s steps ([`Step`]), each a
//! call into a library (`lut-gen`, `hdl`, `engines`, `campaign`, `measure`) and the
//! writing of its files.

use engines::{Backend, SimOptions, VcdOut};
use lut_gen::{AuditReport, Schedule};
use report::Section;

use super::job::{Done, Glance, Job, Outcome};
use super::plan::{only_names, Run, Step};
use super::scene::Scene;
use super::{Args, Charts};
use crate::cmd::counted;

/// The simulator of the co-simulation and the charts: Verilator when it is
/// installed (the emitted Verilog), else rust-hdl.
fn sim_backend() -> Backend {
    if judge::tools::present("verilator") {
        Backend::Verilator
    } else {
        Backend::RustHdl
    }
}

/// Place and route started at once in a thread: yosys and nextpnr are
/// other processes, so on two cores they run beside the simulations.
type Background = std::thread::JoinHandle<(Result<measure::Synth, String>, f64)>;

/// Why place and route did not start.
enum NotStarted {
    /// yosys or nextpnr for the part is not installed.
    Missing,
    /// Its files could not be written (the message says which).
    Io(String),
}

fn start_synth(
    out: &std::path::Path,
    s: &Schedule,
    fpga: lut_gen::Fpga,
) -> Result<Background, NotStarted> {
    let (pnr, _) = fpga.nextpnr();
    if measure::find_program(fpga.yosys()).is_err() || measure::find_program(pnr).is_err() {
        return Err(NotStarted::Missing);
    }
    let dir = out.join("synth");
    let io =
        |p: &std::path::Path, e: std::io::Error| NotStarted::Io(format!("{}: {e}", p.display()));
    // iCE40: IO left unconstrained, as the estimate always was; the other
    // parts on their board (Gowin's nextpnr places no unconstrained port)
    let board = (fpga != lut_gen::Fpga::Ice40Hx8k).then(|| dir.join(fpga.board().1));
    std::fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
    if let Some(b) = &board {
        std::fs::write(b, hdl::stock_board(fpga)).map_err(|e| io(b, e))?;
    }
    let clock = s.grid.clock_hz;
    let e = hdl::emit(s, board.as_deref());
    if let Ok(e) = &e {
        super::super::write_atomic(&dir, hdl::VERILOG_FILE, e.verilog()).map_err(NotStarted::Io)?;
        let c = fpga.family().constraints().file();
        if let (true, Some(text)) = (board.is_some(), e.file(c)) {
            super::super::write_atomic(&dir, c, text).map_err(NotStarted::Io)?;
        }
    }
    let constraints = board.map(|_| dir.join(fpga.family().constraints().file()));
    Ok(std::thread::spawn(move || {
        let t = std::time::Instant::now();
        let r = match e {
            Ok(_) => measure::place_and_route_for(fpga, &dir, constraints.as_deref(), clock, 1),
            Err(e) => Err(e.to_string()),
        };
        (r, t.elapsed().as_secs_f64())
    }))
}

pub fn run_all(job: &mut Job, a: &Args, s: &Schedule, plan: &[(Step, Run)], scene: &Scene) {
    let mut sim_report = None;
    // engines run clean outside the campaign, for the speed chart
    let mut clean: Vec<measure::CleanRun> = Vec::new();
    let mut campaign = None;
    let mut background = plan
        .contains(&(Step::Synth, Run::Yes))
        .then(|| start_synth(&job.out, s, a.fpga));
    for &(step, run) in plan {
        if let Run::Skip(why) = run {
            job.not_run(step, &format!("not run ({why})"));
            if step == Step::Prove {
                job.answer(Glance::Proved, format!("not in this build ({why})"));
            }
            continue;
        }
        job.step(step, |j| match step {
            Step::Audit => audit(j, s),
            Step::Lut => lut(j, s),
            Step::Verilog => verilog(j, s),
            Step::Sim => sim(j, scene, s, &mut sim_report, &mut clean),
            Step::Golden => golden(j, a, s),
            Step::Faults => faults(j, a, s, &mut campaign),
            Step::Prove => prove(j, s, &mut clean),
            Step::Synth => synth(
                j,
                s,
                a.fpga,
                background.take().unwrap_or(Err(NotStarted::Missing)),
            ),
            Step::Netlist => netlist(j, s),
            Step::Timing => timing(j, s),
            Step::Figure7 => figure7(s),
            Step::Schedulability => {
                let (sec, line) = measure::schedulability(s);
                Done::ok(line)
                    .section(sec)
                    .files(&["schedulability.svg", "schedulability.csv"])
            }
            Step::Speed => speed(j, s, a, campaign.as_ref(), &mut clean),
        });
    }
}

fn written(r: Result<(), String>, d: Done) -> Done {
    match r {
        Ok(()) => d,
        Err(e) => Done::failed(e, ""),
    }
}

fn audit(j: &mut Job, s: &Schedule) -> Done {
    let r = AuditReport::of_schedule(s);
    let w = j.write(
        "",
        &[("audit.txt", r.to_text()), ("audit.json", r.to_json())],
    );
    // a mix with modes: every mode's rate, not the reset mode's alone
    let rate = if r.modes.len() > 1 {
        r.modes
            .iter()
            .map(|m| {
                format!(
                    "{} samples/s in `{}` ({:.1} %)",
                    m.aggregate_hz,
                    m.name,
                    m.adc_utilization * 100.0
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
            + &format!(" of the converters' {:.0}", r.adc_limit_hz)
    } else {
        format!(
            "{} samples/s of the converters' {:.0} ({:.1} %)",
            r.aggregate_hz,
            r.adc_limit_hz,
            r.adc_utilization * 100.0
        )
    };
    let line = format!(
        "feasible, {} slots per slice, {rate}; {}",
        s.grid.slots_per_slice,
        counted(r.warnings.len() as u64, "warning")
    );
    let mut sec = Section {
        title: "Audit".into(),
        paragraphs: r
            .warnings
            .iter()
            .map(|w| format!("Warning: {w}"))
            .chain(r.notes.iter().map(|n| format!("Note: {n}")))
            .collect(),
        links: vec![
            ("audit.txt".into(), "the audit as text".into()),
            ("audit.json".into(), "as JSON".into()),
        ],
        ..Section::default()
    };
    sec.tables = measure::budget_tables(&r);
    answer_audit(j, &r);
    written(
        w,
        Done::ok(line)
            .files(&["audit.txt", "audit.json"])
            .section(sec),
    )
}

/// The first screen's answers from the audit: whether it fits, and the
/// limit that binds with its margin (and the link's budget).
fn answer_audit(j: &mut Job, r: &AuditReport) {
    // a mix with modes: each mode's use, not the reset mode's alone
    let used = if r.modes.len() > 1 {
        r.modes
            .iter()
            .map(|m| format!("{:.1} % in `{}`", m.adc_utilization * 100.0, m.name))
            .collect::<Vec<_>>()
            .join(", ")
    } else {
        format!("{:.1} %", r.adc_utilization * 100.0)
    };
    j.answer(
        Glance::Fits,
        format!(
            "yes: {} channels, each at its rate with zero jitter; the converters {used} used",
            r.channels.len(),
        ),
    );
    let mut binds = measure::Tightest::of(r).map_or("-".into(), |t| t.words());
    if let Some(l) = &r.link {
        binds += &format!(
            "; link: {:.1} % of the line, FIFO {} tokens deep, latency {:.1} us",
            l.utilization * 100.0,
            l.fifo_depth,
            l.latency_us
        );
    }
    j.answer(Glance::Binds, binds);
}

fn lut(j: &mut Job, s: &Schedule) -> Done {
    let files = [
        ("slots.hex", lut_gen::lut::to_hex(s)),
        ("slots.csv", lut_gen::lut::to_csv(s)),
        ("slots.md", lut_gen::lut::to_markdown(s)),
    ];
    let sec = Section {
        title: "Slot table".into(),
        paragraphs: vec![format!(
            "The schedule as the paper's Table 1: {} slots per slice, {} slices per frame; every slice runs the same slots, and a rotation group's channel changes from slice to slice (the slice counter picks it).",
            s.grid.slots_per_slice, s.grid.slices_per_frame
        )],
        tables: measure::slot_table(s),
        links: vec![
            ("lut/slots.hex".into(), "one word per frame slot ($readmemh)".into()),
            ("lut/slots.csv".into(), "the frame table".into()),
            ("lut/slots.md".into(), "this table as Markdown".into()),
        ],
        ..Section::default()
    };
    written(
        j.write("lut", &files),
        Done::ok(format!("{} frame slots in lut/slots.*", s.grid.frame_slots))
            .files(&["lut/slots.hex", "lut/slots.csv", "lut/slots.md"])
            .section(sec),
    )
}

fn verilog(j: &mut Job, s: &Schedule) -> Done {
    let e = match hdl::emit(s, None) {
        Ok(e) => e,
        Err(e) => return Done::failed(format!("{e}"), ""),
    };
    let files: Vec<(&str, String)> = e
        .files()
        .iter()
        .map(|(n, t)| (n.as_str(), t.clone()))
        .collect();
    let names: Vec<String> = e
        .files()
        .iter()
        .map(|(n, _)| format!("verilog/{n}"))
        .collect();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    written(
        j.write("verilog", &files),
        Done::ok(format!(
            "{} lines of Verilog in verilog/",
            e.verilog().lines().count()
        ))
        .files(&refs),
    )
}

fn sim(
    j: &mut Job,
    scene: &Scene,
    s: &Schedule,
    keep: &mut Option<judge::Verdict>,
    clean: &mut Vec<measure::CleanRun>,
) -> Done {
    let g = &s.grid;
    let backend = sim_backend();
    let frames = scene.frames;
    let opts = SimOptions {
        vcd: Some(VcdOut {
            path: j.out.join("frame0.vcd"),
            from: 0,
            to: g.frame_cycles,
            gtkw: true,
        }),
        stimulus: engines::Stimulus::parse_for(&scene.stimulus, s).unwrap_or_default(),
        modes: scene.requests.clone(),
        ..SimOptions::default()
    };
    let t = std::time::Instant::now();
    let (r, modes) = if s.modes.len() > 1 {
        match measure::mode_scene(s, backend, frames, &opts) {
            Ok(m) => (m.verdict.clone(), Some(m)),
            Err(e) => return Done::failed(e, ""),
        }
    } else {
        match engines::run(s, backend, frames, &opts) {
            Ok(r) => (r, None),
            Err(e) => return Done::failed(format!("{e}"), ""),
        }
    };
    clean.push(measure::CleanRun {
        method: format!("engine: {}", backend.name()),
        wall_seconds: t.elapsed().as_secs_f64(),
        how: format!(
            "the co-simulation step: {frames} frames of the emitted design under the checker, with a waveform written{}",
            if modes.is_some() { ", and the same scene on the mix with one mode" } else { "" }
        ),
    });
    let json = serde_json::to_string_pretty(&r).expect("report");
    let w = j.write("", &[("sim.json", json)]);
    let d = checked(j, s, &r, backend, &scene.words(s));
    *keep = Some(r);
    let Some(m) = modes else {
        return written(w, d);
    };
    let (sec, line, glance) = measure::mode_section(s, &m, &scene.words(s), backend.name());
    j.answer(Glance::Modes, glance);
    let problems = m.problems(s);
    let d = match (&d.outcome, problems.is_empty()) {
        (Outcome::Ok(_), true) => Done {
            outcome: Outcome::Ok(line),
            ..d
        },
        (Outcome::Ok(_), false) => Done {
            outcome: Outcome::Failed(line, problems.join("\n")),
            ..d
        },
        _ => d,
    };
    written(
        w,
        d.files(&["modes-rate.svg", "modes-rate.csv"]).section(sec),
    )
}

/// The co-simulation's step and section from its verdict.
fn checked(
    j: &mut Job,
    s: &Schedule,
    r: &judge::Verdict,
    backend: Backend,
    stimulus: &str,
) -> Done {
    let sec = Section {
        title: "Co-simulation".into(),
        paragraphs: vec![format!(
            "{} of the emitted design in {} (stimulus `{stimulus}`), every cycle compared with the reference model and every invariant checked: {}. Sample counts and intervals as the run measured them, by branch and rate (jitter = largest minus smallest interval; the channels themselves are listed once, in the audit).",
            counted(r.frames, "frame"),
            backend.name(),
            if r.ok { "no divergence, no violation".to_string() } else { format!("{}, {}", counted(r.divergence_count, "divergence"), counted(r.violation_count, "violation")) }
        )],
        tables: vec![("Intervals measured, by branch and rate".into(), measure::interval_table(s, r))],
        links: vec![
            ("frame0.vcd".into(), "frame 0 with its reset cycles (VCD)".into()),
            ("frame0.gtkw".into(), "GTKWave save file for it".into()),
            (
                "frame0.channels.txt".into(),
                "GTKWave translate file: sample_channel as channel names".into(),
            ),
            ("sim.json".into(), "the check report".into()),
        ],
        ..Section::default()
    };
    let files = [
        "frame0.vcd",
        "frame0.gtkw",
        "frame0.channels.txt",
        "sim.json",
    ];
    let d = if r.ok {
        Done::ok(format!(
            "{}: {}, {}, every cycle equal to the model, no violation",
            backend.name(),
            counted(r.frames, "frame"),
            counted(r.samples, "sample")
        ))
    } else {
        Done::failed(
            format!(
                "{}, {}",
                counted(r.divergence_count, "divergence"),
                counted(r.violation_count, "violation")
            ),
            r.summary(),
        )
    };
    j.answer(
        Glance::Checked,
        if r.ok {
            format!(
                "yes: {} of the emitted Verilog on {}, every pin every cycle equal to the reference model, no violation",
                counted(r.frames, "frame"),
                backend.name()
            )
        } else {
            format!(
                "NO: {}, {} in {} on {}",
                counted(r.divergence_count, "divergence"),
                counted(r.violation_count, "violation"),
                counted(r.frames, "frame"),
                backend.name()
            )
        },
    );
    d.files(&files).section(sec)
}

fn golden(j: &mut Job, a: &Args, s: &Schedule) -> Done {
    let dir = a.golden.join(&s.mix.name);
    if !dir.join("events.log").exists() {
        return Done::skipped(format!("no golden in {}", dir.display()));
    }
    let ga = super::super::golden::Args {
        mix: vec![a.mix.clone()],
        backend: sim_backend(),
        rtl: None,
        update: false,
        dir: a.golden.clone(),
        junit: None,
        quiet: true,
        scene: Default::default(),
    };
    let mut o = super::super::golden::Output::default();
    let code = super::super::golden::execute(&ga, &a.mix, &mut o);
    let w = j.write("", &[("golden.txt", format!("{}{}", o.out, o.err))]);
    let first = o.out.lines().next().unwrap_or("").to_string();
    let d = if code == 0 {
        Done::ok(first)
    } else {
        Done::failed(first, format!("{}{}", o.out, o.err))
    };
    written(w, d.files(&["golden.txt"]))
}

/// The campaign's plan: the model's pins (the gateware with `--thorough`);
/// with `--charts all`, also the deep Verilog faults on every installed
/// Verilog engine and `prove`, so the speed chart compares every method.
fn fault_plan(a: &Args, s: &Schedule) -> Result<campaign::Plan, String> {
    let target = if a.thorough {
        campaign::Target::Rusthdl
    } else {
        campaign::Target::Model
    };
    // A fresh mix gets every class at one site (mid-frame) and one clean
    // random mix, judged by the model and the invariants, in seconds; the
    // full campaign (every site, five clean mixes, sigrok's decode) when it
    // is asked for: --only faults, --charts all, --thorough.
    let mut plan = campaign::Plan::new(target, 3, 5);
    if !full_campaign(a) {
        let mid = campaign::sites(s)
            .into_iter()
            .filter(|x| x.name == "mid-frame");
        plan.sites = Some(mid.collect());
        plan.false_alarm_mixes = 1;
        plan.sigrok = false;
    }
    if a.charts == Charts::All {
        plan.verilog_engines = [
            ("verilator", Backend::Verilator),
            ("iverilog", Backend::Icarus),
        ]
        .into_iter()
        .filter(|(tool, _)| judge::tools::present(tool))
        .map(|(_, b)| b)
        .collect();
        plan.verilog_faults = campaign::deep_faults(s, plan.frames)?;
        plan.prove = true;
    }
    Ok(plan)
}

/// Every site and five clean mixes, rather than the quick default.
fn full_campaign(a: &Args) -> bool {
    a.thorough || a.charts == Charts::All || only_names(a, Step::Faults)
}

fn faults(j: &mut Job, a: &Args, s: &Schedule, keep: &mut Option<campaign::Campaign>) -> Done {
    let full = full_campaign(a);
    let hook = j.runs_hook("fault campaign");
    let c = match fault_plan(a, s).and_then(|mut p| {
        p.on_run = hook;
        campaign::campaign_with(s, &p).map_err(|e| e.to_string())
    }) {
        Ok(c) => c,
        Err(e) => return Done::failed(e, ""),
    };
    let scope = if full {
        "The full campaign"
    } else {
        "The quick campaign (every class at one site; --only faults or --charts all for every site)"
    };
    let json = serde_json::to_string_pretty(&c).expect("campaign");
    let w = j.write("", &[("faults.json", json)]);
    let target_name = if a.thorough {
        "rusthdl (the gateware)"
    } else {
        "cycle model (the reference model's pins)"
    };
    let line = match &c.clean.why {
        Some(why) => format!(
            "the mix's own clean run on {} fails, so no fault was injected: {}",
            c.clean.engine,
            why.lines().next().unwrap_or("")
        ),
        None => format!(
        "{} of {} injections detected ({} undetected, {} proved equivalent) over {} classes and {} ({target_name}{}); {} false alarms in {}",
        c.detected,
        c.injected,
        c.undetected,
        c.proved_equivalent,
        c.classes.len(),
        counted(c.sites.len() as u64, "site"),
        if full { "" } else { "; quick" },
        c.false_alarms.rejected,
        counted(c.false_alarms.runs, "clean run")
        ),
    };
    let sec = Section {
        title: "Fault campaign".into(),
        paragraphs: vec![format!(
            "{scope}. Target: {target_name}; sites: {}. {line}.",
            c.sites
                .iter()
                .map(|x| format!("{} (slot {})", x.name, x.slot))
                .collect::<Vec<_>>()
                .join(", ")
        )],
        tables: vec![("Faults by class".into(), measure::fault_table(&c))],
        links: vec![("faults.json".into(), "every injection".into())],
        ..Section::default()
    };
    let d = if c.ok() {
        Done::ok(line)
    } else {
        Done::failed(line, "see faults.json")
    };
    let glance = match c.clean.ok {
        false => format!("none: the mix's own clean run on {} fails", c.clean.engine),
        true => format!(
            "{} of {} injected faults detected, {} false alarms in {} ({})",
            c.detected,
            c.injected,
            c.false_alarms.rejected,
            counted(c.false_alarms.runs, "clean run"),
            if full {
                "the full campaign"
            } else {
                "the quick campaign"
            }
        ),
    };
    j.answer(Glance::Faults, glance);
    *keep = Some(c);
    written(w, d.files(&["faults.json"]).section(sec))
}

fn prove(j: &mut Job, s: &Schedule, clean: &mut Vec<measure::CleanRun>) -> Done {
    if let Some(t) = ["yosys", "yosys-abc", "iverilog"]
        .into_iter()
        .find(|t| !judge::tools::present(t))
    {
        return Done::skipped(format!("{t} not installed (make tools)"));
    }
    let r = measure::proof(s, &j.out);
    proved(j, r, clean)
}

/// A proof's step: proved is ok; bounded (not a proof) and failed fail.
fn proved(
    j: &mut Job,
    r: Result<measure::ShownProof, String>,
    clean: &mut Vec<measure::CleanRun>,
) -> Done {
    let shown = match r {
        Ok(x) => x,
        Err(e) => {
            j.answer(Glance::Proved, "no: the proof could not run");
            return Done::failed("the proof could not run", e);
        }
    };
    let whose = if shown.cached {
        "remembered for this same Verilog"
    } else {
        "proved in this build"
    };
    clean.push(measure::CleanRun {
        method: "prove".into(),
        wall_seconds: shown.proof.seconds,
        how: format!("the clean design proved for all time ({whose}; the seconds it took then)"),
    });
    j.answer(
        Glance::Proved,
        if shown.proof.result == formal::Outcome::Proved {
            format!("yes ({whose}): {}", shown.line)
        } else {
            format!("NO ({whose}): {}", shown.line)
        },
    );
    let files: Vec<String> = shown.section.links.iter().map(|(f, _)| f.clone()).collect();
    let files: Vec<&str> = files.iter().map(String::as_str).collect();
    let d = if shown.proof.result == formal::Outcome::Proved {
        Done::ok(shown.line)
    } else {
        Done::failed(shown.line, shown.proof.summary())
    };
    d.files(&files).section(shown.section)
}

fn synth(
    j: &mut Job,
    s: &Schedule,
    fpga: lut_gen::Fpga,
    background: Result<Background, NotStarted>,
) -> Done {
    let (pnr, _) = fpga.nextpnr();
    let h = match background {
        Ok(h) => h,
        Err(NotStarted::Missing) => {
            j.answer(
                Glance::Size,
                format!("not measured: {} or {pnr} not installed", fpga.yosys()),
            );
            let make = if fpga == lut_gen::Fpga::Ice40Hx8k {
                "make tools"
            } else {
                "make tools-extra"
            };
            return Done::skipped(format!("{} or {pnr} not installed ({make})", fpga.yosys()));
        }
        Err(NotStarted::Io(why)) => {
            j.answer(Glance::Size, format!("not measured: {why}"));
            return Done::failed(format!("not measured: {why}"), "");
        }
    };
    let Ok((r, secs)) = h.join() else {
        return Done::failed("place and route stopped unexpectedly", "");
    };
    let g = &s.grid;
    match r {
        Ok(r) => {
            let line = format!(
                "{} logic cells, {} block RAMs, Fmax {:.1} MHz = {:.2}x the {:.1} MHz clock (placed and routed beside the other steps)",
                r.lcs,
                r.brams,
                r.fmax_mhz,
                r.fmax_mhz * 1e6 / g.clock_hz as f64,
                g.clock_hz as f64 / 1e6
            );
            j.answer(
                Glance::Size,
                format!(
                    "{} logic cells and {} block RAMs of {}; Fmax {:.1} MHz, {:.2}x the {:.1} MHz clock ({} and {pnr})",
                    r.lcs,
                    r.brams,
                    part_words(fpga),
                    r.fmax_mhz,
                    r.fmax_mhz * 1e6 / g.clock_hz as f64,
                    g.clock_hz as f64 / 1e6,
                    fpga.yosys()
                ),
            );
            let how = match fpga {
                lut_gen::Fpga::Ice40Hx8k => "yosys synth_ice40 and nextpnr-ice40 --hx8k (IO left unconstrained, seed 1), the flow of hdl/synth.sh".to_string(),
                f => format!("{} synth_{} and {pnr} (the pins of the {}, seed 1), the flow of `slotforge synth --fpga {f}`", f.yosys(), f.family(), f.board().0),
            };
            let sec = Section {
                title: "Synthesis estimate".into(),
                paragraphs: vec![format!(
                    "{how}: {line}; {} LUT4s and {} flip-flops.",
                    r.lut4, r.dff
                )],
                links: vec![
                    (
                        "synth/slotforge_top.v".into(),
                        "the Verilog synthesized".into(),
                    ),
                    ("synth/yosys.log".into(), "yosys log".into()),
                    ("synth/stat.txt".into(), "cell counts".into()),
                    ("synth/nextpnr.log".into(), "place and route log".into()),
                ],
                ..Section::default()
            };
            // the row's time is the place and route's own, not the wait for it
            Done::ok(line)
                .took(secs)
                .files(&["synth/yosys.log", "synth/nextpnr.log"])
                .section(sec)
        }
        Err(e) => Done::failed("place and route failed", e),
    }
}

/// The netlist that goes to the chip: yosys' iCE40 netlist of the emitted
/// Verilog with the cell models, one frame under the same ADC model and
/// judge as the co-simulation (`sim --netlist ice40`); its report is
/// `netlist.json` (as `sim --json`), the summary and section read from it.
fn netlist(j: &mut Job, s: &Schedule) -> Done {
    let backend = if judge::tools::present("verilator") {
        Backend::Verilator
    } else {
        Backend::Icarus
    };
    if !judge::tools::present("yosys") || !judge::tools::present(backend.name()) {
        return Done::skipped("yosys or a Verilog simulator not installed (make tools)");
    }
    let fpga = lut_gen::Fpga::Ice40Hx8k;
    let dir = j.out.join("netlist");
    if let Err(e) = measure::netlist(s, fpga, &dir) {
        return Done::failed("yosys could not write the netlist", e);
    }
    let opts = SimOptions {
        rtl: Some(dir.join(measure::NETLIST_SIM_FILE)),
        ..SimOptions::default()
    };
    let mut r = match engines::run(s, backend, 1, &opts) {
        Ok(r) => r,
        Err(e) => return Done::failed(format!("{e}"), ""),
    };
    r.source = format!("{}, {fpga} netlist", r.source);
    let json = serde_json::to_string_pretty(&r).expect("report");
    let w = j.write("", &[("netlist.json", json)]);
    let line = if r.ok {
        format!(
            "{}: {}, {}, every cycle equal to the model, no violation",
            r.source,
            counted(r.frames, "frame"),
            counted(r.samples, "sample")
        )
    } else {
        format!(
            "{}: {}, {}",
            r.source,
            counted(r.divergence_count, "divergence"),
            counted(r.violation_count, "violation")
        )
    };
    let sec = Section {
        title: "The netlist on the chip".into(),
        paragraphs: vec![format!(
            "yosys synth_ice40 of the emitted Verilog, written back as gate-level Verilog and simulated with yosys' iCE40 cell models under the same ADC model and checker as the co-simulation ({line}). Place and route and timing are not part of this check (the synthesis estimate's Fmax is)."
        )],
        links: vec![
            (
                format!("netlist/{}", measure::NETLIST_FILE),
                "the netlist".into(),
            ),
            ("netlist.json".into(), "the check report".into()),
        ],
        ..Section::default()
    };
    let d = if r.ok {
        Done::ok(line)
    } else {
        Done::failed(line, r.summary())
    };
    written(w, d.files(&["netlist.json"]).section(sec))
}

/// The part as the report's glance names it.
fn part_words(fpga: lut_gen::Fpga) -> &'static str {
    match fpga {
        lut_gen::Fpga::Ice40Hx8k => "an iCE40 HX8K",
        lut_gen::Fpga::Ecp5_25k => "an ECP5 LFE5U-25F",
        lut_gen::Fpga::Gw1n9 => "a Gowin GW1NR-9",
    }
}

fn timing(j: &mut Job, s: &Schedule) -> Done {
    match measure::timing(s, sim_backend()) {
        Ok((sec, wavedrom, line)) => written(
            j.write("", &[("conversion.wavedrom.json", wavedrom)]),
            Done::ok(line)
                .section(sec)
                .files(&["timing-slice.svg", "conversion.wavedrom.json"]),
        ),
        Err(e) => Done::failed(e, ""),
    }
}

fn figure7(s: &Schedule) -> Done {
    match measure::figure7(s) {
        Ok((sec, line)) => Done::ok(line).section(sec),
        Err(e) => Done::failed(e, ""),
    }
}

/// Drawn from the fault step's campaign of this build, with the gateware's
/// engines on a sample of its faults (those not already in the campaign:
/// rust-hdl, and Verilator when installed) and what ran clean beside it.
/// The sample's misses are data on the chart, not a failed step.
fn speed(
    j: &mut Job,
    s: &Schedule,
    a: &Args,
    c: Option<&campaign::Campaign>,
    clean: &mut Vec<measure::CleanRun>,
) -> Done {
    let Some(c) = c else {
        return Done::skipped(
            "draws the fault campaign of this build, and the faults step did not run",
        );
    };
    let mut plan = Vec::new();
    let in_campaign = |e: campaign::Engine| c.engines.iter().any(|x| x.engine == e.name());
    // rust-hdl takes seconds a run on a 48 MHz mix: a few faults of the sample
    if !in_campaign(campaign::Engine::Rusthdl) {
        plan.push((campaign::Engine::Rusthdl, RUSTHDL_SAMPLE));
    }
    if judge::tools::present("verilator") && !in_campaign(campaign::Engine::Verilator) {
        plan.push((campaign::Engine::Verilator, usize::MAX));
    }
    let methods = campaign::methods(s, &plan, SAMPLE_FRAMES);
    // an engine with a measured catch leaves the cost-only row
    clean.retain(|m| {
        !methods
            .iter()
            .any(|r| r.not_run.is_none() && m.method == format!("engine: {}", r.engine.name()))
    });
    let json = serde_json::to_string_pretty(&methods).expect("methods");
    let w = j.write("", &[("methods.json", json)]);
    let (sec, line) = measure::speed(c, &methods, clean, a.charts == Charts::All);
    written(
        w,
        Done::ok(line).section(sec).files(&[
            "speed-accuracy.svg",
            "speed-accuracy.csv",
            "methods.json",
        ]),
    )
}

/// Faults of the sample rust-hdl runs (about 2 s a frame on a 48 MHz mix),
/// so a default build stays under a minute.
const RUSTHDL_SAMPLE: usize = 3;

/// Frames per run of the sample: the fault lands mid-way through frame 1.
const SAMPLE_FRAMES: u64 = 2;
