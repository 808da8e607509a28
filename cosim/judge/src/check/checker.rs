//! The streaming checker: feed it one cycle of pins at a time (in-process
//! back ends, or cycles recovered from a VCD), then [`Checker::finish`].
//!
//! Two independent layers:
//! - invariants from the mix alone ([`Invariants`], `invariants.rs`, for counts, intervals and
//!   the sample stream; edge tracking per branch for SPI timing, mux settling
//!   and exclusivity, and MISO decoding);
//! - cycle-exact equality with the [`CycleModel`] built from the schedule.

use lut_gen::ns_to_cycles;
use lut_gen::{FrameGrid, Schedule};
use serde_json::{json, Value};

use lut_gen::{Layout, Pins, Role, Signal};

use crate::converter::LowRead;
use crate::converter::{CommandRead, Selected};
use crate::line::LinkLine;
use crate::line::{Joined, LinkJoin};
use crate::model::CycleModel;
use crate::model::Invariants;
use crate::model::Rule;
use crate::model::{Divergence, Verdict, Violation};

/// How much the checker records (it always counts everything).
#[derive(Debug, Clone, Copy)]
pub struct CheckOptions {
    /// Compare every pin against the cycle-level model.
    pub model: bool,
    /// Divergences and violations listed in the report (each).
    pub max_records: usize,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            model: true,
            max_records: 50,
        }
    }
}

/// Datasheet and mix limits of one branch, in cycles (from the mix, not the schedule's SPI plan).
#[derive(Debug, Clone)]
struct Limits {
    sclk_max_hz: u64,
    sclk_min_hz: u64,
    duty_min_pct: u64,
    /// Cycles from the conversion start to the first data clock (CNV
    /// parts: the conversion time plus the setup).
    setup_min: u64,
    quiet_min: u64,
    settle_min: u64,
    /// CNV part: conversion pin active high, SCK idles low, bits read at
    /// SCK rising edges (all of them); CS part: bits 1.. read at SCLK rising
    /// edges.  The checker works in the CS view (CNV lanes inverted).
    cnv: bool,
    /// Serial clocks per conversion, per word; data and leading bits.
    sclks: u32,
    word_sclks: u32,
    bits: u32,
    leading: u32,
}

#[derive(Debug, Clone, Default)]
struct BranchState {
    low: bool,
    t: u64,
    ch: Option<u16>,
    falls: u32,
    rises: u32,
    last_fall: u64,
    last_rise: u64,
    /// Bits read from MISO in this conversion (the last in bit 0).
    word: u128,
    word_bad: bool,
    cs_rise: Option<u64>,
    mux_since: u64,
    /// The mux pins have not changed since reset was released.
    mux_from_reset: bool,
    /// Consecutive reset cycles, up to release, in which the mux pins held
    /// their final reset value, counting the one in which they took it (the
    /// first reset cycle seen at the latest): they count towards the first
    /// settling.
    reset_held: u64,
    en_multi: bool,
    /// Joined mid-stream before this branch's mux last moved: the settling of
    /// its first conversion cannot be known.
    mux_unknown: bool,
    /// A commanded branch: the conversion is prepared (no sample), and the
    /// cycle of the conversion whose word selected `ch`.
    prepared: bool,
    word_at: Option<u64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    PreReset,
    Reset,
    Run,
    Stopped,
}

const CONTEXT_BEFORE: usize = 3;

/// The last `CONTEXT_BEFORE + 1` cycles (cycle, actual, expected), oldest
/// first: a fixed ring, as every checked cycle writes one.
#[derive(Debug, Clone, Default)]
pub struct History {
    buf: [(u64, Pins, Option<Pins>); CONTEXT_BEFORE + 1],
    next: usize,
    len: usize,
}

impl History {
    #[inline]
    pub fn push(&mut self, e: (u64, Pins, Option<Pins>)) {
        const N: usize = CONTEXT_BEFORE + 1;
        self.buf[self.next] = e;
        self.next = (self.next + 1) % N;
        self.len = (self.len + 1).min(N);
    }

    pub fn iter(&self) -> impl Iterator<Item = &(u64, Pins, Option<Pins>)> {
        const N: usize = CONTEXT_BEFORE + 1;
        let start = (self.next + N - self.len) % N;
        (0..self.len).map(move |i| &self.buf[(start + i) % N])
    }
}

/// `a == b` without a branch per field: the checker compares pins several
/// times in every cycle, and they are almost always equal.
#[inline]
pub fn same(a: &Pins, b: &Pins) -> bool {
    let words = (a.mux_en ^ b.mux_en)
        | ((a.mux_sel ^ b.mux_sel) as u128)
        | (((a.cs_n ^ b.cs_n) as u128) << 64)
        | (((a.sclk ^ b.sclk) as u128) << 80)
        | (((a.sample_channel ^ b.sample_channel) as u128) << 96)
        | (((a.sample_value ^ b.sample_value) as u128) << 112)
        // overlapping bits are harmless: only `== 0` is asked
        | ((a.mosi ^ b.mosi) as u128);
    let modes = (a.mode ^ b.mode) | (a.mode_sel ^ b.mode_sel);
    let flags = (a.sample_valid ^ b.sample_valid)
        | (a.link_tx ^ b.link_tx)
        | (a.link_overflow ^ b.link_overflow)
        | (a.axis_tvalid ^ b.axis_tvalid)
        | (a.axis_tlast ^ b.axis_tlast)
        | (a.axis_tready ^ b.axis_tready);
    words == 0 && (a.axis_tdata ^ b.axis_tdata) | modes == 0 && !flags
}
const CONTEXT_AFTER: u8 = 2;

