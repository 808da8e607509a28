//! A mix with modes in the harness (docs/timing.md, "Mode switches"): the
//! harness keeps its own record of the mode in force and of the next
//! frame's, decided at each frame start as the contract says (pin select:
//! `mode_sel`, a free input in every cycle, as it was in the frame's last
//! cycle; auto select: the triggers evaluated here on the words the harness
//! itself recorded from MISO), asserts `mode`, and reads every pin's
//! expected value from the slot table of the mode in force, each mode's
//! own table from `Schedule::modes` (not from `hdl`'s mode plan).
//!
//! The mux rule across frames: after a branch's last instant of a frame its
//! mux moves to its first instant of the next frame in the next frame's
//! mode; with none (the next mode does not use the branch) it holds
//! (`mx{b}`, the last cycle's expected address), and a frame that does not
//! use it holds through its first cycle too, moving in the second.

use std::fmt::Write;

use lut_gen::{Layout, ModeSelect, Schedule, When};

use super::{width, Clause, FreeInput, PropertyDef, Row};

/// The harness's free input for pin select.
pub const MODE_SEL: &str = "mode_sel";

/// The modes of `s` (more than one), else `None`.
pub(super) fn modes(s: &Schedule) -> Option<&lut_gen::Modes> {
    s.mode_plan()
        .filter(|m| m.names.len() > 1 && !s.modes.is_empty())
}

/// With auto select (the engine then splits its paths on the mode and
/// run registers, `symsim/cases.rs`), the frames the search may need beyond
/// the default depth before every path has come round: two per frame of
/// every trigger's run (a run counts up to `for_frames` in one mode, and the
/// mode it switches to starts another); `None` without auto select.
pub(crate) fn auto_frames(s: &Schedule) -> Option<u64> {
    let m = modes(s).filter(|m| m.select == ModeSelect::Auto)?;
    let runs: u64 = m
        .triggers
        .iter()
        .map(|t| t.for_frames.max(1) as u64 + 1)
        .sum();
    Some(2 * runs)
}

/// With auto select, each trigger's register holding its run of windows
/// (`run{k}`, the name yosys's map gives its latches), in file order;
/// empty without auto select.  The engine generalises them with the
/// design's at frame starts (`lib.rs`, `runs_generalised`).
pub(crate) fn trigger_runs(s: &Schedule) -> Vec<String> {
    let m = modes(s).filter(|m| m.select == ModeSelect::Auto);
    let n = m.map_or(0, |m| m.triggers.len());
    (0..n).map(run_name).collect()
}

/// Trigger `k`'s run register in the harness.
fn run_name(k: usize) -> String {
    format!("run{k}")
}

/// Bits of the mode number (0: no modes).
pub(super) fn bits(s: &Schedule) -> u32 {
    modes(s).map_or(0, |m| m.select_bits())
}

/// `mode_sel` for pin select (after the link's inputs).
pub(super) fn inputs(s: &Schedule) -> Vec<FreeInput> {
    match modes(s) {
        Some(m) if m.select == ModeSelect::Pin => vec![FreeInput {
            name: MODE_SEL.into(),
            width: m.select_bits(),
        }],
        _ => Vec::new(),
    }
}

/// The header's port text for the mode inputs.
pub(super) fn ports(s: &Schedule) -> String {
    inputs(s)
        .iter()
        .map(|i| format!(",\n  input [{}:0] {}", i.width - 1, i.name))
        .collect()
}

/// `.mode_sel(mode_sel), .mode(mode)` after the link's connections.
pub(super) fn connections(s: &Schedule) -> String {
    let Some(m) = modes(s) else {
        return String::new();
    };
    let sel = if m.select == ModeSelect::Pin {
        format!(", .{MODE_SEL}({MODE_SEL})")
    } else {
        String::new()
    };
    format!("{sel}, .mode(mode)")
}

