//! Random mixes with converters that take a command word
//! (`campaign::Shape::commanded`, a mix no test was written for): the
//! rust-hdl twin of the gateware equals the judge's cycle model in every
//! pin of every cycle (`adc_mosi` included), and the emitted Verilog reads
//! as blocks (the command units named in the header) and lints clean.

use std::path::Path;

use judge::{Adc, Dut, ModelDut, Stimulus};
use lut_gen::Schedule;

/// Feasible random mixes with at least one commanded branch.
fn commanded_mixes(count: usize) -> Vec<(u64, Schedule)> {
    let shape = campaign::Shape {
        commanded: 2,
        ..campaign::Shape::default()
    };
    let mut v = vec![];
    for seed in 0..200u64 {
        let text = campaign::random_mix(seed, &shape);
        let Ok(mix) = lut_gen::parse(Path::new("random.toml"), &text) else {
            continue;
        };
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        if (0..s.branches.len()).any(|b| s.has_command(b)) && hdl::emit(&s, None).is_ok() {
            v.push((seed, s));
        }
        if v.len() == count {
            break;
        }
    }
    assert_eq!(v.len(), count, "too few feasible commanded random mixes");
    v
}

#[test]
fn the_twin_equals_the_model_on_random_commanded_mixes() {
    for (seed, s) in commanded_mixes(6) {
        let mut dut = engines::RustHdlDut::new(&s).unwrap();
        let mut model = ModelDut::new(&s);
        let mut adc = Adc::new(&s, Stimulus::Pattern);
        let mut miso = (1u64 << s.branches.len()) - 1;
        let mut mosi = 0;
        for k in 0..2 * s.grid.frame_cycles + 2 {
            let rst = k < 2;
            let (d, m) = (dut.step(rst, miso), model.step(rst, miso));
            assert_eq!(d, m, "seed {seed}: cycle {k} of the run");
            mosi += (d.mosi != 0) as u64;
            miso = adc.drive(k.saturating_sub(2), &d);
        }
        assert!(mosi > 0, "seed {seed}: adc_mosi never high");
    }
}