/// The cycle-level streaming checker.
#[derive(Debug, Clone)]
pub struct Checker {
    opts: CheckOptions,
    mix_name: String,
    layout: Layout,
    signals: Vec<Signal>,
    names: Vec<String>,
    branch_names: Vec<String>,
    limits: Vec<Limits>,
    clock_hz: u64,
    grid: FrameGrid,
    model: Option<CycleModel>,
    inv: Invariants,
    /// The link (UART line or AXIS beats) decoded without the model.
    line: Option<LinkLine>,
    phase: Phase,
    c: u64,
    prev: Pins,
    prev_xz: Pins,
    prev_miso: u64,
    prev_miso_xz: u64,
    reset_pins: (Pins, Pins),
    br: Vec<BranchState>,
    /// CNV lanes of `adc_cs_n`/`adc_sclk` (inverted into the CS view).
    flip: u16,
    /// Lanes read with CNV low, given their read's window in the CS view.
    low: LowRead,
    /// Per channel: the channels read in its conversion, by chain member.
    groups: Vec<Vec<Option<usize>>>,
    next_frame_at: u64,
    /// Last cycles (cycle, actual, expected) for divergence context.
    hist: History,
    ctx_open: Vec<(usize, u8)>,
    diverging: Vec<bool>,
    divergence_count: u64,
    divergences: Vec<Divergence>,
    div_active: bool,
    /// The `mode` output differed from the model's in the last cycle.
    mode_diverging: bool,
    xz_seen: bool,
    rst_x_seen: bool,
    /// The model cycle checking began at (0: at reset; later: joined mid-stream).
    origin: u64,
    /// Per branch: its command words read from `adc_mosi` (a converter that
    /// takes one); each channel's input (for reports).
    cmds: Vec<Option<CommandRead>>,
    inputs: Vec<u32>,
    /// Sampling instants held back, in time order, while a commanded
    /// branch's word (a part that converts in the same read) is still being
    /// clocked in: (cycle, branch, channel, still open).  Frames do not close
    /// while any is held.
    held: std::collections::VecDeque<(u64, usize, Option<u16>, bool)>,
    /// Joined mid-stream with the model: its link joins from the line
    /// (until then the link's pins are not compared) ...
    link_join: Option<LinkJoin>,
    /// ... and where it did.
    link_joined: Option<Joined>,
}

/// Where a check joins a run that it did not see start (a capture from the
/// middle of a run): the capture's pins just before, and what the capture
/// showed of the branches' recent past.  Cycles are the model's.
#[derive(Debug, Clone)]
pub struct Join {
    /// The capture's cycle at which checking begins (for reports).
    pub capture_cycle: u64,
    /// Pins (and x/z) and MISO in the cycle before.
    pub prev: Pins,
    pub prev_xz: Pins,
    /// Per branch: the cycle its mux last changed, if the capture showed it.
    pub mux_since: Vec<Option<u64>>,
    /// Per branch: the cycle its CS last rose, if the capture showed it.
    pub cs_rise: Vec<Option<u64>>,
    /// The CS/mux pins repeat every this many cycles (the frame when they
    /// do not): the model's phase is the run's only modulo it.
    pub repeat: u64,
}

/// No bit unknown: an `xz` mask of every pin low.
const NO_XZ: Pins = Pins::LOW;

impl Checker {
    pub fn new(s: &Schedule, opts: CheckOptions) -> Checker {
        let layout = Layout::new(s);
        let mix = &s.mix;
        let limits = mix
            .branches
            .iter()
            .map(|b| Limits {
                sclk_max_hz: b.adc.sclk_max_hz,
                sclk_min_hz: b.adc.sclk_min_hz,
                duty_min_pct: b.adc.duty_min_pct as u64,
                setup_min: ns_to_cycles(b.adc.conversion_ns, mix.clock_hz)
                    + ns_to_cycles(b.adc.setup_ns, mix.clock_hz).max(1),
                quiet_min: ns_to_cycles(b.adc.quiet_ns, mix.clock_hz).max(1),
                settle_min: ns_to_cycles(b.settle_ns, mix.clock_hz),
                cnv: b.adc.start == lut_gen::Start::Cnv,
                sclks: b.adc.word_sclks() * b.chain,
                word_sclks: b.adc.word_sclks(),
                bits: b.adc.bits,
                leading: b.adc.leading_bits,
            })
            .collect();
        let signals = layout.signals();
        let nsig = signals.len();
        let flip = mix
            .branches
            .iter()
            .enumerate()
            .filter(|(_, b)| b.adc.start == lut_gen::Start::Cnv)
            .fold(0u16, |a, (b, _)| a | 1 << b);
        Checker {
            flip,
            low: LowRead::new(s),
            groups: s.groups.clone(),
            opts,
            mix_name: mix.name.clone(),
            signals,
            names: mix.channels.iter().map(|c| c.name.clone()).collect(),
            branch_names: mix.branches.iter().map(|b| b.name.clone()).collect(),
            limits,
            clock_hz: mix.clock_hz,
            grid: s.grid,
            model: opts.model.then(|| CycleModel::new(s)),
            inv: Invariants::new(s, opts.max_records),
            line: LinkLine::new(s),
            phase: Phase::PreReset,
            c: 0,
            prev: Pins::default(),
            prev_xz: NO_XZ,
            prev_miso: 0,
            prev_miso_xz: 0,
            reset_pins: (Pins::default(), NO_XZ),
            br: vec![BranchState::default(); layout.branches],
            layout,
            next_frame_at: s.grid.frame_cycles,
            hist: History::default(),
            ctx_open: Vec::new(),
            diverging: vec![false; nsig],
            divergence_count: 0,
            divergences: Vec::new(),
            div_active: false,
            mode_diverging: false,
            xz_seen: false,
            rst_x_seen: false,
            origin: 0,
            link_join: None,
            link_joined: None,
            cmds: (0..s.branches.len())
                .map(|b| CommandRead::new(s, b))
                .collect(),
            inputs: s.mix.channels.iter().map(|c| c.input).collect(),
            held: Default::default(),
        }
    }

