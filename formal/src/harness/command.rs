//! Converters with a command word (docs/timing.md, "Command words"): the
//! harness asserts `adc_mosi` bit for bit (each conversion's word, read
//! from the schedule's `commands_in_frame`, bit `k` through SCLK period
//! `k + 1`, 0 elsewhere) and leaves the first `ahead` conversions after
//! reset out of the merged stream (they are prepared, never data).  What
//! the converter does with the word is the part's: `adc_miso` stays free,
//! so the proof holds for any code it returns, and says nothing of whether
//! it converted the input the word selected (`Clause::CommandEffect`).

use std::fmt::Write;

use lut_gen::{Layout, Role, Schedule};

use super::{width, Clause, PropertyDef};

/// The declaration of the top's `adc_mosi` and its connection (none for a
/// mix without a command word).
pub(super) fn port(layout: &Layout) -> (String, &'static str) {
    let w = layout.width(Role::Mosi);
    if w == 0 {
        return (String::new(), "");
    }
    (
        format!("\n  wire [{}:0] adc_mosi;", w - 1),
        " .adc_mosi(adc_mosi),",
    )
}

/// `done{b}` of a branch with a pipeline: a completion counts only once the
/// prepared conversions are past (`prep{b}` counts them down); for every
/// other branch the plain completion.
pub(super) fn done(v: &mut String, s: &Schedule, b: usize, completes: &str) {
    let ahead = s.prepared_conversions(b) as u64;
    if ahead == 0 {
        let _ = writeln!(v, "  wire done{b} = {completes};");
        return;
    }
    let w = width(ahead + 1);
    let _ = writeln!(
        v,
        "  // The first {ahead} conversions after reset are prepared: no word leaves.\n  \
         reg [{}:0] prep{b} = {w}'d{ahead};\n  wire fin{b} = {completes};\n  \
         always @(posedge clk) if (fin{b} && prep{b} != {w}'d0) prep{b} <= prep{b} - {w}'d1;\n  \
         wire done{b} = fin{b} && prep{b} == {w}'d0;",
        w - 1
    );
}

/// Branch `b`'s expected `adc_mosi` bit and its property (a branch with a
/// command word only).
pub(super) fn mosi(
    v: &mut String,
    props: &mut Vec<PropertyDef>,
    s: &Schedule,
    layout: &Layout,
    b: usize,
) {
    let Some(lane) = layout.mosi_lo[b] else {
        return;
    };
    let sent = s.commands_in_frame(b);
    let l = sent.first().map_or(1, |c| c.word.len()).max(1);
    let (cb, sb) = (width(s.grid.slot_cycles), width(s.grid.frame_slots));
    let spi = &s.branches[b].spi;
    let bits = |w: &[bool]| -> String { w.iter().map(|&x| if x { '1' } else { '0' }).collect() };
    let _ = writeln!(
        v,
        "  // The word each conversion of branch {b} sends, first bit on top."
    );
    let _ = writeln!(v, "  reg [{}:0] cw{b};\n  always @* case (slot)", l - 1);
    for c in &sent {
        let _ = writeln!(v, "    {sb}'d{}: cw{b} = {l}'b{};", c.slot, bits(&c.word));
    }
    let _ = writeln!(v, "    default: cw{b} = {l}'d0;\n  endcase");
    let terms: Vec<String> = (0..l as u64)
        .filter(|&k| k < spi.sclks())
        .map(|k| {
            // after the branch's hold-off, if it has one
            let from = spi.holdoff_cycles + spi.setup_cycles + k * spi.sclk_div;
            format!(
                "(cyc >= {cb}'d{from} && cyc < {cb}'d{} && cw{b}[{}])",
                from + spi.sclk_div,
                l as u64 - 1 - k
            )
        })
        .collect();
    let _ = writeln!(
        v,
        "  wire exp_mosi{b} = conv{b} && ({});\n  wire ok_mosi{b} = adc_mosi[{lane}] == exp_mosi{b};",
        terms.join(" || ")
    );
    props.push(PropertyDef {
        name: format!("mosi[{}]", s.branches[b].name),
        wire: format!("ok_mosi{b}"),
        covers: vec![Clause::Mosi(b)],
        what: "the command word of every conversion on adc_mosi, one bit per SCLK period, \
               selecting the channel the schedule converts `ahead` conversions later; low \
               outside the word"
            .into(),
    });
}