/// Why `s`'s modes have no harness (`None`: they have one).
pub(super) fn refused(s: &Schedule) -> Option<String> {
    modes(s)?;
    let nb = s.branches.len();
    if s.grid.frame_slots < 2 {
        return Some(format!(
            "mix `{}`: a mix with modes needs at least 2 slots per frame",
            s.mix.name
        ));
    }
    // A lead's words must be the same in every mode that converts it (the
    // merger's tables are by lead).
    for (m, ms) in s.modes.iter().enumerate() {
        let leads = (0..s.grid.frame_slots).flat_map(|u| (0..nb).filter_map(move |b| ms.at(u, b)));
        for l in leads {
            if !ms.words_of(l).eq(s.words_of(l)) {
                return Some(format!(
                    "mix `{}`: channel {}'s conversion reads other chained words in mode `{}`, which the formal harness does not follow",
                    s.mix.name, s.mix.channels[l].name, modes(s)?.names[m]
                ));
            }
        }
    }
    let t = modes(s)?.triggers.iter().flat_map(|t| t.channels.iter());
    let chained = t
        .copied()
        .find(|&c| s.mix.branches[s.mix.channels[c].branch].chain > 1);
    chained.map(|c| {
        format!(
            "mix `{}`: a trigger watches channel {} on a chained branch, which the formal harness does not follow",
            s.mix.name, s.mix.channels[c].name
        )
    })
}

/// The mode registers: `mcur` (the frame in force), `mnext` (the next
/// frame's, decided at the edge that began this frame), `mprev` (the frame
/// before's), and `mode` from the design.
pub(super) fn declare(v: &mut String, s: &Schedule) {
    let mb = bits(s);
    if mb == 0 {
        return;
    }
    let _ = writeln!(
        v,
        "  // Modes: the mode in force, the next frame's (decided one frame ahead) and\n  \
         // the one before (docs/timing.md, \"Mode switches\"); frames 0 and 1 run mode 0.\n  \
         wire [{m}:0] mode;\n  reg [{m}:0] mcur = 0, mnext = 0, mprev = 0;",
        m = mb - 1
    );
}

/// Per branch, per mode: the rows of its table (as for one mode, with the
/// tail bit: no instant later in the frame), whether the mode uses the
/// branch and the mux address `(en, sel)` of its first instant.
pub(super) struct ModeRows {
    pub rows: Vec<Vec<Row>>,
    pub tail: Vec<Vec<bool>>,
    pub first: Vec<Option<(u8, u8)>>,
}

pub(super) fn rows(s: &Schedule, b: usize) -> ModeRows {
    let fs = s.grid.frame_slots as usize;
    let mut out = ModeRows {
        rows: vec![],
        tail: vec![],
        first: vec![],
    };
    for ms in &s.modes {
        let rows = super::branch_rows(ms, b);
        let mut tail = vec![true; fs];
        let mut later = false;
        for u in (0..fs).rev() {
            tail[u] = !later;
            later |= rows[u].lead.is_some();
        }
        let first = rows.iter().find_map(|r| r.lead).map(|l| {
            let c = &ms.channels[l as usize];
            (c.device as u8, c.select as u8)
        });
        out.rows.push(rows);
        out.tail.push(tail);
        out.first.push(first);
    }
    out
}

/// Branch `b`'s table over every mode: `tab{b}` (as for one mode) and
/// `tl{b}` from `{mcur, slot}`.
pub(super) fn table(
    s: &Schedule,
    b: usize,
    mr: &ModeRows,
    word: &dyn Fn(&Row) -> String,
) -> String {
    let (mb, sb) = (bits(s), width(s.grid.frame_slots));
    let mut all = Vec::new();
    for (m, rows) in mr.rows.iter().enumerate() {
        for (u, r) in rows.iter().enumerate() {
            all.push((m, u, format!("{{1'b{}, {}}}", mr.tail[m][u] as u8, word(r))));
        }
    }
    let texts: Vec<String> = all.iter().map(|a| a.2.clone()).collect();
    let default = super::most_common(&texts);
    let mut v = format!("  reg tl{b};\n  always @* case ({{mcur, slot}})\n");
    for (m, u, row) in &all {
        if *row != default {
            let _ = writeln!(
                v,
                "    {{{mb}'d{m}, {sb}'d{u}}}: {{tl{b}, tab{b}}} = {row};"
            );
        }
    }
    let _ = writeln!(v, "    default: {{tl{b}, tab{b}}} = {default};\n  endcase");
    v
}