    /// A checker that joins a run at the model's current cycle (in steady
    /// state, where [`CycleModel::quiet`] holds), checking every later cycle
    /// as strictly as one that saw reset.
    pub fn join(s: &Schedule, opts: CheckOptions, model: CycleModel, j: &Join) -> Checker {
        let mut chk = Checker::new(s, opts);
        let mut model = model;
        // The sample port holds the last word sent (in the cycle before, at
        // the latest), from a conversion the check did not see: take it as
        // the model's.
        model.hold_sample(j.prev.sample_channel, j.prev.sample_value);
        let c = model.cycle();
        // the run's slices begin a multiple of this off the model's
        let step = gcd(s.grid.slice_cycles, j.repeat.max(1));
        if opts.model {
            chk.link_join = model
                .tx_config()
                .map(|cfg| LinkJoin::new(cfg, s.grid.slices_per_frame, step, c));
        }
        chk.model = opts.model.then_some(model);
        chk.phase = Phase::Run;
        chk.c = c;
        chk.origin = c;
        chk.inv.join_at(c, j.capture_cycle);
        if let Some(l) = &mut chk.line {
            l.join_at(c, j.prev.link_tx, step);
        }
        chk.next_frame_at = (c / s.grid.frame_cycles + 1) * s.grid.frame_cycles;
        chk.prev = j.prev;
        chk.prev_xz = j.prev_xz;
        let view = chk.view(&j.prev);
        for (b, st) in chk.br.iter_mut().enumerate() {
            st.low = view.cs_n >> b & 1 == 0;
            st.cs_rise = j.cs_rise[b];
            st.mux_unknown = j.mux_since[b].is_none();
            st.mux_since = j.mux_since[b].unwrap_or(0);
        }
        chk.cmds.iter_mut().flatten().for_each(CommandRead::join);
        chk
    }

    /// Cycles checked so far (after reset, or since joining).
    pub fn cycles(&self) -> u64 {
        self.c - self.origin
    }

    /// Whether anything failed so far.
    pub fn failed(&self) -> bool {
        self.divergence_count > 0 || self.inv.violation_count() > 0
    }

    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// One clock cycle: `rst` as sampled at the edge that began it, the
    /// outputs in it, and `adc_miso` during it.
    #[inline]
    pub fn cycle(&mut self, rst: bool, p: &Pins, miso: u64) {
        if self.phase == Phase::Run && !rst && !self.xz_seen {
            self.run_cycle(p, &NO_XZ, miso, 0);
        } else {
            self.cycle_xz(Some(rst), p, &NO_XZ, miso, 0);
        }
    }

    /// Like [`Checker::cycle`] with 4-state values: bits set in `xz` /
    /// `miso_xz` are x or z; `rst = None` is an x/z reset.
    pub fn cycle_xz(&mut self, rst: Option<bool>, p: &Pins, xz: &Pins, miso: u64, miso_xz: u64) {
        match (rst, self.phase) {
            (_, Phase::Stopped) => return,
            (None, Phase::PreReset | Phase::Reset) => return,
            (None, Phase::Run) => {
                if !self.rst_x_seen {
                    self.rst_x_seen = true;
                    self.inv.record(
                        Violation::new(Rule::XOrZ, self.c)
                            .signal(Role::Reset.name().to_string())
                            .actual(json!("x"))
                            .detail("rst is x/z after reset was released"),
                    );
                }
            }
            (Some(true), Phase::Run) => {
                self.inv.record(
                    Violation::new(Rule::Reset, self.c)
                        .signal(Role::Reset.name().to_string())
                        .detail("reset asserted again: checking stops here"),
                );
                self.phase = Phase::Stopped;
                return;
            }
            (Some(true), _) => {
                let (was, was_xz) = self.reset_pins;
                let first = self.phase != Phase::Reset;
                for b in 0..self.layout.branches {
                    let l = &self.layout;
                    let known = l.sel(xz, b) == 0 && l.en(xz, b) == 0;
                    let same = !first
                        && l.sel(&was_xz, b) == 0
                        && l.en(&was_xz, b) == 0
                        && l.sel(p, b) == l.sel(&was, b)
                        && l.en(p, b) == l.en(&was, b);
                    let st = &mut self.br[b];
                    st.reset_held = match (known, same) {
                        (false, _) => 0,
                        (true, false) => 1,
                        (true, true) => st.reset_held + 1,
                    };
                }
                self.phase = Phase::Reset;
                self.reset_pins = (*p, *xz);
                self.prev = *p;
                self.prev_xz = *xz;
                return;
            }
            (Some(false), Phase::PreReset) => return,
            (Some(false), Phase::Reset) => self.start(),
            (Some(false), Phase::Run) => {}
        }
        self.xz_seen |= *xz != NO_XZ || miso_xz != 0;
        self.run_cycle(p, xz, miso, miso_xz);
    }

    fn start(&mut self) {
        self.phase = Phase::Run;
        let (rp, rxz) = self.reset_pins;
        let compare = !crate::switch::disabled("model");
        if let (Some(m), true) = (&self.model, compare) {
            let e = m.reset_pins();
            for i in 0..self.signals.len() {
                let s = self.signals[i];
                let (ev, av, ax) = (
                    s.get(&self.layout, &e),
                    s.get(&self.layout, &rp),
                    s.get(&self.layout, &rxz),
                );
                if ev != av || ax != 0 {
                    self.divergence_count += 1;
                    if self.divergences.len() < self.opts.max_records {
                        self.divergences.push(Divergence {
                            cycle: 0,
                            frame: 0,
                            slot: 0,
                            signal: format!("{} (in reset)", s.name(&self.layout)),
                            expected: json!(ev),
                            actual: if ax != 0 { json!("x") } else { json!(av) },
                            branch: s.branch().map(|b| self.branch_names[b].clone()),
                            channel: None,
                            actual_channel: None,
                            context: vec![format!(
                                "reset: {} | expected {}",
                                fmt_pins(&rp),
                                fmt_pins(&e)
                            )],
                        });
                    }
                }
            }
        }
        let rp = self.view(&rp);
        for b in 0..self.layout.branches {
            let st = &mut self.br[b];
            st.mux_from_reset = true;
            st.low = rp.cs_n >> b & 1 == 0;
        }
    }

