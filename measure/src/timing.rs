//! The timing diagram of a steady-state slice (frame 1, the slice with the
//! most conversions: not the start-up slice, where a slow branch may be
//! empty) from simulation, per branch `mux_en`, `mux_sel` named by the
//! channel it selects, CS and SCLK, the sample strobe named by channel, and
//! the slot boundaries; and WaveDrom JSON of one conversion with its
//! `sample_valid` strobe.

use engines::{Backend, SimOptions};
use judge::CycleSink;
use judge::Observer;
use lut_gen::Schedule;
use lut_gen::{Layout, Pins, Role};
use report::{draw, Axes, Figure, Section, Series, Table};

/// Keeps the pins of cycles `[from, to)` after cycle 0 only.
struct Window {
    from: u64,
    to: u64,
    seen: u64,
    zero: Option<u64>,
    cycles: Vec<(Pins, u64)>,
}

impl Window {
    fn push(&mut self, rst: bool, pins: &Pins, miso: u64) {
        if !rst && self.zero.is_none() {
            self.zero = Some(self.seen);
        }
        if let Some(z) = self.zero {
            let c = self.seen - z;
            if (self.from..self.to).contains(&c) {
                self.cycles.push((*pins, miso));
            }
        }
        self.seen += 1;
    }
}

impl Observer for Window {
    fn cycle(&mut self, _cycle: u64, rst: bool, pins: &Pins, miso: u64) {
        self.push(rst, pins, miso);
    }
}

impl CycleSink for Window {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, _xz: &Pins, miso: u64, _miso_xz: u64) {
        self.push(rst.unwrap_or(true), pins, miso);
    }
}

/// The slice of frame 1 (of 0-based slices) with the most conversions.
pub fn busiest_slice(s: &Schedule) -> u64 {
    let g = &s.grid;
    let nb = s.branches.len();
    (0..g.slices_per_frame)
        .map(|j| {
            let n = (0..g.slots_per_slice)
                .flat_map(|k| (0..nb).map(move |b| (j * g.slots_per_slice + k, b)))
                .filter(|&(slot, b)| s.at(slot, b).is_some())
                .count();
            (j, n)
        })
        .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)))
        .map_or(0, |x| x.0)
}

/// A trace's full-scale height in rows: the rest of the row holds the
/// channel names, clear of the row above.
const HIGH: f64 = 0.55;

/// Lines the strobe names take: one among the strobes' ticks (for a name
/// that fits before the next tick) and three below the trace, as merged
/// names of several branches are wider than two slots, and a name wider
/// than a slot (eskin34's) never fits among the ticks.
const STROBE_LINES: usize = 4;

/// Strobe labels closer than this share of the window are one label, so
/// that back-to-back strobes of two branches do not print over each other.
const STROBE_MERGE: f64 = 0.03;

/// Lines of strobe labels sit this far (in rows) apart: a 12-pixel text on
/// rows of about 37 pixels.
const STAGGER: f64 = 0.36;

/// The height of a label's text in rows (with a little room), for a line
/// that must clear a trace.
const TEXT_ROWS: f64 = 0.40;

/// The y of strobe label line `k`: the first beside the strobes, above the
/// row's low level; the others below that level, clear of the trace.
fn strobe_line_y(k: usize) -> f64 {
    if k == 0 {
        0.05 - HIGH / 2.0
    } else {
        -HIGH / 2.0 - TEXT_ROWS - STAGGER * (k - 1) as f64
    }
}

/// Where a select's second line of names sits, below its own trace's low
/// level and above the high level of the row below (in rows from the row).
const SELECT_LOW: f64 = -0.69;

/// The width of a label in the plot's x units: about 7.5 pixels a character
/// of the 12-pixel sans-serif (capitals and `_` are wide), plus its 6-pixel
/// offset, on the plot's ~860 pixels across `span`.
pub fn label_width(t: &str, span: f64) -> f64 {
    (t.len() as f64 * 7.5 + 10.0) / 860.0 * span
}

