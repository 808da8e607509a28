//! A capture of a mix with modes, judged frame by frame against the mode in
//! force (docs/timing.md, "Mode switches").
//!
//! A frame's edges depend on three modes: its own (its instants), the one
//! before (a conversion that started late in that frame ends in this one)
//! and the next (the mux rule addresses the next frame's first instant).
//! So the periodic template of a one-mode mix becomes one frame of edges per
//! triple of modes, all recorded from one run of the model through a
//! sequence of modes holding every triple (a de Bruijn sequence).  Each
//! frame phase the scan keeps also keeps its frames' modes, read from the
//! capture as the phase places the frames: `mode_sel` in the last cycle of
//! frame `w - 2` (pin select), or else the `mode` output in the middle of
//! frame `w` (whose edges are then timed like every output, so a switch
//! inside a frame still fails).  The frames before the capture could say
//! (the first three after the lock at most) are tried in every mode.

use std::cell::RefCell;

use lut_gen::Schedule;

use crate::capture::check::{Capture, Lane, ModePin, TimedError};
use crate::model::CycleModel;

/// Per triple of modes `(before, this, next)` (index `(a n + b) n + c`):
/// per lane, (cycle in frame, new level) of the frame's edges.
pub(crate) struct Modal {
    pub n: usize,
    pub frames: Vec<Vec<Vec<(u64, bool)>>>,
    /// Conversion starts in the frame, per triple.
    pub conversions: Vec<u64>,
    /// Per lane: the closest two edges anywhere in the run, in cycles.
    pub min_gap: Vec<u64>,
    /// Per branch: the least cycles from a mux change to the next instant.
    pub settle_margin: Vec<Option<u64>>,
}

impl Modal {
    pub fn triple(&self, (a, b, c): (usize, usize, usize)) -> usize {
        (a * self.n + b) * self.n + c
    }
}

/// A de Bruijn sequence over `n` symbols of order 3: every triple occurs
/// once as a cyclic window.
fn de_bruijn(n: usize) -> Vec<usize> {
    fn db(t: usize, p: usize, n: usize, a: &mut [usize], out: &mut Vec<usize>) {
        if t > 3 {
            if 3 % p == 0 {
                out.extend_from_slice(&a[1..=p]);
            }
            return;
        }
        a[t] = a[t - p];
        db(t + 1, p, n, a, out);
        for j in a[t - p] + 1..n {
            a[t] = j;
            db(t + 1, t, n, a, out);
        }
    }
    let mut out = Vec::new();
    db(1, 1, n, &mut [0; 4], &mut out);
    out
}

/// Every triple's frame of edges on `lanes`, from the model run through a
/// sequence of forced modes.
pub(crate) fn template(s: &Schedule, lanes: &[Lane], n: usize) -> Modal {
    let f = s.grid.frame_cycles;
    let db = de_bruijn(n);
    // two frames of warm-up in the first mode, then every window, wrapped
    let mut seq = vec![db[0], db[0]];
    seq.extend(&db);
    seq.extend(&db[..2]);
    let forced: Vec<(u64, usize)> = (seq.iter().enumerate())
        .map(|(i, &m)| (2 + i as u64, m))
        .collect();
    let mut m = CycleModel::with_modes(s, &forced);
    let layout = lut_gen::Layout::new(s);
    let nb = layout.branches;
    let cnv = crate::capture::check::cnv_mask(s);
    let mut out = Modal {
        n,
        frames: vec![Vec::new(); n * n * n],
        conversions: vec![0; n * n * n],
        min_gap: vec![u64::MAX; lanes.len()],
        settle_margin: vec![None; nb],
    };
    // frames recorded: seq index 2 on, each with its window
    let first = 4 * f;
    let last = (2 + seq.len() as u64 - 1) * f;
    while m.cycle() < first - f {
        m.step(0);
    }
    let mut prev = *m.pins();
    let mut last_edge: Vec<Option<u64>> = vec![None; lanes.len()];
    let mut last_mux = vec![0u64; nb];
    let mut rec: Option<usize> = None;
    m.step(0);
    while m.cycle() < last {
        let c = m.cycle();
        if c.is_multiple_of(f) && c >= first {
            let i = (c / f - 2) as usize;
            let k = out.triple((seq[i - 1], seq[i], seq[i + 1]));
            rec = out.frames[k].is_empty().then(|| {
                out.frames[k] = vec![Vec::new(); lanes.len()];
                k
            });
        }
        let p = *m.pins();
        for (i, lane) in lanes.iter().enumerate() {
            if lane.get(&p) == lane.get(&prev) {
                continue;
            }
            if let Some(k) = rec {
                out.frames[k][i].push((c % f, lane.get(&p)));
            }
            if let Some(e) = last_edge[i] {
                out.min_gap[i] = out.min_gap[i].min(c - e);
            }
            last_edge[i] = Some(c);
        }
        #[allow(clippy::needless_range_loop)] // b: a branch of the pins too
        for b in 0..nb {
            if layout.sel(&p, b) != layout.sel(&prev, b) || layout.en(&p, b) != layout.en(&prev, b)
            {
                last_mux[b] = c;
            }
            let cs = |q: &lut_gen::Pins| (q.cs_n ^ cnv) >> b & 1 == 0;
            if cs(&p) && !cs(&prev) && c >= first {
                if let Some(k) = rec {
                    out.conversions[k] += 1;
                }
                let g = c - last_mux[b];
                let mg = &mut out.settle_margin[b];
                *mg = Some(mg.map_or(g, |x| x.min(g)));
            }
        }
        prev = p;
        m.step(0);
    }
    for g in &mut out.min_gap {
        *g = (*g).min(f);
    }
    out
}

