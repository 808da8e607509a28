//! Charts as SVG text (plotters' SVG back end: no fonts, no files), each
//! drawn from a [`Table`] that is also written as CSV, so every number in a
//! picture can be reused.

use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;

/// A table of numbers (and labels) behind a chart.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new(columns: &[&str]) -> Table {
        Table {
            columns: columns.iter().map(|c| c.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.columns.len());
        self.rows.push(row);
    }

    /// RFC 4180 CSV (fields with commas or quotes are quoted).
    pub fn csv(&self) -> String {
        let field = |f: &str| {
            if f.contains([',', '"', '\n']) {
                format!("\"{}\"", f.replace('"', "\"\""))
            } else {
                f.to_string()
            }
        };
        let mut t = self
            .columns
            .iter()
            .map(|c| field(c))
            .collect::<Vec<_>>()
            .join(",");
        t.push('\n');
        for r in &self.rows {
            t.push_str(&r.iter().map(|c| field(c)).collect::<Vec<_>>().join(","));
            t.push('\n');
        }
        t
    }
}

/// A named set of points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    /// Draw as points (scatter) instead of a line.
    pub points_only: bool,
    /// Draw as a step line (digital waveforms).
    pub steps: bool,
    /// The marker of a scatter: shape as well as colour tells series apart.
    pub marker: Marker,
    /// Text beside points: `(x, y, text)`.
    pub labels: Vec<(f64, f64, String)>,
}

/// A scatter marker's shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Marker {
    #[default]
    Circle,
    Cross,
    Triangle,
    Square,
}

impl Series {
    pub fn line(name: &str, points: Vec<(f64, f64)>) -> Series {
        Series {
            name: name.into(),
            points,
            points_only: false,
            steps: false,
            marker: Marker::Circle,
            labels: Vec::new(),
        }
    }

    pub fn scatter(name: &str, points: Vec<(f64, f64)>) -> Series {
        Series {
            points_only: true,
            ..Series::line(name, points)
        }
    }

    /// The same series with scatter marker `m`.
    pub fn with_marker(mut self, m: Marker) -> Series {
        self.marker = m;
        self
    }
}

/// Axes of a chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Axes {
    pub title: String,
    pub x: String,
    pub y: String,
    pub log_x: bool,
    pub log_y: bool,
    /// Labels at integer y positions (a timing diagram's signal names).
    pub y_names: Vec<String>,
    /// Vertical reference lines, each with a label at its top.
    pub vlines: Vec<(f64, String)>,
    /// The legend in the upper left corner instead of the upper right.
    pub legend_left: bool,
    /// Fixed ranges instead of the data's (every point must lie inside).
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
}

impl Axes {
    pub fn new(title: &str, x: &str, y: &str) -> Axes {
        Axes {
            title: title.into(),
            x: x.into(),
            y: y.into(),
            log_x: false,
            log_y: false,
            y_names: vec![],
            vlines: vec![],
            legend_left: false,
            x_range: None,
            y_range: None,
        }
    }
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

fn range(v: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite() && (!log || *x > 0.0)) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !lo.is_finite() {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        (lo / 1.5, hi * 1.5)
    } else if hi == lo {
        (lo - 1.0, hi + 1.0)
    } else {
        let pad = (hi - lo) * 0.05;
        (lo - pad, hi + pad)
    }
}

/// Draws `series` on `axes` as an SVG document of `w` x `h` pixels.
pub fn draw(axes: &Axes, series: &[Series], w: u32, h: u32) -> String {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        let _ = root.fill(&WHITE);
        let ((x0, x1), (y0, y1)) = ranges(axes, series);
        let mut b = ChartBuilder::on(&root);
        b.caption(&axes.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(if axes.y_names.is_empty() { 60 } else { 110 });
        let p = Plot {
            axes,
            series,
            y0,
            y1,
        };
        // four combinations of linear/log axes; plotters types them apart
        match (axes.log_x, axes.log_y) {
            (false, false) => {
                if let Ok(c) = b.build_cartesian_2d(x0..x1, y0..y1) {
                    p.body(c)
                }
            }
            (true, false) => {
                if let Ok(c) = b.build_cartesian_2d((x0..x1).log_scale(), y0..y1) {
                    p.body(c)
                }
            }
            (false, true) => {
                if let Ok(c) = b.build_cartesian_2d(x0..x1, (y0..y1).log_scale()) {
                    p.body(c)
                }
            }
            (true, true) => {
                if let Ok(c) = b.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale()) {
                    p.body(c)
                }
            }
        }
        let _ = root.present();
    }
    svg
}

/// The axes' fixed ranges, or the data's (x, y).
fn ranges(axes: &Axes, series: &[Series]) -> ((f64, f64), (f64, f64)) {
    let x = axes.x_range.unwrap_or_else(|| {
        range(
            series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0))
                .chain(axes.vlines.iter().map(|v| v.0)),
            axes.log_x,
        )
    });
    let y = axes.y_range.unwrap_or_else(|| {
        range(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
            axes.log_y,
        )
    });
    (x, y)
}

