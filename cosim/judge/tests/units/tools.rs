use std::path::Path;
use std::time::Duration;

use judge::tools::{run, Tool, ToolError};

#[test]
fn a_run_in_a_folder_with_its_output_and_exit() {
    let d = tempfile::tempdir().unwrap();
    let out = Tool::new("sh")
        .args(["-c", "pwd; echo oops >&2; exit 3"])
        .current_dir(d.path())
        .run()
        .unwrap();
    assert!(!out.success);
    let here = d.path().canonicalize().unwrap();
    assert_eq!(Path::new(out.stdout.trim()), here);
    assert_eq!(out.stderr, "oops\n");
    // no output files left in the folder unless asked for
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
    let kept = run(
        "sh",
        &["-c", "echo kept"],
        d.path(),
        Duration::from_secs(60),
    )
    .unwrap();
    assert_eq!(kept.stdout, "kept\n");
    let file = std::fs::read_to_string(d.path().join("sh.stdout")).unwrap();
    assert_eq!(file, "kept\n");
}

#[test]
fn missing_and_too_slow_tools_are_told_apart() {
    let missing = Tool::new("slotforge-no-such-tool-7f3a").run();
    assert_eq!(
        missing.unwrap_err(),
        ToolError::Missing("slotforge-no-such-tool-7f3a".into())
    );
    let slow = Tool::new("sleep")
        .arg("5")
        .timeout(Duration::from_millis(100))
        .run();
    assert_eq!(slow.unwrap_err(), ToolError::Timeout("sleep".into(), 0));
}
