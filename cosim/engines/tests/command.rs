//! Converters with a command word on the gateware: every pin of the
//! rust-hdl twin and of the emitted Verilog (Verilator) equals the judge's
//! cycle model in every cycle (docs/timing.md, "Command words": `adc_mosi`
//! bit for bit, and no sample from a prepared conversion), on the test
//! mixes and on random mixes with commanded branches.

use engines::{RustHdlDut, VerilatedDut};
use judge::{Adc, Dut, ModelDut, Stimulus};
use lut_gen::{Pins, Schedule};

use crate::tools;

fn schedule(name: &str) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(&testkit::mix(name)).unwrap()).unwrap()
}

/// A small deterministic generator (random mixes of commanded branches).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self, n: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) % n
    }
}

/// One to three branches drawn from the two commanded parts and a
/// listening one, channels on random inputs at random harmonic rates.
fn random_mix(seed: u64) -> Schedule {
    let mut r = Lcg(seed * 104_729 + 7);
    let clock = [48_000_000u64, 24_000_000, 40_000_000][r.next(3) as usize];
    let mut t = format!(
        "name = \"cmd{seed}\"\n[clock]\nhz = {clock}\n[frame]\nperiod_us = 1000\nslice_us = 500\n"
    );
    let parts = [
        ("mcp3208", "internal"),
        ("ad7689", "internal"),
        ("ad7940", "tmux1108"),
    ];
    let nb = 1 + r.next(3);
    let mut chosen = vec![];
    for b in 0..nb {
        // at least one commanded branch
        let (adc, mux) = parts[if b == 0 { r.next(2) } else { r.next(3) } as usize];
        t += &format!("[[branch]]\nname = \"b{b}\"\nadc = \"{adc}\"\nmux = \"{mux}\"\n");
        chosen.push(adc);
    }
    let mut n = 0;
    for (b, adc) in chosen.iter().enumerate() {
        let mut inputs: Vec<u64> = (0..8).collect();
        let rates: &[u64] = if *adc == "mcp3208" {
            &[1000, 2000, 4000]
        } else {
            &[1000, 2000, 4000, 8000]
        };
        for _ in 0..1 + r.next(4) {
            let input = inputs.remove(r.next(inputs.len() as u64) as usize);
            let rate = rates[r.next(rates.len() as u64) as usize];
            t += &format!(
                "[[channel]]\nname = \"c{n}\"\nbranch = \"b{b}\"\nrate_hz = {rate}\ninput = {input}\n"
            );
            n += 1;
        }
    }
    let m = lut_gen::parse(std::path::Path::new("cmd.toml"), &t).unwrap();
    lut_gen::synthesize(&m).unwrap_or_else(|e| panic!("seed {seed}: {e:?}\n{t}"))
}

/// The first cycle at which `dut`'s pins differ from the model's, in
/// `frames` frames under the ADC model (fed the DUT's pins); the number of
/// samples and of `adc_mosi` high cycles seen.
fn first_difference<D: Dut>(s: &Schedule, dut: &mut D, frames: u64) -> (Option<String>, u64, u64) {
    let mut model = ModelDut::new(s);
    let mut adc = Adc::new(s, Stimulus::Pattern);
    let mut miso = (1u64 << s.branches.len()) - 1;
    let (mut samples, mut mosi) = (0, 0);
    let cmp = |c: i64, d: &Pins, m: &Pins| {
        (d != m).then(|| format!("cycle {c}: gateware {d:?}\nmodel    {m:?}"))
    };
    for k in 0..2 {
        let (d, m) = (dut.step(true, miso), model.step(true, miso));
        if let Some(e) = cmp(k - 2, &d, &m) {
            return (Some(e), samples, mosi);
        }
        miso = adc.drive(0, &d);
    }
    for c in 0..frames * s.grid.frame_cycles {
        let (d, m) = (dut.step(false, miso), model.step(false, miso));
        if let Some(e) = cmp(c as i64, &d, &m) {
            return (Some(e), samples, mosi);
        }
        samples += d.sample_valid as u64;
        mosi += (d.mosi != 0) as u64;
        miso = adc.drive(c, &d);
    }
    (None, samples, mosi)
}

fn assert_same<D: Dut>(what: &str, s: &Schedule, dut: &mut D, frames: u64) {
    let (diff, samples, mosi) = first_difference(s, dut, frames);
    if let Some(e) = diff {
        panic!("{what}: {e}");
    }
    let prepared: u64 = (0..s.branches.len())
        .map(|b| s.prepared_conversions(b) as u64)
        .sum();
    let skipped = s.startup_skips();
    assert_eq!(
        samples,
        frames * s.samples_per_frame() - skipped - prepared,
        "{what}: samples"
    );
    assert!(mosi > 0, "{what}: adc_mosi never high");
}

#[test]
fn rusthdl_drives_the_command_words_of_the_test_mixes() {
    for name in ["cmd-mcp3208", "cmd-ad7689", "cmd-both"] {
        let s = schedule(name);
        assert_same(name, &s, &mut RustHdlDut::new(&s).unwrap(), 3);
    }
}

#[test]
fn rusthdl_drives_the_command_words_of_random_mixes() {
    for seed in 0..10 {
        let s = random_mix(seed);
        let what = format!("random commanded mix {seed}");
        assert_same(&what, &s, &mut RustHdlDut::new(&s).unwrap(), 2);
    }
}

#[test]
fn verilator_drives_the_command_words() {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let mut mixes: Vec<(String, Schedule)> = ["cmd-mcp3208", "cmd-ad7689", "cmd-both"]
        .iter()
        .map(|n| (n.to_string(), schedule(n)))
        .collect();
    mixes.extend((0..3).map(|k| (format!("random commanded mix {k}"), random_mix(k))));
    for (what, s) in mixes {
        let v = engines::verilog(&s).unwrap();
        let (mut dut, _) = VerilatedDut::new(&v).unwrap();
        assert_same(&what, &s, &mut dut, 2);
    }
}
