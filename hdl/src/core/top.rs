//! Core: fixed-maximum ports, per-mix children, generated glue.

use crate::rhdl::*;

use super::glue::{core_glue, route_miso, LaneForm, SeqWires};
use super::{BranchUnit, CmdUnit, CnvPulse, HoldOff, Merger, ModeGen, SpiSeq, TimingGen};
use crate::plan::Plan;
use crate::widths::*;

#[derive(LogicBlock)]
pub struct Core {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub adc_miso: Signal<In, Bits<MAX_BRANCHES>>,
    pub adc_cs_n: Signal<Out, Bits<MAX_BRANCHES>>,
    pub adc_sclk: Signal<Out, Bits<MAX_BRANCHES>>,
    /// `adc_mosi`, lane `i` = the `i`-th branch whose converter takes a
    /// command word: one signal when the mix has such a branch, none
    /// otherwise (so the core of any other mix has no such port).
    pub adc_mosi: Vec<Signal<Out, Bits<MAX_BRANCHES>>>,
    pub mux_sel: Signal<Out, Bits<{ 3 * MAX_BRANCHES }>>,
    pub mux_en: Signal<Out, Bits<EN_TOTAL>>,
    pub sample_valid: Signal<Out, Bit>,
    pub sample_channel: Signal<Out, Bits<CH_BITS>>,
    pub sample_value: Signal<Out, Bits<VALUE_BITS>>,
    /// The timebase's `start1` (the next cycle starts a slot), for the link.
    pub slot_tick: Signal<Out, Bit>,
    /// A mix with modes: `mode_sel` (pin select) and `mode`, one each, and
    /// the mode block; none otherwise, so a mix without modes has the
    /// core it always had.
    pub mode_sel: Vec<Signal<In, Bits<MODE_BITS>>>,
    pub mode: Vec<Signal<Out, Bits<MODE_BITS>>>,
    pub timing: TimingGen,
    pub seqs: Vec<SpiSeq>,
    /// The CNV pulse of each sequencer whose part is read with CNV low.
    pub pulses: Vec<CnvPulse>,
    /// The pulse of each sequencer, if it has one.
    _pulse_of: Vec<Option<usize>>,
    /// The hold-off of each sequencer whose transactions start after the
    /// slot tick (none in a mix without one).
    pub holds: Vec<HoldOff>,
    _hold_of: Vec<Option<usize>>,
    pub branches: Vec<BranchUnit>,
    /// One command unit per branch with a command word, in branch order.
    pub cmds: Vec<CmdUnit>,
    pub merge: Merger,
    /// The command unit of each branch, if it has one.
    _cmd_of: Vec<Option<usize>>,
    pub modes: Vec<ModeGen>,
    /// Devices per branch (the glue's per-mix parameters besides the count).
    _devices: Vec<usize>,
    /// Sequencer of each branch.
    _seq_of: Vec<usize>,
    /// The merger's queue form: each lane's MISO sources (`Plan::queue`).
    _queue: Option<Vec<Vec<usize>>>,
    /// The value last written to `mux_en.next` (simulation only).
    _mux_en: u128,
    /// The value last written to `mux_sel.next` (simulation only).
    _mux_sel: u64,
}

