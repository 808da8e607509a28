//! `formal::prove` end to end: yosys, ABC and Icarus on real designs.
//!
//! Default suite (quick): the smallest preset proves for all time; a
//! Verilog mutant that changes an output fails with a counterexample whose
//! VCD the checker rejects at the same cycle; a fault that shows only after
//! several frames fails too (the recurrence check sees the design keeps
//! state across frames and the search goes deeper); a random mix from
//! `campaign::mixgen` proves; an AXI4-Stream link's harness, a bounded search
//! of its clean gateware and two link mutants.
//! Long (`make test-long`): every preset and the 16-branch / 1,024-channel
//! test mixes prove; six random mixes prove; the mutant campaign; the deep
//! fault classes against a three-frame simulation; the `symbolic` and `abc`
//! engines agree; the AXI4-Stream link over a slice and its payload and
//! FIFO faults.

use crate::common;

use std::path::Path;
use std::time::Instant;

use formal::DeepFault;
use formal::{Outcome, Proof, ProveOptions};

use common::{assert_fails_exactly, assert_rejected_at_its_cycle, edit, emitted, failed};
use common::{rejected, root, schedule, TOOLS};
use testkit::mutate;

// Missing tools fail under CI=true, skip loudly elsewhere.
use testkit::tools;

fn prove(s: &lut_gen::Schedule, design: &str, out: &Path) -> Proof {
    let mut o = ProveOptions::new(out);
    o.timeout_s = 1200;
    o.bmc_timeout_s = 1200;
    o.frame_counter = Some(hdl::LINK_FRAME_COUNTER.to_string());
    o.mode_decision = Some(hdl::MODE_DECISION.to_string());
    o.trigger_run = Some(hdl::TRIGGER_RUN.to_string());
    formal::prove(s, design, &o).expect("prove runs")
}

/// `prove` of the design emitted for the mix at `rel` with `from` edited
/// to `to`, in a fresh folder (kept while the proof is read).
fn prove_edited(rel: &str, from: &str, to: &str) -> (Proof, tempfile::TempDir) {
    let s = schedule(rel);
    let bad = edit(&emitted(&s), from, to);
    let dir = tempfile::tempdir().unwrap();
    (prove(&s, &bad, dir.path()), dir)
}

/// The checker must reject the counterexample's VCD, at the cycle prove names.
fn assert_counterexample(s: &lut_gen::Schedule, p: &Proof) {
    assert_eq!(p.result, Outcome::Failed, "{}", p.summary());
    let c = p.counterexample.as_ref().expect("a counterexample");
    assert!(c.reproduced, "the replay reproduces it: {}", p.summary());
    assert!(c.vcd.exists() && c.gtkw.exists(), "{c:?}");
    assert!(
        p.properties.iter().any(|q| q.result == Outcome::Failed),
        "the replay names the failing property: {}",
        p.summary()
    );
    let report = rejected(s, c);
    if c.cycle >= 0 {
        assert_rejected_at_its_cycle(&report, p, c);
    }
}

/// A preset (120,000-cycle frame) proves; about a CPU minute, so in `make
/// test-long`: the default suite proves the tiny mix through the CLI
/// (`tests/prove_cli.rs`).
#[test]
#[ignore = "long: make test-long"]
fn smallest_preset_proves_for_all_time() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("mixes/softslip1k.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    eprintln!("{}", p.summary());
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    assert!(p.properties.iter().all(|q| q.result == Outcome::Proved));
    assert_eq!(p.depth, 2 * s.grid.frame_cycles + 2);
    assert!(p.counterexample.is_none());
}

/// Mutants of the emitted Verilog on the small two-branch mutation mix.
fn mutants(s: &lut_gen::Schedule) -> Vec<mutate::Mutant> {
    use mutate::Operator::*;
    let per_op = [
        (RelOp, 5),
        (Const, 8),
        (Reset, 5),
        (AndOr, 3),
        (Arith, 3),
        (DropNot, 2),
        (Concat, 4),
        (Stuck, 6),
    ];
    mutate::mutants(&emitted(s), &per_op)
}

#[test]
fn an_output_mutant_fails_with_a_counterexample_check_rejects() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/mutants.toml");
    // A stuck output: it changes a pin whatever the schedule.
    let m = mutants(&s)
        .into_iter()
        .find(|m| m.site.op == mutate::Operator::Stuck)
        .expect("a stuck-output mutant");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &m.text, dir.path());
    eprintln!("{}\n{}", m.describe(), p.summary());
    assert_counterexample(&s, &p);
}

#[test]
fn a_fault_after_five_frames_fails_and_is_never_called_proved() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/mutants.toml");
    let f = DeepFault::LateCounter { frames: 5 };
    let design = f.apply(&s, &emitted(&s)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &design, dir.path());
    eprintln!("{}", p.summary());
    assert_counterexample(&s, &p);
    let c = p.counterexample.as_ref().unwrap();
    assert_eq!(
        c.cycle as u64,
        5 * s.grid.frame_cycles + 1,
        "{}",
        p.summary()
    );
}

/// Random mixes of `common::quick_proof_shape` (each proof takes seconds).
fn unseen_mixes(count: usize) -> Vec<(u64, lut_gen::Schedule)> {
    unseen_mixes_with(count, 0, &|_| true)
}

/// [`unseen_mixes`] with branches drawn without a mux 1 in `muxless`, kept
/// when `keep` says so.
fn unseen_mixes_with(
    count: usize,
    muxless: u64,
    keep: &dyn Fn(&lut_gen::Schedule) -> bool,
) -> Vec<(u64, lut_gen::Schedule)> {
    let shape = common::quick_proof_shape(muxless);
    let mut found = Vec::new();
    for seed in 1..200u64 {
        let text = campaign::random_mix(seed, &shape);
        let path = Path::new("random.toml");
        let Ok(mix) = lut_gen::parse(path, &text) else {
            continue;
        };
        // An overloaded draw has no schedule; one beyond the harness's
        // limits has no proof to give: both are skipped, not proved.
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        if formal::generate(&s).is_err() || !keep(&s) {
            continue;
        }
        found.push((seed, s));
        if found.len() == count {
            break;
        }
    }
    assert_eq!(found.len(), count, "too few feasible random mixes");
    found
}

