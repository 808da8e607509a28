//! report: the main job's report, `report.html` (self-contained: SVG
//! inline, no scripts, no external files) and `report.md` (figures as files
//! beside it), and the charts in it ([`draw`]).
//!
//! It knows nothing of simulation: the `build` command measures, and hands
//! this crate steps, sections, tables and charts to lay out.

mod chart;

use std::fmt::Write as _;

pub use chart::{draw, Axes, Marker, Series, Table};

/// How a step of the job ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    Ok,
    Failed,
    /// Not run (a tool is missing, or nothing to do); says why in `summary`.
    Skipped,
}

impl Status {
    pub fn word(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Failed => "FAILED",
            Status::Skipped => "skipped",
        }
    }
}

/// One step of the job.
#[derive(Debug, Clone)]
pub struct Step {
    /// The step's name on the command line (`--only`, `--skip`).
    pub id: String,
    pub name: String,
    pub status: Status,
    pub seconds: f64,
    /// One line.
    pub summary: String,
    /// Preformatted detail (a command's output), may be empty.
    pub detail: String,
    /// Files the step wrote, relative to the report (linked from it).
    pub files: Vec<String>,
}

/// A chart with the table it was drawn from.
#[derive(Debug, Clone)]
pub struct Figure {
    /// File stem: `<stem>.svg` and `<stem>.csv`.
    pub stem: String,
    pub title: String,
    pub caption: String,
    pub svg: String,
    pub table: Table,
}

/// A section of the report: paragraphs, tables and figures.
#[derive(Debug, Clone, Default)]
pub struct Section {
    pub title: String,
    pub paragraphs: Vec<String>,
    pub tables: Vec<(String, Table)>,
    pub figures: Vec<Figure>,
    /// Preformatted text blocks.
    pub pre: Vec<String>,
    /// Files to link: (path relative to the report, what it is).
    pub links: Vec<(String, String)>,
}

impl Section {
    /// The section's anchor in `report.html`.
    pub fn anchor(&self) -> String {
        slug(&self.title)
    }
}

fn slug(t: &str) -> String {
    let mut s = String::new();
    for c in t.chars() {
        if c.is_ascii_alphanumeric() {
            s.push(c.to_ascii_lowercase());
        } else if !s.ends_with('-') {
            s.push('-');
        }
    }
    s.trim_matches('-').to_string()
}

/// The whole report.
#[derive(Debug, Clone, Default)]
pub struct Document {
    pub title: String,
    pub subtitle: String,
    /// A warning shown at the top (e.g. the job had not finished), may be empty.
    pub note: String,
    /// The first screen: a question a reader asks first (does it fit,
    /// what binds, is it checked, proved, how big) and its answer.
    pub glance: Vec<(String, String)>,
    pub steps: Vec<Step>,
    pub sections: Vec<Section>,
    /// The whole job from start to end, by the wall clock (the steps'
    /// own times can overlap: a step's work may run beside the others).
    pub wall_seconds: Option<f64>,
}

