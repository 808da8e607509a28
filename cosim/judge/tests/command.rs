//! Converters with a command word, closed loop: the cycle model drives
//! `adc_mosi`, the ADC model converts the input each word selected (with the
//! part's pipeline), and every sample the model emits is the code of the
//! channel the slot table names at its instant; the prepared conversions
//! after reset are never emitted.  A DUT that sends a wrong channel bit is
//! caught by the same comparison.

use judge::{Adc, Analog, CycleModel, Dut, ModelDut, Stimulus};
use lut_gen::{Pins, Schedule};

/// A small deterministic generator (the judge may not see `campaign`).
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

/// A mix with an `mcp3208` branch, a listening `ad7940` branch and an
/// `ad7689` branch, channels on random inputs at random rates.
fn random_mix(seed: u64) -> Schedule {
    let mut r = Lcg(seed * 7919 + 1);
    let mut t = String::from(
        "name = \"cmd\"\n[clock]\nhz = 48000000\n[frame]\nperiod_us = 1000\nslice_us = 1000\n",
    );
    let branches = [
        ("m", "mcp3208", "internal"),
        ("l", "ad7940", "tmux1108"),
        ("a", "ad7689", "internal"),
    ];
    for (name, adc, mux) in branches {
        t += &format!("[[branch]]\nname = \"{name}\"\nadc = \"{adc}\"\nmux = \"{mux}\"\n");
    }
    let mut n = 0;
    for (name, _, _) in branches {
        let mut inputs: Vec<u64> = (0..8).collect();
        for _ in 0..1 + r.next(4) {
            let input = inputs.remove(r.next(inputs.len() as u64) as usize);
            let rate = [1000, 2000, 4000][r.next(3) as usize];
            t += &format!(
                "[[channel]]\nname = \"c{n}\"\nbranch = \"{name}\"\nrate_hz = {rate}\ninput = {input}\n"
            );
            n += 1;
        }
    }
    let m = lut_gen::parse(std::path::Path::new("cmd.toml"), &t).unwrap();
    lut_gen::synthesize(&m).unwrap()
}

/// Flips bit `bit` of branch `b`'s `adc_mosi` whenever it is sent.
struct WrongBit<D> {
    dut: D,
    lane: u32,
}
impl<D: Dut> Dut for WrongBit<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        let mut p = self.dut.step(rst, miso);
        p.mosi ^= 1 << self.lane;
        p
    }
}

/// (channel, code) of every sample the DUT emits in `frames` frames, per branch.
fn emitted<D: Dut>(s: &Schedule, dut: &mut D, frames: u64) -> Vec<Vec<(u16, u16)>> {
    let mut adc = Adc::new(s, Stimulus::Pattern);
    let mut miso = (1u64 << s.branches.len()) - 1;
    let mut out = vec![Vec::new(); s.branches.len()];
    for _ in 0..3 {
        let p = dut.step(true, miso);
        miso = adc.drive(0, &p);
    }
    for c in 0..frames * s.grid.frame_cycles {
        let p = dut.step(false, miso);
        miso = adc.drive(c, &p);
        if p.sample_valid {
            let b = s.mix.channels[p.sample_channel as usize].branch;
            out[b].push((p.sample_channel, p.sample_value));
        }
    }
    out
}

/// What each branch should emit: its instants in order, past the prepared ones.
fn expected(s: &Schedule, frames: u64) -> Vec<Vec<(u16, u16)>> {
    let analog = Analog::new(s, Stimulus::Pattern);
    let mut want = vec![Vec::new(); s.branches.len()];
    for i in s.instants(frames) {
        let bits = s.mix.branches[i.branch].adc.bits;
        want[i.branch].push((
            i.channel as u16,
            analog.code_bits(i.channel as u64, i.cycle, bits),
        ));
    }
    for (b, w) in want.iter_mut().enumerate() {
        w.drain(..s.prepared_conversions(b) as usize);
    }
    want
}

#[test]
fn every_sample_is_the_channel_its_command_selected() {
    for seed in 0..6 {
        let s = random_mix(seed);
        let frames = 3;
        let got = emitted(&s, &mut ModelDut::new(&s), frames);
        let want = expected(&s, frames);
        for b in 0..s.branches.len() {
            let per_frame = want[b].len() as u64 / frames;
            assert!(!got[b].is_empty(), "seed {seed} branch {b}: no samples");
            assert!(
                got[b].len() as u64 + per_frame >= want[b].len() as u64,
                "seed {seed} branch {b}"
            );
            assert_eq!(got[b], want[b][..got[b].len()], "seed {seed} branch {b}");
        }
        // The model drives adc_mosi exactly on the commanded branches.
        let m = CycleModel::new(&s);
        assert_eq!(m.layout().mosi_lo, vec![Some(0), None, Some(1)]);
    }
}

#[test]
fn a_wrong_channel_bit_is_a_wrong_sample() {
    for seed in 0..3 {
        let s = random_mix(seed);
        let want = expected(&s, 2);
        for (lane, b) in [(0u32, 0usize), (1, 2)] {
            let got = emitted(
                &s,
                &mut WrongBit {
                    dut: ModelDut::new(&s),
                    lane,
                },
                2,
            );
            let n = got[b].len().min(want[b].len());
            assert!(n > 0);
            assert_ne!(
                got[b][..n],
                want[b][..n],
                "seed {seed}: lane {lane} flipped, branch {b} unchanged"
            );
        }
    }
}
