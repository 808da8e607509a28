//! The mode rules of a run, without the model (docs/timing.md, "Mode
//! switches"): the `mode` output changes only at a frame start, and each
//! frame's mode is the one the contract decides from `mode_sel` (pin
//! select) or from the watched samples (auto select).  Each frame's
//! per-channel counts and intervals are then those of the mode the design
//! shows ([`crate::Invariants`]).

use serde_json::json;

use crate::model::modes::ModeTrack;
use crate::model::rule::Rule;
use crate::model::verdict::Violation;

#[derive(Debug, Clone)]
pub(crate) struct ModeCheck {
    pub(crate) track: ModeTrack,
    names: Vec<String>,
    frame_cycles: u64,
    /// `mode_sel` and `mode` in the last cycle seen.
    sel: u8,
    prev: u8,
    /// The mode the design showed at the start of the frame being counted.
    pub(crate) shown: usize,
    /// A check that joined mid-run: the last frame whose mode is learnt
    /// from the `mode` pin (decided before the join), and whether a cycle
    /// was seen yet.
    learn_until: Option<u64>,
    seen: bool,
}

impl ModeCheck {
    /// `None` for a mix without switches.
    pub(crate) fn new(s: &lut_gen::Schedule) -> Option<ModeCheck> {
        let track = ModeTrack::new(s);
        track.switches().then(|| ModeCheck {
            track,
            names: s.mode_plan().map(|p| p.names.clone()).unwrap_or_default(),
            frame_cycles: s.grid.frame_cycles,
            sel: 0,
            prev: 0,
            shown: 0,
            learn_until: None,
            seen: false,
        })
    }

    fn name(&self, m: usize) -> String {
        self.names
            .get(m)
            .map_or_else(|| format!("{m} (no such mode)"), |n| format!("{m} ({n})"))
    }

    /// Cycle `c`'s `mode_sel` and `mode`: a violation if `mode` changed
    /// inside a frame, or shows at a frame start another mode than the one
    /// decided.
    pub(crate) fn cycle(&mut self, c: u64, mode_sel: u8, mode: u8) -> Option<Violation> {
        self.sel = mode_sel;
        let prev = std::mem::replace(&mut self.prev, mode);
        let f = c / self.frame_cycles;
        let first = !std::mem::replace(&mut self.seen, true);
        if self.learn_until.is_some_and(|l| f <= l)
            && (first || c.is_multiple_of(self.frame_cycles))
        {
            // decided before the join: the design says which
            self.track.learn(mode as usize, first);
            self.shown = (mode as usize).min(self.names.len() - 1);
            return None;
        }
        if c.is_multiple_of(self.frame_cycles) {
            let want = self.track.mode_of(f).unwrap_or(0);
            self.shown = if (mode as usize) < self.names.len() {
                mode as usize
            } else {
                want
            };
            if mode as usize != want {
                let why = if self.track.by_pin() {
                    "the mode_sel value in the last cycle two frames before"
                } else {
                    "the triggers' windows"
                };
                return Some(
                    Violation::new(Rule::ModeDecision, c)
                        .signal("mode".to_string())
                        .expected(json!(want))
                        .actual(json!(mode))
                        .detail(format!(
                            "this frame runs mode {}, but {why} decide mode {}",
                            self.name(mode as usize),
                            self.name(want)
                        )),
                );
            }
        } else if mode != prev && c > 0 {
            return Some(
                Violation::new(Rule::ModeSwitch, c)
                    .signal("mode".to_string())
                    .expected(json!(prev))
                    .actual(json!(mode))
                    .detail(format!(
                        "mode changed from {} to {} inside the frame (a switch takes effect at a frame start only)",
                        self.name(prev as usize),
                        self.name(mode as usize)
                    )),
            );
        }
        None
    }

    /// The check joins a run in frame `frame` (model cycles).
    pub(crate) fn join(&mut self, frame: u64) {
        self.learn_until = Some(self.track.join(frame));
        self.seen = false;
    }

    /// The edge that begins the next frame: decides the mode of the frame
    /// after it from the last `mode_sel` seen or the windows closed.
    pub(crate) fn frame_start(&mut self) {
        self.track.frame_start(self.sel as u64);
    }
}
