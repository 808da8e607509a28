//! An independent protocol check: sigrok-cli's SPI decoder reads every
//! branch's `cs_n`/`sclk`/`miso` from the VCD that `slotforge sim --vcd`
//! writes, and the words it decodes must be, in order, the sample values the
//! design emitted for that branch's conversions (`sample_valid` strobes with
//! `sample_channel`/`sample_value`, the channel's branch from the mix).
//!
//! Nothing of slotforge's own SPI decoding is used: a CS-style read (the
//! AD7940) is decoded by sigrok in mode 3 (cpol=1, cpha=1), CS active low,
//! one word per CS, and the code is `(word >> 1) & 0x3fff` for the AD7940 (the
//! part shifts out two leading zeros, the first after CS falls, before the
//! first rising SCLK edge); a CNV-style chain (four AD7685s) in mode 0 (cpol=0,
//! cpha=0) with CNV as an active-high select, one 16-bit word per chained
//! part, member 0's first, each word the code.  sigrok's VCD input
//! takes only 1-bit signals, so the test hands it a VCD of the branches'
//! scalar lanes, times converted to nanoseconds.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command as Process;

use assert_cmd::Command;
use judge::{read_cycles, CycleSink};
use lut_gen::Pins;
use lut_gen::Schedule;

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::tools;

use crate::common_cli::root;
use crate::common_presets;

fn presets() -> Vec<PathBuf> {
    common_presets::presets(&root())
}

/// The sample stream of a VCD: `(channel, value)` at each `sample_valid`.
#[derive(Default)]
struct Samples(Vec<(u16, u16)>);

impl CycleSink for Samples {
    fn cycle(&mut self, rst: Option<bool>, p: &Pins, _: &Pins, _: u64, _: u64) {
        if rst != Some(true) && p.sample_valid {
            self.0.push((p.sample_channel, p.sample_value));
        }
    }
}

/// The 1-bit lanes of each branch scope (`<top>.branch_<name>`), as a VCD
/// sigrok reads: one scope, channels `b<i>_cs_n`, `b<i>_sclk`, `b<i>_miso`,
/// times in ns.  Returns the text and the branch names in order.
fn scalar_vcd(src: &str) -> (String, Vec<String>) {
    let mut scopes: Vec<String> = Vec::new();
    let mut keep: BTreeMap<String, String> = BTreeMap::new(); // id -> channel name
    let mut branches: Vec<String> = Vec::new();
    let mut unit_fs: Option<f64> = None;
    let mut lines = src.lines();
    let mut header = String::new();
    // the header, as `$keyword ... $end` tokens
    for l in lines.by_ref() {
        header.push_str(l);
        header.push(' ');
        if l.contains("$enddefinitions") {
            break;
        }
    }
    let toks: Vec<&str> = header.split_whitespace().collect();
    let mut i = 0;
    while i < toks.len() {
        match toks[i] {
            "$timescale" => {
                let body: String = toks[i + 1..]
                    .iter()
                    .take_while(|t| **t != "$end")
                    .copied()
                    .collect();
                let digits: String = body.chars().take_while(|c| c.is_ascii_digit()).collect();
                let unit = &body[digits.len()..];
                let mul = match unit {
                    "s" => 1e15,
                    "ms" => 1e12,
                    "us" => 1e9,
                    "ns" => 1e6,
                    "ps" => 1e3,
                    "fs" => 1.0,
                    u => panic!("timescale unit `{u}`"),
                };
                unit_fs = Some(digits.parse::<f64>().unwrap() * mul);
            }
            "$scope" => scopes.push(toks[i + 2].to_string()),
            "$upscope" => {
                scopes.pop();
            }
            "$var" => {
                let (width, id, name) = (toks[i + 2], toks[i + 3], toks[i + 4]);
                if let Some(b) = scopes.last().and_then(|s| s.strip_prefix("branch_")) {
                    if width == "1" && ["cs_n", "sclk", "miso"].contains(&name) {
                        let bi = match branches.iter().position(|x| x == b) {
                            Some(k) => k,
                            None => {
                                branches.push(b.to_string());
                                branches.len() - 1
                            }
                        };
                        keep.insert(id.to_string(), format!("b{bi}_{name}"));
                    }
                }
            }
            _ => {}
        }
        i += 1;
    }
    let unit_fs = unit_fs.expect("a $timescale");
    let mut out = String::from("$timescale 1 ns $end\n$scope module top $end\n");
    for (id, name) in &keep {
        let _ = writeln!(out, "$var wire 1 {id} {name} $end");
    }
    out.push_str("$upscope $end\n$enddefinitions $end\n");
    let mut last_ns: Option<u64> = None;
    for l in lines {
        let l = l.trim();
        if let Some(t) = l.strip_prefix('#') {
            let ns = (t.parse::<f64>().unwrap() * unit_fs / 1e6).round() as u64;
            if last_ns != Some(ns) {
                if let Some(p) = last_ns {
                    assert!(ns > p, "time goes back at {l}");
                }
                let _ = writeln!(out, "#{ns}");
                last_ns = Some(ns);
            }
        } else if l.len() >= 2 && "01xzXZ".contains(&l[..1]) && keep.contains_key(&l[1..]) {
            let _ = writeln!(out, "{l}");
        }
    }
    (out, branches)
}

