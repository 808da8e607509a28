//! What a logic analyser records of a run, for the capture tests of the
//! judge and of the campaign (random mixes): every cycle's pins resampled at the
//! analyser's rate with an arbitrary phase, from the middle of a run, no
//! clock or reset, channels D0..Dn; sigrok-cli's `.sr` and VCD of it; and
//! faults made on the recorded pins.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use judge::tools::Tool;
use judge::{check_capture, TimedReport};
use judge::{id_code, wire_header};
use judge::{run_dut, Dut, Observer, RunOptions};
use lut_gen::Schedule;
use lut_gen::{Layout, Pins, Role};

/// Every cycle's pins after reset.
#[derive(Default)]
pub struct Rec(pub Vec<Pins>);

impl Observer for Rec {
    fn cycle(&mut self, _: u64, rst: bool, p: &Pins, _: u64) {
        if !rst {
            self.0.push(*p);
        }
    }
}

pub fn run<D: Dut>(s: &Schedule, dut: &mut D, frames: u64) -> Vec<Pins> {
    let mut r = Rec::default();
    run_dut(s, dut, frames, &RunOptions::default(), "gen", Some(&mut r));
    r.0
}

/// Every cycle's pins and MISO word (bit b: branch b) after reset.
#[derive(Default)]
pub struct RecMiso(pub Vec<Pins>, pub Vec<u64>);

impl Observer for RecMiso {
    fn cycle(&mut self, _: u64, rst: bool, p: &Pins, miso: u64) {
        if !rst {
            self.0.push(*p);
            self.1.push(miso);
        }
    }
}

pub fn run_with_miso<D: Dut>(s: &Schedule, dut: &mut D, frames: u64) -> (Vec<Pins>, Vec<u64>) {
    let mut r = RecMiso::default();
    run_dut(s, dut, frames, &RunOptions::default(), "gen", Some(&mut r));
    (r.0, r.1)
}

/// The analyser's channels: every CS, SCLK, MOSI, mux select and enable bit and
/// sample_valid, as D0..Dn, with the `--map` that names them.
pub fn lanes(s: &Schedule) -> (Vec<(Option<Role>, u32)>, String) {
    let l = Layout::new(s);
    let mut v = Vec::new();
    for r in [
        Role::CsN,
        Role::Sclk,
        Role::Mosi,
        Role::MuxSel,
        Role::MuxEn,
        Role::SampleValid,
    ] {
        for b in 0..l.width(r) {
            v.push((Some(r), b));
        }
    }
    // The link's line, for a mix with a UART; an AXI4-Stream link's beat
    // ports and overflow flag ([`AXIS_LANE`] on).
    match (l.link, l.axis) {
        (true, false) => v.push((None, 0)),
        (true, true) => v.extend((0..AXIS_LANES.len() as u32).map(|k| (None, AXIS_LANE + k))),
        _ => {}
    }
    let map = v
        .iter()
        .enumerate()
        .map(|(i, (r, b))| match (r, b.checked_sub(AXIS_LANE)) {
            (None, Some(k)) => format!("D{i}={}", AXIS_LANES[k as usize]),
            _ => format!("D{i}={}[{b}]", r.map_or("link_tx", |r| r.name())),
        })
        .collect::<Vec<_>>()
        .join(",");
    (v, map)
}

/// A lane `(None, AXIS_LANE + k)` of [`lanes`] is the AXI4-Stream port bit
/// `AXIS_LANES[k]`.
pub const AXIS_LANE: u32 = 100;
pub const AXIS_LANES: [&str; 12] = [
    "m_axis_tdata[0]",
    "m_axis_tdata[1]",
    "m_axis_tdata[2]",
    "m_axis_tdata[3]",
    "m_axis_tdata[4]",
    "m_axis_tdata[5]",
    "m_axis_tdata[6]",
    "m_axis_tdata[7]",
    "m_axis_tvalid",
    "m_axis_tready",
    "m_axis_tlast",
    "link_overflow",
];

pub fn bit(p: &Pins, r: Option<Role>, b: u32) -> bool {
    let v: u128 = match r {
        Some(Role::CsN) => p.cs_n as u128,
        Some(Role::Sclk) => p.sclk as u128,
        Some(Role::Mosi) => p.mosi as u128,
        Some(Role::MuxSel) => p.mux_sel as u128,
        Some(Role::MuxEn) => p.mux_en,
        Some(_) => p.sample_valid as u128,
        None => match b.checked_sub(AXIS_LANE) {
            Some(k @ 0..8) => return p.axis_tdata >> k & 1 == 1,
            Some(8) => return p.axis_tvalid,
            Some(9) => return p.axis_tready,
            Some(10) => return p.axis_tlast,
            Some(_) => return p.link_overflow,
            None => p.link_tx as u128,
        },
    };
    v >> b & 1 == 1
}

