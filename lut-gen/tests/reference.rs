//! The reference design (the paper's e-skin) must reproduce the paper's Table 1.

use std::path::Path;

fn eskin() -> lut_gen::Schedule {
    let mix = lut_gen::load(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../mixes/eskin34.toml"
    )))
    .unwrap();
    lut_gen::synthesize(&mix).unwrap()
}

#[test]
fn eskin34_reproduces_table_1() {
    let s = eskin();
    assert_eq!(s.grid.slots_per_slice, 30);
    assert_eq!(s.grid.slot_cycles, 1600);
    assert_eq!(s.samples_per_frame(), 349);
    assert_eq!(s.mix.channels.len(), 41);
    let acoustic = s.mix.branch_index("acoustic").unwrap();
    let ch35 = s.mix.channel_index("CH35").unwrap();
    let ch36 = s.mix.channel_index("CH36").unwrap();
    for slice in 0..10 {
        let base = slice * 30;
        assert_eq!(s.at(base, acoustic), Some(ch35));
        assert_eq!(s.at(base + 1, acoustic), Some(ch36));
        assert_eq!(s.at(base + 15, acoustic), Some(ch35));
        assert_eq!(s.at(base + 16, acoustic), Some(ch36));
    }
    // The quasi-static channels share slot 0 of the static branch, rotated by slice.
    let stat = s.mix.branch_index("static").unwrap();
    for k in 0..9u64 {
        let ch = s.mix.channel_index(&format!("CH{}", 26 + k)).unwrap();
        assert_eq!(s.at(k * 30, stat), Some(ch));
    }
    assert_eq!(s.at(9 * 30, stat), None);
    lut_gen::validate(&s).unwrap();
}

/// Snapshots of the reference outputs: a change here is reviewed like code
/// (`make update-snapshots`, then read the diff).
#[test]
fn eskin34_audit_and_lut_snapshots() {
    let s = eskin();
    insta::assert_snapshot!(
        "eskin34_audit_json",
        lut_gen::AuditReport::of_schedule(&s).to_json()
    );
    insta::assert_snapshot!(
        "eskin34_audit_text",
        lut_gen::AuditReport::of_schedule(&s).to_text()
    );
    insta::assert_snapshot!("eskin34_slots_md", lut_gen::lut::to_markdown(&s));
    insta::assert_snapshot!("eskin34_slots_csv", lut_gen::lut::to_csv(&s));
    insta::assert_snapshot!("eskin34_slots_hex", lut_gen::lut::to_hex(&s));
}

#[test]
fn compact_lut_expands_to_the_frame_table() {
    let s = eskin();
    let c = lut_gen::lut::CompactLut::from_schedule(&s);
    assert_eq!(c.expand(), s.frame_table);
    assert_eq!(c.rotations.len(), 1);
    assert_eq!(c.entries(), 30 * 3 + 10);
}