    #[inline]
    fn run_cycle(&mut self, p: &Pins, xz: &Pins, miso: u64, miso_xz: u64) {
        let c = self.c;
        let mut expected = None;
        if let Some(m) = &mut self.model {
            // tready and mode_sel are inputs: the model takes them from the pins
            m.set_tready(p.axis_tready);
            m.set_mode_sel(p.mode_sel);
            if let Some(j) = &mut self.link_join {
                if let Some((tx, joined)) = j.cycle(c, p, m.pins()) {
                    m.set_tx(tx);
                    self.link_join = None;
                    self.link_joined = Some(joined);
                }
            }
            let e = *m.pins();
            if !same(&e, p) || !same(xz, &NO_XZ) || self.div_active || self.mode_diverging {
                self.compare(c, &e, p, xz);
                self.compare_mode(c, &e, p);
            }
            expected = Some(e);
            self.model.as_mut().unwrap().step(miso);
        }
        if !self.ctx_open.is_empty() {
            self.add_context(c, p, expected);
        }
        self.hist.push((c, *p, expected));

        if !same(xz, &self.prev_xz) {
            self.xz_changes(c, p, xz);
        }
        // before the samples of this cycle: a slice that begins in it opens
        if let Some(l) = &mut self.line {
            l.cycle(c, p, &mut self.inv);
        }
        self.inv.mode_cycle(c, p.mode_sel, p.mode);
        if !same(p, &self.prev) || p.sample_valid || !same(xz, &NO_XZ) {
            self.edges(c, p, xz);
        }
        if self.layout.link {
            self.link_rules(c, p);
        }
        if c + 1 >= self.next_frame_at && self.held.is_empty() {
            self.inv.close_frames(c + 1);
            while self.next_frame_at <= c + 1 {
                self.next_frame_at += self.grid.frame_cycles;
            }
        }
        self.prev = *p;
        self.prev_xz = *xz;
        self.prev_miso = miso;
        self.prev_miso_xz = miso_xz;
        self.c = c + 1;
    }

    /// AXI4-Stream's rule, without the model: once `tvalid` is high it
    /// stays high, with `tdata` and `tlast` unchanged, until the edge where
    /// `tready` is high too; and the link's FIFO never overflows.
    fn link_rules(&mut self, c: u64, p: &Pins) {
        let q = self.prev;
        if c > 0 && q.axis_tvalid && !q.axis_tready {
            let held =
                p.axis_tvalid && p.axis_tdata == q.axis_tdata && p.axis_tlast == q.axis_tlast;
            if !held {
                let what = if !p.axis_tvalid {
                    "tvalid fell"
                } else if p.axis_tdata != q.axis_tdata {
                    "tdata changed"
                } else {
                    "tlast changed"
                };
                self.inv.record(
                    Violation::new(Rule::AxisStable, c)
                        .signal("m_axis_tvalid/tdata/tlast".to_string())
                        .expected(json!(format!("tvalid=1 tdata={:#04x} tlast={}", q.axis_tdata, q.axis_tlast as u8)))
                        .actual(json!(format!("tvalid={} tdata={:#04x} tlast={}", p.axis_tvalid as u8, p.axis_tdata, p.axis_tlast as u8)))
                        .detail(format!("{what} while the beat waited for tready (AXI4-Stream: a master holds tvalid, tdata and tlast until the handshake)")),
                );
            }
        }
        if p.link_overflow && !q.link_overflow {
            self.inv.record(
                Violation::new(Rule::LinkOverflow, c)
                    .signal("link_overflow".to_string())
                    .expected(json!(0))
                    .actual(json!(1))
                    .detail("the link's FIFO overflowed: a token was dropped (its depth is the schedule's worst-case backlog under the slave's guarantee)"),
            );
        }
    }

    fn compare(&mut self, c: u64, e: &Pins, p: &Pins, xz: &Pins) {
        if crate::switch::disabled("model") {
            return;
        }
        let mut any = false;
        // the link's pins wait for the line to show where the run is
        let joining = self.link_join.is_some();
        for i in 0..self.signals.len() {
            let s = self.signals[i];
            let (ev, av, ax) = (
                s.get(&self.layout, e),
                s.get(&self.layout, p),
                s.get(&self.layout, xz),
            );
            let bad = (ev != av || ax != 0) && !(joining && s.role().is_none());
            if bad {
                any = true;
                if !self.diverging[i] && self.divergences.len() < self.opts.max_records {
                    let (cycle, frame, slot) = self.inv.place(c);
                    let m = self.model.as_ref().unwrap();
                    let ch = match s.branch() {
                        Some(b) => Some(m.branch_channel(b)),
                        None if e.sample_valid => Some(e.sample_channel),
                        None => Some(p.sample_channel),
                    };
                    let inv = &self.inv;
                    let mut context: Vec<String> = self
                        .hist
                        .iter()
                        .map(|(hc, hp, he)| ctx_line(inv.place(*hc).0, hp, he.as_ref()))
                        .collect();
                    context.push(format!("{} <- diverges", ctx_line(cycle, p, Some(e))));
                    if let Signal::Mosi(b) = s {
                        context.insert(0, self.command_context(b, m, ev));
                    }
                    if s == Signal::LinkTx {
                        context.extend(m.link_context());
                    }
                    self.divergences.push(Divergence {
                        cycle,
                        frame,
                        slot,
                        signal: s.name(&self.layout),
                        expected: json!(ev),
                        actual: if ax != 0 {
                            json!(format!("{av:#b} with x/z mask {ax:#b}"))
                        } else {
                            json!(av)
                        },
                        branch: s.branch().map(|b| self.branch_names[b].clone()),
                        // a mux pin: the channel each select addresses
                        channel: match self.selected_channel(s, e) {
                            Some(c) => Some(c),
                            None => ch.and_then(|c| self.names.get(c as usize).cloned()),
                        },
                        actual_channel: self.selected_channel(s, p),
                        context,
                    });
                    self.ctx_open
                        .push((self.divergences.len() - 1, CONTEXT_AFTER));
                }
            }
            self.diverging[i] = bad;
        }
        if any {
            self.divergence_count += 1;
        }
        self.div_active = any;
    }

    /// For a divergence on a mux pin: the channel the pins `p` select
    /// (its name), or why none is, in words.
    fn selected_channel(&self, s: Signal, p: &Pins) -> Option<String> {
        let b = match s {
            Signal::MuxSel(b) | Signal::MuxEn(b) => b,
            _ => return None,
        };
        Some(match self.layout.selected(p, b) {
            Ok(c) => self.names.get(c as usize).cloned().unwrap_or_default(),
            Err(why) => why,
        })
    }