/// Branch `b`'s expected mux `{en, sel}` across frames (`exp_m{b}`), from
/// the rows' `m0{b}` (cycle 0) and `m1{b}` (later cycles).
pub(super) fn mux(v: &mut String, s: &Schedule, b: usize, mr: &ModeRows, en_n: u32) {
    let (mb, cb, sb) = (
        bits(s),
        width(s.grid.slot_cycles),
        width(s.grid.frame_slots),
    );
    let w = en_n + 3;
    let cst = |f: Option<(u8, u8)>| {
        let (d, sel) = f.unwrap_or((0, 0));
        format!("{{{}, 3'd{sel}}}", super::en_const(d, en_n))
    };
    let hold = mr.first.iter().any(|f| f.is_none());
    let _ = writeln!(v, "  reg [{}:0] nf{b};\n  reg nu{b}, cu{b};", w - 1);
    // The next frame's first instant (nu: the next mode uses the branch),
    // and whether the frame in force uses it.
    let _ = writeln!(v, "  always @* begin\n    case (mnext)");
    for (m, f) in mr.first.iter().enumerate() {
        let _ = writeln!(
            v,
            "      {mb}'d{m}: begin nf{b} = {}; nu{b} = 1'b{}; end",
            cst(*f),
            f.is_some() as u8
        );
    }
    let _ = writeln!(
        v,
        "      default: begin nf{b} = {}; nu{b} = 1'b{}; end\n    endcase\n    case (mcur)",
        cst(mr.first[0]),
        mr.first[0].is_some() as u8
    );
    for (m, f) in mr.first.iter().enumerate() {
        let _ = writeln!(v, "      {mb}'d{m}: cu{b} = 1'b{};", f.is_some() as u8);
    }
    let _ = writeln!(v, "      default: cu{b} = 1'b1;\n    endcase\n  end");
    let next = if hold {
        let _ = writeln!(
            v,
            "  // A mode that does not use the branch: its mux holds (mx: last cycle's).\n  \
             reg [{}:0] mx{b} = 0;\n  \
             wire hold0{b} = cyc == {cb}'d0 && slot == {sb}'d0 && !cu{b};",
            w - 1
        );
        format!("hold0{b} ? mx{b} : tl{b} ? (nu{b} ? nf{b} : mx{b})")
    } else {
        format!("tl{b} ? nf{b}")
    };
    let _ = writeln!(
        v,
        "  wire [{}:0] exp_m{b} = (cyc == {cb}'d0 && act{b}) ? m0{b} : {next} : \
         (cyc == {cb}'d0 ? m0{b} : m1{b});",
        w - 1
    );
    if hold {
        let _ = writeln!(
            v,
            "  always @(posedge clk) if (st != 2'd0) mx{b} <= exp_m{b};"
        );
    }
}

/// After the branches: the decision at each frame start, the `mode`
/// property.
pub(super) fn decide(v: &mut String, props: &mut Vec<PropertyDef>, s: &Schedule, layout: &Layout) {
    let Some(m) = modes(s) else {
        return;
    };
    let (mb, n) = (m.select_bits(), m.names.len());
    let dec = match m.select {
        ModeSelect::Pin => format!(
            "  // Pin select: mode_sel in the frame's last cycle; a value naming no mode keeps mnext.\n  \
             wire [{}:0] dec = {MODE_SEL} < {}'d{n} ? {MODE_SEL} : mnext;\n",
            mb - 1,
            mb + 1
        ),
        ModeSelect::Auto => triggers(v, s, layout, m),
    };
    v.push_str(&dec);
    let _ = writeln!(
        v,
        "  always @(posedge clk) if (run && frame_end) begin\n    \
         mprev <= mcur; mcur <= mnext; mnext <= dec;\n  end\n  \
         wire ok_mode = mode == mcur;"
    );
    props.push(PropertyDef {
        name: "mode".into(),
        wire: "ok_mode".into(),
        covers: vec![Clause::Mode],
        what: match m.select {
            ModeSelect::Pin => "`mode` shows the mode in force; a switch takes effect at a frame start, two frames after mode_sel names the mode in a frame's last cycle, for every sequence of requests".into(),
            ModeSelect::Auto => "`mode` shows the mode in force; a switch takes effect at a frame start, the frame after a trigger's condition held in its windows, for any MISO input".into(),
        },
    });
}