fn assert_unseen_mix_proves(seed: u64, s: &lut_gen::Schedule) {
    let dir = tempfile::tempdir().unwrap();
    let p = prove(s, &emitted(s), dir.path());
    eprintln!("random mix {seed}: {}", p.summary());
    assert_eq!(p.result, Outcome::Proved, "seed {seed}: {}", p.summary());
    assert_eq!(p.depth, 2 * s.grid.frame_cycles + 2);
    assert!(p.properties.iter().all(|q| q.result == Outcome::Proved));
}

/// A mix no test was written for proves for all time (seconds).
#[test]
fn an_unseen_random_mix_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let (seed, s) = unseen_mixes(1).remove(0);
    assert_unseen_mix_proves(seed, &s);
}

/// A random mix with a branch that has no mux (`mux = "none"`) beside one
/// that has: the top has no mux lanes for it, the harness asserts none for
/// it (no `mux[...]` property), and the rest of the contract proves.
#[test]
fn an_unseen_mix_with_a_muxless_branch_proves() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let mixed = |s: &lut_gen::Schedule| {
        let l = lut_gen::Layout::new(s);
        l.muxed.contains(&true) && l.muxed.contains(&false)
    };
    let (seed, s) = unseen_mixes_with(1, 2, &mixed).remove(0);
    let l = lut_gen::Layout::new(&s);
    let h = formal::generate(&s).unwrap();
    for (b, br) in s.branches.iter().enumerate() {
        let named = h
            .properties
            .iter()
            .any(|p| p.name == format!("mux[{}]", br.name));
        assert_eq!(named, l.muxed[b], "seed {seed}: branch {}", br.name);
    }
    assert_unseen_mix_proves(seed, &s);
}

/// vibrotactile8k has no mux at all: its top has no `mux_sel`/`mux_en`, and
/// the harness neither declares nor connects them.
#[test]
fn a_mix_without_muxes_has_a_harness_without_mux_pins() {
    let s = schedule("mixes/vibrotactile8k.toml");
    let h = formal::generate(&s).unwrap();
    assert!(!h.verilog.contains("mux_sel") && !h.verilog.contains("mux_en"));
    assert!(!h.properties.iter().any(|p| p.name.starts_with("mux[")));
}

#[test]
fn harness_is_deterministic_and_names_every_contract_property() {
    let s = schedule("mixes/eskin34.toml");
    let a = formal::generate(&s).unwrap();
    let b = formal::generate(&s).unwrap();
    assert_eq!(a.verilog, b.verilog);
    let names: Vec<&str> = a.properties.iter().map(|p| p.name.as_str()).collect();
    for want in [
        "conversion[standard]",
        "sclk[static]",
        "mux[acoustic]",
        "stream.valid",
        "stream.channel",
        "stream.value",
    ] {
        assert!(names.contains(&want), "{want} missing from {names:?}");
    }
    // The harness never names the design's internals: only the port contract.
    assert!(
        !a.verilog.contains("dut."),
        "harness reaches into the design"
    );
}

/// A small AXI4-Stream mix: `tiny` (4 MHz, 4,000-cycle frame) with a
/// slave that takes every beat within 8 cycles.
fn tiny_axis() -> lut_gen::Schedule {
    let path = root().join("testkit/mixes/tiny.toml");
    let text = std::fs::read_to_string(&path).unwrap()
        + "\n[link]\nkind = \"axis\"\ntlast = \"slice\"\nready_within = 8\n";
    let mix = lut_gen::parse(Path::new("tiny-axis.toml"), &text).expect("parses");
    lut_gen::synthesize(&mix).expect("feasible")
}

/// yosys reads a memory's table of initial words from a `$readmemh` file
/// (the engine writes one beside the design, `design.yosys.v`): yosys
/// makes the same memories of it, word for word, as of the table in the
/// text, and the rest of the text is the same.
#[test]
fn tables_read_from_hex_files_give_yosys_the_same_memories() {
    if !tools::require_tools(&["yosys"]) {
        return;
    }
    for mix in ["testkit/mixes/cmd-modes.toml", "mixes/eskin34.toml"] {
        let s = schedule(mix);
        let h = formal::generate(&s).expect("a harness");
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("harness.v"), &h.verilog).unwrap();
        std::fs::write(dir.path().join("design.v"), emitted(&s)).unwrap();
        formal::prepare(dir.path(), formal::Solver::Symbolic).expect("yosys");
        let (given, read) = (
            memories(dir.path(), "design.v"),
            memories(dir.path(), "design.yosys.v"),
        );
        assert!(given.len() >= 3, "{mix}: {given:?}");
        assert_eq!(given, read, "{mix}");
        let text = |f: &str| std::fs::read_to_string(dir.path().join(f)).unwrap();
        // the rest of the text the same, on the same lines (yosys's
        // messages name them)
        let outside = |t: String| -> Vec<(usize, String)> {
            (t.lines().enumerate())
                .filter(|(_, l)| !l.contains("] = ") && !l.contains("initial"))
                .filter(|(_, l)| !matches!(l.trim(), "end" | ""))
                .map(|(k, l)| (k, l.to_string()))
                .collect()
        };
        assert_eq!(
            outside(text("design.v")),
            outside(text("design.yosys.v")),
            "{mix}"
        );
    }
}

/// Each memory yosys makes of `file` in `dir`: its module, name, size and
/// initial words (`write_rtlil` after `memory_collect`).
/// A memory yosys named itself (`proc_rom` makes one of a `case` table,
/// `$auto$proc_rom.cc:150:do_switch$586`) without its running number,
/// which counts the objects made before it in that file.
fn unnumbered(id: &str) -> String {
    match id.strip_suffix('"').and_then(|s| s.rsplit_once('$')) {
        Some((head, n)) if id.starts_with("\"$auto$") && n.bytes().all(|b| b.is_ascii_digit()) => {
            format!("{head}$N\"")
        }
        _ => id.to_string(),
    }
}

