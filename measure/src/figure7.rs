//! The paper's Figure 7 for the mix's own rates, from simulation: for each
//! rate the mix has, a tone above that rate's Nyquist frequency on a
//! channel of that rate (its samples as markers on the continuous signal,
//! and their spectrum with the apparent frequency marked), and for the
//! slowest rate a slow tone whose samples keep its shape, compared with the
//! same channel's own signal.

use judge::Analog;
use judge::SlotModel;
use judge::Stimulus;
use lut_gen::Schedule;
use report::{draw, Axes, Figure, Marker, Section, Series, Table};

use crate::dft;

/// Samples per aliasing run and per channel: enough for the DFT to resolve
/// the alias at 1/128 of the sample rate.
const TONE_SAMPLES: f64 = 128.0;
/// Where the tone sits: 1.2 x the Nyquist frequency (0.6 x the rate), so it
/// appears at 0.4 x the rate.
const TONE: f64 = 0.6;

/// One channel's samples: `(sampling instant in s, code)`.
struct Trace {
    channel: usize,
    points: Vec<(f64, f64)>,
}

/// The samples `channel` takes of a sine of `hz` on every input over
/// `frames` frames, at their sampling instants: the slot-level model's
/// conversions (whose every instant the co-simulation step checks against
/// the gateware, cycle by cycle) and the ADC model's codes.
fn run(s: &Schedule, hz: f64, frames: u64, channel: usize) -> Trace {
    let a = Analog::new(s, Stimulus::Sine(Some(hz)));
    let bits = s.mix.branches[s.mix.channels[channel].branch].adc.bits;
    let clock = s.grid.clock_hz as f64;
    let points = SlotModel::new(s)
        .iter(frames)
        .filter(|c| c.channel as usize == channel)
        .map(|c| {
            (
                c.instant as f64 / clock,
                a.code_bits(channel as u64, c.instant, bits) as f64,
            )
        })
        .collect();
    Trace { channel, points }
}

fn frames_for(s: &Schedule, seconds: f64) -> u64 {
    let f = s.grid.frame_cycles as f64 / s.grid.clock_hz as f64;
    (seconds / f).ceil() as u64 + 1
}

/// The continuous signal of `channel` (the ADC model's code) from `t0` to
/// `t1`, 400 points.
fn continuous(s: &Schedule, a: &Analog, channel: usize, t0: f64, t1: f64) -> Vec<(f64, f64)> {
    let clock = s.grid.clock_hz as f64;
    let bits = s.mix.branches[s.mix.channels[channel].branch].adc.bits;
    (0..=400)
        .map(|k| {
            let t = t0 + (t1 - t0) * k as f64 / 400.0;
            (
                t,
                a.code_bits(channel as u64, (t * clock) as u64, bits) as f64,
            )
        })
        .collect()
}

fn ms(v: &[(f64, f64)]) -> Vec<(f64, f64)> {
    v.iter().map(|p| (p.0 * 1e3, p.1)).collect()
}

/// The mix's rates, fastest first, each with the schedule that samples it
/// (a mix with modes: every mode's rates, each in the first mode that has
/// it) and its first channel there.
fn rates(s: &Schedule) -> Vec<(u64, &Schedule, usize)> {
    let scheds: Vec<&Schedule> = if s.modes.len() > 1 {
        s.modes.iter().collect()
    } else {
        vec![s]
    };
    let mut v: Vec<(u64, &Schedule, usize)> = Vec::new();
    for ms in scheds {
        for (i, c) in ms.mix.channels.iter().enumerate() {
            if c.rate_hz > 0 && !v.iter().any(|r| r.0 == c.rate_hz) {
                v.push((c.rate_hz, ms, i));
            }
        }
    }
    v.sort_by_key(|r| std::cmp::Reverse(r.0));
    v
}

/// Figure 7 of this mix: the section and a one-line summary.
pub fn figure7(s: &Schedule) -> Result<(Section, String), String> {
    let mut figures = Vec::new();
    let mut lines = Vec::new();
    for (rate, ms, ch) in rates(s) {
        let (fig_t, fig_s, line) = aliasing(ms, rate as f64, ch)?;
        figures.push(fig_t);
        figures.push(fig_s);
        lines.push(line);
    }
    let (slow_fig, slow_line) = slow(s)?;
    figures.push(slow_fig);
    let line = format!("{}; {slow_line}", lines.join("; "));
    Ok((
        Section {
            title: "Figure 7: sampling rate against what a channel sees".into(),
            paragraphs: vec![
                format!("The paper's Figure 7 for this mix's own rates{}: the sampling instants of this schedule (the slot-level model's, which the co-simulation checks against the gateware cycle by cycle) and the ADC model's codes of a sine on every input. For each rate a tone at {:.1} x its Nyquist frequency is sampled by a channel of that rate: the samples (markers) follow a slower sine, and the spectrum of the samples peaks at the folded frequency |f - rate|, not at f.", modal_words(s), 2.0 * TONE),
                "The last panel is the other half of the figure: a slow signal on the mix's slowest channel keeps its shape, shown against that channel's own input signal (not another channel's).".into(),
                format!("{line}."),
            ],
            figures,
            ..Section::default()
        },
        line,
    ))
}

