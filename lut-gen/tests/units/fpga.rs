use lut_gen::Fpga;

#[test]
fn parts_and_families_parse_to_the_same_part_and_others_are_refused() {
    for f in Fpga::ALL {
        assert_eq!(Fpga::parse(f.name()), Ok(f));
        assert_eq!(Fpga::parse(f.family().name()), Ok(f));
        assert_eq!(Fpga::parse(&f.name().to_uppercase()), Ok(f));
    }
    let e = Fpga::parse("xc7a35t").unwrap_err();
    assert!(e.contains("xc7a35t") && e.contains("ecp5-25k"), "{e}");
}
