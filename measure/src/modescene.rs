//! A mix with modes over a scene: the run with its switches beside the same
//! scene on the mix with one mode (every channel at its top mode's rate),
//! as `build` charts it: the data rate frame by frame, the switches, the
//! saving and the reactions, every number measured on the pins of the runs
//! (the audit's worst reaction beside it).

use engines::{Backend, SimOptions};
use judge::Verdict;
use lut_gen::Schedule;
use report::{Axes, Figure, Section, Series, Table};

use crate::reaction::{reactions, Reaction};
use crate::scenelog::{FrameFigures, SceneLog};

/// A scene run on a mix with modes and on its one-mode twin.
pub struct ModeScene {
    /// The check of the run with modes (the co-simulation's verdict).
    pub verdict: Verdict,
    /// Every frame of it, as the pins showed it.
    pub with_modes: Vec<FrameFigures>,
    /// The one-mode mix's run and frames, or why it could not run.
    pub without: Result<(Verdict, Vec<FrameFigures>), String>,
    /// Every switch and the reaction measured to it.
    pub reactions: Vec<Reaction>,
    /// Bytes on the link (a mix with a `[link]`), else samples.
    pub bytes: bool,
}

impl ModeScene {
    /// The quantity charted for one frame: link bytes, or samples.
    pub fn amount(&self, f: &FrameFigures) -> u64 {
        if self.bytes {
            f.bytes
        } else {
            f.samples
        }
    }

    /// The amounts summed over the run, with modes and without.
    pub fn totals(&self) -> (u64, Option<u64>) {
        let with = self.with_modes.iter().map(|f| self.amount(f)).sum();
        let without = self
            .without
            .as_ref()
            .ok()
            .map(|(_, v)| v.iter().map(|f| self.amount(f)).sum());
        (with, without)
    }

    /// What the modes saved, in % of the one-mode run's amount.
    pub fn saving_pct(&self) -> Option<f64> {
        match self.totals() {
            (with, Some(without)) if without > 0 => {
                Some(100.0 * (1.0 - with as f64 / without as f64))
            }
            _ => None,
        }
    }

    /// The reaction measured longest.
    pub fn worst(&self) -> Option<&Reaction> {
        self.reactions.iter().max_by_key(|r| r.measured())
    }

    /// What went wrong: a run that failed its check, a reaction slower than
    /// the audit's worst case (empty: nothing).
    pub fn problems(&self, s: &Schedule) -> Vec<String> {
        let mut p = Vec::new();
        if !self.verdict.ok {
            p.push(format!(
                "the run with modes: {}",
                self.verdict.summary().trim()
            ));
        }
        match &self.without {
            Ok((v, _)) if !v.ok => p.push(format!("the run with one mode: {}", v.summary().trim())),
            _ => {}
        }
        for r in self.reactions.iter().filter(|r| r.measured() > r.predicted) {
            p.push(format!(
                "the switch at frame {} took {:.3} ms, longer than the audit's worst {:.3} ms",
                r.frame,
                ms(s, r.measured()),
                ms(s, r.predicted)
            ));
        }
        p
    }
}

/// The mix with one mode: every channel at the highest of its rates, no
/// `[[mode]]`, the same link: what the array would send without switching.
pub fn one_mode(s: &Schedule) -> Result<Schedule, String> {
    let mut mix = s.mix.clone();
    for c in &mut mix.channels {
        c.rate_hz = c
            .rates
            .iter()
            .copied()
            .chain([c.rate_hz])
            .max()
            .unwrap_or(0);
        c.rates.clear();
    }
    mix.modes = None;
    let flat = lut_gen::synthesize(&mix).map_err(|e| e.to_string())?;
    if let Some(Err(e)) = lut_gen::plan_link(&flat) {
        return Err(format!("its link cannot carry it: {}", e.detail));
    }
    Ok(flat)
}

/// Runs `frames` frames of `s` on `backend` under `opts` (its stimulus the
/// scene, its `modes` the pin's requests), checked, and the same scene on
/// [`one_mode`] of it (no waveform, no requests).
pub fn mode_scene(
    s: &Schedule,
    backend: Backend,
    frames: u64,
    opts: &SimOptions,
) -> Result<ModeScene, String> {
    let mut log = SceneLog::new(s);
    let verdict = engines::run_observed(s, backend, frames, opts, Some(&mut log))
        .map_err(|e| e.to_string())?;
    log.frames.truncate(frames as usize);
    let without = one_mode(s).and_then(|flat| {
        let o = SimOptions {
            vcd: None,
            modes: Vec::new(),
            ..opts.clone()
        };
        let mut l = SceneLog::new(&flat);
        let v = engines::run_observed(&flat, backend, frames, &o, Some(&mut l))
            .map_err(|e| format!("the one-mode mix: {e}"))?;
        l.frames.truncate(frames as usize);
        Ok((v, l.frames))
    });
    Ok(ModeScene {
        verdict,
        reactions: reactions(s, &log),
        with_modes: log.frames,
        without,
        bytes: s.mix.link.is_some(),
    })
}

