//! `prove` of mixes with modes (docs/timing.md, "Mode switches"): the
//! harness follows every sequence of mode requests (pin select: `mode_sel`
//! free in every cycle) or evaluates the triggers on the words it recorded
//! (auto select: MISO free), each mode's own table from `Schedule::modes`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use formal::{Outcome, Proof, ProveOptions};

use testkit::tools;

const TOOLS: [&str; 4] = ["yosys", "yosys-abc", "iverilog", "vvp"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn schedule(rel: &str) -> lut_gen::Schedule {
    let mix = lut_gen::load(&root().join(rel)).expect("mix loads");
    lut_gen::synthesize(&mix).expect("mix is feasible")
}

fn emitted(s: &lut_gen::Schedule) -> String {
    hdl::emit(s, None).expect("emits").verilog().to_string()
}

fn prove(s: &lut_gen::Schedule, design: &str, out: &Path) -> Proof {
    let o = ProveOptions::new(out);
    let t = Instant::now();
    let p = formal::prove(s, design, &o).expect("prove runs");
    eprintln!(
        "{} in {:.1} s\n{}",
        s.mix.name,
        t.elapsed().as_secs_f64(),
        p.summary()
    );
    p
}

#[test]
fn pin_select_mix_proves_for_every_sequence_of_requests() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/modes-pin.toml");
    let h = formal::generate(&s).expect("a harness");
    std::fs::write("/work/tmp-s10-prove/h.v", &h.verilog).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
}