fn memories(dir: &Path, file: &str) -> Vec<String> {
    let script = format!("read_verilog -formal {file}; proc; memory_collect; write_rtlil mems.il");
    let ok = std::process::Command::new("yosys")
        .args(["-q", "-p", &script])
        .current_dir(dir)
        .status()
        .unwrap()
        .success();
    assert!(ok, "yosys reads {file}");
    let il = std::fs::read_to_string(dir.join("mems.il")).unwrap();
    let (mut module, mut cell, mut out) = ("", None::<String>, Vec::new());
    for line in il.lines().map(str::trim) {
        if let Some(m) = line.strip_prefix("module ") {
            module = m;
        } else if line.starts_with("cell $mem_v2 ") {
            cell = Some(module.to_string());
        } else if line == "end" {
            out.extend(cell.take());
        } else if let Some(c) = cell.as_mut() {
            for p in [
                "parameter \\MEMID ",
                "parameter \\SIZE ",
                "parameter \\WIDTH ",
                "parameter \\INIT ",
            ] {
                if let Some(v) = line.strip_prefix(p) {
                    c.push(' ');
                    c.push_str(&unnumbered(v));
                }
            }
        }
    }
    out.sort();
    out
}

/// ABC's bounded search from reset of harness + `design`, `steps` deep.
fn bmc(s: &lut_gen::Schedule, design: &str, steps: u64) -> formal::SolverVerdict {
    let h = formal::generate(s).expect("a harness");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("harness.v"), &h.verilog).unwrap();
    std::fs::write(dir.path().join("design.v"), design).unwrap();
    let prep = formal::prepare(dir.path(), formal::Solver::Abc).expect("yosys");
    formal::bmc(&prep, steps, 300).expect("bmc3 runs")
}

#[test]
fn axis_harness_models_the_slave_and_names_the_link_properties() {
    let s = schedule("mixes/eskin34-axis.toml");
    let h = formal::generate(&s).expect("an AXI4-Stream mix has a harness");
    let names: Vec<&str> = h.properties.iter().map(|p| p.name.as_str()).collect();
    for want in [
        "link.overflow",
        "axis.tvalid",
        "axis.payload",
        "stream.value",
    ] {
        assert!(names.contains(&want), "{want} missing from {names:?}");
    }
    let overflow = h
        .properties
        .iter()
        .find(|p| p.name == "link.overflow")
        .unwrap();
    assert!(
        overflow.what.contains("within 64 cycles"),
        "{}",
        overflow.what
    );
    // tready is the harness's choice within the guarantee, never assumed.
    let inputs: Vec<&str> = h.inputs.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(inputs, ["adc_miso", formal::TREADY_ANY]);
    assert!(
        h.verilog.contains("waited >= 6'd63"),
        "deadline: 63 cycles waited"
    );
    assert!(
        !h.verilog.contains("assume"),
        "the slave is modelled, not assumed"
    );
    assert!(h.verilog.contains(".m_axis_tready(m_axis_tready)"));
}

/// The harness's slave when it is never early (`tready_any` low) is the
/// simulations' worst-case slave: `judge::AxisSlave` with
/// `link::ReadyPattern::WorstCase`, fed the same `tvalid`, raises `tready`
/// in exactly the same cycles (each beat taken in its `ready_within`-th
/// cycle), so the harness's slaves are the guarantee's, to the cycle.
#[test]
fn the_harness_slave_never_early_is_the_worst_case_slave() {
    if !tools::require_tools(&["iverilog", "vvp"]) {
        return;
    }
    let s = tiny_axis();
    let h = formal::generate(&s).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("harness.v"), &h.verilog).unwrap();
    std::fs::write(dir.path().join("design.v"), emitted(&s)).unwrap();
    let tb = format!(
        "`timescale 1ns/1ns\nmodule tb;\n  reg clk = 1'b0;\n  reg [{}:0] adc_miso = 0;\n  \
         integer i, seed;\n  slotforge_formal h (.clk(clk), .adc_miso(adc_miso), .{}(1'b0));\n  \
         initial begin\n    seed = 3;\n    for (i = 0; i < 800; i = i + 1) begin\n      \
         adc_miso = $random(seed);\n      #1 clk = 1'b1;\n      #1 clk = 1'b0;\n      \
         if (h.st == 2'd2) $display(\"C %b %b\", h.m_axis_tvalid, h.m_axis_tready);\n    end\n    \
         $finish;\n  end\nendmodule\n",
        s.branches.len() - 1,
        formal::TREADY_ANY
    );
    std::fs::write(dir.path().join("tb.v"), tb).unwrap();
    let ok = std::process::Command::new("iverilog")
        .args(["-g2005", "-o", "tb.vvp", "tb.v", "harness.v", "design.v"])
        .current_dir(dir.path())
        .status()
        .unwrap();
    assert!(ok.success());
    let out = std::process::Command::new("vvp")
        .args(["-n", "tb.vvp"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let trace: Vec<(bool, bool)> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.strip_prefix("C "))
        .map(|l| (l.as_bytes()[0] == b'1', l.as_bytes()[2] == b'1'))
        .collect();
    // A design that shows the harness's tvalid, cycle by cycle.
    struct Trace(std::vec::IntoIter<bool>);
    impl judge::Dut for Trace {
        fn step(&mut self, rst: bool, _miso: u64) -> lut_gen::Pins {
            lut_gen::Pins {
                axis_tvalid: !rst && self.0.next().unwrap_or(false),
                ..Default::default()
            }
        }
    }
    let tvalid: Vec<bool> = trace.iter().map(|&(v, _)| v).collect();
    let within = s.mix.link.unwrap().ready_within;
    let mut slave = judge::AxisSlave::new(
        Trace(tvalid.into_iter()),
        link::ReadyPattern::WorstCase,
        within,
    );
    use judge::Dut;
    slave.step(true, 0);
    let (mut waits, mut taken) = (0, 0);
    for (c, &(valid, ready)) in trace.iter().enumerate() {
        let p = slave.step(false, 0);
        assert_eq!(p.axis_tready, ready, "cycle {c}: tvalid {valid}");
        waits += (valid && !ready) as usize;
        taken += (valid && ready) as usize;
    }
    // Every beat taken waited its ready_within - 1 cycles first.
    assert!(
        trace.len() >= 790 && taken >= 10 && waits >= (within as usize - 1) * taken,
        "{} cycles, {taken} beats taken, {waits} cycles waited",
        trace.len()
    );
}

