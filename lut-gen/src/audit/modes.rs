//! The audit of a mix with modes: each mode audited as the schedule it is
//! (its figures are that audit's, so the per-mode table and a mode's own
//! audit cannot disagree), the triggers' worst reaction, and the pin's.

use std::fmt::Write as _;

use serde::Serialize;

use super::{AuditReport, Limit};
use crate::mix::ModeSelect;
use crate::schedule::Schedule;

/// One mode, measured on its own schedule.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeAudit {
    pub name: String,
    /// Its number on `mode_sel` and `mode` (0: the mode after reset).
    pub number: usize,
    pub samples_per_frame: u64,
    pub aggregate_hz: u64,
    pub adc_utilization: f64,
    /// The branch nearest its limit in this mode, and which limit that is
    /// (`slot_grid`: conversions over slots; `adc_throughput`: demand over
    /// the converter's maximum), at `utilization`.
    pub binding_branch: String,
    pub binding: Limit,
    pub utilization: f64,
    pub branches: Vec<ModeBranch>,
    pub channels: Vec<ModeChannel>,
    /// With a link: this mode's words and bytes per frame, line utilisation,
    /// and its own FIFO backlog in steady state.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link: Option<ModeLink>,
    /// Pin select: the worst cycles from `mode_sel` first showing this mode
    /// to its first sample (`lut_gen::pin_latency`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_latency_cycles: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_latency_us: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeBranch {
    pub name: String,
    pub utilization: f64,
    pub conversions_per_frame: u64,
    pub demand_sps: u64,
    pub adc_utilization: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeChannel {
    pub name: String,
    /// The rate in this mode (0: not sampled in it).
    pub rate_hz: u64,
    pub samples_per_frame: u64,
    pub interval_cycles: u64,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeLink {
    pub words_per_frame: u64,
    pub bytes_per_frame: u64,
    pub utilization: f64,
    pub fifo_depth: usize,
}

/// One trigger and its worst reaction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TriggerAudit {
    pub to: String,
    /// The modes it leaves (its `from`, or every mode but `to`).
    pub from: Vec<String>,
    pub when: crate::mix::When,
    pub level: u32,
    pub channels: Vec<String>,
    pub for_frames: u32,
    /// Worst cycles from the first watched sample past `level` to the first
    /// sample of `to` (docs/timing.md, "Mode switches"), and where: the mode
    /// left and the watched channel whose sample starts it.
    pub latency_cycles: u64,
    pub latency_us: f64,
    pub worst_from: String,
    pub worst_channel: String,
}

impl ModeAudit {
    fn of(s: &Schedule, m: usize, name: &str) -> (ModeAudit, AuditReport) {
        let ms = &s.modes[m];
        let r = AuditReport::of_schedule(ms);
        let (binding_branch, binding, utilization) = r
            .branches
            .iter()
            .flat_map(|b| {
                [
                    (b.name.clone(), Limit::SlotGrid, b.utilization),
                    (b.name.clone(), Limit::AdcThroughput, b.adc_utilization),
                ]
            })
            .fold(None, |best: Option<(String, Limit, f64)>, x| match best {
                Some(b) if b.2 >= x.2 => Some(b),
                _ => Some(x),
            })
            .expect("a mix has branches");
        let pin = s.mix.modes.as_ref().map(|x| x.select) == Some(ModeSelect::Pin);
        let pin_cycles = pin.then(|| crate::switching::pin_latency(s, m));
        let a = ModeAudit {
            name: name.to_string(),
            number: m,
            samples_per_frame: r.samples_per_frame,
            aggregate_hz: r.aggregate_hz,
            adc_utilization: r.adc_utilization,
            binding_branch,
            binding,
            utilization,
            branches: r
                .branches
                .iter()
                .map(|b| ModeBranch {
                    name: b.name.clone(),
                    utilization: b.utilization,
                    conversions_per_frame: b.conversions_per_frame,
                    demand_sps: b.demand_sps,
                    adc_utilization: b.adc_utilization,
                })
                .collect(),
            channels: r
                .channels
                .iter()
                .map(|c| ModeChannel {
                    name: c.name.clone(),
                    rate_hz: c.requested_hz,
                    samples_per_frame: c.samples_per_frame,
                    interval_cycles: c.interval_cycles,
                })
                .collect(),
            link: r.link.as_ref().map(|l| ModeLink {
                words_per_frame: l.words_per_frame,
                bytes_per_frame: l.bytes_per_frame,
                utilization: l.utilization,
                fifo_depth: l.fifo_depth,
            }),
            pin_latency_cycles: pin_cycles,
            pin_latency_us: pin_cycles.map(|c| c as f64 * 1e6 / s.grid.clock_hz as f64),
        };
        (a, r)
    }
}

impl AuditReport {
    /// A mix with modes: every mode's table, and the triggers; what is
    /// wrong in a mode other than the reset mode (whose figures are the
    /// report's own) joins the errors and warnings, said of that mode.
    pub(super) fn add_modes(&mut self, s: &Schedule) {
        let Some(plan) = s.mix.modes.as_ref() else {
            return;
        };
        self.mode_select = Some(plan.select);
        for (m, name) in plan.names.iter().enumerate() {
            let (a, r) = ModeAudit::of(s, m, name);
            if m > 0 {
                let said = |x: &String| format!("in mode `{name}`: {x}");
                // (a link a mode cannot carry is the report's own error already)
                let own = r
                    .errors
                    .iter()
                    .filter(|e| Some(*e) != r.link_error.as_ref());
                self.errors.extend(own.map(said));
                self.warnings.extend(r.warnings.iter().map(said));
            }
            self.modes.push(a);
        }
        let ch = |c: usize| s.mix.channels[c].name.clone();
        for (k, t) in plan.triggers.iter().enumerate() {
            let Some(l) = crate::switching::trigger_latency(s, k) else {
                continue;
            };
            self.triggers.push(TriggerAudit {
                to: plan.names[t.to].clone(),
                from: (0..plan.names.len())
                    .filter(|&m| t.leaves(m))
                    .map(|m| plan.names[m].clone())
                    .collect(),
                when: t.when,
                level: t.level,
                channels: t.channels.iter().map(|&c| ch(c)).collect(),
                for_frames: t.for_frames,
                latency_cycles: l.cycles,
                latency_us: l.cycles as f64 * 1e6 / s.grid.clock_hz as f64,
                worst_from: plan.names[l.from].clone(),
                worst_channel: ch(l.channel),
            });
        }
        self.feasible = self.errors.is_empty();
    }

