//! Which mode each frame runs in, as docs/timing.md ("Mode switches")
//! decides it, from what a design's pins show: `mode_sel` (pin select) or
//! the samples (auto select).  The reference model follows it, and so does
//! the model-free check of a run's `mode` pin.
//!
//! In brief (F = `frame_cycles`): frames 0 and 1 run mode 0; at the edge
//! that begins frame `f + 1` the mode of frame `f + 2` is decided, from
//! `mode_sel` as it was in the last cycle of frame `f` (a value naming no
//! mode keeps the mode of frame `f + 1`), or from the first trigger armed in
//! frame `f + 1`'s mode whose condition held in its last `for_frames`
//! windows, all of frames in that mode (window `w`: the watched samples
//! whose conversion completes in frame `w`).

use lut_gen::Schedule;
use lut_gen::{ModeSelect, When};

/// One trigger's condition over the window being filled.
#[derive(Debug, Clone, Copy, Default)]
struct Window {
    /// Some watched sample was seen.
    any: bool,
    /// Some watched sample's code was above the level.
    above: bool,
    /// Every watched sample's code was below the level.
    below: bool,
}

#[derive(Debug, Clone)]
struct Trig {
    to: usize,
    from: Option<usize>,
    when: When,
    level: u32,
    for_frames: u32,
    win: Window,
    /// Consecutive windows, ending at the last closed one, in which the
    /// condition held, all of frames in one mode.
    run: u32,
}

impl Trig {
    fn armed_in(&self, m: usize) -> bool {
        m != self.to && self.from.is_none_or(|f| f == m)
    }
    fn held(&self) -> bool {
        match self.when {
            When::Above => self.win.above,
            When::Below => self.win.any && self.win.below,
        }
    }
}

/// The modes of the frame in force and of the next one, decided frame by
/// frame.  Without modes every frame is mode 0.
#[derive(Debug, Clone)]
pub struct ModeTrack {
    count: usize,
    select: Option<ModeSelect>,
    trig: Vec<Trig>,
    /// Per channel: the triggers watching it.
    watch: Vec<Vec<usize>>,
    /// The frame in force, its mode, the next frame's mode and the mode of
    /// the frame before (the last closed window's).
    frame: u64,
    cur: usize,
    next: usize,
    prev: usize,
    /// Decisions given, not taken from the pins: (frame, mode).  A check
    /// that joins a run mid-way starts its model with the modes the run's
    /// `mode` pin showed (`lock`), and the lock's templates run one mode.
    forced: Vec<(u64, usize)>,
    /// When kept: every decision the pins or the windows made, `(frame,
    /// mode)`, before a forced mode replaced it (a capture's check holds
    /// the modes the design ran to the triggers on the samples it read).
    decisions: Option<Vec<(u64, usize)>>,
}

impl ModeTrack {
    pub fn new(s: &Schedule) -> ModeTrack {
        let plan = s.mode_plan();
        let trig: Vec<Trig> = plan
            .filter(|p| p.select == ModeSelect::Auto)
            .map(|p| {
                p.triggers
                    .iter()
                    .map(|t| Trig {
                        to: t.to,
                        from: t.from,
                        when: t.when,
                        level: t.level,
                        for_frames: t.for_frames.max(1),
                        win: Window::default(),
                        run: 0,
                    })
                    .collect()
            })
            .unwrap_or_default();
        let mut watch = vec![Vec::new(); s.channels.len()];
        if let Some(p) = plan.filter(|p| p.select == ModeSelect::Auto) {
            for (k, t) in p.triggers.iter().enumerate() {
                for &c in &t.channels {
                    watch[c].push(k);
                }
            }
        }
        let mut m = ModeTrack {
            count: plan.map_or(1, |p| p.names.len()),
            select: plan.map(|p| p.select),
            trig,
            watch,
            frame: 0,
            cur: 0,
            next: 0,
            prev: 0,
            forced: Vec::new(),
            decisions: None,
        };
        m.open_windows();
        m
    }

    /// The mix has more than one mode.
    pub fn switches(&self) -> bool {
        self.count > 1
    }

    /// Modes are chosen by the `mode_sel` pin.
    pub fn by_pin(&self) -> bool {
        self.select == Some(ModeSelect::Pin)
    }