    /// The `mode` output against the model's (not a [`Signal`]: a mix
    /// with modes only), once per run of cycles it differs in.
    fn compare_mode(&mut self, c: u64, e: &Pins, p: &Pins) {
        let bad = e.mode != p.mode;
        if bad && !self.mode_diverging && !crate::switch::disabled("model") {
            self.divergence_count += 1;
            if self.divergences.len() < self.opts.max_records {
                let (cycle, frame, slot) = self.inv.place(c);
                self.divergences.push(Divergence {
                    cycle,
                    frame,
                    slot,
                    signal: "mode".into(),
                    expected: json!(e.mode),
                    actual: json!(p.mode),
                    branch: None,
                    channel: None,
                    actual_channel: None,
                    context: vec![format!(
                        "mode_sel={} mode={} | expected mode={}",
                        p.mode_sel, p.mode, e.mode
                    )],
                });
            }
        }
        self.mode_diverging = bad;
    }

    fn add_context(&mut self, c: u64, p: &Pins, e: Option<Pins>) {
        // The cycle that opened the context is already in it.
        let c = self.inv.place(c).0;
        let line = ctx_line(c, p, e.as_ref());
        let divs = &mut self.divergences;
        self.ctx_open.retain_mut(|(i, left)| {
            if divs[*i].cycle == c {
                return true;
            }
            divs[*i].context.push(line.clone());
            *left -= 1;
            *left > 0
        });
    }

    fn xz_changes(&mut self, c: u64, p: &Pins, xz: &Pins) {
        for i in 0..self.signals.len() {
            let s = self.signals[i];
            let now = s.get(&self.layout, xz);
            let was = s.get(&self.layout, &self.prev_xz);
            let matters =
                !matches!(s, Signal::SampleChannel | Signal::SampleValue) || p.sample_valid;
            if now != 0 && was == 0 && matters {
                self.inv.record(
                    Violation::new(Rule::XOrZ, c)
                        .signal(s.name(&self.layout))
                        .actual(json!("x"))
                        .detail(format!("{} is x/z (mask {now:#b})", s.name(&self.layout))),
                );
            }
        }
    }

    /// The CS view of the pins: CNV lanes inverted, so that "low" is
    /// "converting" and a fall of the serial clock is a SCK rising edge.
    #[inline]
    fn view(&self, p: &Pins) -> Pins {
        Pins {
            cs_n: p.cs_n ^ self.flip,
            sclk: p.sclk ^ self.flip,
            ..*p
        }
    }

    /// Reads serial bit `idx` of branch `b`'s conversion from MISO as it was
    /// in the cycle before the edge at `c`.
    fn capture(&mut self, b: usize, c: u64, idx: u32) {
        if self.prev_miso_xz >> b & 1 != 0 {
            self.br[b].word_bad = true;
            self.inv.record(
                Violation::new(Rule::XOrZ, c)
                    .signal(Signal::Miso(b).name(&self.layout))
                    .actual(json!("x"))
                    .detail(format!(
                        "MISO is x/z when the serial clock reads it ({c}, bit {idx})"
                    )),
            );
        }
        let st = &mut self.br[b];
        st.word = (st.word << 1) | (self.prev_miso >> b & 1) as u128;
    }

    fn edges(&mut self, c: u64, p: &Pins, xz: &Pins) {
        let mut prev = self.view(&self.prev);
        self.low.last_view(&mut prev);
        let mut v = self.view(p);
        (self.low).view(c, &self.prev, p, &mut v, &self.layout, &mut self.inv);
        let p = &v;
        let dcs = prev.cs_n ^ p.cs_n;
        let dsclk = prev.sclk ^ p.sclk;
        for b in 0..self.layout.branches {
            let bit = 1u16 << b;
            let (sel, en) = (self.layout.sel(p, b), self.layout.en(p, b));
            if sel != self.layout.sel(&prev, b) || en != self.layout.en(&prev, b) {
                let st = &mut self.br[b];
                st.mux_since = c;
                st.mux_from_reset = false;
                st.mux_unknown = false;
                let multi = en.count_ones() > 1;
                if multi && !st.en_multi {
                    self.inv.record(
                        Violation::new(Rule::MuxExclusive, c)
                            .signal(Signal::MuxEn(b).name(&self.layout))
                            .expected(json!("at most one bit set"))
                            .actual(json!(en))
                            .detail(format!(
                                "branch {}: {} mux devices enabled at once",
                                self.branch_names[b],
                                en.count_ones()
                            )),
                    );
                }
                self.br[b].en_multi = multi;
            }
            let low_now = p.cs_n & bit == 0;
            if dcs & bit != 0 && low_now {
                self.cs_fall(b, c, p, xz);
            }
            if dsclk & bit != 0 {
                if self.br[b].low {
                    if p.sclk & bit == 0 {
                        self.sclk_fall(b, c);
                    } else {
                        self.sclk_rise(b, c);
                    }
                    // the part latches DIN at its own clock's rising edge
                    // (a fall in the CS view for a CNV part)
                    let real_rise = (p.sclk & bit != 0) != self.limits[b].cnv;
                    if real_rise && self.cmds[b].is_some() {
                        self.latch(b, self.layout.mosi(p, b));
                    }
                } else {
                    self.inv.record(
                        Violation::new(Rule::SclkIdle, c)
                            .signal(Signal::Sclk(b).name(&self.layout))
                            .actual(json!(p.sclk >> b & 1))
                            .detail("SCLK toggles while CS is high"),
                    );
                }
            }
            if dcs & bit != 0 && !low_now {
                self.cs_rise(b, c, p);
            }
        }
        if p.sample_valid {
            if xz.sample_channel != 0 || xz.sample_value != 0 || xz.sample_valid {
                // already flagged as x/z; the value cannot be compared
                self.inv.emitted(c, p.sample_channel, p.sample_value);
            } else {
                self.inv.emitted(c, p.sample_channel, p.sample_value);
            }
            if let Some(l) = &mut self.line {
                l.sample(c, p.sample_channel, p.sample_value);
            }
        }
    }

