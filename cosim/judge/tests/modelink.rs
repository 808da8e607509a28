//! The link of a mix with modes (docs/packet-format.md, "Modes"): every
//! header names its frame's mode and the mode of the frame before, the
//! host's decoder reads them back, and the judge holds them to the `mode`
//! pin with and without the model.

use judge::{Adc, Dut, ModeRequests, ModelDut, Stimulus};
use lut_gen::{Pins, Schedule};
use testkit::modemix::{random_pin_mode_mix, PinShape};

fn schedule_of(text: &str, tag: &str) -> Schedule {
    let path =
        std::env::temp_dir().join(format!("judge-modelink-{tag}-{}.toml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let s = lut_gen::synthesize(&lut_gen::load(&path).unwrap()).unwrap();
    let _ = std::fs::remove_file(&path);
    s
}

/// `name`'s text with a UART link (modes-pin has none).
fn with_link(name: &str) -> Schedule {
    let mut text = std::fs::read_to_string(testkit::mix(name)).unwrap();
    if !text.contains("[link]") {
        text.push_str("\n[link]\nkind = \"uart\"\nbaud = 1_000_000\n");
    }
    schedule_of(&text, name)
}

/// A run of the model (4 reset cycles), every cycle recorded.
fn record(
    s: &Schedule,
    frames: u64,
    requests: &[(u64, u8)],
    k: Stimulus,
) -> Vec<(bool, Pins, u64)> {
    let mut dut = ModeRequests::new(s, ModelDut::new(s), requests);
    let mut adc = Adc::new(s, k);
    let mut out = Vec::new();
    let mut miso = (1u64 << s.branches.len()) - 1;
    for c in 0..4 + frames * s.grid.frame_cycles {
        let rst = c < 4;
        let p = dut.step(rst, miso);
        miso = adc.drive(c.saturating_sub(4), &p);
        out.push((rst, p, miso));
    }
    out
}

fn judge_trace(s: &Schedule, trace: &[(bool, Pins, u64)], model: bool) -> judge::Verdict {
    let opts = judge::CheckOptions {
        model,
        ..Default::default()
    };
    let mut chk = judge::Checker::new(s, opts);
    for (rst, p, miso) in trace {
        chk.cycle(*rst, p, *miso);
    }
    chk.finish("trace")
}

/// The line's bytes (read by `link`'s receiver) decoded with the mix's modes.
fn packets(s: &Schedule, trace: &[(bool, Pins, u64)]) -> Vec<link::Packet> {
    let plan = lut_gen::plan_link(s).unwrap().unwrap();
    let cfg = plan.tx_config(s);
    assert!(cfg.mode_bits > 0);
    let mut rx = link::UartRx::new(plan.uart().unwrap());
    let mut dec = link::Decoder::with_modes(s.grid.slices_per_frame, cfg.mode_bits);
    let mut out = Vec::new();
    for (rst, p, _) in trace.iter().filter(|t| !t.0) {
        let _ = rst;
        if let Some(b) = rx.sample(p.link_tx) {
            dec.push_packets(&[b.byte], &mut out);
        }
    }
    assert!(dec.finish().clean());
    out
}

/// The mode pin in the first cycle of each frame.
fn frame_modes(s: &Schedule, trace: &[(bool, Pins, u64)]) -> Vec<u8> {
    let f = s.grid.frame_cycles as usize;
    trace[4..].iter().step_by(f).map(|t| t.1.mode).collect()
}

/// Every packet of a switching run names its frame's mode and the one
/// before, as the `mode` pin showed them; the run is clean with and
/// without the model, and both modes travel.
fn check_run(s: &Schedule, frames: u64, requests: &[(u64, u8)], k: Stimulus) {
    let trace = record(s, frames, requests, k);
    for model in [true, false] {
        let v = judge_trace(s, &trace, model);
        assert!(v.ok, "{}, model {model}: {}", s.mix.name, v.summary());
    }
    let modes = frame_modes(s, &trace);
    let got = packets(s, &trace);
    assert!(got.len() as u64 >= (frames - 1) * s.grid.slices_per_frame);
    for p in &got {
        let f = p.frame as usize;
        let before = if f == 0 { 0 } else { modes[f - 1] };
        assert_eq!(
            (p.mode, p.prev_mode),
            (modes[f], before),
            "{}: frame {f} slice {}",
            s.mix.name,
            p.slice
        );
    }
    let mut seen: Vec<u8> = got.iter().map(|p| p.mode).collect();
    seen.dedup();
    assert!(seen.len() >= 3, "{}: {seen:?}", s.mix.name);
}

#[test]
fn packets_carry_the_modes_of_pin_and_auto_runs() {
    check_run(
        &with_link("modes-pin"),
        10,
        &[(2, 1), (5, 0)],
        Stimulus::default(),
    );
    let s = with_link("modes-auto");
    let k = Stimulus::parse_for("touch:T0,T2@2-6", &s).unwrap();
    check_run(&s, 14, &[], k);
}

/// The random mixes: 2 or 3 modes (pin select) over a UART, 2 branches and
/// 2 to 8 channels at harmonic rates per mode.
const RANDOM_MODES: PinShape = PinShape {
    header: "[clock]\nhz = 8_000_000\n[frame]\nperiod_us = 1_000\nslice_us = 250\n[link]\nkind = \"uart\"\nbaud = 2_000_000\n",
    mux_devices: 1,
    more_channels: 7,
};

#[test]
fn random_mode_mixes_send_their_modes() {
    let mut ran = 0;
    for seed in 1..30u64 {
        let Some(text) = random_pin_mode_mix(seed, &RANDOM_MODES) else {
            continue;
        };
        let Ok(s) = std::panic::catch_unwind(|| schedule_of(&text, &format!("r{seed}"))) else {
            continue;
        };
        let n = s.modes.len() as u8;
        let req = [(1, 1 % n), (3, 0), (4, n - 1), (7, 0)];
        check_run(&s, 11, &req, Stimulus::default());
        ran += 1;
        if ran == 4 {
            break;
        }
    }
    assert!(ran >= 3, "only {ran} random mixes scheduled");
}

/// A link that sends every header with mode 0 (its `mode` input tied low):
/// the model-free check names the first packet after the switch
/// (`link-mode`), and the model sees the line diverge.
#[test]
fn a_header_with_the_wrong_mode_fails() {
    let s = with_link("modes-pin");
    let mut trace = record(&s, 8, &[(2, 1)], Stimulus::default());
    let plan = lut_gen::plan_link(&s).unwrap().unwrap();
    let mut tx = link::TxModel::new(plan.tx_config(&s));
    for (rst, p, _) in trace.iter_mut() {
        p.link_tx = tx.line();
        let sample = p.sample_valid.then_some((p.sample_channel, p.sample_value));
        tx.clock(*rst, sample);
    }
    let v = judge_trace(&s, &trace, false);
    let f = s.grid.frame_cycles;
    let first = v
        .violations
        .iter()
        .find(|x| x.rule == "link-mode")
        .expect("link-mode");
    // frame 4 is the first in mode 1: its first packet closes in frame 4
    assert!(
        (4 * f..5 * f + f / 2).contains(&first.cycle),
        "{}",
        v.summary()
    );
    let v = judge_trace(&s, &trace, true);
    assert!(
        v.divergences.iter().any(|d| d.signal == "link_tx"),
        "{}",
        v.summary()
    );
}