impl Core {
    pub fn new(plan: &Plan) -> Core {
        let step = super::merger::stepped_reader(plan);
        let mut pulse_of = vec![None; plan.seqs.len()];
        let mut pulses = vec![];
        for (i, q) in plan.seqs.iter().enumerate().filter(|(_, q)| q.pulsed()) {
            pulse_of[i] = Some(pulses.len());
            pulses.push(CnvPulse::new(q.pin_cycles));
        }
        let mut hold_of = vec![None; plan.seqs.len()];
        let mut holds = vec![];
        for (i, q) in plan.seqs.iter().enumerate().filter(|(_, q)| q.holdoff > 0) {
            hold_of[i] = Some(holds.len());
            holds.push(HoldOff::new(q.holdoff, !q.cnv));
        }
        let mut cmd_of = vec![None; plan.branches.len()];
        let mut cmds = vec![];
        for (b, r) in plan.branches.iter().enumerate() {
            if let Some(c) = &r.command {
                cmd_of[b] = Some(cmds.len());
                let setup = plan.seqs[r.seq].setup_cycles;
                let held = !plan.seqs[r.seq].pulsed();
                let w = super::command::CmdWiring {
                    cnv: r.cnv,
                    held,
                    setup,
                    branch: b,
                    front: r.front.clone(),
                };
                cmds.push(CmdUnit::new(c, w));
            }
        }
        Core {
            clock: Default::default(),
            rst: Default::default(),
            adc_miso: Default::default(),
            adc_cs_n: Default::default(),
            adc_sclk: Default::default(),
            adc_mosi: match cmds.is_empty() {
                true => vec![],
                false => vec![Default::default()],
            },
            mux_sel: Default::default(),
            mux_en: Default::default(),
            sample_valid: Default::default(),
            sample_channel: Default::default(),
            sample_value: Default::default(),
            slot_tick: Default::default(),
            mode_sel: (plan.modes.iter().filter(|m| m.pin))
                .map(|_| Default::default())
                .collect(),
            mode: plan.modes.iter().map(|_| Default::default()).collect(),
            timing: TimingGen::new(plan),
            seqs: plan.seqs.iter().map(SpiSeq::new).collect(),
            pulses,
            _pulse_of: pulse_of,
            holds,
            _hold_of: hold_of,
            branches: plan
                .branches
                .iter()
                .map(|b| BranchUnit::new(b, plan.queue.is_some(), step))
                .collect(),
            cmds,
            _cmd_of: cmd_of,
            merge: Merger::new(
                plan.branches.len(),
                plan.queue.is_some(),
                step,
                plan.lane_ch.clone(),
            ),
            modes: (plan.modes.iter())
                .map(|m| ModeGen::new(m, plan.branches.len()))
                .collect(),
            _devices: plan.branches.iter().map(|b| b.devices).collect(),
            _seq_of: plan.branches.iter().map(|b| b.seq).collect(),
            _queue: plan.queue.clone(),
            _mux_en: 0,
            _mux_sel: 0,
        }
    }
}

/// Drive one clock signal to `level` now (as its own `update_all` would).
#[inline(always)]
fn drive(sig: &mut Signal<In, Clock>, level: Clock) {
    sig.next = level;
    sig.update_all();
}

impl Core {
    /// `mux_en` as a number (the value of the `mux_en` signal).
    pub fn mux_en_u128(&self) -> u128 {
        self._mux_en
    }

    /// `mux_sel` as a number (the value of the `mux_sel` signal).
    pub fn mux_sel_u64(&self) -> u64 {
        self._mux_sel
    }

    /// Put `level` on every clock signal of the hierarchy at once: the
    /// zero-skew clock net of the emitted Verilog.
    ///
    /// rust-hdl's own propagation moves the clock one hierarchy level per
    /// evaluation pass (`Core.clock` -> `timing.clock` -> `timing.cnt.clock`),
    /// which costs three passes per clock level before any flip-flop can
    /// react. After this call the next pass sees the edge at every flip-flop
    /// and ROM together, and the per-pass copies that the blocks' own
    /// `update` (`clock!`/`dff_setup!` wiring) make are no-ops.  Only the
    /// clock moves here; data still propagates through rust-hdl's passes.
    pub fn drive_clock(&mut self, level: bool) {
        let k = Clock::from(level);
        drive(&mut self.clock, k);
        let t = &mut self.timing;
        drive(&mut t.clock, k);
        drive(&mut t.cnt.clock, k);
        drive(&mut t.st.clock, k);
        drive(&mut t.st2.clock, k);
        drive(&mut t.st0.clock, k);
        drive(&mut t.slot.clock, k);
        drive(&mut t.sl.clock, k);
        drive(&mut t.succ.clock, k);
        for q in self.seqs.iter_mut() {
            drive(&mut q.clock, k);
            drive(&mut q.r_cs_n.clock, k);
            drive(&mut q.r_sclk.clock, k);
            drive(&mut q.ph.clock, k);
            drive(&mut q.nfall.clock, k);
            drive(&mut q.wbit.clock, k);
            drive(&mut q.indata.clock, k);
            drive(&mut q.r_cap.clock, k);
            drive(&mut q.r_done.clock, k);
            drive(&mut q.f_wrap.clock, k);
            drive(&mut q.f_half.clock, k);
            drive(&mut q.f_nz.clock, k);
            drive(&mut q.f_end.clock, k);
        }
        for u in self.branches.iter_mut() {
            drive(&mut u.clock, k);
            drive(&mut u.rom.clock, k);
            drive(&mut u.act.clock, k);
            drive(&mut u.r_cs_n.clock, k);
            drive(&mut u.r_sclk.clock, k);
            drive(&mut u.reader.clock, k);
            drive(&mut u.cur_ch.clock, k);
            drive(&mut u.r_sel.clock, k);
            drive(&mut u.r_en.clock, k);
            drive(&mut u.r_done.clock, k);
            drive(&mut u.p_sel.clock, k);
            drive(&mut u.p_dev.clock, k);
        }
        for u in self.cmds.iter_mut() {
            drive(&mut u.clock, k);
        }
        for u in self.pulses.iter_mut() {
            drive(&mut u.clock, k);
        }
        for u in self.holds.iter_mut() {
            drive(&mut u.clock, k);
        }
        let m = &mut self.merge;
        drive(&mut m.clock, k);
        drive(&mut m.r_valid.clock, k);
        drive(&mut m.r_ch.clock, k);
        drive(&mut m.r_val.clock, k);
        drive(&mut m.pend.clock, k);
        drive(&mut m.r_any.clock, k);
        for g in self.modes.iter_mut() {
            drive(&mut g.clock, k);
        }
        drive(&mut m.r_shen.clock, k);
        drive(&mut m.r_chen.clock, k);
    }
}

