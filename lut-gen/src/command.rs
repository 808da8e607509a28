//! The command words a schedule sends to converters that take one on DIN
//! (`adc_mosi`), and the pipeline they imply.
//!
//! A branch's conversions repeat every frame in slot order.  The word sent
//! with conversion `k` selects the channel of conversion `k + ahead` (the
//! part's `Command::ahead`), counted cyclically through the frame, so in a
//! steady run every conversion converts the channel the frame table names.
//! After reset the first `ahead` conversions of the branch were selected by
//! no word of ours: they are prepared, never read as data.

use crate::schedule::Schedule;

/// The command one conversion of a branch sends.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CommandSent {
    /// The frame slot of the conversion that carries the word.
    pub slot: u64,
    /// The channel (index into `Mix::channels`) the word selects, and its
    /// input number on the converter's multiplexer.
    pub selects: usize,
    pub input: u32,
    /// The word, first bit first (one bit per SCLK period).
    pub word: Vec<bool>,
}

impl Schedule {
    /// Whether branch `b`'s converter takes a command word (the branch then
    /// drives an `adc_mosi` bit).
    pub fn has_command(&self, b: usize) -> bool {
        self.mix.branches[b].adc.command.is_some()
    }

    /// Conversions of branch `b` after reset that are prepared, not data:
    /// the part's `ahead` (0 for a part without a command word).
    pub fn prepared_conversions(&self, b: usize) -> u32 {
        self.mix.branches[b]
            .adc
            .command
            .as_ref()
            .map_or(0, |c| c.ahead)
    }

    /// The words branch `b` sends in one frame, in slot order: one per
    /// conversion; empty for a branch without a command word.
    pub fn commands_in_frame(&self, b: usize) -> Vec<CommandSent> {
        let Some(cmd) = &self.mix.branches[b].adc.command else {
            return Vec::new();
        };
        let convs: Vec<(u64, usize)> = (0..self.grid.frame_slots)
            .filter_map(|s| self.at(s, b).map(|c| (s, c)))
            .collect();
        let n = convs.len();
        (0..n)
            .map(|k| {
                let (slot, _) = convs[k];
                let (_, selects) = convs[(k + cmd.ahead as usize) % n];
                let input = self.mix.channels[selects].input;
                CommandSent {
                    slot,
                    selects,
                    input,
                    word: cmd.word(input),
                }
            })
            .collect()
    }

    /// Whether branch `b`'s conversion number `k` after reset (0: its
    /// first) is prepared rather than read as data.
    pub fn is_prepared(&self, b: usize, k: u64) -> bool {
        k < self.prepared_conversions(b) as u64
    }
}
