//! The command words a design sends on `adc_mosi`, read back from its pins
//! without the model (docs/timing.md, "Command words"): the part latches
//! DIN at each rising edge of its serial clock while it is selected, and the
//! word selects the input of the branch's conversion `ahead` conversions
//! later (0: the conversion that carries it).  The checker asks it which
//! channel each conversion converted, so a sample can be held to the channel
//! its command selected, not to the one the design claims.

use std::collections::{BTreeMap, VecDeque};

use lut_gen::{Command, Schedule};

/// What a conversion of a commanded branch converts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Selected {
    /// One of the first `ahead` conversions after reset: no word of ours
    /// selected it, so it is prepared, never data.
    Prepared,
    /// The check joined mid-stream and did not see the word that selected it.
    Unknown,
    /// The word sent in the conversion that began at `sent_at` (cycle):
    /// `channel` the mix's channel on the input it selects (`None`: the word
    /// is malformed or selects an input no channel of the branch is on).
    Word { sent_at: u64, channel: Option<u16> },
}

/// A word that is not one the part would take as the mix meant it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct BadWord {
    /// The cycle of the conversion that carried it.
    pub sent_at: u64,
    pub bits: String,
    pub why: String,
}

/// One commanded branch's words, as the part latches them.
#[derive(Debug, Clone)]
pub(crate) struct CommandRead {
    cmd: Command,
    /// The channel on each input of the converter's own multiplexer.
    inputs: Vec<Option<u16>>,
    /// Behind a front mux (`front_mux`): per converter input wired to it,
    /// the channel on each front input (device * 8 + select); empty for an
    /// input wired straight.  Such a conversion converts the channel of the
    /// input its word selected AND the front pins at its sampling instant.
    front: Vec<BTreeMap<u32, u16>>,
    /// The front mux's input the pins addressed at the conversion's start.
    pin: Option<u32>,
    /// DIN bits latched in the conversion in progress (first first), and its start.
    din: Vec<bool>,
    t: u64,
    /// What the coming conversions convert (a pipelined part: `ahead`
    /// long), and the converter input the word selected (the front pins
    /// at the conversion settle the channel of a fronted one).
    queue: VecDeque<(Selected, Option<u32>)>,
}

impl CommandRead {
    /// Branch `b`'s reader, after reset; `None` for a listening part.
    pub fn new(s: &Schedule, b: usize) -> Option<CommandRead> {
        let cmd = s.mix.branches[b].adc.command.clone()?;
        let mut inputs = vec![None; cmd.channels() as usize];
        let mut front = vec![BTreeMap::new(); inputs.len()];
        for (c, ch) in s.mix.channels.iter().enumerate() {
            if ch.branch == b && (ch.input as usize) < inputs.len() {
                match ch.front_input {
                    Some(f) => _ = front[ch.input as usize].insert(f, c as u16),
                    None => inputs[ch.input as usize] = Some(c as u16),
                }
            }
        }
        let queue = std::iter::repeat_n((Selected::Prepared, None), cmd.ahead as usize).collect();
        Some(CommandRead {
            cmd,
            inputs,
            front,
            pin: None,
            din: Vec::new(),
            t: 0,
            queue,
        })
    }

    /// A check that joins mid-stream: the words in flight were not seen.
    pub fn join(&mut self) {
        self.queue.iter_mut().for_each(|q| q.0 = Selected::Unknown);
        self.t = u64::MAX;
    }

    /// The bits the word has.
    pub fn len(&self) -> usize {
        self.cmd.bits.len()
    }

    /// Whether some input is wired through a front mux (the branch's mux
    /// pins are then the front mux's).
    pub fn fronted(&self) -> bool {
        self.front.iter().any(|f| !f.is_empty())
    }

    /// A conversion begins at `c` with the front mux's pins on input `pin`
    /// (`None`: no front mux, or not one device enabled): what it converts,
    /// if its word came earlier (a pipelined part), else `None` (the word is
    /// in this read).
    pub fn start(&mut self, c: u64, pin: Option<u32>) -> Option<Selected> {
        self.din.clear();
        self.t = c;
        self.pin = pin;
        if self.cmd.ahead == 0 {
            return None;
        }
        let (sel, input) = self.queue.pop_front().unwrap_or((Selected::Unknown, None));
        Some(match (sel, input) {
            (Selected::Word { sent_at, .. }, Some(i)) => Selected::Word {
                sent_at,
                channel: self.channel_on(i),
            },
            (sel, _) => sel,
        })
    }

    /// The channel on converter input `i` under the front pins of this
    /// conversion.
    fn channel_on(&self, i: u32) -> Option<u16> {
        match self.front.get(i as usize) {
            Some(f) if !f.is_empty() => self.pin.and_then(|p| f.get(&p).copied()),
            _ => self.inputs.get(i as usize).copied().flatten(),
        }
    }

    /// DIN `v` latched at a rising edge of the serial clock; once the word
    /// is whole, for a part that converts in the same read, what it selects.
    pub fn latch(&mut self, v: bool) -> Option<Selected> {
        self.din.push(v);
        (self.cmd.ahead == 0 && self.din.len() == self.len()).then(|| self.selected())
    }

    /// The read ends: what the word selects (a pipelined part queues it for
    /// a later conversion; a part that converts in the same read and did
    /// not see its whole word gets `Some`, the word malformed).
    pub fn end(&mut self) -> Option<Selected> {
        let sel = self.selected();
        if self.cmd.ahead > 0 {
            let input = (self.t != u64::MAX)
                .then(|| self.cmd.channel_of(&self.din))
                .flatten();
            self.queue.push_back((sel, input));
            return None;
        }
        (self.din.len() < self.len()).then_some(sel)
    }

    /// What the bits latched so far select.
    fn selected(&self) -> Selected {
        if self.t == u64::MAX {
            return Selected::Unknown;
        }
        let channel = self
            .cmd
            .channel_of(&self.din)
            .and_then(|i| self.channel_on(i));
        Selected::Word {
            sent_at: self.t,
            channel,
        }
    }

    /// Why the word of the read just ended is not one the mix would send,
    /// if it is not (call before the next [`CommandRead::start`]).
    pub fn bad_word(&self) -> Option<BadWord> {
        if self.t == u64::MAX {
            return None;
        }
        let n = self.len();
        let bits: String = self
            .din
            .iter()
            .take(n)
            .map(|&b| if b { '1' } else { '0' })
            .collect();
        let why = if self.din.len() < n {
            format!(
                "only {} of the word's {n} bits were clocked in",
                self.din.len()
            )
        } else {
            match self.cmd.channel_of(&self.din) {
                None => format!(
                    "a fixed bit differs from the part's word {}",
                    self.cmd.template()
                ),
                Some(i)
                    if self.inputs.get(i as usize).copied().flatten().is_none()
                        && self.front.get(i as usize).is_none_or(|f| f.is_empty()) =>
                {
                    format!("it selects input {i}, where the branch has no channel")
                }
                Some(_) => return None,
            }
        };
        Some(BadWord {
            sent_at: self.t,
            bits,
            why,
        })
    }
}
