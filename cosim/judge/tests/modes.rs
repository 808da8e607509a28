//! The reference model follows mode switches (docs/timing.md, "Mode
//! switches"): driven with `mode_sel` requests, every frame samples each
//! channel as often as its frame's mode says, and the switch lands two
//! frames after the frame whose last cycle showed the request.  Counted
//! from the pins alone (CS falls and the mux address at each), not from
//! the model's tables.

use judge::{Adc, CycleModel, Layout, Stimulus};
use lut_gen::Schedule;

fn schedule(path: &std::path::Path) -> Schedule {
    lut_gen::synthesize(&lut_gen::load(path).unwrap()).unwrap()
}

/// `mode_sel` in cycle `c`: the last request at or before `c`'s frame.
fn sel_at(requests: &[(u64, u8)], f: u64) -> u8 {
    requests
        .iter()
        .rfind(|&&(rf, _)| rf <= f)
        .map_or(0, |&(_, m)| m)
}

/// Runs `frames` frames of the model with `requests` on `mode_sel`;
/// returns, per frame, the `mode` pin at its first cycle and the CS falls
/// per channel.
fn run(s: &Schedule, frames: u64, requests: &[(u64, u8)]) -> Vec<(u8, Vec<u64>)> {
    let f = s.grid.frame_cycles;
    let layout = Layout::new(s);
    let mut adc = Adc::new(s, Stimulus::Pattern);
    let mut m = CycleModel::new(s);
    let mut out: Vec<(u8, Vec<u64>)> = Vec::new();
    let mut prev_cs = m.pins().cs_n;
    let mut miso;
    for c in 0..frames * f {
        let p = *m.pins();
        if c % f == 0 {
            out.push((p.mode, vec![0; s.channels.len()]));
        } else {
            assert_eq!(
                p.mode,
                out.last().unwrap().0,
                "mode changed inside a frame at cycle {c}"
            );
        }
        for b in 0..s.branches.len() {
            if prev_cs >> b & 1 == 1 && p.cs_n >> b & 1 == 0 {
                let ch = (0..s.channels.len())
                    .filter(|&k| s.mix.channels[k].branch == b)
                    .find(|&k| {
                        let mut q = p;
                        let cs = &s.channels[k];
                        layout.set_mux(&mut q, b, cs.device, cs.select);
                        q == p
                    })
                    .expect("the mux addresses a channel of the branch");
                out.last_mut().unwrap().1[ch] += 1;
            }
        }
        prev_cs = p.cs_n;
        miso = adc.drive(c, &p);
        m.set_mode_sel(sel_at(requests, c / f));
        m.step(miso);
    }
    out
}

/// The mode frame `g` must run in under `requests` (pin select).
fn expected_mode(s: &Schedule, requests: &[(u64, u8)], g: u64) -> usize {
    let n = s.modes.len();
    let mut mode = 0;
    for h in 2..=g {
        let v = sel_at(requests, h - 2) as usize;
        if v < n {
            mode = v;
        }
    }
    mode
}

fn check(s: &Schedule, frames: u64, requests: &[(u64, u8)]) {
    let got = run(s, frames, requests);
    for (g, (mode, counts)) in got.iter().enumerate() {
        let want = expected_mode(s, requests, g as u64);
        assert_eq!(*mode as usize, want, "frame {g}: mode pin");
        if g == 0 {
            continue; // the start-up skip
        }
        let ms = &s.modes[want];
        for (c, &n) in counts.iter().enumerate() {
            assert_eq!(
                n, ms.channels[c].samples_per_frame,
                "frame {g} (mode {want}): {} sampled {n} times",
                s.mix.channels[c].name
            );
        }
    }
}

#[test]
fn pin_requests_switch_two_frames_later_with_each_modes_counts() {
    let s = schedule(&testkit::mix("modes-pin"));
    check(&s, 12, &[(2, 1), (5, 0), (6, 1), (9, 3), (10, 0)]);
    // a request held for one frame only, and one that names no mode
    check(&s, 8, &[(1, 1), (2, 0), (4, 2)]);
}

/// `text` with its triggers dropped and modes chosen by the pin.
fn as_pin_select(text: &str) -> String {
    let mut out = String::new();
    let mut skip = false;
    for line in text.lines() {
        if line.starts_with('[') {
            skip = line.trim() == "[[trigger]]";
        }
        if !skip {
            out.push_str(&line.replace("select = \"auto\"", "select = \"pin\""));
            out.push('\n');
        }
    }
    out
}

#[test]
fn random_request_sequences_on_pin_mode_mixes() {
    let mut x = 0x2545_f491_4f6c_dd1du64;
    let dir = std::env::temp_dir();
    for name in ["modes-pin", "modes-auto", "eskin34-adaptive"] {
        let text = std::fs::read_to_string(testkit::mix(name)).unwrap();
        let path = dir.join(format!("judge-modes-{name}-{}.toml", std::process::id()));
        std::fs::write(&path, as_pin_select(&text)).unwrap();
        let s = schedule(&path);
        let _ = std::fs::remove_file(&path);
        let n = s.modes.len() as u64;
        for _ in 0..3 {
            let mut req = Vec::new();
            for f in 0..10 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                if x.is_multiple_of(3) {
                    req.push((f, (x / 3 % (n + 1)) as u8));
                }
            }
            check(&s, 10, &req);
        }
    }
}
