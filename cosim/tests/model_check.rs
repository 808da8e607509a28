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
