//! Random feasible mixes: the checker passes the model's pins and hdl's
//! RtlSim, and catches every injected fault.

use std::fmt::Write;
use std::path::Path;

use judge::faults::{Fault, FaultyDut};
use judge::run::{run_dut, ModelDut, RunOptions};

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn pick<T: Copy>(&mut self, v: &[T]) -> T {
        v[(self.next() % v.len() as u64) as usize]
    }
}

/// A mix of 1-3 branches with 2 ms frames and a few channels per branch.
fn random_mix(seed: u64) -> String {
    let mut r = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let nb = 1 + r.next() % 3;
    let mut t = String::from(
        "name = \"rand\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 2_000\nslice_us = 1_000\n",
    );
    let mut devs = Vec::new();
    for b in 0..nb {
        let d = 1 + r.next() % 3;
        devs.push(d);
        let sclk = r.pick(&[2_500_000u64, 1_000_000, 2_000_000]);
        let settle = r.pick(&[0u64, 1_000, 2_000, 5_000]);
        let _ = write!(t, "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nsclk_hz = {sclk}\nmux = \"tmux1108\"\nmux_devices = {d}\nsettle_ns = {settle}\n");
    }
    let n = 2 + r.next() % 8;
    let mut used = std::collections::HashSet::new();
    for i in 0..n {
        let b = r.next() % nb;
        let input = r.next() % (devs[b as usize] * 8);
        if !used.insert((b, input)) {
            continue;
        }
        let rate = r.pick(&[500u64, 1_000, 2_000, 4_000, 8_000]);
        let _ = write!(
            t,
            "[[channel]]\nname = \"c{i}\"\nbranch = \"b{b}\"\nrate_hz = {rate}\ninput = {input}\n"
        );
    }
    t
}

#[test]
fn random_feasible_mixes() {
    let mut tested = 0;
    for seed in 0..40u64 {
        let text = random_mix(seed);
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
        let m = cosim::run(&s, cosim::Backend::Model, 10, &cosim::SimOptions::default()).unwrap();
        assert!(m.ok, "seed {seed}: {}", m.summary());
        if let Ok(mut dut) = cosim::RustHdlDut::new(&s) {
            let r = run_dut(&s, &mut dut, 2, &opts, "rusthdl", None);
            assert!(r.ok, "seed {seed} rusthdl:\n{text}\n{}", r.summary());
        }
        let at = s.grid.frame_cycles / 3 + 11;
        for f in Fault::all(&s) {
            let mut dut = FaultyDut::new(&s, ModelDut::new(&s), f, at);
            let r = run_dut(&s, &mut dut, 2, &opts, "faulty", None);
            // A mux switching two cycles early is only an invariant violation when settling takes longer.
            let invariant_visible = match f {
                Fault::MuxLate { branch } => s.branches[branch].settle_cycles > 2,
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
    assert!(tested >= 10, "only {tested} random mixes were feasible");
}