    fn cs_fall(&mut self, b: usize, c: u64, p: &Pins, xz: &Pins) {
        let lim = self.limits[b].clone();
        let name = |s: Signal, l: &Layout| Some(s.name(l));
        if let Some(r) = self.br[b].cs_rise {
            if c - r < lim.quiet_min {
                self.inv.record(
                    Violation::new(Rule::CsQuiet, c)
                        .signal(name(Signal::CsN(b), &self.layout))
                        .expected(json!(lim.quiet_min))
                        .actual(json!(c - r))
                        .detail(format!(
                            "CS high for {} cycles between conversions, the ADC needs {} (t_quiet)",
                            c - r,
                            lim.quiet_min
                        )),
                );
            }
        }
        if p.sclk >> b & 1 == 0 {
            self.inv.record(
                Violation::new(Rule::SclkIdle, c)
                    .signal(name(Signal::Sclk(b), &self.layout))
                    .expected(json!(1))
                    .actual(json!(0))
                    .detail(if self.limits[b].cnv {
                        "SCK is high when CNV rises (chain mode needs SCK low)"
                    } else {
                        "SCLK is low when CS falls (CPOL=1 idles high)"
                    }),
            );
        }
        if self.cmds[b].is_some() {
            self.cs_fall_commanded(b, c, p, xz);
            return;
        }
        let sel_x = self.layout.sel(xz, b) != 0 || self.layout.en(xz, b) != 0;
        let ch = match self.layout.selected(p, b) {
            Ok(ch) if !sel_x => Some(ch),
            Ok(_) => None,
            Err(e) => {
                self.inv.record(
                    Violation::new(Rule::MuxSelect, c)
                        .signal(name(Signal::MuxEn(b), &self.layout))
                        .actual(json!(self.layout.en(p, b)))
                        .detail(format!("at the sampling instant: {e}")),
                );
                None
            }
        };
        self.mux_settle(b, c, ch);
        let st = &mut self.br[b];
        st.low = true;
        st.t = c;
        st.ch = ch;
        st.falls = 0;
        st.rises = 0;
        st.word = 0;
        st.word_bad = false;
        if let Some(ch) = ch {
            match self.groups.get(ch as usize) {
                // Every chained part samples at this instant.
                Some(g) => {
                    for m in g.clone().into_iter().flatten() {
                        self.inv.instant(c, b, m as u16);
                    }
                }
                None => self.instant(c, b, ch),
            }
        }
    }

    /// A sampling instant, or held back behind a command word still being
    /// clocked in (`held`).
    fn instant(&mut self, t: u64, b: usize, ch: u16) {
        if self.held.is_empty() {
            self.inv.instant(t, b, ch);
        } else {
            self.held.push_back((t, b, Some(ch), false));
        }
    }

    /// A conversion of a commanded branch begins at `c`: its channel is the
    /// one its command word selected (docs/timing.md, "Command words"), not
    /// the mux pins' (it has none); a part that converts in the same read
    /// holds the instant until the word is in.
    fn cs_fall_commanded(&mut self, b: usize, c: u64, p: &Pins, xz: &Pins) {
        let pin = self.front_pin(b, c, p, xz);
        let sel = self.cmds[b].as_mut().and_then(|r| r.start(c, pin));
        let st = &mut self.br[b];
        st.low = true;
        st.t = c;
        st.falls = 0;
        st.rises = 0;
        st.word = 0;
        st.word_bad = false;
        st.ch = None;
        st.prepared = false;
        st.word_at = None;
        match sel {
            None => self.held.push_back((c, b, None, true)),
            Some(sel) => self.selected(b, c, sel),
        }
    }

    /// A fronted branch's front mux input at its sampling instant `c`
    /// (device * 8 + select), held to the mux rules of an external-mux
    /// branch (one device enabled, settled); `None` on a branch without one.
    fn front_pin(&mut self, b: usize, c: u64, p: &Pins, xz: &Pins) -> Option<u32> {
        if !self.cmds[b].as_ref().is_some_and(CommandRead::fronted) {
            return None;
        }
        if self.layout.sel(xz, b) != 0 || self.layout.en(xz, b) != 0 {
            self.mux_settle(b, c, None);
            return None;
        }
        let en = self.layout.en(p, b);
        if en.count_ones() != 1 {
            self.inv.record(
                Violation::new(Rule::MuxSelect, c)
                    .signal(Signal::MuxEn(b).name(&self.layout))
                    .actual(json!(en))
                    .detail(
                        "at the sampling instant: not one front mux device enabled".to_string(),
                    ),
            );
            return None;
        }
        let pin = en.trailing_zeros() * 8 + self.layout.sel(p, b);
        self.mux_settle(b, c, None);
        Some(pin)
    }

    /// Branch `b`'s conversion at `t` converts what `sel` says.
    fn selected(&mut self, b: usize, t: u64, sel: Selected) {
        match sel {
            Selected::Prepared => self.br[b].prepared = true,
            Selected::Unknown => self.inv.blind(t),
            Selected::Word { sent_at, channel } => {
                let st = &mut self.br[b];
                st.ch = channel;
                st.word_at = Some(sent_at);
                if let Some(ch) = channel {
                    self.instant(t, b, ch);
                }
            }
        }
    }

    /// DIN bit `v` of branch `b` latched; a whole word of a part that
    /// converts in the same read settles its held instant.
    fn latch(&mut self, b: usize, v: bool) {
        if let Some(sel) = self.cmds[b].as_mut().and_then(|r| r.latch(v)) {
            self.resolve(b, sel);
        }
    }

    /// Branch `b`'s held instant converts what `sel` says: the instants
    /// held behind it go on in time order.
    fn resolve(&mut self, b: usize, sel: Selected) {
        let t = self.br[b].t;
        if let Some(h) = self.held.iter_mut().find(|h| h.3 && h.1 == b) {
            h.3 = false;
            match sel {
                Selected::Word { sent_at, channel } => {
                    h.2 = channel;
                    self.br[b].ch = channel;
                    self.br[b].word_at = Some(sent_at);
                }
                _ => self.inv.blind(t),
            }
        }
        self.flush_held();
    }

    fn flush_held(&mut self) {
        while let Some(&(t, b, ch, false)) = self.held.front() {
            self.held.pop_front();
            if let Some(ch) = ch {
                self.inv.instant(t, b, ch);
            }
        }
    }

    /// A commanded branch's read ended at `c`: its word, if malformed, is
    /// `command-word`; a pipelined part queues what it selects.
    fn end_word(&mut self, b: usize, c: u64) {
        let Some(r) = self.cmds[b].as_mut() else {
            return;
        };
        let bad = r.bad_word();
        let sel = r.end();
        if let Some(w) = bad {
            let t = self.inv.place(w.sent_at).0;
            self.inv.record(
                Violation::new(Rule::CommandWord, c)
                    .signal(Signal::Mosi(b).name(&self.layout))
                    .actual(json!(w.bits))
                    .detail(format!(
                        "branch {}: the command word {} of the conversion at cycle {t}: {}",
                        self.branch_names[b], w.bits, w.why
                    )),
            );
        }
        if let Some(sel) = sel {
            self.resolve(b, sel);
        }
    }

