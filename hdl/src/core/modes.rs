//! Mode block (a mix with modes only): the mode register, the slot ROMs'
//! address with the mode on it, and the triggers (docs/timing.md, "Mode
//! switches").

use std::fmt::Write as _;

use crate::rhdl::*;

use crate::modeplan::{ModePlan, TrigPlan};
use crate::widths::*;

/// The mode of the frame in force (`cur`) and of the next (`nxt`), decided
/// at the edge that begins a frame (`start1` in a cycle whose next slot
/// start is slot 0: the registered `z`), from `mode_sel` (pin select) or
/// from the first trigger armed whose condition held in its last
/// `for_frames` windows (auto). A window is the watched words of the
/// conversions that complete in a frame: a branch's word sits on its
/// reader in the cycle its `done` is high, so the words of the frame's last
/// cycle join the window the edge closes.
///
/// The ROM address is the timing generator's slot with the mode of that
/// slot's frame above it (`nxt` when the slot is in the next frame); `minfo`
/// tells the ROMs the next frame's mode and whether the word they read is
/// of the next frame (then its successor's mode is not decided yet).
/// Custom Verilog: its shape (triggers, watched channels) is the mix's.
#[derive(LogicBlock)]
pub struct ModeGen {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub start1: Signal<In, Bit>,
    pub addr: Signal<In, Bits<SLOT_BITS>>,
    pub mode_sel: Signal<In, Bits<MODE_BITS>>,
    pub done: Signal<In, Bits<MAX_BRANCHES>>,
    /// Each branch's word and its channel (auto select only).
    pub ch: Vec<Signal<In, Bits<CH_BITS>>>,
    pub v: Vec<Signal<In, Bits<VALUE_BITS>>>,
    pub mode: Signal<Out, Bits<MODE_BITS>>,
    pub maddr: Signal<Out, Bits<SLOT_BITS>>,
    pub minfo: Signal<Out, Bits<SLICE_BITS>>,
    _p: ModePlan,
    _nb: usize,
    _cur: usize,
    _nxt: usize,
    _prev: usize,
    _go: bool,
    _z: bool,
    /// Per trigger: the window so far (any, above, below) and the run.
    _win: Vec<(bool, bool, bool)>,
    _run: Vec<u32>,
}

impl ModeGen {
    pub(super) fn new(p: &ModePlan, nb: usize) -> ModeGen {
        let lanes = if p.pin { 0 } else { nb };
        ModeGen {
            clock: Default::default(),
            rst: Default::default(),
            start1: Default::default(),
            addr: Default::default(),
            mode_sel: Default::default(),
            done: Default::default(),
            ch: (0..lanes).map(|_| Default::default()).collect(),
            v: (0..lanes).map(|_| Default::default()).collect(),
            mode: Default::default(),
            maddr: Default::default(),
            minfo: Default::default(),
            _p: p.clone(),
            _nb: nb,
            _cur: 0,
            _nxt: 0,
            _prev: 0,
            _go: false,
            _z: true,
            _win: vec![(false, false, true); p.triggers.len()],
            _run: vec![0; p.triggers.len()],
        }
    }

    /// Trigger `k`'s window with this cycle's words.
    fn window(&self, k: usize, t: &TrigPlan) -> (bool, bool, bool) {
        let (mut any, mut above, mut below) = self._win[k];
        let done = self.done.val().to_u64();
        for (b, chans) in t.watch.iter().enumerate() {
            if done >> b & 1 == 0 || !chans.contains(&(self.ch[b].val().to_u64() as u32)) {
                continue;
            }
            let v = self.v[b].val().to_u64() as u32;
            any = true;
            above |= v > t.level;
            below &= v < t.level;
        }
        (any, above, below)
    }

    /// The edge that begins a frame (after the first): runs, the decision.
    fn decide(&mut self, wins: &[(bool, bool, bool)]) {
        let same = self._cur == self._prev;
        let (cur, nxt) = (self._cur, self._nxt);
        let mut decided = nxt;
        if self._p.pin {
            let sel = self.mode_sel.val().to_u64() as usize;
            if sel < self._p.count {
                decided = sel;
            }
        }
        let mut fired = false;
        for (k, t) in self._p.triggers.iter().enumerate() {
            let (any, above, below) = wins[k];
            let held = if t.above { above } else { any && below };
            self._run[k] = match (held, same) {
                (false, _) => 0,
                (true, true) => (self._run[k] + 1).min(t.for_frames),
                (true, false) => 1,
            };
            if !fired && t.armed_in(nxt) && cur == nxt && self._run[k] >= t.for_frames {
                decided = t.to;
                fired = true;
            }
        }
        self._prev = cur;
        self._cur = nxt;
        self._nxt = decided;
    }
}

