use campaign::for_tests::{decode_commands, sigrok_check as check, window_conversions, SpiCapture};
use judge::{run_dut, Dut, FaultyDut, ModeRequests, ModelDut, PinFault, RunOptions};
use lut_gen::Schedule;

fn capture(s: &Schedule, dut: &mut dyn Dut, frames: u64) -> SpiCapture {
    let opts = RunOptions::default();
    let mut cap = SpiCapture::new(s, judge::reset_cycles(s, opts.reset_cycles));
    run_dut(s, dut, frames, &opts, "sigrok", Some(&mut cap));
    cap
}

/// sigrok's decoder reads the command words on `mosi`: on a clean run
/// of the shared commanded mixes they are the schedule's, every one;
/// a word with a wrong channel bit is named.
#[test]
fn sigrok_reads_the_command_words_on_mosi() {
    if !testkit::tools::require_tool("sigrok-cli") {
        return;
    }
    for name in ["cmd-pair", "cmd-solo"] {
        let s = lut_gen::synthesize(&lut_gen::load(&testkit::mix(name)).unwrap()).unwrap();
        let frames = 4;
        let dir = tempfile::tempdir().unwrap();
        let cap = capture(&s, &mut ModelDut::new(&s), frames);
        assert_eq!(
            check(&s, &cap, frames, dir.path()).unwrap(),
            Ok(()),
            "{name}"
        );
        for b in (0..s.branches.len()).filter(|&b| s.has_command(b)) {
            let got = decode_commands(&dir.path().join("spi.vcd"), &s, b).unwrap();
            let want: Vec<Vec<bool>> = window_conversions(&s, cap.modes(), b, frames, 0)
                .iter()
                .map(|&(m, k, _)| m.commands_in_frame(b)[k].word.clone())
                .collect();
            assert!(!got.is_empty(), "{name} branch {b}");
            assert_eq!(got, want, "{name} branch {b}");
        }
        let b = (0..s.branches.len()).find(|&b| s.has_command(b)).unwrap();
        let at = s.grid.frame_cycles * 3 / 2;
        let mut dut = FaultyDut::new(
            &s,
            ModelDut::new(&s),
            PinFault::WrongChannelBits { branch: b },
            at,
        );
        let cap = capture(&s, &mut dut, frames);
        let e = check(&s, &cap, frames, dir.path()).unwrap().unwrap_err();
        assert!(e.contains("command word"), "{name}: {e}");
    }
}

/// sigrok's detector counts each frame's conversions, and reads its
/// command words, in the mode that frame ran in: a clean run of a mode mix
/// whose MCP3208 converts more often in one mode passes once it switches,
/// and its command words are each frame's mode's (judged against the
/// schedule of one mode for every frame, the count would differ).
#[test]
fn sigrok_judges_each_frame_in_the_mode_it_ran_in() {
    if !testkit::tools::require_tool("sigrok-cli") {
        return;
    }
    let s = lut_gen::synthesize(&lut_gen::load(&testkit::mix("cmd-modes")).unwrap()).unwrap();
    let frames = 4;
    // requested from frame 0, mode 1 runs from frame 2: frame 1 in mode 0
    let mut dut = ModeRequests::new(&s, ModelDut::new(&s), &[(0, 1)]);
    let cap = capture(&s, &mut dut, frames);
    assert_eq!(
        &cap.modes()[1..frames as usize],
        &[0, 1, 1],
        "the run switches"
    );
    let b = (0..s.branches.len()).find(|&b| s.has_command(b)).unwrap();
    let per_mode: Vec<usize> = (0..2)
        .map(|m| s.modes[m].commands_in_frame(b).len())
        .collect();
    assert_ne!(
        per_mode[0], per_mode[1],
        "the modes convert as often: the test cannot fail"
    );
    let dir = tempfile::tempdir().unwrap();
    assert_eq!(check(&s, &cap, frames, dir.path()).unwrap(), Ok(()));
    let got = decode_commands(&dir.path().join("spi.vcd"), &s, b).unwrap();
    let want: Vec<Vec<bool>> = window_conversions(&s, cap.modes(), b, frames, 0)
        .iter()
        .map(|&(m, k, _)| m.commands_in_frame(b)[k].word.clone())
        .collect();
    assert_eq!(got.len(), per_mode[0] + 2 * per_mode[1], "{per_mode:?}");
    assert_eq!(got, want);
}

/// A pin-select mix whose AD7689 (its word selects the conversion two
/// ahead) starts each frame on another channel in each mode.
const AHEAD_MODES: &str = r#"
name = "ahead-modes"
[clock]
hz = 24_000_000
[frame]
period_us = 2_000
slice_us = 1_000
[[mode]]
name = "rest"
[[mode]]
name = "busy"
[modes]
select = "pin"
[[branch]]
name = "b"
adc = "ad7689"
mux = "internal"
[[channel]]
name = "B0"
branch = "b"
rate_hz = 2000
rates = { busy = 1000 }
input = 7
[[channel]]
name = "B1"
branch = "b"
rate_hz = 500
rates = { busy = 2000 }
input = 6
[[channel]]
name = "B2"
branch = "b"
rate_hz = 1000
rates = { busy = 2000 }
input = 5
[[channel]]
name = "B3"
branch = "b"
rate_hz = 1000
rates = { busy = 2000 }
input = 4
"#;

/// A converter whose word selects a later conversion (the AD7689's 2)
/// sends, in a frame's last conversions, the words of the next frame's
/// first ones in the next frame's mode: a clean run that switches passes
/// sigrok's check, and the two words before the switch select the new
/// mode's first channels (judged against the old mode's own wrap, as the
/// check once did, the clean run failed).
#[test]
fn the_words_before_a_switch_select_the_next_modes_first_conversions() {
    if !testkit::tools::require_tool("sigrok-cli") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ahead-modes.toml");
    std::fs::write(&path, AHEAD_MODES).unwrap();
    let s = lut_gen::synthesize(&lut_gen::load(&path).unwrap()).unwrap();
    let (b, ahead) = (0, s.prepared_conversions(0) as usize);
    assert_eq!(ahead, 2);
    let frames = 4;
    let mut dut = ModeRequests::new(&s, ModelDut::new(&s), &[(0, 1)]);
    let cap = capture(&s, &mut dut, frames);
    assert_eq!(&cap.modes()[1..3], &[0, 1], "frame 1 rest, frame 2 busy");
    assert_eq!(check(&s, &cap, frames, dir.path()).unwrap(), Ok(()));
    let got = decode_commands(&dir.path().join("spi.vcd"), &s, b).unwrap();
    // a frame's first `ahead` channels in mode `m`, as the words name them
    let cmd = s.mix.branches[b].adc.command.clone().unwrap();
    let first = |m: usize| -> Vec<Vec<bool>> {
        (s.modes[m].instants(1))
            .filter(|i| i.branch == b)
            .take(ahead)
            .map(|i| cmd.word(s.mix.channels[i.channel].input))
            .collect()
    };
    assert_ne!(
        first(0),
        first(1),
        "the modes start alike: the test cannot fail"
    );
    // frame 1's conversions come first in the window
    let n0 = s.modes[0].commands_in_frame(b).len();
    assert_eq!(got[n0 - ahead..n0].to_vec(), first(1));
}
