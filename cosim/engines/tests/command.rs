//! Converters with a command word on the gateware: every pin of the
//! rust-hdl twin and of the emitted Verilog (Verilator) equals the judge's
//! cycle model in every cycle (docs/timing.md, "Command words": `adc_mosi`
//! bit for bit, and no sample from a prepared conversion), on the test
//! mixes and on random mixes with commanded branches.

use engines::{RustHdlDut, VerilatedDut};
use judge::{Adc, Dut, ModelDut, Stimulus};
use lut_gen::{Pins, Schedule};

use crate::tools;

pub(crate) fn schedule(name: &str) -> Schedule {
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

/// The first cycle at which `dut`'s pins differ from the model's (counted
/// from cycle 0 after reset, the reset cycles negative) and how, in
/// `frames` frames under the ADC model (fed the DUT's pins); the number of
/// samples and of `adc_mosi` high cycles seen.
pub(crate) fn first_difference<D: Dut>(
    s: &Schedule,
    dut: &mut D,
    frames: u64,
) -> (Option<(i64, String)>, u64, u64) {
    let mut model = ModelDut::new(s);
    let mut adc = Adc::new(s, Stimulus::Pattern);
    let mut miso = (1u64 << s.branches.len()) - 1;
    let (mut samples, mut mosi) = (0, 0);
    let cmp = |c: i64, d: &Pins, m: &Pins| {
        (d != m).then(|| {
            let text = format!(
                "cycle {c}: differs in {:?}\ngateware {d:?}\nmodel    {m:?}",
                differing(d, m)
            );
            (c, text)
        })
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

/// The pins in which `a` and `b` differ.
fn differing(a: &Pins, b: &Pins) -> Vec<&'static str> {
    let mut v = vec![];
    for (name, same) in [
        ("cs_n", a.cs_n == b.cs_n),
        ("sclk", a.sclk == b.sclk),
        ("mosi", a.mosi == b.mosi),
        ("mux", a.mux_sel == b.mux_sel && a.mux_en == b.mux_en),
        ("sample_valid", a.sample_valid == b.sample_valid),
        ("sample_channel", a.sample_channel == b.sample_channel),
        ("sample_value", a.sample_value == b.sample_value),
    ] {
        if !same {
            v.push(name);
        }
    }
    v
}

pub(crate) fn assert_same<D: Dut>(what: &str, s: &Schedule, dut: &mut D, frames: u64) {
    let (diff, samples, mosi) = first_difference(s, dut, frames);
    if let Some((_, e)) = diff {
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
    for name in ["cmd-mcp3208", "cmd-ad7689", "cmd-both", "cmd-ads7953"] {
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

/// The command-word test mixes and a random commanded mix on Verilator,
/// pin for pin as the model.  Each is a Verilator model to build (g++ was
/// most of this test's CPU): `cmd-both` holds the MCP3208's and the
/// AD7689's command units that `cmd-mcp3208` and `cmd-ad7689` hold alone,
/// so those two, and two more random mixes, run on Verilator in `make
/// test-long` (rust-hdl runs them all above, and ten random mixes).
#[test]
fn verilator_drives_the_command_words() {
    verilator_drives_the_command_words_of(&["cmd-both", "cmd-ads7953"], 0..1);
}

#[test]
#[ignore = "long: make test-long (the single-part test mixes and random commanded mixes 1 and 2 on Verilator)"]
fn verilator_drives_the_command_words_of_the_other_mixes() {
    verilator_drives_the_command_words_of(&["cmd-mcp3208", "cmd-ad7689"], 1..3);
}

/// The test mixes `named` and the random commanded mixes `randoms`, each
/// on Verilator.
fn verilator_drives_the_command_words_of(named: &[&str], randoms: std::ops::Range<u64>) {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let mut mixes: Vec<(String, Schedule)> =
        named.iter().map(|n| (n.to_string(), schedule(n))).collect();
    mixes.extend(randoms.map(|k| (format!("random commanded mix {k}"), random_mix(k))));
    for (what, s) in mixes {
        let v = engines::verilog(&s).unwrap();
        let (mut dut, _) = VerilatedDut::new(&v).unwrap();
        assert_same(&what, &s, &mut dut, 2);
    }
}

/// Steps the judge's cycle model beside a back end's run (each cycle's
/// pins as the engine or its VCD gives them) and keeps the first
/// difference: the comparison without the checker.
pub(crate) struct BesideModel {
    model: ModelDut,
    miso: u64,
    pub(crate) cycles: u64,
    pub(crate) samples: u64,
    pub(crate) mosi: u64,
    pub(crate) diff: Option<String>,
    /// Each sample the gateware emitted: (channel, value).
    pub(crate) emitted: Vec<(u16, u16)>,
}

impl BesideModel {
    pub(crate) fn new(s: &Schedule) -> BesideModel {
        BesideModel {
            model: ModelDut::new(s),
            miso: (1u64 << s.branches.len()) - 1,
            cycles: 0,
            samples: 0,
            mosi: 0,
            diff: None,
            emitted: Vec::new(),
        }
    }

    fn see(&mut self, rst: bool, pins: &Pins, miso: u64) {
        let m = self.model.step(rst, self.miso);
        if self.diff.is_none() && m != *pins {
            self.diff = Some(format!(
                "cycle {} of the run: gateware {pins:?}\nmodel    {m:?}",
                self.cycles
            ));
        }
        self.miso = miso;
        self.cycles += 1;
        self.samples += (!rst && pins.sample_valid) as u64;
        if !rst && pins.sample_valid {
            self.emitted.push((pins.sample_channel, pins.sample_value));
        }
        self.mosi += (pins.mosi != 0) as u64;
    }
}

impl judge::Observer for BesideModel {
    fn cycle(&mut self, _: u64, rst: bool, pins: &Pins, miso: u64) {
        self.see(rst, pins, miso);
    }
}

impl judge::CycleSink for BesideModel {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, _: &Pins, miso: u64, _: u64) {
        self.see(rst.unwrap_or(false), pins, miso);
    }
}

/// The emitted Verilog in Icarus with the testbench's own ADC models (the
/// commanded parts' too, `icarus_cmd`): every pin of its VCD equals the
/// cycle model's. The default suite runs each commanded part's model once,
/// all three in one Icarus run of `cmd-small` (the MCP3208, the AD7689 and
/// the ADS7953-like part at 8 MHz in 500 us frames: 8,000 cycles for two
/// frames; Icarus's time is the cycles, and `cmd-pair` and `cmd-ads7953`,
/// which the default suite ran before, took 48,000 and 80,000), under the
/// pattern stimulus; the long test runs every test mix, those two among them.
#[test]
fn icarus_testbench_converts_what_the_words_select() {
    icarus_converts_what_the_words_select(false);
}

/// Every test mix, a table stimulus and two random commanded mixes in Icarus
/// (minutes): `make test-long`.
#[test]
#[ignore = "long: make test-long"]
fn icarus_testbench_converts_what_the_words_select_on_every_mix() {
    icarus_converts_what_the_words_select(true);
}

fn icarus_converts_what_the_words_select(every: bool) {
    if !tools::require_tools(&["iverilog", "vvp"]) {
        return;
    }
    let names: &[&str] = if every {
        &[
            "cmd-mcp3208",
            "cmd-ad7689",
            "cmd-both",
            "cmd-pair",
            "cmd-ads7953",
        ]
    } else {
        &["cmd-small"]
    };
    let mut runs: Vec<(String, Schedule, Stimulus)> = names
        .iter()
        .map(|n| (n.to_string(), schedule(n), Stimulus::Pattern))
        .collect();
    if every {
        runs.push((
            "cmd-both (step)".into(),
            schedule("cmd-both"),
            Stimulus::Step,
        ));
        runs.extend((3..5).map(|k| {
            (
                format!("random commanded mix {k}"),
                random_mix(k),
                Stimulus::Pattern,
            )
        }));
    }
    for (what, s, stimulus) in runs {
        let mut beside = BesideModel::new(&s);
        icarus_beside(&s, None, stimulus, 2 * s.grid.frame_cycles, &mut beside);
        if let Some(d) = beside.diff {
            panic!("{what}: {d}");
        }
        assert!(beside.cycles >= 2 * s.grid.frame_cycles, "{what}: cycles");
        assert!(beside.mosi > 0 && beside.samples > 0, "{what}");
        // the model beside was fed the testbench's MISO, so it agrees with
        // any part model: the codes themselves are compared with the
        // judge's own converters' (each input's code per slot), which
        // convert the input each word selected
        let want = judged_samples(&s, stimulus, 2);
        let n = beside.emitted.len().min(want.len());
        assert!(
            n > 0 && n + 8 >= want.len(),
            "{what}: {n} of {}",
            want.len()
        );
        if let Some(k) = (0..n).find(|&k| beside.emitted[k] != want[k]) {
            panic!(
                "{what}: sample {k}: the testbench's converter gave (channel, code) {:?}, the judge's {:?}",
                beside.emitted[k], want[k]
            );
        }
    }
}

/// The samples (channel, code) of the cycle model run `frames` frames
/// with the judge's converter models under `stimulus`.
fn judged_samples(s: &Schedule, stimulus: Stimulus, frames: u64) -> Vec<(u16, u16)> {
    struct Emitted(Vec<(u16, u16)>);
    impl judge::Observer for Emitted {
        fn cycle(&mut self, _: u64, rst: bool, pins: &Pins, _: u64) {
            if !rst && pins.sample_valid {
                self.0.push((pins.sample_channel, pins.sample_value));
            }
        }
    }
    let mut out = Emitted(Vec::new());
    let opts = judge::RunOptions {
        stimulus,
        ..Default::default()
    };
    let v = judge::run_dut(
        s,
        &mut ModelDut::new(s),
        frames,
        &opts,
        "model",
        Some(&mut out),
    );
    assert!(v.ok, "{}", v.mix);
    out.0
}

/// Runs the Icarus testbench (`engines::icarus_testbench`, the back end's
/// own) on the emitted Verilog for `cycles` cycles after reset and hands
/// every cycle of its VCD to `sink`.
pub(crate) fn icarus_beside(
    s: &Schedule,
    design: Option<&str>,
    stimulus: Stimulus,
    cycles: u64,
    sink: &mut BesideModel,
) {
    let dir = tempfile::Builder::new()
        .prefix("slotforge-cmd-icarus-")
        .tempdir()
        .unwrap();
    let d = dir.path();
    hdl::emit(s, None).unwrap().write_to(d).unwrap();
    if let Some(v) = design {
        std::fs::write(d.join(hdl::VERILOG_FILE), v).unwrap();
    }
    let tb = engines::icarus_testbench(s, stimulus, 4, cycles);
    std::fs::write(d.join("tb.v"), &tb.tb).unwrap();
    for (name, text) in &tb.tables {
        std::fs::write(d.join(name), text).unwrap();
    }
    let run = |cmd: &mut std::process::Command| {
        let o = cmd.current_dir(d).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).to_string()
    };
    run(std::process::Command::new("iverilog").args([
        "-g2005",
        "-Wall",
        "-s",
        "tb",
        "-o",
        "sim.vvp",
        "tb.v",
        hdl::VERILOG_FILE,
    ]));
    run(std::process::Command::new("vvp").args(["-n", "sim.vvp"]));
    judge::read_cycles(s, &d.join("wave.vcd"), Some("tb"), sink).unwrap();
}

/// The emitted Verilog with channel bit 0 of every command word taken from
/// channel bit 1: a gateware that sends the wrong channel bits (the mutant
/// the issue names).
pub fn wrong_channel_bits(verilog: &str) -> String {
    let (out, n) = rewrite_lines(verilog, |l| {
        (l.trim_start().starts_with("wire [") && l.contains(" word = {"))
            .then(|| l.replacen("sel[0]", "sel[1]", 1))
    });
    assert!(n > 0, "no command word in the design");
    out
}

/// `verilog` with every line `edit` rewrites rewritten (each line ended by
/// a newline), and how many it rewrote.
pub(crate) fn rewrite_lines(
    verilog: &str,
    mut edit: impl FnMut(&str) -> Option<String>,
) -> (String, usize) {
    let mut n = 0;
    let out: Vec<String> = (verilog.lines())
        .map(|l| match edit(l) {
            Some(new) => {
                n += 1;
                new
            }
            None => l.to_string(),
        })
        .collect();
    (out.join("\n") + "\n", n)
}

/// The wrong-channel mutant differs from the model on both Verilog engines:
/// on `adc_mosi` first, and the ADC models then convert the wrong input.
#[test]
fn a_gateware_sending_the_wrong_channel_bits_fails_on_both_verilog_engines() {
    for name in ["cmd-mcp3208", "cmd-ad7689"] {
        fails_on_both_verilog_engines(name, wrong_channel_bits, "differs in [\"mosi\"]");
    }
}

/// The emitted Verilog with the ad7689's CNV held high through the read (its
/// branches take the sequencer's pin instead of the CNV pulse): the part
/// would leave SDO high-impedance and ignore DIN.
pub fn cnv_held_through_the_read(verilog: &str) -> String {
    let (out, n) = rewrite_lines(verilog, |l| {
        let seq = l.split("_seq_cs_n").next().unwrap();
        (l.contains("_seq_cs_n = cnv_pulse")).then(|| format!("{seq}_seq_cs_n = spi_seq0_cs_n;"))
    });
    assert!(n > 0, "no CNV pulse in the design");
    out
}

/// A gateware that holds the ad7689's CNV high through the read differs
/// from the model on its CNV pin, on both Verilog engines.
#[test]
fn a_gateware_holding_cnv_through_the_read_fails_on_both_verilog_engines() {
    fails_on_both_verilog_engines("cmd-ad7689", cnv_held_through_the_read, "cs_n");
}

/// The gateware of mix `name` made faulty by `mutate` differs from the
/// model in its first frame on Verilator (the difference naming `pin`) and
/// on Icarus (skipped, loudly, without the tools).  Icarus runs only up to
/// and including the cycle Verilator differs in (both run the same Verilog
/// from the same reset; a frame of cmd-front is 80,000 cycles, the slowest
/// part of these tests): it must differ there too, not merely somewhere in
/// the frame.
pub(crate) fn fails_on_both_verilog_engines(name: &str, mutate: fn(&str) -> String, pin: &str) {
    if !tools::require_tools(&["verilator", "g++", "iverilog", "vvp"]) {
        return;
    }
    let s = &schedule(name);
    let bad = &mutate(&engines::verilog(s).unwrap());
    let (mut dut, _) = VerilatedDut::new(bad).unwrap();
    let (diff, _, _) = first_difference(s, &mut dut, 1);
    let (cycle, d) = diff.unwrap_or_else(|| panic!("{name}: Verilator ran the mutant clean"));
    assert!(d.contains(pin), "{name}: {d}");
    let mut beside = BesideModel::new(s);
    let through = (cycle + 1).max(1) as u64;
    icarus_beside(s, Some(bad), Stimulus::Pattern, through, &mut beside);
    assert!(
        beside.diff.is_some(),
        "{name}: Icarus ran the mutant clean through cycle {cycle}, where Verilator differs"
    );
}
