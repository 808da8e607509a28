//! The numbers of a mix with modes (docs/timing.md, "Mode switches"), pure
//! Rust: every mode's slot table in one ROM image per branch (the mode's
//! number on the address bits above the slot), each branch's first instant
//! of every mode (where its mux goes when a frame ends without another
//! instant), and the triggers as the mode block evaluates them.

use lut_gen::{ModeSelect, Schedule, When};

use crate::plan::{addr_bits, BranchRom, FrontWords, Plan};
use crate::widths::{MODE_BITS, SLOT_BITS};
use crate::HdlError;

/// The modes of a plan: what the mode block (`core/modes.rs`) is built from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModePlan {
    pub count: usize,
    /// Bits of `mode_sel` and `mode` (`Modes::select_bits`).
    pub bits: u32,
    /// `select = "pin"` (else the triggers decide).
    pub pin: bool,
    /// Address bits of one mode's table (the slot's); the mode sits above.
    pub slot_bits: usize,
    pub triggers: Vec<TrigPlan>,
}

/// One `[[trigger]]` in the gateware's terms.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrigPlan {
    pub to: usize,
    pub from: Option<usize>,
    pub above: bool,
    pub level: u32,
    pub for_frames: u32,
    /// Per branch, the watched channels it converts (empty: none).
    pub watch: Vec<Vec<u32>>,
}

impl TrigPlan {
    /// Armed in mode `m` (docs/timing.md: `from = m`, or no `from` and `to != m`).
    pub fn armed_in(&self, m: usize) -> bool {
        m != self.to && self.from.is_none_or(|f| f == m)
    }
    /// Bits of the run counter (counts to `for_frames`, saturating).
    pub fn run_bits(&self) -> usize {
        addr_bits(self.for_frames as u64 + 1)
    }
}

/// A branch's mode-specific ROM numbers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModeRom {
    /// Per mode: the mux field a word with the `w` bit takes when the next
    /// frame runs that mode, by the index `j` the word holds in its select
    /// field: the (select, device) of the branch's first instant (`j` = 0),
    /// or for a converter whose word selects the conversion `ahead` later,
    /// the input of the frame's conversion `j` (`j < ahead`: the words of a
    /// frame's last conversions select the next frame's first ones).
    /// Empty when the mode does not use the branch.
    pub first: Vec<Vec<(u32, u32)>>,
    /// Bits of the mode number on the address and in the `slice` input.
    pub mode_bits: usize,
}

impl ModeRom {
    /// The `w` words index the next mode's fields (a converter whose word
    /// selects a conversion two or more ahead): else every mode has one.
    pub fn indexed(&self) -> bool {
        self.first.iter().any(|f| f.len() > 1)
    }
}

fn unsupported(m: String) -> HdlError {
    HdlError::Unsupported(m)
}

/// Every mode's table into the plan's ROMs, and the mode block's numbers;
/// nothing for a mix without modes.
pub fn apply(s: &Schedule, p: &mut Plan) -> Result<(), HdlError> {
    let Some(m) = s.mode_plan().filter(|m| m.names.len() > 1) else {
        return Ok(());
    };
    let count = m.names.len();
    let bits = m.select_bits();
    let slot_bits = addr_bits(p.frame_slots);
    if p.compact {
        return Err(unsupported(format!(
            "a mix with modes needs the full frame table, but {} slots per frame of {} branches take the compact form",
            p.frame_slots,
            p.branches.len()
        )));
    }
    if p.frame_slots < 2 {
        return Err(unsupported(
            "a mix with modes needs at least 2 slots per frame (the next frame's table is read in the last slot)".into(),
        ));
    }
    if bits as usize > MODE_BITS || slot_bits + bits as usize > SLOT_BITS {
        return Err(unsupported(format!(
            "{count} modes of {} slots: the slot ROM's address has {SLOT_BITS} bits for the slot and the mode together",
            p.frame_slots
        )));
    }
    for b in 0..p.branches.len() {
        let used: Vec<bool> = s
            .modes
            .iter()
            .map(|ms| (0..p.frame_slots).any(|u| ms.at(u, b).is_some()))
            .collect();
        if !used[0] && used.iter().any(|u| *u) {
            return Err(unsupported(format!(
                "branch {}: the reset mode `{}` does not use it but another mode does: its mux would have no reset value to hold (give it a channel in `{}`)",
                s.branches[b].name, m.names[0], m.names[0]
            )));
        }
        let rom = &mut p.branches[b];
        rom.members = all_members(s, b, rom)?;
        fill(s, b, rom, bits as usize, slot_bits);
    }
    let triggers = match m.select {
        ModeSelect::Pin => vec![],
        ModeSelect::Auto => triggers(s, m)?,
    };
    p.modes = Some(ModePlan {
        count,
        bits,
        pin: m.select == ModeSelect::Pin,
        slot_bits,
        triggers,
    });
    Ok(())
}