/// How sigrok reads a branch's part: its SPI decoder options and the code
/// in each decoded word.
struct PartDecoder {
    options: String,
    wordsize: u32,
    /// Right shift and mask from a decoded word to the code.
    shift: u32,
    mask: u16,
}

impl PartDecoder {
    fn of(part: &lut_gen::AdcPart) -> PartDecoder {
        let w = part.word_sclks();
        let cnv = part.start == lut_gen::Start::Cnv;
        // Mode 3 reads stream bits 1..=w at the w rising edges (bit 0 comes
        // before the first); mode 0 reads bits 0..w.
        let low = cnv && part.read == lut_gen::CnvRead::CnvLow;
        let (options, shift) = if low {
            // CNV low frames the read, as an active-low CS
            ("cs_polarity=active-low:cpol=0:cpha=0", part.trailing_bits)
        } else if cnv {
            ("cs_polarity=active-high:cpol=0:cpha=0", part.trailing_bits)
        } else {
            (
                "cs_polarity=active-low:cpol=1:cpha=1",
                part.trailing_bits + 1,
            )
        };
        PartDecoder {
            options: options.to_string(),
            wordsize: w,
            shift,
            mask: ((1u32 << part.bits) - 1) as u16,
        }
    }

    fn code(&self, word: u32) -> u16 {
        (word >> self.shift) as u16 & self.mask
    }
}

/// The words sigrok's SPI decoder reads on MISO of branch `b`.
fn sigrok_words(vcd: &Path, b: usize, d: &PartDecoder) -> Vec<u32> {
    let dec = format!(
        "spi:clk=b{b}_sclk:miso=b{b}_miso:cs=b{b}_cs_n:{}:wordsize={}",
        d.options, d.wordsize
    );
    let out = Process::new("sigrok-cli")
        .args(["-I", "vcd", "-i"])
        .arg(vcd)
        .args(["-P", &dec, "-A", "spi=miso-data"])
        .output()
        .expect("sigrok-cli runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "sigrok-cli failed: {stderr}");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let w = l.rsplit(':').next().unwrap().trim();
            u32::from_str_radix(w, 16).unwrap_or_else(|_| panic!("sigrok line `{l}`"))
        })
        .collect()
}

