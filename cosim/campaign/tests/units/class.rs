use campaign::{FaultClass, Level};
use hdl::GatewareFault;
use judge::PinFault;

/// One name per class: the judge's names of its pin faults and `hdl`'s
/// of the link stage's are the campaign's.
#[test]
fn class_names_are_the_judges_and_hdls() {
    for name in ["eskin34-uart", "eskin34-axis"] {
        let mix = testkit::root().join(format!("mixes/{name}.toml"));
        let s = lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap();
        let pins = PinFault::all(&s);
        assert!(pins.iter().any(|f| FaultClass::of_pins(*f).on_link()));
        for f in pins {
            assert_eq!(FaultClass::of_pins(f).name(), f.class(), "{f:?}");
        }
        for (class, f) in GatewareFault::link_faults(&s) {
            assert_eq!(FaultClass::of_gateware(f).name(), class, "{f:?}");
        }
    }
    assert_eq!(format!("{:<6}|", Level::Pins), "pins  |");
    assert_eq!(format!("{:<12}|", FaultClass::CsLate), "cs-late     |");
}