/// The clean AXI4-Stream gateware: no violation of any property (the
/// link's three included) in 300 steps from reset, under every slave the
/// guarantee allows: beats start in cycle 0 (the first header) and wait.
#[test]
fn axis_gateware_has_no_violation_in_a_bounded_search() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = tiny_axis();
    let v = bmc(&s, &emitted(&s), 300);
    assert_eq!(v, formal::SolverVerdict::Bounded { steps: 300 }, "{v:?}");
}

/// The clean AXI4-Stream gateware proves for all time under every slave
/// the guarantee allows: the handshake's properties by 2-induction, the
/// FIFO's fill level by explicit-state search over the slave's choices,
/// the rest by symbolic simulation, its paths subsumed by the slave's wait.
#[test]
fn axis_gateware_proves_for_every_slave() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = tiny_axis();
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    assert!(p.not_covered.is_empty(), "{:?}", p.not_covered);
    for name in ["link.bytes", "link.packets", "link.overflow"] {
        let r = p.properties.iter().find(|q| q.name == name).unwrap();
        assert_eq!(r.result, Outcome::Proved, "{}", p.summary());
    }
    for how in [
        "split on the slave's choices",
        "frame counter generalised",
        // paths equal but for the slave's wait: the lower count kept
        "whose slave had waited fewer cycles",
    ] {
        assert!(p.note.contains(how), "{how}: {}", p.note);
    }
}

/// With `tlast = "frame"` (two slices a frame) the clean gateware proves
/// its beats for all time, and the gateware of `tlast = "slice"` (tlast on
/// every trailer, so on a beat where the frame's packet goes on) fails
/// `link.bytes` with a trace `check` rejects at the same cycle.
#[test]
fn axis_tlast_per_frame_proves_and_tlast_per_slice_fails() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let slice = tiny_axis();
    let path = root().join("testkit/mixes/tiny.toml");
    let text = std::fs::read_to_string(&path).unwrap()
        + "\n[link]\nkind = \"axis\"\ntlast = \"frame\"\nready_within = 8\n";
    let mix = lut_gen::parse(Path::new("tiny-axis-frame.toml"), &text).expect("parses");
    let s = lut_gen::synthesize(&mix).expect("feasible");
    assert_eq!(s.grid.slices_per_frame, 2);
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    assert!(p.not_covered.is_empty(), "{:?}", p.not_covered);
    assert_mutant_fails(&s, &emitted(&slice), "link.bytes");
}

/// Mutants of the AXI4-Stream master fail the proof with a counterexample
/// whose trace `check` rejects at the same cycle: a beat withdrawn after
/// one cycle whether taken or not (tvalid falls while tready is low), and
/// the overflow flag tied high (the long suite has more).
#[test]
fn axis_mutants_fail_with_counterexamples_check_rejects() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = tiny_axis();
    let clean = emitted(&s);
    for (from, to, property) in [
        (
            "if (busy & tready) busy <= 1'b0;",
            "if (busy) busy <= 1'b0;",
            "axis.tvalid",
        ),
        ("  ovf = ovf_r;", "  ovf = 1'b1;", "link.overflow"),
    ] {
        assert_mutant_fails(&s, &edit(&clean, from, to), property);
    }
}

/// `design` fails `prove` with a counterexample `check` rejects, and
/// `property` is among the failing ones.
fn assert_mutant_fails(s: &lut_gen::Schedule, design: &str, property: &str) {
    {
        let dir = tempfile::tempdir().unwrap();
        let p = prove(s, design, dir.path());
        eprintln!("{}", p.summary());
        assert_counterexample(s, &p);
        let failed = failed(&p);
        assert!(
            failed.contains(&property),
            "fails {failed:?}, not {property}"
        );
    }
}

/// Icarus runs `harnesses` (module names made unique) around one copy of
/// `design` on the same random MISO for `steps` cycles; returns the
/// mismatches it printed: a cycle where some harness's `ok` is low after
/// reset, or where `signals` (harness wires) differ between the first
/// harness and another.
fn icarus_compare(
    s: &lut_gen::Schedule,
    harnesses: &[&formal::Harness],
    design: &str,
    signals: &[String],
    steps: u64,
) -> Vec<String> {
    let dir = tempfile::tempdir().unwrap();
    let mut files = vec!["tb.v".to_string(), "design.v".to_string()];
    std::fs::write(dir.path().join("design.v"), design).unwrap();
    let mut tb = format!(
        "`timescale 1ns/1ns\nmodule tb;\n  reg clk = 1'b0;\n  reg [{}:0] adc_miso = 0;\n  integer i, seed, bad;\n",
        s.branches.len() - 1
    );
    for (k, h) in harnesses.iter().enumerate() {
        let name = format!("h{k}");
        let text = h.verilog.replace(
            "module slotforge_formal (",
            &format!("module slotforge_formal_{k} ("),
        );
        std::fs::write(dir.path().join(format!("{name}.v")), text).unwrap();
        files.push(format!("{name}.v"));
        tb += &format!("  slotforge_formal_{k} {name} (.clk(clk), .adc_miso(adc_miso));\n");
    }
    let mut checks = Vec::new();
    for k in 0..harnesses.len() {
        checks.push(format!("(h{k}.st != 2'd0 && h{k}.ok !== 1'b1)"));
        for sig in signals.iter().filter(|_| k > 0) {
            checks.push(format!("h0.{sig} !== h{k}.{sig}"));
        }
    }
    tb += &format!(
        "  initial begin\n    seed = 7; bad = 0;\n    for (i = 0; i < {steps}; i = i + 1) begin\n      \
         adc_miso = $random(seed);\n      #1 clk = 1'b1;\n      #1 clk = 1'b0;\n      \
         if ({}) begin\n        bad = bad + 1;\n        if (bad <= 5) $display(\"MISMATCH %0d\", i);\n      end\n    end\n    \
         $display(\"DONE %0d\", bad);\n    $finish;\n  end\nendmodule\n",
        checks.join(" || ")
    );
    std::fs::write(dir.path().join("tb.v"), tb).unwrap();
    let run = |cmd: &mut std::process::Command| {
        let out = cmd.current_dir(dir.path()).output().expect("runs");
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{text}");
        text
    };
    let mut args = vec!["-g2005".to_string(), "-o".into(), "tb.vvp".into()];
    args.extend(files);
    run(std::process::Command::new("iverilog").args(&args));
    let log = run(std::process::Command::new("vvp").args(["-n", "tb.vvp"]));
    assert!(log.contains("DONE"), "{log}");
    log.lines()
        .filter(|l| l.starts_with("MISMATCH"))
        .map(str::to_string)
        .collect()
}

