//! Random feasible mixes: the checker passes the model's pins and hdl's
//! RtlSim, and catches every injected fault.

use std::path::Path;

use judge::{run_dut, ModelDut, RunOptions};
use judge::{FaultyDut, PinFault};

/// The twin with the slot decoding by logic, as a judge DUT.
struct Logic(hdl::RtlSim);

impl judge::Dut for Logic {
    fn step(&mut self, rst: bool, miso: u64) -> lut_gen::Pins {
        self.0.step(rst, miso)
    }
}

/// Twelve seeds in the default suite at 12 MHz, a quarter of the shape's
/// 48 MHz cycles (every run's cost is its cycles: the model's, rust-hdl's,
/// the checker's); the same twelve at 48 MHz and 28 more in `make
/// test-long`.
#[test]
fn random_feasible_mixes() {
    random_feasible_mixes_from(0..12, 12_000_000);
}

#[test]
#[ignore = "long: make test-long"]
fn random_feasible_mixes_40_seeds() {
    random_feasible_mixes_from(0..40, campaign::Shape::default().clock_hz);
}

fn random_feasible_mixes_from(seeds: std::ops::Range<u64>, clock_hz: u64) {
    let drawn = (seeds.end - seeds.start) as usize;
    let mut tested = 0;
    let shape = campaign::Shape {
        clock_hz,
        ..campaign::Shape::default()
    };
    for seed in seeds {
        let text = campaign::random_mix(seed, &shape);
        let Ok(mix) = lut_gen::parse(Path::new("rand.toml"), &text) else {
            continue;
        };
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        // branches without channels are not interesting here
        if (0..s.branches.len()).any(|b| s.branch_instants_in_frame(b).is_empty()) {
            continue;
        }
        tested += 1;
        let opts = RunOptions::default();
        let r = run_dut(&s, &mut ModelDut::new(&s), 2, &opts, "model", None);
        assert!(r.ok, "seed {seed}:\n{text}\n{}", r.summary());
        assert_eq!(r.samples, 2 * s.samples_per_frame() - s.startup_skips());
        let m = engines::run(
            &s,
            engines::Backend::Model,
            10,
            &engines::SimOptions::default(),
        )
        .unwrap();
        assert!(m.ok, "seed {seed}: {}", m.summary());
        if let Ok(mut dut) = engines::RustHdlDut::new(&s) {
            let r = run_dut(&s, &mut dut, 2, &opts, "rusthdl", None);
            assert!(r.ok, "seed {seed} rusthdl:\n{text}\n{}", r.summary());
        }
        // the slot decoding by logic (hdl/DESIGN.md, "Slot LUT"), forced
        // whether or not it is the cheaper form for this mix
        if let Ok(sim) = hdl::RtlSim::with_form(&s, hdl::LutForm::Logic) {
            let r = run_dut(&s, &mut Logic(sim), 2, &opts, "rusthdl-logic", None);
            assert!(r.ok, "seed {seed} logic:\n{text}\n{}", r.summary());
        }
        let at = s.grid.frame_cycles / 3 + 11;
        for f in PinFault::all(&s) {
            let mut dut = FaultyDut::new(&s, ModelDut::new(&s), f, at);
            let r = run_dut(&s, &mut dut, 2, &opts, "faulty", None);
            // a fault that found nothing to change (e.g. no idle slot to move
            // a conversion into) was not injected: nothing to catch
            if !dut.injected() {
                continue;
            }
            // A mux switching two cycles early is only an invariant violation when settling takes longer.
            let invariant_visible = match f {
                PinFault::MuxLate { branch } => s.branches[branch].settle_cycles > 2,
                _ => true,
            };
            assert!(
                r.divergence_count > 0,
                "seed {seed}: fault {} missed by the model\n{text}\n{}",
                f.name(),
                r.summary()
            );
            assert!(
                !invariant_visible || r.violation_count > 0,
                "seed {seed}: fault {} missed by the invariants\n{text}\n{}",
                f.name(),
                r.summary()
            );
        }
    }
    assert!(
        tested * 4 >= drawn,
        "only {tested} of {drawn} random mixes were feasible"
    );
}
