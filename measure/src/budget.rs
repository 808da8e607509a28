//! The audit as a datasheet: what binds and the margin first, then the
//! mix's figures, a budget per branch, the link's budget, the converters
//! and the channels, each a table of its own with human words and units in
//! every header and row label (the JSON's field names stay in
//! `audit.json`). Every cell is read from the [`AuditReport`] the audit
//! step wrote, so the tables and the JSON cannot disagree.

use lut_gen::AuditReport;
use lut_gen::LinkPlan;
use lut_gen::{BranchAudit, ChannelAudit, Headroom};
use report::Table;

/// A frequency in the unit that reads best (`48 MHz`, `2.4 MHz`, `1000 Hz`).
pub fn hz(x: f64) -> String {
    let trim = |v: f64| {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    if x >= 1e6 {
        format!("{} MHz", trim(x / 1e6))
    } else if x >= 1e4 {
        format!("{} kHz", trim(x / 1e3))
    } else {
        format!("{} Hz", trim(x))
    }
}

fn pct(f: f64) -> String {
    format!("{:.1} %", f * 100.0)
}

/// The limit that binds the whole mix: the most used of every branch's
/// slots and converter, and the link's line.
#[derive(Debug, Clone, PartialEq)]
pub struct Tightest {
    /// What it is, in words (`branch standard's slot grid`).
    pub what: String,
    /// Its use, 0..=1.
    pub used: f64,
}

impl Tightest {
    pub fn of(r: &AuditReport) -> Option<Tightest> {
        let mut all: Vec<Tightest> = Vec::new();
        // a mix with modes: every mode's limits, each named with its mode
        // (the top-level tables are the reset mode's; the busiest may be another)
        let modal = r.modes.len() > 1;
        for b in r.branches.iter().filter(|_| !modal) {
            all.push(Tightest {
                what: format!("branch `{}`'s slots", b.name),
                used: b.utilization,
            });
            all.push(Tightest {
                what: format!("branch `{}`'s converter throughput", b.name),
                used: b.adc_utilization,
            });
        }
        if let Some(l) = r.link.as_ref().filter(|_| !modal) {
            all.push(Tightest {
                what: format!("the {} link's line", link_kind(l)),
                used: l.utilization,
            });
        }
        for m in r.modes.iter().filter(|_| modal) {
            for b in &m.branches {
                all.push(Tightest {
                    what: format!("branch `{}`'s slots in mode `{}`", b.name, m.name),
                    used: b.utilization,
                });
                all.push(Tightest {
                    what: format!(
                        "branch `{}`'s converter throughput in mode `{}`",
                        b.name, m.name
                    ),
                    used: b.adc_utilization,
                });
            }
            if let (Some(l), Some(ml)) = (&r.link, &m.link) {
                all.push(Tightest {
                    what: format!("the {} link's line in mode `{}`", link_kind(l), m.name),
                    used: ml.utilization,
                });
            }
        }
        first_most_used(all, |t| t.used)
    }

    /// "branch `standard`'s slots, 100.0 % used (0.0 % margin)".
    pub fn words(&self) -> String {
        format!(
            "{}, {} used ({} margin)",
            self.what,
            pct(self.used),
            pct((1.0 - self.used).max(0.0))
        )
    }
}

fn link_kind(l: &LinkPlan) -> &'static str {
    match l.kind {
        "uart" => "UART",
        "axis" => "AXI4-Stream",
        _ => "host",
    }
}

/// Every table of the audit, in reading order.
pub fn budget_tables(r: &AuditReport) -> Vec<(String, Table)> {
    let mut out = vec![("The mix".to_string(), facts(r))];
    out.push((branch_caption(r), branches(r)));
    out.push((
        "Headroom: further channels each branch could take, by rate".into(),
        headroom(r),
    ));
    if let Some(l) = &r.link {
        out.push((
            format!(
                "Link budget: {} of the line used, FIFO {} tokens deep",
                pct(l.utilization),
                l.fifo_depth
            ),
            link(l, r.clock_hz),
        ));
    }
    if r.modes.len() > 1 {
        out.push((
            "Modes: the tables above are the reset mode's; each mode's own figures".into(),
            modes(r),
        ));
        out.push(("Branch budgets in every mode".into(), mode_branches(r)));
    }
    if !r.triggers.is_empty() {
        out.push(("Triggers and their worst reaction".into(), triggers(r)));
    }
    out.push(("Converters".into(), parts(r)));
    out.push(("Channels".into(), channels(r)));
    out
}

