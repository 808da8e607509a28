//! Speed against accuracy of the verification methods, drawn from one
//! fault campaign (`campaign::Campaign`) and nothing else: its
//! detector columns and its engines, each with the detections the matrix
//! counts and the seconds the same campaign measured.  The chart draws
//! counts (n of N), a real-time line, and keeps every point inside its axes.

use campaign::{Campaign, MethodRun};
use report::{draw, Axes, Figure, Marker, Section, Series, Table};

/// One method: what one judged run cost it, and how many of the faults
/// that can reach it it detected, both from the campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodScore {
    /// A detector's name as the fault table names it (`model`,
    /// `invariants`, `sigrok`, `prove`), or `engine: NAME` for an engine
    /// the faults ran through (`cycle model`, `rusthdl`, `verilator`,
    /// `icarus`).
    pub method: String,
    /// Runs (or proofs) timed, and their wall seconds in all.
    pub runs: u64,
    pub wall_seconds: f64,
    pub detected: u64,
    /// Injections that can reach this method (the classes it can see; for
    /// an engine, those that ran through it).
    pub of: u64,
    /// What was timed.
    pub how: String,
}

impl MethodScore {
    /// Wall seconds per judged run.
    pub fn seconds_per_run(&self) -> f64 {
        self.wall_seconds / self.runs.max(1) as f64
    }
}

/// An engine this build ran clean under the full check outside the fault
/// campaign (the co-simulation on Verilator, a rust-hdl run, the
/// remembered proof): its cost is measured, but no fault went through it
/// in the quick campaign, so it sits on the chart's cost-only row.
#[derive(Debug, Clone, PartialEq)]
pub struct CleanRun {
    /// `engine: verilator`, `engine: rusthdl`, `prove`.
    pub method: String,
    pub wall_seconds: f64,
    /// What was timed.
    pub how: String,
}

/// The methods of campaign `c`: every detector that ran, then every engine.
pub fn scores(c: &Campaign) -> Vec<MethodScore> {
    let mut out = Vec::new();
    for col in c.columns.iter().filter(|col| col.not_run.is_none()) {
        let how = match col.detector {
            campaign::Detector::Model => "a clean run checked against the model",
            campaign::Detector::Invariants => "a clean run checked without the model",
            campaign::Detector::Sigrok => "every sigrok-cli decode of the campaign",
            campaign::Detector::Prove => "every proof of the campaign (for all time)",
        };
        out.push(MethodScore {
            method: col.detector.name().into(),
            runs: col.runs,
            wall_seconds: col.seconds,
            detected: col.detected,
            of: col.injected,
            how: how.into(),
        });
    }
    for e in &c.engines {
        out.push(MethodScore {
            method: format!("engine: {}", e.engine),
            runs: 1,
            wall_seconds: e.seconds,
            detected: e.detected,
            of: e.injected,
            how: "a clean run under the checker; detected by any detector".into(),
        });
    }
    out
}

const MARKERS: [Marker; 4] = [
    Marker::Circle,
    Marker::Triangle,
    Marker::Square,
    Marker::Cross,
];

/// The simulated seconds one judged run of `c` covers.
pub fn run_seconds(c: &Campaign) -> f64 {
    c.engines.first().map_or(0.0, |e| e.cycles as f64) / c.clock_hz.max(1) as f64
}

/// The clean runs' rows and their points on the cost-only row (y -4),
/// labels stepped so none hides another.
fn clean_points(
    clean: &[CleanRun],
    table: &mut Table,
    series: &mut Vec<Series>,
    placed: &mut Vec<(f64, f64)>,
) {
    for (i, m) in clean.iter().enumerate() {
        table.push(vec![
            m.method.clone(),
            "1".into(),
            format!("{:.6}", m.wall_seconds),
            format!("{:.6}", m.wall_seconds),
            "0".into(),
            "0".into(),
            m.how.clone(),
        ]);
        let x = m.wall_seconds.max(1e-6);
        let label = format!("{} (cost only)", m.method);
        let mut sr =
            Series::scatter(&label, vec![(x, -4.0)]).with_marker(MARKERS[(i + 2) % MARKERS.len()]);
        let near = placed
            .iter()
            .filter(|&&(px, py)| (px / x).log10().abs() < 0.6 && (py + 4.0).abs() < 6.0)
            .count();
        placed.push((x, -4.0));
        sr.labels = vec![(x, -4.0 + 5.0 * near as f64, label)];
        series.push(sr);
    }
}

