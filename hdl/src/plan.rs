//! From a `lut_gen::Schedule` to the numbers the gateware is built from
//! (pure Rust, no rust-hdl): limits, per-branch ROM images, reset values.

use lut_gen::Schedule;

use crate::decode::SlotLogic;
use crate::modeplan::{FrontModes, ModePlan, ModeRom};
use crate::HdlError;

use crate::widths::{
    CNT_BITS, MEMBER_BITS, NFALL_BITS, PH_BITS, SLICE_BITS, SLOT_BITS, WORD_BIT_BITS,
};
/// Largest frame the full-frame slot ROM takes.
pub const MAX_FRAME_SLOTS: u64 = 1 << SLOT_BITS;
/// Limits of the compact slot LUT (slice table + rotation groups).
pub const MAX_SLOTS_PER_SLICE: u64 = 1 << SLOT_BITS;
pub const MAX_SLICES_PER_FRAME: u64 = 1 << SLICE_BITS;
/// The full-frame ROMs are used while they fit in this many bits (16 of the
/// HX8K's 32 block RAMs): they cost no logic cells.
pub const FULL_LUT_MAX_BITS: u64 = 16 * 4096;
pub const MAX_SLOT_CYCLES: u64 = 1 << CNT_BITS;
pub const MAX_SCLK_DIV: u64 = (1 << PH_BITS) - 1;
/// The phase counter also times the setup (and a CNV part's conversion):
/// it starts at `sclk_div - setup` modulo `2^PH_BITS`.
pub const MAX_SETUP_CYCLES: u64 = (1 << PH_BITS) - 1;
/// SCLK periods per conversion (`nfall`), serial clocks per word (the
/// in-word bit counter) and chained words (the word reader's member count).
pub const MAX_SCLKS: u64 = (1 << NFALL_BITS) - 1;
pub const MAX_WORD_SCLKS: u64 = 1 << (WORD_BIT_BITS - 1);
pub const MAX_CHAIN: u64 = 1 << MEMBER_BITS;

/// The SPI timing of one or more branches: one shared sequencer each.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SeqTiming {
    pub sclk_div: u64,
    pub sclk_half: u64,
    /// Conversion start to the first SCLK period (CNV parts: t_CONV too).
    pub setup_cycles: u64,
    pub read_cycles: u64,
    /// Cycles the conversion pin stays active: `read_cycles`, or for a part
    /// read with CNV low the conversion alone (a [`CnvPulse`] times it).
    ///
    /// [`CnvPulse`]: crate::core
    pub pin_cycles: u64,
    /// CNV style: SCK idles low, and the last rising edge captures too.
    pub cnv: bool,
    /// SCLK periods per conversion (every word of the chain).
    pub sclks: u64,
    /// Serial clocks per word, and which of them carry data bits.
    pub word_sclks: u64,
    pub leading_bits: u64,
    pub bits: u64,
    /// Cycles from the slot tick to the transaction's start (0, or at
    /// least 2: a sync group's hold-off, `SpiTiming::holdoff_cycles`).
    pub holdoff: u64,
}

impl SeqTiming {
    /// The conversion pin is released before the read: CNV falls when the
    /// conversion ends (a part read with CNV low).
    pub fn pulsed(&self) -> bool {
        self.pin_cycles < self.read_cycles
    }

    /// The serial bit index (within its word) that rising edge 1 captures:
    /// a CS part drives bit 0 before any clock and edge `i` captures bit
    /// `i`; a CNV part's edge `i` captures bit `i - 1`.
    pub fn first_bit(&self) -> u64 {
        if self.cnv {
            0
        } else {
            1 % self.word_sclks
        }
    }
}