/// Each mode's figures, from the audit's per-mode tables.
fn modes(r: &AuditReport) -> Table {
    let pin = r.modes.iter().any(|m| m.pin_latency_us.is_some());
    let mut cols = vec![
        "mode",
        "samples per frame",
        "samples/s",
        "converters used",
        "what binds",
        "link bytes per frame",
        "link use",
    ];
    if pin {
        cols.push("switch by the pin, worst (us)");
    }
    let mut t = Table::new(&cols);
    for m in &r.modes {
        let mut row = vec![
            m.name.clone(),
            m.samples_per_frame.to_string(),
            m.aggregate_hz.to_string(),
            pct(m.adc_utilization),
            format!(
                "{} of {}, {}",
                m.binding.describe(),
                m.binding_branch,
                pct(m.utilization)
            ),
            m.link
                .as_ref()
                .map_or("-".into(), |l| l.bytes_per_frame.to_string()),
            m.link.as_ref().map_or("-".into(), |l| pct(l.utilization)),
        ];
        if pin {
            row.push(m.pin_latency_us.map_or("-".into(), |u| format!("{u:.1}")));
        }
        t.push(row);
    }
    t
}

/// Each trigger: what it watches and its worst reaction.
fn triggers(r: &AuditReport) -> Table {
    let mut t = Table::new(&[
        "trigger",
        "condition",
        "watches",
        "worst reaction (ms)",
        "worst when",
    ]);
    for x in &r.triggers {
        t.push(vec![
            format!("{} to {}", x.from.join(", "), x.to),
            format!(
                "{} {} for {}",
                match x.when {
                    lut_gen::When::Above => "above",
                    lut_gen::When::Below => "below",
                },
                x.level,
                if x.for_frames == 1 {
                    "1 frame".to_string()
                } else {
                    format!("{} frames", x.for_frames)
                }
            ),
            crate::short_names(&x.channels.iter().map(String::as_str).collect::<Vec<_>>()),
            format!("{:.2}", x.latency_us / 1e3),
            format!("in {}, on {}", x.worst_from, x.worst_channel),
        ]);
    }
    t
}

/// The mix's figures as label and value.
fn facts(r: &AuditReport) -> Table {
    let mut t = Table::new(&["figure", "value"]);
    let mut row = |k: &str, v: String| t.push(vec![k.to_string(), v]);
    row(
        "Fits",
        if r.feasible {
            "yes: every channel at its rate with zero jitter".into()
        } else {
            "no".into()
        },
    );
    if let Some(b) = Tightest::of(r) {
        row("What binds", b.words());
    }
    row("Clock", hz(r.clock_hz as f64));
    let ms = r.frame_cycles as f64 / r.clock_hz.max(1) as f64 * 1e3;
    row(
        "Frame",
        format!(
            "{} cycles ({ms} ms) = {} slices x {} slots x {} cycles",
            r.frame_cycles,
            r.frame_cycles / r.slice_cycles.max(1),
            r.slots_per_slice,
            r.slot_cycles
        ),
    );
    row("Samples per frame", r.samples_per_frame.to_string());
    row(
        "Sample rate of all channels",
        format!(
            "{} samples/s = {} of the converters' {:.0} samples/s",
            r.aggregate_hz,
            pct(r.adc_utilization),
            r.adc_limit_hz
        ),
    );
    row("Placement", r.placement.clone());
    row(
        "Slot table size",
        format!(
            "{} entries compact, {} as a full frame table",
            r.lut_entries_compact, r.lut_entries_full
        ),
    );
    row(
        "Warnings and errors",
        format!(
            "{}, {}{}",
            judge::counted(r.warnings.len() as u64, "warning"),
            judge::counted(r.errors.len() as u64, "error"),
            if r.warnings.is_empty() && r.errors.is_empty() {
                ""
            } else {
                " (listed above)"
            }
        ),
    );
    t
}

/// The headroom entry of branch `b` at its fastest own rate (what a user
/// adding "one more of these" meets first).
fn own_headroom<'a>(r: &AuditReport, b: &'a BranchAudit) -> Option<&'a Headroom> {
    let fastest = r
        .channels
        .iter()
        .filter(|c| c.branch == b.name)
        .map(|c| c.requested_hz)
        .max();
    fastest
        .and_then(|f| b.headroom.iter().find(|h| h.rate_hz == f))
        .or(b.headroom.first())
}

