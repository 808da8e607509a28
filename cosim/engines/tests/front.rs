//! An external mux in front of a converter's own (`front_mux`): the
//! gateware drives the front mux's pins as an external-mux branch does and
//! the words from its own table; every back end equals the judge's cycle
//! model pin for pin (their ADC models convert the channel on the input the
//! word selected behind the front pins at the instant), on the test mix and
//! on random fronted mixes; a gateware driving the wrong front select fails.

use engines::{RustHdlDut, VerilatedDut};
use judge::Stimulus;
use lut_gen::Schedule;

use crate::command::{
    assert_same, fails_on_both_verilog_engines, icarus_beside, rewrite_lines, schedule, BesideModel,
};
use crate::tools;

/// A small deterministic generator.
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

const ADS: &str = "[[adc_part]]\nname = \"ads7953\"\nbits = 12\nstart = \"cs\"\nleading_bits = 4\n\
                   sclk_max_hz = 20_000_000\nmax_sps = 1_000_000\ncommand = \"0001_1_CCCC_0000000\"\n\
                   command_ahead = 2\n";

/// A fronted branch (an AD7689 or a declared ADS7953-like part behind one
/// to three TMUX1108s) with channels through the front mux on one or two
/// converter inputs and some wired straight, and maybe a listening branch.
pub(crate) fn random_fronted(seed: u64) -> Schedule {
    let mut r = Lcg(seed * 7_919 + 13);
    let mut t = format!(
        "name = \"front{seed}\"\n[clock]\nhz = 40_000_000\n[frame]\nperiod_us = 1000\nslice_us = 500\n{ADS}"
    );
    let adc = ["ad7689", "ads7953"][r.next(2) as usize];
    let devices = 1 + r.next(3);
    t += &format!(
        "[[branch]]\nname = \"f\"\nadc = \"{adc}\"\nmux = \"internal\"\nfront_mux = \"tmux1108\"\n\
         front_mux_devices = {devices}\nsettle_ns = {}\n",
        250 * r.next(5)
    );
    let listening = r.next(2) == 1;
    if listening {
        t += "[[branch]]\nname = \"e\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n";
    }
    let fronted: Vec<u64> = vec![r.next(4), 4 + r.next(4)][..1 + r.next(2) as usize].to_vec();
    let mut fronts: Vec<u64> = (0..8 * devices).collect();
    for n in 0..2 + r.next(4) {
        let f = fronts.remove(r.next(fronts.len() as u64) as usize);
        // a front device has one output: its inputs share a converter input
        let input = fronted[(f / 8) as usize % fronted.len()];
        let rate = [1000, 2000, 4000][r.next(3) as usize];
        t += &format!(
            "[[channel]]\nname = \"c{n}\"\nbranch = \"f\"\nrate_hz = {rate}\ninput = {input}\nfront_input = {f}\n"
        );
    }
    let straight: Vec<u64> = (0..8).filter(|i| !fronted.contains(i)).collect();
    for k in 0..r.next(3) {
        let rate = [1000, 2000][r.next(2) as usize];
        t += &format!(
            "[[channel]]\nname = \"s{k}\"\nbranch = \"f\"\nrate_hz = {rate}\ninput = {}\n",
            straight[k as usize * 2]
        );
    }
    if listening {
        t += "[[channel]]\nname = \"e0\"\nbranch = \"e\"\nrate_hz = 2000\ninput = 5\n";
    }
    let m = lut_gen::parse(std::path::Path::new("front.toml"), &t).unwrap();
    lut_gen::synthesize(&m).unwrap_or_else(|e| panic!("seed {seed}: {e:?}\n{t}"))
}

#[test]
fn rusthdl_drives_fronted_branches_as_the_model() {
    let mut mixes = vec![("cmd-front".to_string(), schedule("cmd-front"))];
    mixes.extend((0..8).map(|k| (format!("random fronted mix {k}"), random_fronted(k))));
    for (what, s) in mixes {
        assert!(s.mix.branches.iter().any(|b| b.fronted), "{what}");
        assert_same(&what, &s, &mut RustHdlDut::new(&s).unwrap(), 3);
    }
}

/// `cmd-front` and a random fronted mix on Verilator; in Icarus, the
/// random mix under the pattern stimulus: its 1 ms frames are half of
/// `cmd-front`'s 80,000 cycles a frame, and Icarus's time is the cycles it
/// runs (with a third Verilator build, most of this test's CPU before).
/// rust-hdl runs `cmd-front` and eight random fronted mixes pin for pin.
#[test]
fn verilator_and_icarus_drive_fronted_branches_as_the_model() {
    fronted_on_verilator_and_icarus(false);
}

/// Every mix (a second random one too) on Verilator, and in Icarus under
/// the pattern and a step stimulus (minutes): `make test-long`.
#[test]
#[ignore = "long: make test-long"]
fn verilator_and_icarus_drive_fronted_branches_as_the_model_every_stimulus() {
    fronted_on_verilator_and_icarus(true);
}

fn fronted_on_verilator_and_icarus(every: bool) {
    if !tools::require_tools(&["verilator", "g++", "iverilog", "vvp"]) {
        return;
    }
    let mut mixes = vec![("cmd-front".to_string(), schedule("cmd-front"))];
    let randoms = if every { 8..10 } else { 8..9 };
    mixes.extend(randoms.map(|k| (format!("random fronted mix {k}"), random_fronted(k))));
    for (i, (what, s)) in mixes.into_iter().enumerate() {
        assert!(s.mix.branches.iter().any(|b| b.fronted), "{what}");
        let v = engines::verilog(&s).unwrap();
        let (mut dut, _) = VerilatedDut::new(&v).unwrap();
        assert_same(&what, &s, &mut dut, 2);
        let stimuli: &[Stimulus] = match (every, i) {
            (true, _) => &[Stimulus::Pattern, Stimulus::Step],
            (false, 1) => &[Stimulus::Pattern],
            (false, _) => &[],
        };
        for &stimulus in stimuli {
            let mut beside = BesideModel::new(&s);
            icarus_beside(&s, None, stimulus, 2 * s.grid.frame_cycles, &mut beside);
            if let Some(d) = beside.diff {
                panic!("{what} (Icarus): {d}");
            }
            assert!(beside.mosi > 0 && beside.samples > 0, "{what}");
        }
    }
}

/// The emitted Verilog with select bit 0 of the first branch's mux pins
/// inverted: the fronted branch of `cmd-front` addresses the wrong front
/// input at every conversion.
pub fn wrong_front_select(verilog: &str) -> String {
    let (out, n) = rewrite_lines(verilog, |l| {
        let rest = l
            .trim_start()
            .strip_prefix("assign mux_sel = core_mux_sel[")?;
        let hi: u32 = rest.split(':').next().unwrap().parse().unwrap();
        Some(format!(
            "{};",
            l.trim_end_matches(';').to_string() + &format!(" ^ {}'d1", hi + 1)
        ))
    });
    assert_eq!(n, 1, "the wrapper's mux_sel assignment");
    out
}

#[test]
fn a_gateware_driving_the_wrong_front_select_fails_on_both_verilog_engines() {
    fails_on_both_verilog_engines("cmd-front", wrong_front_select, "\"mux\"");
}
