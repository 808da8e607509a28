use measure::for_tests::{alias, peak, spectrum};

#[test]
fn a_tone_above_nyquist_peaks_at_its_alias() {
    let fs = 1000.0;
    let x: Vec<(f64, f64)> = (0..200)
        .map(|i| {
            let t = i as f64 / fs;
            (t, 100.0 * (2.0 * std::f64::consts::PI * 600.0 * t).sin())
        })
        .collect();
    let s = spectrum(&x, fs, 501);
    let (f, a) = peak(&s).unwrap();
    assert_eq!(f, 400.0);
    assert!((a - 100.0).abs() < 1.0, "{a}");
    assert_eq!(alias(600.0, 1000.0), 400.0);
    assert_eq!(alias(300.0, 1000.0), 300.0);
    assert_eq!(alias(2600.0, 1000.0), 400.0);
}