/// The first of the most used of `items`, so that a tie keeps the mix's
/// order: "What binds" and the branch table's caption name one branch.
fn first_most_used<T>(items: impl IntoIterator<Item = T>, used: impl Fn(&T) -> f64) -> Option<T> {
    items.into_iter().fold(None, |best, t| match best {
        Some(b) if used(&b) >= used(&t) => Some(b),
        _ => Some(t),
    })
}

pub fn branch_caption(r: &AuditReport) -> String {
    let tight = first_most_used(&r.branches, |b| b.utilization.max(b.adc_utilization));
    // a mix with modes: these are the reset mode's budgets (every mode's
    // follow in their own table)
    let mode = match r.modes.first().filter(|_| r.modes.len() > 1) {
        Some(m) => format!(" in the reset mode `{}`", m.name),
        None => String::new(),
    };
    match tight {
        Some(b) => format!(
            "Branch budgets{mode}: `{}` is the most used ({} of its slots, {} of its converter)",
            b.name,
            pct(b.utilization),
            pct(b.adc_utilization)
        ),
        None => format!("Branch budgets{mode}"),
    }
}

/// A mix with modes: every branch's budget in every mode, from the audit's
/// per-mode tables.
fn mode_branches(r: &AuditReport) -> Table {
    let mut t = Table::new(&[
        "mode",
        "branch",
        "conversions per frame",
        "slots used",
        "converter use (samples/s)",
        "converter used",
    ]);
    for m in &r.modes {
        for b in &m.branches {
            t.push(vec![
                m.name.clone(),
                b.name.clone(),
                b.conversions_per_frame.to_string(),
                pct(b.utilization),
                b.demand_sps.to_string(),
                pct(b.adc_utilization),
            ]);
        }
    }
    t
}

/// A row per branch, led by what binds and the room left.
fn branches(r: &AuditReport) -> Table {
    let mut t = Table::new(&[
        "branch",
        "what binds",
        "room: more channels at its fastest rate",
        "slots used per frame",
        "converter use (samples/s)",
        "free mux inputs",
        "SCLK",
    ]);
    for b in &r.branches {
        let (binds, room) = match own_headroom(r, b) {
            Some(h) => (
                h.binding.describe().to_string(),
                format!("{} at {}", h.more_channels, hz(h.rate_hz as f64)),
            ),
            None => ("-".into(), "-".into()),
        };
        t.push(vec![
            b.name.clone(),
            binds,
            room,
            format!(
                "{} of {} ({})",
                b.conversions_per_frame,
                b.slots_per_frame,
                pct(b.utilization)
            ),
            format!(
                "{} of {:.0} ({})",
                b.demand_sps,
                b.adc_max_sps,
                pct(b.adc_utilization)
            ),
            b.free_mux_inputs.to_string(),
            format!(
                "{} = clock / {} ({} {})",
                hz(b.sclk_hz),
                b.sclk_div,
                hz(b.sclk_requested_hz as f64),
                if b.sclk_explicit {
                    "asked"
                } else {
                    "by default"
                }
            ),
        ]);
    }
    t
}

/// A row per branch and rate: the room, what ends it, each limit apart.
fn headroom(r: &AuditReport) -> Table {
    let mut t = Table::new(&[
        "branch",
        "rate (Hz)",
        "more channels",
        "what binds",
        "free mux inputs allow",
        "converter throughput allows",
        "slot grid allows",
        "on a finer slot grid",
    ]);
    for b in &r.branches {
        for h in &b.headroom {
            t.push(vec![
                b.name.clone(),
                h.rate_hz.to_string(),
                h.more_channels.to_string(),
                h.binding.describe().into(),
                h.by_mux_inputs.to_string(),
                h.by_adc_throughput.to_string(),
                h.by_slot_grid.to_string(),
                h.finer_grid.as_ref().map_or("-".into(), |f| {
                    format!(
                        "{} more with {} slots of {} cycles ({} then binds)",
                        f.more_channels,
                        f.slots_per_slice,
                        f.slot_cycles,
                        f.binding.describe()
                    )
                }),
            ]);
        }
    }
    t
}

