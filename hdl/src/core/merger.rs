//! Merged sample stream.

use crate::rhdl::*;

use crate::plan::LaneChannels;
use crate::widths::*;

/// P(c) = pending completions plus this cycle's; the lowest branch in it
/// leaves in the next cycle (docs/timing.md, "Merged sample stream").
/// Fixed-maximum lanes (`MAX_BRANCHES`); the update is a loop and the
/// Verilog a priority chain over the mix's branches only, generated per mix,
/// so the lanes a mix does not have cost nothing.
///
/// The output registers load when P(c) is not empty; that enable is a
/// flip-flop (`r_any`, computed a cycle early from the next pending set and
/// the branches' `done_next`) rather than an OR over the pending set and
/// the completions, which was the core's critical path (docs/performance.md, "Lean gateware").
#[derive(LogicBlock)]
pub struct Merger {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub done: Signal<In, Bits<MAX_BRANCHES>>,
    /// Lane `b` has more words of the same conversion after the one offered.
    pub more: Signal<In, Bits<MAX_BRANCHES>>,
    /// `done` of the next cycle.
    pub done_next: Signal<In, Bits<MAX_BRANCHES>>,
    pub ch: [Signal<In, Bits<CH_BITS>>; MAX_BRANCHES],
    pub v: [Signal<In, Bits<VALUE_BITS>>; MAX_BRANCHES],
    /// Queue form: the sequencer's `cap` of the next cycle and the timing
    /// generator's `start2`, for the registered lane enables below.
    pub cap_next: Signal<In, Bit>,
    pub start2: Signal<In, Bit>,
    /// The timing generator's ROM address and the sequencer's done strobe
    /// (the queue form with the channel table).
    pub addr: Signal<In, Bits<SLOT_BITS>>,
    pub seq_done: Signal<In, Bit>,
    /// The lane whose word is taken at the end of this cycle (one-hot).
    pub grant: Signal<Out, Bits<MAX_BRANCHES>>,
    /// Queue form: the lanes' shift registers load (`cap | mv`) and their
    /// channel registers load (`start1 | mv`) at the end of this cycle,
    /// where `mv` (= `r_any`) moves every lane's word and channel to the
    /// lane below, lane 0's leaving. Zero in the priority form.
    /// Each is a flip-flop kept equal to its OR, so the enables of about 60
    /// flip-flops (global buffers in nextpnr) have no LUT in front of them.
    pub sh_en: Signal<Out, Bit>,
    pub ch_en: Signal<Out, Bit>,
    pub valid: Signal<Out, Bit>,
    pub channel: Signal<Out, Bits<CH_BITS>>,
    pub value: Signal<Out, Bits<VALUE_BITS>>,
    pub(super) r_valid: DFF<Bit>,
    pub(super) r_ch: DFF<Bits<CH_BITS>>,
    pub(super) r_val: DFF<Bits<VALUE_BITS>>,
    pub(super) pend: DFF<Bits<MAX_BRANCHES>>,
    /// P(c) is not empty (kept equal to `(pend | done) != 0`).
    pub(super) r_any: DFF<Bit>,
    pub(super) r_shen: DFF<Bit>,
    pub(super) r_chen: DFF<Bit>,
    /// Branches of the mix (lanes `0..nb` are used).
    _nb: usize,
    /// The queue form (`Plan::queue`): the branches' registers are the
    /// queue, lane 0 its head; `pend` is then a thermometer of the words
    /// still queued behind the head.
    _queue: bool,
    /// One chained branch (priority form, [`stepped_reader`]): `sh_en` is
    /// the registered `cap | r_any` the word reader's register steps under.
    _step: bool,
    /// The queue form's channel table (`Plan::lane_ch`), the words out
    /// since the last idle cycle (`kcnt`) and the table's registered read.
    _lane_ch: Option<LaneChannels>,
    _kcnt: usize,
    _chq: u32,
}

