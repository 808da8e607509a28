//! The Verilog twin of `Core::update`.

use crate::widths::*;

/// The merger's form as the glue wires it: the queue (each lane's MISO
/// sources) or the priority form, with a stepped chain's reader
/// (`merger::stepped_reader`) or not.
pub(super) enum LaneForm<'a> {
    Queue(&'a [Vec<usize>]),
    Priority { stepped: bool },
}

/// The Verilog twin of `Core::update`: pure wiring, generated per mix.
/// `wires`: per sequencer, its CNV pulse if its part is read with CNV low
/// and its hold-off if its transactions start after the slot tick. `modes`:
/// a mix with modes (pin select, the branches whose words the mode block
/// reads). `cmds`: each branch's command unit, and per unit whether it reads
/// the modes (behind a front mux in a mix with modes).
pub(super) fn core_glue(
    nb: usize,
    devices: &[usize],
    seq_of: &[usize],
    wires: SeqWires,
    (cmd_of, moded): (&[Option<usize>], &[bool]),
    modes: Option<(bool, usize)>,
    lanes_form: LaneForm,
) -> String {
    let (queue, step) = match lanes_form {
        LaneForm::Queue(q) => (Some(q), false),
        LaneForm::Priority { stepped } => (None, stepped),
    };
    let mut s = String::new();
    let nseq = wires.pulse_of.len();
    s.push_str("always @(*) begin\n");
    child_inputs(&mut s, nb, seq_of, &wires, modes.is_none());
    if let Some((pin, lanes)) = modes {
        mode_inputs(&mut s, nb, pin, lanes, cmd_of);
    }
    let act_read = queue_inputs(&mut s, nb, queue, step);
    command_units(&mut s, seq_of, &wires, (cmd_of, moded));
    lanes(&mut s, nb, devices, cmd_of);
    s.push_str(
        "  sample_valid = merge$valid;\n  sample_channel = merge$channel;\n  sample_value = merge$value;\n  slot_tick = timing$start1;\nend\n",
    );
    unused_wires(&mut s, nb, devices, nseq);
    let released: Vec<String> = (0..nseq)
        .filter(|&i| wires.pulse_of[i].is_some())
        .map(|i| format!("seqs${i}$cs_n"))
        .collect();
    if !released.is_empty() {
        s.push_str(&format!(
            "// sequencers whose branches take the CNV pulse as their pin\nwire unused_seq_cs_n = |{{{}}};\n",
            released.join(", ")
        ));
    }
    if modes.is_some() {
        s.push_str("// the mode block gives the branches their ROM address\nwire unused_slice = |timing$slice;\n");
    }
    let unread: Vec<String> = (0..nb)
        .filter(|b| !act_read.contains(b))
        .map(|b| format!("branches${b}$act_q"))
        .collect();
    if queue.is_none() && step {
        s.push_str("// the queue form's channel enable (zero in the priority form)\nwire unused_queue_en = merge$ch_en;\n");
    } else if queue.is_none() {
        s.push_str("// the queue form's lane enables (zero in the priority form)\nwire unused_queue_en = merge$sh_en | merge$ch_en;\n");
    }
    if !unread.is_empty() {
        s.push_str(&format!(
            "// conversion flags the MISO routing does not need\nwire unused_act = |{{{}}};\n",
            unread.join(", ")
        ));
    }
    s
}

/// The lane whose register captures branch `b`'s MISO is `j` when `b`
/// converts and exactly `j` branches below it do: the routing of the
/// merger's queue form (each lane takes the next one's word, so a slot's
/// words must sit in lanes `0..n` in branch order). A lane with one source
/// reads it unconditionally: in the slots it is used it is that one.
pub fn route_miso(queue: &[Vec<usize>], act: u64, miso: u64) -> u64 {
    let mut out = 0u64;
    for (j, srcs) in queue.iter().enumerate() {
        let last = srcs.last().copied().unwrap_or(j);
        let b = srcs[..srcs.len().saturating_sub(1)]
            .iter()
            .copied()
            .find(|&b| (act >> b) & 1 == 1 && (act & ((1u64 << b) - 1)).count_ones() as usize == j)
            .unwrap_or(last);
        out |= ((miso >> b) & 1) << j;
    }
    out
}

