//! The pin contract as clauses, so `prove` can say what it did not assert.
//!
//! [`contract`] lists the clauses a mix's `slotforge_top` owes at its
//! outputs (docs/timing.md; with a link, docs/packet-format.md), from the
//! ports the mix has.  (How long the reset is, is the proof's assumption,
//! not a clause: the harness holds `rst` high in one cycle, the shortest
//! reset and the hardest for start-up, and every summary says so.)  Each harness property names the clauses it asserts
//! ([`super::PropertyDef::covers`]); [`not_covered`] is the difference.  So
//! the list a user reads follows what the generated harness asserts: a
//! property added for a clause takes that clause off the list, and none is
//! listed by preset.

use lut_gen::Layout;
use lut_gen::Schedule;

use super::link::AXIS_BYTES_MAX_WAIT;
use super::PropertyDef;

/// One clause of the pin contract at the design's outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Clause {
    /// Branch `b`'s conversion pin (CS or CNV) in every conversion window.
    Conversion(usize),
    /// Branch `b`'s SCLK: count, period, phase and idle level.
    Sclk(usize),
    /// Branch `b`'s mux select and device enables.
    Mux(usize),
    /// Branch `b`'s command word on `adc_mosi` (a converter that takes one).
    Mosi(usize),
    /// That branch `b`'s converter converts the input its word selected,
    /// `ahead` conversions later: the part's own behaviour, which no proof
    /// with a free `adc_miso` can assert.
    CommandEffect(usize),
    /// `sample_valid`: one strobe per word, in the merged stream's order.
    StreamValid,
    /// `sample_channel` of each word.
    StreamChannel,
    /// `sample_value` of each word.
    StreamValue,
    /// `link_overflow` stays low: the FIFO never drops a token.
    LinkOverflow,
    /// The UART's characters on `link_tx`: start bit, data bits, parity,
    /// stop bits at the baud divider, idle high.
    UartCharacters,
    /// The AXI4-Stream's beats taken: each the next byte of the packets,
    /// and `tlast` on exactly the last byte of each (by slice or frame).
    AxisBeats,
    /// A beat offered and not taken stays offered (`tvalid`).
    AxisValidHeld,
    /// A beat offered and not taken keeps its `tdata` and `tlast`.
    AxisPayloadHeld,
    /// The bytes the link carries: packets, records, frame counter, CRC.
    LinkPackets,
    /// `mode` shows the mode in force, switching only at the frame starts
    /// the contract decides (a mix with modes).
    Mode,
}

/// The clauses `s`'s design owes at its outputs, in report order.
pub fn contract(s: &Schedule, layout: &Layout) -> Vec<Clause> {
    // A branch without a mux has no mux lines to owe.
    let mut c: Vec<Clause> = (0..s.branches.len())
        .flat_map(|b| {
            let mux = layout.muxed.get(b).copied().unwrap_or(true);
            let cmd = s.has_command(b);
            [Clause::Conversion(b), Clause::Sclk(b)]
                .into_iter()
                .chain(mux.then_some(Clause::Mux(b)))
                .chain(cmd.then_some(Clause::Mosi(b)))
                .chain(cmd.then_some(Clause::CommandEffect(b)))
        })
        .collect();
    c.extend([
        Clause::StreamValid,
        Clause::StreamChannel,
        Clause::StreamValue,
    ]);
    if layout.link {
        c.push(Clause::LinkOverflow);
        if layout.axis {
            c.extend([
                Clause::AxisValidHeld,
                Clause::AxisPayloadHeld,
                Clause::AxisBeats,
            ]);
        } else {
            c.push(Clause::UartCharacters);
        }
        c.push(Clause::LinkPackets);
    }
    if layout.mode_bits > 0 {
        c.push(Clause::Mode);
    }
    c
}

/// The clauses of `s`'s contract that none of `props` asserts.
pub fn not_covered(s: &Schedule, props: &[PropertyDef]) -> Vec<Clause> {
    contract(s, &Layout::new(s))
        .into_iter()
        .filter(|c| !props.iter().any(|p| p.covers.contains(c)))
        .collect()
}