/// The compact slot tables (for frames beyond the full tables) describe
/// the same schedule as the full ones: on a mix that fits both, with
/// rotation groups, every branch's table row and every property wire agree
/// in every cycle of two frames, and the clean design keeps `ok` high in
/// both.
#[test]
fn compact_and_full_harness_tables_agree_cycle_by_cycle() {
    if !tools::require_tools(&["iverilog", "vvp"]) {
        return;
    }
    let s = schedule("testkit/mixes/tiny.toml");
    let full = formal::generate_with(&s, formal::TableForm::Full).unwrap();
    let compact = formal::generate_with(&s, formal::TableForm::Compact).unwrap();
    assert!(compact.verilog.contains("case (sis)") && compact.verilog.contains("rot0_0"));
    assert!(!full.verilog.contains("case (sis)"));
    let mut signals: Vec<String> = (0..s.branches.len()).map(|b| format!("tab{b}")).collect();
    signals.extend(full.properties.iter().map(|p| p.wire.clone()));
    let bad = icarus_compare(
        &s,
        &[&full, &compact],
        &emitted(&s),
        &signals,
        2 * s.grid.frame_cycles + 2,
    );
    assert!(bad.is_empty(), "{bad:?}");
}

/// A frame of 80,000 slots (beyond the full tables) gets the compact
/// tables, and the emitted gateware (its compact slot LUT) keeps every
/// property through the first three slices, the 1 Hz channels' rotation
/// entries included.
#[test]
fn a_frame_beyond_the_full_tables_gets_the_compact_harness() {
    let s = schedule("formal/tests/data/frame80k.toml");
    assert!(s.grid.frame_slots > formal::FULL_TABLE_MAX_SLOTS);
    let h = formal::generate(&s).expect("a compact harness");
    assert!(h.verilog.contains("case (sis)"), "compact tables");
    let full = formal::generate_with(&s, formal::TableForm::Full);
    assert!(full.unwrap_err().to_string().contains("full tables"));
    if !tools::require_tools(&["iverilog", "vvp"]) {
        return;
    }
    let bad = icarus_compare(&s, &[&h], &emitted(&s), &[], 3 * s.grid.slice_cycles);
    assert!(bad.is_empty(), "{bad:?}");
}

// ---- long: make test-long -------------------------------------------------

#[test]
#[ignore = "long: make test-long"]
fn every_preset_and_the_largest_test_mixes_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let mut mixes: Vec<String> = std::fs::read_dir(root().join("mixes"))
        .unwrap()
        .map(|e| format!("mixes/{}", e.unwrap().file_name().to_string_lossy()))
        .filter(|n| n.ends_with(".toml"))
        // Not the presets with modes: tests/modes.rs proves the adaptive
        // preset on its own (it takes minutes).
        .filter(|n| lut_gen::load(&root().join(n)).unwrap().modes.is_none())
        .collect();
    mixes.sort();
    mixes.push("hdl/tests/data/b16.toml".into());
    mixes.push("hdl/tests/data/ch1024.toml".into());
    // 60 channels in 20 ms frames: the proof's cost against the frame length
    mixes.push("formal/tests/data/ch60-20ms.toml".into());
    for m in mixes {
        let s = schedule(&m);
        let dir = tempfile::tempdir().unwrap();
        let t = Instant::now();
        let p = prove(&s, &emitted(&s), dir.path());
        eprintln!(
            "{m}: {:?} in {:.1} s\n{}",
            p.result,
            t.elapsed().as_secs_f64(),
            p.summary()
        );
        assert_eq!(p.result, Outcome::Proved, "{m}: {}", p.summary());
    }
}

/// Six random mixes (one to three branches each) prove for all time.
#[test]
#[ignore = "long: make test-long"]
fn unseen_random_mixes_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    for (seed, s) in unseen_mixes(6) {
        assert_unseen_mix_proves(seed, &s);
    }
}

#[test]
#[ignore = "long: make test-long"]
fn mutant_campaign_every_output_changing_mutant_fails() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/mutants.toml");
    let (mut failed, mut proved, mut bounded, mut power_on) = (0, 0, 0, 0);
    for m in mutants(&s) {
        let dir = tempfile::tempdir().unwrap();
        let p = prove(&s, &m.text, dir.path());
        eprintln!("{}: {:?} ({:.1} s)", m.describe(), p.result, p.seconds);
        match p.result {
            // A violation that needs power-on values the reset does not set
            // cannot be replayed in Icarus (docs/formal.md); counted apart.
            Outcome::Failed if !p.counterexample.as_ref().unwrap().reproduced => power_on += 1,
            Outcome::Failed => {
                assert_counterexample(&s, &p);
                failed += 1;
            }
            // Proved: the mutant's outputs equal the contract in every state
            // (an equivalent mutant); never silently bounded.
            Outcome::Proved => proved += 1,
            Outcome::Bounded => bounded += 1,
        }
    }
    eprintln!(
        "mutants: {failed} failed (replayed, check rejects), {power_on} failed from a power-on state only, \
         {proved} proved (equivalent), {bounded} bounded"
    );
    assert_eq!(bounded, 0, "every mutant gets a verdict");
    assert!(failed > 0);
}