/// The triggers with each watched channel by branch; a watched channel must
/// be its conversion's only word (the mode block reads the word as the
/// conversion completes, before the merger steps a chain).
fn triggers(s: &Schedule, m: &lut_gen::Modes) -> Result<Vec<TrigPlan>, HdlError> {
    let nb = s.branches.len();
    let mut out = vec![];
    for t in &m.triggers {
        let mut watch = vec![vec![]; nb];
        for &c in &t.channels {
            let b = s.mix.channels[c].branch;
            if s.mix.branches[b].chain > 1 {
                return Err(unsupported(format!(
                    "trigger at line {}: channel {} is on the chained branch {}: the gateware watches unchained branches only",
                    t.line, s.mix.channels[c].name, s.branches[b].name
                )));
            }
            watch[b].push(c as u32);
        }
        out.push(TrigPlan {
            to: t.to,
            from: t.from,
            above: t.when == When::Above,
            level: t.level,
            for_frames: t.for_frames.max(1),
            watch,
        });
    }
    Ok(out)
}

/// The chain members of every lead channel branch `b` converts in any mode.
fn all_members(s: &Schedule, b: usize, rom: &BranchRom) -> Result<Vec<(u32, Vec<u32>)>, HdlError> {
    let mut members = rom.members.clone();
    if rom.chain < 2 {
        return Ok(members);
    }
    for ms in &s.modes {
        for u in 0..s.grid.frame_slots {
            let Some(lead) = ms.at(u, b) else { continue };
            if members.iter().any(|(l, _)| *l as usize == lead) {
                continue;
            }
            let chans: Vec<u32> = ms.groups[lead]
                .iter()
                .flatten()
                .map(|c| *c as u32)
                .collect();
            if chans.len() != rom.chain as usize {
                return Err(unsupported(format!(
                    "branch {}: the conversion of channel {} reads {} chained words but only {} of them are declared channels",
                    s.branches[b].name, s.mix.channels[lead].name, rom.chain, chans.len()
                )));
            }
            members.push((lead as u32, chans));
        }
    }
    members.sort();
    Ok(members)
}

/// Branch `b`'s ROM: mode `m`'s word of slot `u` at address `m << slot_bits
/// | u`, `{w, conv, ch, sel, dev}` with `w` set when the mux field is the
/// next frame's, chosen as the word is read ([`ModeRom::first`], its index
/// in the select field): when the mode has no instant at slot `u` or
/// later, or when the word of the next instant selects a conversion of the
/// next frame (a converter whose word selects one `ahead`).
fn fill(s: &Schedule, b: usize, rom: &mut BranchRom, mode_bits: usize, slot_bits: usize) {
    let n = s.grid.frame_slots as usize;
    let top = rom.word_bits();
    let mut words = vec![0u32; 1 << (slot_bits + mode_bits)];
    let mut first = vec![];
    for (m, ms) in s.modes.iter().enumerate() {
        let slots: Vec<Option<usize>> = (0..n as u64).map(|u| ms.at(u, b)).collect();
        let fields = mode_fields(s, b, &slots);
        let mut next = None;
        for u in (0..n).rev() {
            if slots[u].is_some() {
                next = fields[u];
            }
            // no instant left: the next frame's first (index 0)
            let (wrap, (sel, dev)) = next.map_or((true, (0, 0)), |f| match f {
                Field::Here(sel, dev) => (false, (sel, dev)),
                Field::Next(j) => (true, (j, 0)),
            });
            let w = rom.word(slots[u].is_some(), slots[u].unwrap_or(0) as u32, sel, dev);
            words[(m << slot_bits) | u] = w | (wrap as u32) << top;
        }
        first.push(first_fields(s, b, &slots));
    }
    rom.words = words;
    rom.addr_bits = slot_bits + mode_bits;
    rom.modes = Some(ModeRom { first, mode_bits });
    if rom.front.is_none() && word_in_mux_field(s, b).is_some_and(|c| c.ahead > 0) {
        // The command unit takes the words from a table of its own, as
        // behind a front mux: the ROM's field is loaded a slot ahead, and
        // a frame's first word, when the frame has only `ahead` conversions,
        // selects a conversion of the frame after the next, whose mode is
        // decided only at the edge that begins the frame (the unit reads
        // the mode block's `nxt` as it loads the word there).
        let skipped = s.modes[0].at(0, b).is_some() && s.branches[b].settle_cycles > 1;
        rom.front = Some(FrontWords {
            inputs: s.commands_in_frame(b).iter().map(|w| w.input).collect(),
            first: skipped as u32,
            modes: None,
        });
    }
    if let Some(f) = &mut rom.front {
        f.modes = front_modes(s, b, mode_bits);
    }
}