/// Places labels along a row, left to right: each pulled left so that it
/// ends inside the window (`x0 + span`), and on the first of `lines` lines
/// whose last label ends left of it, else the one whose last label ends
/// first; so names a slot apart (30 in eskin34's slice) do not print over
/// each other, nor past the plot's right edge.  Line 0 sits among
/// vertical `ticks` (the strobes): a label goes there only if no tick lies
/// under its text, which starts 6 pixels right of its strobe (so the ticks
/// of strobes a few cycles apart that share one label do not count).
pub fn stagger(
    labels: &[(f64, String)],
    ticks: &[f64],
    x0: f64,
    span: f64,
    lines: usize,
) -> Vec<(f64, usize)> {
    let mut ends = vec![f64::MIN; lines];
    let own = 6.0 / 860.0 * span;
    labels
        .iter()
        .map(|(x, t)| {
            let w = label_width(t, span);
            let x = x.min(x0 + span - w);
            let crosses = ticks.iter().any(|&k| k > x + own && k < x + w);
            let free = |k: &usize| !(*k == 0 && crosses);
            let line = (0..lines)
                .filter(free)
                .find(|&k| ends[k] <= x)
                .unwrap_or_else(|| {
                    (0..lines)
                        .filter(free)
                        .min_by(|&a, &b| ends[a].total_cmp(&ends[b]))
                        .unwrap_or(lines - 1)
                });
            ends[line] = x + w;
            (x, line)
        })
        .collect()
}

/// A diagram row: its name, `(cycle, value)` at each change, full scale.
type Row = (String, Vec<(u64, u64)>, f64);

fn lane(l: &Layout, p: &Pins, r: Role, b: usize) -> u64 {
    let (hi, lo) = l.lane_bits(r, b);
    ((p.value(r) >> lo) as u64) & ((1u64 << (hi - lo + 1)) - 1)
}

/// The window drawn: frame 1's slice `j`, cycles `[from, to)` after cycle 0.
struct View<'a> {
    s: &'a Schedule,
    j: u64,
    from: u64,
    to: u64,
}

impl View<'_> {
    fn new(s: &Schedule) -> View<'_> {
        let g = &s.grid;
        let slice_cycles = g.slots_per_slice * g.slot_cycles;
        let j = busiest_slice(s);
        let from = g.frame_cycles + j * slice_cycles;
        // one slot more: the last conversion's word leaves after its slot
        let to = from + slice_cycles + g.slot_cycles;
        View { s, j, from, to }
    }

    /// Microseconds after cycle 0.
    fn us(&self, c: u64) -> f64 {
        c as f64 * 1e6 / self.s.grid.clock_hz as f64
    }

    fn channel(&self, c: usize) -> String {
        self.s.mix.channels[c].name.clone()
    }

    /// Where a label's x must end: the window's start and width in us.
    fn span(&self) -> (f64, f64) {
        (self.us(self.from), self.us(self.to) - self.us(self.from))
    }
}

/// The section, the WaveDrom JSON, and a one-line summary.
pub fn timing(s: &Schedule, backend: Backend) -> Result<(Section, String, String), String> {
    let g = &s.grid;
    let view = View::new(s);
    let (j, from) = (view.j, view.from);
    let w = simulate(s, backend, &view)?;
    let l = Layout::new(s);
    let rows = signal_rows(s, &l, &w, from);
    let (table, mut series, names) = traces(&view, &rows);
    let mut labels = Series::line("", vec![]);
    select_labels(&view, &names, &mut labels);
    strobe_labels(&view, &w, &mut labels);
    series.push(labels);
    let axes = slice_axes(&view, backend, names, rows.len());
    let svg = draw(&axes, &series, 1000, 170 + 34 * rows.len() as u32);
    let (wavedrom, wd_line) = wavedrom(s, &l, &w, s.branches.len())?;
    let slice_cycles = g.slots_per_slice * g.slot_cycles;
    let line = format!(
        "slice {j} of frame 1 ({} slots of {} cycles), {} conversions; {wd_line}",
        g.slots_per_slice,
        g.slot_cycles,
        s.instants(3)
            .filter(|i| (from..from + slice_cycles).contains(&i.cycle))
            .count()
    );
    Ok((slice_section(j, svg, table), wavedrom, line))
}