/// Milliseconds of `cycles` at the mix's clock.
fn ms(s: &Schedule, cycles: u64) -> f64 {
    cycles as f64 * 1e3 / s.grid.clock_hz as f64
}

/// The chart's table: one row per frame, both runs.
fn table(s: &Schedule, m: &ModeScene) -> Table {
    let unit = if m.bytes { "bytes" } else { "samples" };
    let mut t = Table::new(&[
        "frame",
        "start_ms",
        "mode",
        &format!("{unit}_with_modes"),
        &format!("{unit}_without_modes"),
        &format!("{unit}_per_s_with_modes"),
        &format!("{unit}_per_s_without_modes"),
    ]);
    let names = s
        .mix
        .modes
        .as_ref()
        .map(|x| x.names.clone())
        .unwrap_or_default();
    let per_s = s.grid.clock_hz as f64 / s.grid.frame_cycles as f64;
    let flat = m.without.as_ref().ok().map(|(_, v)| v);
    for f in &m.with_modes {
        let other = flat
            .and_then(|v| v.get(f.frame as usize))
            .map(|g| m.amount(g));
        t.push(vec![
            f.frame.to_string(),
            format!("{:.3}", ms(s, f.frame * s.grid.frame_cycles)),
            names
                .get(f.mode as usize)
                .cloned()
                .unwrap_or_else(|| f.mode.to_string()),
            m.amount(f).to_string(),
            other.map_or(String::new(), |x| x.to_string()),
            format!("{:.0}", m.amount(f) as f64 * per_s),
            other.map_or(String::new(), |x| format!("{:.0}", x as f64 * per_s)),
        ]);
    }
    t
}

/// The chart: the rate per frame with modes and without (a step line each),
/// the switches marked.
fn chart(s: &Schedule, m: &ModeScene, t: &Table) -> Figure {
    let unit = if m.bytes {
        "kB/s on the link"
    } else {
        "k samples/s"
    };
    let g = &s.grid;
    let end = ms(s, m.with_modes.len() as u64 * g.frame_cycles);
    let series_of = |col: usize| {
        let mut p: Vec<(f64, f64)> = t
            .rows
            .iter()
            .filter_map(|r| Some((r[1].parse().ok()?, r[col].parse::<f64>().ok()? / 1e3)))
            .collect();
        if let Some(&(_, y)) = p.last() {
            p.push((end, y));
        }
        let mut x = Series::line("", p);
        x.steps = true;
        x
    };
    let mut with = series_of(5);
    with.name = "with modes".into();
    let mut without = series_of(6);
    without.name = "without (every channel at its top rate)".into();
    let names = s
        .mix
        .modes
        .as_ref()
        .map(|x| x.names.clone())
        .unwrap_or_default();
    let mut axes = Axes::new("Data rate over the scene", "time (ms)", unit);
    // each switch: a line, and the new mode named at the corner of the step
    // (labels at the top would run into the legend)
    for r in &m.reactions {
        let x = ms(s, r.frame * g.frame_cycles);
        axes.vlines.push((x, String::new()));
        if let Some(p) = with.points.iter().find(|p| p.0 >= x) {
            with.labels.push((p.0, p.1, format!("to {}", names[r.to])));
        }
    }
    let top = with
        .points
        .iter()
        .chain(&without.points)
        .map(|p| p.1)
        .fold(0.0, f64::max);
    axes.y_range = Some((0.0, top * 1.25 + 1e-9));
    axes.x_range = Some((0.0, end));
    Figure {
        stem: "modes-rate".into(),
        title: "Data rate with modes and without".into(),
        caption: format!(
            "{} per frame ({} ms) as the runs measured them: with the mix's modes (switches marked) and the same scene on the mix with one mode, every channel at its top mode's rate.",
            if m.bytes { "Bytes the host received" } else { "Samples on the sample port" },
            ms(s, g.frame_cycles)
        ),
        // without a one-mode run (it could not run) the chart has one line
        svg: report::draw(
            &axes,
            &[without, with]
                .into_iter()
                .filter(|x| !x.points.is_empty())
                .collect::<Vec<_>>(),
            820,
            380,
        ),
        table: t.clone(),
    }
}

