//! Windows of link designs (a run seen from its middle, as `sim --from/--to`
//! writes it or a logic analyser captures it): `check` joins the link's
//! state from the line itself and passes a clean design with and without
//! the model, on every link preset and on random link mixes at random
//! offsets; a fault inside the window fails it at the fault's cycle.

use std::path::Path;

use judge::faults::{Fault, FaultyDut};
use judge::lock::Judge;
use judge::run::{run_dut, Dut, Observer, RunOptions};
use judge::vcd::CycleSink;
use judge::{CheckOptions, LockInfo, Pins, Report};

/// Feeds the cycles `[from, to)` of a run (counted from its first reset
/// cycle) to the judge, as a VCD of that window would.
struct Window<'a> {
    judge: Judge<'a>,
    from: u64,
    to: u64,
}

impl Observer for Window<'_> {
    fn cycle(&mut self, cycle: u64, rst: bool, pins: &Pins, miso: u64) {
        if (self.from..self.to).contains(&cycle) {
            self.judge.cycle(Some(rst), pins, &Pins::default(), miso, 0);
        }
    }
}

/// The window `[from, to)` of a run of `dut` (behind the AXIS slave a back
/// end puts in front of it), judged with or without the model.
fn judge_window(
    s: &lut_gen::Schedule,
    dut: impl Dut,
    (from, to): (u64, u64),
    model: bool,
) -> (Report, LockInfo) {
    let opts = CheckOptions {
        model,
        ..Default::default()
    };
    let mut w = Window {
        judge: Judge::new(s, opts),
        from,
        to,
    };
    let mut dut = judge::run::with_slave(s, dut, ::link::ReadyPattern::Random { seed: 11 });
    let frames = to / s.grid.frame_cycles + 1;
    run_dut(
        s,
        &mut dut,
        frames,
        &RunOptions::default(),
        "run",
        Some(&mut w),
    );
    let (r, lock) = w.judge.finish("window").expect("the window locks");
    (r, lock.expect("a window from the middle of a run"))
}

fn load(path: &Path) -> lut_gen::Schedule {
    lut_gen::synthesize(&lut_gen::load(path).unwrap()).unwrap()
}

fn preset(name: &str) -> lut_gen::Schedule {
    load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("mixes")
            .join(name),
    )
}

fn rusthdl(s: &lut_gen::Schedule) -> engines::RustHdlDut {
    engines::RustHdlDut::new(s).expect("rust-hdl builds")
}

/// A seeded xorshift for the windows' offsets.
fn rng(seed: u64) -> impl FnMut() -> u64 {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    }
}

#[test]
fn explore_presets() {
    for name in ["eskin34-uart.toml", "eskin34-axis.toml"] {
        let s = preset(name);
        let f = s.grid.frame_cycles;
        let mut next = rng(1);
        for _ in 0..2 {
            let from = f / 2 + next() % f;
            let to = from + f;
            for model in [true, false] {
                let (r, lock) = judge_window(&s, judge::run::ModelDut::new(&s), (from, to), model);
                eprintln!("{name} {from} model={model}: {}\n  {lock}", r.summary());
            }
        }
    }
}

/// Random link mixes (the one generator, with a `[link]` drawn) whose
/// link the audit finds feasible: `n` of them from seed `seed` on.
fn random_link_mixes(seed: u64, n: usize) -> Vec<(u64, lut_gen::Schedule)> {
    let shape = campaign::mixgen::Shape {
        link: Some(campaign::mixgen::LinkShape::Either),
        ..Default::default()
    };
    (seed..)
        .filter_map(|k| {
            let text = campaign::mixgen::random_mix(k, &shape);
            let mix = lut_gen::parse(Path::new("random.toml"), &text).ok()?;
            let s = lut_gen::synthesize(&mix).ok()?;
            matches!(lut_gen::hostlink::plan(&s), Some(Ok(_))).then_some((k, s))
        })
        .take(n)
        .collect()
}

#[test]
fn explore_random() {
    for (k, s) in random_link_mixes(1, 12) {
        let f = s.grid.frame_cycles;
        let mut next = rng(k);
        for _ in 0..3 {
            let from = f / 2 + next() % (2 * f);
            let to = from + f + next() % (2 * f);
            for model in [true, false] {
                let (r, _lock) = judge_window(&s, judge::run::ModelDut::new(&s), (from, to), model);
                if !r.ok {
                    eprintln!("seed {k} {from}..{to} model={model}: {}", r.summary());
                }
            }
        }
    }
}

#[test]
fn explore_seed3() {
    let (k, s) = random_link_mixes(3, 1).remove(0);
    let text = campaign::mixgen::random_mix(
        k,
        &campaign::mixgen::Shape {
            link: Some(campaign::mixgen::LinkShape::Either),
            ..Default::default()
        },
    );
    eprintln!("{text}");
    let plan = lut_gen::hostlink::plan(&s).unwrap().unwrap();
    eprintln!(
        "latency {} slice {} spf {}",
        plan.latency_cycles, s.grid.slice_cycles, s.grid.slices_per_frame
    );
    let r = judge::run::run_dut(
        &s,
        &mut judge::run::ModelDut::new(&s),
        6,
        &RunOptions::default(),
        "run",
        None,
    );
    eprintln!("from reset: {}", r.summary());
}