/// Three frames on `backend`, the window's pins kept.
fn simulate(s: &Schedule, backend: Backend, view: &View) -> Result<Window, String> {
    let mut w = Window {
        from: view.from,
        to: view.to,
        seen: 0,
        zero: None,
        cycles: Vec::new(),
    };
    engines::run_observed(s, backend, 3, &SimOptions::default(), Some(&mut w))
        .map_err(|e| e.to_string())?;
    if w.cycles.is_empty() {
        return Err("the run gave no cycles in the window".into());
    }
    Ok(w)
}

/// The diagram's rows, bottom up: the strobe, then per branch (last first)
/// SCLK, CS, select and enable.
fn signal_rows(s: &Schedule, l: &Layout, w: &Window, from: u64) -> Vec<Row> {
    let changes = |f: &dyn Fn(&Pins) -> u64| -> Vec<(u64, u64)> {
        let mut v: Vec<(u64, u64)> = Vec::new();
        for (k, (p, _)) in w.cycles.iter().enumerate() {
            let x = f(p);
            if v.last().map(|e| e.1) != Some(x) {
                v.push((from + k as u64, x));
            }
        }
        v
    };
    let mut rows: Vec<Row> = vec![(
        Role::SampleValid.name().into(),
        changes(&|p| p.sample_valid as u64),
        1.0,
    )];
    for (b, br) in s.branches.iter().enumerate().rev() {
        let mut lanes = vec![
            (format!("{} sclk", br.name), Role::Sclk, 1.0),
            (
                format!("{} {}", br.name, l.lane_key(Role::CsN, b)),
                Role::CsN,
                1.0,
            ),
        ];
        if l.muxed[b] {
            // one-hot: the highest device's bit is the tallest step
            let (hi, lo) = l.lane_bits(Role::MuxEn, b);
            let en_max = (1u64 << (hi - lo)) as f64;
            lanes.push((format!("{} mux_sel", br.name), Role::MuxSel, 7.0));
            lanes.push((format!("{} mux_en", br.name), Role::MuxEn, en_max));
        }
        for (name, role, scale) in lanes {
            rows.push((name, changes(&|p| lane(l, p, role, b)), scale));
        }
    }
    rows
}

/// Each row's steps (centred on its name: low half a trace below, high
/// above), the table of changes, and the rows' names.
fn traces(view: &View, rows: &[Row]) -> (Table, Vec<Series>, Vec<String>) {
    let mut table = Table::new(&["cycle", "time_us", "signal", "value"]);
    let mut series = Vec::new();
    let mut names = Vec::new();
    for (i, (n, ch, scale)) in rows.iter().enumerate() {
        let base = i as f64 - HIGH / 2.0;
        let mut pts: Vec<(f64, f64)> = ch
            .iter()
            .map(|&(c, v)| (view.us(c), base + HIGH * (v as f64 / scale).min(1.0)))
            .collect();
        pts.push((view.us(view.to), pts.last().map_or(base, |p| p.1)));
        for &(c, v) in ch {
            table.push(vec![
                c.to_string(),
                format!("{:.6}", view.us(c)),
                n.clone(),
                v.to_string(),
            ]);
        }
        let mut sr = Series::line(n, pts);
        sr.steps = true;
        series.push(sr);
        names.push(n.clone());
    }
    (table, series, names)
}

/// Names each select value by the channel it selects, just above its own
/// trace's high level, or below its low level.
fn select_labels(view: &View, names: &[String], labels: &mut Series) {
    let s = view.s;
    let row_of = |label: &str| {
        names
            .iter()
            .position(|n| n == label)
            .map_or(0.0, |i| i as f64)
    };
    let (x0, span) = view.span();
    let l = Layout::new(s);
    for (b, br) in s.branches.iter().enumerate() {
        if !l.muxed[b] {
            continue; // no select row to label
        }
        let r = row_of(&format!("{} mux_sel", br.name));
        let texts: Vec<(f64, String)> = s
            .instants(3)
            // at the conversion's start: the tick, or its hold-off later
            .map(|i| (i.cycle + s.holdoff(b), i))
            .filter(|(t, i)| i.branch == b && (view.from..view.to).contains(t))
            .map(|(t, i)| (view.us(t), view.channel(i.channel)))
            .collect();
        for ((x, line), (_, text)) in stagger(&texts, &[], x0, span, 2).into_iter().zip(texts) {
            let y = [r + HIGH / 2.0 + 0.05, r + SELECT_LOW][line];
            labels.labels.push((x, y, text));
        }
    }
}

