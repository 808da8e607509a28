//! Mutation test of the checker: mutants of the emitted Verilog that the
//! independent Icarus testbench (`tests/tb/adc_tb.v`, judged as
//! `tests/icarus.rs` judges it) rejects must all be rejected by
//! `judge::check_vcd` on the VCD of the same Icarus run.
//!
//! One Icarus run per mutant gives both verdicts: the testbench is compiled
//! unchanged next to a two-line module that dumps the ports of `adc_tb.dut`.
//! Mutants come from the test-only `mutate` module (deterministic sites, fixed counts per
//! operator) on `tests/data/mutants.toml`, a two-branch mix with harmonic
//! and non-harmonic rates and two mux devices on one branch; 2.5 frames of
//! 4000 cycles each.  Run with `--nocapture` for the per-mutant table.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use campaign::{campaign_with, Campaign, Detector, FaultClass, Level, Plan, Target, VerilogFault};

use mutate::Operator;
use testkit::mutate;

// The independent testbench's verdict, shared with the root tests/icarus.rs.
use judge::judge;
use testkit::tb_judge as judge;

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::tools;

/// Sites per operator: 36 mutants on the test mix.
const PER_OP: [(Operator, usize); 8] = [
    (Operator::RelOp, 5),
    (Operator::Const, 8),
    (Operator::Reset, 5),
    (Operator::AndOr, 3),
    (Operator::Arith, 3),
    (Operator::DropNot, 2),
    (Operator::Concat, 4),
    (Operator::Stuck, 6),
];

/// A normal run takes about half a second.
const VVP_TIMEOUT: Duration = Duration::from_secs(20);

fn manifest() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The mutation campaigns' mix (`testkit/mixes/mutants.toml`), scheduled.
fn mutants_schedule() -> lut_gen::Schedule {
    lut_gen::synthesize(&lut_gen::load(&testkit::mix("mutants")).unwrap()).unwrap()
}

struct Bench {
    mix: lut_gen::Mix,
    s: lut_gen::Schedule,
    cycles: u64,
    tb: PathBuf,
}

#[derive(Debug)]
struct Verdicts {
    /// iverilog's complaint, if it did not compile.
    compile: Option<String>,
    /// The independent testbench's verdict.
    independent: Result<(), String>,
    /// `check_vcd`'s verdict.
    check: Result<(), String>,
}

