//! Side-by-side throughput ratios (not a timed test):
//!   cargo bench -p engines --bench cosim [-- FRAMES]
//!
//! - 1: verilator back end with full checking vs the same verilated model stepped unchecked;
//! - 2: rusthdl back end with full checking vs hdl::RtlSim stepped unchecked;
//! - 2b: rusthdl back end with full checking vs the same core under rust-hdl's
//!   stock threaded `Simulation` (goal >= 20x);
//! - 3: model back end vs real time;
//! - 4: `check` of a VCD vs a bare streaming parse with the same reader;
//! - 5: `check` vs the `wellen` crate's bare load of the same VCD (single-
//!   and multi-threaded);
//! - 6: the slot decoding by logic vs the ROM (hdl/DESIGN.md, "Slot LUT"),
//!   RtlSim and Verilator, unchecked, on eskin34 and vibrotactile8k.

use std::path::Path;
use std::time::Instant;

use engines::Stimulus;
use engines::VerilatedDut;
use engines::{verilog, RustHdlDut};
use judge::write_run;
use judge::{run_dut, run_model, run_unchecked, ModelDut, RunOptions};

fn secs<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let t = Instant::now();
    let r = f();
    (t.elapsed().as_secs_f64(), r)
}

fn main() {
    let frames: u64 = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(10);
    let mix = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../mixes/eskin34.toml");
    let s = lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap();
    let cycles = frames * s.grid.frame_cycles;
    let real = frames as f64 * s.mix.frame_us as f64 * 1e-6;
    let opts = RunOptions::default();
    println!("mix eskin34, {frames} frames = {cycles} cycles = {real} s of acquisition");

    // 1. verilator
    let v = verilog(&s).unwrap();
    let (mut dut, built) = VerilatedDut::new(&v).unwrap();
    println!(
        "verilator model {} ({})",
        built.key,
        if built.cached { "cached" } else { "built" }
    );
    let (tu, _) = secs(|| run_unchecked(&s, &mut dut, frames, Stimulus::Pattern));
    drop(dut);
    let (mut dut, _) = VerilatedDut::new(&v).unwrap();
    let (tc, r) = secs(|| run_dut(&s, &mut dut, frames, &opts, "verilator", None));
    assert!(r.ok);
    println!(
        "verilator: checked {:.2} Mcycles/s, unchecked {:.2} Mcycles/s, ratio {:.2} (goal >= 0.5)",
        cycles as f64 / tc / 1e6,
        cycles as f64 / tu / 1e6,
        tu / tc
    );

    // 2. rusthdl (fewer frames: it is much slower)
    let hf = (frames / 5).max(1);
    let hc = hf * s.grid.frame_cycles;
    let mut dut = RustHdlDut::new(&s).unwrap();
    let (tu, _) = secs(|| run_unchecked(&s, &mut dut, hf, Stimulus::Pattern));
    let mut dut = RustHdlDut::new(&s).unwrap();
    let (tc, r) = secs(|| run_dut(&s, &mut dut, hf, &opts, "rusthdl", None));
    assert!(r.ok);
    println!(
        "rusthdl: checked {:.3} Mcycles/s, RtlSim unchecked {:.3} Mcycles/s, ratio {:.2} ({hf} frames)",
        hc as f64 / tc / 1e6,
        hc as f64 / tu / 1e6,
        tu / tc
    );

    // 2b. rusthdl (checked) vs rust-hdl's stock threaded Simulation of the
    // same core: the stock engine is ~50x slower still, so a slice of a frame.
    let rusthdl_checked = hc as f64 / tc;
    let sc = (hc / 10).clamp(20_000, 200_000);
    let stock = hdl::stock_simulation_cycles(&s, sc).unwrap();
    let same = hdl::rtlsim_cycles(&s, sc).unwrap();
    assert!(
        stock.changes == same.changes && stock.reset_pins == same.reset_pins,
        "stock Simulation and RtlSim disagree"
    );
    println!(
        "rusthdl vs stock Simulation: checked {:.3} Mcycles/s, stock {:.4} Mcycles/s ({sc} cycles), ratio {:.1} (goal >= 20); \
         RtlSim on the stock run's stimulus {:.3} Mcycles/s, identical waveform ({} changes, {} samples)",
        rusthdl_checked / 1e6,
        stock.cycles_per_second() / 1e6,
        rusthdl_checked / stock.cycles_per_second(),
        same.cycles_per_second() / 1e6,
        stock.changes.len(),
        stock.samples
    );

    // 3. model back end vs real time
    let mf = 10_000u64;
    let (tm, r) = secs(|| run_model(&s, mf, Stimulus::Pattern, 20));
    assert!(r.ok);
    let mreal = mf as f64 * s.mix.frame_us as f64 * 1e-6;
    println!(
        "model: {mf} frames ({mreal} s of acquisition, {} samples) in {tm:.3} s: {:.0}x real time (goal >= 1000)",
        r.samples,
        mreal / tm
    );

    // 4. VCD check vs bare parse
    let dir = std::env::temp_dir().join(format!("slotforge-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let vcd = dir.join("bench.vcd");
    let vf = (frames / 2).max(1);
    write_run(&vcd, &s, &mut ModelDut::new(&s), vf, &opts, (0, u64::MAX)).unwrap();
    let size = std::fs::metadata(&vcd).unwrap().len() as f64;
    let (tp, n) = secs(|| judge::parse_vcd(&s, &vcd, None).unwrap());
    let (tk, r) = secs(|| judge::check_vcd(&s, &vcd, None).unwrap());
    assert!(r.ok, "{}", r.summary());
    println!(
        "vcd: {:.1} MB, {n} cycles; parse only {:.0} MB/s, check {:.0} MB/s, ratio {:.2} (goal >= 0.8)",
        size / 1e6,
        size / tp / 1e6,
        size / tk / 1e6,
        tp / tk
    );

    // 5. check against the wellen crate's bare load of the same VCD (header
    // + body + every signal), single- and multi-threaded
    let wellen_load = |multi_thread: bool| {
        secs(|| {
            let opts = wellen::LoadOptions {
                multi_thread,
                remove_scopes_with_empty_name: false,
            };
            let mut w = wellen::simple::read_with_options(&vcd, &opts).expect("wellen reads it");
            let h = w.hierarchy();
            let refs: Vec<wellen::SignalRef> = h.all_vars().map(|v| h[v].signal_ref()).collect();
            w.load_signals(&refs);
            refs.len()
        })
    };
    let (tw1, nv) = wellen_load(false);
    let (twm, _) = wellen_load(true);
    println!(
        "vcd vs wellen ({nv} vars): check {:.0} MB/s, wellen single-threaded {:.0} MB/s, multi-threaded {:.0} MB/s; check / wellen-1 = {:.2}, check / wellen-mt = {:.2}",
        size / tk / 1e6,
        size / tw1 / 1e6,
        size / twm / 1e6,
        tw1 / tk,
        twm / tk
    );
    let _ = std::fs::remove_dir_all(&dir);
    for m in ["eskin34", "vibrotactile8k"] {
        slot_forms(m, frames);
    }
}

/// `hdl::RtlSim` with a chosen slot LUT form, as a judge DUT.
struct Form(hdl::RtlSim);

impl judge::Dut for Form {
    fn step(&mut self, rst: bool, miso: u64) -> lut_gen::Pins {
        self.0.step(rst, miso)
    }
}

/// 6: the same mix with its slot table in ROM and as logic, side by side.
fn slot_forms(name: &str, frames: u64) {
    let mix = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../mixes/{name}.toml"));
    let s = lut_gen::synthesize(&lut_gen::load(&mix).unwrap()).unwrap();
    let (rom, logic) = (hdl::LutForm::Full, hdl::LutForm::Logic);
    let hf = (frames / 5).max(1);
    let rate = |form, n: u64| {
        let mut d = Form(hdl::RtlSim::with_form(&s, form).unwrap());
        let (t, _) = secs(|| run_unchecked(&s, &mut d, n, Stimulus::Pattern));
        (n * s.grid.frame_cycles) as f64 / t / 1e6
    };
    let (hr, hl) = (rate(rom, hf), rate(logic, hf));
    let vrate = |form| {
        let v = hdl::emit_with(&s, None, form)
            .unwrap()
            .verilog()
            .to_string();
        let (mut d, _) = VerilatedDut::new(&v).unwrap();
        let (t, _) = secs(|| run_unchecked(&s, &mut d, frames, Stimulus::Pattern));
        (frames * s.grid.frame_cycles) as f64 / t / 1e6
    };
    let (vr, vl) = (vrate(rom), vrate(logic));
    println!(
        "slot decoding {name}: RtlSim ROM {hr:.3} / logic {hl:.3} Mcycles/s (ratio {:.2}); \
         verilator ROM {vr:.2} / logic {vl:.2} Mcycles/s (ratio {:.2})",
        hl / hr,
        vl / vr
    );
}
