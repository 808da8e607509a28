use lut_gen::{manifest, Layout, Pins, Role, Signal, PORTS};

#[test]
fn roles_index_the_table() {
    for (i, r) in Role::ALL.iter().enumerate() {
        assert_eq!(PORTS[i].role, *r);
        assert_eq!(*r as usize, i);
    }
    let mut names: Vec<&str> = PORTS.iter().map(|p| p.name).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), PORTS.len(), "port names are unique");
}

#[test]
fn lanes_and_bits_follow_the_widths() {
    let m = lut_gen::parse(
        std::path::Path::new("t.toml"),
        include_str!("../../../mixes/eskin34.toml"),
    )
    .unwrap();
    let s = lut_gen::synthesize(&m).unwrap();
    let l = Layout::new(&s);
    let total: u32 = l.port_widths().iter().sum();
    assert_eq!(l.bits().len() as u32, total);
    assert_eq!(l.lane(Role::MuxSel, 1), "mux_sel[5:3]");
    assert_eq!(l.lane(Role::CsN, 2), "adc_cs_n[2]");
    let (hi, lo) = l.lane_bits(Role::MuxEn, l.branches - 1);
    assert_eq!(hi + 1, l.mux_devices);
    assert!(lo <= hi);
}

/// A mix with a listening branch between two converters that take a
/// command word: `adc_mosi` has one bit per commanded branch, in branch
/// order, and `ports.json` names each one's lane and word.
#[test]
fn commanded_branches_have_a_mosi_lane() {
    let text = "name = \"cmd\"\n[clock]\nhz = 48000000\n[frame]\nperiod_us = 1000\n\
                slice_us = 1000\n\
                [[branch]]\nname = \"m\"\nadc = \"mcp3208\"\nmux = \"internal\"\n\
                [[branch]]\nname = \"l\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n\
                [[branch]]\nname = \"a\"\nadc = \"ad7689\"\nmux = \"internal\"\n\
                [[channel]]\nname = \"x\"\nbranch = \"m\"\nrate_hz = 1000\ninput = 3\n\
                [[channel]]\nname = \"y\"\nbranch = \"l\"\nrate_hz = 1000\n\
                [[channel]]\nname = \"z\"\nbranch = \"a\"\nrate_hz = 2000\ninput = 5\n";
    let m = lut_gen::parse(std::path::Path::new("cmd.toml"), text).unwrap();
    let s = lut_gen::synthesize(&m).unwrap();
    // the gateware drives adc_mosi: the mix fits
    assert_eq!(Layout::fits(&s), Ok(()));
    let l = Layout::new(&s);
    assert_eq!(l.mosi_lo, vec![Some(0), None, Some(1)]);
    assert_eq!(l.width(Role::Mosi), 2);
    assert_eq!(l.lane(Role::Mosi, 2), "adc_mosi[1]");
    assert_eq!(l.muxed, vec![false, true, false]);
    let total: u32 = l.port_widths().iter().sum();
    assert_eq!(l.bits().len() as u32, total);
    let p = Pins {
        mosi: 0b10,
        ..Pins::default()
    };
    assert!(!l.mosi(&p, 0) && !l.mosi(&p, 1) && l.mosi(&p, 2));
    assert_eq!(Signal::Mosi(2).get(&l, &p), 1);
    assert!(!l.signals().contains(&Signal::Mosi(1)));
    let j: serde_json::Value = serde_json::from_str(&manifest(&s)).unwrap();
    assert_eq!(j["branches"][0]["mosi"], "adc_mosi[0]");
    assert_eq!(j["branches"][2]["command"], "1111CCC1001001");
    assert_eq!(j["branches"][2]["command_ahead"], 2);
    assert!(j["branches"][1].get("mosi").is_none());
    // A mix without a commanded converter has no `adc_mosi` at all.
    let plain = lut_gen::parse(
        std::path::Path::new("cnvmix.toml"),
        include_str!("../../../hdl/tests/data/cnvmix.toml"),
    )
    .unwrap();
    let l = Layout::new(&lut_gen::synthesize(&plain).unwrap());
    assert!(!l.has(Role::Mosi));
    assert!(l.ports().all(|p| p.role != Role::Mosi));
}

/// cnvmix: branch 1 (`lone`, `mux = "none"`) between two branches with a
/// mux has no mux lanes; branch 2's lanes follow branch 0's directly.
#[test]
fn a_branch_without_a_mux_has_no_mux_lanes() {
    let m = lut_gen::parse(
        std::path::Path::new("cnvmix.toml"),
        include_str!("../../../hdl/tests/data/cnvmix.toml"),
    )
    .unwrap();
    let s = lut_gen::synthesize(&m).unwrap();
    let l = Layout::new(&s);
    assert_eq!(l.muxed, vec![true, false, true]);
    assert_eq!(l.width(Role::MuxSel), 6);
    assert_eq!(l.lane(Role::MuxSel, 2), "mux_sel[5:3]");
    assert_eq!(l.lane(Role::MuxEn, 2), "mux_en[1]");
    assert!(!l.lanes(1).any(|r| matches!(r, Role::MuxSel | Role::MuxEn)));
    assert!(!l.signals().contains(&Signal::MuxEn(1)));
    let total: u32 = l.port_widths().iter().sum();
    assert_eq!(l.bits().len() as u32, total);
    // the lone branch always converts its one channel; setting its
    // (absent) mux changes no pin
    let mut p = Pins::default();
    l.set_mux(&mut p, 2, 0, 5);
    let before = p;
    l.set_mux(&mut p, 1, 0, 7);
    assert_eq!(p, before);
    assert_eq!(l.sel(&p, 2), 5);
    assert_eq!(
        l.selected(&p, 1)
            .map(|c| m.channels[c as usize].name.clone()),
        Ok("LONE".into())
    );
    let j: serde_json::Value = serde_json::from_str(&manifest(&s)).unwrap();
    let lone = &j["branches"][1];
    assert!(lone.get("mux_sel").is_none() && lone.get("mux_en").is_none());
    assert_eq!(lone["cnv"], "adc_cs_n[1]");
    assert_eq!(j["branches"][2]["mux_sel"], "mux_sel[5:3]");
}