/// The link's budget as label and value, its use and margin first.
fn link(l: &LinkPlan, clock_hz: u64) -> Table {
    let mut t = Table::new(&["link figure", "value"]);
    let mut row = |k: &str, v: String| t.push(vec![k.to_string(), v]);
    row(
        "Line use",
        format!(
            "{} ({} margin), {} bytes per frame",
            pct(l.utilization),
            pct((1.0 - l.utilization).max(0.0)),
            l.bytes_per_frame
        ),
    );
    row(
        "FIFO depth (worst-case backlog)",
        format!("{} tokens", l.fifo_depth),
    );
    row(
        "Latency, sampling instant to the packet's last bit",
        format!("{} cycles = {:.1} us", l.latency_cycles, l.latency_us),
    );
    row("Kind", link_kind(l).into());
    if l.kind == "uart" {
        row(
            "Baud",
            format!(
                "{} used = clock {} / {} ({} asked)",
                l.baud.round(),
                hz(clock_hz as f64),
                l.baud_divider,
                l.baud_requested
            ),
        );
        row(
            "Lowest baud that carries the mix",
            format!("{}", l.min_baud.round()),
        );
        row(
            "Character",
            format!(
                "{} line bits per byte: start, 8 data, parity {}, {} stop",
                l.bits_per_byte, l.parity, l.stop_bits
            ),
        );
    }
    if let Some(tl) = l.tlast {
        row("`tlast`", tl.to_string());
    }
    if let Some(w) = l.ready_within {
        row(
            "Slave's guarantee (FIFO sized for it)",
            format!(
                "every beat accepted within {w} cycles{}",
                l.max_ready_within
                    .map(|m| format!(" (the weakest that still carries the mix: {m})"))
                    .unwrap_or_default()
            ),
        );
    }
    row(
        "Words per frame (header, records, trailer)",
        l.words_per_frame.to_string(),
    );
    t
}

/// A row per branch's converter part.
fn parts(r: &AuditReport) -> Table {
    let mut t = Table::new(&[
        "branch",
        "converter",
        "conversion started by",
        "bits",
        "devices in chain (most)",
        "datasheet maximum (samples/s)",
        "maximum at this SCLK (samples/s)",
        "SCLK maximum",
        "read (cycles)",
    ]);
    for p in &r.parts {
        t.push(vec![
            p.branch.clone(),
            p.adc.to_uppercase(),
            match p.start {
                lut_gen::Start::Cs => "CS falling".into(),
                lut_gen::Start::Cnv => format!("CNV rising, {} ns", p.conversion_ns),
            },
            p.bits.to_string(),
            format!("{} ({})", p.chain, p.chain_max),
            p.max_sps.to_string(),
            format!("{}", p.max_samples_hz.round()),
            hz(p.sclk_max_hz as f64),
            p.read_cycles.to_string(),
        ]);
    }
    t
}

/// A row per channel: where it is, when it is sampled, whether its input
/// settles and whether its band aliases.
fn channels(r: &AuditReport) -> Table {
    let mut t = Table::new(&[
        "channel",
        "branch",
        "mux (device.select, or the converter's input)",
        "rate (Hz)",
        "`sample_channel`",
        "interval (cycles)",
        "first sample (cycle)",
        "settling time (us)",
        "signal band, Nyquist (Hz)",
    ]);
    for c in &r.channels {
        t.push(channel_row(c));
    }
    t
}

fn channel_row(c: &ChannelAudit) -> Vec<String> {
    let num = |x: f64| {
        let s = format!("{x:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let rate = if (c.achieved_hz - c.requested_hz as f64).abs() < 1e-9 {
        num(c.achieved_hz)
    } else {
        format!("{} ({} asked)", num(c.achieved_hz), c.requested_hz)
    };
    let band = match (c.bandwidth_hz, c.alias_hz) {
        (Some(b), Some(a)) => format!("{} ({}): ALIASES to {}", num(b), num(c.nyquist_hz), num(a)),
        (Some(b), None) => format!("{} ({})", num(b), num(c.nyquist_hz)),
        (None, _) => format!("not given ({})", num(c.nyquist_hz)),
    };
    vec![
        c.name.clone(),
        c.branch.clone(),
        c.mux_words(),
        rate,
        c.sample_channel.to_string(),
        format!("{} (jitter {})", c.interval_cycles, c.jitter_cycles),
        c.first_sample_cycle.to_string(),
        format!(
            "{:.1} (needs {:.1})",
            c.settle_available_ns / 1e3,
            c.settle_required_ns as f64 / 1e3
        ),
        band,
    ]
}