/// Names the strobes by channel, low in their row beside the strobe;
/// strobes close together share one label.
fn strobe_labels(view: &View, w: &Window, labels: &mut Series) {
    let (from, to) = (view.from, view.to);
    let merge = ((to - from) as f64 * STROBE_MERGE) as u64;
    let mut strobes: Vec<(u64, Vec<String>)> = Vec::new();
    let mut ticks = Vec::new();
    for (k, (p, _)) in w.cycles.iter().enumerate() {
        if p.sample_valid {
            let (c, n) = (from + k as u64, view.channel(p.sample_channel as usize));
            ticks.push(view.us(c));
            match strobes.last_mut() {
                Some((c0, names)) if c - *c0 <= merge => names.push(n),
                _ => strobes.push((c, vec![n])),
            }
        }
    }
    let texts: Vec<(f64, String)> = strobes
        .into_iter()
        .map(|(c, names)| (view.us(c), names.join(",")))
        .collect();
    let (x0, span) = view.span();
    for ((x, level), (_, text)) in stagger(&texts, &ticks, x0, span, STROBE_LINES)
        .into_iter()
        .zip(texts)
    {
        labels.labels.push((x, strobe_line_y(level), text));
    }
}

/// The axes: one named row per signal, the window, the slot boundaries.
fn slice_axes(view: &View, backend: Backend, names: Vec<String>, rows: usize) -> Axes {
    let g = &view.s.grid;
    let (j, from) = (view.j, view.from);
    let mut axes = Axes::new(
        &format!(
            "Slice {j} of frame 1, per branch ({} back end)",
            backend.name()
        ),
        "time after cycle 0 (us); grey lines: slot boundaries",
        "",
    );
    axes.y_names = names;
    axes.x_range = Some((view.us(from), view.us(view.to)));
    // room below the strobe row for its lines of names
    let bottom = strobe_line_y(STROBE_LINES - 1) - 0.06;
    axes.y_range = Some((bottom, rows as f64 - 0.3));
    // the window ends one slot into the next slice (the last word leaves
    // there): that slot is closed by a boundary too, not cut at the edge
    for k in 0..=g.slots_per_slice + 1 {
        let c = from + k * g.slot_cycles;
        let label = if k > g.slots_per_slice {
            String::new()
        } else if g.slots_per_slice <= 16 || k % 4 == 0 {
            format!("{}", j * g.slots_per_slice + k)
        } else {
            String::new()
        };
        axes.vlines.push((view.us(c), label));
    }
    axes
}

fn slice_section(j: u64, svg: String, table: Table) -> Section {
    Section {
        title: "Timing of a slice".into(),
        paragraphs: vec![
            format!("What the paper's Figure 4 shows, drawn from simulation in steady state (frame 1, slice {j}: the slice of the frame with the most conversions). Per branch, from the bottom up: mux_en (the one-hot device enable), mux_sel (labelled with the channel it selects at each sampling instant), CS and SCLK; at the bottom the merged sample_valid strobe, labelled with sample_channel. Grey lines are slot boundaries, numbered by frame slot; the last slot drawn is the first of the next slice, where the slice's last sample leaves."),
            "conversion.wavedrom.json holds one conversion of the first branch in WaveDrom form (one step per SCLK half period; a step shows sample_valid high if the one-cycle strobe falls in it).".into(),
        ],
        figures: vec![Figure {
            stem: "timing-slice".into(),
            title: format!("Slice {j} of frame 1"),
            caption: "steps are the pins' levels, one row per signal; text gives the channel a select value or a strobe stands for".into(),
            svg,
            table,
        }],
        links: vec![("conversion.wavedrom.json".into(), "one conversion for WaveDrom".into())],
        ..Section::default()
    }
}

