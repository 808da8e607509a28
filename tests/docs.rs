//! Figures in the docs that the binary computes must be what it prints
//! (issue 19, item 5): a document that drifts from the tool fails here.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common_cli::root;
use crate::tools;

fn doc(path: &str) -> String {
    std::fs::read_to_string(root().join(path)).unwrap()
}

/// docs/reference-design.md's sample count of 10 frames is `sim`'s.
#[test]
fn the_reference_design_sample_count_is_the_binarys() {
    let out = Command::new(env!("CARGO_BIN_EXE_slotforge"))
        .args(["sim", "--frames", "10", "--json"])
        .arg(root().join("mixes/eskin34.toml"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let n = v["samples"].as_u64().unwrap();
    let text = doc("docs/reference-design.md");
    for claim in [
        format!("{n} in 10 frames"),
        format!("--frames 10   # {n} samples"),
        format!("holds the {n} samples"),
    ] {
        assert!(
            text.contains(&claim),
            "docs/reference-design.md: `{claim}` missing"
        );
    }
    // and no other 10-frame count
    let wrong = (n - 10..n + 10).filter(|&k| k != n).find(|k| {
        text.contains(&format!("{k} in 10 frames")) || text.contains(&format!("# {k} samples"))
    });
    assert_eq!(wrong, None);
}

/// eskin34's row of the current synthesis table of docs/performance.md.
fn eskin34_row() -> String {
    let perf = doc("docs/performance.md");
    let current = perf.split("## Gateware synthesis").nth(1).unwrap();
    let row = current.lines().find(|l| l.starts_with("| eskin34 |"));
    row.expect("an eskin34 row in docs/performance.md")
        .to_string()
}

/// eskin34's logic cells are stated once, in the current table of
/// docs/performance.md, and ARCHITECTURE.md and README state no other
/// count; the table's row is what `hdl/synth.sh` measures now.
#[test]
fn the_reference_design_logic_cells_are_stated_once() {
    let row = eskin34_row();
    let lcs: u64 = row.split('|').nth(4).unwrap().trim().parse().unwrap();
    for f in ["ARCHITECTURE.md", "README.md"] {
        let t = doc(f);
        assert!(
            !t.contains(" LCs; the reference design ") && !t.contains("reference design 2"),
            "{f} states eskin34's logic cells; docs/performance.md is their one home"
        );
    }
    assert!(lcs > 0);
}

#[test]
#[ignore = "long: make test-long (yosys + nextpnr on eskin34)"]
fn the_current_logic_cell_figure_is_what_synthesis_gives() {
    if !tools::require_tools(&["yosys", "nextpnr-ice40"]) {
        return;
    }
    let row = eskin34_row();
    let want: Vec<String> = row.split('|').map(|c| c.trim().to_string()).collect();
    let out = tools::run_ok(
        Command::new("bash")
            .arg(root().join("hdl/synth.sh"))
            .arg(root().join("mixes/eskin34.toml"))
            .current_dir(root()),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let got: Vec<&str> = text
        .lines()
        .find(|l| l.starts_with("eskin34"))
        .unwrap()
        .split_whitespace()
        .collect();
    // mix clock_MHz LCs LUT4 DFF BRAM Fmax_MHz ratio
    assert_eq!(got[2], want[4], "LCs: synth.sh {text}, doc {row}");
    assert_eq!(got[5], want[7], "BRAMs: synth.sh {text}, doc {row}");
}

/// docs/reference-design.md's audit figures are `audit`'s output: the
/// samples per frame and the aggregate rate of eskin34, and the link lines
/// of eskin34-uart quoted verbatim (words, bytes, line use, FIFO depth,
/// latency, minimum baud).  No simulation: milliseconds.
#[test]
fn the_reference_design_audit_figures_are_the_binarys() {
    let audit = |mix: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_slotforge"))
            .arg("audit")
            .arg(root().join(mix))
            .output()
            .unwrap();
        assert!(out.status.success(), "{mix}");
        String::from_utf8(out.stdout).unwrap()
    };
    let text = doc("docs/reference-design.md");
    let eskin = audit("mixes/eskin34.toml");
    let per_frame: u64 = eskin
        .lines()
        .find_map(|l| l.split_once(" samples/frame")?.0.parse().ok())
        .expect("audit prints samples/frame");
    for claim in [
        format!("{per_frame} samples per 10 ms"),
        format!("{per_frame} samples / {:.1} kHz", per_frame as f64 / 10.0),
    ] {
        assert!(
            text.contains(&claim),
            "docs/reference-design.md: `{claim}` missing"
        );
    }
    let uart = audit("mixes/eskin34-uart.toml");
    for l in uart.lines().filter(|l| l.starts_with("link")) {
        assert!(
            text.contains(l),
            "docs/reference-design.md does not quote audit's line:\n{l}"
        );
    }
    assert!(uart.lines().any(|l| l.starts_with("link: ")), "{uart}");
}

/// The repository's tracked files (relative paths): `git ls-files`, or,
/// outside a git checkout, every file but build output and `.git`.
fn tracked_files() -> Vec<PathBuf> {
    let git = Command::new("git")
        .args(["ls-files", "-z"])
        .current_dir(root())
        .output();
    match git {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout)
            .split('\0')
            .filter(|p| !p.is_empty())
            .map(PathBuf::from)
            .filter(|p| root().join(p).is_file())
            .collect(),
        _ => walk(&root(), Path::new("")),
    }
}

/// Files under `dir`, relative to the root, skipping what a build writes.
fn walk(base: &Path, rel: &Path) -> Vec<PathBuf> {
    let skip = [".git", "target", "out", "build", "prove-out"];
    let mut files = Vec::new();
    for e in std::fs::read_dir(base.join(rel)).unwrap().flatten() {
        let r = rel.join(e.file_name());
        if e.path().is_dir() {
            if !skip.iter().any(|s| Path::new(s) == r) {
                files.extend(walk(base, &r));
            }
        } else {
            files.push(r);
        }
    }
    files
}

/// Markdown text with fenced code blocks and inline code spans blanked, so
/// that code that looks like a link is not taken for one.
fn prose(md: &str) -> String {
    let mut out = String::new();
    let mut fenced = false;
    for line in md.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced {
            let mut code = false;
            for part in line.split('`') {
                if !code {
                    out.push_str(part);
                }
                out.push(' ');
                code = !code;
            }
        }
        out.push('\n');
    }
    out
}

