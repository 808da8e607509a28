//! The audit: what an engineer asks before touching hardware.  Does the mix
//! fit, at what exact rates, with what jitter, how much room is left, does
//! every mux settle in time, and is every signal sampled above Nyquist?
//!
//! Everything here is measured on the frame table itself (not on the
//! synthesizer's intentions), so the audit doubles as a second opinion.

use serde::Serialize;

use crate::lut::CompactLut;
use crate::parts::cycles_to_ns;
use crate::schedule::{Placement, Schedule};
use crate::synth::Infeasible;

mod modes;
mod text;

pub use modes::{ModeAudit, ModeBranch, ModeChannel, ModeLink, TriggerAudit};
// For this crate's tests only (`crate::for_tests`).
pub use modes::compact;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AuditReport {
    pub mix: String,
    pub feasible: bool,
    /// For a mix without a schedule: `infeasible` (proved) or `unknown` (the
    /// exact search's bound ran out first; exit code 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<crate::Verdict>,
    pub clock_hz: u64,
    pub frame_cycles: u64,
    pub slice_cycles: u64,
    pub slot_cycles: u64,
    pub slots_per_slice: u64,
    pub samples_per_frame: u64,
    /// Sum of all channels' rates.
    pub aggregate_hz: u64,
    /// The ADCs' physical limit: the sum of the branches' `adc_max_sps`.
    pub adc_limit_hz: f64,
    pub adc_utilization: f64,
    pub placement: String,
    pub lut_entries_compact: usize,
    pub lut_entries_full: usize,
    pub errors: Vec<String>,
    /// Which of `errors` is the link's (a line the mix's worst mode cannot
    /// carry): the mode tables leave it to the report's own.
    #[serde(skip)]
    pub link_error: Option<String>,
    pub warnings: Vec<String>,
    /// Facts worth knowing that are neither errors nor warnings (e.g. an
    /// SCLK the clock cannot give exactly).
    pub notes: Vec<String>,
    pub branches: Vec<BranchAudit>,
    /// What each branch's converter allows (throughput, bits, chain).
    pub parts: Vec<PartAudit>,
    pub channels: Vec<ChannelAudit>,
    /// The link to the host (`[link]`): divider, bytes per frame, line
    /// utilisation, FIFO depth, worst latency, minimum baud.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link: Option<crate::hostlink::LinkPlan>,
    /// Only without a schedule: the changes that make the mix fit, each
    /// applied and audited feasible first, cheapest first (empty: none
    /// found), and how many changes were tried.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fixes: Option<Vec<crate::fixes::Fix>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fixes_tried: Option<usize>,
    /// A mix with modes (the figures above are the reset mode's): how the
    /// mode is selected, every mode's table, and each trigger's worst
    /// reaction. Absent for a mix without modes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode_select: Option<crate::mix::ModeSelect>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub modes: Vec<ModeAudit>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub triggers: Vec<TriggerAudit>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartAudit {
    pub branch: String,
    pub adc: String,
    /// `cs` (CS falling samples) or `cnv` (CNV rising samples).
    pub start: crate::parts::Start,
    pub bits: u32,
    /// Parts daisy-chained on the branch, and how many the part allows.
    pub chain: u32,
    pub chain_max: u32,
    /// The part's throughput limit, per part.
    pub max_sps: u64,
    pub sclk_max_hz: u64,
    pub conversion_ns: u64,
    /// Cycles one conversion holds the port (conversion + every word read).
    pub read_cycles: u64,
    /// Conversions per second the converter allows on this port (its
    /// conversion, every word read at the SCLK used, the quiet time, the
    /// datasheet's rate), and samples per second (times the chain): the
    /// branch's `adc_max_sps`, the same value.
    pub max_conversions_hz: f64,
    pub max_samples_hz: f64,
    /// The supply whose datasheet figures (`max_sps`, `sclk_max_hz`,
    /// `conversion_ns`) apply, in volts: the branch's `vdd`, or the part's
    /// lowest supply when the mix says none (`vdd_given` false); `None`
    /// for a declared part (one set of figures).
    pub vdd_v: Option<f64>,
    pub vdd_given: bool,
    /// Where the part holds its input: at the conversion's start edge, or
    /// at a falling SCLK edge inside its transaction; and how long after
    /// the start edge that is (cycles, and ns): what `sampled_s` adds to
    /// the conversion's start.
    pub sample_at: crate::parts::SampleAt,
    pub sample_after_cycles: u64,
    pub sample_after_ns: f64,
    /// The branch's hold-off: cycles (and ns) from the slot tick to its
    /// transaction's start, for a sync group whose other parts hold their
    /// inputs later in theirs (absent when 0). `sampled_s` adds it too.
    #[serde(skip_serializing_if = "is_zero")]
    pub holdoff_cycles: u64,
    #[serde(skip_serializing_if = "is_zero_f")]
    pub holdoff_ns: f64,
}