/// Whether the merger gives the word reader a registered shift enable in
/// the priority form: one branch, chained, no modes (the mode block reads
/// the reader's word). Its grant is then `r_any` (P(c) is that lane alone),
/// and the reader's 64-odd flip-flops step under `sh_en`, a flip-flop, not
/// under the priority chain's grant through a LUT and a global buffer
/// (vibrotactile8k's critical path).
pub(crate) fn stepped_reader(p: &crate::plan::Plan) -> bool {
    p.queue.is_none() && p.modes.is_none() && p.branches.len() == 1 && p.branches[0].chain > 1
}

impl Merger {
    pub(super) fn new(nb: usize, queue: bool, step: bool, lane_ch: Option<LaneChannels>) -> Merger {
        Merger {
            clock: Default::default(),
            rst: Default::default(),
            done: Default::default(),
            more: Default::default(),
            done_next: Default::default(),
            ch: std::array::from_fn(|_| Default::default()),
            v: std::array::from_fn(|_| Default::default()),
            cap_next: Default::default(),
            start2: Default::default(),
            addr: Default::default(),
            seq_done: Default::default(),
            grant: Default::default(),
            sh_en: Default::default(),
            ch_en: Default::default(),
            valid: Default::default(),
            channel: Default::default(),
            value: Default::default(),
            r_valid: Default::default(),
            r_ch: Default::default(),
            r_val: Default::default(),
            pend: Default::default(),
            r_any: Default::default(),
            r_shen: Default::default(),
            r_chen: Default::default(),
            _nb: nb,
            _queue: queue,
            _step: step,
            _lane_ch: lane_ch,
            _kcnt: 0,
            _chq: 0,
        }
    }
}

impl Merger {
    /// The word reader steps under `sh_en` ([`stepped_reader`]).
    pub(super) fn stepped(&self) -> bool {
        self._step
    }

    /// The queue form's update: P(c) is the words queued behind the head
    /// plus this cycle's completions, which all fall in one cycle (one SPI
    /// sequencer) and sit in lanes `0..n` in branch order; P(c) as a
    /// thermometer, lane 0 leaves and every lane moves up one.
    fn update_queue(&mut self) {
        if self._lane_ch.is_some() {
            self.update_table();
            return;
        }
        let n = self.done.val().to_u64().count_ones();
        let p = self.pend.q.val().to_u64() | ((1u64 << n) - 1);
        self.r_valid.d.next = p & 1 == 1;
        let mut pend = p >> 1;
        self.grant.next = 0u64.into();
        if self.r_any.q.val() {
            self.r_ch.d.next = self.ch[0].val();
            self.r_val.d.next = self.v[0].val();
        }
        if self.rst.val() {
            self.r_valid.d.next = false;
            self.r_ch.d.next = 0u64.into();
            self.r_val.d.next = 0u64.into();
            pend = 0;
        }
        self.pend.d.next = pend.into();
        let any = !self.rst.val() & ((pend & 1) | self.done_next.val().to_u64() != 0);
        self.r_any.d.next = any;
        // start1 of the next cycle is start2 or reset in this one
        self.r_shen.d.next = self.cap_next.val() | any;
        self.r_chen.d.next = self.start2.val() | self.rst.val() | any;
        self.sh_en.next = self.r_shen.q.val();
        self.ch_en.next = self.r_chen.q.val();
    }
}