/// Samples cycles `[from, to)` every `ts_ps` from `from`'s start plus
/// `phase_ps`, and writes them as a 1 ps VCD of channels D0..Dn.
pub fn resample(
    s: &Schedule,
    pins: &[Pins],
    from: u64,
    to: u64,
    ts_ps: u64,
    phase_ps: u64,
    out: &Path,
) {
    let (lanes, _) = lanes(s);
    let level = |c: usize, r: Option<Role>, b: u32| bit(&pins[c], r, b);
    resample_lanes(s, &lanes, &level, (from, to), ts_ps, phase_ps, out);
}

/// [`resample`] of any lanes, each cycle's level given by `level(cycle,
/// role, bit)`.
pub fn resample_lanes(
    s: &Schedule,
    lanes: &[(Option<Role>, u32)],
    level: &dyn Fn(usize, Option<Role>, u32) -> bool,
    (from, to): (u64, u64),
    ts_ps: u64,
    phase_ps: u64,
    out: &Path,
) {
    resample_scaled(s, lanes, level, (from, to), (ts_ps, phase_ps), 0.0, out);
}

/// [`resample`] by an analyser whose clock is `ppm` parts per million off
/// the design's (positive: the analyser runs fast, so its timestamps
/// stretch each of the design's cycles by that much): a board's crystal
/// against an analyser's.
pub fn resample_drifting(
    s: &Schedule,
    pins: &[Pins],
    (from, to): (u64, u64),
    (ts_ps, phase_ps): (u64, u64),
    ppm: f64,
    out: &Path,
) {
    let (lanes, _) = lanes(s);
    let level = |c: usize, r: Option<Role>, b: u32| bit(&pins[c], r, b);
    resample_scaled(s, &lanes, &level, (from, to), (ts_ps, phase_ps), ppm, out);
}