/// A three-frame simulation (Verilator, the default stimulus) passes the
/// deep faults; prove fails them with a counterexample check rejects.
#[test]
#[ignore = "long: make test-long"]
fn deep_faults_escape_three_frames_of_simulation_and_fail_prove() {
    if !tools::require_tools(&["yosys", "yosys-abc", "iverilog", "vvp", "verilator"]) {
        return;
    }
    let s = schedule("testkit/mixes/mutants.toml");
    for f in [
        DeepFault::LateCounter { frames: 4 },
        DeepFault::RareCollision,
    ] {
        let design = f.apply(&s, &emitted(&s)).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let rtl = dir.path().join("faulty.v");
        std::fs::write(&rtl, &design).unwrap();
        let opts = engines::SimOptions {
            rtl: Some(rtl),
            ..Default::default()
        };
        let sim = engines::run(&s, engines::Backend::Verilator, 3, &opts).expect("simulates");
        assert!(
            sim.ok,
            "{}: three frames of simulation already catch it",
            f.name()
        );
        let p = prove(&s, &design, dir.path());
        eprintln!("{}: simulation passes; prove:\n{}", f.name(), p.summary());
        assert_counterexample(&s, &p);
    }
}

/// The two engines that prove for all time, by different arguments, agree:
/// on the clean design both prove at the same recurrence depth; on the
/// frame-5 late counter and on an output mutant both fail at the same step
/// (both search from reset step by step, so both find the first violation).
#[test]
#[ignore = "long: make test-long"]
fn the_symbolic_and_abc_engines_agree() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/mutants.toml");
    let stuck = mutants(&s)
        .into_iter()
        .find(|m| m.site.op == mutate::Operator::Stuck)
        .expect("a stuck-output mutant")
        .text;
    let late = DeepFault::LateCounter { frames: 5 }
        .apply(&s, &emitted(&s))
        .unwrap();
    for (what, design) in [("clean", emitted(&s)), ("stuck", stuck), ("late", late)] {
        let run = |solver: formal::Solver| {
            let dir = tempfile::tempdir().unwrap();
            let mut o = ProveOptions::new(dir.path());
            o.solver = solver;
            let p = formal::prove(&s, &design, &o).expect("prove runs");
            eprintln!("{what}: {}", p.summary());
            (p.result, p.depth, p.cycle)
        };
        assert_eq!(
            run(formal::Solver::Symbolic),
            run(formal::Solver::Abc),
            "{what}"
        );
    }
}

/// The AXI4-Stream link under every slave the guarantee allows: the clean
/// gateware has no violation over a slice of the tiny mix (and 300 steps
/// of eskin34-axis); a new byte
/// loaded over a waiting one fails `axis.payload`; a FIFO one token short
/// of the planned depth overflows (the engine finds the slow slave), each
/// with a counterexample `check` rejects.
#[test]
#[ignore = "long: make test-long"]
fn axis_link_holds_for_every_slave_and_its_faults_fail() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = tiny_axis();
    let clean = emitted(&s);
    let payload = edit(&clean, "wire ready = !busy | tready;", "wire ready = 1'b1;");
    assert_mutant_fails(&s, &payload, "axis.payload");
    let (_, short) = hdl::verilog_pair(&s, hdl::GatewareFault::LinkFifoShort).unwrap();
    assert_mutant_fails(&s, &short, "link.overflow");
    // A whole slice (the link's period: a header and its records) and the
    // next slice's start; a free tready makes each step costly for bmc3.
    let steps = s.grid.slice_cycles + 4;
    let t = Instant::now();
    let v = bmc(&s, &clean, steps);
    eprintln!("clean: {v:?} in {:.1} s", t.elapsed().as_secs_f64());
    assert_eq!(v, formal::SolverVerdict::Bounded { steps }, "{v:?}");
    // The preset: its first beats wait up to 63 cycles behind any slave.
    let s = schedule("mixes/eskin34-axis.toml");
    let t = Instant::now();
    let v = bmc(&s, &emitted(&s), 300);
    eprintln!("eskin34-axis: {v:?} in {:.1} s", t.elapsed().as_secs_f64());
    assert_eq!(v, formal::SolverVerdict::Bounded { steps: 300 }, "{v:?}");
}

/// `tiny` with a 1 Mbaud UART link (4 cycles a bit).
fn tiny_uart() -> lut_gen::Schedule {
    let path = root().join("testkit/mixes/tiny.toml");
    let text =
        std::fs::read_to_string(&path).unwrap() + "\n[link]\nkind = \"uart\"\nbaud = 1_000_000\n";
    let mix = lut_gen::parse(Path::new("tiny-uart.toml"), &text).expect("parses");
    lut_gen::synthesize(&mix).expect("feasible")
}

/// A UART mix's proof reads the line (`link.bytes`, `link.packets`): the
/// clean gateware proves the whole contract, the link's bytes for all time
/// too (the frame counters generalised at frame starts: the state comes
/// round after a few frames, not 256), so the fault campaign takes it as the excuse
/// "contract proved"; a gateware whose `link_tx` is stuck high fails
/// `link.packets` (its tokens pile up in the harness's queue) and is
/// never excused.  Each design is proved once, the campaign's way
/// (`campaign::prove_in`): the proof and the verdict the campaign takes.
#[test]
fn a_uart_proof_reads_the_line_and_a_stuck_line_fails() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = tiny_uart();
    let clean = emitted(&s);
    let dir = tempfile::tempdir().unwrap();
    let (p, verdict) = campaign::prove_in(&s, &clean, dir.path()).expect("prove runs");
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    assert!(p.not_covered.is_empty(), "{:?}", p.not_covered);
    assert!(p.depth < 20 * s.grid.frame_cycles, "{}", p.summary());
    for name in ["link.bytes", "link.packets"] {
        assert!(
            p.properties
                .iter()
                .any(|q| q.name == name && q.result == Outcome::Proved),
            "{}",
            p.summary()
        );
    }
    assert!(p.summary().contains("PROVED (the whole contract)"));
    assert_eq!(verdict, campaign::ProveVerdict::Proved);
    let stuck = edit(&clean, "      tx = chr[0];", "      tx = 1'b1;");
    let dir = tempfile::tempdir().unwrap();
    let (p, verdict) = campaign::prove_in(&s, &stuck, dir.path()).expect("prove runs");
    assert_eq!(p.result, Outcome::Failed, "{}", p.summary());
    assert!(
        p.properties
            .iter()
            .any(|q| q.name == "link.packets" && q.result == Outcome::Failed),
        "{}",
        p.summary()
    );
    assert!(matches!(verdict, campaign::ProveVerdict::Failed { .. }));
}

