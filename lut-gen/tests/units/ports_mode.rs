use lut_gen::{manifest, Dir, Layout, Schedule};

fn schedule(name: &str) -> Schedule {
    lut_gen::synthesize(&crate::common::testkit(name)).unwrap()
}

fn doc(s: &Schedule) -> serde_json::Value {
    serde_json::from_str(&manifest(s)).unwrap()
}

#[test]
fn pin_select_has_mode_sel_and_mode_as_wide_as_the_modes_need() {
    let s = schedule("modes-pin");
    let l = Layout::new(&s);
    assert_eq!(l.mode_bits, 1);
    let names: Vec<&str> = l.mode_ports().iter().map(|p| p.name).collect();
    assert_eq!(names, ["mode_sel", "mode"]);
    let d = doc(&s);
    assert_eq!(d["mode"]["select"], "pin");
    assert_eq!(d["mode"]["sel"], "mode_sel");
    assert_eq!(d["mode"]["mode"], "mode");
    assert_eq!(d["mode"]["bits"], 1);
    assert_eq!(d["mode"]["names"], serde_json::json!(["fast", "slow"]));
    let ports = d["ports"].as_array().unwrap();
    let last: Vec<_> = ports[ports.len() - 2..]
        .iter()
        .map(|p| (p["name"].clone(), p["dir"].clone(), p["width"].clone()))
        .collect();
    assert_eq!(last[0], ("mode_sel".into(), "in".into(), 1.into()));
    assert_eq!(last[1], ("mode".into(), "out".into(), 1.into()));
    assert_eq!(
        l.mode_port_bits(),
        [
            ("mode_sel[0]".to_string(), Dir::In),
            ("mode[0]".to_string(), Dir::Out)
        ]
    );
    // a board places them: they end the port bits
    assert!(l.bits().ends_with(&l.mode_port_bits()));
}

#[test]
fn auto_select_has_only_mode_and_three_modes_take_two_bits() {
    let s = schedule("modes-auto");
    let l = Layout::new(&s);
    assert_eq!((l.mode_bits, l.mode_ports().len()), (2, 1));
    let d = doc(&s);
    assert_eq!(d["mode"]["select"], "auto");
    assert!(d["mode"].get("sel").is_none());
    assert_eq!(d["ports"].as_array().unwrap().last().unwrap()["width"], 2);
}

#[test]
fn a_mix_without_modes_keeps_its_ports() {
    for name in ["tiny", "mutants", "every_slot", "cnvmix2ms"] {
        let s = schedule(name);
        let l = Layout::new(&s);
        assert!(
            l.mode_ports().is_empty() && l.mode_port_bits().is_empty(),
            "{name}"
        );
        assert!(doc(&s).get("mode").is_none(), "{name}");
    }
}