/// One branch's slot ROM and numbers.
#[derive(Debug, Clone)]
pub struct BranchRom {
    /// `2^addr_bits` words of [`BranchRom::word_bits`] bits, for frame slot
    /// `u`: `{conv, ch[ch_bits], msel[3], mdev[dev_bits]}`: whether the branch
    /// converts in slot `u` and which channel, and the mux select/device of
    /// the branch's first instant at slot `u` or later (cyclic), i.e. what
    /// the mux addresses after the first cycle of slot `u - 1`.
    pub words: Vec<u32>,
    pub addr_bits: usize,
    pub ch_bits: usize,
    pub dev_bits: usize,
    /// Index of the branch's SPI sequencer in [`Plan::seqs`].
    pub seq: usize,
    pub reset_sel: u32,
    /// One-hot mux enable of the first instant of frame 0 (0 if the branch never converts).
    pub reset_en: u64,
    /// Whether the branch converts in slot 0 of frame 0, right after reset
    /// (docs/timing.md, "Start-up").
    pub conv0: bool,
    pub devices: usize,
    /// The branch has a multiplexer.  Without one (`mux = "none"`) the core
    /// still drives a constant device 0 at `en_offset`, but the wrapper and
    /// [`crate::RtlSim`] leave its mux lanes out of `slotforge_top`'s ports.
    pub muxed: bool,
    /// First device bit of this branch in the core's `mux_en` (the port's
    /// when every branch has a multiplexer).
    pub en_offset: usize,
    /// The conversion pin is a CNV (active high, SCK idles low), not a CS.
    pub cnv: bool,
    /// Data bits per word, and words per conversion (parts in the chain).
    pub bits: u32,
    pub chain: u32,
    /// Chained branches: for each lead channel (the frame table's entry),
    /// the channel of every chain member in the order the words leave.
    pub members: Vec<(u32, Vec<u32>)>,
    /// The compact form (only in a compact plan; `words` is then empty and
    /// the mux field of slot `u`'s word is the next instant after slot `u`).
    pub compact: Option<CompactRom>,
    /// The converter takes a command word on `adc_mosi`.  Its branch has no
    /// external mux, so the ROM's mux field carries instead the input each
    /// conversion's word selects (`Schedule::commands_in_frame`), under the
    /// same rule (the branch's first instant at slot `u` or later).
    pub command: Option<lut_gen::Command>,
    /// A converter with a command word behind a front mux (`front_mux`):
    /// the mux field is the front mux's, the words come from this table.
    pub front: Option<FrontWords>,
    /// A mix with modes: every mode's table in `words` (the mode above the
    /// slot on the address, a `w` bit above each word), see `modeplan`.
    pub modes: Option<ModeRom>,
    /// Arithmetic slot decoding (a logic plan): `words` as logic of the
    /// slot-in-slice and slice counters, in place of the ROM.
    pub logic: Option<SlotLogic>,
    /// Per frame slot (full table): the word's channel field names a
    /// conversion (the branch's, or in the queue form its lane's).
    pub ch_used: Vec<bool>,
}

/// The inputs a fronted branch's words select, one per conversion of the
/// frame in slot order, and the first one's index after reset; in a mix
/// with modes, every mode's (`inputs` is then the reset mode's, unread).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrontWords {
    pub inputs: Vec<u32>,
    pub first: u32,
    pub modes: Option<FrontModes>,
}

impl BranchRom {
    pub fn word_bits(&self) -> usize {
        1 + self.ch_bits + 3 + self.dev_bits + self.modes.is_some() as usize
    }

    /// The bits of frame slot `u`'s word nothing reads: its channel when
    /// no conversion's word is in the branch's lane in that slot (the
    /// merger and the word reader read the channel only with a word).
    pub fn free_bits(&self, u: usize) -> u32 {
        let (cw, dw) = (self.ch_bits, self.dev_bits);
        if self.ch_used.get(u).copied().unwrap_or(true) {
            0
        } else {
            ((1 << cw) - 1) << (3 + dw)
        }
    }

    /// Pack one ROM word.
    pub fn word(&self, conv: bool, ch: u32, sel: u32, dev: u32) -> u32 {
        let (cw, dw) = (self.ch_bits, self.dev_bits);
        ((conv as u32) << (cw + 3 + dw)) | (ch << (3 + dw)) | (sel << dw) | dev
    }
}

/// Which form of the slot LUT the gateware embeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LutForm {
    /// Full frame table while it fits (`MAX_FRAME_SLOTS` slots,
    /// `FULL_LUT_MAX_BITS` bits over all branches), else compact.
    #[default]
    Auto,
    /// One ROM word per frame slot and branch.
    Full,
    /// A slice table plus rotation groups indexed by a slice counter.
    Compact,
    /// The full table's words as logic of the slot-in-slice and slice
    /// counters (`decode`), no ROM; `Auto` takes it where it costs less.
    Logic,
}

/// A branch's compact LUT: `slice_words[p]` for slot-in-slice `p` is
/// `{rot, payload}`: a ROM word (as in [`BranchRom::words`]) when that slot's
/// word is the same in every slice, else (`rot` = 1) a rotation group `g`
/// whose word for slice `j` is `rot_words[g << slice_bits | j]`.
#[derive(Debug, Clone)]
pub struct CompactRom {
    pub slice_words: Vec<u32>,
    pub slice_addr_bits: usize,
    pub rot_words: Vec<u32>,
    pub group_bits: usize,
    pub slice_bits: usize,
}

