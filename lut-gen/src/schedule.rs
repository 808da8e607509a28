//! The synthesized schedule: the data model every other crate builds on.
//!
//! Time is counted in clock cycles from the first rising edge after reset.
//! The frame is `frame_slots` slots; a channel occupies the slots
//! `offset_slot + k * period_slots` of every frame, so its sampling instants
//! (the first cycle of each of those slots, where CS falls) are exactly
//! `interval_cycles = clock / rate` apart, across frame boundaries too.

use serde::Serialize;

use crate::mix::Mix;
use crate::parts::SpiTiming;

/// The frame / slice / slot grid shared by all branches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct FrameGrid {
    pub clock_hz: u64,
    pub frame_cycles: u64,
    pub slice_cycles: u64,
    pub slices_per_frame: u64,
    pub slots_per_slice: u64,
    pub slot_cycles: u64,
    pub frame_slots: u64,
}

impl FrameGrid {
    pub fn new(mix: &Mix, slots_per_slice: u64) -> FrameGrid {
        let slice_cycles = mix.slice_cycles();
        FrameGrid {
            clock_hz: mix.clock_hz,
            frame_cycles: mix.frame_cycles(),
            slice_cycles,
            slices_per_frame: mix.slices_per_frame(),
            slots_per_slice,
            slot_cycles: slice_cycles / slots_per_slice,
            frame_slots: mix.slices_per_frame() * slots_per_slice,
        }
    }

    /// Where an absolute cycle falls: (frame, slot in frame, cycle in slot).
    pub fn locate(&self, cycle: u64) -> (u64, u64, u64) {
        let frame = cycle / self.frame_cycles;
        let in_frame = cycle % self.frame_cycles;
        (
            frame,
            in_frame / self.slot_cycles,
            in_frame % self.slot_cycles,
        )
    }
}

/// Per-branch timing derived from its parts and the clock.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BranchPlan {
    pub name: String,
    pub spi: SpiTiming,
    /// Cycles the mux must be steady before a sampling instant.
    pub settle_cycles: u64,
    /// Shortest legal slot: a whole conversion, quiet time, throughput limit,
    /// and the mux settling (it switches one cycle after the previous CS fall).
    pub min_slot_cycles: u64,
    pub mux_devices: u32,
}

/// Where one channel sits in the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ChannelSlots {
    pub samples_per_frame: u64,
    pub period_slots: u64,
    pub offset_slot: u64,
    pub interval_cycles: u64,
    /// Mux device and address: device = input / 8, select = input % 8.
    pub device: u32,
    pub select: u32,
}

/// How the placement was found (for reports and benchmarks).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Placement {
    /// Greedy first-fit in period order; exact for harmonic rates.
    Constructive,
    /// The exact search (`synth`): placements it tried on the chosen grid.
    Search { nodes: u64 },
}

/// A sampling instant: the cycle where a branch's CS falls for a channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct SamplingInstant {
    pub cycle: u64,
    pub branch: usize,
    pub channel: usize,
}

/// A complete, validated, jitter-free schedule.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Schedule {
    pub mix: Mix,
    pub grid: FrameGrid,
    pub branches: Vec<BranchPlan>,
    pub channels: Vec<ChannelSlots>,
    /// `frame_slots x branches`, row-major: the channel each branch converts in each slot.
    pub frame_table: Vec<Option<u16>>,
    pub placement: Placement,
    /// Per channel: the channels read in its conversion, by chain member
    /// (`Mix::conversion_group`); `[Some(c)]` for an unchained channel.
    #[serde(skip)]
    pub groups: Vec<Vec<Option<usize>>>,
    /// A mix with modes: every mode's schedule by mode number (the mix's
    /// `[[mode]]` order; `modes[0]`, the mode after reset, has this
    /// schedule's own table), all on this schedule's `grid`; each one's `mix`
    /// is `Mix::in_mode` without `modes` (rates of that mode, 0 for a
    /// channel it does not sample, whose `ChannelSlots` have no samples and
    /// no slot) and its own `modes` is empty. Empty for a mix without
    /// modes. This schedule's `mix` is `Mix::in_mode(0)` with `modes`: the
    /// select kind and the triggers (channels by index, levels as codes).
    #[serde(skip)]
    pub modes: Vec<Schedule>,
}

impl Schedule {
    /// `groups` of a mix.
    pub fn groups_of(mix: &Mix) -> Vec<Vec<Option<usize>>> {
        (0..mix.channels.len())
            .map(|c| mix.conversion_group(c))
            .collect()
    }

    /// The words one conversion of `lead` (a frame-table entry) delivers, in
    /// the order they leave the chain: (member, channel) for every member a
    /// channel reads.
    pub fn words_of(&self, lead: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.groups[lead]
            .iter()
            .enumerate()
            .filter_map(|(m, c)| c.map(|c| (m, c)))
    }

    pub fn branch_count(&self) -> usize {
        self.branches.len()
    }

    /// The channel branch `branch` converts in frame slot `slot`.
    pub fn at(&self, slot: u64, branch: usize) -> Option<usize> {
        self.frame_table[slot as usize * self.branches.len() + branch].map(usize::from)
    }

