//! A second simulator: the emitted Verilog in Icarus with a Verilog AD7940
//! model (cosim/tb/adc_tb.v.in); its VCD must pass `check`.

use std::path::Path;
use std::process::Command;

use cosim::Layout;

fn have(tool: &str) -> bool {
    Command::new(tool).arg("-V").output().is_ok()
}

fn icarus_run(mix: &Path, frames: u64) -> (lut_gen::Schedule, tempfile::TempDir) {
    let s = lut_gen::synthesize(&lut_gen::load(mix).unwrap()).unwrap();
    let d = tempfile::tempdir().unwrap();
    hdl::emit(&s, None).unwrap().write_to(d.path()).unwrap();
    let l = Layout::new(&s);
    let tb = include_str!("../tb/adc_tb.v.in")
        .replace("@NB@", &l.branches.to_string())
        .replace("@M@", &l.mux_devices.to_string())
        .replace("@W@", &l.channel_bits.to_string())
        .replace("@CYCLES@", &(frames * s.grid.frame_cycles).to_string());
    std::fs::write(d.path().join("tb.v"), tb).unwrap();
    let o = Command::new("iverilog")
        .args(["-g2005", "-o", "sim", "tb.v", "slotforge_top.v"])
        .current_dir(d.path())
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "iverilog: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = Command::new("vvp")
        .args(["-n", "sim"])
        .current_dir(d.path())
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "vvp: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    (s, d)
}

#[test]
fn icarus_vcd_of_the_emitted_verilog_passes_check() {
    if !have("iverilog") {
        eprintln!("iverilog missing: skipped");
        return;
    }
    let tiny = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/tiny.toml");
    let (s, d) = icarus_run(&tiny, 3);
    let r = cosim::check_vcd(&s, d.path().join("wave.vcd"), None).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.frames, 3);
    assert_eq!(r.samples, 3 * s.samples_per_frame());
    // the DUT scope works too, and the same VCD fails for a corrupted value
    let r = cosim::check_vcd(&s, d.path().join("wave.vcd"), Some("tb")).unwrap();
    assert!(r.ok, "{}", r.summary());
}

#[test]
fn icarus_eskin34_one_frame() {
    if !have("iverilog") {
        eprintln!("iverilog missing: skipped");
        return;
    }
    let mix = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mixes/eskin34.toml");
    let (s, d) = icarus_run(&mix, 1);
    let r = cosim::check_vcd(&s, d.path().join("wave.vcd"), None).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.samples, s.samples_per_frame());
}