/// Mixes whose frame carries 13 tokens (11 words, 2 boundaries) through a
/// FIFO of 3 entries, with a UART and with an AXI4-Stream: the FIFO's
/// pointers rewind when it empties, so the link's state at a frame start,
/// and the proof with it, comes round one frame later (without the rewind
/// the pointers moved by 13 mod 3 each frame, and both proofs came round
/// three frames later, at step 16,002).
#[test]
fn a_links_state_comes_round_with_the_frame() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let base = std::fs::read_to_string(root().join("testkit/mixes/tiny.toml")).unwrap()
        + "\n[[channel]]\nname = \"B2\"\nbranch = \"slow\"\nrate_hz = 1_000\n\n";
    for link in [
        "[link]\nkind = \"uart\"\nbaud = 1_000_000\n",
        "[link]\nkind = \"axis\"\ntlast = \"slice\"\nready_within = 8\n",
    ] {
        let mix =
            lut_gen::parse(Path::new("tiny-13.toml"), &(base.clone() + link)).expect("parses");
        let s = lut_gen::synthesize(&mix).expect("feasible");
        let design = emitted(&s);
        assert!(
            design.contains("FIFO of 2 tokens"),
            "{link}: the FIFO's depth moved"
        );
        let dir = tempfile::tempdir().unwrap();
        let p = prove(&s, &design, dir.path());
        assert_eq!(p.result, Outcome::Proved, "{link}: {}", p.summary());
        assert!(p.not_covered.is_empty(), "{link}: {:?}", p.not_covered);
        let f = s.grid.frame_cycles;
        assert_eq!(p.depth, 2 * f + 2, "{link}: {}", p.note);
    }
}

/// Without a link the same proof is the whole contract, and excuses.
/// `make test` holds it through the CLI (`prove_cli`'s
/// `proved_json_has_its_keys_and_exit_0`: nothing left uncovered, proved
/// for all time; the campaign's verdict of such a proof is the UART's
/// above).
#[test]
#[ignore = "long: make test-long (a third proof; make test proves tiny through the CLI)"]
fn a_proof_without_a_link_is_the_whole_contract() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/tiny.toml");
    let dir = tempfile::tempdir().unwrap();
    let (p, verdict) = campaign::prove_in(&s, &emitted(&s), dir.path()).expect("prove runs");
    assert!(p.not_covered.is_empty(), "{:?}", p.not_covered);
    assert!(p.note.starts_with("proved for all time"), "{}", p.note);
    assert!(p.summary().contains("PROVED (the whole contract)"));
    assert_eq!(verdict, campaign::ProveVerdict::Proved);
}

/// Mutants of the link module of the tiny mix with a UART (every operator,
/// spread over `slotforge_link`), each proved twice: with the packets'
/// frame counters generalised (the default) and without, where this
/// 4,000-cycle frame's 258 frames are simulated exactly (the truth for
/// all time).  The generalised proof never claims more: proved only if
/// the exact one proves, failed no later than the exact one with a trace
/// from reset the judge rejects, and bounded (the link's
/// bytes named as not covered) where it cannot tell.
#[test]
#[ignore = "long: make test-long (two proofs of each of 27 link mutants, about 4 minutes)"]
fn generalised_frame_counters_agree_with_the_exact_search_on_link_mutants() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    use mutate::Operator::*;
    let s = tiny_uart();
    let clean = emitted(&s);
    let start = clean
        .find("module slotforge_link(")
        .expect("the link module");
    let end = start + clean[start..].find("endmodule").unwrap();
    // not the power-on loops (`initial for ...`): a step of -1 never ends,
    // and yosys unrolls it until memory runs out
    let line_of = |at: usize| clean[..at].lines().last().unwrap_or("");
    let sites: Vec<mutate::Site> = (mutate::sites(&clean).into_iter())
        .filter(|x| x.start > start && x.end < end && !line_of(x.end).contains("initial"))
        .collect();
    let per_op = [
        (RelOp, 10),
        (Const, 10),
        (AndOr, 8),
        (Arith, 5),
        (DropNot, 3),
        (Stuck, 8),
    ];
    let (mut agree, mut bounded, mut lost) = (0, 0, 0);
    for site in mutate::select(&sites, &per_op) {
        let mut site = site;
        site.original = clean[site.start..site.end].to_string();
        let text = site.apply(&clean);
        eprintln!(
            "line {} `{}` -> `{}`",
            site.line, site.original, site.replacement
        );
        let dir = tempfile::tempdir().unwrap();
        let general = prove(&s, &text, dir.path());
        let mut o = ProveOptions::new(dir.path().join("exact"));
        o.timeout_s = 1200;
        o.bmc_timeout_s = 1200;
        let exact = formal::prove(&s, &text, &o).expect("prove runs");
        let what = format!(
            "line {} `{}` -> `{}`",
            site.line, site.original, site.replacement
        );
        eprintln!("{what}: {:?} / exact {:?}", general.result, exact.result);
        match general.result {
            Outcome::Proved => {
                assert_eq!(exact.result, Outcome::Proved, "{what}: {}", exact.summary());
                assert!(general.not_covered.is_empty(), "{what}");
                agree += 1;
            }
            // the whole harness at once finds the earliest violation of any
            // property; the search of before, the first of the rest (then
            // it never reads the line): never later, and a trace from reset
            Outcome::Failed => {
                assert_eq!(exact.result, Outcome::Failed, "{what}: {}", exact.summary());
                assert!(
                    general.cycle <= exact.cycle,
                    "{what}: {}",
                    general.summary()
                );
                let c = general.counterexample.as_ref().unwrap();
                // the judge rejects the replayed trace (at this cycle, or
                // earlier by a rule of its own, e.g. a token never sent)
                if c.reproduced && c.cycle >= 0 {
                    assert!(
                        c.check_cycle.is_some_and(|k| k <= c.cycle as u64),
                        "{what}: {c:?}"
                    );
                }
                agree += 1;
            }
            // not a claim: the exact search may prove what a generalised
            // state (a count beside a state no run has with it) fails
            Outcome::Bounded => {
                assert!(general
                    .not_covered
                    .iter()
                    .any(|n| n.contains("link.packets")));
                bounded += 1;
                lost += usize::from(exact.result == Outcome::Proved);
            }
        }
    }
    eprintln!("{agree} agree, {bounded} bounded ({lost} of them proved exactly)");
    assert!(agree > 20, "{agree} agree, {bounded} bounded");
}