    /// docs/timing.md, "Start-up": whether the gateware skips branch `b`'s
    /// instant at cycle `t` of the first frame after reset.  The mux pins take
    /// their reset value at the first reset edge, so at instant `t` they have
    /// held it for `t + 1` cycles at the least (a one-cycle reset); an
    /// instant with `t + 1 < settle_cycles` would sample an unsettled mux.
    /// Slots are longer than the settling time, so only an instant at cycle 0
    /// can be skipped.
    pub fn skipped_at_startup(&self, b: usize, t: u64) -> bool {
        t + self.holdoff(b) + 1 < self.branches[b].settle_cycles
    }

    /// How many samples the instants of the first frame after reset that the
    /// gateware skips would have given (see [`Schedule::skipped_at_startup`];
    /// a chained conversion gives one sample per chain member).
    pub fn startup_skips(&self) -> u64 {
        (0..self.branches.len())
            .filter(|&b| self.skipped_at_startup(b, 0))
            .filter_map(|b| self.at(0, b))
            // a chained conversion gives one sample per chain member
            .map(|lead| self.words_of(lead).count() as u64)
            .sum()
    }

    /// Sampling instants of one branch within one frame, in time order.
    pub fn branch_instants_in_frame(&self, branch: usize) -> Vec<SamplingInstant> {
        (0..self.grid.frame_slots)
            .filter_map(|s| {
                self.at(s, branch).map(|c| SamplingInstant {
                    cycle: s * self.grid.slot_cycles,
                    branch,
                    channel: c,
                })
            })
            .collect()
    }

    /// Every sampling instant of every branch in frames `0..frames`, in
    /// (cycle, branch) order.
    pub fn instants(&self, frames: u64) -> impl Iterator<Item = SamplingInstant> + '_ {
        let b = self.branches.len();
        (0..frames).flat_map(move |f| {
            (0..self.grid.frame_slots).flat_map(move |s| {
                (0..b).filter_map(move |br| {
                    self.at(s, br).map(|c| SamplingInstant {
                        cycle: f * self.grid.frame_cycles + s * self.grid.slot_cycles,
                        branch: br,
                        channel: c,
                    })
                })
            })
        })
    }

    /// First sampling instant of a channel after reset: its first
    /// conversion's start plus its part's [`Schedule::sample_after`].
    pub fn first_sample_cycle(&self, channel: usize) -> u64 {
        self.channels[channel].offset_slot * self.grid.slot_cycles
            + self.sample_after(self.mix.channels[channel].branch)
    }

    /// Cycles from the slot tick of a conversion of `branch` (the cycle
    /// [`Schedule::instants`] gives) to the instant its part holds its
    /// input: the branch's hold-off ([`Schedule::holdoff`]) plus its part's
    /// own `SpiTiming::sample_cycles` (0 for a part that samples at its
    /// start edge; the MCP3208's falling SCLK edge after its 6th rising one).
    pub fn sample_after(&self, branch: usize) -> u64 {
        self.branches[branch].spi.tick_to_sample()
    }

    /// Cycles from the slot tick to the start of a conversion of `branch`
    /// (its CS fall or CNV rise): 0 unless a sync group holds the branch
    /// back for a part that samples later in its transaction.
    pub fn holdoff(&self, branch: usize) -> u64 {
        self.branches[branch].spi.holdoff_cycles
    }

    /// The sampling instant of the sample of `channel` that leaves on
    /// `sample_valid` in cycle `strobe` (docs/timing.md, "Merged sample
    /// stream"): for the channel's last conversion start `t` with
    /// `t + R + 1 <= strobe`, `R` its branch's read, the instant its part
    /// holds its input, `t + sample_after(branch)`.  A word waits behind other branches' words for
    /// fewer cycles than the channel's interval, so no later instant can have
    /// completed first; `None` when no instant of the channel has completed
    /// by `strobe` (or the channel does not exist).
    pub fn sampled_at(&self, channel: usize, strobe: u64) -> Option<u64> {
        let ch = self.channels.get(channel)?;
        if ch.samples_per_frame == 0 {
            return None;
        }
        let branch = self.mix.channels[channel].branch;
        let first = ch.offset_slot * self.grid.slot_cycles;
        let last = strobe.checked_sub(self.branches[branch].spi.tick_to_complete() + 1)?;
        let n = last.checked_sub(first)? / ch.interval_cycles.max(1);
        Some(first + n * ch.interval_cycles + self.sample_after(branch))
    }

    /// The mix's modes (select kind, names, triggers), if it has any.
    pub fn mode_plan(&self) -> Option<&crate::mix::Modes> {
        self.mix.modes.as_ref()
    }

    /// Samples converted per frame by all branches.
    pub fn samples_per_frame(&self) -> u64 {
        self.channels.iter().map(|c| c.samples_per_frame).sum()
    }

    /// Bits needed for a channel index (at least 1).
    pub fn channel_bits(&self) -> u32 {
        bits_for(self.channels.len() as u64)
    }
}

/// `cycle / clock_hz` seconds as text, rounded once to 1 ps (12 decimals):
/// the one formatting of a time in cycles that every CSV uses, so the same
/// instant reads the same in each (no float in between, no drift).
pub fn seconds(cycle: u64, clock_hz: u64) -> String {
    let hz = clock_hz.max(1) as u128;
    let ps = (cycle as u128 * 2_000_000_000_000 + hz) / (2 * hz);
    format!("{}.{:012}", ps / 1_000_000_000_000, ps % 1_000_000_000_000)
}

/// Bits to hold values `0..n` (at least 1).
pub fn bits_for(n: u64) -> u32 {
    if n <= 2 {
        1
    } else {
        64 - (n - 1).leading_zeros()
    }
}