#[derive(Debug, Clone)]
pub struct Plan {
    /// Compact LUT (then every branch has `compact`), else full frame table.
    pub compact: bool,
    /// The full table decoded by logic from slot-in-slice and slice
    /// counters (then every branch has `logic`), not read from ROM.
    pub logic: bool,
    pub slots_per_slice: u64,
    pub slices_per_frame: u64,
    pub slot_cycles: u64,
    pub frame_slots: u64,
    pub channel_bits: u32,
    pub seqs: Vec<SeqTiming>,
    pub branches: Vec<BranchRom>,
    /// The link stage, when the mix has a `[link]`.
    pub link: Option<crate::link::LinkParams>,
    /// The mode block, when the mix has modes.
    pub modes: Option<ModePlan>,
    /// The merger's form: `Some(sources)` when the branches' shift registers
    /// are the output queue (see [`queue_sources`]), `sources[j]` the
    /// branches whose MISO lane `j`'s register ever captures; `None` for the
    /// pending-set merger with its own output multiplexer.
    pub queue: Option<Vec<Vec<usize>>>,
    /// The queue form with the full table: the channel of each word out,
    /// from the merger's own table (see [`LaneChannels`]), not from the
    /// lanes' channel registers.
    pub lane_ch: Option<LaneChannels>,
}

/// The queue form's channel table (hdl/DESIGN.md, "Merger"): the merger
/// reads the channel of the `k`-th word a slot's completion puts out from a
/// block RAM at `{a, k}`, `a` the timing generator's ROM address during
/// that slot (the next slot's), `k` the words already out; the lanes then
/// carry no channel registers (eskin34: 16 flip-flops and their
/// multiplexers).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LaneChannels {
    /// At `(a << k_bits) | k`: the channel, and above it (bit
    /// `ch_bits`) whether another word of the slot follows.
    pub words: Vec<u32>,
    pub ch_bits: usize,
    pub addr_bits: usize,
    pub k_bits: usize,
}

pub fn addr_bits(frame_slots: u64) -> usize {
    let mut b = 1;
    while (1u64 << b) < frame_slots {
        b += 1;
    }
    b
}

fn unsupported(msg: String) -> HdlError {
    HdlError::Unsupported(msg)
}

#[cfg(feature = "stock")]
pub fn plan(s: &Schedule) -> Result<Plan, HdlError> {
    plan_with(s, LutForm::Auto)
}

/// Compact a per-slot word table (`[slice][slot in slice]` order) into a
/// slice table and rotation groups.
fn compact_words(table: &[u32], sps: usize, k: usize, word_bits: usize) -> CompactRom {
    let mut groups: Vec<Vec<u32>> = vec![];
    let mut cells: Vec<(bool, u32)> = vec![];
    for p in 0..sps {
        let col: Vec<u32> = (0..k).map(|j| table[j * sps + p]).collect();
        if col.iter().all(|w| *w == col[0]) {
            cells.push((false, col[0]));
        } else {
            let g = groups.iter().position(|x| *x == col).unwrap_or_else(|| {
                groups.push(col.clone());
                groups.len() - 1
            });
            cells.push((true, g as u32));
        }
    }
    let group_bits = addr_bits(groups.len().max(1) as u64);
    let slice_bits = addr_bits(k as u64);
    let payload = word_bits.max(group_bits);
    let slice_addr_bits = addr_bits(sps as u64);
    let mut slice_words = vec![0u32; 1 << slice_addr_bits];
    for (p, &(rot, v)) in cells.iter().enumerate() {
        slice_words[p] = ((rot as u32) << payload) | v;
    }
    let mut rot_words = vec![0u32; 1 << (group_bits + slice_bits)];
    for (g, col) in groups.iter().enumerate() {
        for (j, w) in col.iter().enumerate() {
            rot_words[(g << slice_bits) | j] = *w;
        }
    }
    CompactRom {
        slice_words,
        slice_addr_bits,
        rot_words,
        group_bits,
        slice_bits,
    }
}

impl CompactRom {
    /// The word of frame slot `j * sps + p` (what the hardware looks up).
    pub fn word(&self, p: usize, j: usize, word_bits: usize) -> u32 {
        let payload = word_bits.max(self.group_bits);
        let w = self.slice_words[p];
        if w >> payload & 1 == 1 {
            let g = (w & ((1 << payload) - 1)) as usize;
            self.rot_words[(g << self.slice_bits) | j]
        } else {
            w & ((1 << payload) - 1)
        }
    }
}