impl Merger {
    /// The queue form with the channel table (`queue_table_text`): the
    /// head's channel and whether another word follows it come from the
    /// table, read a cycle ahead at `{addr, kcnt_d}`; no pending set
    /// (P(c)'s lowest bit is `r_any`, a word leaves in the next cycle when
    /// the slot completes then or another word follows this one).
    fn update_table(&mut self) {
        let Some(t) = &self._lane_ch else { return };
        let any_q = self.r_any.q.val();
        let kd = if any_q {
            (self._kcnt + 1) & ((1 << t.k_bits) - 1)
        } else {
            0
        };
        let next = self._chq >> t.ch_bits & 1 == 1;
        let ch = self._chq & ((1 << t.ch_bits) - 1);
        if self.clock.pos_edge() {
            let a = self.addr.val().to_u64() as usize & ((1 << t.addr_bits) - 1);
            self._chq = t.words[(a << t.k_bits) | kd];
            self._kcnt = kd;
        }
        let rst = self.rst.val();
        self.grant.next = 0u64.into();
        self.r_valid.d.next = any_q & !rst;
        if any_q {
            self.r_ch.d.next = (ch as u64).into();
            self.r_val.d.next = self.v[0].val();
        }
        if rst {
            self.r_ch.d.next = 0u64.into();
            self.r_val.d.next = 0u64.into();
        }
        self.pend.d.next = 0u64.into();
        let any = !rst & (self.done_next.val().to_u64() != 0 || any_q && next);
        self.r_any.d.next = any;
        // `cap | mv`, and also at every completion of the sequencer and a
        // cycle after the last word (the lanes move, harmless: the next
        // capture refills them): flip-flops only, not the table's read
        self.r_shen.d.next = self.cap_next.val() | self.seq_done.val() | any_q;
        self.r_chen.d.next = self.start2.val() | rst | any;
        self.sh_en.next = self.r_shen.q.val();
        self.ch_en.next = self.r_chen.q.val();
    }
}

impl Logic for Merger {
    fn update(&mut self) {
        dff_setup!(self, clock, r_valid, r_ch, r_val, pend, r_any, r_shen, r_chen);
        self.valid.next = self.r_valid.q.val();
        self.channel.next = self.r_ch.q.val();
        self.value.next = self.r_val.q.val();
        if self._queue {
            self.update_queue();
            return;
        }
        self.sh_en.next = false;
        self.ch_en.next = false;
        self.r_shen.d.next = false;
        self.r_chen.d.next = false;
        let p = self.pend.q.val().to_u64() | self.done.val().to_u64();
        self.r_valid.d.next = p != 0;
        let mut pend = 0u64;
        self.grant.next = 0u64.into();
        if p != 0 {
            let b = p.trailing_zeros() as usize;
            let more = self.more.val().to_u64() & (1 << b);
            // A chained conversion stays pending until its last word leaves.
            pend = (p & (p - 1)) | more;
            self.grant.next = (1u64 << b).into();
        }
        if self.r_any.q.val() {
            // the Verilog's last lane is its `else`: the same lane when
            // `r_any` holds its invariant
            let b = if p != 0 {
                p.trailing_zeros() as usize
            } else {
                self._nb - 1
            };
            self.r_ch.d.next = self.ch[b].val();
            self.r_val.d.next = self.v[b].val();
        }
        if self.rst.val() {
            self.r_valid.d.next = false;
            self.r_ch.d.next = 0u64.into();
            self.r_val.d.next = 0u64.into();
            pend = 0;
        }
        self.pend.d.next = pend.into();
        let any = !self.rst.val() & ((pend | self.done_next.val().to_u64()) != 0);
        self.r_any.d.next = any;
        if self._step {
            self.r_shen.d.next = self.cap_next.val() | any;
            self.sh_en.next = self.r_shen.q.val();
        }
    }

    fn connect(&mut self) {
        self.r_valid.clock.connect();
        self.r_valid.d.connect();
        self.r_ch.clock.connect();
        self.r_ch.d.connect();
        self.r_val.clock.connect();
        self.r_val.d.connect();
        self.pend.clock.connect();
        self.pend.d.connect();
        self.r_any.clock.connect();
        self.r_any.d.connect();
        self.r_shen.clock.connect();
        self.r_shen.d.connect();
        self.r_chen.clock.connect();
        self.r_chen.d.connect();
        self.grant.connect();
        self.sh_en.connect();
        self.ch_en.connect();
        self.valid.connect();
        self.channel.connect();
        self.value.connect();
    }

