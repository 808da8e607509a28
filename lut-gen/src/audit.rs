//! The audit: what an engineer asks before touching hardware.  Does the mix
//! fit, at what exact rates, with what jitter, how much room is left, does
//! every mux settle in time, and is every signal sampled above Nyquist?
//!
//! Everything here is measured on the frame table itself (not on the
//! synthesizer's intentions), so the audit doubles as a second opinion.

use std::fmt::Write as _;

use serde::Serialize;

use crate::lut::CompactLut;
use crate::parts::cycles_to_ns;
use crate::schedule::{Placement, Schedule};
use crate::synth::Infeasible;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AuditReport {
    pub mix: String,
    pub feasible: bool,
    pub clock_hz: u64,
    pub frame_cycles: u64,
    pub slice_cycles: u64,
    pub slot_cycles: u64,
    pub slots_per_slice: u64,
    pub samples_per_frame: u64,
    /// Sum of all channels' rates.
    pub aggregate_hz: u64,
    /// The ADCs' physical limit: sum of their maximum throughputs.
    pub adc_limit_hz: u64,
    pub adc_utilization: f64,
    pub placement: String,
    pub lut_entries_compact: usize,
    pub lut_entries_full: usize,
    pub errors: Vec<String>,
    pub warnings: Vec<String>,
    pub branches: Vec<BranchAudit>,
    /// What each branch's converter allows (throughput, bits, chain).
    pub parts: Vec<PartAudit>,
    pub channels: Vec<ChannelAudit>,
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
    /// Conversions per second the branch allows (the shortest legal slot),
    /// and samples per second (times the chain).
    pub max_conversions_hz: f64,
    pub max_samples_hz: f64,
}