/// The scores of the engines that ran the sample of the quick campaign
/// (`campaign::methods`), rows of the methods table: each engine's faults
/// run, caught, and its wall seconds.
pub fn sample_scores(methods: &[MethodRun]) -> Vec<MethodScore> {
    methods
        .iter()
        .filter(|m| m.not_run.is_none() && m.faults_run > 0)
        .map(|m| MethodScore {
            method: format!("engine: {}", m.engine.name()),
            runs: m.faults_run,
            wall_seconds: m.seconds,
            detected: m.caught,
            of: m.faults_run,
            how: format!(
                "the sample of the quick campaign: {} fault(s) at its site; {} frames each; judged by the checker",
                m.faults_run, m.frames
            ),
        })
        .collect()
}

/// The methods table of the report: one row per engine of the sample, the
/// figures the chart's points are drawn from.
pub fn methods_table(methods: &[MethodRun]) -> Table {
    let mut t = Table::new(&[
        "Engine",
        "Faults run",
        "Caught",
        "Missed",
        "Frames per run",
        "Time (s)",
        "Time per run (s)",
    ]);
    for m in methods {
        let missed = match &m.not_run {
            Some(why) => format!("not run: {why}"),
            None if m.missed.is_empty() => "none".into(),
            None => m.missed.join(", "),
        };
        t.push(vec![
            m.engine.name().into(),
            m.faults_run.to_string(),
            m.caught.to_string(),
            missed,
            m.frames.to_string(),
            format!("{:.3}", m.seconds),
            format!("{:.3}", m.seconds_per_run()),
        ]);
    }
    t
}

/// What the engines of the sample ran, in words: how many faults each
/// point ran, and those an engine could not run.
fn methods_paragraph(c: &Campaign, methods: &[MethodRun]) -> Option<String> {
    if methods.is_empty() {
        return None;
    }
    let each: Vec<String> = methods
        .iter()
        .map(|m| match &m.not_run {
            Some(why) => format!("{}: not run ({why})", m.engine.name()),
            None => format!(
                "`engine: {}` ran {} of them and caught {}",
                m.engine.name(),
                m.faults_run,
                m.caught
            ),
        })
        .collect();
    Some(format!(
        "The gateware's engines ran a sample of the quick campaign (its pin faults, one of each class, in an order fixed by the mix's name, at the same site, {} frames per run, judged by the same checker): {}. Their points and the table below are the same figures; a fault an engine misses is shown, and does not fail the build (the campaign above gates it).",
        methods.first().map_or(c.frames, |m| m.frames),
        each.join("; ")
    ))
}

/// The chart and its table for `c`'s methods, the engines of the sample
/// (`methods`) and the clean runs beside them.
pub fn chart(c: &Campaign, methods: &[MethodRun], clean: &[CleanRun]) -> Figure {
    let mut scores = scores(c);
    scores.extend(sample_scores(methods));
    let mut table = Table::new(&[
        "method",
        "runs_timed",
        "wall_seconds",
        "wall_seconds_per_run",
        "faults_detected",
        "faults_reaching_it",
        "what was timed",
    ]);
    // Methods with the same cost and the same count (the model detector
    // and the cycle-model engine time the same clean run) share one point
    // and one label naming both: one marker drawn over the other would hide it.
    let mut points: Vec<(f64, u64, u64, Vec<String>)> = Vec::new();
    for m in &scores {
        table.push(vec![
            m.method.clone(),
            m.runs.to_string(),
            format!("{:.6}", m.wall_seconds),
            format!("{:.6}", m.seconds_per_run()),
            m.detected.to_string(),
            m.of.to_string(),
            m.how.clone(),
        ]);
        if m.of == 0 || m.runs == 0 {
            continue; // nothing reaches it: no accuracy to place
        }
        let x = m.seconds_per_run().max(1e-6);
        let same = points
            .iter_mut()
            .find(|p| (p.0 / x).log10().abs() < 0.005 && (p.1, p.2) == (m.detected, m.of));
        match same {
            Some(p) => p.3.push(m.method.clone()),
            None => points.push((x, m.detected, m.of, vec![m.method.clone()])),
        }
    }
    let mut series = Vec::new();
    let mut placed: Vec<(f64, f64)> = Vec::new();
    clean_points(clean, &mut table, &mut series, &mut placed);
    for (i, (x, detected, of, names)) in points.into_iter().enumerate() {
        let pct = 100.0 * detected as f64 / of as f64;
        let label = format!("{} ({detected} of {of})", names.join(" and "));
        let mut sr =
            Series::scatter(&label, vec![(x, pct)]).with_marker(MARKERS[i % MARKERS.len()]);
        // labels of points close together step down, so none hides another
        let near = placed
            .iter()
            .filter(|&&(px, py)| (px / x).log10().abs() < 0.6 && (py - pct).abs() < 6.0)
            .count();
        placed.push((x, pct));
        sr.labels = vec![(x, (pct - 7.0 * near as f64).max(-8.0), label.clone())];
        series.push(sr);
    }
    let real = run_seconds(c);
    let xs = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .chain([real.max(1e-6)]);
    let (lo, hi) = xs.fold((f64::MAX, f64::MIN), |a, v| (a.0.min(v), a.1.max(v)));
    let mut axes = Axes::new(
        "Speed against accuracy of the verification methods (this build)",
        "wall seconds per judged run (log; left of the line: faster than real time)",
        "faults detected (% of those reaching the method; labels: n of N; below 0: cost only)",
    );
    axes.log_x = true;
    // a decade of room on each side, so markers and labels stay inside
    axes.x_range = Some((lo / 10.0, hi * 10.0));
    // room above 100 % for the legend (upper right, about 17 px a row of
    // the plot's ~380 px), so it hides no point or label
    let frac = ((series.len() * 17 + 20) as f64 / 380.0).min(0.6);
    axes.y_range = Some((-12.0, ((110.0 + 10.0 * frac) / (1.0 - frac)).max(115.0)));
    axes.vlines = vec![(real.max(1e-6), "real time".into())];
    Figure {
        stem: "speed-accuracy".into(),
        title: "Speed against accuracy".into(),
        caption: format!(
            "From the fault campaign of this build: x, wall seconds one judged run took (the line: the {:.4} s of acquisition one run simulates); y, share of the injections reaching each method that it detected, labelled n of N as in the fault table",
            real
        ),
        svg: draw(&axes, &series, 900, 480),
        table,
    }
}