/// Like `plan` (feature `stock`), with the slot LUT form chosen by the caller.
pub fn plan_with(s: &Schedule, form: LutForm) -> Result<Plan, HdlError> {
    let g = &s.grid;
    let compact = check_grid(s, form)?;
    // words per round of the merger: one per chained part of every branch
    let words: u64 = s.mix.branches.iter().map(|b| b.chain as u64).sum();
    let mut seqs: Vec<SeqTiming> = Vec::new();
    let mut branches = Vec::with_capacity(s.branches.len());
    let mut en_offset = 0usize;
    for b in 0..s.branches.len() {
        let rom = branch_rom(s, b, compact, words, en_offset, &mut seqs, None)?;
        en_offset += rom.devices;
        branches.push(rom);
    }
    let queue = queue_sources(s, &seqs, &branches);
    if queue.is_some() {
        // lane b's ROM names the channel of the slot's b-th converting branch
        let lanes = lane_channels(s);
        let mut en_offset = 0usize;
        for (b, rom) in branches.iter_mut().enumerate() {
            *rom = branch_rom(s, b, compact, words, en_offset, &mut seqs, Some(&lanes[b]))?;
            en_offset += rom.devices;
        }
    }
    let mut p = Plan {
        compact,
        logic: false,
        slots_per_slice: g.slots_per_slice,
        slices_per_frame: g.slices_per_frame,
        slot_cycles: g.slot_cycles,
        frame_slots: g.frame_slots,
        channel_bits: s.channel_bits(),
        seqs,
        branches,
        link: crate::link::LinkParams::of(s).map_err(unsupported)?,
        queue,
        lane_ch: None,
        modes: None,
    };
    crate::modeplan::apply(s, &mut p)?;
    if !compact && form != LutForm::Full {
        decode_by_logic(&mut p, form == LutForm::Logic)?;
    }
    p.lane_ch = lane_channel_table(s, &p);
    Ok(p)
}

/// Arithmetic slot decoding (hdl/DESIGN.md, "Slot LUT") where it costs
/// less than the ROM's frame-wide slot pointer (two registers of the
/// address's width and a compare), or always when `forced`. Mixes with
/// modes (every mode's table on the ROM address) and command words keep
/// the ROM.
fn decode_by_logic(p: &mut Plan, forced: bool) -> Result<(), HdlError> {
    if p.modes.is_some() || p.branches.iter().any(|r| r.command.is_some()) {
        if forced {
            return Err(unsupported(
                "the logic slot decoding is not for mixes with modes or command words".into(),
            ));
        }
        return Ok(());
    }
    let (sps, k) = (p.slots_per_slice as usize, p.slices_per_frame as usize);
    let logic: Vec<SlotLogic> = p
        .branches
        .iter()
        .map(|r| SlotLogic::of(&r.words, r.word_bits(), sps, k, |u| r.free_bits(u)))
        .collect();
    let (rom, counters, decode) = logic_costs(p, &logic);
    if forced || counters + decode < rom {
        p.logic = true;
        for (r, l) in p.branches.iter_mut().zip(logic) {
            r.logic = Some(l);
        }
    }
    Ok(())
}

/// Block RAM bits (an iCE40 SB_RAM40_4K): a ROM under this is built of
/// LUTs by yosys (induction5k-adc12's 1,280-bit tables: no block RAM;
/// eskin34's 6 kbit ones: five), then its words cost logic like the
/// decoding's.
const BRAM_BITS: usize = 4096;

/// Estimated LCs of the ROM form (the slot pointer, and the tables where
/// they are too small for block RAM), of the logic form's counters, and
/// of its decoding.
pub fn logic_costs(p: &Plan, logic: &[SlotLogic]) -> (usize, usize, usize) {
    let ab = addr_bits(p.frame_slots);
    let l = &logic[0];
    let refs: Vec<&SlotLogic> = logic.iter().collect();
    let decode = SlotLogic::cost(&refs);
    let in_luts = p.branches.iter().all(|r| (r.word_bits() << ab) < BRAM_BITS);
    let rom = 2 * ab + 2 + if in_luts { decode } else { 0 };
    // the logic form's timing counts slots in the slice (with their
    // successor register, as the compact form's) and slices
    (rom, 2 * l.slot_bits + l.slice_bits + 2, decode)
}

/// The queue form's channel table, for the full table's ROM address (not
/// the compact or logic forms, whose address is the slot in the slice):
/// during frame slot `u` the address is `u + 1` (the ROM reads a slot
/// ahead). Only when a slot's words are all out before the address moves:
/// the completion comes at most `read_cycles` after the slot start, then
/// a word a cycle, and the address moves in the slot's last cycles.
fn lane_channel_table(s: &Schedule, p: &Plan) -> Option<LaneChannels> {
    let nb = p.branches.len();
    let q = p.seqs.first()?;
    if p.queue.is_none() || p.compact || p.logic || p.modes.is_some() {
        return None;
    }
    if q.setup_cycles + q.read_cycles + nb as u64 + 4 > p.slot_cycles {
        return None;
    }
    let (fs, ab, kb) = (
        p.frame_slots,
        addr_bits(p.frame_slots),
        addr_bits(nb as u64),
    );
    let cw = (p.channel_bits as usize).max(1);
    let mut words = vec![0u32; 1 << (ab + kb)];
    for u in 0..fs {
        let a = ((u + 1) % fs) as usize;
        let conv: Vec<usize> = (0..nb).filter_map(|b| s.at(u, b)).collect();
        for (k, c) in conv.iter().enumerate() {
            let next = (k + 1 < conv.len()) as u32;
            words[(a << kb) | k] = next << cw | *c as u32;
        }
    }
    Some(LaneChannels {
        words,
        addr_bits: ab,
        k_bits: kb,
        ch_bits: cw,
    })
}