    fn hdl(&self) -> Verilog {
        if self._queue {
            return Verilog::Custom(queue_text(self._nb, self._lane_ch.as_ref()));
        }
        let nb = self._nb;
        let w = MAX_BRANCHES;
        let mut s = format!(
            "// P(c) of the mix's {nb} lanes: pending plus this cycle's completions\nwire [{}:0] p = pend$q[{0}:0] | done[{0}:0];\n\n",
            nb - 1
        );
        s.push_str("always @(*) begin\n");
        for f in [
            "r_valid", "r_ch", "r_val", "pend", "r_any", "r_shen", "r_chen",
        ] {
            s.push_str(&format!("  {f}$clock = clock;\n"));
        }
        s.push_str(&format!(
            "  r_valid$d = |p;\n  r_ch$d = r_ch$q;\n  r_val$d = r_val$q;\n  pend$d = {w}'h0;\n  grant = {w}'h0;\n"
        ));
        // grant and the next pending set: the priority chain over P(c)
        for b in 0..nb {
            let kw = if b == 0 { "if" } else { "else if" };
            let mut rest = String::new();
            if nb > 1 {
                rest = format!("p & {nb}'h{:x}", ((1u64 << nb) - 1) & !(1u64 << b));
            }
            let pend = if nb == 1 {
                format!("{w}'h0")
            } else if nb < w {
                format!("{{{}'h0, {rest}}}", w - nb)
            } else {
                rest
            };
            s.push_str(&format!(
                "  {kw} (p[{b}]) begin\n    pend$d = {pend};\n    pend$d[{b}] = more[{b}];\n    grant = {w}'h{:x};\n  end\n",
                1u64 << b
            ));
        }
        // the output registers: enabled by the registered r_any (= P(c) not
        // empty), the last lane as the chain's `else`
        s.push_str("  if (r_any$q) begin\n");
        for b in 0..nb {
            let kw = match b {
                0 if nb == 1 => "  begin".to_string(),
                0 => format!("  if (p[{b}]) begin"),
                _ if b + 1 == nb => "  else begin".to_string(),
                _ => format!("  else if (p[{b}]) begin"),
            };
            s.push_str(&format!(
                "  {kw}\n      r_ch$d = ch${b};\n      r_val$d = v${b};\n    end\n"
            ));
        }
        s.push_str("  end\n");
        s.push_str(&format!(
            "  if (rst) begin\n    r_valid$d = 1'b0;\n    r_ch$d = {CH_BITS}'h0;\n    r_val$d = {VALUE_BITS}'h0;\n    pend$d = {w}'h0;\n  end\n"
        ));
        s.push_str(&format!(
            "  r_any$d = !rst & |{{pend$d[{0}:0], done_next[{0}:0]}};\n",
            nb - 1
        ));
        if self._step {
            s.push_str("  // the chained reader's shift enable, registered\n  r_shen$d = cap_next | r_any$d;\n  sh_en = r_shen$q;\n");
            s.push_str("  r_chen$d = 1'b0;\n  ch_en = 1'b0;\n");
        } else {
            s.push_str(
                "  r_shen$d = 1'b0;\n  r_chen$d = 1'b0;\n  sh_en = 1'b0;\n  ch_en = 1'b0;\n",
            );
        }
        s.push_str("  valid = r_valid$q;\n  channel = r_ch$q;\n  value = r_val$q;\nend\n");
        let unused = self.priority_unused();
        {
            s.push_str(&format!(
                "\n// lanes of branches the mix does not have (tied to zero by the core),\n// the queue form's inputs\nwire unused_lanes = |{{{}}};\n",
                unused.join(", ")
            ));
        }
        Verilog::Custom(s)
    }
}

impl Merger {
    /// The priority form's unused inputs: the queue form's inputs and
    /// enables, and the lanes of branches the mix does not have.
    fn priority_unused(&self) -> Vec<String> {
        let (nb, w) = (self._nb, MAX_BRANCHES);
        let mut unused: Vec<String> = if self._step {
            vec![
                "start2".into(),
                "r_chen$q".into(),
                "addr".into(),
                "seq_done".into(),
            ]
        } else {
            [
                "cap_next", "start2", "r_shen$q", "r_chen$q", "addr", "seq_done",
            ]
            .map(String::from)
            .to_vec()
        };
        if nb < w {
            unused.push(format!("done[{}:{nb}]", w - 1));
            unused.push(format!("more[{}:{nb}]", w - 1));
            unused.push(format!("done_next[{}:{nb}]", w - 1));
            unused.push(format!("pend$q[{}:{nb}]", w - 1));
            for b in nb..w {
                unused.push(format!("ch${b}"));
                unused.push(format!("v${b}"));
            }
        }
        unused
    }
}

