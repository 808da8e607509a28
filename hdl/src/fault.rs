//! Faults the gateware itself can suffer: a corrupted slot-ROM word, two
//! words swapped, a counter that wraps one slot or slice early or late.
//! They are built into the real blocks (the plan the core is generated
//! from), so the checker is tested against what the gateware would do, not
//! against a pin-level imitation of it.

use crate::plan::{LutForm, Plan};
use crate::HdlError;

/// A design-level fault of the gateware.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GatewareFault {
    /// Branch `branch`'s slot-ROM word for frame slot `slot` holds the word
    /// of frame slot `from` instead (another channel's entry).
    RomWord { branch: usize, slot: u64, from: u64 },
    /// Branch `branch`'s slot-ROM words of frame slots `a` and `b` swapped.
    RomSwap { branch: usize, a: u64, b: u64 },
    /// The slot counter wraps after `frame_slots + delta` slots (full LUT).
    SlotWrap { delta: i64 },
    /// The slice counter wraps after `slices_per_frame + delta` slices
    /// (compact LUT, whose slot counter counts slots in the slice).
    SliceWrap { delta: i64 },
    /// The link's FIFO one token shallower than the schedule's worst-case
    /// backlog: it overflows.
    LinkFifoShort,
    /// The link's baud divider off by `delta` cycles per bit.
    LinkBaud { delta: i32 },
    /// The link's CRC starts from 0 instead of 0xFFFF.
    LinkCrcInit,
    /// A mix with modes: the mode register never leaves the reset mode
    /// (pin select: it takes only mode 0 from `mode_sel`; auto select: no
    /// trigger's level can be crossed).
    ModeStuck,
}

/// The fault in a report's words (fault campaigns name each injection by it).
impl std::fmt::Display for GatewareFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            GatewareFault::RomWord { branch, slot, from } => write!(
                f,
                "branch {branch}'s ROM word for slot {slot} holds slot {from}'s"
            ),
            GatewareFault::RomSwap { branch, a, b } => {
                write!(
                    f,
                    "branch {branch}'s ROM words of slots {a} and {b} swapped"
                )
            }
            GatewareFault::SlotWrap { delta } => {
                write!(f, "slot counter wraps {delta:+} slots off the frame")
            }
            GatewareFault::SliceWrap { delta } => {
                write!(f, "slice counter wraps {delta:+} slices off the frame")
            }
            GatewareFault::LinkFifoShort => write!(f, "link FIFO one token too shallow"),
            GatewareFault::LinkBaud { delta } => {
                write!(f, "link baud divider {delta:+} cycles per bit")
            }
            GatewareFault::LinkCrcInit => write!(f, "link CRC starts from 0"),
            GatewareFault::ModeStuck => write!(f, "mode register never leaves the reset mode"),
        }
    }
}

impl GatewareFault {
    /// The LUT form the fault lives in.
    pub fn lut_form(&self) -> LutForm {
        match self {
            GatewareFault::SliceWrap { .. } => LutForm::Compact,
            // the link does not depend on the LUT's form
            GatewareFault::LinkFifoShort
            | GatewareFault::LinkBaud { .. }
            | GatewareFault::LinkCrcInit
            | GatewareFault::ModeStuck => LutForm::Auto,
            _ => LutForm::Full,
        }
    }

    /// One fault of each link class, for a mix with a `[link]` (none without).
    pub fn link_faults(s: &lut_gen::Schedule) -> Vec<(&'static str, GatewareFault)> {
        let Some(link) = &s.mix.link else {
            return Vec::new();
        };
        let mut v = vec![
            ("link-fifo-short", GatewareFault::LinkFifoShort),
            ("link-crc-init", GatewareFault::LinkCrcInit),
        ];
        // an AXI4-Stream link has no baud divider to get wrong
        if link.kind == lut_gen::LinkKind::Uart {
            v.insert(1, ("link-baud-fast", GatewareFault::LinkBaud { delta: -1 }));
        }
        v
    }

    /// The mode faults of a mix with modes (none without).
    pub fn mode_faults(s: &lut_gen::Schedule) -> Vec<(&'static str, GatewareFault)> {
        if s.modes.len() > 1 {
            vec![("mode-stuck", GatewareFault::ModeStuck)]
        } else {
            Vec::new()
        }
    }