/// The section for campaign `c` and the clean runs beside it, and its
/// one-line summary. `charts_all`: whether this build ran every method.
pub fn speed(
    c: &Campaign,
    methods: &[MethodRun],
    clean: &[CleanRun],
    charts_all: bool,
) -> (Section, String) {
    let mut scores = scores(c);
    scores.extend(sample_scores(methods));
    let line = scores
        .iter()
        .map(|m| {
            format!(
                "{} {:.4} s per run, {} of {}",
                m.method,
                m.seconds_per_run(),
                m.detected,
                m.of
            )
        })
        .chain(
            clean
                .iter()
                .map(|m| format!("{} {:.4} s per run, cost only", m.method, m.wall_seconds)),
        )
        .collect::<Vec<_>>()
        .join("; ");
    let not_run: Vec<String> = c
        .columns
        .iter()
        .filter_map(|col| {
            Some(format!(
                "{}: {}",
                col.detector.name(),
                col.not_run.as_ref()?
            ))
        })
        .collect();
    let mut paragraphs = vec![
        "The campaign's points are the columns of the fault table above: a detector (its name as in the table) with the injections it can see, or an engine the faults ran through (`engine: NAME`) with the injections that ran through it and were detected by any detector. The cost is what the campaign measured: a clean run of its frames under the checker with and without the model, each sigrok-cli decode, each proof.".into(),
        format!("{line}."),
    ];
    paragraphs.extend(methods_paragraph(c, methods));
    if !clean.is_empty() {
        paragraphs.push(format!(
            "On the row below 0 %, what this build also ran clean, outside the campaign, so no fault went through it here: {}. Its cost is measured; what it catches is measured by `--charts all`.",
            clean
                .iter()
                .map(|m| format!("{} ({})", m.method, m.how))
                .collect::<Vec<_>>()
                .join("; ")
        ));
    }
    if !not_run.is_empty() {
        paragraphs.push(format!("Not on the chart: {}.", not_run.join("; ")));
    }
    if !charts_all {
        paragraphs.push("`--charts all` adds: every class at every site with five clean random mixes, sigrok-cli's SPI decode as a detector, the deep Verilog faults (a counter that misbehaves after the run's last frame, a merger collision no stimulus drives) run through Verilator and Icarus, each engine with the faults through it and what caught them (a simulation misses the deep faults by design: that is what they show), and `prove` as a detector of every fault that is a design (minutes on a 48 MHz mix).".into());
    }
    (
        Section {
            title: "Speed against accuracy".into(),
            paragraphs,
            tables: if methods.is_empty() {
                vec![]
            } else {
                vec![(
                    "Engines on a sample of the quick campaign".into(),
                    methods_table(methods),
                )]
            },
            figures: vec![chart(c, methods, clean)],
            ..Section::default()
        },
        line,
    )
}
