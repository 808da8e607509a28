use campaign::{random_mix, Shape};

/// The random mixes around a preset with many channels on few branches
/// are mixes (they parse), so the schedulability chart has points.
#[test]
fn mixes_around_the_reference_design_parse() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../mixes/eskin34.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let mix = lut_gen::parse(&path, &text).unwrap();
    let shape = Shape::around(&mix, 423);
    assert_eq!(parsed(&shape, 20), 20);
}

/// Of the random mixes of seeds `1..=n` drawn from `shape`, those that parse.
fn parsed(shape: &Shape, n: u64) -> usize {
    (1..=n)
        .filter(|&seed| {
            let text = random_mix(seed, shape);
            lut_gen::parse(std::path::Path::new("random.toml"), &text).is_ok()
        })
        .count()
}

/// Around a mix with modes (the schedule's mix, whose rates are its reset
/// mode's: `cmd-ahead-modes` leaves two channels out of it at 0 Hz), the
/// random mixes are mixes too: no rate of 0 is drawn.
#[test]
fn mixes_around_a_mode_mix_draw_no_rate_of_zero() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../testkit/mixes/cmd-ahead-modes.toml");
    let s = lut_gen::synthesize(&lut_gen::load(&path).unwrap()).unwrap();
    assert!(s.mix.channels.iter().any(|c| c.rate_hz == 0));
    let shape = Shape::around(&s.mix, 512);
    assert!(!shape.rates_hz.contains(&0), "{:?}", shape.rates_hz);
    assert_eq!(parsed(&shape, 20), 20);
}