/// The Verilog of [`route_miso`] and the queue's lane-to-lane wiring (or in
/// the priority form, MISO straight and the queue inputs tied low); the
/// branches whose `act_q` it reads.
fn queue_inputs(s: &mut String, nb: usize, queue: Option<&[Vec<usize>]>, step: bool) -> Vec<usize> {
    let mut read = Vec::new();
    // a stepped chain's reader loads under the merger's registered enable
    let sh_en = if step { "merge$sh_en" } else { "1'b0" };
    for b in 0..nb {
        let u = format!("branches${b}");
        let Some(q) = queue else {
            s.push_str(&format!(
                "  {u}$miso = adc_miso[{b}];\n  {u}$sh_en = {sh_en};\n  {u}$ch_en = 1'b0;\n  {u}$q_ch = {CH_BITS}'h0;\n  {u}$q_val = {VALUE_BITS}'h0;\n"
            ));
            continue;
        };
        let srcs = &q[b];
        let last = srcs.last().copied().unwrap_or(b);
        let mut e = format!("adc_miso[{last}]");
        for &src in srcs[..srcs.len().saturating_sub(1)].iter().rev() {
            read.extend(0..=src);
            e = format!("({}) ? adc_miso[{src}] : {e}", lanes_below_is(src, b));
        }
        s.push_str(&format!(
            "  {u}$miso = {e};\n  {u}$sh_en = merge$sh_en;\n  {u}$ch_en = merge$ch_en;\n"
        ));
        if b + 1 < nb {
            let n = format!("branches${}", b + 1);
            s.push_str(&format!(
                "  {u}$q_ch = {n}$res_ch;\n  {u}$q_val = {n}$res_val;\n"
            ));
        } else {
            s.push_str(&format!(
                "  {u}$q_ch = {CH_BITS}'h0;\n  {u}$q_val = {VALUE_BITS}'h0;\n"
            ));
        }
    }
    read.sort_unstable();
    read.dedup();
    read
}

/// Branch `src` converts with exactly `j` branches below it converting.
fn lanes_below_is(src: usize, j: usize) -> String {
    let act = |b: usize| format!("branches${b}$act_q");
    let mut t = vec![act(src)];
    if j == 0 {
        t.extend((0..src).map(|b| format!("!{}", act(b))));
    } else if j == src {
        t.extend((0..src).map(act));
    } else {
        let w = usize::BITS as usize - src.leading_zeros() as usize;
        let sum: Vec<String> = (0..src)
            .map(|b| format!("{{{}'h0, {}}}", w - 1, act(b)))
            .collect();
        t.push(format!("({}) == {w}'d{j}", sum.join(" + ")));
    }
    t.join(" && ")
}

/// Where each sequencer's levels come from and its start goes: its CNV
/// pulse (`pulse_of`), its hold-off (`hold_of`).
pub(super) struct SeqWires<'a> {
    pub(super) pulse_of: &'a [Option<usize>],
    pub(super) hold_of: &'a [Option<usize>],
}

impl SeqWires<'_> {
    /// The start of sequencer `i` (and of its pulse).
    fn start2(&self, i: usize) -> String {
        match self.hold_of[i] {
            Some(h) => format!("holds${h}$fire2"),
            None => "timing$start2".into(),
        }
    }

    /// The slot start the branches (and command units) of sequencer `i` see.
    fn start0(&self, i: usize) -> String {
        match self.hold_of[i] {
            Some(h) => format!("holds${h}$start0"),
            None => "timing$start0".into(),
        }
    }

    /// The sequencer's level `what` (`cs_n`, `sclk`, `cap`, `done`) as its
    /// branches take it: through the hold-off's mask, the pin from the CNV pulse.
    fn level(&self, i: usize, what: &str) -> String {
        match (self.hold_of[i], what) {
            (Some(h), _) => format!("holds${h}${what}"),
            (None, "cs_n") => self.pin(i),
            (None, _) => format!("seqs${i}${what}"),
        }
    }

    fn pin(&self, i: usize) -> String {
        match self.pulse_of[i] {
            Some(p) => format!("pulses${p}$pin_n"),
            None => format!("seqs${i}$cs_n"),
        }
    }
}

