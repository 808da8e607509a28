//! The switching scenario of a mix with modes (docs/faults.md, "Mode
//! switches"): every run of the campaign on such a mix switches, so every
//! class is judged across a switch, and the `mode` faults land at its frame
//! starts.  Pin select: `mode_sel` asks for mode 1 from frame 0 (the switch
//! lands at frame 2); auto select: the watched channels of the first
//! `above` trigger armed after reset are touched from frame 0.

use judge::{Dut, ModeRequests, ModelDut, PinFault, RunOptions, Stimulus};
use lut_gen::{ModeSelect, Schedule, When};

use super::Site;

/// The `mode_sel` requests and the stimulus of the scenario (none: a mix
/// without modes, or an auto mix no touch switches).
pub(super) fn scenario(s: &Schedule, frames: u64) -> (Vec<(u64, u8)>, Option<Stimulus>) {
    let Some(plan) = s.mode_plan().filter(|_| s.modes.len() > 1) else {
        return (Vec::new(), None);
    };
    if plan.select == ModeSelect::Pin {
        return (vec![(0, 1)], None);
    }
    let touch = plan
        .triggers
        .iter()
        .find(|t| t.when == When::Above && t.leaves(0))
        .map(|t| {
            let names: Vec<&str> = t
                .channels
                .iter()
                .map(|&c| s.mix.channels[c].name.as_str())
                .collect();
            format!("touch:{}@0-{}", names.join(","), frames + 1)
        });
    (
        Vec::new(),
        touch.and_then(|k| Stimulus::parse_for(&k, s).ok()),
    )
}

/// The run options of every run of the campaign on `s`: its stimulus.
pub(super) fn run_options(s: &Schedule, frames: u64) -> RunOptions {
    let mut o = RunOptions::default();
    if let Some(k) = scenario(s, frames).1 {
        o.stimulus = k;
    }
    o
}

/// `dut` with the scenario's `mode_sel` requests (pin select).
pub(super) fn with_requests(s: &Schedule, dut: Box<dyn Dut>) -> Box<dyn Dut> {
    let (requests, _) = scenario(s, 0);
    if requests.is_empty() {
        dut
    } else {
        Box::new(ModeRequests::new(s, dut, &requests))
    }
}

/// Where a `mode` fault lands: the first frame start from frame 1 on where
/// the clean scenario switches (`ModeEarly`, `ModeStuck`), or where it does
/// not (`ModeUnasked`); `None` if the run has none.
pub(super) fn mode_site(s: &Schedule, f: PinFault, frames: u64) -> Option<Site> {
    let modes = frame_modes(s, frames);
    let fc = s.grid.frame_cycles;
    let switch = f != PinFault::ModeUnasked;
    (1..modes.len())
        .find(|&g| (modes[g] != modes[g - 1]) == switch)
        .map(|g| Site {
            name: if switch { "mode-switch" } else { "mode-steady" },
            cycle: g as u64 * fc,
            slot: 0,
        })
}

/// The `mode` pin at each frame's first cycle in a clean run of the scenario
/// on the model.
fn frame_modes(s: &Schedule, frames: u64) -> Vec<u8> {
    struct Modes(Vec<u8>, u64, u64);
    impl judge::Observer for Modes {
        fn cycle(&mut self, _cycle: u64, rst: bool, pins: &lut_gen::Pins, _miso: u64) {
            if rst {
                self.2 = 0;
                self.0.clear();
                return;
            }
            if self.2.is_multiple_of(self.1) {
                self.0.push(pins.mode);
            }
            self.2 += 1;
        }
    }
    let mut dut = with_requests(s, Box::new(ModelDut::new(s)));
    let mut seen = Modes(Vec::new(), s.grid.frame_cycles, 0);
    let opts = run_options(s, frames);
    judge::run_dut(s, &mut dut, frames, &opts, "scenario", Some(&mut seen));
    seen.0
}