/// The comparison: the decoded words of a branch against the sample values
/// emitted for its channels, in order.
fn compare(branch: &str, decoded: &[u16], samples: &[u16]) -> Result<(), String> {
    if let Some(k) = (0..decoded.len().min(samples.len())).find(|&k| decoded[k] != samples[k]) {
        return Err(format!(
            "branch {branch}: conversion {k}: SPI (sigrok) read {:#06x}, the design emitted sample_value {:#06x}",
            decoded[k], samples[k]
        ));
    }
    if decoded.len() != samples.len() {
        return Err(format!(
            "branch {branch}: sigrok decoded {} words, the design emitted {} samples",
            decoded.len(),
            samples.len()
        ));
    }
    Ok(())
}

/// A branch's name, the words sigrok decoded, and the sample values emitted.
type Decoded = (String, Vec<u16>, Vec<u16>);

/// One preset: simulate one frame with a VCD, decode every branch with
/// sigrok, and return per branch (name, decoded words, sample values).
fn decode_preset(mix: &Path, dir: &Path) -> (Schedule, Vec<Decoded>) {
    let s = lut_gen::synthesize(&lut_gen::load(mix).unwrap()).unwrap();
    let stem = mix.file_stem().unwrap().to_string_lossy().to_string();
    let wave = dir.join(format!("{stem}.vcd"));
    Command::cargo_bin("slotforge")
        .unwrap()
        .arg("sim")
        .arg(mix)
        .args(["--backend", "rusthdl", "--frames", "1", "--vcd"])
        .arg(&wave)
        .assert()
        .code(0);
    let mut samples = Samples::default();
    read_cycles(&s, &wave, None, &mut samples).unwrap();
    let (text, names) = scalar_vcd(&std::fs::read_to_string(&wave).unwrap());
    assert_eq!(names.len(), s.branches.len(), "{stem}: a scope per branch");
    let scalar = dir.join(format!("{stem}.scalar.vcd"));
    std::fs::write(&scalar, text).unwrap();
    let mut out = Vec::new();
    for (k, name) in names.iter().enumerate() {
        let b = s
            .branches
            .iter()
            .position(|x| &x.name == name)
            .unwrap_or_else(|| panic!("{stem}: scope branch_{name} is no branch of the mix"));
        let d = PartDecoder::of(&s.mix.branches[b].adc);
        let words: Vec<u16> = sigrok_words(&scalar, k, &d)
            .into_iter()
            .map(|w| d.code(w))
            .collect();
        let values: Vec<u16> = samples
            .0
            .iter()
            .filter(|(c, _)| s.mix.channels[*c as usize].branch == b)
            .map(|&(_, v)| v)
            .collect();
        // every conversion of the frame was emitted and decoded (but those
        // the gateware skips at start-up: their mux has not settled), one
        // sample per chained word
        let expect: usize = s
            .instants(1)
            .filter(|i| i.branch == b && !s.skipped_at_startup(b, i.cycle))
            .map(|i| s.words_of(i.channel).count())
            .sum();
        assert_eq!(values.len(), expect, "{stem}: samples of branch {name}");
        out.push((name.clone(), words, values));
    }
    (s, out)
}

/// The presets whose converters and muxes another preset of `make test`'s
/// decode has, each a debug rust-hdl frame and sigrok's decodes of it:
/// `make test` decodes `eskin34` (three AD7940 branches),
/// `induction5k-adc12` (a declared part beside an AD7940) and
/// `vibrotactile8k` (a daisy chain), `make test-long` these too.  The
/// link presets are `eskin34`'s branches exactly (the link stage does not
/// touch the SPI lanes); `eskin34-adaptive`'s are too, in its first mode
/// (sigrok's decodes of a mode mix's gateware, each frame in its mode, are
/// `modes_cli.rs`'s fault campaign on `modes-pin`); `induction5k` and
/// `softslip1k` have one AD7940 branch, at 48 and 12 MHz.
const LONG_ONLY: [&str; 5] = [
    "eskin34-uart",
    "eskin34-axis",
    "eskin34-adaptive",
    "induction5k",
    "softslip1k",
];