/// A chart's contents, drawn the same on linear and log coordinates.
struct Plot<'a> {
    axes: &'a Axes,
    series: &'a [Series],
    /// The y range, for the vertical lines.
    y0: f64,
    y1: f64,
}

/// A chart on coordinates of either scale, both of `f64`.
type Chart<'a, DB, X, Y> = ChartContext<'a, DB, Cartesian2d<X, Y>>;

impl Plot<'_> {
    fn body<'a, DB: DrawingBackend + 'a, X, Y>(&self, mut chart: Chart<'a, DB, X, Y>)
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        self.mesh(&mut chart);
        for (i, s) in self.series.iter().enumerate() {
            self.series_on(&mut chart, i, s);
        }
        self.vlines(&mut chart);
        if self.axes.y_names.is_empty() && self.series.len() > 1 {
            let _ = chart
                .configure_series_labels()
                .position(if self.axes.legend_left {
                    SeriesLabelPosition::UpperLeft
                } else {
                    SeriesLabelPosition::UpperRight
                })
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw();
        }
    }

    /// The grid, the axis descriptions and the tick labels (a timing
    /// diagram's signal names on y).
    fn mesh<'a, DB: DrawingBackend + 'a, X, Y>(&self, chart: &mut Chart<'a, DB, X, Y>)
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let axes = self.axes;
        let names = axes.y_names.clone();
        let mut mesh = chart.configure_mesh();
        // faint minor lines: dense ones (a log decade's nine)
        // otherwise read as a grey band
        mesh.x_desc(axes.x.as_str())
            .y_desc(axes.y.as_str())
            .light_line_style(RGBColor(246, 246, 246));
        let log_y = axes.log_y;
        let fmt = move |v: &f64| {
            let i = v.round();
            if (v - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
                names[i as usize].clone()
            } else if names.is_empty() && (!log_y || log_labelled(*v)) {
                plotters_num(*v)
            } else {
                String::new()
            }
        };
        let log_x = axes.log_x;
        let xfmt = move |v: &f64| {
            if !log_x || log_labelled(*v) {
                plotters_num(*v)
            } else {
                String::new()
            }
        };
        mesh.x_label_formatter(&xfmt);
        if !axes.y_names.is_empty() {
            mesh.y_labels(axes.y_names.len() * 2 + 1);
        }
        mesh.y_label_formatter(&fmt);
        let _ = mesh.draw();
    }

    /// Series `i`: its markers or line, its legend entry and its texts.
    fn series_on<'a, DB: DrawingBackend + 'a, X, Y>(
        &self,
        chart: &mut Chart<'a, DB, X, Y>,
        i: usize,
        s: &Series,
    ) where
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        let c = PALETTE[i % PALETTE.len()];
        let pts = drawn_points(s);
        let r = if s.points_only {
            let m = s.marker;
            chart.draw_series(
                pts.iter()
                    .map(move |p| EmptyElement::at(*p) + Polygon::new(shape(m), c.filled())),
            )
        } else {
            chart.draw_series(LineSeries::new(pts, c.stroke_width(2)))
        };
        if let Ok(a) = r {
            if self.axes.y_names.is_empty() {
                let (m, dots) = (s.marker, s.points_only);
                a.label(s.name.clone()).legend(move |(x, y)| {
                    // one element type for every legend entry:
                    // the marker filled as on the plot, or a
                    // line as a 2-pixel bar
                    let pts = if dots {
                        legend_path(m)
                    } else {
                        vec![(0, -1), (16, -1), (16, 1), (0, 1)]
                    };
                    EmptyElement::at((x, y)) + Polygon::new(pts, c.filled())
                });
            }
        }
        let _ = chart.draw_series(s.labels.iter().map(|(x, y, t)| {
            EmptyElement::at((*x, *y))
                + Text::new(t.clone(), (6, -14), ("sans-serif", 12).into_font())
        }));
    }

    /// The vertical reference lines, each labelled at its top.
    fn vlines<'a, DB: DrawingBackend + 'a, X, Y>(&self, chart: &mut Chart<'a, DB, X, Y>)
    where
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        let (y0, y1) = (self.y0, self.y1);
        for (x, label) in &self.axes.vlines {
            let grey = RGBColor(90, 90, 90);
            let _ = chart.draw_series(std::iter::once(PathElement::new(
                vec![(*x, y0), (*x, y1)],
                grey.stroke_width(1),
            )));
            let _ = chart.draw_series(std::iter::once(
                EmptyElement::at((*x, y1))
                    + Text::new(label.clone(), (3, 2), ("sans-serif", 12).into_font()),
            ));
        }
    }
}