/// `lanes[j][u]`: the channel of the `j`-th branch (in branch order) that
/// converts in frame slot `u`.
fn lane_channels(s: &Schedule) -> Vec<Vec<Option<usize>>> {
    let nb = s.branches.len();
    let mut lanes = vec![vec![None; s.grid.frame_slots as usize]; nb];
    for u in 0..s.grid.frame_slots {
        let conv = (0..nb).filter_map(|b| s.at(u, b));
        for (j, c) in conv.enumerate() {
            lanes[j][u as usize] = Some(c);
        }
    }
    lanes
}

/// Whether the branches' MISO shift registers can be the merger's queue
/// (hdl/DESIGN.md, "Merger"), and if so, for each lane `j`, the branches
/// whose MISO its register captures (the `j`-th converting branch of some
/// slot). It can when every branch completes in the same cycle of its slot
/// (one SPI sequencer) with one word (no chain), so a slot's words leave in
/// branch order from lane 0 while each lane takes the next one's register;
/// and when the start-up skip (docs/timing.md, "Start-up") drops only
/// branches above every branch that converts in slot 0, so that the lanes
/// the ROM names for slot 0 are the ones that capture.
fn queue_sources(s: &Schedule, seqs: &[SeqTiming], roms: &[BranchRom]) -> Option<Vec<Vec<usize>>> {
    let nb = roms.len();
    if nb < 2 || seqs.len() != 1 || roms.iter().any(|r| r.chain != 1) {
        return None;
    }
    // modes put every mode's table on the ROM address and a command unit
    // reads the mux field: both keep the pending-set merger
    if !s.modes.is_empty() || roms.iter().any(|r| r.command.is_some()) {
        return None;
    }
    let conv: Vec<bool> = (0..nb).map(|b| s.at(0, b).is_some()).collect();
    let kept = (0..nb).filter(|&b| conv[b] && roms[b].conv0).max();
    let skipped = (0..nb).filter(|&b| conv[b] && !roms[b].conv0).min();
    if let (Some(k), Some(x)) = (kept, skipped) {
        if x < k {
            return None;
        }
    }
    let mut sources = vec![Vec::new(); nb];
    for u in 0..s.grid.frame_slots {
        let on = (0..nb).filter(|&b| s.at(u, b).is_some());
        for (j, b) in on.enumerate() {
            if !sources[j].contains(&b) {
                sources[j].push(b);
            }
        }
    }
    for src in sources.iter_mut() {
        src.sort_unstable();
    }
    Some(sources)
}

/// The grid against the gateware's counters and ROMs; whether the slot LUT
/// is compact (`form`, or for `Auto` whether the full one would be too big).
fn check_grid(s: &Schedule, form: LutForm) -> Result<bool, HdlError> {
    let g = &s.grid;
    let nb = s.branches.len();
    // branch, channel and device counts: the pin contract's limits
    lut_gen::Layout::fits(s).map_err(unsupported)?;
    let sps = g.slots_per_slice;
    let k = g.slices_per_frame;
    if g.frame_slots == 0 || sps * k != g.frame_slots {
        return Err(unsupported(format!(
            "{} slots per frame is not {sps} slots x {k} slices",
            g.frame_slots
        )));
    }
    let cw = s.channel_bits().max(1) as usize;
    let max_dev_bits = s
        .branches
        .iter()
        .map(|b| addr_bits(b.mux_devices.max(1) as u64))
        .max()
        .unwrap_or(1);
    let full_bits = (1u64 << addr_bits(g.frame_slots)) * (4 + cw + max_dev_bits) as u64 * nb as u64;
    let compact = match form {
        LutForm::Full | LutForm::Logic => false,
        LutForm::Compact => true,
        LutForm::Auto => g.frame_slots > MAX_FRAME_SLOTS || full_bits > FULL_LUT_MAX_BITS,
    };
    if !compact && g.frame_slots > MAX_FRAME_SLOTS {
        return Err(unsupported(format!(
            "{} slots per frame: the full-frame slot ROM holds at most {MAX_FRAME_SLOTS}",
            g.frame_slots
        )));
    }
    if compact && (sps > MAX_SLOTS_PER_SLICE || k > MAX_SLICES_PER_FRAME) {
        return Err(unsupported(format!(
            "{sps} slots per slice x {k} slices: the compact slot LUT supports at most {MAX_SLOTS_PER_SLICE} slots per slice and at most {MAX_SLICES_PER_FRAME} slices"
        )));
    }
    if g.slot_cycles < 2 || g.slot_cycles > MAX_SLOT_CYCLES {
        return Err(unsupported(format!(
            "{} cycles per slot: the slot counter supports 2 to {MAX_SLOT_CYCLES}",
            g.slot_cycles
        )));
    }
    if s.frame_table.len() as u64 != g.frame_slots * nb as u64 {
        return Err(unsupported(
            "frame table size does not match the grid".into(),
        ));
    }
    Ok(compact)
}