impl Document {
    pub fn ok(&self) -> bool {
        self.steps.iter().all(|s| s.status != Status::Failed)
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Is `w` a code identifier (`sample_valid`, `synth_ice40`): lower case
/// words joined by underscores. Upper-case names (`ACC_X`) are the user's.
pub fn is_snake(w: &str) -> bool {
    let w = w.trim_matches(|c: char| !c.is_ascii_alphanumeric() && c != '_');
    let b = w.as_bytes();
    let joined = (1..b.len().saturating_sub(1)).any(|i| {
        b[i] == b'_' && b[i - 1].is_ascii_alphanumeric() && b[i + 1].is_ascii_alphanumeric()
    });
    joined
        && w.chars().next().is_some_and(|c| c.is_ascii_lowercase())
        && w.chars().all(|c| {
            c.is_ascii_lowercase() || c.is_ascii_digit() || matches!(c, '_' | '.' | '/' | '-')
        })
}

/// Splits text into (is code, piece): spans between backticks are code,
/// and so is any identifier written in snake case outside them (a port or
/// a file name in a summary), so prose never shows code as words.
fn spans(t: &str) -> Vec<(bool, String)> {
    let mut out = Vec::new();
    for (i, part) in t.split('`').enumerate() {
        if i % 2 == 1 {
            out.push((true, part.to_string()));
            continue;
        }
        let mut word = String::new();
        let flush = |word: &mut String, out: &mut Vec<(bool, String)>| {
            if !word.is_empty() {
                out.push((is_snake(word), std::mem::take(word)));
            }
        };
        for c in part.chars() {
            // a word: letters, digits, `_`, `.` and `/` inside (file names)
            if c.is_ascii_alphanumeric() || c == '_' || ((c == '.' || c == '/') && !word.is_empty())
            {
                word.push(c);
            } else {
                flush(&mut word, &mut out);
                out.push((false, c.to_string()));
            }
        }
        flush(&mut word, &mut out);
    }
    out
}

/// Text as HTML, code spans in `<code>` (a trailing `.` of a sentence
/// stays outside).
fn inline(t: &str) -> String {
    spans(t)
        .into_iter()
        .map(|(code, p)| {
            if code {
                let body = p.trim_end_matches('.');
                format!("<code>{}</code>{}", esc(body), &p[body.len()..])
            } else {
                esc(&p)
            }
        })
        .collect()
}

/// Text as Markdown, code spans in backticks.
fn md_inline(t: &str) -> String {
    spans(t)
        .into_iter()
        .map(|(code, p)| {
            if code {
                let body = p.trim_end_matches('.');
                format!("`{body}`{}", &p[body.len()..])
            } else {
                p
            }
        })
        .collect()
}

/// The SVG made embeddable: no XML prolog, a title for screen readers.
fn inline_svg(svg: &str, title: &str) -> String {
    let body = match svg.find("<svg") {
        Some(i) => &svg[i..],
        None => svg,
    };
    body.replacen(
        '>',
        &format!(" role=\"img\" aria-label=\"{}\">", esc(title)),
        1,
    )
}

fn html_table(t: &Table) -> String {
    let mut h = String::from("<table>\n<tr>");
    for c in &t.columns {
        // long snake_case headers may break after an underscore
        let _ = write!(h, "<th>{}</th>", inline(c));
    }
    h.push_str("</tr>\n");
    for r in &t.rows {
        h.push_str("<tr>");
        for c in r {
            let _ = write!(h, "<td>{}</td>", inline(c));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
    h
}

fn md_table(t: &Table) -> String {
    md_table_with(t, None)
}

/// [`md_table`] with column `links` (if any) written as it is: Markdown
/// links, whose targets must not become code spans.
fn md_table_with(t: &Table, links: Option<usize>) -> String {
    let cell = |s: &str| md_inline(s).replace('|', "\\|");
    let mut m = format!(
        "| {} |\n|{}|\n",
        t.columns
            .iter()
            .map(|c| cell(c))
            .collect::<Vec<_>>()
            .join(" | "),
        t.columns
            .iter()
            .map(|_| "---")
            .collect::<Vec<_>>()
            .join("|")
    );
    for r in &t.rows {
        let _ = writeln!(
            m,
            "| {} |",
            (r.iter().enumerate())
                .map(|(i, c)| if Some(i) == links { c.clone() } else { cell(c) })
                .collect::<Vec<_>>()
                .join(" | ")
        );
    }
    m
}

/// The steps table's last row, for what it is: the job's wall time beside
/// the sum of the steps' own times (which overlap when a step's work ran
/// beside the others, so they never make a "total"), or, without a wall
/// time, that sum named as a sum.
fn time_row(d: &Document) -> (String, f64, String) {
    let sum: f64 = d.steps.iter().map(|s| s.seconds).sum();
    let Some(wall) = d.wall_seconds else {
        return ("the steps' times added up".into(), sum, String::new());
    };
    // as shown, to two decimals: equal when they print equal
    let why = if (sum * 100.0).round() > (wall * 100.0).round() {
        ", more than the wall time: some steps' work ran at the same time as others and counts in each"
    } else {
        "; the rest of the wall time went between the steps (writing the report)"
    };
    (
        "the whole build, start to end (wall clock)".into(),
        wall,
        format!("the steps' own times add up to {sum:.2} s{why}"),
    )
}

fn steps_table(d: &Document) -> Table {
    let mut t = Table::new(&["step", "status", "seconds", "result", "files"]);
    for s in &d.steps {
        t.push(vec![
            s.name.clone(),
            s.status.word().into(),
            format!("{:.2}", s.seconds),
            s.summary.clone(),
            s.files
                .iter()
                .map(|f| format!("[`{f}`]({f})"))
                .collect::<Vec<_>>()
                .join(" "),
        ]);
    }
    let (what, seconds, note) = time_row(d);
    t.push(vec![
        what,
        String::new(),
        format!("{seconds:.2}"),
        note,
        String::new(),
    ]);
    t
}

/// The first screen's questions and answers (nothing when there are none).
fn html_glance(d: &Document) -> String {
    if d.glance.is_empty() {
        return String::new();
    }
    let mut h = String::from("<table class=\"glance\">\n");
    for (q, a) in &d.glance {
        let _ = writeln!(h, "<tr><th>{}</th><td>{}</td></tr>", inline(q), inline(a));
    }
    h.push_str("</table>\n");
    h
}

/// A section's linked files as a list (a file with no description: just its link).
fn html_links(links: &[(String, String)]) -> String {
    let mut h = String::new();
    if !links.is_empty() {
        h.push_str("<ul>\n");
        for (f, what) in links {
            if what.is_empty() {
                let _ = writeln!(h, "<li>{}</li>", link(f, f));
            } else {
                let _ = writeln!(h, "<li>{}: {}</li>", link(f, f), inline(what));
            }
        }
        h.push_str("</ul>\n");
    }
    h
}

/// `report.html`: one self-contained file (charts inline), with a table
/// of contents, a line per step and links to every file the job wrote.
pub fn html(d: &Document) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n<style>\n{}</style>\n</head>\n<body>\n<h1>{}</h1>\n<p>{}</p>\n",
        esc(&d.title.replace('`', "")),
        CSS,
        inline(&d.title),
        inline(&d.subtitle)
    );
    if !d.note.is_empty() {
        let _ = writeln!(h, "<p class=\"FAILED\">{}</p>", esc(&d.note));
    }
    h.push_str(&html_glance(d));
    let verdict = if d.ok() { "ok" } else { "FAILED" };
    h.push_str("<nav><h2>Contents</h2>\n<ol>\n<li><a href=\"#steps\">Steps</a></li>\n");
    for sec in &d.sections {
        let _ = writeln!(
            h,
            "<li><a href=\"#{}\">{}</a></li>",
            sec.anchor(),
            esc(&sec.title)
        );
    }
    h.push_str("</ol>\n</nav>\n");
    let _ = writeln!(
        h,
        "<h2 id=\"steps\">Steps: <span class=\"{verdict}\">{verdict}</span></h2>\n<table>\n<tr><th>step</th><th>status</th><th>seconds</th><th>result</th><th>files</th></tr>"
    );
    for s in &d.steps {
        let w = s.status.word();
        let _ = writeln!(
            h,
            "<tr><td>{} <code>{}</code></td><td class=\"{w}\">{w}</td><td class=\"num\">{:.2}</td><td>{}</td><td>{}</td></tr>",
            esc(&s.name),
            esc(&s.id),
            s.seconds,
            inline(&s.summary),
            s.files.iter().map(|f| link(f, f)).collect::<Vec<_>>().join(" ")
        );
    }
    let (what, seconds, note) = time_row(d);
    let _ = writeln!(
        h,
        "<tr><td>{}</td><td></td><td class=\"num\">{seconds:.2}</td><td>{}</td><td></td></tr>\n</table>",
        esc(&what),
        inline(&note)
    );
    for s in d
        .steps
        .iter()
        .filter(|s| s.status == Status::Failed && !s.detail.is_empty())
    {
        let _ = writeln!(
            h,
            "<h3>{} failed</h3>\n<pre>{}</pre>",
            esc(&s.name),
            esc(&s.detail)
        );
    }
    for sec in &d.sections {
        let _ = writeln!(
            h,
            "<section>\n<h2 id=\"{}\">{}</h2>",
            sec.anchor(),
            esc(&sec.title)
        );
        for p in &sec.paragraphs {
            let _ = writeln!(h, "<p>{}</p>", inline(p));
        }
        h.push_str(&html_links(&sec.links));
        for (cap, t) in &sec.tables {
            if !cap.is_empty() {
                let _ = writeln!(h, "<p><b>{}</b></p>", inline(cap));
            }
            h.push_str(&html_table(t));
        }
        for p in &sec.pre {
            let _ = writeln!(h, "<pre>{}</pre>", esc(p));
        }
        for f in &sec.figures {
            let _ = writeln!(
                h,
                "<figure>\n{}\n<figcaption><b>{}</b>. {} (data: {}, picture: {})</figcaption>\n</figure>",
                inline_svg(&f.svg, &f.title),
                inline(&f.title),
                inline(&f.caption),
                link(&format!("{}.csv", f.stem), &format!("{}.csv", f.stem)),
                link(&format!("{}.svg", f.stem), &format!("{}.svg", f.stem)),
            );
        }
        h.push_str("</section>\n");
    }
    h.push_str("</body>\n</html>\n");
    h
}

/// The page's style: tables and text wrap inside the page's width (long
/// names break anywhere rather than run out of their cell; headers and the
/// first column, names of things, break only between words).
const CSS: &str = "body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}\n\
table{border-collapse:collapse;margin:1em 0;max-width:100%}td,th{border:1px solid #bbb;padding:3px 8px;text-align:left;vertical-align:top;overflow-wrap:break-word}\n\
th{background:#eee}td.num{text-align:right;white-space:nowrap}th,td:first-child{overflow-wrap:normal}td.ok,td.FAILED,td.skipped{white-space:nowrap}pre{background:#f6f6f6;padding:.6em;white-space:pre-wrap;overflow-wrap:anywhere;font-size:85%}\n\
.ok{color:#176917}.FAILED{color:#b00;font-weight:bold}.skipped{color:#777}figure{margin:1.5em 0}\n\
figcaption{font-size:90%;color:#444;max-width:900px}svg{max-width:100%;height:auto}code{overflow-wrap:anywhere}th code{overflow-wrap:normal}\n\
nav ol{columns:2}table.glance{font-size:110%}table.glance th{text-align:left;white-space:nowrap}\n";

fn link(href: &str, text: &str) -> String {
    format!("<a href=\"{}\"><code>{}</code></a>", esc(href), esc(text))
}

/// `report.md`: the same, figures as `<stem>.svg` files beside it.
pub fn markdown(d: &Document) -> String {
    let mut m = format!("# {}\n\n{}\n\n", d.title, md_inline(&d.subtitle));
    if !d.note.is_empty() {
        let _ = writeln!(m, "**{}**\n", d.note);
    }
    if !d.glance.is_empty() {
        let mut t = Table::new(&["question", "answer"]);
        for (q, a) in &d.glance {
            t.push(vec![q.clone(), a.clone()]);
        }
        let _ = writeln!(m, "{}", md_table(&t));
    }
    let _ = writeln!(
        m,
        "## Steps: {}\n\n{}",
        if d.ok() { "ok" } else { "FAILED" },
        md_table_with(&steps_table(d), Some(4))
    );
    for s in d
        .steps
        .iter()
        .filter(|s| s.status == Status::Failed && !s.detail.is_empty())
    {
        let _ = writeln!(
            m,
            "### {} failed\n\n```text\n{}\n```\n",
            s.name,
            s.detail.trim_end()
        );
    }
    for sec in &d.sections {
        let _ = writeln!(m, "## {}\n", sec.title);
        for p in &sec.paragraphs {
            let _ = writeln!(m, "{}\n", md_inline(p));
        }
        for (f, what) in &sec.links {
            if what.is_empty() {
                let _ = writeln!(m, "- [`{f}`]({f})");
            } else {
                let _ = writeln!(m, "- [`{f}`]({f}): {}", md_inline(what));
            }
        }
        if !sec.links.is_empty() {
            m.push('\n');
        }
        for (cap, t) in &sec.tables {
            if !cap.is_empty() {
                let _ = writeln!(m, "**{}**\n", md_inline(cap));
            }
            let _ = writeln!(m, "{}", md_table(t));
        }
        for p in &sec.pre {
            let _ = writeln!(m, "```text\n{}\n```\n", p.trim_end());
        }
        for f in &sec.figures {
            let _ = writeln!(
                m,
                "![{}]({}.svg)\n\n*{}.* {} (data: [`{}.csv`]({}.csv))\n",
                f.title,
                f.stem,
                f.title,
                md_inline(&f.caption),
                f.stem,
                f.stem
            );
        }
    }
    m
}

/// Every file of the report: `report.html`, `report.md`, and each figure's
/// `.svg` and `.csv`.
pub fn files(d: &Document) -> Vec<(String, String)> {
    let mut v = vec![
        ("report.html".to_string(), html(d)),
        ("report.md".to_string(), markdown(d)),
    ];
    for f in d.sections.iter().flat_map(|s| &s.figures) {
        v.push((format!("{}.svg", f.stem), f.svg.clone()));
        v.push((format!("{}.csv", f.stem), f.table.csv()));
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn html_is_self_contained_and_shows_failures() {
        let svg = draw(
            &Axes::new("c", "x", "y"),
            &[Series::line("s", vec![(0.0, 0.0), (1.0, 1.0)])],
            300,
            200,
        );
        let mut t = Table::new(&["x", "y"]);
        t.push(vec!["0".into(), "0".into()]);
        let d = Document {
            title: "r <1>".into(),
            subtitle: "s".into(),
            note: String::new(),
            glance: vec![("Does it fit?".into(), "yes, `mux_en` ok".into())],
            steps: vec![
                Step {
                    id: "a".into(),
                    files: vec!["a.txt".into()],
                    name: "a".into(),
                    status: Status::Ok,
                    seconds: 1.0,
                    summary: "fine".into(),
                    detail: String::new(),
                },
                Step {
                    id: "b".into(),
                    files: vec![],
                    name: "b".into(),
                    status: Status::Failed,
                    seconds: 0.5,
                    summary: "bad".into(),
                    detail: "why".into(),
                },
            ],
            sections: vec![Section {
                title: "charts".into(),
                figures: vec![Figure {
                    stem: "c".into(),
                    title: "C".into(),
                    caption: "cap".into(),
                    svg,
                    table: t,
                }],
                ..Section::default()
            }],
            wall_seconds: None,
        };
        assert!(!d.ok());
        let h = html(&d);
        assert!(h.contains("r &lt;1&gt;"));
        assert!(h.contains("<svg") && !h.contains("<?xml"));
        assert!(!h.contains("<script") && !h.contains("src=\"http"));
        assert!(h.contains("class=\"FAILED\""));
        assert!(h.contains("<a href=\"#charts\">charts</a>") && h.contains("<h2 id=\"charts\">"));
        assert!(h.contains("<a href=\"a.txt\">") && h.contains("<a href=\"c.csv\">"));
        let m = markdown(&d);
        assert!(
            m.contains("![C](c.svg)")
                && m.contains("| b | FAILED |")
                && m.contains("[`a.txt`](a.txt)")
        );
        assert!(h.contains("<code>mux_en</code>") && m.contains("`mux_en` ok"));
        // no wall time: the last row is the sum, named as one
        assert!(
            h.contains(
                "<tr><td>the steps' times added up</td><td></td><td class=\"num\">1.50</td>"
            ),
            "{h}"
        );
        assert!(m.contains("| the steps' times added up |  | 1.50 |"), "{m}");
        let names: Vec<String> = files(&d).into_iter().map(|f| f.0).collect();
        assert_eq!(names, ["report.html", "report.md", "c.svg", "c.csv"]);
    }

    /// The last row of the steps table is the wall time when the job gives
    /// one, beside the steps' sum, said to be more than it when steps
    /// overlapped and less when time went between them.
    #[test]
    fn the_steps_last_row_is_the_wall_time_beside_their_sum() {
        let step = |id: &str, seconds: f64| Step {
            id: id.into(),
            name: id.into(),
            status: Status::Ok,
            seconds,
            summary: String::new(),
            detail: String::new(),
            files: vec![],
        };
        for (wall, more) in [(2.0, true), (5.0, false)] {
            let d = Document {
                steps: vec![step("a", 1.0), step("b", 2.5)],
                wall_seconds: Some(wall),
                ..Document::default()
            };
            let (h, m) = (html(&d), markdown(&d));
            let row = format!("| the whole build, start to end (wall clock) |  | {wall:.2} | the steps' own times add up to 3.50 s");
            assert!(m.contains(&row), "{m}");
            assert!(
                h.contains(&format!("<td class=\"num\">{wall:.2}</td><td>the steps")),
                "{h}"
            );
            assert_eq!(m.contains("more than the wall time"), more, "{m}");
            assert!(!m.contains("| total |") && !h.contains("<td>total</td>"));
        }
    }

    #[test]
    fn code_in_prose_is_marked_as_code() {
        assert!(
            is_snake("sample_valid")
                && is_snake("verilog/slot_rom.hex")
                && is_snake("synth_ice40.")
        );
        assert!(
            !is_snake("ACC_X") && !is_snake("_x") && !is_snake("frame0.vcd") && !is_snake("a_")
        );
        assert_eq!(
            inline("a sample_valid strobe, `CH_1 x` and slot_rom.hex."),
            "a <code>sample_valid</code> strobe, <code>CH_1 x</code> and <code>slot_rom.hex</code>."
        );
        assert_eq!(md_inline("see mux_sel."), "see `mux_sel`.");
        assert_eq!(md_inline("1.5 MHz, ACC_X"), "1.5 MHz, ACC_X");
    }
}