/// The mux field of an instant: in the word, or the next frame's `j`-th.
#[derive(Debug, Clone, Copy)]
enum Field {
    Here(u32, u32),
    Next(u32),
}

/// The mux field of each instant of one mode's frame: the channel's
/// (select, device), or for a converter with a command word the input its
/// word selects, `ahead` conversions later (docs/timing.md, "Command
/// words"), past the frame's end the next frame's conversion `j`.
fn mode_fields(s: &Schedule, b: usize, slots: &[Option<usize>]) -> Vec<Option<Field>> {
    let mux = |c: usize| Field::Here(s.channels[c].select, s.channels[c].device);
    let Some(cmd) = word_in_mux_field(s, b) else {
        return slots.iter().map(|c| c.map(mux)).collect();
    };
    let convs: Vec<usize> = slots.iter().flatten().copied().collect();
    let input = |c: usize| s.mix.channels[c].input;
    let mut k = 0;
    let mut out = vec![None; slots.len()];
    for (u, c) in slots.iter().enumerate() {
        if c.is_some() {
            let i = k + cmd.ahead as usize;
            out[u] = Some(match convs.get(i) {
                Some(&c) => Field::Here(input(c) & 7, input(c) >> 3),
                None => Field::Next((i - convs.len()) as u32),
            });
            k += 1;
        }
    }
    out
}

/// The command word of branch `b` when the mux field carries the input it
/// selects: a converter with a command word and no front mux (behind one,
/// the field is the front mux's pins and the words are [`FrontModes`]).
fn word_in_mux_field(s: &Schedule, b: usize) -> Option<&lut_gen::Command> {
    let br = &s.mix.branches[b];
    br.adc.command.as_ref().filter(|_| !br.fronted)
}

/// The word of one conversion of a fronted branch's frame: the converter
/// input of a conversion of its own frame, or the index `j` of the next
/// frame's conversion it selects (that frame's mode decides its input).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrontWord {
    Here(u32),
    Next(u32),
}

/// A fronted branch's words in a mix with modes (the command unit's table
/// on the mode in force and the conversion counter; docs/timing.md,
/// "Command words"): every mode converts the branch at least `ahead`
/// times per frame (the mix check refuses less), so a `Next(j)` word
/// always finds the next frame's conversion `j`, in the mode decided
/// while this frame runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrontModes {
    /// Per mode, the word of each of its frame's conversions, in slot order.
    pub words: Vec<Vec<FrontWord>>,
    /// Per mode, the inputs of its frame's first `ahead` conversions.
    pub first: Vec<Vec<u32>>,
    /// Bits of the mode number.
    pub mode_bits: usize,
}

/// Branch `b`'s [`FrontModes`] (`None` without a front mux).
fn front_modes(s: &Schedule, b: usize, mode_bits: usize) -> Option<FrontModes> {
    let br = &s.mix.branches[b];
    let ahead = (br.adc.command.as_ref())
        .filter(|c| br.fronted || c.ahead > 0)?
        .ahead as usize;
    let input = |&c: &usize| s.mix.channels[c].input;
    let (mut words, mut first) = (vec![], vec![]);
    for ms in &s.modes {
        let convs: Vec<usize> = (0..s.grid.frame_slots)
            .filter_map(|u| ms.at(u, b))
            .collect();
        let n = convs.len();
        words.push(
            (0..n)
                .map(|k| match convs.get(k + ahead) {
                    Some(c) => FrontWord::Here(input(c)),
                    None => FrontWord::Next((k + ahead - n) as u32),
                })
                .collect(),
        );
        first.push(convs.iter().take(ahead).map(input).collect());
    }
    Some(FrontModes {
        words,
        first,
        mode_bits,
    })
}

/// [`ModeRom::first`] of one mode: what a `w` word with index `j` takes
/// when the next frame runs this mode (empty when it does not use the
/// branch).
fn first_fields(s: &Schedule, b: usize, slots: &[Option<usize>]) -> Vec<(u32, u32)> {
    let convs: Vec<usize> = slots.iter().flatten().copied().collect();
    let Some(cmd) = word_in_mux_field(s, b) else {
        let mux = |&c: &usize| (s.channels[c].select, s.channels[c].device);
        return convs.first().map(mux).into_iter().collect();
    };
    let input = |&c: &usize| (s.mix.channels[c].input & 7, s.mix.channels[c].input >> 3);
    match cmd.ahead {
        // the word of the next frame's first instant selects its own
        0 => convs.first().map(input).into_iter().collect(),
        a => convs.iter().take(a as usize).map(input).collect(),
    }
}