/// Branch `b`'s ROM image and reset values; its SPI timing joins `seqs`
/// (one sequencer per distinct timing).  `words`: the merger's words per
/// round; `en_offset`: its first mux enable among all branches'.
fn branch_rom(
    s: &Schedule,
    b: usize,
    compact: bool,
    words: u64,
    en_offset: usize,
    seqs: &mut Vec<SeqTiming>,
    lane: Option<&[Option<usize>]>,
) -> Result<BranchRom, HdlError> {
    let g = &s.grid;
    let bp = &s.branches[b];
    let adc = &s.mix.branches[b].adc;
    let chain = s.mix.branches[b].chain;
    let cnv = adc.start == lut_gen::Start::Cnv;
    let spi = &bp.spi;
    check_spi(s, b, words)?;
    let fronted = s.mix.branches[b].fronted;
    let devices = bp.mux_devices.max(1) as usize;
    let timing = SeqTiming {
        sclk_div: spi.sclk_div,
        sclk_half: spi.sclk_half,
        setup_cycles: spi.setup_cycles,
        read_cycles: spi.read_cycles,
        pin_cycles: spi.pin_cycles,
        cnv,
        sclks: adc.word_sclks() as u64 * chain as u64,
        word_sclks: adc.word_sclks() as u64,
        leading_bits: adc.leading_bits as u64,
        bits: adc.bits as u64,
        holdoff: spi.holdoff_cycles,
    };
    if timing.holdoff == 1 {
        return Err(unsupported(format!(
            "branch {}: a hold-off of one cycle (the gateware delays a transaction by 2 cycles or more)",
            bp.name
        )));
    }
    let seq = match seqs.iter().position(|t| *t == timing) {
        Some(i) => i,
        None => {
            seqs.push(timing);
            seqs.len() - 1
        }
    };
    let slots: Vec<Option<usize>> = (0..g.frame_slots).map(|t| s.at(t, b)).collect();
    for c in slots
        .iter()
        .flatten()
        .filter(|_| !s.has_command(b) || fronted)
    {
        let ch = &s.channels[*c];
        if ch.select > 7 || ch.device as usize >= devices {
            return Err(unsupported(format!(
                "branch {}: channel device {} select {} outside the branch's muxes",
                bp.name, ch.device, ch.select
            )));
        }
    }
    let members = chain_members(s, b, &slots)?;
    let fields = mux_fields(s, b, &slots)?;
    let next = next_instants(&fields);
    let mut rom = BranchRom {
        words: vec![],
        addr_bits: addr_bits(g.frame_slots),
        ch_bits: s.channel_bits().max(1) as usize,
        dev_bits: addr_bits(devices as u64),
        seq,
        reset_sel: 0,
        reset_en: 0,
        // docs/timing.md, "Start-up": the mux takes its reset value at
        // the first reset edge, one cycle before cycle 0 at the least;
        // an instant at cycle 0 it cannot have settled for is skipped.
        // docs/timing.md "Start-up": skipped unless the mux has settled by the start
        conv0: slots[0].is_some() && !s.skipped_at_startup(b, 0),
        devices,
        muxed: s.mix.branches[b].mux.select_bits > 0,
        en_offset,
        cnv,
        bits: adc.bits,
        chain,
        members,
        compact: None,
        command: adc.command.clone(),
        front: front_words(s, b, &slots)?,
        modes: None,
        logic: None,
        ch_used: vec![],
    };
    // the ROM's channel field: the branch's own, or in the queue form its
    // lane's (the conversion and mux fields stay the branch's)
    fill_rom(s, &mut rom, &slots, lane.unwrap_or(&slots), &next, compact);
    if let Some((sel, dev)) = next[0] {
        rom.reset_sel = sel;
        rom.reset_en = 1u64 << dev;
    }
    Ok(rom)
}

