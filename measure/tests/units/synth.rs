use lut_gen::Fpga;
use measure::for_tests::parse_synth as parse;
use measure::{anchor, median_fmax, Synth};

#[test]
fn reads_nextpnr_and_yosys_figures() {
    let report = r#"{"fmax": {"clk$SB_IO_IN_$glb_clk": {"achieved": 117.25, "constraint": 48}},
        "utilization": {"ICESTORM_LC": {"available": 7680, "used": 263},
          "ICESTORM_RAM": {"available": 32, "used": 3}, "SB_GB": {"available": 8, "used": 0}}}"#;
    let stat: Vec<(String, u64)> = [
        ("SB_CARRY", 4),
        ("SB_DFF", 10),
        ("SB_DFFER", 7),
        ("SB_LUT4", 120),
    ]
    .map(|(c, n)| (c.to_string(), n))
    .to_vec();
    let r = parse(Fpga::Ice40Hx8k, report, &stat).unwrap();
    assert_eq!((r.lcs, r.brams, r.lut4, r.dff), (263, 3, 120, 17));
    assert_eq!(r.fmax_mhz, 117.25);
    assert_eq!(
        r.cells,
        vec![
            ("ICESTORM_LC".to_string(), 263, 7680),
            ("ICESTORM_RAM".into(), 3, 32)
        ]
    );
    // Gowin's names: LUT1-LUT4 are LUTs, every DFF* a flip-flop
    let report = r#"{"fmax": {"clk": {"achieved": 133.5}},
        "utilization": {"LUT4": {"available": 8640, "used": 220}, "BSRAM": {"available": 26, "used": 3}}}"#;
    let stat: Vec<(String, u64)> = [
        ("LUT1", 9),
        ("LUT3", 50),
        ("DFFRE", 45),
        ("DFF", 28),
        ("ALU", 34),
    ]
    .map(|(c, n)| (c.to_string(), n))
    .to_vec();
    let r = parse(Fpga::Gw1n9, report, &stat).unwrap();
    assert_eq!((r.lcs, r.brams, r.lut4, r.dff), (220, 3, 59, 73));
}

#[test]
fn median_of_seeds_is_the_middle_run() {
    let run = |f| Synth {
        fpga: Fpga::Ice40Hx8k,
        cells: vec![],
        lcs: 1,
        lut4: 1,
        dff: 1,
        brams: 0,
        fmax_mhz: f,
    };
    assert_eq!(
        median_fmax(&[run(150.0), run(120.0), run(170.0)]),
        Some(150.0)
    );
    assert_eq!(median_fmax(&[run(100.0), run(120.0)]), Some(110.0));
    assert_eq!(median_fmax(&[]), None);
    assert_eq!(anchor("eskin34").map(|a| a.lcs), Some(166));
    assert!(anchor("softslip1k").is_none());
}

#[test]
fn a_report_that_cannot_be_parsed_is_an_error_not_zero_cells() {
    // a nextpnr whose report changed its words: no ICESTORM_LC
    let report = r#"{"fmax": {"clk": {"achieved": 98.5}},
        "utilization": {"LOGIC_CELLS": {"available": 7680, "used": 263}}}"#;
    let e = parse(Fpga::Ice40Hx8k, report, &[]).unwrap_err();
    assert!(
        e.contains("ICESTORM_LC") && e.contains("could not be parsed"),
        "{e}"
    );
    let no_fmax = r#"{"fmax": {}, "utilization": {"ICESTORM_LC": {"available": 7680, "used": 263},
        "ICESTORM_RAM": {"available": 32, "used": 3}}}"#;
    assert!(parse(Fpga::Ice40Hx8k, no_fmax, &[])
        .unwrap_err()
        .contains("Fmax"));
    assert!(parse(Fpga::Ecp5_25k, "Info: not JSON", &[]).is_err());
}
