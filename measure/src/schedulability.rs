//! Where scheduling breaks, around the user's mix: random mixes of its own
//! clock, frame, branches and rates (the one generator,
//! `campaign::mixgen`), from one channel to about twice its demand, each
//! synthesized; scheduled, proved infeasible and undecided (the exact
//! search's bound hit: `lut_gen::Verdict::Unknown`) ones drawn with different
//! markers, the mix itself marked. An undecided mix is never counted as one
//! without a schedule.

use std::path::Path;
use std::time::Instant;

use campaign::{random_mix, Shape};
use lut_gen::{Schedule, Verdict};
use report::{draw, Axes, Figure, Marker, Section, Series, Table};

/// Random mixes drawn.
pub const MIXES: u64 = 60;

/// ADC utilization of a mix: demand over the converters' throughput, the
/// audit's `adc_utilization` (the same per-branch maximum,
/// `lut_gen::Branch::max_samples_hz`, summed in the same order).
fn utilization(m: &lut_gen::Mix) -> f64 {
    let demand: u64 = m.channels.iter().map(|c| c.rate_hz).sum();
    let cap: f64 = m
        .branches
        .iter()
        .map(|b| b.max_samples_hz(m.clock_hz))
        .sum();
    demand as f64 / cap
}

/// The parts of a mix's branches, counted: `2 x AD7940, 1 x AD7685 (chain
/// of 4)`, in the order they first appear.
pub fn parts(m: &lut_gen::Mix) -> String {
    let mut seen: Vec<(String, usize)> = Vec::new();
    for b in &m.branches {
        let name = match b.chain {
            1 => b.adc.name.to_uppercase(),
            n => format!("{} (chain of {n})", b.adc.name.to_uppercase()),
        };
        match seen.iter_mut().find(|(n, _)| *n == name) {
            Some((_, k)) => *k += 1,
            None => seen.push((name, 1)),
        }
    }
    seen.iter()
        .map(|(n, k)| format!("{k} x {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The random mixes by outcome, each as (utilization %, synthesis ms).
#[derive(Default)]
struct Outcomes {
    scheduled: Vec<(f64, f64)>,
    infeasible: Vec<(f64, f64)>,
    unknown: Vec<(f64, f64)>,
}

impl Outcomes {
    fn total(&self) -> usize {
        self.scheduled.len() + self.infeasible.len() + self.unknown.len()
    }
}

/// The section and a one-line summary.
pub fn schedulability(s: &Schedule) -> (Section, String) {
    let mix = &s.mix;
    let u0 = utilization(mix);
    // enough channels to reach about twice the mix's demand, or full ADCs
    let n0 = mix.channels.len() as f64;
    let max = ((n0 * (2.0f64).max(1.2 / u0.max(1e-3))).ceil() as u64).clamp(4, 512);
    let shape = Shape::around(mix, max);
    let mut table = Table::new(&["seed", "channels", "utilization", "verdict", "synthesis_ms"]);
    let (outcomes, drawn) = sample(&shape, &mut table);
    let t = Instant::now();
    let _ = lut_gen::synthesize(mix);
    let own = (t.elapsed().as_secs_f64() * 1e3).max(1e-3);
    let line = summary(&outcomes, u0);
    let mut me = Series::scatter(
        &format!("this mix ({:.0} %)", u0 * 100.0),
        vec![(u0 * 100.0, own)],
    )
    .with_marker(Marker::Square);
    me.labels = vec![(u0 * 100.0, own, mix.name.clone())];
    let mut series = outcome_series(outcomes);
    series.push(me);
    let rates: Vec<String> = shape.rates_hz.iter().map(|r| format!("{r} Hz")).collect();
    (
        Section {
            title: "Where scheduling breaks".into(),
            paragraphs: vec![
                format!("{MIXES} random mixes around this one: its clock ({} Hz), frame ({} us) and slice ({} us), its number of branches ({}; this mix: {}; the random mixes: {drawn}) and its rates ({}), with 1 to {max} channels. Dots: an exact schedule exists; crosses: none does (synthesis proves it); triangles, if any: undecided (the exact search hit its bound); the square is this mix.", mix.clock_hz, mix.frame_us, mix.slice_us, mix.branches.len(), parts(mix), rates.join(", ")),
                format!("{line}."),
            ],
            figures: vec![Figure {
                stem: "schedulability".into(),
                title: "Where scheduling breaks".into(),
                caption: "each marker a random mix around this one; x: demand over the converters' throughput; y: time to synthesize (or to prove there is no exact schedule)".into(),
                svg: draw(&breaks_axes(), &series, 900, 460),
                table,
            }],
            ..Section::default()
        },
        line,
    )
}

/// Synthesizes the random mixes of `shape`, one table row each; with the
/// parts the random mixes were drawn with (each mix's [`parts`], the
/// different ones joined by "or").
fn sample(shape: &Shape, table: &mut Table) -> (Outcomes, String) {
    let mut o = Outcomes::default();
    let mut drawn: Vec<String> = Vec::new();
    for seed in 1..=MIXES {
        let text = random_mix(seed, shape);
        let Ok(m) = lut_gen::parse(Path::new("random.toml"), &text) else {
            continue;
        };
        let p = parts(&m);
        if !drawn.contains(&p) {
            drawn.push(p);
        }
        let u = utilization(&m);
        let t = Instant::now();
        // `None`: scheduled
        let verdict = lut_gen::synthesize(&m).err().map(|e| e.verdict);
        let ms = (t.elapsed().as_secs_f64() * 1e3).max(1e-3);
        table.push(vec![
            seed.to_string(),
            m.channels.len().to_string(),
            format!("{u:.4}"),
            verdict.map_or("scheduled", Verdict::as_str).to_string(),
            format!("{ms:.4}"),
        ]);
        match verdict {
            None => &mut o.scheduled,
            Some(Verdict::Infeasible) => &mut o.infeasible,
            Some(Verdict::Unknown) => &mut o.unknown,
        }
        .push((u * 100.0, ms));
    }
    (o, drawn.join(" or "))
}

fn summary(o: &Outcomes, u0: f64) -> String {
    let best = o.scheduled.iter().map(|p| p.0).fold(0.0f64, f64::max);
    let worst = o
        .infeasible
        .iter()
        .map(|p| p.0)
        .fold(f64::INFINITY, f64::min);
    let undecided = if o.unknown.is_empty() {
        String::new()
    } else {
        format!(
            "; {} undecided (the search's bound hit, no proof either way)",
            o.unknown.len()
        )
    };
    format!(
        "{} of {} random mixes around this one have an exact schedule, up to {best:.0} % ADC utilization{}{undecided}; this mix: {:.1} % (the audit's ADC utilization)",
        o.scheduled.len(),
        o.total(),
        if worst.is_finite() { format!(", the least loaded proved without one at {worst:.0} %") } else { String::new() },
        u0 * 100.0
    )
}

/// One marker kind per outcome (undecided only when there are some).
fn outcome_series(o: Outcomes) -> Vec<Series> {
    let mut series = vec![
        Series::scatter(
            &format!("exact schedule ({})", o.scheduled.len()),
            o.scheduled,
        )
        .with_marker(Marker::Circle),
        Series::scatter(
            &format!("none exists ({})", o.infeasible.len()),
            o.infeasible,
        )
        .with_marker(Marker::Cross),
    ];
    if !o.unknown.is_empty() {
        let n = o.unknown.len();
        series.push(
            Series::scatter(&format!("undecided ({n})"), o.unknown).with_marker(Marker::Triangle),
        );
    }
    series
}

fn breaks_axes() -> Axes {
    let mut axes = Axes::new(
        "Where scheduling breaks around this mix",
        "ADC utilization (% of the converters' throughput)",
        "synthesis time (ms, log)",
    );
    axes.log_y = true;
    // infeasible mixes sit on the right: keep the legend off them
    axes.legend_left = true;
    axes.vlines = vec![(100.0, "100 %".into())];
    axes
}
