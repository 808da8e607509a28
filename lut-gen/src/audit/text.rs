//! The audit as text: one writer per section of the report.

use std::fmt::Write as _;

use super::{fmt_hz, AuditReport};

impl AuditReport {
    /// The human-readable table.
    pub fn to_text(&self) -> String {
        let mut o = String::new();
        self.header(&mut o);
        self.branch_table(&mut o);
        self.part_table(&mut o);
        self.channel_table(&mut o);
        self.link_lines(&mut o);
        self.mode_lines(&mut o);
        self.messages(&mut o);
        o
    }

    /// The verdict, the grid and the totals.
    fn header(&self, o: &mut String) {
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
            "{} samples/frame; aggregate {} samples/s of {:.0} the ADCs can do ({:.1} %)",
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
    }

    /// Per branch: demand, ADC and grid use, SCLK, free inputs.
    fn branch_table(&self, o: &mut String) {
        if !self.branches.is_empty() {
            let _ = writeln!(
                o,
                "\n{:<16} {:>11} {:>11} {:>8} {:>11} {:>8} {:>10} {:>11}",
                "branch",
                "demand S/s",
                "ADC max S/s",
                "of ADC %",
                "conv/frame",
                "of grid %",
                "SCLK Hz",
                "free inputs"
            );
            for b in &self.branches {
                let _ = writeln!(
                    o,
                    "{:<16} {:>11} {:>11.0} {:>8.1} {:>11} {:>8.1} {:>10} {:>11}",
                    b.name,
                    b.demand_sps,
                    b.adc_max_sps,
                    b.adc_utilization * 100.0,
                    format!("{}/{}", b.conversions_per_frame, b.slots_per_frame),
                    b.utilization * 100.0,
                    fmt_hz(b.sclk_hz),
                    b.free_mux_inputs
                );
            }
            let _ = writeln!(
                o,
                "of ADC = demanded samples/s over the ADC's maximum; of grid = conversions over the slots of the slot grid"
            );
            self.headroom_lines(o);
            self.command_lines(o);
        }
    }

    /// Branches whose converter takes a command word: the word and its pipeline.
    fn command_lines(&self, o: &mut String) {
        for b in &self.branches {
            let Some(c) = &b.command else { continue };
            let when = match c.ahead {
                0 => "selects the conversion it is sent in".to_string(),
                n => format!(
                    "selects the conversion {n} ahead; the first {} conversion(s) after reset are prepared, not data",
                    c.prepared_conversions
                ),
            };
            let _ = writeln!(
                o,
                "command: {} sends {} on adc_mosi (C: channel bits); it {when}",
                b.name, c.template
            );
        }
    }

    /// More channels per rate, and what limits them.
    fn headroom_lines(&self, o: &mut String) {
        let _ = writeln!(
            o,
            "\nheadroom: more channels per rate = the least of what the free mux inputs, the ADC throughput and the slot grid allow"
        );
        for b in &self.branches {
            for h in &b.headroom {
                let mut line = format!(
                    "  {:<16} {:>7} Hz: {:>4} more (limit: {}; inputs {}, ADC {}, grid {})",
                    b.name,
                    h.rate_hz,
                    h.more_channels,
                    h.binding.describe(),
                    h.by_mux_inputs,
                    h.by_adc_throughput,
                    h.by_slot_grid
                );
                if let Some(f) = &h.finer_grid {
                    let _ = write!(
                        line,
                        "; up to {} more with a {}-slot slice (limit: {}; that grid: {})",
                        f.more_channels,
                        f.slots_per_slice,
                        f.binding.describe(),
                        f.by_slot_grid
                    );
                }
                let _ = writeln!(o, "{line}");
            }
        }
    }

    /// Per branch: the ADC part and its limits.
    fn part_table(&self, o: &mut String) {
        if !self.parts.is_empty() {
            let _ = writeln!(
                o,
                "\n{:<16} {:<10} {:>5} {:>5} {:>5} {:>6} {:>9} {:>10} {:>9} {:>13} {:>13} {:>9}",
                "branch",
                "adc",
                "VDD",
                "start",
                "bits",
                "chain",
                "max SPS",
                "SCLK max",
                "t_conv",
                "conv/s max",
                "samples/s max",
                "sampled"
            );
            for p in &self.parts {
                let _ = writeln!(
                    o,
                    "{:<16} {:<10} {:>5} {:>5} {:>5} {:>6} {:>9} {:>10} {:>9} {:>13.0} {:>13.0} {:>9}",
                    p.branch,
                    p.adc,
                    match p.vdd_v {
                        None => "-".to_string(),
                        Some(v) => format!(
                            "{}{}",
                            crate::parts::volts((v * 1000.0).round() as u32),
                            if p.vdd_given { "" } else { "*" }
                        ),
                    },
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
                    p.max_samples_hz,
                    sampled_words(p)
                );
            }
            let _ = writeln!(
                o,
                "VDD: the supply whose datasheet figures apply (*: the part's lowest, no `vdd` given); sampled: where the part holds its input, at its start edge (CS falling, CNV rising) or this long after it (sampled_s and the first instants below include it)"
            );
            if self.parts.iter().any(|p| p.holdoff_cycles > 0) {
                let _ = writeln!(
                    o,
                    "hold-off: the branch starts its transactions this long after the slot tick, so its sync group holds its inputs at one instant (sampled_s includes it)"
                );
            }
        }
    }