/// A fronted branch's command unit: the input each of the frame's words
/// selects, in instant order, and the instant its counter starts at after
/// reset (1 when the instant at cycle 0 is skipped: docs/timing.md,
/// "Start-up").  The mux field carries the front mux's pins, so the words
/// need their own table; indexed by the branch's conversions in the frame,
/// it is as long as the frame's words, not its slots.
fn front_words(
    s: &Schedule,
    b: usize,
    slots: &[Option<usize>],
) -> Result<Option<FrontWords>, HdlError> {
    if !s.mix.branches[b].fronted {
        return Ok(None);
    }
    let inputs: Vec<u32> = s.commands_in_frame(b).iter().map(|w| w.input).collect();
    if let Some(i) = inputs.iter().find(|&&i| i > 15) {
        return Err(unsupported(format!(
            "branch {}: its word selects input {i}: the gateware sends at most 4 channel bits",
            s.branches[b].name
        )));
    }
    let skipped = slots[0].is_some() && s.branches[b].settle_cycles > 1;
    Ok(Some(FrontWords {
        inputs,
        first: skipped as u32,
        modes: None,
    }))
}

/// The mux field of each frame slot where branch `b` converts: the
/// channel's (select, device), or for a converter with a command word and
/// no front mux the input its word selects (its low 3 bits as the select,
/// bit 3 as the device).
fn mux_fields(
    s: &Schedule,
    b: usize,
    slots: &[Option<usize>],
) -> Result<Vec<Option<(u32, u32)>>, HdlError> {
    let mut f: Vec<Option<(u32, u32)>> = slots
        .iter()
        .map(|c| c.map(|c| (s.channels[c].select, s.channels[c].device)))
        .collect();
    if s.mix.branches[b].fronted {
        return Ok(f);
    }
    // inputs 0..=15 (`Command::parse` allows at most 4 channel bits): the
    // low 3 in the select field, the 4th in the device field (one bit for
    // a branch without mux devices, `BranchRom::dev_bits`)
    for w in s.commands_in_frame(b) {
        if w.input > 15 {
            return Err(unsupported(format!(
                "branch {}: its word selects input {}: the gateware sends at most 4 channel bits",
                s.branches[b].name, w.input
            )));
        }
        f[w.slot as usize] = Some((w.input & 7, w.input >> 3));
    }
    Ok(f)
}

/// Branch `b`'s part and SPI timing against what the sequencer's counters,
/// the word reader and the slot can hold.
fn check_spi(s: &Schedule, b: usize, words: u64) -> Result<(), HdlError> {
    let g = &s.grid;
    let bp = &s.branches[b];
    let adc = &s.mix.branches[b].adc;
    let chain = s.mix.branches[b].chain;
    let cnv = adc.start == lut_gen::Start::Cnv;
    let spi = &bp.spi;
    let sclks = adc.word_sclks() as u64 * chain as u64;
    if adc.bits < 1 || adc.bits > lut_gen::SAMPLE_VALUE_BITS {
        return Err(unsupported(format!(
            "branch {}: ADC {} has {} data bits: the gateware carries 1 to {}",
            bp.name,
            adc.name,
            adc.bits,
            lut_gen::SAMPLE_VALUE_BITS
        )));
    }
    if adc.word_sclks() > MAX_WORD_SCLKS as u32 {
        return Err(unsupported(format!(
            "branch {}: ADC {} takes {} serial clocks per word: the gateware counts at most {MAX_WORD_SCLKS}",
            bp.name,
            adc.name,
            adc.word_sclks()
        )));
    }
    if chain < 1 || chain as u64 > MAX_CHAIN || sclks > MAX_SCLKS {
        return Err(unsupported(format!(
            "branch {}: a chain of {chain} x {} serial clocks: the gateware reads at most {MAX_CHAIN} words and {MAX_SCLKS} clocks per conversion",
            bp.name,
            adc.word_sclks()
        )));
    }
    if !cnv && adc.leading_bits < 1 {
        // A CS part drives its first bit before any SCLK edge: the
        // master has no edge to capture it at (docs/timing.md).
        return Err(unsupported(format!(
            "branch {}: CS-style ADC {} needs at least one leading bit before its MSB",
            bp.name, adc.name
        )));
    }
    if spi.sclk_div < 2 || spi.sclk_div > MAX_SCLK_DIV || !spi.sclk_div.is_multiple_of(2) {
        return Err(unsupported(format!(
            "branch {}: SCLK divider {} must be even and in 2..={MAX_SCLK_DIV}",
            bp.name, spi.sclk_div
        )));
    }
    if spi.sclk_half * 2 != spi.sclk_div {
        return Err(unsupported(format!(
            "branch {}: sclk_half {} is not sclk_div/2",
            bp.name, spi.sclk_half
        )));
    }
    if spi.setup_cycles < 1 || spi.setup_cycles > MAX_SETUP_CYCLES {
        return Err(unsupported(format!(
            "branch {}: conversion start to first SCLK of {} cycles must be within 1..={MAX_SETUP_CYCLES}",
            bp.name, spi.setup_cycles
        )));
    }
    if spi.read_cycles != spi.setup_cycles + sclks * spi.sclk_div {
        return Err(unsupported(format!(
            "branch {}: read_cycles {} != setup + {sclks} * sclk_div",
            bp.name, spi.read_cycles
        )));
    }
    // The branch's shift register and channel register hold a result
    // until the merger has taken every word (at most one word of every
    // branch's chain before each of this branch's words, after the
    // completion at t + R); the next slot must not start before.
    if spi.read_cycles + words > g.slot_cycles {
        return Err(unsupported(format!(
            "branch {}: a conversion ({} cycles) plus the merger's {words} cycles does not fit in a slot ({} cycles)",
            bp.name, spi.read_cycles, g.slot_cycles
        )));
    }
    Ok(())
}