    /// The mode of frame `f`, if decided yet (the frame in force or the next).
    #[inline]
    pub fn mode_of(&self, f: u64) -> Option<usize> {
        if !self.switches() {
            Some(0)
        } else if f == self.frame {
            Some(self.cur)
        } else if f == self.frame + 1 {
            Some(self.next)
        } else {
            None
        }
    }

    /// The mode in force.
    pub fn mode(&self) -> usize {
        self.cur
    }

    /// The frame in force.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Frame `frame` (2 or later: frames 0 and 1 run mode 0) runs `mode`,
    /// whatever the pins or the windows say.
    pub fn force(&mut self, frame: u64, mode: usize) {
        if mode < self.count {
            self.forced.push((frame, mode));
        }
    }

    /// Keeps every decision from now on, before a forced mode replaces it
    /// ([`ModeTrack::decisions`]).
    pub(crate) fn keep_decisions(&mut self) {
        self.decisions = Some(Vec::new());
    }

    /// The decisions kept: `(frame, mode)` the pins or the windows decided.
    pub(crate) fn decisions(&self) -> &[(u64, usize)] {
        self.decisions.as_deref().unwrap_or(&[])
    }

    /// A check that joined a run in frame `frame`, whose mode it does not
    /// know yet: every trigger's run restarts (the windows before the join
    /// were not seen).  Returns the last frame whose mode was decided from
    /// what came before the join (the caller takes it from the `mode` pin
    /// with [`ModeTrack::learn`]): the next frame for pin select, and the
    /// frames decided from a window the join cut, for auto select.
    pub fn join(&mut self, frame: u64) -> u64 {
        self.frame = frame;
        for t in &mut self.trig {
            t.run = 0;
        }
        self.open_windows();
        let reach = self
            .trig
            .iter()
            .map(|t| t.for_frames as u64)
            .max()
            .unwrap_or(0);
        frame + 1 + reach
    }

    /// The mode of the frame in force, taken from the design (a frame whose
    /// decision the check did not see).  At the join (`joined`) the next
    /// frame's is not known either: it is learnt at its start too.
    pub fn learn(&mut self, mode: usize, joined: bool) {
        if mode < self.count {
            self.cur = mode;
            if joined {
                self.next = mode;
                self.prev = mode;
            }
        }
    }

    fn open_windows(&mut self) {
        for t in &mut self.trig {
            t.win = Window {
                any: false,
                above: false,
                below: true,
            };
        }
    }

    /// A word of `channel` with `code` whose conversion completed in the
    /// frame in force (auto select: it joins that frame's window).
    #[inline]
    pub fn sample(&mut self, channel: usize, code: u16) {
        let Some(ks) = self.watch.get(channel) else {
            return;
        };
        for &k in ks {
            let t = &mut self.trig[k];
            t.win.any = true;
            t.win.above |= code as u32 > t.level;
            t.win.below &= (code as u32) < t.level;
        }
    }

    /// The edge that begins the next frame, with `mode_sel` as it was in the
    /// last cycle of the frame ending: closes its window, decides the mode
    /// of the frame after the next one and moves on.  Returns that mode.
    pub fn frame_start(&mut self, mode_sel: u64) -> usize {
        if !self.switches() {
            self.frame += 1;
            return 0;
        }
        // The window of the frame ending (`self.frame`, mode `self.cur`),
        // continuing a run only over frames of one mode.
        let same = self.frame > 0 && self.cur == self.prev;
        for t in &mut self.trig {
            t.run = match (t.held(), same) {
                (false, _) => 0,
                (true, true) => t.run.saturating_add(1),
                (true, false) => 1,
            };
        }
        let m = self.next;
        let decided = match self.select {
            Some(ModeSelect::Pin) => {
                if (mode_sel as usize) < self.count {
                    mode_sel as usize
                } else {
                    m
                }
            }
            _ => self
                .trig
                .iter()
                .find(|t| t.armed_in(m) && self.cur == m && t.run >= t.for_frames)
                .map_or(m, |t| t.to),
        };
        if let Some(d) = &mut self.decisions {
            d.push((self.frame + 2, decided));
        }
        let decided = self
            .forced
            .iter()
            .find(|f| f.0 == self.frame + 2)
            .map_or(decided, |f| f.1);
        self.prev = self.cur;
        self.frame += 1;
        self.cur = m;
        self.next = decided;
        self.open_windows();
        decided
    }
}
