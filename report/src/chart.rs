//! Charts as SVG text (plotters' SVG back end: no fonts, no files), each
//! drawn from a [`Table`] that is also written as CSV, so every number in a
//! picture can be reused.

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
}

impl Series {
    pub fn line(name: &str, points: Vec<(f64, f64)>) -> Series {
        Series {
            name: name.into(),
            points,
            points_only: false,
            steps: false,
        }
    }

    pub fn scatter(name: &str, points: Vec<(f64, f64)>) -> Series {
        Series {
            points_only: true,
            ..Series::line(name, points)
        }
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
        let (x0, x1) = range(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
            axes.log_x,
        );
        let (y0, y1) = range(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
            axes.log_y,
        );
        let mut b = ChartBuilder::on(&root);
        b.caption(&axes.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(if axes.y_names.is_empty() { 60 } else { 110 });
        // four combinations of linear/log axes; plotters types them apart
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                let names = axes.y_names.clone();
                let mut mesh = chart.configure_mesh();
                mesh.x_desc(axes.x.as_str()).y_desc(axes.y.as_str());
                let fmt = move |v: &f64| {
                    let i = v.round();
                    if (v - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
                        names[i as usize].clone()
                    } else if names.is_empty() {
                        format!("{}", plotters_num(*v))
                    } else {
                        String::new()
                    }
                };
                if !axes.y_names.is_empty() {
                    mesh.y_labels(axes.y_names.len() * 2 + 1);
                }
                mesh.y_label_formatter(&fmt);
                let _ = mesh.draw();
                for (i, s) in series.iter().enumerate() {
                    let c = PALETTE[i % PALETTE.len()];
                    let pts: Vec<(f64, f64)> = if s.steps {
                        let mut v = Vec::with_capacity(s.points.len() * 2);
                        for (k, p) in s.points.iter().enumerate() {
                            if k > 0 {
                                v.push((p.0, s.points[k - 1].1));
                            }
                            v.push(*p);
                        }
                        v
                    } else {
                        s.points.clone()
                    };
                    let r = if s.points_only {
                        chart.draw_series(pts.iter().map(|p| Circle::new(*p, 3, c.filled())))
                    } else {
                        chart.draw_series(LineSeries::new(pts, c.stroke_width(2)))
                    };
                    if let Ok(a) = r {
                        if axes.y_names.is_empty() {
                            a.label(s.name.clone()).legend(move |(x, y)| {
                                PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2))
                            });
                        }
                    }
                }
                if axes.y_names.is_empty() && series.len() > 1 {
                    let _ = chart
                        .configure_series_labels()
                        .background_style(WHITE.mix(0.85))
                        .border_style(BLACK)
                        .draw();
                }
            }};
        }
        match (axes.log_x, axes.log_y) {
            (false, false) => {
                if let Ok(c) = b.build_cartesian_2d(x0..x1, y0..y1) {
                    body!(c)
                }
            }
            (true, false) => {
                if let Ok(c) = b.build_cartesian_2d((x0..x1).log_scale(), y0..y1) {
                    body!(c)
                }
            }
            (false, true) => {
                if let Ok(c) = b.build_cartesian_2d(x0..x1, (y0..y1).log_scale()) {
                    body!(c)
                }
            }
            (true, true) => {
                if let Ok(c) = b.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale()) {
                    body!(c)
                }
            }
        }
        let _ = root.present();
    }
    svg
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
        assert!(s.contains("<circle"));
    }
}
