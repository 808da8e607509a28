//! Hints repeat the options the user gave: the command a message suggests
//! works as printed.

use crate::common_cli::{slotforge, tiny};

/// `golden` without a golden in the `--dir` given suggests recording one
/// with that folder and back end; running the suggestion records it, after
/// which the first command passes.
#[test]
fn the_missing_golden_hint_keeps_the_folder_and_back_end() {
    let dir = tempfile::tempdir().unwrap();
    let gold = dir.path().join("my goldens");
    let first = || {
        let mut c = slotforge();
        c.args(["golden", "--backend", "rusthdl", "--dir"])
            .arg(&gold)
            .arg(tiny());
        c
    };
    let o = first().output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    let hint = err
        .split("record one with `")
        .nth(1)
        .and_then(|h| h.split('`').next())
        .unwrap_or_else(|| panic!("no hint: {err}"));
    assert!(
        hint.contains("--backend rusthdl") && hint.contains("my goldens"),
        "{hint}"
    );
    // the hint as a shell would split it (single quotes around the folder)
    let words = shell_words(hint);
    assert_eq!(words[0], "slotforge", "{hint}");
    slotforge().args(&words[1..]).assert().success();
    first().assert().success();
}

/// `sh`-style splitting of a printed command: spaces, and '...' quoting.
fn shell_words(s: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted, mut any) = (Vec::new(), String::new(), false, false);
    for c in s.chars() {
        match c {
            '\'' => (quoted, any) = (!quoted, true),
            ' ' if !quoted => {
                if any {
                    out.push(std::mem::take(&mut cur));
                }
                any = false;
            }
            c => (cur, any) = (cur + &c.to_string(), true),
        }
    }
    if any {
        out.push(cur);
    }
    out
}
