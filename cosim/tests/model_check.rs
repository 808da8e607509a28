use cosim::run::{run_dut, run_model, ModelDut, RunOptions};
use std::path::Path;

fn eskin() -> lut_gen::Schedule {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mixes/eskin34.toml");
    lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap()
}

#[test]
fn model_pins_pass_the_checker() {
    let s = eskin();
    let mut dut = ModelDut::new(&s);
    let r = run_dut(&s, &mut dut, 2, &RunOptions::default(), "model-dut", None);
    eprintln!("{}", r.summary());
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.frames, 2);
    assert_eq!(r.samples, 2 * 349);
}

#[test]
fn slot_model_passes() {
    let s = eskin();
    let r = run_model(&s, 100, cosim::Stimulus::Pattern, 20);
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.samples, 100 * 349);
}

#[test]
fn every_fault_is_caught() {
    use cosim::faults::{Fault, FaultyDut};
    let s = eskin();
    let at = s.grid.frame_cycles / 2 + 7;
    for f in Fault::all(&s) {
        let mut dut = FaultyDut::new(&s, ModelDut::new(&s), f, at);
        let r = run_dut(&s, &mut dut, 2, &RunOptions::default(), "faulty", None);
        assert!(!r.ok, "fault {} not caught", f.name());
        assert!(r.divergence_count > 0, "fault {}: no divergence", f.name());
        assert!(
            r.violation_count > 0,
            "fault {}: no invariant violation\n{}",
            f.name(),
            r.summary()
        );
        let d = &r.divergences[0];
        assert!(
            d.cycle + 2 * s.grid.slot_cycles >= at,
            "fault {} first divergence at {}",
            f.name(),
            d.cycle
        );
        eprintln!(
            "{}: {} divergent cycles, {} violations; first: {} at {} ({:?}), rule {}",
            f.name(),
            r.divergence_count,
            r.violation_count,
            d.signal,
            d.cycle,
            d.channel,
            r.violations[0].rule
        );
    }
}