fn is_zero(v: &u64) -> bool {
    *v == 0
}

fn is_zero_f(v: &f64) -> bool {
    *v == 0.0
}

impl PartAudit {
    fn of(
        mix: &crate::mix::Mix,
        b: usize,
        plan: Option<&crate::schedule::BranchPlan>,
    ) -> PartAudit {
        let br = &mix.branches[b];
        let a = &br.adc;
        let spi = plan.map(|p| p.spi).or_else(|| br.timing(mix.clock_hz).ok());
        let samples_hz = br.max_samples_hz(mix.clock_hz);
        PartAudit {
            branch: br.name.clone(),
            adc: a.name.clone(),
            start: a.start,
            bits: a.bits,
            chain: br.chain,
            chain_max: a.chain_max,
            max_sps: a.max_sps,
            sclk_max_hz: a.sclk_max_hz,
            conversion_ns: a.conversion_ns,
            read_cycles: spi.map(|t| t.read_cycles).unwrap_or(0),
            max_conversions_hz: samples_hz / br.chain as f64,
            max_samples_hz: samples_hz,
            vdd_v: br.supply_mv().map(|mv| mv as f64 / 1000.0),
            vdd_given: br.vdd_mv.is_some(),
            sample_at: a.sample,
            sample_after_cycles: spi.map_or(0, |t| t.sample_cycles),
            sample_after_ns: cycles_to_ns(spi.map_or(0, |t| t.sample_cycles), mix.clock_hz),
            holdoff_cycles: spi.map_or(0, |t| t.holdoff_cycles),
            holdoff_ns: cycles_to_ns(spi.map_or(0, |t| t.holdoff_cycles), mix.clock_hz),
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BranchAudit {
    pub name: String,
    /// Of the slot grid: conversions per frame over slots per frame.
    pub utilization: f64,
    pub conversions_per_frame: u64,
    pub slots_per_frame: u64,
    /// Samples per second the branch's channels demand (sum of their rates).
    pub demand_sps: u64,
    /// The most samples per second the branch's converter delivers at this
    /// clock and SCLK (`lut_gen::Branch::max_samples_hz`): the datasheet's
    /// rate, or less when a conversion and its read take longer.
    pub adc_max_sps: f64,
    /// Of the ADC: `demand_sps / adc_max_sps`.
    pub adc_utilization: f64,
    /// SCLK asked for (`sclk_hz` in the mix, or the ADC's maximum by default).
    pub sclk_requested_hz: u64,
    /// Whether the mix sets `sclk_hz` (else the ADC's maximum is asked for).
    pub sclk_explicit: bool,
    /// SCLK used: `clock_hz / sclk_div`.
    pub sclk_hz: f64,
    /// System clocks per SCLK period (even, so the duty is exactly 50 %).
    pub sclk_div: u64,
    pub min_slot_cycles: u64,
    pub free_mux_inputs: u32,
    /// How many more channels of each rate present in the mix would still fit.
    pub headroom: Vec<Headroom>,
    /// The command word of a converter that takes one (`None`: it only listens).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<CommandAudit>,
}

/// A branch's command word and the pipeline it implies.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct CommandAudit {
    /// The word's template (`0`, `1`, `C` a channel bit), first bit first.
    pub template: String,
    /// Conversions ahead the word applies (0: the one it is sent in).
    pub ahead: u32,
    /// Conversions after reset that are prepared, never read as data.
    pub prepared_conversions: u32,
}

impl CommandAudit {
    fn of(mix: &crate::Mix, b: usize) -> Option<CommandAudit> {
        mix.branches[b].adc.command.as_ref().map(|c| CommandAudit {
            template: c.template(),
            ahead: c.ahead,
            // `Schedule::prepared_conversions`: the part's `ahead`.
            prepared_conversions: c.ahead,
        })
    }
}

/// Which limit ends a branch's headroom at one rate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Limit {
    /// No free mux input left for another channel.
    MuxInputs,
    /// The ADC's maximum samples per second.
    AdcThroughput,
    /// The free slots of the slot grid.
    SlotGrid,
}

impl Limit {
    pub fn describe(self) -> &'static str {
        match self {
            Limit::MuxInputs => "free mux inputs",
            Limit::AdcThroughput => "ADC throughput",
            Limit::SlotGrid => "slot grid",
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Headroom {
    pub rate_hz: u64,
    /// Further channels at this rate on this branch: the least of the three
    /// limits below.
    pub more_channels: u64,
    /// The limit that binds (the first of inputs, ADC, grid at the minimum).
    pub binding: Limit,
    /// Channels the free mux inputs allow.
    pub by_mux_inputs: u64,
    /// Channels the ADC's remaining throughput allows: `(max_sps - demand) / rate`.
    pub by_adc_throughput: u64,
    /// Channels the free slots of the current slot grid hold.
    pub by_slot_grid: u64,
    /// A finer slot grid (more slots per slice, still legal for every
    /// branch) on which more would fit; `None` when none would.
    pub finer_grid: Option<FinerGrid>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FinerGrid {
    pub slots_per_slice: u64,
    pub slot_cycles: u64,
    /// Further channels at this rate with that grid (least of the limits).
    pub more_channels: u64,
    pub binding: Limit,
    /// Channels that grid's free slots hold after re-placing the branch's channels.
    pub by_slot_grid: u64,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelAudit {
    pub name: String,
    /// The value `sample_channel` carries for this channel: its index in the
    /// mix file, 0-based, in file order of the `[[channel]]` tables.
    pub sample_channel: usize,
    pub branch: String,
    pub requested_hz: u64,
    pub achieved_hz: f64,
    pub samples_per_frame: u64,
    pub interval_cycles: u64,
    pub jitter_cycles: u64,
    pub first_sample_cycle: u64,
    pub device: u32,
    pub select: u32,
    /// On a branch whose converter picks its input (`mux = "internal"`):
    /// that input; `device`/`select` are then a front mux's pins (0.0 for a
    /// channel wired straight), or, without a front mux, the input again.
    pub adc_input: Option<u32>,
    /// Whether the channel is behind a front mux (`front_input`).
    pub front_mux: bool,
    /// Shortest time the mux has to settle before one of this channel's instants.
    pub settle_available_ns: f64,
    pub settle_required_ns: u64,
    pub bandwidth_hz: Option<f64>,
    /// `rate / 2`, against which `bandwidth_hz` is checked.
    pub nyquist_hz: f64,
    /// Where a tone at `bandwidth_hz` shows up when that is above Nyquist:
    /// the folded frequency `|f - k rate|` nearest 0 ([`alias_hz`]).
    pub alias_hz: Option<f64>,
}

impl ChannelAudit {
    /// Where the channel is wired, as the audit's `dev.sel` column and the
    /// report write it: an external mux's device and select (`0.3`), the
    /// converter's own input on a branch with `mux = "internal"` (`in2`),
    /// or both with a front mux (`in2/0.3`).
    pub fn mux_words(&self) -> String {
        match self.adc_input {
            None => format!("{}.{}", self.device, self.select),
            Some(k) if self.front_mux => format!("in{k}/{}.{}", self.device, self.select),
            Some(k) => format!("in{k}"),
        }
    }
}

impl AuditReport {
    pub fn of_schedule(s: &Schedule) -> AuditReport {
        let g = &s.grid;
        let nb = s.branches.len();
        let mix = &s.mix;
        let mut warnings = Vec::new();
        let mut errors = Vec::new();

        // Instants per branch over one frame, straight from the table.
        let branch_slots: Vec<Vec<u64>> = (0..nb)
            .map(|b| {
                (0..g.frame_slots)
                    .filter(|&t| s.at(t, b).is_some())
                    .collect()
            })
            .collect();

        let channels = (0..mix.channels.len())
            .map(|c| ChannelAudit::of(s, c, &branch_slots, &mut errors, &mut warnings))
            .collect();

        let mut rates: Vec<u64> = mix.channels.iter().map(|c| c.rate_hz).collect();
        rates.sort_unstable();
        rates.dedup();
        // (0: a channel the mode does not sample, no headroom to give)
        rates.retain(|&r| r > 0);
        let finer = FinerGrids::of(s);
        let branches: Vec<BranchAudit> = (0..nb)
            .map(|b| BranchAudit::of(s, b, &branch_slots[b], &rates, &finer))
            .collect();
        let notes = sclk_notes(&branches, g.clock_hz);

        let aggregate_hz: u64 = mix.channels.iter().map(|c| c.rate_hz).sum();
        let adc_limit_hz = adc_limit_hz(mix);
        let lut = CompactLut::from_schedule(s);
        let mut link_error = None;
        let link = match crate::hostlink::plan(s) {
            None => None,
            Some(Ok(p)) => Some(p),
            Some(Err(e)) => {
                errors.push(e.message.clone());
                link_error = Some(e.message);
                None
            }
        };
        let mut report = AuditReport {
            mix: mix.name.clone(),
            feasible: errors.is_empty(),
            verdict: None,
            link,
            clock_hz: g.clock_hz,
            frame_cycles: g.frame_cycles,
            slice_cycles: g.slice_cycles,
            slot_cycles: g.slot_cycles,
            slots_per_slice: g.slots_per_slice,
            samples_per_frame: s.samples_per_frame(),
            aggregate_hz,
            adc_limit_hz,
            adc_utilization: aggregate_hz as f64 / adc_limit_hz,
            placement: match s.placement {
                Placement::Constructive => "constructive (first-fit)".into(),
                Placement::Search { nodes } => format!("exact search ({nodes} nodes)"),
            },
            parts: (0..nb)
                .map(|b| PartAudit::of(mix, b, Some(&s.branches[b])))
                .collect(),
            lut_entries_compact: lut.entries(),
            lut_entries_full: g.frame_slots as usize * nb,
            errors,
            link_error,
            warnings,
            notes,
            branches,
            channels,
            fixes: None,
            fixes_tried: None,
            mode_select: None,
            modes: Vec::new(),
            triggers: Vec::new(),
        };
        report.add_modes(s);
        report
    }

    /// The report of a mix with no schedule: the diagnosis becomes `errors`.
    pub fn of_infeasible(mix: &crate::Mix, why: &Infeasible) -> AuditReport {
        let mut errors = why.reasons.clone();
        for b in &why.branches {
            if !b.unplaced.is_empty() || b.demand_slots_per_frame > b.capacity_slots_per_frame {
                errors.push(format!(
                    "branch `{}`: demand {} samples/s ({} slots/frame) vs capacity {:.0} samples/s ({} slots/frame); could not place: {}",
                    b.name,
                    b.demand_hz,
                    b.demand_slots_per_frame,
                    b.capacity_hz,
                    b.capacity_slots_per_frame,
                    if b.unplaced.is_empty() { "-".to_string() } else { b.unplaced.join(", ") }
                ));
            }
        }
        errors.extend(why.suggestions.iter().map(|s| format!("suggestion: {s}")));
        let aggregate_hz: u64 = mix.channels.iter().map(|c| c.rate_hz).sum();
        let adc_limit_hz = adc_limit_hz(mix);
        let max_sps = |name: &str| {
            mix.branch_index(name)
                .map_or(0.0, |i| mix.branches[i].max_samples_hz(mix.clock_hz))
        };
        let sps = why.slots_per_slice.unwrap_or(0);
        let slice_cycles = mix.slice_cycles();
        AuditReport {
            mix: mix.name.clone(),
            feasible: false,
            verdict: Some(why.verdict),
            clock_hz: mix.clock_hz,
            frame_cycles: mix.frame_cycles(),
            slice_cycles,
            slot_cycles: slice_cycles.checked_div(sps).unwrap_or(0),
            slots_per_slice: sps,
            samples_per_frame: mix
                .channels
                .iter()
                .map(|c| mix.samples_per_frame(c.rate_hz))
                .sum(),
            aggregate_hz,
            adc_limit_hz,
            adc_utilization: aggregate_hz as f64 / adc_limit_hz,
            placement: "none".into(),
            parts: (0..mix.branches.len())
                .map(|b| PartAudit::of(mix, b, None))
                .collect(),
            lut_entries_compact: 0,
            lut_entries_full: 0,
            errors,
            link_error: None,
            warnings: Vec::new(),
            notes: Vec::new(),
            branches: why
                .branches
                .iter()
                .map(|b| BranchAudit {
                    name: b.name.clone(),
                    utilization: b.demand_slots_per_frame as f64
                        / b.capacity_slots_per_frame.max(1) as f64,
                    conversions_per_frame: b.demand_slots_per_frame,
                    slots_per_frame: b.capacity_slots_per_frame,
                    demand_sps: b.demand_hz,
                    adc_max_sps: max_sps(&b.name),
                    adc_utilization: b.demand_hz as f64 / max_sps(&b.name),
                    sclk_requested_hz: mix
                        .branch_index(&b.name)
                        .map_or(0, |i| mix.branches[i].sclk_hz),
                    sclk_explicit: mix
                        .branch_index(&b.name)
                        .is_some_and(|i| mix.branches[i].sclk_explicit),
                    sclk_hz: 0.0,
                    sclk_div: 0,
                    min_slot_cycles: 0,
                    free_mux_inputs: 0,
                    headroom: Vec::new(),
                    command: mix
                        .branch_index(&b.name)
                        .and_then(|i| CommandAudit::of(mix, i)),
                })
                .collect(),
            channels: Vec::new(),
            link: None,
            fixes: None,
            fixes_tried: None,
            mode_select: None,
            modes: Vec::new(),
            triggers: Vec::new(),
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("audit serializes") + "\n"
    }
}

impl ChannelAudit {
    /// Channel `c` measured on the table: its intervals, its mux settling and
    /// its bandwidth against Nyquist.  What is wrong goes to `errors` and
    /// `warnings`.
    fn of(
        s: &Schedule,
        c: usize,
        branch_slots: &[Vec<u64>],
        errors: &mut Vec<String>,
        warnings: &mut Vec<String>,
    ) -> ChannelAudit {
        let g = &s.grid;
        let mix = &s.mix;
        let ch = &mix.channels[c];
        let slots: Vec<u64> = branch_slots[ch.branch]
            .iter()
            .copied()
            // A chain member is read in its lead's conversions.
            .filter(|&t| s.at(t, ch.branch) == Some(mix.lead_of(c)))
            .collect();
        let n = slots.len();
        let intervals: Vec<u64> = (0..n)
            .map(|i| {
                let next = if i + 1 < n {
                    slots[i + 1]
                } else {
                    slots[0] + g.frame_slots
                };
                (next - slots[i]) * g.slot_cycles
            })
            .collect();
        let (lo, hi) = (
            intervals.iter().min().copied().unwrap_or(0),
            intervals.iter().max().copied().unwrap_or(0),
        );
        let settle_cycles = settle_cycles(s, &slots, &branch_slots[ch.branch]);
        let settle_available_ns = cycles_to_ns(settle_cycles, g.clock_hz);
        let required = mix.branches[ch.branch].settle_ns;
        // A channel its mode does not sample (rate 0) has no instant to settle for.
        if n > 0 && settle_available_ns < required as f64 {
            errors.push(format!(
                "`{}`: mux settles for {:.0} ns before a sampling instant, {} ns required",
                ch.name, settle_available_ns, required
            ));
        }
        let nyquist = ch.rate_hz as f64 / 2.0;
        let alias = if ch.rate_hz > 0 {
            nyquist_check(ch, nyquist, warnings)
        } else {
            None
        };
        if hi != lo || lo != s.channels[c].interval_cycles {
            errors.push(format!(
                "`{}`: intervals {lo}..{hi} cycles, {} promised",
                ch.name, s.channels[c].interval_cycles
            ));
        }
        ChannelAudit {
            name: ch.name.clone(),
            sample_channel: c,
            branch: mix.branches[ch.branch].name.clone(),
            requested_hz: ch.rate_hz,
            achieved_hz: if lo > 0 {
                g.clock_hz as f64 / lo as f64
            } else {
                0.0
            },
            samples_per_frame: n as u64,
            interval_cycles: lo,
            jitter_cycles: hi - lo,
            first_sample_cycle: slots.first().copied().unwrap_or(0) * g.slot_cycles
                + s.sample_after(ch.branch),
            device: s.channels[c].device,
            select: s.channels[c].select,
            adc_input: {
                let b = &mix.branches[ch.branch];
                (b.mux.is_internal() || b.fronted).then_some(ch.input)
            },
            front_mux: ch.front_input.is_some(),
            settle_available_ns,
            settle_required_ns: required,
            bandwidth_hz: ch.bandwidth_hz,
            nyquist_hz: nyquist,
            alias_hz: alias,
        }
    }
}

/// The ADCs' summed limit: every branch's [`crate::Branch::max_samples_hz`].
fn adc_limit_hz(mix: &crate::Mix) -> f64 {
    mix.branches
        .iter()
        .map(|b| b.max_samples_hz(mix.clock_hz))
        .sum()
}

/// The shortest settling before any of `slots`: the mux switches one cycle
/// after the previous CS fall on the branch (`bs`, its conversions).
fn settle_cycles(s: &Schedule, slots: &[u64], bs: &[u64]) -> u64 {
    let g = &s.grid;
    slots
        .iter()
        .map(|&t| {
            let i = bs.binary_search(&t).unwrap();
            let prev = if i > 0 { bs[i - 1] } else { bs[bs.len() - 1] };
            let gap = if prev < t {
                t - prev
            } else {
                t + g.frame_slots - prev
            };
            gap * g.slot_cycles - 1
        })
        .min()
        .unwrap_or(0)
}

/// A warning when the channel's bandwidth is not below Nyquist; the alias
/// frequency when it is above.
fn nyquist_check(
    ch: &crate::mix::Channel,
    nyquist: f64,
    warnings: &mut Vec<String>,
) -> Option<f64> {
    let mut alias = None;
    if let Some(bw) = ch.bandwidth_hz {
        if bw > nyquist {
            alias = Some(alias_hz(bw, ch.rate_hz as f64));
        }
        if bw >= nyquist {
            warnings.push(format!(
                "`{}`: bandwidth {bw} Hz is not below Nyquist ({nyquist} Hz at {} Hz): it will alias{}; sample at more than {} Hz",
                ch.name,
                ch.rate_hz,
                match alias {
                    Some(a) => format!(" (a {bw} Hz tone shows as {} Hz)", fmt_hz(a)),
                    None => String::new(),
                },
                2.0 * bw
            ));
        }
    }
    alias
}

impl BranchAudit {
    /// Branch `b` measured on the table (`used_slots`, its conversions), with
    /// the headroom left at each of the mix's `rates`.
    fn of(
        s: &Schedule,
        b: usize,
        used_slots: &[u64],
        rates: &[u64],
        finer: &FinerGrids,
    ) -> BranchAudit {
        let g = &s.grid;
        let mix = &s.mix;
        let used = used_slots.len() as u64;
        let br = &mix.branches[b];
        let taken = mix
            .channels
            .iter()
            .filter(|c| c.branch == b)
            .map(|c| (c.input, c.front_input))
            .collect::<std::collections::BTreeSet<_>>()
            .len() as u32;
        let free_inputs = front_free(mix, b).unwrap_or(br.input_capacity().saturating_sub(taken));
        // A chain of N parts gives N samples per conversion.
        let adc_max_sps = br.max_samples_hz(mix.clock_hz);
        let demand_sps: u64 = mix
            .channels
            .iter()
            .filter(|c| c.branch == b)
            .map(|c| c.rate_hz)
            .sum();
        let room = Room {
            free_inputs: free_inputs as u64,
            adc_spare_sps: (adc_max_sps - demand_sps as f64).max(0.0),
        };
        let headroom = rates
            .iter()
            .map(|&r| headroom(s, b, r, &room, finer))
            .collect();
        let spi = &s.branches[b].spi;
        BranchAudit {
            name: br.name.clone(),
            utilization: used as f64 / g.frame_slots as f64,
            conversions_per_frame: used,
            slots_per_frame: g.frame_slots,
            demand_sps,
            adc_max_sps,
            adc_utilization: demand_sps as f64 / adc_max_sps,
            sclk_requested_hz: br.sclk_hz,
            sclk_explicit: br.sclk_explicit,
            sclk_hz: spi.sclk_hz,
            sclk_div: spi.sclk_div,
            min_slot_cycles: s.branches[b].min_slot_cycles,
            free_mux_inputs: free_inputs,
            headroom,
            command: CommandAudit::of(mix, b),
        }
    }
}

/// What a branch has left besides table slots.
struct Room {
    free_inputs: u64,
    adc_spare_sps: f64,
}

/// How many more channels at `rate_hz` branch `b` takes, and what binds.
fn headroom(s: &Schedule, b: usize, rate_hz: u64, room: &Room, finer: &FinerGrids) -> Headroom {
    let g = &s.grid;
    let mix = &s.mix;
    let mut free: Vec<bool> = (0..g.frame_slots).map(|t| s.at(t, b).is_none()).collect();
    let by_grid = more_that_fit(&mut free, g.frame_slots, mix.samples_per_frame(rate_hz));
    let by_adc = (room.adc_spare_sps / rate_hz as f64).floor() as u64;
    let (more, binding) = least(room.free_inputs, by_adc, by_grid);
    let finer_grid = finer
        .best(
            b,
            mix.samples_per_frame(rate_hz),
            more,
            room.free_inputs,
            by_adc,
        )
        .filter(|f| f.more_channels > more);
    Headroom {
        rate_hz,
        more_channels: more,
        binding,
        by_mux_inputs: room.free_inputs,
        by_adc_throughput: by_adc,
        by_slot_grid: by_grid,
        finer_grid,
    }
}

/// A note per branch whose SCLK is not the one asked for.
fn sclk_notes(branches: &[BranchAudit], clock_hz: u64) -> Vec<String> {
    let mut notes = Vec::new();
    for b in branches {
        if b.sclk_hz != b.sclk_requested_hz as f64 {
            notes.push(format!(
                "branch `{}`: SCLK {} Hz {}, {} Hz used = {} Hz / {} (SCLK comes from even dividers of the clock only)",
                b.name,
                b.sclk_requested_hz,
                if b.sclk_explicit {
                    "requested"
                } else {
                    "asked by default (the ADC's maximum; no sclk_hz in the mix)"
                },
                fmt_hz(b.sclk_hz),
                clock_hz,
                b.sclk_div
            ));
        }
    }
    notes
}

/// First-fit count of further progressions of `n` samples per frame that the
/// free slots hold.  Exact when the branch's periods are harmonic with it.
fn more_that_fit(free: &mut [bool], slots: u64, n: u64) -> u64 {
    if n == 0 || !slots.is_multiple_of(n) {
        return 0;
    }
    let p = slots / n;
    let mut count = 0;
    for o in 0..p {
        if (o..slots).step_by(p as usize).all(|t| free[t as usize]) {
            for t in (o..slots).step_by(p as usize) {
                free[t as usize] = false;
            }
            count += 1;
        }
    }
    count
}

/// The least of the three headroom limits and which one binds (ties go to
/// the first of inputs, ADC, grid: the hardest to change).
pub fn least(inputs: u64, adc: u64, grid: u64) -> (u64, Limit) {
    let mut best = (inputs, Limit::MuxInputs);
    if adc < best.0 {
        best = (adc, Limit::AdcThroughput);
    }
    if grid < best.0 {
        best = (grid, Limit::SlotGrid);
    }
    best
}

/// Where a tone of `f` Hz sampled at `fs` Hz shows up: the folded frequency
/// `|f - k fs|` nearest 0, in `0..=fs/2`.
pub fn alias_hz(f: f64, fs: f64) -> f64 {
    let r = f.abs().rem_euclid(fs);
    r.min(fs - r)
}

/// A frequency as an integer when it is one, else with up to 3 decimals.
fn fmt_hz(f: f64) -> String {
    if f.fract() == 0.0 {
        format!("{f:.0}")
    } else {
        let t = format!("{f:.3}");
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// The finer slot grids (more slots per slice than the schedule's, every
/// slot still at least the longest shortest-legal-slot of all branches,
/// since the grid is shared) on which every branch's channels place.  On
/// such a grid a branch's headroom at a rate is found by placing its
/// channels together with the extra ones, first-fit in period order as the
/// synthesizer does: exact when the periods are harmonic, a lower bound
/// otherwise.  Sync groups are not re-checked: synthesizing with
/// `slots_per_slice` set is the proof.
struct FinerGrids {
    /// Per branch, the periods (in frame slots of each grid) are derived
    /// from these samples-per-frame counts.
    demand: Vec<Vec<u64>>,
    /// (slots per slice, slot cycles, frame slots).
    grids: Vec<(u64, u64, u64)>,
}

/// Finer grids with more frame slots than this are not examined (the audit
/// stays quick for one-second frames).
const FINER_GRID_MAX_FRAME_SLOTS: u64 = 1 << 20;

impl FinerGrids {
    fn of(s: &Schedule) -> FinerGrids {
        let g = &s.grid;
        let mix = &s.mix;
        let min_slot = s
            .branches
            .iter()
            .map(|b| b.min_slot_cycles)
            .max()
            .unwrap_or(1);
        let demand: Vec<Vec<u64>> = (0..s.branches.len())
            .map(|b| {
                mix.channels
                    .iter()
                    .filter(|c| c.branch == b && c.rate_hz > 0)
                    .map(|c| mix.samples_per_frame(c.rate_hz))
                    .collect()
            })
            .collect();
        let mut any = mix.clone();
        any.slots_per_slice = None;
        let grids = crate::synth::candidate_slots_per_slice(&any, min_slot)
            .into_iter()
            .filter(|&sps| sps > g.slots_per_slice)
            .filter(|&sps| sps * g.slices_per_frame <= FINER_GRID_MAX_FRAME_SLOTS)
            .map(|sps| (sps, g.slice_cycles / sps, sps * g.slices_per_frame))
            .filter(|&(sps, _, frame_slots)| {
                demand.iter().all(|d| place(d, 0, 0, sps, frame_slots))
            })
            .collect();
        FinerGrids { demand, grids }
    }

    /// The coarsest finer grid that allows the most further channels of `n`
    /// samples per frame on `branch`, given the limits no grid changes.
    fn best(&self, branch: usize, n: u64, now: u64, inputs: u64, adc: u64) -> Option<FinerGrid> {
        let cap = inputs.min(adc);
        if now >= cap {
            return None;
        }
        let mut best: Option<FinerGrid> = None;
        for &(sps, slot_cycles, frame_slots) in &self.grids {
            let d = &self.demand[branch];
            // Largest k in 0..=cap that places (placement is monotone in k).
            let (mut lo, mut hi) = (0, cap);
            while lo < hi {
                let mid = (lo + hi).div_ceil(2);
                if place(d, n, mid, sps, frame_slots) {
                    lo = mid;
                } else {
                    hi = mid - 1;
                }
            }
            let (more, binding) = least(inputs, adc, lo);
            if best.as_ref().is_none_or(|b| more > b.more_channels) {
                best = Some(FinerGrid {
                    slots_per_slice: sps,
                    slot_cycles,
                    more_channels: more,
                    binding,
                    by_slot_grid: lo,
                });
            }
            if more >= cap {
                break;
            }
        }
        best
    }
}

/// Whether progressions of the given samples-per-frame counts, plus `k`
/// more of `n` each, place first-fit (shortest period first, offsets by slot
/// in slice first, as the synthesizer orders them) on one branch of a grid
/// of `sps` slots per slice and `frame_slots` slots per frame.
fn place(demand: &[u64], n: u64, k: u64, sps: u64, frame_slots: u64) -> bool {
    let mut periods = Vec::with_capacity(demand.len() + k as usize);
    for &m in demand.iter().chain(std::iter::repeat_n(&n, k as usize)) {
        if m == 0 || !frame_slots.is_multiple_of(m) {
            return false;
        }
        periods.push(frame_slots / m);
    }
    periods.sort_unstable();
    let mut free = vec![true; frame_slots as usize];
    for p in periods {
        let Some(o) = crate::synth::candidate_offsets(p, sps).find(|&o| {
            (o..frame_slots)
                .step_by(p as usize)
                .all(|t| free[t as usize])
        }) else {
            return false;
        };
        for t in (o..frame_slots).step_by(p as usize) {
            free[t as usize] = false;
        }
    }
    true
}

/// Free places on a fronted branch: converter inputs no channel uses (one
/// sensor each), the free inputs of each front device already wired to a
/// converter input (a device has one output), and a device with no channel
/// yet on a free converter input (its other inputs).
fn front_free(mix: &crate::Mix, b: usize) -> Option<u32> {
    let br = &mix.branches[b];
    if !br.fronted {
        return None;
    }
    let mine: Vec<&crate::mix::Channel> = mix.channels.iter().filter(|c| c.branch == b).collect();
    let wired: std::collections::BTreeSet<u32> = mine.iter().map(|c| c.input).collect();
    let straight_free = br.input_capacity() - wired.len() as u32;
    let per = br.mux.inputs;
    let mut on_device = vec![std::collections::BTreeSet::new(); br.mux_devices as usize];
    for c in &mine {
        if let Some(f) = c.front_input {
            on_device[(f / per) as usize].insert(f);
        }
    }
    let spare: u32 = on_device
        .iter()
        .filter(|d| !d.is_empty())
        .map(|d| per - d.len() as u32)
        .sum();
    // a front device with no channel yet takes a free converter input
    let idle = on_device.iter().filter(|d| d.is_empty()).count() as u32;
    Some(straight_free + spare + (per - 1) * idle.min(straight_free))
}