impl Core {
    /// Each branch's MISO input: the pin, or in the merger's queue form the
    /// pin of the branch whose word the lane's register captures.
    fn miso_lanes(&self) -> u64 {
        let miso = self.adc_miso.val().to_u64();
        let Some(q) = &self._queue else {
            return miso;
        };
        let act = self
            .branches
            .iter()
            .enumerate()
            .fold(0u64, |a, (b, u)| a | (u.act_q.val() as u64) << b);
        route_miso(q, act, miso)
    }
}

impl Core {
    /// The mode block's timebase inputs and `mode`; the ROM address and
    /// `slice` the branches take: the mode block's with modes, else the
    /// timing generator's.
    fn mode_block_inputs(&mut self, clk: Clock, rst: bool) -> (Bits<SLOT_BITS>, Bits<SLICE_BITS>) {
        let Some(g) = self.modes.first_mut() else {
            return (self.timing.addr.val(), self.timing.slice.val());
        };
        g.clock.next = clk;
        g.rst.next = rst;
        g.start1.next = self.timing.start1.val();
        g.addr.next = self.timing.addr.val();
        if let Some(sel) = self.mode_sel.first() {
            g.mode_sel.next = sel.val();
        }
        self.mode[0].next = g.mode.val();
        (g.maddr.val(), g.minfo.val())
    }
}

/// A command unit's inputs: the core's clock, reset and slot start, its
/// branch's pins and its sequencer's SCLK and done strobe.
#[inline]
fn feed_cmd(
    q: &mut CmdUnit,
    u: &BranchUnit,
    (clk, rst, start0): (Clock, bool, bool),
    (q_sclk, q_done): (bool, bool),
    modes: Option<(Bits<MODE_BITS>, Bits<SLICE_BITS>)>,
) {
    if let (Some(m), Some((mode, info))) = (q.mode.first_mut(), modes) {
        m.next = mode;
        // `minfo`'s low bits: the next frame's mode (the unit masks them)
        q.nxt[0].next = (info.to_u64() & ((1 << MODE_BITS) - 1)).into();
    }
    q.clock.next = clk;
    q.rst.next = rst;
    q.start0.next = start0;
    q.pin.next = u.cs_n.val();
    q.bsclk.next = u.sclk.val();
    q.qsclk.next = q_sclk;
    q.qdone.next = q_done;
    q.sel.next = u.mux_sel.val();
    q.hi.next = u.mux_en.val().get_bit(1);
    q.done.next = u.done.val();
}

