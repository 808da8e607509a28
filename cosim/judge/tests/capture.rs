//! Issue 17's evidence: a clean simulation turned into what a logic
//! analyser records (resampled at 24 and 100 MHz with an arbitrary phase,
//! started mid-frame, no clock or reset, channels D0..Dn), converted by
//! sigrok-cli into a `.sr` session and its VCD, passes the time-level check;
//! the same capture of faulty gateware (a conversion one slot late, a mux
//! moved early, one SCLK edge missing) fails with the fault named.

use std::path::{Path, PathBuf};
use std::process::Command;

use judge::run::{run_dut, ModelDut, Observer, RunOptions};
use judge::timed::{check_capture, TimedReport};
use lut_gen::ports::{Layout, Pins, Role};
use lut_gen::Schedule;

#[path = "../../../tests/common/tools.rs"]
mod tools;

fn load(mix: &str) -> Schedule {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(mix);
    lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap()
}

/// Every cycle's pins after reset.
#[derive(Default)]
struct Rec(Vec<Pins>);

impl Observer for Rec {
    fn cycle(&mut self, _: u64, rst: bool, p: &Pins, _: u64) {
        if !rst {
            self.0.push(*p);
        }
    }
}

fn run(s: &Schedule, frames: u64) -> Vec<Pins> {
    let mut r = Rec::default();
    run_dut(
        s,
        &mut ModelDut::new(s),
        frames,
        &RunOptions::default(),
        "gen",
        Some(&mut r),
    );
    r.0
}

/// The analyser's channels: every CS, SCLK, mux select and enable bit and
/// sample_valid, as D0..Dn, with the `--map` that names them.
fn lanes(s: &Schedule) -> (Vec<(Role, u32)>, String) {
    let l = Layout::new(s);
    let mut v = Vec::new();
    for r in [
        Role::CsN,
        Role::Sclk,
        Role::MuxSel,
        Role::MuxEn,
        Role::SampleValid,
    ] {
        for b in 0..l.width(r) {
            v.push((r, b));
        }
    }
    let map = v
        .iter()
        .enumerate()
        .map(|(i, (r, b))| format!("D{i}={}[{b}]", r.name()))
        .collect::<Vec<_>>()
        .join(",");
    (v, map)
}

fn bit(p: &Pins, r: Role, b: u32) -> bool {
    let v: u128 = match r {
        Role::CsN => p.cs_n as u128,
        Role::Sclk => p.sclk as u128,
        Role::MuxSel => p.mux_sel as u128,
        Role::MuxEn => p.mux_en,
        _ => p.sample_valid as u128,
    };
    v >> b & 1 == 1
}

/// Samples cycles `[from, to)` every `ts_ps` from `from`'s start plus
/// `phase_ps`, and writes them as a 1 ps VCD of channels D0..Dn.
fn resample(
    s: &Schedule,
    pins: &[Pins],
    from: u64,
    to: u64,
    ts_ps: u64,
    phase_ps: u64,
    out: &Path,
) {
    let (lanes, _) = lanes(s);
    let tc = 1e12 / s.mix.clock_hz as f64;
    let mut text = String::from("$timescale 1 ps $end\n$scope module libsigrok $end\n");
    for (i, _) in lanes.iter().enumerate() {
        text += &format!("$var wire 1 {} D{i} $end\n", code(i));
    }
    text += "$upscope $end\n$enddefinitions $end\n";
    let start = from as f64 * tc + phase_ps as f64;
    let mut prev: Option<Vec<bool>> = None;
    let mut n = 0u64;
    loop {
        let t = start + (n * ts_ps) as f64;
        let c = (t / tc) as u64;
        if c >= to {
            break;
        }
        let v: Vec<bool> = lanes
            .iter()
            .map(|(r, b)| bit(&pins[c as usize], *r, *b))
            .collect();
        if prev.as_ref() != Some(&v) {
            text += &format!("#{}\n", n * ts_ps);
            for (i, x) in v.iter().enumerate() {
                if prev.as_ref().map(|p| p[i]) != Some(*x) {
                    text += &format!("{}{}\n", *x as u8, code(i));
                }
            }
            prev = Some(v);
        }
        n += 1;
    }
    text += &format!("#{}\n", n * ts_ps);
    std::fs::write(out, text).unwrap();
}