    /// The modes as text: a table per mode, the rates of every channel in
    /// every mode, the triggers and the FIFO across switches.
    pub(super) fn mode_lines(&self, o: &mut String) {
        let Some(select) = self.mode_select else {
            return;
        };
        let _ = writeln!(
            o,
            "\nmodes: select = \"{}\"; a switch takes effect at a frame start and is decided a frame ahead (docs/timing.md, \"Mode switches\")",
            select.name()
        );
        let _ = writeln!(
            o,
            "{:<3} {:<16} {:>13} {:>13} {:>8}  binds",
            "#", "mode", "samples/frame", "samples/s", "of ADC %"
        );
        for m in &self.modes {
            let _ = writeln!(
                o,
                "{:<3} {:<16} {:>13} {:>13} {:>8.1}  branch `{}`: {} {:.1} %{}",
                m.number,
                m.name,
                m.samples_per_frame,
                m.aggregate_hz,
                m.adc_utilization * 100.0,
                m.binding_branch,
                m.binding.describe(),
                m.utilization * 100.0,
                match &m.link {
                    Some(l) => format!(
                        "; link {} bytes/frame, line {:.1} % used, FIFO {} tokens",
                        l.bytes_per_frame,
                        l.utilization * 100.0,
                        l.fifo_depth
                    ),
                    None => String::new(),
                }
            );
        }
        self.mode_rates(o);
        self.mode_reactions(o);
    }

    /// Channel by channel, its rate in each mode (Hz; 0 not sampled).
    fn mode_rates(&self, o: &mut String) {
        let _ = write!(o, "{:<16}", "rate Hz");
        for m in &self.modes {
            let _ = write!(o, " {:>10}", m.name);
        }
        let _ = writeln!(o);
        for (c, ch) in self.channels.iter().enumerate() {
            let _ = write!(o, "{:<16}", ch.name);
            for m in &self.modes {
                let _ = write!(o, " {:>10}", m.channels[c].rate_hz);
            }
            let _ = writeln!(o);
        }
    }

    /// The pin's and each trigger's worst reaction, and the FIFO across switches.
    fn mode_reactions(&self, o: &mut String) {
        for m in self.modes.iter().filter(|m| m.pin_latency_cycles.is_some()) {
            let _ = writeln!(
                o,
                "pin: mode_sel = {} -> first sample of `{}` within {} cycles ({:.1} us)",
                m.number,
                m.name,
                m.pin_latency_cycles.unwrap_or(0),
                m.pin_latency_us.unwrap_or(0.0)
            );
        }
        for (k, t) in self.triggers.iter().enumerate() {
            let _ = writeln!(
                o,
                "trigger {k}: {} -> {} when {} {} {} {} for {} frame(s): worst latency {} cycles ({:.1} us), first sample past the level (`{}` in `{}`) -> first sample of `{}`",
                t.from.join("|"),
                t.to,
                match t.when {
                    crate::mix::When::Above => "any of",
                    crate::mix::When::Below => "all of",
                },
                compact(&t.channels),
                t.when.name(),
                t.level,
                t.for_frames,
                t.latency_cycles,
                t.latency_us,
                t.worst_channel,
                t.worst_from,
                t.to
            );
        }
        if let Some(l) = self.link.as_ref().filter(|l| !l.switches.is_empty()) {
            let each: Vec<String> = l
                .switches
                .iter()
                .map(|s| format!("{}->{} {}", s.from, s.to, s.backlog))
                .collect();
            let _ = writeln!(
                o,
                "link across switches (FIFO tokens): {}; the link is sized for mode `{}` (most bytes per frame) and the deepest FIFO of any mode or switch",
                each.join(", "),
                l.worst_mode.as_deref().unwrap_or("?")
            );
        }
    }
}

/// Names as the mix's bulk syntax writes a run of them: `CH1..CH25` (each
/// the next number after the same prefix) as `CH{1..25}`, the rest as they
/// are, comma-separated.
pub fn compact(names: &[String]) -> String {
    let split = |n: &str| {
        let digits = n.len() - n.bytes().rev().take_while(u8::is_ascii_digit).count();
        let (p, d) = n.split_at(digits);
        (!d.is_empty() && (d == "0" || !d.starts_with('0')))
            .then(|| d.parse::<u64>().ok().map(|v| (p.to_string(), v)))
            .flatten()
    };
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < names.len() {
        let mut j = i;
        if let Some((p, v)) = split(&names[i]) {
            while j + 1 < names.len()
                && split(&names[j + 1]) == Some((p.clone(), v + (j + 1 - i) as u64))
            {
                j += 1;
            }
            if j - i >= 2 {
                out.push(format!("{p}{{{v}..{}}}", v + (j - i) as u64));
                i = j + 1;
                continue;
            }
        }
        out.push(names[i].clone());
        i += 1;
    }
    out.join(",")
}
