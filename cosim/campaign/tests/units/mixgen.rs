use campaign::{random_mix, Shape};

/// The random mixes around a preset with many channels on few branches
/// are mixes (they parse), so the schedulability chart has points.
#[test]
fn mixes_around_the_reference_design_parse() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../mixes/eskin34.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let mix = lut_gen::parse(&path, &text).unwrap();
    let shape = Shape::around(&mix, 423);
    let parsed = (1..=20)
        .filter(|&seed| {
            lut_gen::parse(
                std::path::Path::new("random.toml"),
                &random_mix(seed, &shape),
            )
            .is_ok()
        })
        .count();
    assert_eq!(parsed, 20);
}
