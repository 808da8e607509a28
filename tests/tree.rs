//! The shape of the source tree, held as tests so that it stays readable:
//! no crate inside another crate's folder, the dependency edges that keep
//! the layers apart, functions that fit on a screen, and an
//! ARCHITECTURE.md that is short and names every crate.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common_cli::root;

/// The workspace's packages: name -> (folder, normal dependencies).
fn packages() -> BTreeMap<String, (PathBuf, Vec<String>)> {
    let out = Command::new(env!("CARGO"))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .current_dir(root())
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["packages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let dir = Path::new(p["manifest_path"].as_str().unwrap())
                .parent()
                .unwrap()
                .to_path_buf();
            let deps = p["dependencies"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|d| d["kind"].is_null())
                .map(|d| d["name"].as_str().unwrap().to_string())
                .collect();
            (p["name"].as_str().unwrap().to_string(), (dir, deps))
        })
        .collect()
}

#[test]
fn no_crate_lives_inside_another_crates_folder() {
    let pkgs = packages();
    let top = pkgs["slotforge"].0.clone();
    for (a, (da, _)) in &pkgs {
        for (b, (db, _)) in &pkgs {
            if a != b && *db != top && da.starts_with(db) {
                panic!(
                    "crate {a} ({}) lies inside crate {b}'s folder ({})",
                    da.display(),
                    db.display()
                );
            }
        }
    }
}

#[test]
fn the_layers_hold() {
    let pkgs = packages();
    let deps = |name: &str| &pkgs[name].1;
    for forbidden in ["hdl", "rust-hdl", "engines", "campaign", "formal"] {
        assert!(
            !deps("judge").iter().any(|d| d == forbidden),
            "the judge must not see {forbidden}"
        );
    }
    assert!(
        !deps("engines")
            .iter()
            .any(|d| d == "formal" || d == "campaign"),
        "no engine may depend on formal or the campaign"
    );
    assert!(
        deps("link").is_empty(),
        "link is a leaf: {:?}",
        deps("link")
    );
    for (name, (_, d)) in &pkgs {
        if name != "hdl" {
            assert!(
                !d.iter().any(|d| d == "rust-hdl"),
                "{name} uses rust-hdl outside hdl"
            );
        }
    }
}

/// One function's length in lines, from its `fn` line to its closing brace.
struct Unit {
    lines: usize,
    at: String,
}

/// The file's lines with string and char literals emptied and comments
/// dropped, so braces in them do not count; newlines are kept.
fn code_lines(text: &str) -> Vec<String> {
    let b: Vec<char> = text.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            i += 2;
            while i + 1 < b.len() && !(b[i] == '*' && b[i + 1] == '/') {
                if b[i] == '\n' {
                    out.push('\n');
                }
                i += 1;
            }
            i += 2;
        } else if c == 'r' && (next == Some('"') || next == Some('#')) && !ident_before(&b, i) {
            let hashes = b[i + 1..].iter().take_while(|&&h| h == '#').count();
            if b.get(i + 1 + hashes) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            i += 2 + hashes;
            while i < b.len()
                && !(b[i] == '"'
                    && b[i + 1..]
                        .iter()
                        .take(hashes)
                        .filter(|&&h| h == '#')
                        .count()
                        == hashes)
            {
                if b[i] == '\n' {
                    out.push('\n');
                }
                i += 1;
            }
            i += 1 + hashes;
            out.push_str("\"\"");
        } else if c == '"' {
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    i += 1;
                }
                if b.get(i) == Some(&'\n') {
                    out.push('\n');
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == '\'' && next == Some('\\') {
            // an escaped char literal: '\n', '\u{7b}'
            i += 2;
            while i < b.len() && b[i] != '\'' {
                i += 1;
            }
            i += 1;
        } else if c == '\'' && b.get(i + 2) == Some(&'\'') {
            i += 3;
        } else {
            out.push(c);
            i += 1;
        }
    }
    out.lines().map(str::to_string).collect()
}

fn ident_before(b: &[char], i: usize) -> bool {
    i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_')
}