fn code(i: usize) -> String {
    let mut s = String::new();
    let mut n = i;
    loop {
        s.push((b'!' + (n % 94) as u8) as char);
        n /= 94;
        if n == 0 {
            return s;
        }
    }
}

/// The capture as `.sr` (sigrok-cli from the 1 ps VCD, downsampled to the
/// analyser's rate) and as sigrok-cli's VCD of that session.
fn to_sigrok(vcd: &Path, ts_ps: u64) -> (PathBuf, PathBuf) {
    let sr = vcd.with_extension("sr");
    let st = Command::new("sigrok-cli")
        .arg("-i")
        .arg(vcd)
        .arg("-I")
        .arg(format!("vcd:downsample={ts_ps}"))
        .arg("-o")
        .arg(&sr)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let back = vcd.with_extension("sigrok.vcd");
    let st = Command::new("sigrok-cli")
        .arg("-i")
        .arg(&sr)
        .args(["-O", "vcd", "-o"])
        .arg(&back)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    (sr, back)
}

fn check(s: &Schedule, map: &str, file: &Path) -> TimedReport {
    let lanes = judge::capture::parse_map(map, s).unwrap();
    let cap = judge::capture::read(file, lanes).unwrap();
    check_capture(s, &cap, 0).unwrap()
}

/// A fault made on the recorded pins of branch 0 at the first conversion at
/// or after cycle `at`.
#[derive(Debug, Clone, Copy)]
enum Mutation {
    /// The conversion (CS and SCLK) one slot late.
    OneSlotLate,
    /// The mux switches 8 cycles before its time.
    MuxEarly,
    /// One SCLK low pulse missing.
    SclkEdgeMissing,
}

fn mutate(s: &Schedule, pins: &mut [Pins], m: Mutation, at: u64) {
    let at = at as usize;
    let fall = (at..pins.len())
        .find(|&c| pins[c].cs_n & 1 == 0 && pins[c - 1].cs_n & 1 == 1)
        .unwrap();
    let slot = s.grid.slot_cycles as usize;
    match m {
        Mutation::OneSlotLate => {
            let orig: Vec<Pins> = pins[fall..fall + 2 * slot].to_vec();
            for k in 0..2 * slot {
                let (cs, sclk) = if k < slot {
                    (1, 1)
                } else {
                    (orig[k - slot].cs_n & 1, orig[k - slot].sclk & 1)
                };
                pins[fall + k].cs_n = (pins[fall + k].cs_n & !1) | cs;
                pins[fall + k].sclk = (pins[fall + k].sclk & !1) | sclk;
            }
        }
        Mutation::MuxEarly => {
            let ch = (fall + 1..pins.len())
                .find(|&c| {
                    pins[c].mux_sel != pins[c - 1].mux_sel || pins[c].mux_en != pins[c - 1].mux_en
                })
                .unwrap();
            for c in ch - 8..ch {
                pins[c].mux_sel = pins[ch].mux_sel;
                pins[c].mux_en = pins[ch].mux_en;
            }
        }
        Mutation::SclkEdgeMissing => {
            let f = (fall + 1..pins.len())
                .find(|&c| pins[c].sclk & 1 == 0 && pins[c - 1].sclk & 1 == 1)
                .unwrap();
            let mut c = f;
            while pins[c].sclk & 1 == 0 {
                pins[c].sclk |= 1;
                c += 1;
            }
        }
    }
}