impl Logic for Core {
    fn update(&mut self) {
        let clk = self.clock.val();
        let rst = self.rst.val();
        self.timing.clock.next = clk;
        self.timing.rst.next = rst;
        self.merge.clock.next = clk;
        self.merge.rst.next = rst;
        let start = self.timing.start2.val();
        let start1 = self.timing.start1.val();
        let start0 = self.timing.start0.val();
        let (addr, slice) = self.mode_block_inputs(clk, rst);
        let modes = self.modes.first().map(|g| (g.mode.val(), g.minfo.val()));
        let mut seq = [(false, false, false, false); MAX_BRANCHES];
        // each sequencer's start, and the slot start its branches see
        let mut starts = [(start, start0); MAX_BRANCHES];
        for (i, h) in self._hold_of.iter().enumerate() {
            let Some(h) = h else { continue };
            let u = &mut self.holds[*h];
            u.clock.next = clk;
            u.rst.next = rst;
            u.start2.next = start;
            starts[i] = (u.fire2.val(), u.start0.val());
        }
        for (i, q) in self.seqs.iter_mut().enumerate() {
            q.clock.next = clk;
            q.rst.next = rst;
            q.start2.next = starts[i].0;
            seq[i] = (q.cs_n.val(), q.sclk.val(), q.cap.val(), q.done.val());
        }
        for (i, p) in self._pulse_of.iter().enumerate() {
            let Some(p) = p else { continue };
            let u = &mut self.pulses[*p];
            u.clock.next = clk;
            u.rst.next = rst;
            u.start2.next = starts[i].0;
            // the branches register the pulse in place of the sequencer's pin
            seq[i].0 = u.pin_n.val();
        }
        for (i, h) in self._hold_of.iter().enumerate() {
            let Some(h) = h else { continue };
            // the branches see the sequencer's levels through the hold-off's mask
            let u = &mut self.holds[*h];
            (u.cs_in.next, u.sclk_in.next, u.cap_in.next, u.done_in.next) = seq[i];
            seq[i] = (u.cs_n.val(), u.sclk.val(), u.cap.val(), u.done.val());
        }
        let miso = self.miso_lanes();
        let grant = self.merge.grant.val().to_u64();
        let (mut cs, mut sclk, mut sel, mut en, mut done) = (0u64, 0u64, 0u64, 0u128, 0u64);
        let mut more = 0u64;
        let mut done_next = 0u64;
        let mut mosi = 0u64;
        let mut en_off = 0usize;
        let mut chs = [0u64; MAX_BRANCHES];
        let mut vals = [0u64; MAX_BRANCHES];
        for (b, u) in self.branches.iter_mut().enumerate() {
            u.clock.next = clk;
            u.rst.next = rst;
            u.start2.next = start;
            u.start1.next = start1;
            let start0 = starts[self._seq_of[b]].1;
            u.start0.next = start0;
            u.addr.next = addr;
            u.slice.next = slice;
            let (q_cs, q_sclk, q_cap, q_done) = seq[self._seq_of[b]];
            u.seq_cs_n.next = q_cs;
            u.seq_sclk.next = q_sclk;
            u.seq_cap.next = q_cap;
            u.seq_done.next = q_done;
            u.miso.next = (miso >> b) & 1 == 1;
            u.grant.next = (grant >> b) & 1 == 1;
            (u.sh_en.next, u.ch_en.next) = (self.merge.sh_en.val(), self.merge.ch_en.val());
            more |= (u.more.val() as u64) << b;
            cs |= (u.cs_n.val() as u64) << b;
            sclk |= (u.sclk.val() as u64) << b;
            sel |= u.mux_sel.val().to_u64() << (3 * b);
            let d = self._devices[b];
            let mask = if d >= 64 { u64::MAX } else { (1u64 << d) - 1 };
            en |= ((u.mux_en.val().to_u64() & mask) as u128) << en_off;
            en_off += d;
            let mut live = true;
            if let Some(i) = self._cmd_of[b] {
                let q = &mut self.cmds[i];
                feed_cmd(q, u, (clk, rst, start0), (q_sclk, q_done), modes);
                live = q.live.val();
                mosi |= (q.mosi.val() as u64) << i;
            }
            done |= ((u.done.val() && live) as u64) << b;
            done_next |= ((u.done_next.val() && live) as u64) << b;
            chs[b] = u.res_ch.val().to_u64();
            vals[b] = u.res_val.val().to_u64();
        }
        // Unused lanes read as all ones on CS/SCLK (idle level) in the core;
        // the wrapper only exposes the mix's branches.
        let nb = self.branches.len();
        let idle: u64 = ((1u64 << MAX_BRANCHES) - 1) & !((1u64 << nb) - 1);
        self.adc_cs_n.next = (cs | idle).into();
        self.adc_sclk.next = (sclk | idle).into();
        for m in self.adc_mosi.iter_mut() {
            m.next = mosi.into();
        }
        // `mux_sel` (48 bits) and `mux_en` (128 bits) are wider than rust-hdl's
        // short bit vectors (32 bits), so it stores them as `[bool; N]`:
        // converting them on every evaluation pass dominated the simulation,
        // so they are written only when their value changes (same signal value).
        if sel != self._mux_sel {
            self._mux_sel = sel;
            self.mux_sel.next = sel.into();
        }
        if en != self._mux_en {
            self._mux_en = en;
            self.mux_en.next = en.to_bits();
        }
        if let Some(g) = self.modes.first_mut() {
            g.done.next = done.into();
            for b in 0..g.ch.len() {
                g.ch[b].next = chs[b].into();
                g.v[b].next = vals[b].into();
            }
        }
        self.merge.done.next = done.into();
        self.merge.more.next = more.into();
        self.merge.done_next.next = done_next.into();
        // the queue form's single sequencer (unused in the priority form)
        self.merge.cap_next.next = self.seqs[0].cap_next.val();
        self.merge.start2.next = start;
        self.merge.addr.next = self.timing.addr.val();
        self.merge.seq_done.next = seq[0].3;
        if self._queue.is_some() {
            // the queue form: each lane reads the next lane's channel and word
            for b in 0..nb - 1 {
                let u = &mut self.branches[b];
                u.q_ch.next = chs[b + 1].into();
                u.q_val.next = vals[b + 1].into();
            }
        }
        // Lanes >= nb keep their default 0 (the glue ties them to zero).
        let m = &mut self.merge;
        for b in 0..nb {
            m.ch[b].next = chs[b].into();
            m.v[b].next = vals[b].into();
        }
        self.sample_valid.next = self.merge.valid.val();
        self.sample_channel.next = self.merge.channel.val();
        self.sample_value.next = self.merge.value.val();
        self.slot_tick.next = start1;
    }