fn is_fn_start(code: &str) -> bool {
    let words: Vec<&str> = code.split_whitespace().collect();
    let fn_at = words.iter().position(|w| *w == "fn");
    match fn_at {
        Some(i) => words[..i].iter().all(|w| {
            w.starts_with("pub") || ["const", "async", "unsafe", "extern", "\"C\""].contains(w)
        }),
        None => false,
    }
}

/// The line (0-based) where the item starting at `start` ends; None for a
/// declaration without a body.
fn item_end(lines: &[String], start: usize) -> Option<usize> {
    let mut depth = 0i64;
    let mut opened = false;
    for (j, code) in lines.iter().enumerate().skip(start) {
        depth += code.matches('{').count() as i64 - code.matches('}').count() as i64;
        opened |= code.contains('{');
        if opened && depth <= 0 {
            return Some(j);
        }
        if !opened && code.trim_end().ends_with(';') {
            return None;
        }
    }
    None
}

fn units_of(path: &Path, out: &mut Vec<Unit>) {
    let lines = code_lines(&std::fs::read_to_string(path).unwrap());
    let mut i = 0;
    while i < lines.len() {
        let code = lines[i].trim_start();
        if code.starts_with("#[cfg(test)]") {
            i = item_end(&lines, i + 1).map_or(i + 1, |e| e + 1);
            continue;
        }
        if is_fn_start(code) {
            if let Some(end) = item_end(&lines, i) {
                out.push(Unit {
                    lines: end - i + 1,
                    at: format!("{}:{}", path.display(), i + 1),
                });
            }
        }
        i += 1;
    }
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Library code: every package's `src/`, tests (`#[cfg(test)]`) left out,
/// and `testkit`, which is test code that other crates' tests share.
#[test]
fn functions_fit_on_a_screen() {
    let mut files = Vec::new();
    for (name, (dir, _)) in packages() {
        let src = dir.join("src");
        if name == "testkit" {
            continue;
        }
        if src.is_dir() {
            rust_files(&src, &mut files);
        }
    }
    let mut units = Vec::new();
    for f in &files {
        units_of(f, &mut units);
    }
    units.sort_by_key(|u| std::cmp::Reverse(u.lines));
    let long: Vec<String> = units
        .iter()
        .filter(|u| u.lines > 100)
        .map(|u| format!("{} lines at {}", u.lines, u.at))
        .collect();
    assert!(
        units.len() > 500,
        "the count found only {} functions",
        units.len()
    );
    assert!(
        long.len() * 100 <= units.len() && units[0].lines <= 200,
        "{} of {} functions exceed 100 lines (at most 1 %, none over 200):\n{}",
        long.len(),
        units.len(),
        long.join("\n")
    );
}

#[test]
fn the_line_counter_sees_a_long_function_and_skips_tests() {
    let dir = tempfile::tempdir().unwrap();
    let body = "    let s = \"}\"; // {\n    let r = r#\"\n}\"#; /* { */\n".repeat(75);
    let text = format!(
        "pub(crate) fn long() {{\n{body}}}\n#[cfg(test)]\nmod tests {{\n    fn hidden() {{\n{body}    }}\n}}\nfn short() -> char {{ '{{' }}\n"
    );
    let p = dir.path().join("x.rs");
    std::fs::write(&p, text).unwrap();
    let mut units = Vec::new();
    units_of(&p, &mut units);
    assert_eq!(units.len(), 2);
    assert_eq!(units[0].lines, 227);
    assert_eq!(units[1].lines, 1);
}

#[test]
fn architecture_is_short_and_names_every_crate() {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    assert!(
        text.len() <= 20_000,
        "ARCHITECTURE.md is {} characters (at most 20,000)",
        text.len()
    );
    for name in packages().keys() {
        assert!(
            text.contains(&format!("`{name}`")),
            "ARCHITECTURE.md does not name the crate `{name}`"
        );
    }
}

/// The `pub mod`s a crate's `lib.rs` may declare: a module that is a
/// namespace its callers read (`format::SYNC`), not a crate's way of
/// exposing its insides. Everything else is private behind the crate's
/// export list (`pub use`).
const PUBLIC_MODULES: &[(&str, &str, &str)] = &[
    (
        "link",
        "format",
        "the packet format's constants and word builders (`format::SYNC`, `format::header`)",
    ),
    (
        "lut-gen",
        "lut",
        "the slot table's file forms (`lut::to_hex`, `lut::to_csv`, `lut::to_markdown`)",
    ),
    (
        "formal",
        "cache",
        "the proof cache's `cache::key`, `cache::load`, `cache::store`",
    ),
    (
        "judge",
        "tools",
        "the one tool runner (`tools::run`, `tools::present`, `tools::Tool`)",
    ),
    (
        "judge",
        "switch",
        "the test-only detector switch, behind the `test-switch` feature",
    ),
    // The crates without a unit-test harness (`[lib] test = false`, so a
    // test build compiles them once) reach the private items their tests
    // check through one `#[doc(hidden)]` module, named for what it is.
    (
        "judge",
        "for_tests",
        "private items the crate's integration tests check, doc(hidden)",
    ),
    (
        "engines",
        "for_tests",
        "private items the crate's integration tests check, doc(hidden)",
    ),
    (
        "campaign",
        "for_tests",
        "private items the crate's integration tests check, doc(hidden)",
    ),
    (
        "lut-gen",
        "for_tests",
        "private items the crate's integration tests check, doc(hidden)",
    ),
    (
        "hdl",
        "for_tests",
        "private items the crate's integration tests check, doc(hidden)",
    ),
    (
        "measure",
        "for_tests",
        "private items the crate's integration tests check, doc(hidden)",
    ),
    (
        "link",
        "for_tests",
        "private items the crate's integration tests check, doc(hidden)",
    ),
];

/// `testkit` is exempt: a dev-only toolbox whose modules are the helpers'
/// names (`testkit::tools`, `testkit::presets`), never a published API.
const TOOLBOXES: &[&str] = &["testkit"];

/// The `pub mod NAME` declarations of one `lib.rs` (comments skipped).
fn public_modules(lib_rs: &str) -> Vec<String> {
    code_lines(lib_rs)
        .iter()
        .filter_map(|l| {
            let rest = l.trim_start().strip_prefix("pub mod ")?;
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            (!name.is_empty()).then_some(name)
        })
        .collect()
}

#[test]
fn crates_keep_their_modules_private() {
    let mut found = Vec::new();
    for (name, (dir, _)) in packages() {
        let lib = dir.join("src/lib.rs");
        let Ok(text) = std::fs::read_to_string(&lib) else {
            continue;
        };
        if TOOLBOXES.contains(&name.as_str()) {
            continue;
        }
        for m in public_modules(&text) {
            if !PUBLIC_MODULES
                .iter()
                .any(|(c, allowed, _)| *c == name && *allowed == m)
            {
                found.push(format!(
                    "{}: `pub mod {m}` (keep it private and `pub use` its items, or add it \
                     to PUBLIC_MODULES with the reason its namespace is clearer)",
                    lib.display()
                ));
            }
            if m == "for_tests" && !text.contains("#[doc(hidden)]\npub mod for_tests") {
                found.push(format!(
                    "{}: `pub mod for_tests` is not `#[doc(hidden)]`",
                    lib.display()
                ));
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}

#[test]
fn the_public_module_check_sees_a_pub_mod() {
    let text = "//! pub mod in_a_comment;\nmod private;\npub mod open;\npub(crate) mod inner;\n  pub mod indented { }\n";
    assert_eq!(public_modules(text), ["open", "indented"]);
    // Every allowed module still exists, so the list cannot go stale.
    let pkgs = packages();
    for (c, m, why) in PUBLIC_MODULES {
        let text = std::fs::read_to_string(pkgs[*c].0.join("src/lib.rs")).unwrap();
        assert!(
            public_modules(&text).iter().any(|x| x == m),
            "PUBLIC_MODULES allows {c}::{m} ({why}), which is no longer public: drop the entry"
        );
    }
}