/// The targets of the inline links `[text](target)` (and images) of `md`.
fn link_targets(md: &str) -> Vec<String> {
    let text = prose(md);
    let mut targets = Vec::new();
    for (i, _) in text.match_indices("](") {
        let rest = &text[i + 2..];
        if let Some(end) = rest.find(')') {
            let t = rest[..end].split_whitespace().next().unwrap_or("");
            targets.push(t.to_string());
        }
    }
    targets
}

/// The relative links of one Markdown file that name no existing file.
fn broken_links(md: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(root().join(md)).unwrap();
    let dir = md.parent().unwrap_or(Path::new(""));
    link_targets(&text)
        .into_iter()
        .filter(|t| {
            let external = ["http://", "https://", "mailto:"];
            !t.is_empty() && !t.starts_with('#') && !external.iter().any(|p| t.starts_with(p))
        })
        .filter(|t| {
            let file = t.split('#').next().unwrap();
            !root().join(dir).join(file).exists()
        })
        .map(|t| format!("{}: ({t})", md.display()))
        .collect()
}

/// Every relative link in every tracked Markdown file (README,
/// ARCHITECTURE, CHANGELOG, docs/, the crates' folders) names a file that
/// exists; `#anchor` parts are not checked.
#[test]
fn every_relative_markdown_link_resolves() {
    let mds: Vec<PathBuf> = tracked_files()
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    assert!(mds.iter().any(|p| p == Path::new("README.md")), "{mds:?}");
    let broken: Vec<String> = mds.iter().flat_map(|m| broken_links(m)).collect();
    assert!(
        broken.is_empty(),
        "{} broken relative links:\n{}",
        broken.len(),
        broken.join("\n")
    );
}

/// The product names no file its users lack: the project's private notes
/// and sources live outside the repository.
#[test]
fn no_tracked_file_points_outside_the_repository() {
    // spelt in pieces so that this file does not match itself
    let banned = [
        concat!("SPEC", ".md"),
        concat!("../", "shared"),
        concat!("shared/", "seeds"),
    ];
    let mut hits = Vec::new();
    for f in tracked_files() {
        let Ok(text) = std::fs::read_to_string(root().join(&f)) else {
            continue; // not text
        };
        for (n, line) in text.lines().enumerate() {
            if let Some(b) = banned.iter().find(|b| line.contains(*b)) {
                hits.push(format!("{}:{}: {b}", f.display(), n + 1));
            }
        }
    }
    assert!(
        hits.is_empty(),
        "references to files users lack:\n{}",
        hits.join("\n")
    );
}

/// docs/performance.md holds the current figures only (their history is
/// CHANGELOG.md's), so it stays a page a reader takes in: at most 300 lines.
#[test]
fn the_performance_page_holds_current_figures_only() {
    let lines = doc("docs/performance.md").lines().count();
    assert!(
        lines <= 300,
        "docs/performance.md has {lines} lines (at most 300): move history to CHANGELOG.md"
    );
}