/// WaveDrom JSON of the first conversion of branch 0 in the window, up to
/// and including its `sample_valid` strobe.
fn wavedrom(s: &Schedule, l: &Layout, w: &Window, _nb: usize) -> Result<(String, String), String> {
    let spi = s.branches[0].spi;
    let cyc = &w.cycles;
    let cs = |p: &Pins| lane(l, p, Role::CsN, 0);
    // The window starts on a slot boundary, where a conversion may start:
    // the first cycle with the pin active that follows an idle one (or the
    // window's first cycle) is a conversion's start.
    let active = u64::from(spi.style.active_level());
    let t0 = (0..cyc.len())
        .find(|&k| cs(&cyc[k].0) == active && (k == 0 || cs(&cyc[k - 1].0) != active))
        .ok_or("the first branch does not convert in the slice")?;
    let step = spi.sclk_half.max(1) as usize;
    let end = t0 + spi.read_cycles as usize;
    // Its word's strobe: the first of branch 0 after the read (another
    // branch's strobe may come first on the merged stream).
    let strobe = cyc[end.min(cyc.len())..]
        .iter()
        .position(|(p, _)| p.sample_valid && s.mix.channels[p.sample_channel as usize].branch == 0)
        .map(|k| end + k);
    let from = t0.saturating_sub(2 * step);
    let to = (strobe.unwrap_or(end) + 3 * step).min(cyc.len());
    // a signal's level per step: its value at the step's first cycle, or
    // for a strobe whether it is high anywhere in the step
    let wave = |f: &dyn Fn(&Pins, u64) -> u64, any: bool| -> String {
        let mut out = String::new();
        let mut prev = None;
        for k in (from..to).step_by(step) {
            let span = &cyc[k..(k + step).min(to)];
            let v = if any {
                span.iter().any(|(p, m)| f(p, *m) != 0) as u64
            } else {
                f(&span[0].0, span[0].1)
            };
            out.push(if prev == Some(v) {
                '.'
            } else if v == 0 {
                '0'
            } else {
                '1'
            });
            prev = Some(v);
        }
        out
    };
    let named = |f: &dyn Fn(&Pins) -> String| -> (String, Vec<String>) {
        let (mut wv, mut data, mut prev) = (String::new(), Vec::new(), None);
        for k in (from..to).step_by(step) {
            let v = f(&cyc[k].0);
            if prev.as_ref() == Some(&v) {
                wv.push('.');
            } else {
                wv.push('=');
                data.push(v.clone());
            }
            prev = Some(v);
        }
        (wv, data)
    };
    let (sel_w, sel_d) = named(&|p| match l.selected(p, 0) {
        Ok(c) => s.mix.channels[c as usize].name.clone(),
        Err(_) => format!("sel {}", l.sel(p, 0)),
    });
    let (ch_w, ch_d) = named(&|p| {
        if p.sample_valid {
            s.mix.channels[p.sample_channel as usize].name.clone()
        } else {
            "-".into()
        }
    });
    let mut signal = vec![
        serde_json::json!({"name": l.lane_key(Role::CsN, 0), "wave": wave(&|p, _| cs(p), false)}),
        serde_json::json!({"name": Role::Sclk.key(), "wave": wave(&|p, _| lane(l, p, Role::Sclk, 0), false)}),
        serde_json::json!({"name": Role::Miso.key(), "wave": wave(&|_, m| m & 1, false)}),
    ];
    if l.muxed[0] {
        signal.push(serde_json::json!({"name": Role::MuxSel.key(), "wave": sel_w, "data": sel_d}));
    }
    signal.extend([
        serde_json::json!({"name": Role::SampleValid.name(), "wave": wave(&|p, _| p.sample_valid as u64, true)}),
        serde_json::json!({"name": Role::SampleChannel.name(), "wave": ch_w, "data": ch_d}),
    ]);
    let wd = serde_json::json!({
        "signal": signal,
        "head": {"text": format!("{}: a conversion of branch {} in steady state (one step = {} clock cycles)", s.mix.name, s.branches[0].name, step)},
        "config": {"hscale": 1},
    });
    let mut text = serde_json::to_string_pretty(&wd).expect("json");
    text.push('\n');
    let line = match strobe {
        Some(k) => format!(
            "WaveDrom: a conversion of branch {} and its sample_valid strobe {} cycles after {}",
            s.branches[0].name,
            k - t0,
            match spi.style {
                lut_gen::Start::Cs => "CS falls",
                lut_gen::Start::Cnv => "CNV rises",
            }
        ),
        None => "WaveDrom: a conversion (its strobe falls outside the window)".into(),
    };
    Ok((text, line))
}