/// The queue form's Verilog (the twin is `Merger::update_queue`): no word
/// multiplexer, the output registers load lane 0, the head of the queue.
fn queue_text(nb: usize, lane_ch: Option<&LaneChannels>) -> String {
    if let Some(t) = lane_ch {
        return queue_table_text(nb, t);
    }
    let w = MAX_BRANCHES;
    let cb = usize::BITS as usize - nb.leading_zeros() as usize;
    let sum: Vec<String> = (0..nb)
        .map(|b| format!("{{{}'h0, done[{b}]}}", cb - 1))
        .collect();
    let therm: Vec<String> = (0..nb)
        .rev()
        .map(|j| format!("(n_done > {cb}'d{j})"))
        .collect();
    let mut s = format!(
        "// the mix's {nb} lanes are the queue, lane 0 its head: this cycle's\n\
         // completions fill lanes 0..n_done-1, pend holds the words behind the head\n\
         wire [{}:0] n_done = {};\n\
         wire [{top}:0] p = pend$q[{top}:0] | {{{}}};\n\n",
        cb - 1,
        sum.join(" + "),
        therm.join(", "),
        top = nb - 1,
    );
    s.push_str("always @(*) begin\n");
    for f in [
        "r_valid", "r_ch", "r_val", "pend", "r_any", "r_shen", "r_chen",
    ] {
        s.push_str(&format!("  {f}$clock = clock;\n"));
    }
    s.push_str(&format!(
        "  r_valid$d = p[0];\n  r_ch$d = r_ch$q;\n  r_val$d = r_val$q;\n  pend$d = {{{}'h0, p[{}:1]}};\n  grant = {w}'h0;\n",
        w - nb + 1,
        nb - 1
    ));
    // The output registers under `r_any | rst` (an iCE40 flip-flop resets
    // only when enabled). As gates (a LUT per bit, no enable) they were
    // faster, but `prove --netlist` then cannot see them renewed every
    // frame (the held value's feedback LUT), and says bounded, not proved.
    s.push_str("  if (r_any$q) begin\n    r_ch$d = ch$0;\n    r_val$d = v$0;\n  end\n");
    s.push_str(&format!(
        "  if (rst) begin\n    r_valid$d = 1'b0;\n    r_ch$d = {CH_BITS}'h0;\n    r_val$d = {VALUE_BITS}'h0;\n    pend$d = {w}'h0;\n  end\n"
    ));
    s.push_str(&format!(
        "  r_any$d = !rst & |{{pend$d[0], done_next[{}:0]}};\n",
        nb - 1
    ));
    s.push_str("  // the lanes' enables, registered: start1 is start2 or reset a cycle late\n");
    s.push_str("  r_shen$d = cap_next | r_any$d;\n  r_chen$d = start2 | rst | r_any$d;\n");
    s.push_str("  sh_en = r_shen$q;\n  ch_en = r_chen$q;\n");
    s.push_str("  valid = r_valid$q;\n  channel = r_ch$q;\n  value = r_val$q;\nend\n");
    let mut unused: Vec<String> = vec!["more".to_string()];
    // a mix with every lane (16 branches) reads the whole pending set
    if nb < w {
        unused.push(format!("pend$q[{}:{nb}]", w - 1));
        unused.push(format!("done[{}:{nb}]", w - 1));
        unused.push(format!("done_next[{}:{nb}]", w - 1));
    }
    unused.push("addr".to_string());
    unused.push("seq_done".to_string());
    for b in 1..w {
        unused.push(format!("ch${b}"));
        unused.push(format!("v${b}"));
    }
    s.push_str(&format!(
        "\n// lanes behind the head are read by the lane below, not here\nwire unused_lanes = |{{{}}};\n",
        unused.join(", ")
    ));
    s
}

