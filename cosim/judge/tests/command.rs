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
            analog.code_bits(i.channel as u64, i.cycle + s.sample_after(i.branch), bits),
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

/// A run of `frames` frames of `dut` judged by the checker (with or
/// without the model).
fn judged<D: Dut>(s: &Schedule, dut: &mut D, frames: u64, model: bool) -> judge::Verdict {
    let opts = judge::RunOptions {
        check: judge::CheckOptions {
            model,
            ..Default::default()
        },
        ..Default::default()
    };
    judge::run_dut(s, dut, frames, &opts, "test", None)
}

fn rules(v: &judge::Verdict) -> Vec<String> {
    v.violations.iter().map(|v| v.rule.to_string()).collect()
}

#[test]
fn the_model_passes_its_own_checker_with_and_without_itself() {
    for seed in 0..8 {
        let s = random_mix(seed);
        for model in [true, false] {
            let v = judged(&s, &mut ModelDut::new(&s), 3, model);
            assert!(v.ok, "seed {seed} model {model}: {}", v.summary());
            assert!(v.samples > 0);
        }
    }
}

/// The cycles (after reset) in which branch `b` sends bit `k` of the word
/// of its conversion number `n` (0: the first), as the model drives them.
fn bit_cycles(s: &Schedule, b: usize, n: usize, k: usize) -> Vec<u64> {
    let mut m = CycleModel::new(s);
    let mut starts = Vec::new();
    let mut out = Vec::new();
    for c in 0..3 * s.grid.frame_cycles {
        if let Some((_, bit, t)) = m.command_bit(b) {
            if starts.last() != Some(&t) {
                starts.push(t);
            }
            if starts.len() == n + 1 && bit == k {
                out.push(c);
            }
        }
        m.step(0);
    }
    out
}

/// Flips `adc_mosi` bit `lane` in the cycles `at` (counted after reset).
struct FlipAt<D> {
    dut: D,
    lane: u32,
    at: Vec<u64>,
    c: u64,
}
impl<D: Dut> Dut for FlipAt<D> {
    fn step(&mut self, rst: bool, miso: u64) -> Pins {
        let mut p = self.dut.step(rst, miso);
        if rst {
            self.c = 0;
            return p;
        }
        if self.at.contains(&self.c) {
            p.mosi ^= 1 << self.lane;
        }
        self.c += 1;
        p
    }
}

/// The first channel bit of branch `b`'s word (its MSB).
fn channel_bit(s: &Schedule, b: usize) -> usize {
    let cmd = s.mix.branches[b].adc.command.as_ref().unwrap();
    cmd.bits
        .iter()
        .position(|x| matches!(x, lut_gen::CmdBit::Channel(_)))
        .unwrap()
}

#[test]
fn a_wrong_command_bit_is_named_at_its_cycle_and_breaks_the_attribution() {
    for seed in 0..6 {
        let s = random_mix(seed);
        for (lane, b) in [(0u32, 0usize), (1, 2)] {
            let n = 1 + seed as usize % 3;
            let k = channel_bit(&s, b) + seed as usize % 3;
            let at = bit_cycles(&s, b, n, k);
            assert!(!at.is_empty(), "seed {seed} branch {b}");
            let mut dut = FlipAt {
                dut: ModelDut::new(&s),
                lane,
                at: at.clone(),
                c: 0,
            };
            let v = judged(&s, &mut dut, 3, true);
            let d = &v.divergences[0];
            assert_eq!(d.cycle, at[0], "seed {seed} branch {b}: {}", v.summary());
            assert_eq!(d.signal, format!("adc_mosi[{lane}]"));
            assert!(
                d.context[0].contains(&format!("bit {k} (0 = the first) of the command word")),
                "{:?}",
                d.context
            );
            // Without the model: the sample that word selected is held to
            // the channel it selected (or the word to the branch's inputs).
            dut.dut = ModelDut::new(&s);
            let v = judged(&s, &mut dut, 3, false);
            let r = rules(&v);
            assert!(
                r.iter()
                    .any(|r| r == "command-channel" || r == "command-word"),
                "seed {seed} branch {b} bit {k}: {r:?} {}",
                v.summary()
            );
        }
    }
}

