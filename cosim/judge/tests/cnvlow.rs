//! A part read with CNV low (the AD7689): CNV is high for the conversion
//! alone and the word is read while it is low.  The model's pins pass the
//! checker with and without the model; a design that holds CNV high
//! through the read (the part would leave SDO high-impedance and ignore
//! DIN) or lowers it before the conversion ends is caught at the cycle,
//! with the model and by the rules alone.

use judge::{Dut, ModelDut, Rule};
use lut_gen::{Pins, Schedule};

fn shared(name: &str) -> Schedule {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes");
    lut_gen::synthesize(&lut_gen::load(&dir.join(format!("{name}.toml"))).unwrap()).unwrap()
}

/// The branches read with CNV low.
fn low_branches(s: &Schedule) -> Vec<usize> {
    (0..s.branches.len())
        .filter(|&b| s.mix.branches[b].adc.read == lut_gen::CnvRead::CnvLow)
        .collect()
}

/// Branch `b`'s CNV from each rise held high for `hold` cycles (the read's
/// length: the held read; or fewer: CNV falling early).
struct Hold<D> {
    dut: D,
    b: usize,
    hold: u64,
    prev: bool,
    left: u64,
}
impl<D: Dut> Dut for Hold<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        let mut p = self.dut.step(rst, miso);
        let bit = 1u16 << self.b;
        let now = p.cs_n & bit != 0;
        if now && !self.prev && !rst {
            self.left = self.hold;
        }
        self.prev = now;
        if self.left > 0 {
            self.left -= 1;
            p.cs_n |= bit;
        } else {
            p.cs_n &= !bit;
        }
        p
    }
}

fn judged<D: Dut>(s: &Schedule, dut: &mut D, model: bool) -> judge::Verdict {
    let opts = judge::RunOptions {
        check: judge::CheckOptions {
            model,
            ..Default::default()
        },
        ..Default::default()
    };
    judge::run_dut(s, dut, 2, &opts, "test", None)
}

fn has(v: &judge::Verdict, rule: Rule) -> bool {
    v.violations.iter().any(|x| x.rule == rule.as_str())
}

#[test]
fn the_ad7689_is_read_with_cnv_low_and_passes() {
    for name in ["cmd-ad7689", "cmd-both"] {
        let s = shared(name);
        let low = low_branches(&s);
        assert!(!low.is_empty(), "{name}: the ad7689 is read with CNV low");
        for &b in &low {
            let spi = &s.branches[b].spi;
            assert_eq!(spi.pin_cycles, spi.conv_cycles);
            assert!(spi.pin_cycles < spi.setup_cycles);
        }
        for model in [true, false] {
            let v = judged(&s, &mut ModelDut::new(&s), model);
            assert!(
                v.ok && v.samples > 0,
                "{name} model {model}: {}",
                v.summary()
            );
        }
    }
}

#[test]
fn cnv_held_through_the_read_is_caught() {
    let s = shared("cmd-ad7689");
    let b = low_branches(&s)[0];
    let spi = s.branches[b].spi;
    let mut dut = Hold {
        dut: ModelDut::new(&s),
        b,
        hold: spi.read_cycles,
        prev: false,
        left: 0,
    };
    let v = judged(&s, &mut dut, false);
    assert!(!v.ok, "{}", v.summary());
    let idle = v
        .violations
        .iter()
        .find(|x| x.rule == Rule::SclkIdle.as_str())
        .expect("SCK toggling while CNV is high");
    assert!(
        idle.detail.contains("only while CNV is low"),
        "{}",
        idle.detail
    );
    let mut dut = Hold {
        dut: ModelDut::new(&s),
        b,
        hold: spi.read_cycles,
        prev: false,
        left: 0,
    };
    let v = judged(&s, &mut dut, true);
    assert!(!v.ok && v.divergence_count > 0, "{}", v.summary());
}

#[test]
fn cnv_falling_before_the_conversion_ends_is_caught() {
    let s = shared("cmd-ad7689");
    let b = low_branches(&s)[0];
    let spi = s.branches[b].spi;
    let mut dut = Hold {
        dut: ModelDut::new(&s),
        b,
        hold: spi.pin_cycles - 1,
        prev: false,
        left: 0,
    };
    let v = judged(&s, &mut dut, false);
    assert!(has(&v, Rule::CsSetup), "{}", v.summary());
    assert!(!has(&v, Rule::SclkIdle), "{}", v.summary());
}