impl Bench {
    fn run(&self, verilog: &str, dir: &Path) -> Verdicts {
        std::fs::write(dir.join("slotforge_top.v"), verilog).unwrap();
        std::fs::write(
            dir.join("dump.v"),
            "module dump;\n  initial begin\n    $dumpfile(\"wave.vcd\");\n    $dumpvars(1, adc_tb.dut);\n  end\nendmodule\n",
        )
        .unwrap();
        let s = &self.s;
        let nb = s.branches.len();
        let nm: u32 = s.branches.iter().map(|b| b.mux_devices).sum();
        let half_ns = 1e9 / s.grid.clock_hz as f64 / 2.0;
        let o = Command::new("iverilog")
            .args(["-g2005", "-o", "sim"])
            .arg(format!("-DNB={nb}"))
            .arg(format!("-DNM={nm}"))
            .arg(format!("-DWC={}", s.channel_bits()))
            .arg(format!("-DCLK_HALF={half_ns:.4}"))
            .arg(format!("-DCYCLES={}", self.cycles))
            .arg("-DLOG=\"tb.log\"")
            .arg(&self.tb)
            .args(["dump.v", "slotforge_top.v"])
            .current_dir(dir)
            .output()
            .unwrap();
        if !o.status.success() {
            let e = String::from_utf8_lossy(&o.stderr).to_string();
            return Verdicts {
                compile: Some(e.clone()),
                independent: Err(format!("does not compile: {e}")),
                check: Err("no VCD: does not compile".into()),
            };
        }
        let mut child = Command::new("vvp")
            .args(["-n", "sim"])
            .current_dir(dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let t0 = Instant::now();
        let ran = loop {
            if let Some(st) = child.try_wait().unwrap() {
                break if st.success() {
                    Ok(())
                } else {
                    Err(format!("vvp: {st}"))
                };
            }
            if t0.elapsed() > VVP_TIMEOUT {
                let _ = child.kill();
                let _ = child.wait();
                break Err(format!("vvp: no finish within {VVP_TIMEOUT:?}"));
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        let independent = ran.clone().and_then(|()| {
            let log = std::fs::read_to_string(dir.join("tb.log")).map_err(|e| e.to_string())?;
            judge(&self.mix, s, &log, self.cycles)
        });
        let check = match ::judge::check_vcd(s, dir.join("wave.vcd"), None) {
            Ok(r) if r.ok => Ok(()),
            Ok(r) => Err(r.summary().lines().next().unwrap_or("").to_string()),
            Err(e) => Err(format!("error: {e}")),
        };
        Verdicts {
            compile: None,
            independent,
            check,
        }
    }
}

fn short(r: &Result<(), String>) -> String {
    match r {
        Ok(()) => "accept".into(),
        Err(e) => {
            let e = e.replace('\n', " ");
            format!("REJECT ({})", e.chars().take(90).collect::<String>())
        }
    }
}

/// A campaign (36 mutants, each in Icarus): `make test-long`.
#[test]
#[ignore = "long: make test-long"]
fn every_mutant_the_independent_testbench_rejects_is_rejected_by_check() {
    if !tools::require_tool("iverilog") {
        return;
    }
    let t0 = Instant::now();
    let mix = lut_gen::load(&testkit::mix("mutants")).unwrap();
    let s = lut_gen::synthesize(&mix).unwrap();
    let bench = Bench {
        cycles: s.grid.frame_cycles * 5 / 2 + 50,
        tb: manifest().join("../../tests/tb/adc_tb.v"),
        mix,
        s,
    };
    let original = hdl::emit(&bench.s, None)
        .unwrap()
        .file("slotforge_top.v")
        .unwrap()
        .to_string();

    // the unmutated design passes both, so the test can fail
    let d = tempfile::tempdir().unwrap();
    let v = bench.run(&original, d.path());
    assert!(v.compile.is_none(), "original: {v:?}");
    assert_eq!(v.independent, Ok(()), "original, independent testbench");
    assert_eq!(v.check, Ok(()), "original, check_vcd");

    // COSIM_MUTANTS=N: up to N sites per operator instead of PER_OP (a longer hunt)
    let per_op: Vec<(Operator, usize)> = match std::env::var("COSIM_MUTANTS") {
        Ok(n) => {
            let n = n
                .parse()
                .expect("COSIM_MUTANTS: a number of sites per operator");
            Operator::ALL.iter().map(|&o| (o, n)).collect()
        }
        Err(_) => PER_OP.to_vec(),
    };
    let mutants = mutate::mutants(&original, &per_op);
    assert!(mutants.len() >= 30, "only {} mutants", mutants.len());
    let results: Mutex<Vec<Option<Verdicts>>> =
        Mutex::new((0..mutants.len()).map(|_| None).collect());
    let next = AtomicUsize::new(0);
    std::thread::scope(|sc| {
        let workers = std::env::var("COSIM_MUTANT_JOBS")
            .ok()
            .and_then(|j| j.parse().ok())
            .unwrap_or(2);
        for _ in 0..workers {
            sc.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(m) = mutants.get(i) else { break };
                let d = tempfile::tempdir().unwrap();
                let v = bench.run(&m.text, d.path());
                results.lock().unwrap()[i] = Some(v);
            });
        }
    });
    let results: Vec<Verdicts> = results
        .into_inner()
        .unwrap()
        .into_iter()
        .map(Option::unwrap)
        .collect();

    let mut per_op: BTreeMap<Operator, [usize; 4]> = BTreeMap::new();
    let (mut compiled, mut by_tb, mut by_check, mut both_accept) = (0, 0, 0, 0);
    let mut slipped = Vec::new();
    for (m, v) in mutants.iter().zip(&results) {
        eprintln!(
            "{:<60} tb: {:<40} check: {}",
            m.describe(),
            if v.compile.is_some() {
                "does not compile".into()
            } else {
                short(&v.independent)
            },
            if v.compile.is_some() {
                String::new()
            } else {
                short(&v.check)
            }
        );
        let e = per_op.entry(m.site.op).or_default();
        e[0] += 1;
        if v.compile.is_some() {
            continue;
        }
        compiled += 1;
        let (tb_rej, chk_rej) = (v.independent.is_err(), v.check.is_err());
        by_tb += tb_rej as usize;
        by_check += chk_rej as usize;
        e[1] += tb_rej as usize;
        e[2] += chk_rej as usize;
        if !tb_rej && !chk_rej {
            both_accept += 1;
            e[3] += 1;
        }
        if tb_rej && !chk_rej {
            slipped.push(format!("{}: {}", m.describe(), short(&v.independent)));
        }
    }
    eprintln!("operator  mutants  killed-by-tb  killed-by-check  both-accept");
    for (op, [n, t, c, a]) in &per_op {
        eprintln!("{:<9} {n:>7} {t:>13} {c:>16} {a:>12}", op.name());
    }
    eprintln!(
        "{} mutants, {compiled} compile; independent testbench kills {by_tb}, check kills {by_check}; \
         {both_accept} accepted by both (equivalent on this stimulus); {:.1} s",
        mutants.len(),
        t0.elapsed().as_secs_f64()
    );
    assert!(
        slipped.is_empty(),
        "mutants the independent testbench rejects but check accepts:\n{}",
        slipped.join("\n")
    );
    assert!(compiled >= 20, "only {compiled} mutants compile");
    assert!(
        by_tb >= compiled / 2,
        "the testbench kills only {by_tb} of {compiled}"
    );
}

// ---- Verilog mutants through the fault campaign ----------------------------

/// The campaign's plan for `mutants` of the test mix on `engines`, without
/// the target's own classes.
fn mutant_plan(
    s: &lut_gen::Schedule,
    per_op: &[(Operator, usize)],
    engines: &[engines::Backend],
    prove: bool,
) -> Plan {
    let original = engines::verilog(s).unwrap();
    let mut plan = Plan::new(Target::Model, 3, 0);
    plan.builtin = false;
    plan.prove = prove;
    plan.verilog_engines = engines.to_vec();
    plan.verilog_faults = mutate::mutants(&original, per_op)
        .into_iter()
        .map(|m| VerilogFault {
            class: FaultClass::Mutant(m.site.op.name().into()),
            name: m.describe(),
            verilog: m.text,
        })
        .collect();
    plan
}

/// Every mutant run is in the matrix: detected, undetected or proved
/// equivalent, never dropped; an undetected one carries the equivalence
/// check's answer (never a proof).
fn assert_every_mutant_is_counted(c: &Campaign, plan: &Plan) {
    let mut runs = 0;
    for k in c.classes.iter().filter(|k| k.level == Level::Verilog) {
        assert_eq!(
            k.detected + k.undetected.len() as u64 + k.proved_equivalent.len() as u64,
            k.injected,
            "{k:?}"
        );
        for i in &k.undetected {
            let e = i.equivalence.as_ref().expect("an equivalence verdict");
            assert!(!e.is_proof(), "{i:?}");
        }
        runs += k.injected;
    }
    let n = plan.verilog_engines.len() as u64;
    assert!(runs > 0 && runs <= n * plan.verilog_faults.len() as u64);
    let engines: Vec<&str> = c.engines.iter().map(|e| e.engine).collect();
    let want: Vec<&str> = plan.verilog_engines.iter().map(|e| e.name()).collect();
    assert_eq!(engines, want);
    assert_eq!(c.engines.iter().map(|e| e.injected).sum::<u64>(), runs);
    // the clean Verilog on both engines, judged by every detector, passes
    assert_eq!(c.false_alarms.rejected, 0, "{:?}", c.false_alarms);
}

/// A few mutants of the emitted Verilog reach a Verilog engine through the
/// one campaign (Icarus: it builds in a second, where Verilator builds each
/// mutant for a minute; the long test runs both): each stuck output is
/// caught by the model comparison or proved equivalent at the ports.
#[test]
fn a_few_mutants_run_through_the_campaign_on_icarus() {
    if !tools::require_tools(&["iverilog", "yosys", "yosys-abc"]) {
        return;
    }
    let s = mutants_schedule();
    // stuck outputs: they change a pin whatever the schedule, so no
    // equivalence check (up to 90 s each) runs in the default suite
    let plan = mutant_plan(
        &s,
        &[(Operator::Stuck, 3)],
        &[engines::Backend::Icarus],
        false,
    );
    assert_eq!(plan.verilog_faults.len(), 3);
    let c = campaign_with(&s, &plan).unwrap();
    assert_every_mutant_is_counted(&c, &plan);
    let stuck = c
        .classes
        .iter()
        .find(|k| k.name == FaultClass::Mutant("stuck".into()))
        .expect("the stuck output's class");
    // measured: all three change a pin (with two evenly spaced picks, the
    // merger's registered lane enables moved one onto the queue form's
    // constant `grant`, which only a chain reads: proved equivalent; the
    // long test's six stuck outputs still reach the equivalence check)
    assert_eq!(stuck.injected, 3, "{stuck:?}");
    assert_eq!(stuck.detected_by[&Detector::Model], 3, "{stuck:?}");
    assert!(stuck.proved_equivalent.is_empty(), "{stuck:?}");
    assert!(c.column(Detector::Prove).unwrap().not_run.is_some());
}

/// The full mutant campaign (36 mutants, each on Verilator and Icarus, each
/// proved): `make test-long`.
#[test]
#[ignore = "long: make test-long"]
fn the_mutant_campaign_through_every_detector_and_prove() {
    if !tools::require_tools(&["verilator", "iverilog", "yosys", "yosys-abc", "sigrok-cli"]) {
        return;
    }
    let s = mutants_schedule();
    let plan = mutant_plan(
        &s,
        &PER_OP,
        &[engines::Backend::Verilator, engines::Backend::Icarus],
        true,
    );
    let t = Instant::now();
    let c = campaign_with(&s, &plan).unwrap();
    for k in &c.classes {
        eprintln!(
            "{:<16} {} injected, {} detected {:?}, {} undetected, {} proved equivalent",
            k.name,
            k.injected,
            k.detected,
            k.detected_by,
            k.undetected.len(),
            k.proved_equivalent.len()
        );
        for i in &k.undetected {
            eprintln!(
                "    UNDETECTED {} on {}: {:?}",
                i.fault, i.engine, i.equivalence
            );
        }
    }
    eprintln!("{:.1} s", t.elapsed().as_secs_f64());
    assert_every_mutant_is_counted(&c, &plan);
    // prove sees every mutant's design and catches some the runs miss, or
    // none slips past the runs
    let prove = c.column(Detector::Prove).unwrap();
    assert!(prove.not_run.is_none() && prove.detected > 0, "{prove:?}");
}
