use measure::short_names as bulk;

#[test]
fn runs_of_numbered_names_are_written_as_bulk_patterns() {
    assert_eq!(
        bulk(&["CH1", "CH2", "CH3", "CH5", "CH6", "T0", "T1", "T2", "T3"]),
        "CH{1..3},CH5,CH6,T{0..3}"
    );
    assert_eq!(bulk(&["A01", "A02", "A03"]), "A01,A02,A03");
    for written in bulk(&["CH1", "CH2", "CH3", "X"]).split(',') {
        assert!(lut_gen::expand_names(written).is_ok(), "{written}");
    }
}
