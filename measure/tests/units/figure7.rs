use measure::for_tests::{alias, where_aliasing_puts_it};

#[test]
fn an_apparent_frequency_off_its_alias_fails_the_step() {
    // 1.3 x 1 kHz folds to 300 Hz
    let want = alias(1300.0, 1000.0);
    assert!((want - 300.0).abs() < 1e-9, "{want}");
    assert!(where_aliasing_puts_it(1300.0, 1000.0, 302.0, want).is_ok());
    let e = where_aliasing_puts_it(1300.0, 1000.0, 1300.0 - 1000.0 + 50.0, want).unwrap_err();
    assert!(
        e.contains("appears at 350 Hz") && e.contains("300 Hz"),
        "{e}"
    );
}