    /// The command word the model sends on branch `b` now, for the report
    /// of a wrong `adc_mosi` bit (`want`: the model's bit).
    fn command_context(&self, b: usize, m: &CycleModel, want: u64) -> String {
        let name = &self.branch_names[b];
        let Some((sel, k, t)) = m.command_bit(b) else {
            return format!("branch {name}: no command word is being sent here (adc_mosi idles low between words), expected {want}");
        };
        let bits: String = (m.command_word(b).iter())
            .map(|&v| if v { '1' } else { '0' })
            .collect();
        let ch = self.names.get(sel).map_or("?", String::as_str);
        let (at, _, slot) = self.inv.place(t);
        format!(
            "branch {name}: bit {k} (0 = the first) of the command word {bits} of the conversion at cycle {at} (slot {slot}), which selects {ch} (input {}); expected {want}",
            self.inputs[sel]
        )
    }

    /// The mux must have settled for `settle_min` cycles at the sampling
    /// instant `c` of branch `b` (channel `ch`, if known).
    fn mux_settle(&mut self, b: usize, c: u64, ch: Option<u16>) {
        let settle_min = self.limits[b].settle_min;
        let st = &self.br[b];
        if st.mux_from_reset && c + st.reset_held < settle_min {
            // The first conversion after reset: the mux value has settled
            // through the last `reset_held` reset cycles (those since it
            // last moved; the first reset cycle seen counts as a move, as
            // the pins' values before the first reset edge are not the
            // gateware's) and cycles 0..c.  A short reset is no excuse: the
            // gateware must be correct for any reset of one cycle or more.
            let held = st.reset_held;
            self.inv.record(
                Violation::new(Rule::MuxSettle, c)
                    .signal(Signal::MuxSel(b).name(&self.layout))
                    .expected(json!(settle_min))
                    .actual(json!(c + held))
                    .channel(ch.and_then(|ch| self.names.get(ch as usize).cloned()))
                    .detail(format!("first conversion after reset: the mux value held through {held} reset cycles and {c} cycles after reset; settling needs {}", settle_min)),
            );
        } else if !st.mux_from_reset && !st.mux_unknown && c - st.mux_since < settle_min {
            let since = st.mux_since;
            self.inv.record(
                Violation::new(Rule::MuxSettle, c)
                    .signal(Signal::MuxSel(b).name(&self.layout))
                    .expected(json!(settle_min))
                    .actual(json!(c - since))
                    .channel(ch.and_then(|ch| self.names.get(ch as usize).cloned()))
                    .detail(format!("mux switched in cycle {}, {} cycles before the sampling instant; settling needs {}", self.inv.place(since).0, c - since, settle_min)),
            );
        }
    }

    fn sclk_fall(&mut self, b: usize, c: u64) {
        let lim = self.limits[b].clone();
        self.br[b].falls += 1;
        let falls = self.br[b].falls;
        if lim.cnv && falls <= lim.sclks {
            // SCK rising edge `falls`: serial bit falls - 1.
            self.capture(b, c, falls - 1);
        }
        let st = &mut self.br[b];
        let mut v: Vec<(Rule, Option<Value>, Option<Value>, String)> = Vec::new();
        if st.falls == 1 {
            if c - st.t < lim.setup_min {
                v.push((
                    Rule::CsSetup,
                    Some(json!(lim.setup_min)),
                    Some(json!(c - st.t)),
                    format!(
                        "first SCLK falling edge {} cycles after CS fell, needs {} (t2)",
                        c - st.t,
                        lim.setup_min
                    ),
                ));
            }
        } else {
            let period = c - st.last_fall;
            let low = st.last_rise.saturating_sub(st.last_fall);
            let high = c - st.last_rise;
            if period * lim.sclk_max_hz < self.clock_hz {
                v.push((
                    Rule::SclkFrequency,
                    Some(json!(lim.sclk_max_hz)),
                    Some(json!(self.clock_hz / period.max(1))),
                    format!(
                        "SCLK period of {period} cycles is faster than {} Hz",
                        lim.sclk_max_hz
                    ),
                ));
            }
            if period * lim.sclk_min_hz > self.clock_hz {
                v.push((
                    Rule::SclkFrequency,
                    Some(json!(lim.sclk_min_hz)),
                    Some(json!(self.clock_hz / period.max(1))),
                    format!(
                        "SCLK period of {period} cycles is slower than {} Hz",
                        lim.sclk_min_hz
                    ),
                ));
            }
            if st.last_rise < st.last_fall
                || low * 100 < period * lim.duty_min_pct
                || high * 100 < period * lim.duty_min_pct
            {
                v.push((
                    Rule::SclkDuty,
                    Some(json!(format!(">= {} %", lim.duty_min_pct))),
                    Some(json!(format!("low {low} / high {high} cycles"))),
                    format!("SCLK period {period}: low {low}, high {high} cycles"),
                ));
            }
        }
        st.last_fall = c;
        let signal = Signal::Sclk(b).name(&self.layout);
        for (rule, e, a, d) in v {
            self.inv.record(
                Violation::new(rule, c)
                    .signal(signal.clone())
                    .expected(e)
                    .actual(a)
                    .detail(d),
            );
        }
    }

    fn sclk_rise(&mut self, b: usize, c: u64) {
        let st = &mut self.br[b];
        st.rises += 1;
        st.last_rise = c;
        let idx = st.rises;
        if !self.limits[b].cnv && idx < self.limits[b].sclks {
            self.capture(b, c, idx);
        }
    }

