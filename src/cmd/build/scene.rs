//! What `build`'s co-simulation runs: the stimulus, the pin's requests and
//! the frames. A mix without modes runs `--stimulus` (default `pattern`)
//! for `--frames` (default 3). A mix with modes runs a scene that switches
//! it, long enough to come back: auto select a stroke over the channels its
//! reset mode's triggers watch (the paper's Figure 11: a finger sliding over
//! a row of taxels) unless `--stimulus` says otherwise; pin select a request
//! of every mode in turn and back to the first.

use lut_gen::{ModeSelect, Schedule};

use super::Args;

/// The run of the co-simulation step.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Scene {
    /// The stimulus as the command line writes it (`sim --stimulus`).
    pub stimulus: String,
    /// `mode_sel` requests (frame, mode): a pin-select mix's.
    pub requests: Vec<(u64, u8)>,
    pub frames: u64,
}

impl Scene {
    /// The scene as the command line would write it: the stimulus, and the
    /// requests as `sim --modes` takes them (`pattern, --modes 2=slow,8=fast`).
    pub fn words(&self, s: &Schedule) -> String {
        let Some(m) = s.mix.modes.as_ref().filter(|_| !self.requests.is_empty()) else {
            return self.stimulus.clone();
        };
        let r: Vec<String> = self
            .requests
            .iter()
            .map(|&(f, k)| format!("{f}={}", m.names[k as usize]))
            .collect();
        format!("{}, --modes {}", self.stimulus, r.join(","))
    }
}

/// Frames of the default stroke, and the quiet frames before it.
const STROKE_FRAMES: u64 = 10;
const STROKE_FROM: u64 = 3;
/// Frames a default request of the pin holds before the next.
const REQUEST_FRAMES: u64 = 6;

/// The scene for `s`, or why `--stimulus` is refused (bad input).
pub fn scene(a: &Args, s: &Schedule) -> Result<Scene, String> {
    let Some(modes) = s.mix.modes.as_ref().filter(|m| m.names.len() > 1) else {
        let stimulus = a.stimulus.clone().unwrap_or_else(|| "pattern".into());
        judge::Stimulus::parse_for(&stimulus, s).map_err(|e| format!("--stimulus: {e}"))?;
        return Ok(Scene {
            stimulus,
            requests: Vec::new(),
            frames: a.frames.unwrap_or(3).max(1),
        });
    };
    let n = modes.names.len() as u64;
    let (stimulus, requests) = match (&a.stimulus, modes.select) {
        (Some(t), _) => (t.clone(), Vec::new()),
        (None, ModeSelect::Auto) => (default_stroke(s), Vec::new()),
        (None, ModeSelect::Pin) => {
            let mut r: Vec<(u64, u8)> = (1..n)
                .map(|m| (2 + REQUEST_FRAMES * (m - 1), m as u8))
                .collect();
            r.push((2 + REQUEST_FRAMES * (n - 1), 0));
            ("pattern".into(), r)
        }
    };
    let k = judge::Stimulus::parse_for(&stimulus, s).map_err(|e| format!("--stimulus: {e}"))?;
    // long enough for the scene, its last request, and the slowest reaction after them
    let end = match k {
        judge::Stimulus::Scene(x) => x.to,
        _ => 0,
    }
    .max(requests.last().map_or(0, |r| r.0 + 2));
    let frames = a.frames.unwrap_or(end + settle(s) + 2).max(1);
    Ok(Scene {
        stimulus,
        requests,
        frames,
    })
}

/// Frames the slowest reaction of the mix takes, rounded up.
fn settle(s: &Schedule) -> u64 {
    let f = s.grid.frame_cycles;
    let triggers = s.mix.modes.as_ref().map_or(0, |m| m.triggers.len());
    (0..triggers)
        .filter_map(|k| lut_gen::trigger_latency(s, k))
        .map(|t| t.cycles)
        .chain((0..s.modes.len()).map(|m| lut_gen::pin_latency(s, m)))
        .max()
        .unwrap_or(0)
        .div_ceil(f)
}

/// A stroke over the channels the reset mode's triggers watch, in mix
/// order, from frame 3 for 10 frames.
fn default_stroke(s: &Schedule) -> String {
    let mut watched: Vec<usize> = s
        .mix
        .modes
        .iter()
        .flat_map(|m| &m.triggers)
        .filter(|t| t.leaves(0))
        .flat_map(|t| t.channels.iter().copied())
        .collect();
    watched.sort_unstable();
    watched.dedup();
    let names: Vec<&str> = watched
        .iter()
        .map(|&c| s.mix.channels[c].name.as_str())
        .collect();
    format!(
        "stroke:{}@{STROKE_FROM}-{}",
        measure::short_names(&names),
        STROKE_FROM + STROKE_FRAMES
    )
}