/// The queue form with the channel table (`Plan::lane_ch`; the twin is
/// `Merger::update_table`): a block RAM read a cycle ahead at `{addr,
/// kcnt_d}`, `kcnt_d` the index of the word that leaves in the next cycle
/// (the words out since the last idle cycle), gives the head's channel and
/// whether another word follows; the lanes carry no channel and the merger
/// no pending set.
fn queue_table_text(nb: usize, t: &LaneChannels) -> String {
    let w = MAX_BRANCHES;
    let (ab, kb, cw) = (t.addr_bits, t.k_bits, t.ch_bits);
    let digits = (cw + 1).div_ceil(4);
    let mut s = format!(
        "// the mix's {nb} lanes are the queue, lane 0 its head; the channel of each\n\
         // word out (and whether another follows) by the slot's ROM address and\n\
         // the words already out\n\
         reg [{cw}:0] chmem [0:{}];\ninitial begin\n",
        t.words.len() - 1
    );
    for (a, x) in t.words.iter().enumerate() {
        s.push_str(&format!("  chmem[{a}] = {}'h{x:0digits$x};\n", cw + 1));
    }
    s.push_str(&format!(
        "end\nreg [{k}:0] kcnt;\ninitial kcnt = {kb}'h0;\nwire [{k}:0] kcnt_d = r_any$q ? kcnt + {kb}'h1 : {kb}'h0;\n\
         // a block RAM's read register: no initial value, read only after a read\n\
         reg [{cw}:0] chq;\nalways @(posedge clock) begin\n  kcnt <= kcnt_d;\n  chq <= chmem[{{addr[{a}:0], kcnt_d}}];\nend\n\n",
        k = kb - 1,
        a = ab - 1,
    ));
    s.push_str("always @(*) begin\n");
    for f in [
        "r_valid", "r_ch", "r_val", "pend", "r_any", "r_shen", "r_chen",
    ] {
        s.push_str(&format!("  {f}$clock = clock;\n"));
    }
    let pad = if cw < CH_BITS {
        format!("{{{}'h0, chq[{}:0]}}", CH_BITS - cw, cw - 1)
    } else {
        format!("chq[{}:0]", cw - 1)
    };
    s.push_str(&format!(
        "  // P(c)'s lowest bit is r_any: a word leaves in this cycle\n  r_valid$d = r_any$q;\n  r_ch$d = r_ch$q;\n  r_val$d = r_val$q;\n  pend$d = {w}'h0;\n  grant = {w}'h0;\n"
    ));
    s.push_str(&format!(
        "  if (r_any$q) begin\n    r_ch$d = {pad};\n    r_val$d = v$0;\n  end\n"
    ));
    s.push_str(&format!(
        "  if (rst) begin\n    r_valid$d = 1'b0;\n    r_ch$d = {CH_BITS}'h0;\n    r_val$d = {VALUE_BITS}'h0;\n  end\n"
    ));
    s.push_str(&format!(
        "  // a word leaves next: the slot completes now, or another follows this one\n  r_any$d = !rst & (|done_next[{}:0] | r_any$q & chq[{cw}]);\n",
        nb - 1
    ));
    s.push_str("  // the lanes' enables, registered: cap | mv, and also at every completion\n  // and a cycle after the last word (the next capture refills the lanes):\n  // flip-flops only, not the table's read\n");
    s.push_str(
        "  r_shen$d = cap_next | seq_done | r_any$q;\n  r_chen$d = start2 | rst | r_any$d;\n",
    );
    s.push_str("  sh_en = r_shen$q;\n  ch_en = r_chen$q;\n");
    s.push_str("  valid = r_valid$q;\n  channel = r_ch$q;\n  value = r_val$q;\nend\n");
    let mut unused: Vec<String> =
        vec!["more".into(), "done".into(), "pend$q".into(), "ch$0".into()];
    if nb < w {
        unused.push(format!("done_next[{}:{nb}]", w - 1));
    }
    if ab < SLOT_BITS {
        unused.push(format!("addr[{}:{ab}]", SLOT_BITS - 1));
    }
    for b in 1..w {
        unused.push(format!("ch${b}"));
        unused.push(format!("v${b}"));
    }
    s.push_str(&format!(
        "\n// lanes behind the head are read by the lane below, the channels and the\n// words behind the head come from the table\nwire unused_lanes = |{{{}}};\n",
        unused.join(", ")
    ));
    s
}
