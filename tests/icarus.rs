//! An independent testbench for the emitted Verilog: Icarus runs
//! `tests/tb/adc_tb.v` (a datasheet-timed AD7940 per branch, with x on MISO
//! from 10 ns to 80 ns after every SCLK falling edge) and logs every CS fall
//! and every output sample; this test compares the log with lut-gen's
//! schedule.  It uses neither the hdl crate's simulator nor cosim's checker.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn require(tool: &str) {
    let ok = Command::new(tool).arg("-V").output().is_ok();
    assert!(
        ok,
        "`{tool}` is not installed: run `make tools` (apt-get install iverilog)"
    );
}

struct Conversion {
    cycle: u64,
    channel: usize,
    code: u16,
}

fn run_testbench(mix_path: &Path, frames_tenths: u64) {
    require("iverilog");
    let mix = lut_gen::load(mix_path).unwrap();
    let s = lut_gen::synthesize(&mix).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_slotforge"))
        .arg("verilog")
        .arg(mix_path)
        .arg("-o")
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "slotforge verilog failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );

    let nb = s.branches.len();
    let nm: u32 = s.branches.iter().map(|b| b.mux_devices).sum();
    let cycles = s.grid.frame_cycles * frames_tenths / 10;
    let half_ns = 1e9 / s.grid.clock_hz as f64 / 2.0;
    let log = dir.path().join("tb.log");
    let sim = dir.path().join("tb.vvp");
    let compiled = Command::new("iverilog")
        .args(["-g2005", "-o"])
        .arg(&sim)
        .arg(format!("-DNB={nb}"))
        .arg(format!("-DNM={nm}"))
        .arg(format!("-DWC={}", s.channel_bits()))
        .arg(format!("-DCLK_HALF={half_ns:.4}"))
        .arg(format!("-DCYCLES={cycles}"))
        .arg(format!("-DLOG=\"{}\"", log.display()))
        .arg(root().join("tests/tb/adc_tb.v"))
        .arg(dir.path().join("slotforge_top.v"))
        .output()
        .unwrap();
    assert!(
        compiled.status.success(),
        "iverilog: {}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    let ran = Command::new("vvp").arg("-n").arg(&sim).output().unwrap();
    assert!(
        ran.status.success(),
        "vvp: {}",
        String::from_utf8_lossy(&ran.stderr)
    );

    // Which channel a (branch, select, enable vector) addresses.
    let mut first_device = vec![0u32; nb];
    for b in 1..nb {
        first_device[b] = first_device[b - 1] + s.branches[b - 1].mux_devices;
    }
    let address: BTreeMap<(usize, u32, u32), usize> = s
        .channels
        .iter()
        .enumerate()
        .map(|(c, cs)| ((mix.channels[c].branch, cs.select, cs.device), c))
        .collect();

    let text = std::fs::read_to_string(&log).unwrap();
    let mut conversions: Vec<Vec<Conversion>> = (0..nb).map(|_| Vec::new()).collect();
    let mut samples: Vec<(u64, usize, u16)> = Vec::new();
    for line in text.lines() {
        let f: Vec<u64> = line
            .split_whitespace()
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        match line.split_whitespace().next() {
            Some("CS") => {
                let (b, cycle, sel, en, code) =
                    (f[0] as usize, f[1], f[2] as u32, f[3], f[4] as u16);
                let mine = (en >> first_device[b]) & ((1 << s.branches[b].mux_devices) - 1);
                assert_eq!(
                    mine.count_ones(),
                    1,
                    "cycle {cycle}: branch {b} enables {mine:b}: not exactly one device"
                );
                let device = mine.trailing_zeros();
                let channel = *address.get(&(b, sel, device)).unwrap_or_else(|| {
                    panic!("cycle {cycle}: branch {b} samples unused input {device}.{sel}")
                });
                conversions[b].push(Conversion {
                    cycle,
                    channel,
                    code,
                });
            }
            Some("SAMPLE") => samples.push((f[0], f[1] as usize, f[2] as u16)),
            _ => panic!("bad log line {line:?}"),
        }
    }

    // 1. Conversions happen exactly at the schedule's instants, on the right channel.
    let frames = cycles.div_ceil(s.grid.frame_cycles);
    for (b, convs) in conversions.iter().enumerate() {
        let expected: Vec<(u64, usize)> = s
            .instants(frames)
            .filter(|i| i.branch == b && i.cycle < cycles - 2)
            .map(|i| (i.cycle, i.channel))
            .collect();
        let got: Vec<(u64, usize)> = convs.iter().map(|c| (c.cycle, c.channel)).collect();
        assert_eq!(got.len(), expected.len(), "branch {b}: conversion count");
        assert_eq!(
            got, expected,
            "branch {b}: conversions differ from the schedule"
        );
    }
    // 2. Per channel, straight from the log: every interval is exactly clock/rate.
    for (c, ch) in mix.channels.iter().enumerate() {
        let times: Vec<u64> = conversions[ch.branch]
            .iter()
            .filter(|x| x.channel == c)
            .map(|x| x.cycle)
            .collect();
        assert!(!times.is_empty(), "{} never sampled", ch.name);
        for w in times.windows(2) {
            assert_eq!(
                w[1] - w[0],
                mix.clock_hz / ch.rate_hz,
                "{}: interval at cycle {}",
                ch.name,
                w[0]
            );
        }
    }
    // 3. Every sample leaves with the channel and the code the ADC shifted out, in order.
    let mut per_channel: BTreeMap<usize, Vec<u16>> = BTreeMap::new();
    for (_, ch, v) in &samples {
        per_channel.entry(*ch).or_default().push(*v);
    }
    let read = s.branches.iter().map(|b| b.spi.read_cycles).max().unwrap();
    for (c, ch) in mix.channels.iter().enumerate() {
        let shifted: Vec<u16> = conversions[ch.branch]
            .iter()
            .filter(|x| x.channel == c && x.cycle + read + 1 + nb as u64 <= cycles - 2)
            .map(|x| x.code)
            .collect();
        let got = per_channel.get(&c).cloned().unwrap_or_default();
        assert!(
            got.len() >= shifted.len(),
            "{}: {} samples out, {} conversions done",
            ch.name,
            got.len(),
            shifted.len()
        );
        assert_eq!(
            &got[..shifted.len()],
            &shifted[..],
            "{}: sample values differ from the ADC's words",
            ch.name
        );
    }
}

#[test]
fn icarus_reference_mix_matches_the_schedule() {
    run_testbench(&root().join("mixes/eskin34.toml"), 11);
}

#[test]
fn icarus_other_presets_match_the_schedule() {
    for p in ["vibrotactile8k.toml", "induction5k.toml", "softslip1k.toml"] {
        run_testbench(&root().join("mixes").join(p), 12);
    }
}