fn is_long_only(mix: &Path) -> bool {
    LONG_ONLY
        .iter()
        .any(|t| mix.file_stem().is_some_and(|s| s == *t))
}

#[test]
fn sigrok_decodes_every_branch_as_the_sample_stream() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut multi = 0;
    let mut chained = 0;
    let mut seen = Vec::new();
    for mix in presets().into_iter().filter(|m| !is_long_only(m)) {
        let (s, branches) = decode_preset(&mix, dir.path());
        if s.branches.len() > 1 {
            multi += 1;
        }
        if s.mix.branches.iter().any(|b| b.chain > 1) {
            chained += 1;
        }
        let mut total = 0;
        for (name, words, values) in &branches {
            if let Err(e) = compare(name, words, values) {
                panic!("{}: {e}", mix.display());
            }
            assert!(!values.is_empty());
            total += values.len();
        }
        if s.mix.name == "eskin34" {
            // 349 per frame, less the three cycle-0 instants skipped at start-up
            assert_eq!(
                total as u64,
                349 - s.startup_skips(),
                "eskin34: every sample of a frame"
            );
            assert_eq!(s.startup_skips(), 3);
        }
        seen.push(s.mix.name.clone());
    }
    assert!(seen.iter().any(|n| n == "eskin34"), "{seen:?}");
    assert!(
        multi >= 2,
        "eskin34 and another multi-branch preset: {seen:?}"
    );
    assert!(chained >= 1, "a preset with a daisy chain: {seen:?}");
}

/// The other presets' branches decode as the sample stream too (`make
/// test-long`); the link presets' as `eskin34`'s do, every sample of a frame.
#[test]
#[ignore = "long: make test-long (eskin34's branches with a link or modes, the single-branch AD7940 presets)"]
fn sigrok_decodes_every_branch_of_the_other_presets() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let others: Vec<PathBuf> = presets().into_iter().filter(|m| is_long_only(m)).collect();
    assert_eq!(others.len(), LONG_ONLY.len(), "{others:?}");
    for mix in others {
        let (s, branches) = decode_preset(&mix, dir.path());
        for (name, words, values) in &branches {
            if let Err(e) = compare(name, words, values) {
                panic!("{}: {e}", mix.display());
            }
            assert!(!values.is_empty());
        }
        if ["eskin34-uart", "eskin34-axis"].contains(&s.mix.name.as_str()) {
            let total: usize = branches.iter().map(|b| b.2.len()).sum();
            assert_eq!(total as u64, 349 - s.startup_skips(), "{}", mix.display());
        }
    }
}

/// The comparison fails on a wrong value, a missing or an extra word, and
/// words out of order (on real data: eskin34's first branch).
#[test]
fn the_comparison_catches_wrong_values() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (_, branches) = decode_preset(&root().join("mixes/eskin34.toml"), dir.path());
    let (name, words, values) = &branches[0];
    compare(name, words, values).unwrap();
    let k = values.len() / 2;
    let mut wrong = values.clone();
    wrong[k] ^= 1 << 7;
    let e = compare(name, words, &wrong).unwrap_err();
    assert!(e.contains(&format!("conversion {k}")), "{e}");
    let mut fewer = values.clone();
    fewer.pop();
    assert!(compare(name, words, &fewer).is_err());
    let mut more = values.clone();
    more.push(0);
    assert!(compare(name, words, &more).is_err());
    let mut swapped = values.clone();
    let j = (0..swapped.len() - 1)
        .find(|&j| swapped[j] != swapped[j + 1])
        .unwrap();
    swapped.swap(j, j + 1);
    assert!(compare(name, words, &swapped).is_err());
    // and a perturbed MISO word, as sigrok would decode it
    let mut bad_words = words.clone();
    bad_words[0] ^= 1 << 1;
    assert!(compare(name, &bad_words, values).is_err());
}