    fn connect(&mut self) {
        self.timing.clock.connect();
        self.timing.rst.connect();
        self.merge.clock.connect();
        self.merge.rst.connect();
        for q in self.seqs.iter_mut() {
            q.clock.connect();
            q.rst.connect();
            q.start2.connect();
        }
        for u in self.branches.iter_mut() {
            u.clock.connect();
            u.rst.connect();
            u.start2.connect();
            u.start1.connect();
            u.start0.connect();
            u.addr.connect();
            u.slice.connect();
            u.seq_cs_n.connect();
            u.seq_sclk.connect();
            u.seq_cap.connect();
            u.seq_done.connect();
            u.miso.connect();
            u.grant.connect();
            u.sh_en.connect();
            u.ch_en.connect();
            u.q_ch.connect();
            u.q_val.connect();
        }
        for q in self.pulses.iter_mut() {
            q.clock.connect();
            q.rst.connect();
            q.start2.connect();
        }
        for q in self.holds.iter_mut() {
            q.clock.connect();
            q.rst.connect();
            q.start2.connect();
            q.cs_in.connect();
            q.sclk_in.connect();
            q.cap_in.connect();
            q.done_in.connect();
        }
        for q in self.cmds.iter_mut() {
            q.clock.connect();
            q.rst.connect();
            q.start0.connect();
            q.pin.connect();
            q.bsclk.connect();
            q.qsclk.connect();
            q.qdone.connect();
            q.sel.connect();
            q.hi.connect();
            q.done.connect();
            q.mode.iter_mut().for_each(|s| s.connect());
            q.nxt.iter_mut().for_each(|s| s.connect());
        }
        for m in self.adc_mosi.iter_mut() {
            m.connect();
        }
        self.merge.done.connect();
        self.merge.more.connect();
        self.merge.done_next.connect();
        self.merge.cap_next.connect();
        self.merge.start2.connect();
        self.merge.addr.connect();
        self.merge.seq_done.connect();
        for b in 0..MAX_BRANCHES {
            self.merge.ch[b].connect();
            self.merge.v[b].connect();
        }
        self.adc_cs_n.connect();
        self.adc_sclk.connect();
        self.mux_sel.connect();
        self.mux_en.connect();
        self.sample_valid.connect();
        self.sample_channel.connect();
        self.sample_value.connect();
        self.slot_tick.connect();
        for g in self.modes.iter_mut() {
            g.clock.connect();
            g.rst.connect();
            g.start1.connect();
            g.addr.connect();
            g.mode_sel.connect();
            g.done.connect();
            g.ch.iter_mut().for_each(|s| s.connect());
            g.v.iter_mut().for_each(|s| s.connect());
        }
        self.mode.iter_mut().for_each(|s| s.connect());
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(core_glue(
            self.branches.len(),
            &self._devices,
            &self._seq_of,
            SeqWires {
                pulse_of: &self._pulse_of,
                hold_of: &self._hold_of,
            },
            (
                &self._cmd_of,
                &self
                    .cmds
                    .iter()
                    .map(|q| !q.mode.is_empty())
                    .collect::<Vec<_>>(),
            ),
            self.modes
                .first()
                .map(|g| (!self.mode_sel.is_empty(), g.ch.len())),
            match self._queue.as_deref() {
                Some(q) => LaneForm::Queue(q),
                None => LaneForm::Priority {
                    stepped: self.merge.stepped(),
                },
            },
        ))
    }
}
