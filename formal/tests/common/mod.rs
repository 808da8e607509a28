//! What the formal crate's test files share: the mixes, the emitted
//! design, its edits and the reading of a failed proof.

use std::path::{Path, PathBuf};

use formal::{Counterexample, Outcome, Proof};

/// The tools a proof runs.
pub const TOOLS: [&str; 4] = ["yosys", "yosys-abc", "iverilog", "vvp"];

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The schedule of the mix at `rel` (from the repository's root).
pub fn schedule(rel: &str) -> lut_gen::Schedule {
    let mix = lut_gen::load(&root().join(rel)).expect("mix loads");
    lut_gen::synthesize(&mix).expect("mix is feasible")
}

/// The Verilog `hdl` emits for `s`.
pub fn emitted(s: &lut_gen::Schedule) -> String {
    hdl::emit(s, None).expect("emits").verilog().to_string()
}

/// `design` with `from` replaced by `to` exactly once (the test fails if
/// the design no longer has the line, rather than testing nothing).
pub fn edit(design: &str, from: &str, to: &str) -> String {
    assert_eq!(
        design.matches(from).count(),
        1,
        "`{from}` once in the design"
    );
    design.replacen(from, to, 1)
}

/// The names of the properties a proof failed.
pub fn failed(p: &Proof) -> Vec<&str> {
    (p.properties.iter())
        .filter(|q| q.result == Outcome::Failed)
        .map(|q| q.name.as_str())
        .collect()
}

/// A failed proof whose failing properties are exactly `properties`.
pub fn assert_fails_exactly(p: &Proof, properties: &[&str]) {
    assert_eq!(p.result, Outcome::Failed, "{}", p.summary());
    assert_eq!(failed(p), properties, "{}", p.summary());
}

/// The judge's report on the counterexample's VCD, which must reject it.
pub fn rejected(s: &lut_gen::Schedule, c: &Counterexample) -> judge::Verdict {
    let report = judge::check_vcd(s, &c.vcd, Some(formal::DUT_SCOPE)).expect("VCD reads");
    assert!(
        !report.ok,
        "check accepts the counterexample:\n{}",
        report.summary()
    );
    report
}

/// The random mixes the formal tests draw (the one generator,
/// `campaign::random_mix`): a 4 MHz clock and a 1 ms frame (4,000 cycles),
/// so each proof takes seconds; one to three branches, one or two mux
/// devices, SCLK, settling and rates drawn; a branch without a mux 1 in
/// `muxless` (0: every branch has one).
pub fn quick_proof_shape(muxless: u64) -> campaign::Shape {
    campaign::Shape {
        clock_hz: 4_000_000,
        frame_us: 1_000,
        slice_us: 500,
        branches: (1, 3),
        mux_devices: (1, 2),
        sclk_hz: vec![1_000_000, 2_000_000],
        settle_ns: vec![0, 1_000, 2_000],
        channels: (2, 8),
        rates_hz: vec![1_000, 2_000, 4_000],
        muxless,
        commanded: 0,
        link: None,
    }
}

/// The judge's first rejected cycle in `report` is the counterexample's.
pub fn assert_rejected_at_its_cycle(report: &judge::Verdict, p: &Proof, c: &Counterexample) {
    assert_eq!(
        formal::first_rejected(report),
        Some(c.cycle as u64),
        "check fails at another cycle than prove:\n{}",
        p.summary()
    );
}
