use measure::find_program;
use measure::for_tests::{built_venv, stat_cells};

/// A program nowhere says where it was looked for and how to get it;
/// the checkout's own `.venv/bin` is among the places.
#[test]
fn a_missing_program_names_the_places_and_make_tools() {
    let e = find_program("slotforge-no-such-program").unwrap_err();
    assert!(e.contains("neither on PATH"), "{e}");
    assert!(e.contains(&built_venv().display().to_string()), "{e}");
    assert!(
        e.contains("`make tools-extra`")
            && e.contains("`make tools`")
            && e.contains("add that .venv/bin to PATH"),
        "{e}"
    );
    let sh = find_program("sh").unwrap();
    assert!(sh.is_file(), "{}", sh.display());
}

#[test]
fn stat_json_gives_the_designs_cells_by_type() {
    let j = r#"{"creator":"Yosys","modules":{"\\slotforge_top":{"num_cells":3}},
        "design":{"num_cells":20,"num_cells_by_type":{"SB_LUT4":12,"SB_DFF":5,"$scopeinfo":0,"SB_RAM40_4K":3}}}"#;
    let c = stat_cells(j).unwrap();
    assert_eq!(
        c,
        vec![
            ("$scopeinfo".to_string(), 0),
            ("SB_DFF".into(), 5),
            ("SB_LUT4".into(), 12),
            ("SB_RAM40_4K".into(), 3)
        ]
    );
    assert!(stat_cells("{\"modules\":{}}").is_none());
}

#[test]
fn a_missing_program_names_make_tools() {
    let e = find_program("yowasp-no-such-tool-5c1e").unwrap_err();
    assert!(e.contains("make tools-extra"), "{e}");
}