/// Clock, reset, slot strobes and sequencer levels into every child (a
/// branch whose sequencer has a CNV pulse takes the pulse as its pin).
/// `timebase`: the branches' ROM address is the timing generator's (else
/// the mode block's, [`mode_inputs`]).
fn child_inputs(s: &mut String, nb: usize, seq_of: &[usize], w: &SeqWires, timebase: bool) {
    for (who, _) in [("timing", 0), ("merge", 0)] {
        s.push_str(&format!("  {who}$clock = clock;\n  {who}$rst = rst;\n"));
    }
    for i in 0..w.pulse_of.len() {
        let q = format!("seqs${i}");
        s.push_str(&format!(
            "  {q}$clock = clock;\n  {q}$rst = rst;\n  {q}$start2 = {};\n",
            w.start2(i)
        ));
    }
    for (i, p) in w.pulse_of.iter().enumerate() {
        let Some(p) = p else { continue };
        let q = format!("pulses${p}");
        s.push_str(&format!(
            "  {q}$clock = clock;\n  {q}$rst = rst;\n  {q}$start2 = {};\n",
            w.start2(i)
        ));
    }
    for (i, h) in w.hold_of.iter().enumerate() {
        let Some(h) = h else { continue };
        let (q, u) = (format!("seqs${i}"), format!("holds${h}"));
        s.push_str(&format!(
            "  {u}$clock = clock;\n  {u}$rst = rst;\n  {u}$start2 = timing$start2;\n  {u}$cs_in = {};\n  {u}$sclk_in = {q}$sclk;\n  {u}$cap_in = {q}$cap;\n  {u}$done_in = {q}$done;\n",
            w.pin(i)
        ));
    }
    // the queue form's single sequencer (unused by the priority form)
    s.push_str("  merge$cap_next = seqs$0$cap_next;\n  merge$start2 = timing$start2;\n  merge$addr = timing$addr;\n  merge$seq_done = seqs$0$done;\n");
    for (b, &seq) in seq_of.iter().enumerate().take(nb) {
        let u = format!("branches${b}");
        s.push_str(&format!(
            "  {u}$clock = clock;\n  {u}$rst = rst;\n  {u}$start2 = timing$start2;\n  {u}$start1 = timing$start1;\n  {u}$start0 = {};\n",
            w.start0(seq)
        ));
        if timebase {
            s.push_str(&format!(
                "  {u}$addr = timing$addr;\n  {u}$slice = timing$slice;\n"
            ));
        }
        s.push_str(&format!(
            "  {u}$seq_cs_n = {};\n  {u}$seq_sclk = {};\n  {u}$seq_cap = {};\n  {u}$seq_done = {};\n  {u}$grant = merge$grant[{b}];\n",
            w.level(seq, "cs_n"),
            w.level(seq, "sclk"),
            w.level(seq, "cap"),
            w.level(seq, "done")
        ));
    }
}

/// Each command unit's inputs (its branch's pins, its sequencer's levels,
/// the slot start) and the `adc_mosi` lanes (absent without a unit).
fn command_units(
    s: &mut String,
    seq_of: &[usize],
    w: &SeqWires,
    (cmd_of, moded): (&[Option<usize>], &[bool]),
) {
    let mut lanes = vec![];
    for (b, i) in cmd_of.iter().enumerate() {
        let Some(i) = i else { continue };
        let (u, q, c) = (format!("branches${b}"), seq_of[b], format!("cmds${i}"));
        s.push_str(&format!(
            "  {c}$clock = clock;\n  {c}$rst = rst;\n  {c}$start0 = {};\n  {c}$pin = {u}$cs_n;\n  {c}$bsclk = {u}$sclk;\n  {c}$qsclk = {};\n  {c}$qdone = {};\n  {c}$sel = {u}$mux_sel;\n  {c}$hi = {u}$mux_en[1];\n  {c}$done = {u}$done;\n",
            w.start0(q),
            w.level(q, "sclk"),
            w.level(q, "done")
        ));
        if moded[*i] {
            // the mode in force, and the next frame's (minfo's low bits)
            s.push_str(&format!(
                "  {c}$mode$0 = modes$0$mode;\n  {c}$nxt$0 = modes$0$minfo[{}:0];\n",
                MODE_BITS - 1
            ));
        }
        lanes.insert(0, format!("{c}$mosi"));
    }
    if !lanes.is_empty() {
        if lanes.len() < MAX_BRANCHES {
            lanes.insert(0, format!("{}'h0", MAX_BRANCHES - lanes.len()));
        }
        s.push_str(&format!("  adc_mosi$0 = {{{}}};\n", lanes.join(", ")));
    }
}

/// The mode block's inputs, the ROM address and mode information it gives
/// every branch in place of the timing generator's, and the `mode` port.
fn mode_inputs(s: &mut String, nb: usize, pin: bool, lanes: usize, cmd_of: &[Option<usize>]) {
    let g = "modes$0";
    s.push_str(&format!(
        "  {g}$clock = clock;\n  {g}$rst = rst;\n  {g}$start1 = timing$start1;\n  {g}$addr = timing$addr;\n"
    ));
    if pin {
        s.push_str(&format!("  {g}$mode_sel = mode_sel$0;\n"));
    } else {
        s.push_str(&format!("  {g}$mode_sel = {MODE_BITS}'h0;\n"));
    }
    // a prepared conversion (selected by no word of ours) is no sample, so
    // no trigger's window sees it: gated as the merger's `done` (the twin's)
    let done: Vec<String> = (0..nb)
        .rev()
        .map(|b| match cmd_of[b] {
            Some(i) => format!("(branches${b}$done & cmds${i}$live)"),
            None => format!("branches${b}$done"),
        })
        .collect();
    let pad = if nb < MAX_BRANCHES {
        format!("{}'h0, ", MAX_BRANCHES - nb)
    } else {
        String::new()
    };
    s.push_str(&format!("  {g}$done = {{{pad}{}}};\n", done.join(", ")));
    for b in 0..lanes {
        s.push_str(&format!(
            "  {g}$ch${b} = branches${b}$res_ch;\n  {g}$v${b} = branches${b}$res_val;\n"
        ));
    }
    for b in 0..nb {
        s.push_str(&format!(
            "  branches${b}$addr = {g}$maddr;\n  branches${b}$slice = {g}$minfo;\n"
        ));
    }
    s.push_str(&format!("  mode$0 = {g}$mode;\n"));
}