    pub(crate) fn apply(&self, p: &mut Plan) -> Result<(), HdlError> {
        let bad = |m: String| HdlError::Unsupported(format!("fault {self:?}: {m}"));
        let wrap = |n: u64, delta: i64| -> Result<u64, HdlError> {
            let v = n as i64 + delta;
            if v < 1 {
                return Err(bad(format!("a counter of {n} cannot wrap {delta} early")));
            }
            Ok(v as u64)
        };
        match *self {
            GatewareFault::RomWord { branch, slot, from } => {
                let w = rom(p, branch).map_err(bad)?;
                let (s, f) = (slot as usize, from as usize);
                if s >= w.len() || f >= w.len() {
                    return Err(bad("slot outside the frame".into()));
                }
                w[s] = w[f];
                set_table_channels(p, branch, &[(s, f)]);
            }
            GatewareFault::RomSwap { branch, a, b } => {
                let w = rom(p, branch).map_err(bad)?;
                let (a, b) = (a as usize, b as usize);
                if a >= w.len() || b >= w.len() {
                    return Err(bad("slot outside the frame".into()));
                }
                w.swap(a, b);
                set_table_channels(p, branch, &[(a, b), (b, a)]);
            }
            GatewareFault::SlotWrap { delta } => {
                if p.compact || p.logic {
                    return Err(bad("the plan has no frame-wide slot counter".into()));
                }
                p.frame_slots = wrap(p.frame_slots, delta)?;
            }
            GatewareFault::SliceWrap { delta } => {
                if !p.compact {
                    return Err(bad("the plan has a full LUT".into()));
                }
                p.slices_per_frame = wrap(p.slices_per_frame, delta)?;
            }
            GatewareFault::ModeStuck => {
                let m = p
                    .modes
                    .as_mut()
                    .ok_or_else(|| bad("the mix has no modes".into()))?;
                // pin: a request names a mode only below `count`
                m.count = 1;
                // auto: no code is above the top one or below 0
                for t in &mut m.triggers {
                    t.level = if t.above {
                        (1 << crate::widths::VALUE_BITS) - 1
                    } else {
                        0
                    };
                }
            }
            GatewareFault::LinkFifoShort
            | GatewareFault::LinkBaud { .. }
            | GatewareFault::LinkCrcInit => {
                let l = p
                    .link
                    .as_mut()
                    .ok_or_else(|| bad("the mix has no link".into()))?;
                match *self {
                    GatewareFault::LinkFifoShort if l.depth > 1 => l.depth -= 1,
                    GatewareFault::LinkFifoShort => {
                        return Err(bad("a FIFO of one token cannot be shorter".into()))
                    }
                    GatewareFault::LinkBaud { delta } => {
                        l.div = l
                            .div
                            .checked_add_signed(delta)
                            .filter(|&d| d >= 2)
                            .ok_or_else(|| {
                                bad(format!("a divider of {} cannot change by {delta}", l.div))
                            })?
                    }
                    _ => l.crc_init = 0,
                }
            }
        }
        Ok(())
    }
}

/// Branch `b`'s full-frame ROM words.
fn rom(p: &mut Plan, b: usize) -> Result<&mut Vec<u32>, String> {
    if p.compact || p.logic {
        return Err("the plan has no full-frame slot ROM".into());
    }
    p.branches
        .get_mut(b)
        .map(|r| &mut r.words)
        .ok_or_else(|| format!("no branch {b}"))
}

/// A ROM fault where the queue form's channels come from the merger's
/// table (`Plan::lane_ch`): for each `(s, f)`, the channel lane `lane` puts
/// out in frame slot `s` becomes slot `f`'s (read before any is written), as
/// the lane's ROM channel field did before the table.
fn set_table_channels(p: &mut Plan, lane: usize, moves: &[(usize, usize)]) {
    let fs = p.frame_slots as usize;
    let Some(t) = p.lane_ch.as_mut() else { return };
    if lane >= 1 << t.k_bits {
        return;
    }
    let at = |u: usize| (((u + 1) % fs) << t.k_bits) | lane;
    let mask = (1u32 << t.ch_bits) - 1;
    let chans: Vec<u32> = moves.iter().map(|&(_, f)| t.words[at(f)] & mask).collect();
    for (&(s, _), ch) in moves.iter().zip(chans) {
        let i = at(s);
        t.words[i] = (t.words[i] & !mask) | ch;
    }
}