/// Converters with a command word (an MCP3208 beside a listening AD7940;
/// an AD7689 with its two-conversion pipeline beside an AD7685; a
/// user-declared 16-channel part on inputs above 7): the
/// harness asserts `adc_mosi` bit for bit and leaves the prepared
/// conversions out of the stream, the emitted gateware proves, and the
/// proof says it does not cover what the part does with the word.  `make
/// test` proves the declared part's mix (a proof is 2 s of CPU); the
/// other two are `make test-long`'s.
#[test]
fn commanded_mixes_prove_and_name_what_the_part_does_as_not_covered() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    commanded_mix_proves("cmd-ads7953");
}

/// The MCP3208's and the AD7689's own mixes (`make test` proves both parts'
/// words in `cmd-modes`, a mix with modes: `modes.rs`).
#[test]
#[ignore = "long: make test-long (make test proves these parts in cmd-modes)"]
fn the_mcp3208s_and_the_ad7689s_mixes_prove_and_name_what_the_part_does() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    for name in ["cmd-mcp3208", "cmd-ad7689"] {
        commanded_mix_proves(name);
    }
}

/// The emitted gateware of `testkit/mixes/NAME.toml` proves, its words
/// on `adc_mosi` included, and only the part's conversion is not covered.
fn commanded_mix_proves(name: &str) {
    let s = schedule(&format!("testkit/mixes/{name}.toml"));
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    eprintln!("{name}: {}", p.summary());
    assert_eq!(p.result, Outcome::Proved, "{name}: {}", p.summary());
    let b = (0..s.branches.len()).find(|&b| s.has_command(b)).unwrap();
    let mosi = format!("mosi[{}]", s.branches[b].name);
    assert!(
        p.properties
            .iter()
            .any(|q| q.name == mosi && q.result == Outcome::Proved),
        "{name}: {}",
        p.summary()
    );
    assert_eq!(p.not_covered.len(), 1, "{name}: {:?}", p.not_covered);
    assert!(
        p.not_covered[0].contains("converts the input each word selects"),
        "{name}: {:?}",
        p.not_covered
    );
}

/// A gateware that takes channel bit 0 of the MCP3208's word from channel
/// bit 1 (the mix has inputs where they differ) fails `prove` on the
/// command word, with a counterexample the replay reproduces.
#[test]
fn a_gateware_sending_the_wrong_channel_bits_fails_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let (p, _dir) = prove_edited(
        "testkit/mixes/cmd-mcp3208.toml",
        "word = {sel[0], sel[1], sel[2], 1'b1, 1'b1};",
        "word = {sel[1], sel[1], sel[2], 1'b1, 1'b1};",
    );
    eprintln!("{}", p.summary());
    assert_fails_exactly(&p, &["mosi[cmd]"]);
    let c = p.counterexample.as_ref().expect("a counterexample");
    assert!(c.reproduced, "{}", p.summary());
}

/// A gateware that holds the AD7689's CNV high through the read (its
/// branch takes the sequencer's pin instead of the CNV pulse) fails
/// `prove` on the conversion pin, at the cycle the conversion ends.
#[test]
fn a_gateware_holding_the_ad7689s_cnv_through_the_read_fails_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let (p, _dir) = prove_edited(
        "testkit/mixes/cmd-ad7689.toml",
        "branch0_seq_cs_n = cnv_pulse0_pin_n;",
        "branch0_seq_cs_n = spi_seq0_cs_n;",
    );
    assert_fails_exactly(&p, &["conversion[cfg]"]);
}

/// Random mixes of `campaign::random_mix` with converters that take a
/// command word beside listening ones prove (no test was written for them).
#[test]
fn unseen_random_mixes_with_command_words_prove() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let shape = campaign::Shape {
        commanded: 2,
        ..common::quick_proof_shape(0)
    };
    let mut proved = 0;
    for seed in 1..60u64 {
        let text = campaign::random_mix(seed, &shape);
        let Ok(mix) = lut_gen::parse(Path::new("random.toml"), &text) else {
            continue;
        };
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        if !(0..s.branches.len()).any(|b| s.has_command(b)) || formal::generate(&s).is_err() {
            continue;
        }
        assert_unseen_mix_proves(seed, &s);
        proved += 1;
        if proved == 2 {
            break;
        }
    }
    assert_eq!(proved, 2, "too few feasible commanded random mixes");
}

/// External muxes in front of converters with their own (`testkit` mix
/// `cmd-front`: an AD7689 behind two TMUX1108s, a declared ADS7953-like
/// part behind one, an MCP3208 without): the harness asserts the front
/// mux's pins as an external-mux branch's and the words bit for bit, and
/// the gateware proves; with the wrapper's select bit 0 inverted it fails on
/// the fronted branch's mux.
#[test]
fn a_fronted_mix_proves_and_a_wrong_front_select_fails_on_its_mux() {
    if !tools::require_tools(&TOOLS) {
        return;
    }
    let s = schedule("testkit/mixes/cmd-front.toml");
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &emitted(&s), dir.path());
    assert_eq!(p.result, Outcome::Proved, "{}", p.summary());
    for name in ["mux[cfg]", "mosi[cfg]", "mux[ads]", "mosi[ads]"] {
        assert!(
            (p.properties.iter()).any(|q| q.name == name && q.result == Outcome::Proved),
            "{name}: {}",
            p.summary()
        );
    }
    let good = emitted(&s);
    let line = good
        .lines()
        .find(|l| l.trim_start().starts_with("assign mux_sel = core_mux_sel["))
        .unwrap();
    let bad = edit(&good, line, &line.replace(';', " ^ 6'd1;"));
    let dir = tempfile::tempdir().unwrap();
    let p = prove(&s, &bad, dir.path());
    assert_eq!(p.result, Outcome::Failed, "{}", p.summary());
    assert!(failed(&p).contains(&"mux[cfg]"), "{}", p.summary());
}