/// A chained conversion delivers one word per member, every one named by a
/// channel (the word reader has no way to skip a word): per lead channel of
/// branch `b` (its conversions in `slots`), the channels of its members.
fn chain_members(
    s: &Schedule,
    b: usize,
    slots: &[Option<usize>],
) -> Result<Vec<(u32, Vec<u32>)>, HdlError> {
    let chain = s.mix.branches[b].chain;
    let mut members: Vec<(u32, Vec<u32>)> = Vec::new();
    if chain > 1 {
        for &lead in slots.iter().flatten() {
            if members.iter().any(|(l, _)| *l as usize == lead) {
                continue;
            }
            let group = &s.groups[lead];
            let chans: Vec<u32> = (0..chain as usize)
                .filter_map(|m| group.get(m).copied().flatten().map(|c| c as u32))
                .collect();
            if chans.len() != chain as usize {
                return Err(unsupported(format!(
                    "branch {}: the conversion of channel {} reads {chain} chained words but only {} of them are declared channels: the gateware needs a channel for every member",
                    s.branches[b].name,
                    s.mix.channels[lead].name,
                    chans.len()
                )));
            }
            members.push((lead as u32, chans));
        }
        members.sort();
    }
    Ok(members)
}

/// `next[u]`: the mux field of the first instant at slot `u` or later (cyclic).
fn next_instants(slots: &[Option<(u32, u32)>]) -> Vec<Option<(u32, u32)>> {
    let n = slots.len();
    let mut next: Vec<Option<(u32, u32)>> = vec![None; n];
    let mut cur: Option<(u32, u32)> = None;
    for u in (0..2 * n).rev() {
        if let Some(c) = slots[u % n] {
            cur = Some(c);
        }
        if u < n {
            next[u] = cur;
        }
    }
    next
}

/// The ROM's words: the full frame table, or its compact form.
fn fill_rom(
    s: &Schedule,
    rom: &mut BranchRom,
    slots: &[Option<usize>],
    chans: &[Option<usize>],
    next: &[Option<(u32, u32)>],
    compact: bool,
) {
    let g = &s.grid;
    let (sps, k) = (g.slots_per_slice, g.slices_per_frame);
    let n = slots.len();
    let mux = |f: Option<(u32, u32)>| f.unwrap_or((0, 0));
    if compact {
        // The word of slot u carries the mux field of the next instant
        // *after* slot u: the branch moves it to the mux one slot later.
        let table: Vec<u32> = (0..n)
            .map(|u| {
                let (sel, dev) = mux(next[(u + 1) % n]);
                rom.word(slots[u].is_some(), chans[u].unwrap_or(0) as u32, sel, dev)
            })
            .collect();
        let c = compact_words(&table, sps as usize, k as usize, rom.word_bits());
        debug_assert!(
            (0..n).all(|u| c.word(u % sps as usize, u / sps as usize, rom.word_bits()) == table[u])
        );
        rom.compact = Some(c);
    } else {
        let mut words = vec![0u32; 1 << rom.addr_bits];
        for u in 0..n {
            let (sel, dev) = mux(next[u]);
            let ch = chans[u].unwrap_or(0) as u32;
            words[u] = rom.word(slots[u].is_some(), ch, sel, dev);
        }
        rom.words = words;
        rom.ch_used = chans.iter().map(|c| c.is_some()).collect();
    }
}
