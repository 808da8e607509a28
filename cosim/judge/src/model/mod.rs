//! The reference model and what a run is judged by: the model itself
//! ([`SlotModel`] for conversions over hours, [`CycleModel`] for every pin at
//! every cycle), the modes in force frame by frame, the mix's invariants with
//! the [`Rule`]s a violation names, and the [`Verdict`] a check reports.
//! Built from lut-gen's schedule alone; the lowest of the judge's rooms.

mod invariants;
mod mode_rules;
mod modes;
mod reference;
mod rule;
mod verdict;

pub use invariants::Invariants;
pub use modes::ModeTrack;
pub(crate) use reference::Conversion;
pub use reference::{CycleModel, SlotModel};
pub use rule::Rule;
pub use verdict::{counted, ChannelStats, Divergence, ModeStats, Verdict, Violation};
pub(crate) use verdict::{verdict_word, LinkJoin};