/// What "this mix's rates" are in a mix with modes.
fn modal_words(s: &Schedule) -> &'static str {
    if s.modes.len() > 1 {
        " in every mode (each rate on the schedule of the first mode that samples at it)"
    } else {
        ""
    }
}

/// The time and spectrum panels of a tone above `rate`'s Nyquist frequency.
fn aliasing(s: &Schedule, rate: f64, ch: usize) -> Result<(Figure, Figure, String), String> {
    let f = TONE * rate;
    let want = dft::alias(f, rate);
    let tr = run(s, f, frames_for(s, TONE_SAMPLES / rate), ch);
    let name = &s.mix.channels[tr.channel].name;
    // the DFT over every sample; the time panel over 12 sample periods
    let spec = dft::spectrum(&tr.points, rate, 241);
    let (seen, _) = dft::peak(&spec).ok_or("too few samples for a spectrum")?;
    where_aliasing_puts_it(f, rate, seen, want)?;
    let shown: Vec<(f64, f64)> = tr.points.iter().copied().skip(2).take(13).collect();
    let (_, cont) = input_over(s, f, ch, &shown);
    let stem = format!("figure7-{}hz", rate as u64);
    let table = tone_table(["time_s", "code"], name, rate, f, &tr.points, |p| {
        [format!("{:.9}", p.0), format!("{}", p.1)]
    });
    let mut samples = Series::scatter(&format!("{name}'s samples at {rate} Hz"), ms(&shown))
        .with_marker(Marker::Circle);
    samples.labels = Vec::new();
    let time = Figure {
        stem: format!("{stem}-time"),
        title: format!("A {f} Hz tone sampled at {rate} Hz"),
        caption: format!("the continuous {f} Hz input of {name} (blue) and its samples (dots, joined in red): they trace a {want} Hz sine"),
        svg: draw(
            &legend_room(
                Axes::new(&format!("{f} Hz on {name}, sampled at {rate} Hz"), "time (ms)", "ADC code"),
                cont.iter().chain(&shown),
            ),
            &[
                Series::line(&format!("{f} Hz input"), ms(&cont)),
                Series::line(&format!("samples joined: {want} Hz"), ms(&shown)),
                samples,
            ],
            900,
            340,
        ),
        table,
    };
    let st = tone_table(
        ["frequency_hz", "magnitude_codes"],
        name,
        rate,
        f,
        &spec,
        |p| [format!("{:.3}", p.0), format!("{:.3}", p.1)],
    );
    let mut ax = Axes::new(
        &format!(
            "Spectrum of {} samples of {name} at {rate} Hz",
            tr.points.len()
        ),
        "frequency (Hz, up to the Nyquist frequency)",
        "magnitude (codes)",
    );
    ax.vlines = vec![(seen, format!("apparent {seen:.0} Hz"))];
    let spectrum = Figure {
        stem: format!("{stem}-spectrum"),
        title: format!("Spectrum at {rate} Hz"),
        caption: format!("DFT of the samples: the peak (marked) is at {seen:.0} Hz, the {f} Hz tone folded about {} Hz (expected {want} Hz)", rate / 2.0),
        svg: draw(&ax, &[Series::line("DFT of the samples", spec.clone())], 900, 300),
        table: st,
    };
    let line = format!("{f} Hz at {rate} Hz appears at {seen:.0} Hz");
    Ok((time, spectrum, line))
}

/// The CSV of a panel of the `f` Hz tone on `name` at `rate`: one row per
/// point, its two values in `columns` as `cell` writes them.
fn tone_table(
    columns: [&str; 2],
    name: &str,
    rate: f64,
    f: f64,
    points: &[(f64, f64)],
    cell: impl Fn((f64, f64)) -> [String; 2],
) -> Table {
    let mut t = Table::new(&["channel", "rate_hz", "tone_hz", columns[0], columns[1]]);
    for &p in points {
        let [x, y] = cell(p);
        t.push(vec![
            name.to_string(),
            format!("{rate}"),
            format!("{f}"),
            x,
            y,
        ]);
    }
    t
}