impl Logic for ModeGen {
    fn update(&mut self) {
        let fend = self.start1.val() && self._z;
        let addr = self.addr.val().to_u64();
        if self.clock.pos_edge() {
            if self.rst.val() {
                (self._cur, self._nxt, self._prev, self._go) = (0, 0, 0, false);
                self._win.iter_mut().for_each(|w| *w = (false, false, true));
                self._run.iter_mut().for_each(|r| *r = 0);
            } else {
                let trig = std::mem::take(&mut self._p.triggers);
                let wins: Vec<_> = (trig.iter().enumerate())
                    .map(|(k, t)| self.window(k, t))
                    .collect();
                self._p.triggers = trig;
                if fend && self._go {
                    self.decide(&wins);
                }
                if fend {
                    self._go = true;
                    self._win.iter_mut().for_each(|w| *w = (false, false, true));
                } else {
                    self._win = wins;
                }
            }
            self._z = addr == 0;
        }
        // in reset the ROM reads mode 0's first slot: `nxt` and `z` may
        // still hold their power-on values at the first edge
        let rst = self.rst.val();
        let fend = self.start1.val() && self._z && !rst;
        let anx = addr == 0;
        let nxt = if rst { 0 } else { self._nxt };
        let amode = if anx || fend { nxt } else { self._cur };
        self.mode.next = (self._cur as u64).into();
        self.maddr.next = ((amode << self._p.slot_bits) as u64 | addr).into();
        let info = ((anx && !fend) as u64) << self._p.bits | nxt as u64;
        self.minfo.next = info.into();
    }

    fn connect(&mut self) {
        self.mode.connect();
        self.maddr.connect();
        self.minfo.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(mode_verilog(&self._p, self._nb))
    }
}

/// The Verilog of [`ModeGen`].
fn mode_verilog(p: &ModePlan, nb: usize) -> String {
    let mb = p.bits as usize;
    let sb = p.slot_bits;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "// the modes of the frame in force and of the next; the first frame start seen\n// (frames 0 and 1 run the reset mode); the next slot start is a frame's\n// (initial values: their reset values, as the twin starts)\nreg [{}:0] cur = {mb}'d0;\nreg [{0}:0] nxt = {mb}'d0;\nreg go = 1'b0;\nreg z = 1'b1;\n// in reset the ROM reads mode 0's first slot\nwire fend = start1 & z & ~rst;\nwire anx = addr == {SLOT_BITS}'h0;\nwire [{0}:0] nxt0 = rst ? {mb}'d0 : nxt;\n",
        mb - 1
    );
    if !p.pin {
        let _ = writeln!(s, "// the mode of the frame before (a run of windows stays in one mode)\nreg [{}:0] prev = {mb}'d0;", mb - 1);
    }
    let mut unused = vec![];
    let decided = if p.pin {
        unused.push("done".into());
        if mb < MODE_BITS {
            unused.push(format!("mode_sel[{}:{mb}]", MODE_BITS - 1));
        }
        if p.count == 1 << mb {
            format!("mode_sel[{}:0]", mb - 1)
        } else {
            format!(
                "(mode_sel[{}:0] < {mb}'d{}) ? mode_sel[{0}:0] : nxt",
                mb - 1,
                p.count
            )
        }
    } else {
        unused.push("mode_sel".into());
        if nb < MAX_BRANCHES {
            unused.push(format!("done[{}:{nb}]", MAX_BRANCHES - 1));
        }
        triggers_verilog(&mut s, p, nb, &mut unused)
    };
    let _ = writeln!(s, "wire [{}:0] decided = {decided};\n", mb - 1);
    s.push_str(&registers_verilog(p));
    let pad = |v: String, w: usize, full: usize| {
        if w < full {
            format!("{{{}'h0, {v}}}", full - w)
        } else {
            v
        }
    };
    let _ = writeln!(
        s,
        "always @(*) begin\n  mode = {};\n  maddr = {};\n  minfo = {};\nend",
        pad("cur".into(), mb, MODE_BITS),
        pad(
            format!("{{((anx | fend) ? nxt0 : cur), addr[{}:0]}}", sb - 1),
            mb + sb,
            SLOT_BITS
        ),
        pad("{anx & ~fend, nxt0}".into(), mb + 1, SLICE_BITS),
    );
    if !unused.is_empty() {
        let _ = writeln!(
            s,
            "\n// inputs this mix's mode selection does not read\nwire unused_mode = |{{{}}};",
            unused.join(", ")
        );
    }
    s
}