/// Where a capture says which mode each frame runs in.
pub(crate) struct ModeSource<'a> {
    pub(crate) steps: &'a [(u64, u64)],
    /// Capture lane of each bit of the port read.
    pub(crate) bits: Vec<usize>,
    /// `mode_sel` (the decision, two frames ahead) or `mode` (the frame's own).
    pub(crate) by_sel: bool,
    pub(crate) n: usize,
    pub(crate) frame: i128,
    /// Capture start and end, the resolution, one cycle: in units.
    pub(crate) start: i128,
    pub(crate) end: i128,
    pub(crate) res: i128,
    pub(crate) tc: i128,
    pub(crate) clock: i128,
}

impl<'a> ModeSource<'a> {
    /// The source for `cap`: `mode_sel` when all its bits are mapped (pin
    /// select), else `mode`; an error naming what to map without either.
    pub fn new(
        s: &Schedule,
        cap: &'a Capture,
        (res, tc, clock): (i128, i128, i128),
    ) -> Result<ModeSource<'a>, TimedError> {
        let layout = lut_gen::Layout::new(s);
        let plan = s.mode_plan().expect("a mix with modes");
        let bits_of = |pin: ModePin| -> Option<Vec<usize>> {
            (0..layout.mode_bits)
                .map(|b| (cap.lanes.iter()).position(|l| l.mode == Some(pin) && l.bit == b))
                .collect()
        };
        let (bits, by_sel) = match (
            layout.mode_pin,
            bits_of(ModePin::Sel),
            bits_of(ModePin::Mode),
        ) {
            (true, Some(b), _) => (b, true),
            (_, _, Some(b)) => (b, false),
            (pin, _, _) => {
                let w = layout.mode_bits - 1;
                let range = |p: &str| {
                    if w == 0 {
                        format!("{p}[0]")
                    } else {
                        format!("{p}[{w}:0]")
                    }
                };
                return Err(TimedError(format!(
                    "this mix switches modes ({}) and the map does not say which mode each frame runs in: map {} to analyser channels (ports.json \"mode\"), so each frame is judged against its mode",
                    if pin { "select = \"pin\"" } else { "select = \"auto\"" },
                    if pin {
                        format!("{} (the requests) or {} (the mode in force)", range("mode_sel"), range("mode"))
                    } else {
                        format!("{} (the mode in force)", range("mode"))
                    }
                )));
            }
        };
        let t = |x: u64| x as i128 * clock;
        Ok(ModeSource {
            steps: &cap.steps,
            bits,
            by_sel,
            n: plan.names.len(),
            frame: s.grid.frame_cycles as i128,
            start: t(cap.steps.first().map_or(0, |x| x.0)),
            end: t(cap.steps.last().map_or(0, |x| x.0)),
            res,
            tc,
            clock,
        })
    }

    /// The analyser channels the modes are read from.
    pub fn lane_names(&self, cap: &Capture) -> String {
        (self.bits.iter().rev())
            .map(|&l| cap.lanes[l].channel.as_str())
            .collect::<Vec<_>>()
            .join(",")
    }

    /// The port's value at `t` (units).
    fn read(&self, t: i128) -> usize {
        let ps = (t / self.clock).max(0) as u64;
        let i = self.steps.partition_point(|x| x.0 <= ps).max(1) - 1;
        let v = self.steps[i].1;
        (self.bits.iter().enumerate()).fold(0, |a, (k, &l)| a | ((v >> l & 1) as usize) << k)
    }

    /// The mode of frame `w` of a phase with cycle 0 in `[lo, hi]`, the
    /// modes of frames `..w` being `known`; `None` when the capture does
    /// not say (it starts too late).
    pub fn decide(&self, lo: i128, hi: i128, w: u64, known: &[u8]) -> Option<u8> {
        let mid = lo + (hi - lo) / 2;
        let last = known.last().copied();
        if self.by_sel {
            // `mode_sel` in the last cycle of frame w - 2
            let c = (w as i128 - 1) * self.frame - 1;
            let t = mid + c * self.tc + self.tc / 2;
            if t - self.res < self.start {
                return None;
            }
            let v = self.read(t);
            return if v < self.n { Some(v as u8) } else { last };
        }
        let t = mid + (w as i128 * self.frame + self.frame / 2) * self.tc;
        if t < self.start {
            return None;
        }
        if t > self.end {
            return last;
        }
        Some(self.read(t).min(self.n - 1) as u8)
    }

    /// The frame of a phase with cycle 0 at `lo` past which the capture has ended.
    pub fn end_frame(&self, lo: i128) -> u64 {
        ((self.end - lo).max(0) / self.tc / self.frame) as u64 + 2
    }
}

