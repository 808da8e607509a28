//! Where scheduling breaks, around the user's mix: random mixes of its own
//! clock, frame, branches and rates (the one generator,
//! `campaign::mixgen`), from one channel to about twice its demand, each
//! synthesized; scheduled, proved infeasible and undecided (the exact
//! search's bound hit: `lut_gen::Verdict::Unknown`) ones drawn with different
//! markers, the mix itself marked. An undecided mix is never counted as one
//! without a schedule.

use std::path::Path;
use std::time::Instant;

use campaign::mixgen::{random_mix, Shape};
use lut_gen::Schedule;
use report::{draw, Axes, Figure, Marker, Section, Series, Table};

/// Random mixes drawn.
pub const MIXES: u64 = 60;

/// ADC utilization of a mix: demand over the converters' throughput.
fn utilization(m: &lut_gen::Mix) -> f64 {
    let demand: u64 = m.channels.iter().map(|c| c.rate_hz).sum();
    let cap: u64 = m
        .branches
        .iter()
        .map(|b| b.adc.max_sps * b.chain as u64)
        .sum();
    demand as f64 / cap.max(1) as f64
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
    let (mut ok, mut no, mut unknown) = (Vec::new(), Vec::new(), Vec::new());
    for seed in 1..=MIXES {
        let text = random_mix(seed, &shape);
        let Ok(m) = lut_gen::parse(Path::new("random.toml"), &text) else {
            continue;
        };
        let u = utilization(&m);
        let t = Instant::now();
        let verdict = match lut_gen::synthesize(&m) {
            Ok(_) => "scheduled",
            Err(e) => e.verdict.as_str(),
        };
        let ms = (t.elapsed().as_secs_f64() * 1e3).max(1e-3);
        table.push(vec![
            seed.to_string(),
            m.channels.len().to_string(),
            format!("{u:.4}"),
            verdict.to_string(),
            format!("{ms:.4}"),
        ]);
        match verdict {
            "scheduled" => &mut ok,
            "infeasible" => &mut no,
            _ => &mut unknown,
        }
        .push((u * 100.0, ms));
    }
    let best = ok.iter().map(|p| p.0).fold(0.0f64, f64::max);
    let worst = no.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let t = Instant::now();
    let _ = lut_gen::synthesize(mix);
    let own = (t.elapsed().as_secs_f64() * 1e3).max(1e-3);
    let undecided = if unknown.is_empty() {
        String::new()
    } else {
        format!(
            "; {} undecided (the search's bound hit, no proof either way)",
            unknown.len()
        )
    };
    let line = format!(
        "{} of {} random mixes around this one have an exact schedule, up to {best:.0} % ADC utilization{}{undecided}; this mix: {:.0} %",
        ok.len(),
        ok.len() + no.len() + unknown.len(),
        if worst.is_finite() { format!(", the least loaded proved without one at {worst:.0} %") } else { String::new() },
        u0 * 100.0
    );
    let mut me = Series::scatter(
        &format!("this mix ({:.0} %)", u0 * 100.0),
        vec![(u0 * 100.0, own)],
    )
    .with_marker(Marker::Square);
    me.labels = vec![(u0 * 100.0, own, mix.name.clone())];
    let mut series = vec![
        Series::scatter(&format!("exact schedule ({})", ok.len()), ok).with_marker(Marker::Circle),
        Series::scatter(&format!("none exists ({})", no.len()), no).with_marker(Marker::Cross),
    ];
    if !unknown.is_empty() {
        let n = unknown.len();
        series.push(
            Series::scatter(&format!("undecided ({n})"), unknown).with_marker(Marker::Triangle),
        );
    }
    series.push(me);
    let mut axes = Axes::new(
        "Where scheduling breaks around this mix",
        "ADC utilization (% of the converters' throughput)",
        "synthesis time (ms, log)",
    );
    axes.log_y = true;
    // infeasible mixes sit on the right: keep the legend off them
    axes.legend_left = true;
    axes.vlines = vec![(100.0, "100 %".into())];
    let rates: Vec<String> = shape.rates_hz.iter().map(|r| format!("{r} Hz")).collect();
    (
        Section {
            title: "Where scheduling breaks".into(),
            paragraphs: vec![
                format!("{MIXES} random mixes around this one: its clock ({} Hz), frame ({} us) and slice ({} us), its {} branches (AD7940) and its rates ({}), with 1 to {max} channels. Dots: an exact schedule exists; crosses: none does (synthesis proves it); triangles, if any: undecided (the exact search hit its bound); the square is this mix.", mix.clock_hz, mix.frame_us, mix.slice_us, mix.branches.len(), rates.join(", ")),
                format!("{line}."),
            ],
            figures: vec![Figure {
                stem: "schedulability".into(),
                title: "Where scheduling breaks".into(),
                caption: "each marker a random mix around this one; x: demand over the converters' throughput; y: time to synthesize (or to prove there is no exact schedule)".into(),
                svg: draw(&axes, &series, 900, 460),
                table,
            }],
            ..Section::default()
        },
        line,
    )
}
