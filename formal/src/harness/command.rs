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
    if super::modes::bits(s) > 0 {
        mode_words(v, s, b, l);
    } else {
        let _ = writeln!(v, "  reg [{}:0] cw{b};\n  always @* case (slot)", l - 1);
        for c in &sent {
            let _ = writeln!(v, "    {sb}'d{}: cw{b} = {l}'b{};", c.slot, bits(&c.word));
        }
        let _ = writeln!(v, "    default: cw{b} = {l}'d0;\n  endcase");
    }
    let word = match super::modes::bits(s) {
        0 => format!("cw{b}"),
        _ => format!("cwe{b}"),
    };
    let terms: Vec<String> = (0..l as u64)
        .filter(|&k| k < spi.sclks())
        .map(|k| {
            // after the branch's hold-off, if it has one
            let from = spi.holdoff_cycles + spi.setup_cycles + k * spi.sclk_div;
            format!(
                "(cyc >= {cb}'d{from} && cyc < {cb}'d{} && {word}[{}])",
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

/// `cw{b}` in a mix with modes: each mode's words from its own table on
/// `{mcur, slot}`; a word of a frame's last `ahead` conversions selects
/// the next frame's conversion `j`, whose input the next frame's mode
/// (`mnext`, decided at the edge that began this frame) gives.
fn mode_words(v: &mut String, s: &Schedule, b: usize, l: usize) {
    let Some(cmd) = &s.mix.branches[b].adc.command else {
        return;
    };
    let ahead = cmd.ahead as usize;
    let (mb, sb) = (super::modes::bits(s), width(s.grid.frame_slots));
    let jw = width(ahead.max(1) as u64);
    let bits = |w: &[bool]| -> String { w.iter().map(|&x| if x { '1' } else { '0' }).collect() };
    let word = |c: usize| bits(&cmd.word(s.mix.channels[c].input));
    let _ = writeln!(
        v,
        "  reg [{}:0] cw{b}, cf{b};\n  reg cx{b};\n  reg [{}:0] cj{b};\n  always @* begin\n    \
         cw{b} = {l}'d0; cx{b} = 1'b0; cj{b} = {jw}'d0;\n    case ({{mcur, slot}})",
        l - 1,
        jw - 1
    );
    let mut first = vec![];
    for (m, ms) in s.modes.iter().enumerate() {
        let convs: Vec<(u64, usize)> = (0..s.grid.frame_slots)
            .filter_map(|u| ms.at(u, b).map(|c| (u, c)))
            .collect();
        let n = convs.len();
        for (k, (u, _)) in convs.iter().enumerate() {
            let key = format!("{{{mb}'d{m}, {sb}'d{u}}}");
            let _ = match convs.get(k + ahead) {
                Some(&(_, c)) => writeln!(v, "      {key}: cw{b} = {l}'b{};", word(c)),
                None => writeln!(
                    v,
                    "      {key}: begin cx{b} = 1'b1; cj{b} = {jw}'d{}; end",
                    k + ahead - n
                ),
            };
        }
        first.push(
            convs
                .iter()
                .take(ahead)
                .map(|&(_, c)| word(c))
                .collect::<Vec<_>>(),
        );
    }
    let _ = writeln!(
        v,
        "      default: ;\n    endcase\n  end\n  // The next frame's conversion j in the next frame's mode.\n  \
         always @* case ({{mnext, cj{b}}})"
    );
    for (m, f) in first.iter().enumerate() {
        for (j, w) in f.iter().enumerate() {
            let _ = writeln!(v, "    {{{mb}'d{m}, {jw}'d{j}}}: cf{b} = {l}'b{w};");
        }
    }
    let _ = writeln!(
        v,
        "    default: cf{b} = {l}'d0;\n  endcase\n  wire [{}:0] cwe{b} = cx{b} ? cf{b} : cw{b};",
        l - 1
    );
}