/// A phase's frames' modes (frame index as the phase counts them),
/// extended as the scan reaches them.
#[derive(Clone, Default)]
pub(crate) struct Modes(pub RefCell<Vec<u8>>);

impl Modes {
    /// The mode of frame `w`, decided from the capture if not yet.
    pub fn of(&self, src: &ModeSource, lo: i128, hi: i128, w: u64) -> usize {
        let mut m = self.0.borrow_mut();
        while m.len() as u64 <= w {
            let k = m.len() as u64;
            let d = src.decide(lo, hi, k, &m);
            let v = d.or(m.last().copied()).unwrap_or(0);
            m.push(v);
        }
        m[w as usize] as usize
    }
}

/// The modes a capture's frames ran in, as the phase found places them.
#[derive(Debug, Clone, PartialEq)]
pub struct ModesSeen {
    /// The port the modes were read from: `mode_sel` or `mode`.
    pub by: &'static str,
    /// The mode of the frame the phase was found in.
    pub first: String,
    /// Every switch: the time its frame began (ps) and the new mode.
    pub switches: Vec<(u64, String)>,
}

impl ModesSeen {
    pub fn text(&self) -> String {
        let mut t = format!(
            "modes: each frame judged against its mode (read from `{}`): {} when the phase was found",
            self.by, self.first
        );
        for (ps, m) in &self.switches {
            t += &format!(", {m} from {:.3} us", *ps as f64 / 1e6);
        }
        if self.switches.is_empty() {
            t += ", no switch";
        }
        t
    }
}

/// The frames from the lock (`from_ps`) to the capture's end (`end`, in
/// units) of the phase `(lo, hi, c0, modes)`: their modes, the switches,
/// and the conversions they hold (the frames at the ends in proportion).
pub(crate) fn seen(
    s: &Schedule,
    src: &ModeSource,
    modal: &Modal,
    (lo, hi, c0): (i128, i128, u64),
    modes: &Modes,
    (from_ps, end): (u64, i128),
) -> (ModesSeen, u64) {
    let names = &s.mode_plan().expect("modes").names;
    let f = src.frame;
    let mid = lo + (hi - lo) / 2;
    let at = |w: u64| modes.of(src, lo, hi, w);
    let start_of = |w: u64| mid + w as i128 * f * src.tc;
    let first_w = c0 / f as u64;
    let mut out = ModesSeen {
        by: if src.by_sel { "mode_sel" } else { "mode" },
        first: names[at(first_w)].clone(),
        switches: Vec::new(),
    };
    let mut conv = 0.0;
    let mut w = first_w;
    while start_of(w) < end {
        let m = at(w);
        if w > first_w && m != at(w - 1) {
            out.switches
                .push(((start_of(w) / src.clock) as u64, names[m].clone()));
        }
        let a = if w == 0 { m } else { at(w - 1) };
        let n = modal.conversions[modal.triple((a, m, at(w + 1)))] as f64;
        // the part of the frame inside [from, end)
        let (s0, s1) = (start_of(w), start_of(w + 1));
        let lo_t = s0.max(from_ps as i128 * src.clock);
        let hi_t = s1.min(end);
        if hi_t > lo_t {
            conv += n * (hi_t - lo_t) as f64 / (s1 - s0) as f64;
        }
        w += 1;
    }
    (out, conv as u64)
}