/// Auto select: each trigger's window flags over the watched words as
/// their conversions complete (`done{b}`), the run of windows, and the
/// decision; returns the `dec` wire's text.
fn triggers(v: &mut String, s: &Schedule, layout: &Layout, m: &lut_gen::Modes) -> String {
    let (mb, chb, vb) = (m.select_bits(), layout.channel_bits, layout.value_bits);
    let nb = s.branches.len();
    // the code of each branch's completing conversion (word 0: watched
    // channels are on unchained branches)
    for b in 0..nb {
        let spi = &s.branches[b].spi;
        let n = spi.sclks();
        let lo = n - (spi.leading_bits as u64 + spi.bits as u64);
        let _ = writeln!(
            v,
            "  wire [{}:0] code{b} = w{b}[{}:{lo}];",
            vb - 1,
            lo + spi.bits as u64 - 1
        );
    }
    let mut dec = String::new();
    for (k, t) in m.triggers.iter().enumerate() {
        let ff = t.for_frames.max(1) as u64;
        let rb = width(ff + 1);
        let rn = run_name(k);
        let mut hits = Vec::new();
        for b in 0..nb {
            let watched: Vec<String> = (t.channels.iter())
                .filter(|&&c| s.mix.channels[c].branch == b)
                .map(|c| format!("lead{b} == {chb}'d{c}"))
                .collect();
            if !watched.is_empty() {
                hits.push((b, watched.join(" || ")));
            }
        }
        let _ = writeln!(
            v,
            "  // Trigger {k} (line {}): window flags, this cycle's words included.",
            t.line
        );
        let (mut any, mut above, mut below) = (vec![], vec![], vec![]);
        for (b, w) in &hits {
            let _ = writeln!(v, "  wire h{k}_{b} = done{b} && ({w});");
            any.push(format!("h{k}_{b}"));
            above.push(format!("(h{k}_{b} && code{b} > 32'd{})", t.level));
            below.push(format!("(h{k}_{b} && !(code{b} < 32'd{}))", t.level));
        }
        let or = |x: &[String]| {
            if x.is_empty() {
                "1'b0".to_string()
            } else {
                x.join(" || ")
            }
        };
        let _ = writeln!(
            v,
            "  reg wa{k} = 1'b0, wx{k} = 1'b0, wn{k} = 1'b0;\n  \
             wire na{k} = wa{k} || {};\n  wire nx{k} = wx{k} || {};\n  wire nn{k} = wn{k} || {};\n  \
             wire held{k} = {};\n  reg [{}:0] {rn} = 0;\n  \
             wire [{}:0] nrun{k} = !held{k} ? {rb}'d0 : (!first && mcur == mprev) ? \
             ({rn} == {rb}'d{ff} ? {rn} : {rn} + {rb}'d1) : {rb}'d1;\n  \
             always @(posedge clk) if (run) begin\n    \
             if (frame_end) begin wa{k} <= 1'b0; wx{k} <= 1'b0; wn{k} <= 1'b0; {rn} <= nrun{k}; end\n    \
             else begin wa{k} <= na{k}; wx{k} <= nx{k}; wn{k} <= nn{k}; end\n  end",
            or(&any),
            or(&above),
            or(&below),
            match t.when {
                When::Above => format!("nx{k}"),
                When::Below => format!("na{k} && !nn{k}"),
            },
            rb - 1,
            rb - 1,
        );
        // `==`, not `>=`: the same on every count a run reaches (it stops at
        // `ff`), and on every other the same as the gateware's test, so the
        // engine may generalise the counts (`trigger_runs`)
        let armed: Vec<String> = (0..m.names.len())
            .filter(|&x| t.leaves(x))
            .map(|x| format!("mnext == {mb}'d{x}"))
            .collect();
        let _ = write!(
            dec,
            "({}) && mcur == mnext && nrun{k} == {rb}'d{ff} ? {mb}'d{} : ",
            or(&armed),
            t.to
        );
    }
    format!(
        "  // Auto select: the first trigger armed in the next frame's mode whose\n  \
         // condition held in its last for_frames windows, all in that mode.\n  \
         wire [{}:0] dec = {dec}mnext;\n",
        mb - 1
    )
}

/// What a bounded result leaves out for a mix with modes (none for a proof
/// or a counterexample): every cycle past the search, said in the modes'
/// terms, so the report's `not_covered` names what was bounded.
pub(crate) fn bounded_modes(s: &Schedule, result: crate::Outcome, steps: u64) -> Option<String> {
    let m = modes(s).filter(|_| result == crate::Outcome::Bounded)?;
    let f = s.grid.frame_cycles;
    let cycles = steps.saturating_sub(2);
    // the note says why the search stopped (depth or time limit)
    Some(format!(
        "every mode switch and every pin after cycle {cycles} (frame {} on): the search from reset \
         covered {cycles} cycles ({:.2} frames), every sequence of {} within them, nothing beyond",
        cycles / f,
        cycles as f64 / f as f64,
        match m.select {
            ModeSelect::Auto => "MISO codes and so of trigger firings",
            ModeSelect::Pin => "mode requests and MISO codes",
        }
    ))
}