/// The branches' lanes gathered into the fixed-maximum ports and the
/// merger's inputs; lanes the mix does not have are tied off.  A branch
/// with a command unit hands the merger no completion while its unit says
/// the conversion was only prepared.
fn lanes(s: &mut String, nb: usize, devices: &[usize], cmd_of: &[Option<usize>]) {
    let cat = |f: &dyn Fn(usize) -> String, pad: Option<String>| -> String {
        let mut parts: Vec<String> = (0..nb).rev().map(f).collect();
        if let Some(p) = pad {
            parts.insert(0, p);
        }
        format!("{{{}}}", parts.join(", "))
    };
    let pad_lanes = |v: &str| {
        if nb < MAX_BRANCHES {
            Some(format!("{{{}{{{v}}}}}", MAX_BRANCHES - nb))
        } else {
            None
        }
    };
    s.push_str(&format!(
        "  adc_cs_n = {};\n",
        cat(&|b| format!("branches${b}$cs_n"), pad_lanes("1'b1"))
    ));
    s.push_str(&format!(
        "  adc_sclk = {};\n",
        cat(&|b| format!("branches${b}$sclk"), pad_lanes("1'b1"))
    ));
    s.push_str(&format!(
        "  mux_sel = {};\n",
        cat(
            &|b| format!("branches${b}$mux_sel"),
            if nb < MAX_BRANCHES {
                Some(format!("{}'h0", 3 * (MAX_BRANCHES - nb)))
            } else {
                None
            }
        )
    ));
    let total: usize = devices.iter().sum();
    s.push_str(&format!(
        "  mux_en = {};\n",
        cat(
            &|b| format!("branches${b}$mux_en[{}:0]", devices[b] - 1),
            if total < EN_TOTAL {
                Some(format!("{}'h0", EN_TOTAL - total))
            } else {
                None
            }
        )
    ));
    let gated = |b: usize, sig: &str| match cmd_of[b] {
        Some(i) => format!("branches${b}${sig} & cmds${i}$live"),
        None => format!("branches${b}${sig}"),
    };
    s.push_str(&format!(
        "  merge$done = {};\n",
        cat(&|b| gated(b, "done"), pad_lanes("1'b0"))
    ));
    s.push_str(&format!(
        "  merge$done_next = {};\n",
        cat(&|b| gated(b, "done_next"), pad_lanes("1'b0"))
    ));
    s.push_str(&format!(
        "  merge$more = {};\n",
        cat(&|b| format!("branches${b}$more"), pad_lanes("1'b0"))
    ));
    for b in 0..MAX_BRANCHES {
        if b < nb {
            s.push_str(&format!(
                "  merge$ch${b} = branches${b}$res_ch;\n  merge$v${b} = branches${b}$res_val;\n"
            ));
        } else {
            s.push_str(&format!(
                "  merge$ch${b} = {CH_BITS}'h0;\n  merge$v${b} = {VALUE_BITS}'h0;\n"
            ));
        }
    }
}

/// Inputs the mix leaves unused, OR-reduced into named wires so that lint
/// sees them read.
fn unused_wires(s: &mut String, nb: usize, devices: &[usize], nseq: usize) {
    let unused: Vec<String> = (0..nb)
        .filter(|&b| devices[b] < EN_BITS)
        .map(|b| format!("branches${b}$mux_en[{}:{}]", EN_BITS - 1, devices[b]))
        .collect();
    if !unused.is_empty() {
        s.push_str(&format!(
            "\n// enables of devices a branch does not have are always zero\nwire unused_mux_en = |{{{}}};\n",
            unused.join(", ")
        ));
    }
    if nseq > 1 {
        let caps: Vec<String> = (1..nseq).map(|i| format!("seqs${i}$cap_next")).collect();
        s.push_str(&format!(
            "// only a single sequencer's mix has the merger's queue form\nwire unused_cap_next = |{{{}}};\n",
            caps.join(", ")
        ));
    }
    if nb < MAX_BRANCHES {
        s.push_str(&format!(
            "// lanes of branches the mix does not have\nwire unused_miso = |adc_miso[{}:{}];\nwire unused_grant = |merge$grant[{0}:{1}];\n",
            MAX_BRANCHES - 1,
            nb
        ));
    }
}