    fn cs_rise(&mut self, b: usize, c: u64, p: &Pins) {
        let st = self.br[b].clone();
        self.br[b].low = false;
        self.br[b].cs_rise = Some(c);
        if c == 0 && st.falls == 0 {
            return; // CS low through reset: no conversion to account for
        }
        let chname = st.ch.and_then(|ch| self.names.get(ch as usize).cloned());
        let lim = self.limits[b].clone();
        let n = lim.sclks;
        if st.falls != n || st.rises != n {
            self.inv.record(
                Violation::new(Rule::SclkCount, c)
                    .signal(Signal::Sclk(b).name(&self.layout))
                    .expected(json!(n))
                    .actual(json!(st.falls))
                    .channel(chname.clone())
                    .detail(format!("{} SCLK falling and {} rising edges in the conversion window from cycle {}, expected {n}", st.falls, st.rises, self.inv.place(st.t).0)),
            );
        }
        if p.sclk >> b & 1 == 0 {
            self.inv.record(
                Violation::new(Rule::SclkIdle, c)
                    .signal(Signal::Sclk(b).name(&self.layout))
                    .expected(json!(1))
                    .actual(json!(0))
                    .channel(chname)
                    .detail(if lim.cnv {
                        "SCK is high when CNV falls"
                    } else {
                        "SCLK is low when CS rises"
                    }),
            );
        }
        let st = if self.cmds[b].is_some() {
            self.end_word(b, c);
            self.br[b].clone()
        } else {
            st
        };
        if st.prepared {
            return; // no word of ours selected it: not a sample
        }
        // Bit j of the serial stream sits at sclks-1-j of `word` (CS parts
        // never read bit 0, a leading zero).
        let mask = (1u128 << lim.bits) - 1;
        let word = |w: u32| {
            let end = w * lim.word_sclks + lim.leading + lim.bits;
            ((st.word >> (n - end)) & mask) as u16
        };
        match st.ch {
            Some(ch) if (ch as usize) < self.groups.len() => {
                for (m, g) in self.groups[ch as usize].clone().into_iter().enumerate() {
                    if let Some(g) = g {
                        let code = (!st.word_bad).then_some(word(m as u32));
                        let g = Some(g as u16);
                        self.inv.completion_by_word(c, b, g, code, st.t, st.word_at);
                    }
                }
            }
            _ => {
                let code = (!st.word_bad).then_some(word(0));
                self.inv
                    .completion_by_word(c, b, st.ch, code, st.t, st.word_at);
            }
        }
    }

    /// Ends the check and builds the report.
    pub fn finish(mut self, source: &str) -> Verdict {
        let cycles = self.c - self.origin;
        if self.phase == Phase::PreReset || (self.phase == Phase::Reset && cycles == 0) {
            self.inv.record(
                Violation::new(Rule::NoCycles, 0)
                    .signal(Role::Reset.name().to_string())
                    .detail("no cycle after a released reset was seen (rst must be high, then low, at rising clock edges)"),
            );
        }
        if let Some(l) = &mut self.line {
            l.finish(self.c, &mut self.inv);
        }
        // a word never finished: its instant counts for no channel
        self.held.iter_mut().for_each(|h| h.3 = false);
        self.flush_held();
        let link_join = self.link_join_report();
        let (frames, channels) = self.inv.finish(self.c);
        let samples = self.inv.emitted_count();
        let model = self.model.is_some();
        let mut r = self
            .inv
            .report(source, &self.mix_name, cycles, frames, channels, samples);
        r.divergence_count = self.divergence_count;
        r.divergences = self.divergences;
        r.model_compared = model;
        r.link_join = link_join;
        r.ok = r.ok && r.divergence_count == 0;
        r
    }
}

impl Checker {
    /// Where a check that joined mid-stream joined the link, in capture cycles.
    fn link_join_report(&self) -> Option<crate::model::LinkJoin> {
        use crate::model::LinkJoin as Report;
        let place = |c: u64| self.inv.place(c).0;
        // not joined: the line was not judged in any of the capture's cycles
        let unjudged = |by: &str, bytes: u64| Report {
            by: by.into(),
            judged: false,
            checked_from_cycle: None,
            header_cycle: None,
            frame_counter: None,
            slice: None,
            skipped_bytes: bytes,
            unjudged_cycles: place(self.c),
        };
        if self.model.is_none() && self.origin > 0 {
            let line = self.line.as_ref()?;
            let Some((c, frame, slice, bytes, header)) = line.joined else {
                return Some(unjudged("decoder", line.bytes_read()));
            };
            return Some(Report {
                by: "decoder".into(),
                judged: true,
                checked_from_cycle: Some(place(c)),
                header_cycle: header.map(place),
                frame_counter: Some(frame),
                slice: Some(slice),
                skipped_bytes: bytes,
                unjudged_cycles: place(header.unwrap_or(c)),
            });
        }
        if let Some(j) = &self.link_join {
            return Some(unjudged("model", j.bytes_read()));
        }
        let j = self.link_joined?;
        Some(Report {
            by: "model".into(),
            judged: true,
            checked_from_cycle: Some(place(j.cycle)),
            header_cycle: Some(place(j.header_cycle)),
            frame_counter: Some(j.frame),
            slice: Some(j.slice),
            skipped_bytes: j.skipped_bytes,
            unjudged_cycles: place(j.header_cycle),
        })
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

fn fmt_pins(p: &Pins) -> String {
    let mut t = format!(
        "cs_n={:b} sclk={:b} mux_sel={:#x} mux_en={:#x} valid={} ch={} value={:#06x}",
        p.cs_n, p.sclk, p.mux_sel, p.mux_en, p.sample_valid as u8, p.sample_channel, p.sample_value
    );
    if p.axis_tvalid || p.axis_tready || p.axis_tdata != 0 {
        t.push_str(&format!(
            " tdata={:#04x} tvalid={} tlast={} tready={}",
            p.axis_tdata, p.axis_tvalid as u8, p.axis_tlast as u8, p.axis_tready as u8
        ));
    }
    // the link's pins (all zero without a link: nothing added)
    if p.link_tx || p.link_overflow {
        t.push_str(&format!(
            " tx={} overflow={}",
            p.link_tx as u8, p.link_overflow as u8
        ));
    }
    t
}

fn ctx_line(c: u64, p: &Pins, e: Option<&Pins>) -> String {
    match e {
        Some(e) if e != p => format!("cycle {c}: {} | expected {}", fmt_pins(p), fmt_pins(e)),
        _ => format!("cycle {c}: {}", fmt_pins(p)),
    }
}
