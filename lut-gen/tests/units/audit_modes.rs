use lut_gen::for_tests::compact;

#[test]
fn runs_of_names_read_as_the_bulk_syntax() {
    let n = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    assert_eq!(
        compact(&n(&["CH1", "CH2", "CH3", "X", "T0", "T1"])),
        "CH{1..3},X,T0,T1"
    );
    assert_eq!(compact(&n(&["A01", "A02", "A03"])), "A01,A02,A03");
    assert_eq!(compact(&n(&["C9", "C10", "C11", "C13"])), "C{9..11},C13");
}