/// The points as drawn: a step series holds each value until the next
/// point's x.
fn drawn_points(s: &Series) -> Vec<(f64, f64)> {
    if !s.steps {
        return s.points.clone();
    }
    let mut v = Vec::with_capacity(s.points.len() * 2);
    for (k, p) in s.points.iter().enumerate() {
        if k > 0 {
            v.push((p.0, s.points[k - 1].1));
        }
        v.push(*p);
    }
    v
}

/// The marker's outline, pixel offsets around its anchor.
fn shape(m: Marker) -> Vec<(i32, i32)> {
    match m {
        Marker::Circle => (0..12)
            .map(|k| {
                let a = k as f64 * std::f64::consts::PI / 6.0;
                (
                    (4.5 * a.cos()).round() as i32,
                    (4.5 * a.sin()).round() as i32,
                )
            })
            .collect(),
        Marker::Cross => vec![
            (0, -2),
            (4, -6),
            (6, -4),
            (2, 0),
            (6, 4),
            (4, 6),
            (0, 2),
            (-4, 6),
            (-6, 4),
            (-2, 0),
            (-6, -4),
            (-4, -6),
        ],
        Marker::Triangle => vec![(0, -6), (5, 4), (-5, 4)],
        Marker::Square => vec![(-4, -4), (4, -4), (4, 4), (-4, 4)],
    }
}

/// A marker's outline, offset to the legend's sample spot.
fn legend_path(m: Marker) -> Vec<(i32, i32)> {
    shape(m).into_iter().map(|(x, y)| (x + 8, y)).collect()
}

/// Whether a log axis labels the tick at `v`: 1, 2 and 5 times a power of
/// ten.  Labelling all nine ticks of a decade crowds them together at its
/// top, and a tick a rounding error below a power of ten (0.0999...)
/// would print "0.1" a second time over the decade's own.
fn log_labelled(v: f64) -> bool {
    if v <= 0.0 || !v.is_finite() {
        return false;
    }
    let m = v / 10f64.powf(v.log10().floor());
    [1.0, 2.0, 5.0].iter().any(|k| (m - k).abs() < 1e-6)
}

/// A short number for axis labels.
fn plotters_num(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e6).contains(&a) {
        format!("{v:.1e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else {
        let t = format!("{v:.3}");
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_axis_labels_one_two_and_five_once_a_decade() {
        let labelled: Vec<f64> = (1..=9)
            .flat_map(|k| [k as f64 * 0.01, k as f64 * 0.1])
            .filter(|v| super::log_labelled(*v))
            .collect();
        assert_eq!(labelled, vec![0.01, 0.1, 0.02, 0.2, 0.05, 0.5]);
        assert!(!super::log_labelled(0.09999999));
        assert!(super::log_labelled(1000.0));
    }

    #[test]
    fn csv_quotes_what_needs_it() {
        let mut t = Table::new(&["a", "b"]);
        t.push(vec!["1".into(), "x,y".into()]);
        t.push(vec!["say \"hi\"".into(), "2".into()]);
        assert_eq!(t.csv(), "a,b\n1,\"x,y\"\n\"say \"\"hi\"\"\",2\n");
    }

    #[test]
    fn draws_an_svg_with_every_series() {
        let s = draw(
            &Axes::new("t", "x", "y"),
            &[
                Series::line("one", vec![(0.0, 1.0), (1.0, 2.0)]),
                Series::scatter("two", vec![(0.5, 1.5)]),
            ],
            400,
            300,
        );
        assert!(s.starts_with("<svg"), "{}", &s[..40]);
        assert!(s.contains("one") && s.contains("two"));
        let mut log = Axes::new("log", "x", "y");
        log.log_x = true;
        log.log_y = true;
        let s = draw(
            &log,
            &[Series::scatter("p", vec![(1.0, 10.0), (1e4, 1e6)])],
            400,
            300,
        );
        // a filled 12-gon per point, not a circle element
        assert_eq!(s.matches("<polygon").count(), 2, "{s}");
        let cross = draw(
            &Axes::new("m", "x", "y"),
            &[
                Series::scatter("a", vec![(0.0, 0.0)]).with_marker(Marker::Cross),
                Series::scatter("b", vec![(1.0, 1.0)]).with_marker(Marker::Square),
            ],
            400,
            300,
        );
        // the two shapes differ in the points they are drawn with
        // (the points, then the legend's samples: filled like the points)
        let polys: Vec<&str> = cross.split("<polygon").skip(1).collect();
        assert_eq!(polys.len(), 4, "{cross}");
        let corners = |p: &str| p.matches(',').count();
        assert_ne!(corners(polys[0]), corners(polys[1]));
        assert_eq!(corners(polys[2]), corners(polys[0]));
        assert_eq!(corners(polys[3]), corners(polys[1]));
        let fill = |p: &str| p.split("fill=\"").nth(1).map(|f| f[..7].to_string());
        assert_eq!(fill(polys[2]), fill(polys[0]));
        assert!(!polys[2].contains("fill=\"none\""), "{cross}");
    }
}