/// The command-word pin faults apply to every commanded branch of a
/// random mix and to no other; each is caught with the model (its first
/// divergence on that branch's `adc_mosi`) and without it (the conversion
/// held to the channel its word selected, or the word refused).
#[test]
fn command_faults_are_caught_with_and_without_the_model() {
    use judge::{FaultyDut, PinFault};
    for seed in 0..6 {
        let s = random_mix(seed);
        let all = PinFault::all(&s);
        for b in 0..s.branches.len() {
            for f in [
                PinFault::WrongChannelBits { branch: b },
                PinFault::LateCommand { branch: b },
            ] {
                assert_eq!(all.contains(&f), s.has_command(b), "seed {seed} {f:?}");
                if !s.has_command(b) {
                    continue;
                }
                let at = s.grid.frame_cycles / 3 + seed * 977;
                let lane = CycleModel::new(&s).layout().mosi_lo[b].unwrap();
                for model in [true, false] {
                    let mut dut = FaultyDut::new(&s, ModelDut::new(&s), f, at);
                    let v = judged(&s, &mut dut, 4, model);
                    assert!(!v.ok, "seed {seed} {f:?} model {model}: missed");
                    if model {
                        let d = &v.divergences[0];
                        assert_eq!(d.signal, format!("adc_mosi[{lane}]"), "{f:?}");
                        assert!(d.cycle >= at, "{f:?}: {}", d.cycle);
                    } else {
                        let r = rules(&v);
                        assert!(
                            r.iter()
                                .any(|r| r == "command-channel" || r == "command-word"),
                            "seed {seed} {f:?}: {r:?}"
                        );
                    }
                }
            }
        }
    }
}

fn shared(name: &str) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(&testkit::mix(name)).unwrap()).unwrap()
}

/// A VCD of `dut`'s cycles `[from, to)` (counted from the first reset cycle).
fn vcd_of<D: Dut>(s: &Schedule, dut: &mut D, from: u64, to: u64, path: &std::path::Path) {
    let frames = to / s.grid.frame_cycles + 1;
    judge::write_run(
        path,
        s,
        dut,
        frames,
        &judge::RunOptions::default(),
        (from, to),
    )
    .unwrap();
}

fn check_file(s: &Schedule, path: &std::path::Path, model: bool) -> judge::Verdict {
    let opts = judge::CheckOptions {
        model,
        ..Default::default()
    };
    judge::check_vcd_with(s, path, None, opts).unwrap().0
}

/// The VCD carries adc_mosi both ways: a run's VCD passes `check` with and
/// without the model; one MOSI bit flipped in it fails at its cycle, named.
#[test]
fn a_vcd_carries_adc_mosi_and_a_flipped_bit_fails_at_its_cycle() {
    let d = tempfile::tempdir().unwrap();
    let mut mixes = vec![shared("cmd-pair"), shared("cmd-solo")];
    mixes.extend((10..13).map(random_mix));
    for s in &mixes {
        let name = &s.mix.name;
        let to = 5 * s.grid.frame_cycles;
        let p = d.path().join("good.vcd");
        vcd_of(s, &mut ModelDut::new(s), 0, to, &p);
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(
            text.contains(" adc_mosi ["),
            "{name}: no adc_mosi in the VCD"
        );
        for model in [true, false] {
            let v = check_file(s, &p, model);
            assert!(
                v.ok && v.samples > 0,
                "{name} model {model}: {}",
                v.summary()
            );
        }
        let b = (0..s.branches.len())
            .rev()
            .find(|&b| s.has_command(b))
            .unwrap();
        let lane = CycleModel::new(s).layout().mosi_lo[b].unwrap();
        let at = bit_cycles(s, b, 2, channel_bit(s, b));
        let mut dut = FlipAt {
            dut: ModelDut::new(s),
            lane,
            at: at.clone(),
            c: 0,
        };
        let p = d.path().join("bad.vcd");
        vcd_of(s, &mut dut, 0, to, &p);
        let v = check_file(s, &p, true);
        assert_eq!(v.divergences[0].cycle, at[0], "{name}: {}", v.summary());
        assert_eq!(v.divergences[0].signal, format!("adc_mosi[{lane}]"));
        let v = check_file(s, &p, false);
        assert!(
            rules(&v)
                .iter()
                .any(|r| r == "command-channel" || r == "command-word"),
            "{name}: {}",
            v.summary()
        );
    }
}