/// Per trigger: the window registers, this cycle's words, the run; returns
/// the decision's expression (the first trigger that fires, else `nxt`).
fn triggers_verilog(s: &mut String, p: &ModePlan, nb: usize, unused: &mut Vec<String>) -> String {
    let mut used = vec![false; nb];
    let _ = writeln!(s, "wire same = cur == prev;");
    for (k, t) in p.triggers.iter().enumerate() {
        let rb = t.run_bits();
        let n = t.for_frames;
        let _ = writeln!(
            s,
            "// trigger {k}: to mode {}{}, {} {} for {n} frame(s)\nreg wany{k} = 1'b0;\nreg wab{k} = 1'b0;\nreg wbe{k} = 1'b1;\nreg [{}:0] run{k} = {rb}'d0;",
            t.to,
            t.from.map_or(String::new(), |f| format!(" from mode {f}")),
            if t.above { "above" } else { "below" },
            t.level,
            rb - 1
        );
        let (mut any, mut ab, mut be) = (
            vec![format!("wany{k}")],
            vec![format!("wab{k}")],
            vec![format!("wbe{k}")],
        );
        for (b, chans) in t.watch.iter().enumerate().filter(|(_, c)| !c.is_empty()) {
            used[b] = true;
            let m: Vec<String> = chans
                .iter()
                .map(|c| format!("ch${b} == {CH_BITS}'d{c}"))
                .collect();
            let _ = writeln!(s, "wire hit{k}_{b} = done[{b}] & ({});", m.join(" | "));
            any.push(format!("hit{k}_{b}"));
            ab.push(format!(
                "(hit{k}_{b} & (v${b} > {VALUE_BITS}'d{}))",
                t.level
            ));
            be.push(format!(
                "(~hit{k}_{b} | (v${b} < {VALUE_BITS}'d{}))",
                t.level
            ));
        }
        let _ = writeln!(
            s,
            "wire cany{k} = {};\nwire cab{k} = {};\nwire cbe{k} = {};",
            any.join(" | "),
            ab.join(" | "),
            be.join(" & ")
        );
        let held = if t.above {
            format!("cab{k}")
        } else {
            format!("cany{k} & cbe{k}")
        };
        let armed = match t.from {
            Some(f) => format!("nxt == {}'d{f}", p.bits),
            None => format!("nxt != {}'d{}", p.bits, t.to),
        };
        let _ = writeln!(
            s,
            "wire [{}:0] runn{k} = ({held}) ? (same ? ((run{k} == {rb}'d{n}) ? run{k} : run{k} + {rb}'d1) : {rb}'d1) : {rb}'d0;\nwire fire{k} = ({armed}) & (cur == nxt) & (runn{k} == {rb}'d{n});\n",
            rb - 1
        );
    }
    // the triggers in file order: the first that fires wins
    let mut d = "nxt".to_string();
    for (k, t) in p.triggers.iter().enumerate().rev() {
        d = format!("fire{k} ? {}'d{} : ({d})", p.bits, t.to);
    }
    for (b, _) in used.iter().enumerate().filter(|(_, u)| !**u) {
        unused.extend([format!("done[{b}]"), format!("ch${b}"), format!("v${b}")]);
    }
    d
}

/// The registers: the modes at the frame starts, the windows every cycle.
fn registers_verilog(p: &ModePlan) -> String {
    let mut rst = String::new();
    let mut decide = String::new();
    let mut clear = String::new();
    let mut keep = String::new();
    for (k, t) in p.triggers.iter().enumerate() {
        let rb = t.run_bits();
        let _ = write!(
            rst,
            "    wany{k} <= 1'b0;\n    wab{k} <= 1'b0;\n    wbe{k} <= 1'b1;\n    run{k} <= {rb}'d0;\n"
        );
        let _ = writeln!(decide, "      run{k} <= runn{k};");
        let _ = write!(
            clear,
            "      wany{k} <= 1'b0;\n      wab{k} <= 1'b0;\n      wbe{k} <= 1'b1;\n"
        );
        let _ = write!(
            keep,
            "      wany{k} <= cany{k};\n      wab{k} <= cab{k};\n      wbe{k} <= cbe{k};\n"
        );
    }
    let mb = p.bits;
    if !p.pin {
        let _ = writeln!(rst, "    prev <= {mb}'d0;");
        let _ = writeln!(decide, "      prev <= cur;");
    }
    let mut s = format!(
        "always @(posedge clock) begin\n  z <= anx;\n  if (rst) begin\n    cur <= {mb}'d0;\n    nxt <= {mb}'d0;\n    go <= 1'b0;\n{rst}  end else begin\n    if (fend & go) begin\n{decide}      cur <= nxt;\n      nxt <= decided;\n    end\n"
    );
    if p.triggers.is_empty() {
        s.push_str("    if (fend) go <= 1'b1;\n");
    } else {
        let _ = write!(
            s,
            "    if (fend) begin\n      go <= 1'b1;\n{clear}    end else begin\n{keep}    end\n"
        );
    }
    s.push_str("  end\nend\n\n");
    s
}
