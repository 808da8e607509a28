//! What a run of a scene leaves for the mode chart: for every frame the mode
//! in force, the samples on the sample port and the bytes the host received
//! on the link, and every sample strobe and `mode_sel` change, read off the
//! pins of any back end (an [`judge::Observer`] and a [`judge::CycleSink`]).

use judge::{CycleSink, LinkBytes, Observer};
use lut_gen::{Pins, Schedule};

/// One frame of a run, as the pins showed it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameFigures {
    pub frame: u64,
    /// The `mode` pin in the frame's first cycle (0 for a mix without modes).
    pub mode: u8,
    /// `sample_valid` strobes in the frame.
    pub samples: u64,
    /// Bytes the host's receiver finished reading in the frame (0 without a link).
    pub bytes: u64,
}

/// A `sample_valid` strobe, in cycles after cycle 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Strobe {
    pub cycle: u64,
    pub channel: usize,
    pub value: u16,
}

/// The log of a run, kept from the last reset cycle on (cycle 0 is the
/// first cycle after it, as everywhere in the judge).
pub struct SceneLog {
    frame_cycles: u64,
    seen: u64,
    zero: Option<u64>,
    link: Option<LinkBytes>,
    link_start: Option<LinkBytes>,
    pub frames: Vec<FrameFigures>,
    pub strobes: Vec<Strobe>,
    /// `mode_sel` changes: (cycle, value), the first one at cycle 0.
    pub requests: Vec<(u64, u8)>,
}

impl SceneLog {
    pub fn new(s: &Schedule) -> SceneLog {
        let link = LinkBytes::new(s);
        SceneLog {
            frame_cycles: s.grid.frame_cycles,
            seen: 0,
            zero: None,
            link_start: link.clone(),
            link,
            frames: Vec::new(),
            strobes: Vec::new(),
            requests: Vec::new(),
        }
    }

    fn push(&mut self, rst: bool, p: &Pins) {
        let k = self.seen;
        self.seen += 1;
        let before = self.link.as_ref().map_or(0, |l| l.bytes.len());
        if let Some(l) = &mut self.link {
            Observer::cycle(l, k, rst, p, 0);
        }
        if rst {
            self.zero = None;
            self.frames.clear();
            self.strobes.clear();
            self.requests.clear();
            self.link.clone_from(&self.link_start);
            return;
        }
        let zero = *self.zero.get_or_insert(k);
        let cycle = k - zero;
        let f = cycle / self.frame_cycles;
        if self.frames.len() as u64 <= f {
            self.frames.push(FrameFigures {
                frame: f,
                mode: p.mode,
                samples: 0,
                bytes: 0,
            });
        }
        let frame = self.frames.last_mut().expect("pushed above");
        if p.sample_valid {
            frame.samples += 1;
            self.strobes.push(Strobe {
                cycle,
                channel: p.sample_channel as usize,
                value: p.sample_value,
            });
        }
        let after = self.link.as_ref().map_or(0, |l| l.bytes.len());
        frame.bytes += after.saturating_sub(before) as u64;
        if self.requests.last().is_none_or(|r| r.1 != p.mode_sel) {
            self.requests.push((cycle, p.mode_sel));
        }
    }

    /// The mode of frame `f` as the pins showed it (the last one seen for a
    /// frame past the run).
    pub fn mode_of(&self, f: u64) -> usize {
        let i = (f as usize).min(self.frames.len().saturating_sub(1));
        self.frames.get(i).map_or(0, |x| x.mode as usize)
    }

    /// The sampling instant of strobe `x` (`Schedule::sampled_at` in the
    /// schedule of its frame's mode, or of the frame before's for a word
    /// that left after its frame ended), as `sim --samples` finds it.
    pub fn instant(&self, s: &Schedule, x: &Strobe) -> Option<u64> {
        if s.modes.len() < 2 {
            return s.sampled_at(x.channel, x.cycle);
        }
        let f = x.cycle / self.frame_cycles;
        let start = f * self.frame_cycles;
        let here = s.modes.get(self.mode_of(f))?;
        let own = here.sampled_at(x.channel, x.cycle).filter(|&t| t >= start);
        let before = || {
            let m = if f == 0 { 0 } else { self.mode_of(f - 1) };
            s.modes
                .get(m)?
                .sampled_at(x.channel, x.cycle)
                .filter(|&t| t < start)
        };
        own.or_else(before)
    }
}

impl Observer for SceneLog {
    fn cycle(&mut self, _cycle: u64, rst: bool, pins: &Pins, _miso: u64) {
        self.push(rst, pins);
    }
}

impl CycleSink for SceneLog {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, _xz: &Pins, _miso: u64, _miso_xz: u64) {
        // an unknown reset level counts as reset, as in the judge's logs
        self.push(rst.unwrap_or(true), pins);
    }
}
