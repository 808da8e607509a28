use lut_gen::lut::CompactLut;
use measure::for_tests::MAX_COLUMNS;
use measure::{interval_table, slot_table};

/// A mode mix run through a switch and back: the intervals table has a
/// row per mode, branch and rate, each row's promised interval is the
/// audit's for that mode and channel, and a jitter-free run shows no
/// jitter (the figures spanning both modes showed the switch's gap).
#[test]
fn a_mode_mixs_intervals_are_each_modes_own_and_jitter_free() {
    let path = testkit::mix("modes-pin");
    let mix = lut_gen::load(&path).unwrap();
    let s = lut_gen::synthesize(&mix).unwrap();
    let r = lut_gen::AuditReport::of_schedule(&s);
    let mut dut = judge::ModeRequests::new(&s, judge::ModelDut::new(&s), &[(1, 1), (5, 0)]);
    let v = judge::run_dut(
        &s,
        &mut dut,
        9,
        &judge::RunOptions::default(),
        "model",
        None,
    );
    assert!(v.ok, "{}", v.summary());
    let t = interval_table(&s, &v);
    assert_eq!(t.columns[0], "mode");
    let mut modes_seen = std::collections::BTreeSet::new();
    for row in &t.rows {
        let m = r.modes.iter().find(|m| m.name == row[0]).unwrap();
        modes_seen.insert(row[0].clone());
        for name in row[3].split(", ") {
            let c = m.channels.iter().find(|c| c.name == name).unwrap();
            assert_eq!(row[2], c.rate_hz.to_string(), "{row:?}");
            assert_eq!(row[5], c.interval_cycles.to_string(), "{row:?}");
        }
        assert_eq!(row[7], "0", "{row:?}");
    }
    assert_eq!(modes_seen.len(), r.modes.len());
}

/// 20 slices and fewer rotation groups: a row per slice, a column per
/// group (a column per slice, 21 wide, overflowed the report's page).
#[test]
fn many_slices_give_the_rotation_table_a_row_per_slice() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/skin28.toml");
    let mix = lut_gen::parse(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
    let s = lut_gen::synthesize(&mix).unwrap();
    let tables = slot_table(&s);
    let (_, rot) = tables.last().unwrap();
    let csv = rot.csv();
    let head = csv.lines().next().unwrap();
    assert!(head.starts_with("slice,R0"), "{head}");
    let groups = CompactLut::from_schedule(&s).rotations.len();
    assert!(groups < s.grid.slices_per_frame as usize);
    assert_eq!(head.split(',').count(), 1 + groups, "{head}");
    assert_eq!(csv.lines().count(), 1 + s.grid.slices_per_frame as usize);
}

/// A frame of many slices and many rotation groups: neither layout
/// fits the page, so each group is one row listing its channels.
#[test]
fn rotation_groups_wider_than_the_page_become_lists() {
    let mut text = String::from(
        "name = \"t\"\n[clock]\nhz = 4_000_000\n[frame]\nperiod_us = 20_000\nslice_us = 1_000\n",
    );
    for b in 0..12 {
        text += &format!(
            "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 3\n"
        );
    }
    for b in 0..12 {
        for k in 0..20 {
            text += &format!("[[channel]]\nname = \"C{b}_{k}\"\nbranch = \"b{b}\"\nrate_hz = 50\n");
        }
    }
    let mix = lut_gen::parse(std::path::Path::new("t.toml"), &text).unwrap();
    let s = lut_gen::synthesize(&mix).unwrap();
    let lut = CompactLut::from_schedule(&s);
    assert!(lut.rotations.len() >= MAX_COLUMNS && s.grid.slices_per_frame as usize >= MAX_COLUMNS);
    let tables = slot_table(&s);
    let (_, rot) = tables.last().unwrap();
    assert_eq!(rot.columns.len(), 2, "{:?}", rot.columns);
    assert_eq!(rot.rows.len(), lut.rotations.len());
    // every rotating channel is named once, in its group's row
    let all: String = rot.rows.iter().map(|r| r[1].clone() + ", ").collect();
    assert!(all.contains("C0_0,") && all.contains("C11_19,"), "{all}");
    assert!(tables.iter().all(|t| t.1.columns.len() <= MAX_COLUMNS));
}
