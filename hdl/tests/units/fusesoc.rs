use hdl::for_tests::{constraint_kind, vlnv_part};
use lut_gen::Fpga;

#[test]
fn vlnv_parts_keep_what_fusesoc_allows() {
    assert_eq!(vlnv_part("eskin34-axis"), "eskin34-axis");
    assert_eq!(vlnv_part("my mix: v2"), "my_mix__v2");
    assert_eq!(vlnv_part(""), "mix");
}

#[test]
fn constraints_go_to_their_family() {
    assert_eq!(
        constraint_kind("a.pcf"),
        Some(("PCF", Some(Fpga::Ice40Hx8k)))
    );
    assert_eq!(constraint_kind("a.lpf").unwrap().1, Some(Fpga::Ecp5_25k));
    assert_eq!(constraint_kind("a.cst").unwrap().1, Some(Fpga::Gw1n9));
    assert_eq!(constraint_kind("a.hex"), None);
}