/// Channel `ch`'s input, an `f` Hz sine, over the span of the samples `pts`:
/// the model that makes it and the continuous curve.
fn input_over(s: &Schedule, f: f64, ch: usize, pts: &[(f64, f64)]) -> (Analog, Vec<(f64, f64)>) {
    let (t0, t1) = (
        pts.first().map_or(0.0, |p| p.0),
        pts.last().map_or(0.0, |p| p.0),
    );
    let analog = Analog::new(s, Stimulus::Sine(Some(f)));
    let cont = continuous(s, &analog, ch, t0, t1);
    (analog, cont)
}

/// The step fails when the measured apparent frequency `seen` of an `f` Hz
/// tone sampled at `rate` is not where aliasing puts it (`want`), within
/// two bins of the 241-point spectrum up to the Nyquist frequency.
/// The y range of `points` with room above for the legend (three rows in
/// the upper right of a 340-pixel chart), so it hides no part of a trace.
fn legend_room<'a>(mut axes: Axes, points: impl Iterator<Item = &'a (f64, f64)>) -> Axes {
    let (lo, hi) = points.fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.1), a.1.max(p.1)));
    if lo < hi {
        let span = hi - lo;
        axes.y_range = Some((lo - 0.04 * span, hi + 0.5 * span));
    }
    axes
}

pub fn where_aliasing_puts_it(f: f64, rate: f64, seen: f64, want: f64) -> Result<(), String> {
    let tol = rate / 240.0;
    if (seen - want).abs() <= tol {
        Ok(())
    } else {
        Err(format!(
            "Figure 7: the {f} Hz tone sampled at {rate} Hz appears at {seen:.0} Hz; aliasing puts it at {want:.0} Hz (tolerance {tol:.1} Hz)"
        ))
    }
}

/// A slow tone (a tenth of the slowest rate) on the slowest channel against
/// that channel's own input.
fn slow(s: &Schedule) -> Result<(Figure, String), String> {
    let all = rates(s);
    let (&(rate, s, ch), fastest) = (all.last().ok_or("no channels")?, all[0].0);
    let rate = rate as f64;
    let f = rate / 10.0;
    let tr = run(s, f, frames_for(s, 2.0 / f), ch);
    let name = &s.mix.channels[ch].name;
    let pts: Vec<(f64, f64)> = tr.points.iter().copied().skip(1).take(21).collect();
    let (analog, cont) = input_over(s, f, ch, &pts);
    // the samples, linearly interpolated, against the input itself
    let interp = |t: f64| -> Option<f64> {
        let i = pts.iter().position(|p| p.0 >= t)?;
        if i == 0 {
            return (pts[0].0 == t).then_some(pts[0].1);
        }
        let (a, b) = (pts[i - 1], pts[i]);
        Some(a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0))
    };
    let amp = cont
        .iter()
        .fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.1), a.1.max(p.1)));
    let amp = ((amp.1 - amp.0) / 2.0).max(1.0);
    let errs: Vec<f64> = cont
        .iter()
        .filter_map(|p| Some((interp(p.0)? - p.1) / amp))
        .collect();
    let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len().max(1) as f64).sqrt();
    let mut table = Table::new(&[
        "channel",
        "rate_hz",
        "tone_hz",
        "time_s",
        "code",
        "input_code",
    ]);
    for p in &pts {
        let c = analog.code_bits(
            ch as u64,
            (p.0 * s.grid.clock_hz as f64).round() as u64,
            s.mix.branches[s.mix.channels[ch].branch].adc.bits,
        );
        table.push(vec![
            name.clone(),
            format!("{rate}"),
            format!("{f}"),
            format!("{:.9}", p.0),
            format!("{}", p.1),
            c.to_string(),
        ]);
    }
    let share = rate / fastest as f64;
    let line = format!(
        "a {f} Hz signal on {name} at {rate} Hz keeps its shape (samples interpolated differ from its input by {:.1} % rms of the amplitude) with {} % of the data of the {fastest} Hz rate",
        rms * 100.0,
        // 100 Hz of 4000 Hz is 2.5 %, not "2 %"
        format!("{:.1}", share * 100.0).trim_end_matches(".0")
    );
    let fig = Figure {
        stem: "figure7-slow".into(),
        title: format!("A slow signal at {rate} Hz"),
        caption: format!(
            "{name}'s own {f} Hz input (line) and its {} samples (dots), joined: {line}",
            pts.len()
        ),
        svg: draw(
            &legend_room(
                Axes::new(
                    &format!("{f} Hz on {name}, sampled at {rate} Hz"),
                    "time (ms)",
                    "ADC code",
                ),
                cont.iter().chain(&pts),
            ),
            &[
                Series::line(&format!("{name}'s input"), ms(&cont)),
                Series::line(&format!("{name}'s samples, joined"), ms(&pts)),
                Series::scatter(&format!("{name}'s samples"), ms(&pts)).with_marker(Marker::Square),
            ],
            900,
            340,
        ),
        table,
    };
    Ok((fig, line))
}