/// Windows at random offsets of a commanded run lock on their frame phase
/// and pass with and without the model; a wrong command word inside the
/// window fails.
#[test]
fn windows_at_random_offsets_of_a_commanded_run() {
    let d = tempfile::tempdir().unwrap();
    let mut r = Lcg(77);
    for (i, s) in [shared("cmd-pair"), random_mix(21), random_mix(22)]
        .iter()
        .enumerate()
    {
        let f = s.grid.frame_cycles;
        for k in 0..3 {
            let from = f + r.next(3 * f);
            let to = from + 3 * f + r.next(f);
            let p = d.path().join(format!("w{i}-{k}.vcd"));
            vcd_of(s, &mut ModelDut::new(s), from, to, &p);
            for model in [true, false] {
                let (v, info) = judge::check_vcd_with(
                    s,
                    &p,
                    None,
                    judge::CheckOptions {
                        model,
                        ..Default::default()
                    },
                )
                .unwrap();
                assert!(info.lock.is_some(), "mix {i} window {from}..{to}");
                assert!(
                    v.ok && v.samples > 0,
                    "mix {i} window {from}..{to} model {model}: {}",
                    v.summary()
                );
            }
            let b = (0..s.branches.len()).find(|&b| s.has_command(b)).unwrap();
            let f0 = judge::FaultyDut::new(
                s,
                ModelDut::new(s),
                judge::PinFault::WrongChannelBits { branch: b },
                from + f,
            );
            let mut dut = f0;
            let p = d.path().join(format!("w{i}-{k}-bad.vcd"));
            vcd_of(s, &mut dut, from, to, &p);
            for model in [true, false] {
                let opts = judge::CheckOptions {
                    model,
                    ..Default::default()
                };
                let (v, _) = judge::check_vcd_with(s, &p, None, opts).unwrap();
                assert!(!v.ok, "mix {i} window {from}..{to} model {model}: missed");
            }
        }
    }
}

/// An analyser's capture of a commanded run (resampled at 100 MHz from mid
/// frame, through sigrok-cli's session and VCD) maps `adc_mosi` and passes
/// the time-level check; one command bit flipped fails as the command words'.
#[test]
fn analyser_captures_carry_the_command_words() {
    use testkit::analyser;
    if !testkit::tools::require_tool("sigrok-cli") {
        return;
    }
    let s = shared("cmd-pair");
    let clean = analyser::run(&s, &mut ModelDut::new(&s), 3);
    let (_, map) = analyser::lanes(&s);
    assert!(map.contains("adc_mosi[1]"), "{map}");
    let d = tempfile::tempdir().unwrap();
    let f = s.grid.frame_cycles;
    // from between two conversions (a capture that starts inside a read
    // sees SCLK edges before any conversion start)
    let window = (f / 3 + 1_317, 2 * f + f / 2);
    let (sr, back) =
        analyser::capture(&s, &clean, window, (10_000, 3_717), &d.path().join("c.vcd"));
    for file in [&sr, &back] {
        let r = analyser::check(&s, &map, file);
        assert!(r.ok, "{}", r.summary());
        assert!(
            r.summary().contains("every bit of every command word"),
            "{}",
            r.summary()
        );
    }
    let b = 2;
    let lane = CycleModel::new(&s).layout().mosi_lo[b].unwrap();
    let mut bad = clean.clone();
    for c in bit_cycles(&s, b, 9, channel_bit(&s, b)) {
        bad[c as usize].mosi ^= 1 << lane;
    }
    let (sr, _) = analyser::capture(&s, &bad, window, (10_000, 3_717), &d.path().join("b.vcd"));
    let r = analyser::check(&s, &map, &sr);
    assert!(!r.ok);
    assert!(
        r.violations[0].rule.contains("command words"),
        "{}",
        r.summary()
    );
}