    /// Per channel: the rates and instants as measured.
    fn channel_table(&self, o: &mut String) {
        if !self.channels.is_empty() {
            let _ = writeln!(
                o,
                "\n{:<12} {:>3} {:<12} {:>8} {:>11} {:>6} {:>10} {:>6} {:>9} {:>8} {:>12} {:>9} {:>6}",
                "channel",
                "#",
                "branch",
                "rate Hz",
                "achieved",
                "n/frm",
                "interval",
                "jitter",
                "first",
                "dev.sel",
                "settle ns",
                "bw/nyq",
                "alias"
            );
            for c in &self.channels {
                let _ = writeln!(
                    o,
                    "{:<12} {:>3} {:<12} {:>8} {:>11.3} {:>6} {:>10} {:>6} {:>9} {:>8} {:>12} {:>9} {:>6}",
                    c.name,
                    c.sample_channel,
                    c.branch,
                    c.requested_hz,
                    c.achieved_hz,
                    c.samples_per_frame,
                    c.interval_cycles,
                    c.jitter_cycles,
                    c.first_sample_cycle,
                    mux_cell(c),
                    format!("{:.0}/{}", c.settle_available_ns, c.settle_required_ns),
                    match c.bandwidth_hz {
                        Some(bw) => format!("{bw}/{}", c.nyquist_hz),
                        None => "-".into(),
                    },
                    c.alias_hz.map_or("-".into(), fmt_hz)
                );
            }
            let _ = writeln!(
                o,
                "# = the value `sample_channel` carries for the channel: its index in the mix file, 0-based, in [[channel]] order"
            );
            let _ = writeln!(
                o,
                "interval, first: cycles (first = first sampling instant after cycle 0); dev.sel = mux device.select{}; alias = where a tone at bw shows when bw is above Nyquist",
                if self.channels.iter().any(|c| c.adc_input.is_some()) {
                    " (inK: the converter's own input K; inK/d.s: through a front mux's device d, select s)"
                } else {
                    ""
                }
            );
        }
    }

    /// The host link: its line or stream, FIFO and latency.
    fn link_lines(&self, o: &mut String) {
        if let Some(l) = self.link.as_ref().filter(|l| l.ready_within.is_some()) {
            let _ = writeln!(
                o,
                "link axis: 8-bit beats, tlast at the end of each {}; the FIFO is sized for a slave that accepts every beat within {} cycle(s) (tready duty >= 1/{}); the mix needs it within {} cycles at most",
                l.tlast.unwrap_or("slice"),
                l.ready_within.unwrap_or(1),
                l.ready_within.unwrap_or(1),
                l.max_ready_within.map_or("?".into(), |m| m.to_string())
            );
            let _ = writeln!(
                o,
                "link{}: {} words ({} bytes) per frame, stream {:.1} % busy at worst; FIFO depth {} tokens (worst-case backlog); worst latency instant -> last beat of its packet {} cycles ({:.1} us)",
                worst_mode(l),
                l.words_per_frame,
                l.bytes_per_frame,
                l.utilization * 100.0,
                l.fifo_depth,
                l.latency_cycles,
                l.latency_us
            );
        } else if let Some(l) = &self.link {
            let _ = writeln!(
                o,
                "link {}: {:.0} baud (divider {}, {} asked), {} bits per byte ({} parity, {} stop)",
                l.kind,
                l.baud,
                l.baud_divider,
                l.baud_requested,
                l.bits_per_byte,
                l.parity,
                l.stop_bits
            );
            let _ = writeln!(
                o,
                "link{}: {} words ({} bytes) per frame, line {:.1} % used; FIFO depth {} tokens (worst-case backlog); worst latency instant -> last bit of its packet {} cycles ({:.1} us); minimum baud {:.0}",
                worst_mode(l),
                l.words_per_frame,
                l.bytes_per_frame,
                l.utilization * 100.0,
                l.fifo_depth,
                l.latency_cycles,
                l.latency_us,
                l.min_baud
            );
        }
    }

    /// Notes, warnings, errors.
    fn messages(&self, o: &mut String) {
        for n in &self.notes {
            let _ = writeln!(o, "note: {n}");
        }
        for w in &self.warnings {
            let _ = writeln!(o, "warning: {w}");
        }
        for e in &self.errors {
            let _ = writeln!(o, "error: {e}");
        }
    }
}

/// With modes, the link's words and bytes are its worst mode's: say whose.
fn worst_mode(l: &crate::hostlink::LinkPlan) -> String {
    match &l.worst_mode {
        Some(m) => format!(" in mode `{m}` (the most bytes per frame; FIFO the most of every mode and switch, latency and minimum baud the worst mode's)"),
        None => String::new(),
    }
}

/// The `dev.sel` cell: [`super::ChannelAudit::mux_words`].
fn mux_cell(c: &super::ChannelAudit) -> String {
    c.mux_words()
}

/// The parts table's "sampled" cell: where the part holds its input, after
/// its branch's hold-off when it has one.
fn sampled_words(p: &crate::audit::PartAudit) -> String {
    let own = match p.sample_at {
        crate::parts::SampleAt::Start => "at start".to_string(),
        crate::parts::SampleAt::SclkFall(_) => format!("+{:.3}us", p.sample_after_ns / 1000.0),
    };
    match p.holdoff_cycles {
        0 => own,
        _ => format!("{own} after {:.3}us hold-off", p.holdoff_ns / 1000.0),
    }
}