impl Clause {
    /// The clause in a user's words, with `s`'s names and figures.
    pub fn sentence(&self, s: &Schedule) -> String {
        let name = |b: usize| s.branches[b].name.as_str();
        match *self {
            Clause::Conversion(b) => format!(
                "branch {}'s conversion pin (adc_cs_n[{b}]) in every conversion window",
                name(b)
            ),
            Clause::Sclk(b) => format!("branch {}'s SCLK (adc_sclk[{b}])", name(b)),
            Clause::Mux(b) => format!("branch {}'s mux select and enable lines", name(b)),
            Clause::Mosi(b) => format!(
                "branch {}'s command word on adc_mosi[{}]",
                name(b),
                Layout::new(s).mosi_lo[b].unwrap_or_default()
            ),
            Clause::CommandEffect(b) => format!(
                "that branch {}'s {} converts the input each word selects ({}){}: the part's own \
                 behaviour; adc_miso is free in the proof, so any code it returns is taken as \
                 the channel the schedule names",
                name(b),
                s.mix.branches[b].adc.name,
                match s.prepared_conversions(b) {
                    0 => "in the same conversion".to_string(),
                    n => format!("{n} conversions later"),
                },
                match s.mix.branches[b].fronted {
                    true => ", behind the front mux input its pins address at the instant",
                    false => "",
                }
            ),
            Clause::StreamValid => "sample_valid: one strobe per converted word".into(),
            Clause::StreamChannel => "sample_channel of every word".into(),
            Clause::StreamValue => "sample_value of every word".into(),
            Clause::LinkOverflow => {
                "link_overflow stays low (the link's FIFO never drops a token)".into()
            }
            Clause::UartCharacters => uart_characters(s),
            Clause::AxisBeats => format!(
                "the AXI4-Stream's beats: each beat taken (m_axis_tvalid and m_axis_tready) \
                 carries the next byte of the packets on m_axis_tdata, and m_axis_tlast is high \
                 on exactly the last byte of each packet{}",
                axis_wait(s)
            ),
            Clause::AxisValidHeld => {
                "a beat offered and not taken stays offered (m_axis_tvalid)".into()
            }
            Clause::AxisPayloadHeld => {
                "a beat offered and not taken keeps m_axis_tdata and m_axis_tlast".into()
            }
            Clause::LinkPackets => format!(
                "the packets the link carries on {} (each slice's header with the frame \
                 counter{} and slice, one record per sample with its channel and code, the \
                 trailer with the overflow count and CRC-16/MODBUS; docs/packet-format.md){}",
                if Layout::new(s).axis {
                    "m_axis_tdata"
                } else {
                    "link_tx"
                },
                if Layout::new(s).mode_bits > 0 {
                    ", the mode"
                } else {
                    ""
                },
                axis_wait(s)
            ),
            Clause::Mode => mode_sentence(s),
        }
    }
}

/// Why an AXI4-Stream's bytes are not asserted, after their clause's
/// sentence; empty for a mix whose bytes the harness asserts (a UART, or a
/// slave that keeps a beat waiting at most [`AXIS_BYTES_MAX_WAIT`] cycles).
fn axis_wait(s: &Schedule) -> String {
    match s.mix.link.as_ref() {
        Some(l) if Layout::new(s).axis && l.ready_within.max(1) > AXIS_BYTES_MAX_WAIT => format!(
            " (not asserted: the slave may keep a beat waiting up to ready_within = {} \
             cycles, past the {AXIS_BYTES_MAX_WAIT} whose choices a proof splits on in \
             seconds; `slotforge prove --axis-bytes` asserts them, in minutes on a 48 MHz \
             mix; docs/formal.md, \"Limits\")",
            l.ready_within
        ),
        _ => String::new(),
    }
}

/// The UART clause with the character the audit reports (its divider and
/// real baud, `lut_gen::plan_link`).
fn uart_characters(s: &Schedule) -> String {
    let frame = match lut_gen::plan_link(s) {
        Some(Ok(p)) => format!(
            ": start bit, 8 data bits LSB first, parity {}, {} stop bit{}, each bit {} cycles \
             ({:.0} baud)",
            p.parity,
            p.stop_bits,
            if p.stop_bits == 1 { "" } else { "s" },
            p.baud_divider,
            p.baud
        ),
        _ => String::new(),
    };
    format!("the UART's bit stream on link_tx, character by character{frame}; the line idles high")
}

/// The mode clause: what `mode` and the switches owe, by the select kind.
fn mode_sentence(s: &Schedule) -> String {
    let auto = s
        .mode_plan()
        .is_some_and(|m| m.select == lut_gen::ModeSelect::Auto);
    format!(
        "mode shows the mode in force and every switch takes effect at the frame start \
         the contract decides ({}; docs/timing.md, \"Mode switches\")",
        if auto {
            "the triggers on the watched words"
        } else {
            "mode_sel in a frame's last cycle"
        }
    )
}