impl PartAudit {
    fn of(
        mix: &crate::mix::Mix,
        b: usize,
        plan: Option<&crate::schedule::BranchPlan>,
    ) -> PartAudit {
        let br = &mix.branches[b];
        let a = &br.adc;
        let spi = plan.map(|p| p.spi).or_else(|| {
            crate::parts::SpiTiming::derive(a, mix.clock_hz, br.sclk_hz, br.chain).ok()
        });
        let min_slot = plan
            .map(|p| p.min_slot_cycles)
            .or(spi.map(|t| t.min_period_cycles))
            .unwrap_or(0);
        let conv_hz = if min_slot > 0 {
            mix.clock_hz as f64 / min_slot as f64
        } else {
            0.0
        };
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
            max_conversions_hz: conv_hz,
            max_samples_hz: conv_hz * br.chain as f64,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BranchAudit {
    pub name: String,
    /// Conversions per frame over slots per frame.
    pub utilization: f64,
    pub conversions_per_frame: u64,
    pub slots_per_frame: u64,
    pub sclk_hz: f64,
    pub min_slot_cycles: u64,
    pub free_mux_inputs: u32,
    /// How many more channels of each rate present in the mix would still fit.
    pub headroom: Vec<Headroom>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Headroom {
    pub rate_hz: u64,
    /// Further channels at this rate that the branch's free slots hold.
    pub more_channels: u64,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelAudit {
    pub name: String,
    pub branch: String,
    pub requested_hz: u64,
    pub achieved_hz: f64,
    pub samples_per_frame: u64,
    pub interval_cycles: u64,
    pub jitter_cycles: u64,
    pub first_sample_cycle: u64,
    pub device: u32,
    pub select: u32,
    /// Shortest time the mux has to settle before one of this channel's instants.
    pub settle_available_ns: f64,
    pub settle_required_ns: u64,
    pub bandwidth_hz: Option<f64>,
    /// `rate / 2`, against which `bandwidth_hz` is checked.
    pub nyquist_hz: f64,
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

        let mut channels = Vec::new();
        for (c, ch) in mix.channels.iter().enumerate() {
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
            // Settling: the mux switches one cycle after the previous CS fall on the branch.
            let bs = &branch_slots[ch.branch];
            let settle_cycles = slots
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
                .unwrap_or(0);
            let settle_available_ns = cycles_to_ns(settle_cycles, g.clock_hz);
            let required = mix.branches[ch.branch].settle_ns;
            if settle_available_ns < required as f64 {
                errors.push(format!(
                    "`{}`: mux settles for {:.0} ns before a sampling instant, {} ns required",
                    ch.name, settle_available_ns, required
                ));
            }
            let nyquist = ch.rate_hz as f64 / 2.0;
            if let Some(bw) = ch.bandwidth_hz {
                if bw >= nyquist {
                    warnings.push(format!(
                        "`{}`: bandwidth {bw} Hz is not below Nyquist ({nyquist} Hz at {} Hz): it will alias; sample at more than {} Hz",
                        ch.name,
                        ch.rate_hz,
                        2.0 * bw
                    ));
                }
            }
            if hi != lo || lo != s.channels[c].interval_cycles {
                errors.push(format!(
                    "`{}`: intervals {lo}..{hi} cycles, {} promised",
                    ch.name, s.channels[c].interval_cycles
                ));
            }
            channels.push(ChannelAudit {
                name: ch.name.clone(),
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
                first_sample_cycle: slots.first().copied().unwrap_or(0) * g.slot_cycles,
                device: s.channels[c].device,
                select: s.channels[c].select,
                settle_available_ns,
                settle_required_ns: required,
                bandwidth_hz: ch.bandwidth_hz,
                nyquist_hz: nyquist,
            });
        }

        let mut rates: Vec<u64> = mix.channels.iter().map(|c| c.rate_hz).collect();
        rates.sort_unstable();
        rates.dedup();
        let branches = (0..nb)
            .map(|b| {
                let used = branch_slots[b].len() as u64;
                let mut free: Vec<bool> =
                    (0..g.frame_slots).map(|t| s.at(t, b).is_none()).collect();
                let headroom = rates
                    .iter()
                    .map(|&r| Headroom {
                        rate_hz: r,
                        more_channels: more_that_fit(
                            &mut free.clone(),
                            g.frame_slots,
                            mix.samples_per_frame(r),
                        ),
                    })
                    .collect();
                free.clear();
                let br = &mix.branches[b];
                let inputs = br.mux_devices * br.mux.inputs;
                let taken = mix
                    .channels
                    .iter()
                    .filter(|c| c.branch == b)
                    .map(|c| c.input)
                    .collect::<std::collections::BTreeSet<_>>()
                    .len() as u32;
                BranchAudit {
                    name: br.name.clone(),
                    utilization: used as f64 / g.frame_slots as f64,
                    conversions_per_frame: used,
                    slots_per_frame: g.frame_slots,
                    sclk_hz: s.branches[b].spi.sclk_hz,
                    min_slot_cycles: s.branches[b].min_slot_cycles,
                    free_mux_inputs: inputs - taken,
                    headroom,
                }
            })
            .collect();

        let aggregate_hz: u64 = mix.channels.iter().map(|c| c.rate_hz).sum();
        let adc_limit_hz: u64 = mix
            .branches
            .iter()
            .map(|b| b.adc.max_sps * b.chain as u64)
            .sum();
        let lut = CompactLut::from_schedule(s);
        AuditReport {
            mix: mix.name.clone(),
            feasible: errors.is_empty(),
            clock_hz: g.clock_hz,
            frame_cycles: g.frame_cycles,
            slice_cycles: g.slice_cycles,
            slot_cycles: g.slot_cycles,
            slots_per_slice: g.slots_per_slice,
            samples_per_frame: s.samples_per_frame(),
            aggregate_hz,
            adc_limit_hz,
            adc_utilization: aggregate_hz as f64 / adc_limit_hz as f64,
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
            warnings,
            branches,
            channels,
        }
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
        let adc_limit_hz: u64 = mix
            .branches
            .iter()
            .map(|b| b.adc.max_sps * b.chain as u64)
            .sum();
        let sps = why.slots_per_slice.unwrap_or(0);
        let slice_cycles = mix.slice_cycles();
        AuditReport {
            mix: mix.name.clone(),
            feasible: false,
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
            adc_utilization: aggregate_hz as f64 / adc_limit_hz as f64,
            placement: "none".into(),
            parts: (0..mix.branches.len())
                .map(|b| PartAudit::of(mix, b, None))
                .collect(),
            lut_entries_compact: 0,
            lut_entries_full: 0,
            errors,
            warnings: Vec::new(),
            branches: why
                .branches
                .iter()
                .map(|b| BranchAudit {
                    name: b.name.clone(),
                    utilization: b.demand_slots_per_frame as f64
                        / b.capacity_slots_per_frame.max(1) as f64,
                    conversions_per_frame: b.demand_slots_per_frame,
                    slots_per_frame: b.capacity_slots_per_frame,
                    sclk_hz: 0.0,
                    min_slot_cycles: 0,
                    free_mux_inputs: 0,
                    headroom: Vec::new(),
                })
                .collect(),
            channels: Vec::new(),
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("audit serializes") + "\n"
    }

    /// The human-readable table.
    pub fn to_text(&self) -> String {
        let mut o = String::new();
        let _ = writeln!(
            o,
            "mix {}: {}",
            self.mix,
            if self.feasible {
                "FEASIBLE, zero jitter"
            } else {
                "INFEASIBLE"
            }
        );
        if self.slots_per_slice > 0 {
            let _ = writeln!(
                o,
                "clock {} Hz; frame {} cycles; slice {} cycles; {} slots/slice of {} cycles ({:.3} us); {}",
                self.clock_hz,
                self.frame_cycles,
                self.slice_cycles,
                self.slots_per_slice,
                self.slot_cycles,
                self.slot_cycles as f64 * 1e6 / self.clock_hz as f64,
                self.placement
            );
        }
        let _ = writeln!(
            o,
            "{} samples/frame; aggregate {} samples/s of {} the ADCs can do ({:.1} %)",
            self.samples_per_frame,
            self.aggregate_hz,
            self.adc_limit_hz,
            self.adc_utilization * 100.0
        );
        if self.lut_entries_full > 0 {
            let _ = writeln!(
                o,
                "LUT: {} entries compact, {} as a full frame table",
                self.lut_entries_compact, self.lut_entries_full
            );
        }
        if !self.branches.is_empty() {
            let _ = writeln!(
                o,
                "\n{:<16} {:>8} {:>11} {:>10} {:>11}  headroom (more channels at rate)",
                "branch", "util %", "conv/frame", "SCLK Hz", "free inputs"
            );
            for b in &self.branches {
                let head: Vec<String> = b
                    .headroom
                    .iter()
                    .map(|h| format!("{}@{}Hz", h.more_channels, h.rate_hz))
                    .collect();
                let _ = writeln!(
                    o,
                    "{:<16} {:>8.1} {:>11} {:>10.0} {:>11}  {}",
                    b.name,
                    b.utilization * 100.0,
                    format!("{}/{}", b.conversions_per_frame, b.slots_per_frame),
                    b.sclk_hz,
                    b.free_mux_inputs,
                    head.join(" ")
                );
            }
        }
        if !self.parts.is_empty() {
            let _ = writeln!(
                o,
                "\n{:<16} {:<10} {:>5} {:>5} {:>6} {:>9} {:>10} {:>9} {:>13} {:>13}",
                "branch",
                "adc",
                "start",
                "bits",
                "chain",
                "max SPS",
                "SCLK max",
                "t_conv",
                "conv/s max",
                "samples/s max"
            );
            for p in &self.parts {
                let _ = writeln!(
                    o,
                    "{:<16} {:<10} {:>5} {:>5} {:>6} {:>9} {:>10} {:>9} {:>13.0} {:>13.0}",
                    p.branch,
                    p.adc,
                    match p.start {
                        crate::parts::Start::Cs => "cs",
                        crate::parts::Start::Cnv => "cnv",
                    },
                    p.bits,
                    format!("{}/{}", p.chain, p.chain_max),
                    p.max_sps,
                    p.sclk_max_hz,
                    format!("{}ns", p.conversion_ns),
                    p.max_conversions_hz,
                    p.max_samples_hz
                );
            }
        }
        if !self.channels.is_empty() {
            let _ = writeln!(
                o,
                "\n{:<12} {:<12} {:>8} {:>11} {:>6} {:>10} {:>6} {:>9} {:>8} {:>12} {:>9}",
                "channel",
                "branch",
                "rate Hz",
                "achieved",
                "n/frm",
                "interval",
                "jitter",
                "first",
                "dev.sel",
                "settle ns",
                "bw/nyq"
            );
            for c in &self.channels {
                let _ = writeln!(
                    o,
                    "{:<12} {:<12} {:>8} {:>11.3} {:>6} {:>10} {:>6} {:>9} {:>8} {:>12} {:>9}",
                    c.name,
                    c.branch,
                    c.requested_hz,
                    c.achieved_hz,
                    c.samples_per_frame,
                    c.interval_cycles,
                    c.jitter_cycles,
                    c.first_sample_cycle,
                    format!("{}.{}", c.device, c.select),
                    format!("{:.0}/{}", c.settle_available_ns, c.settle_required_ns),
                    match c.bandwidth_hz {
                        Some(bw) => format!("{bw}/{}", c.nyquist_hz),
                        None => "-".into(),
                    }
                );
            }
        }
        for w in &self.warnings {
            let _ = writeln!(o, "warning: {w}");
        }
        for e in &self.errors {
            let _ = writeln!(o, "error: {e}");
        }
        o
    }
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