fn resample_scaled(
    s: &Schedule,
    lanes: &[(Option<Role>, u32)],
    level: &dyn Fn(usize, Option<Role>, u32) -> bool,
    (from, to): (u64, u64),
    (ts_ps, phase_ps): (u64, u64),
    ppm: f64,
    out: &Path,
) {
    // the design's cycle in the analyser's time
    let tc = 1e12 / s.mix.clock_hz as f64 * (1.0 + ppm * 1e-6);
    let names: Vec<String> = (0..lanes.len()).map(|i| format!("D{i}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut text = wire_header("1 ps", "libsigrok", &names);
    let start = from as f64 * tc + phase_ps as f64;
    let mut prev: Option<Vec<bool>> = None;
    let mut n = 0u64;
    // the levels of the cycle last sampled: an analyser faster than the
    // design samples most cycles twice or more, and asking every lane's
    // level again (this crate builds at opt-level 0) was a third of a capture
    let mut sampled: Option<(u64, Vec<bool>)> = None;
    loop {
        let t = start + (n * ts_ps) as f64;
        let c = (t / tc) as u64;
        if c >= to {
            break;
        }
        if sampled.as_ref().map(|x| x.0) != Some(c) {
            let v = lanes.iter().map(|(r, b)| level(c as usize, *r, *b));
            sampled = Some((c, v.collect()));
        }
        let v = &sampled.as_ref().expect("sampled above").1;
        if prev.as_ref() != Some(v) {
            text += &format!("#{}\n", n * ts_ps);
            for (i, x) in v.iter().enumerate() {
                if prev.as_ref().map(|p| p[i]) != Some(*x) {
                    text += &format!("{}{}\n", *x as u8, id_code(i));
                }
            }
            prev = Some(v.clone());
        }
        n += 1;
    }
    text += &format!("#{}\n", n * ts_ps);
    std::fs::write(out, text).unwrap();
}

/// What an analyser at `ts_ps` (its first sample `phase_ps` into cycle
/// `window.0`) records of cycles `window` of `pins`: [`resample`] into
/// `vcd`, then [`to_sigrok`]'s `.sr` and sigrok-cli's VCD of it.
pub fn capture(
    s: &Schedule,
    pins: &[Pins],
    window: (u64, u64),
    (ts_ps, phase_ps): (u64, u64),
    vcd: &Path,
) -> (PathBuf, PathBuf) {
    resample(s, pins, window.0, window.1, ts_ps, phase_ps, vcd);
    to_sigrok(vcd, ts_ps)
}

/// The capture as `.sr` (sigrok-cli from the 1 ps VCD, downsampled to the
/// analyser's rate) and as sigrok-cli's VCD of that session.
pub fn to_sigrok(vcd: &Path, ts_ps: u64) -> (PathBuf, PathBuf) {
    let sr = vcd.with_extension("sr");
    let downsample = format!("vcd:downsample={ts_ps}");
    sigrok_cli(
        Tool::new("sigrok-cli")
            .arg("-i")
            .arg(vcd)
            .args(["-I", &downsample, "-o"])
            .arg(&sr),
    );
    let back = vcd.with_extension("sigrok.vcd");
    sigrok_cli(
        Tool::new("sigrok-cli")
            .arg("-i")
            .arg(&sr)
            .args(["-O", "vcd", "-o"])
            .arg(&back),
    );
    (sr, back)
}

/// Runs sigrok-cli (through the tool runner) to completion; a failure
/// shows its stderr.
fn sigrok_cli(tool: Tool) {
    let out = tool.run().unwrap();
    assert!(out.success, "{}", out.stderr);
}

pub fn check(s: &Schedule, map: &str, file: &Path) -> TimedReport {
    let lanes = judge::parse_map(map, s).unwrap();
    let cap = judge::read_capture(file, lanes).unwrap();
    check_capture(s, &cap, 0).unwrap()
}

/// What an analyser at `ts_ps` running `ppm` off the design's clock
/// ([`resample_drifting`]) records of cycles `window` of `pins`, its rate
/// said in the VCD as sigrok-cli says it, checked at time level.
pub fn check_drifting(
    s: &Schedule,
    pins: &[Pins],
    window: (u64, u64),
    (ts_ps, phase_ps): (u64, u64),
    ppm: f64,
    vcd: &Path,
) -> TimedReport {
    let (_, map) = lanes(s);
    resample_drifting(s, pins, window, (ts_ps, phase_ps), ppm, vcd);
    let text = std::fs::read_to_string(vcd).unwrap().replace(
        "$enddefinitions $end\n",
        &format!(
            "$comment\n  Acquisition at {} Hz\n$end\n$enddefinitions $end\n",
            1e12 / ts_ps as f64
        ),
    );
    std::fs::write(vcd, text).unwrap();
    check(s, &map, vcd)
}

/// A fault made on the recorded pins of branch 0 at the first conversion at
/// or after cycle `at`.
#[derive(Debug, Clone, Copy)]
pub enum Mutation {
    /// The conversion (CS and SCLK) one slot late.
    OneSlotLate,
    /// The mux switches 8 cycles before its time.
    MuxEarly,
    /// One SCLK low pulse missing.
    SclkEdgeMissing,
    /// Three bits of one character on the link's line inverted.
    LinkBitsFlipped,
}

impl Mutation {
    /// The faults on a branch's SPI and mux pins, each with the rule a
    /// capture of it must break.
    pub const PINS: [(Mutation, &'static str); 3] = [
        (Mutation::OneSlotLate, "conversion instant"),
        (Mutation::MuxEarly, "mux switching"),
        (Mutation::SclkEdgeMissing, "serial clock"),
    ];
}

/// The first start bit on the UART line (`link_tx` falling) at or after
/// cycle `at`.
pub fn start_bit(pins: &[Pins], at: u64) -> usize {
    (at as usize..pins.len())
        .find(|&c| !pins[c].link_tx && pins[c - 1].link_tx)
        .unwrap()
}

/// `pins` with the UART line two bit times (`div` cycles each) late from
/// the start bit at `st` on, idle (high) in between: every byte intact,
/// only the timing wrong.
pub fn two_bits_late(pins: &[Pins], st: usize, div: usize) -> Vec<Pins> {
    let mut late = pins.to_vec();
    for c in st..late.len() {
        late[c].link_tx = if c < st + 2 * div {
            true
        } else {
            pins[c - 2 * div].link_tx
        };
    }
    late
}

pub fn mutate(s: &Schedule, pins: &mut [Pins], m: Mutation, at: u64) {
    let at = at as usize;
    let fall = (at..pins.len())
        .find(|&c| pins[c].cs_n & 1 == 0 && pins[c - 1].cs_n & 1 == 1)
        .unwrap();
    let slot = s.grid.slot_cycles as usize;
    if let Mutation::LinkBitsFlipped = m {
        let div = lut_gen::plan_link(s).unwrap().unwrap().baud_divider as usize;
        // A start bit at or after `at`, then its bits 2-4 inverted.
        let st = start_bit(pins, at as u64);
        for p in &mut pins[st + 2 * div..st + 5 * div] {
            p.link_tx = !p.link_tx;
        }
        return;
    }
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
        Mutation::LinkBitsFlipped => unreachable!("handled above"),
    }
}