/// The words for a switch's cause: the trigger by its line in the mix, or the pin.
fn cause_words(s: &Schedule, r: &Reaction) -> String {
    let t = r
        .trigger
        .and_then(|k| s.mix.modes.as_ref()?.triggers.get(k));
    match t {
        Some(t) => format!(
            "[[trigger]] at line {} ({} {}): its first watched sample past the level",
            t.line,
            match t.when {
                lut_gen::When::Above => "above",
                lut_gen::When::Below => "below",
            },
            t.level
        ),
        None => "`mode_sel`: the first cycle of the request".into(),
    }
}

/// What the run carried with modes and without, in words.
fn saving_words(m: &ModeScene) -> String {
    let unit = if m.bytes { "link bytes" } else { "samples" };
    let (with, without) = m.totals();
    match (m.saving_pct(), &m.without) {
        (Some(p), _) => format!(
            "{with} {unit} with modes against {} with one mode: {p:.1} % less",
            without.unwrap_or(0)
        ),
        (None, Err(e)) => {
            format!("{with} {unit} with modes; the mix with one mode could not run ({e})")
        }
        (None, Ok(_)) => format!("{with} {unit} with modes, none with one mode"),
    }
}

/// Each reaction, measured and the audit's worst, in words.
fn reaction_words(s: &Schedule, m: &ModeScene) -> String {
    let names = s
        .mix
        .modes
        .as_ref()
        .map(|x| x.names.clone())
        .unwrap_or_default();
    if m.reactions.is_empty() {
        return "no switch in the scene".into();
    }
    let each: Vec<String> = m
        .reactions
        .iter()
        .map(|r| {
            format!(
                "to `{}` at frame {} in {:.2} ms (the audit's worst {:.2} ms)",
                names[r.to],
                r.frame,
                ms(s, r.measured()),
                ms(s, r.predicted)
            )
        })
        .collect();
    format!("switched {}", each.join(", "))
}

/// The report's section about the scene (`scene`: the stimulus as the
/// command line writes it), its one-line summary and the first screen's
/// answer.
pub fn mode_section(
    s: &Schedule,
    m: &ModeScene,
    scene: &str,
    backend: &str,
) -> (Section, String, String) {
    let t = table(s, m);
    let fig = chart(s, m, &t);
    let names = s
        .mix
        .modes
        .as_ref()
        .map(|x| x.names.clone())
        .unwrap_or_default();
    let saving = saving_words(m);
    let reacted_words = reaction_words(s, m);
    let worst = m.worst().map_or(String::new(), |r| {
        format!(
            "; worst reaction {:.2} ms (audit's worst {:.2} ms)",
            ms(s, r.measured()),
            ms(s, r.predicted)
        )
    });
    let line = format!(
        "{backend}: {} frames of `{scene}`, {}; {saving}{worst}",
        m.with_modes.len(),
        match m.reactions.len() {
            1 => "1 switch".to_string(),
            n => format!("{n} switches"),
        }
    );
    let glance = format!("{saving} over the scene `{scene}`; {reacted_words}");
    let mut reacted = Table::new(&[
        "switch",
        "cause",
        "cause at (ms)",
        "first sample at the new rates (ms)",
        "reaction measured (ms)",
        "audit's worst (ms)",
    ]);
    for r in &m.reactions {
        reacted.push(vec![
            format!(
                "`{}` to `{}` at frame {}",
                names[r.from], names[r.to], r.frame
            ),
            cause_words(s, r),
            format!("{:.3}", ms(s, r.cause)),
            format!("{:.3}", ms(s, r.first)),
            format!("{:.3}", ms(s, r.measured())),
            format!("{:.3}", ms(s, r.predicted)),
        ]);
    }
    let sec = Section {
        title: "Modes over a scene".into(),
        paragraphs: vec![format!(
            "The scene `{scene}` on {backend} for {} frames, checked cycle by cycle, and the same scene on the mix with one mode (every channel at its top mode's rate), measured on the pins: {saving}; {reacted_words}. A reaction runs from its cause to the first sampling instant at the new rates; the audit's worst is the longest over every instant the cause could fall on.",
            m.with_modes.len()
        )],
        tables: vec![("Switches and reactions, measured".into(), reacted)],
        figures: vec![fig],
        ..Section::default()
    };
    (sec, line, glance)
}