fn evidence(mix: &str, frames: u64, window: (u64, u64), rates: &[(u64, u64)]) {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let s = load(mix);
    let clean = run(&s, frames);
    let (_, map) = lanes(&s);
    let d = tempfile::tempdir().unwrap();
    for &(ts, phase) in rates {
        let v = d.path().join(format!("clean{ts}.vcd"));
        resample(&s, &clean, window.0, window.1, ts, phase, &v);
        let (sr, back) = to_sigrok(&v, ts);
        for f in [&sr, &back] {
            let r = check(&s, &map, f);
            assert!(r.ok, "{} at {ts} ps: {}", f.display(), r.summary());
            assert!(r.edges_checked > 50, "{}", r.summary());
        }
        let mid = (window.0 + window.1) / 2;
        for (m, want) in [
            (Mutation::OneSlotLate, "conversion instant"),
            (Mutation::MuxEarly, "mux switching"),
            (Mutation::SclkEdgeMissing, "serial clock"),
        ] {
            let mut bad = clean.clone();
            mutate(&s, &mut bad, m, mid);
            let v = d.path().join(format!("bad{ts}.vcd"));
            resample(&s, &bad, window.0, window.1, ts, phase, &v);
            let (sr, _) = to_sigrok(&v, ts);
            let r = check(&s, &map, &sr);
            assert!(!r.ok, "{m:?} at {ts} ps passed: {}", r.summary());
            assert!(
                r.violations[0].rule.contains(want),
                "{m:?} at {ts} ps: {}",
                r.summary()
            );
        }
    }
}

/// The tiny mix (4 MHz): 100 and 24 MHz analysers, mid-frame, odd phases.
#[test]
fn analyser_captures_of_tiny_pass_and_faults_fail() {
    evidence(
        "../tests/data/tiny.toml",
        3,
        (5_317, 11_900),
        &[(10_000, 3_717), (41_667, 29_001)],
    );
}

/// The reference design (48 MHz): a 24 MHz analyser cannot resolve its
/// cycle, yet proves every edge to ±42 ns; 100 MHz too.
#[test]
#[ignore = "long: make test-long"]
fn analyser_captures_of_eskin34_pass_and_faults_fail() {
    evidence(
        "../../mixes/eskin34.toml",
        2,
        (500_123, 800_000),
        &[(10_000, 4_321), (41_667, 17_000)],
    );
}

/// A subset of pins: branch 0's CS and SCLK only.  It still locks and
/// passes, and names what it could not check.
#[test]
fn a_subset_of_pins_names_what_it_cannot_check() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let s = load("../tests/data/tiny.toml");
    let clean = run(&s, 3);
    let d = tempfile::tempdir().unwrap();
    let v = d.path().join("all.vcd");
    resample(&s, &clean, 4_100, 11_000, 10_000, 1_234, &v);
    let (sr, _) = to_sigrok(&v, 10_000);
    // D0 = adc_cs_n[0], D2 = adc_sclk[0] in `lanes`' order.
    let r = check(&s, "D0=adc_cs_n[0],D2=adc_sclk[0]", &sr);
    assert!(r.ok, "{}", r.summary());
    let text = r.summary();
    assert!(text.contains("branch slow: no CS lane checked"), "{text}");
    assert!(
        text.contains("branch fast: slot order by channel and mux settling"),
        "{text}"
    );
    assert!(
        text.contains("proved: branch fast: every SCLK edge"),
        "{text}"
    );
    // An unknown port or bit is an input error naming the entry.
    let e = judge::capture::parse_map("D0=adc_cs_n[7]", &s).unwrap_err();
    assert!(
        e.contains("D0=adc_cs_n[7]") && e.contains("no bit 7"),
        "{e}"
    );
    let f = d.path().join("map.txt");
    std::fs::write(&f, "# probes\nD0 = adc_cs_n[0]\nD1 = adc_clk[0]\n").unwrap();
    let e = judge::capture::parse_map(f.to_str().unwrap(), &s).unwrap_err();
    assert!(e.contains("map.txt:3") && e.contains("adc_clk"), "{e}");
}
